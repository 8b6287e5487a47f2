// fix insert/stream: particles entering through a planar face of a mesh.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/engine.h"
#include "insert_stream_scene.h"
#include "mesh_files.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;
using granary::test::ScriptEngine;
using mesh_files::Triangle;

namespace {

const std::string kDir = mesh_files::temp_dir();

// The insertion face: a 0.1 m square at z = 0.1 (4 x 4 cells, 32 triangles).
std::string face_file() {
  static const std::string f = [] {
    std::vector<Triangle> t;
    mesh_files::add_rectangle(t, Vec3(0, 0, 0.1), Vec3(0.1, 0, 0), Vec3(0, 0.1, 0), 4, 4);
    mesh_files::write_ascii(kDir + "/face.stl", t);
    return kDir + "/face.stl";
  }();
  return f;
}

// dt 1e-5, normal speed 1 m/s, extrude_length 0.02 m: a batch every 2000 steps
// of 1234 * 0.02 = 24.68 particles (radius 2 mm); no gravity.
std::vector<std::string> scene(const std::string& ins_extra = "extrude_length 0.02") {
  std::vector<std::string> s = insert_stream_scene::box(face_file());
  s.insert(
      s.end(),
      {"fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant "
       "0.002",
       "fix pdd1 all particledistribution/discrete 15485867 1 pts1 1.0",
       "fix ins all insert/stream seed 32452843 distributiontemplate pdd1 nparticles INF particlerate 1234 "
       "vel constant 0.3 0. -1.0 overlapcheck yes insertion_face face " +
           ins_extra,
       "fix integr all nve/sphere"});
  return s;
}

std::map<long long, Vec3> positions(const granary::Particles& p) {
  std::map<long long, Vec3> m;
  for (int i = 0; i < p.nlocal; ++i)
    m[p.id[i]] = p.x[i];
  return m;
}

}  // namespace

TEST_CASE("insert/stream fills the extruded face at the given rate, held particles move to the face",
          "[insert]") {
  ScriptEngine s;
  s.cmds(scene());
  s.cmd("run 1");
  const auto& p = s.p();
  // first batch at step 1: floor(24.68) = 24 particles, all in the volume
  // above the face (extruded against the normal velocity), shifted by their
  // radius away from the face, and not overlapping
  REQUIRE(p.nlocal == 24);
  for (int i = 0; i < p.nlocal; ++i) {
    const Vec3 x = p.x[i];
    CHECK(x[0] >= 0.0);
    CHECK(x[0] <= 0.1);
    CHECK(x[1] >= 0.0);
    CHECK(x[1] <= 0.1);
    // centre r + [0, L] above the face (the sphere wholly behind it), inserted this step
    CHECK(x[2] >= 0.102);
    CHECK(x[2] <= 0.122);
    // held: the normal velocity only
    CHECK(p.v[i] == Vec3(0.0, 0.0, -1.0));
    for (int j = 0; j < i; ++j)
      CHECK((p.x[j] - x).norm() >= 0.004);
  }
  const auto first = positions(p);
  // 3 more batches at steps 2001, 4001, 6001: floor(4 * 24.68) = 98 after step 6001
  s.cmd("run 6000");
  CHECK(p.nlocal == 98);
  CHECK(s.e.fix_value("ins", 1) == 98.0);
  CHECK(s.e.fix_value("ins", 2) == Approx(98 * 2500 * 4.0 / 3.0 * M_PI * 8e-9).epsilon(1e-12));
  int released = 0, held = 0, exact = 0;
  for (int i = 0; i < p.nlocal; ++i) {
    if (p.x[i][2] > 0.1) {
      ++held;
      CHECK(p.v[i] == Vec3(0.0, 0.0, -1.0));
    } else {
      ++released;
      // no gravity, no collisions among particles that all move alike: the
      // full insertion velocity from the face on
      exact += (p.v[i] - Vec3(0.3, 0.0, -1.0)).norm() < 1e-12;
    }
  }
  // held: the batch of step 6001, and those of step 4001 that started less
  // than r = 2 mm above the top (20 mm) of the prism: about 10% of 25
  CHECK(held >= 24);
  CHECK(held <= 24 + 7);
  CHECK(released == 98 - held);
  CHECK(exact >= released - 4);  // a few may graze a held neighbour at the face
  // the first batch: straight down at 1 m/s to the face (0.1 - z0 seconds... ),
  // then at (0.3, 0, -1); after 0.06 s: z = z0 - 0.06, x = x0 + 0.3 (0.06 - (z0 - 0.1))
  const auto now = positions(p);
  int on_line = 0;
  for (const auto& [id, x0] : first) {
    const Vec3 x = now.at(id);
    const double t_face = x0[2] - 0.1;  // seconds to reach the face at 1 m/s
    const Vec3 expect(x0[0] + 0.3 * (0.06 - t_face), x0[1], x0[2] - 0.06);
    on_line += (x - expect).norm() < 2e-5;  // release within one step (1e-5 m)
  }
  CHECK(on_line >= 22);
}

TEST_CASE("insert/stream derives the extrusion from insert_every and continues across a restart",
          "[insert][restart]") {
  const std::string file = kDir + "/stream.restart";
  std::map<long long, Vec3> straight, restarted;
  double n_straight = 0, n_restarted = 0;
  {
    ScriptEngine s;
    s.cmds(scene("insert_every 2000"));  // the same stream as extrude_length 0.02
    s.cmds({"run 3000", "write_restart " + file, "run 3002"});
    straight = positions(s.p());
    n_straight = s.e.fix_value("ins", 1);
    CHECK(n_straight == 98.0);
  }
  {
    ScriptEngine s;
    s.cmds({"atom_style granular", "read_restart " + file});
    std::vector<std::string> again = scene("insert_every 2000");
    again.erase(again.begin(), again.begin() + 7);  // box and neighbour settings come from the file
    s.cmds(again);
    s.cmd("run 3002");
    restarted = positions(s.p());
    n_restarted = s.e.fix_value("ins", 1);
  }
  std::remove(file.c_str());
  CHECK(n_restarted == n_straight);
  REQUIRE(restarted.size() == straight.size());
  double worst = 0;
  for (const auto& [id, x] : straight) {
    REQUIRE(restarted.count(id) == 1);
    worst = std::max(worst, (restarted.at(id) - x).norm());
  }
  CHECK(worst == 0.0);
}

TEST_CASE("insert/stream input errors", "[insert]") {
  ScriptEngine s;
  auto lines = scene();
  lines.pop_back();
  lines.pop_back();
  s.cmds(lines);
  const std::string head =
      "fix ins all insert/stream seed 32452843 distributiontemplate pdd1 nparticles 10 particlerate 100 ";
  REQUIRE_THROWS_WITH(s.cmd(head + "vel constant 0 0 -1 insertion_face face"),
                      Contains("exactly one of extrude_length and insert_every"));
  REQUIRE_THROWS_WITH(
      s.cmd(head + "vel constant 0 0 -1 insertion_face face extrude_length 0.1 insert_every 10"),
      Contains("exactly one of extrude_length and insert_every"));
  REQUIRE_THROWS_WITH(s.cmd(head + "vel constant 0 0 -1 extrude_length 0.1"), Contains("insertion_face"));
  REQUIRE_THROWS_WITH(s.cmd(head + "vel constant 0 0 -1 insertion_face m1 extrude_length 0.1"),
                      Contains("not a mesh/surface"));
  s.cmd(head + "vel constant 1 0 0 insertion_face face extrude_length 0.1");
  REQUIRE_THROWS_WITH(s.cmd("run 1"), Contains("parallel to the insertion face"));
}
