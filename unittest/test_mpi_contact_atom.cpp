// compute contact/atom: the number of particles each particle overlaps,
// against a count over all pairs, on any number of ranks, with newton on and
// off; and the counts LIGGGHTS 3.8 gives for five spheres.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/engine.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

struct Sphere {
  Vec3 x;
  double r;
};

/// Per-atom values of c_ID and the particles, by id, gathered from every rank.
std::map<long long, std::pair<Sphere, double>> gather(granary::Engine& e, const std::string& id, int n) {
  std::vector<double> values;
  e.compute_peratom(id, 0, values);
  const auto& p = *e.particles;
  std::vector<double> local(6 * n, 0.0), all(6 * n);
  for (int i = 0; i < p.nlocal; ++i) {
    const auto k = static_cast<std::size_t>(p.id[i] - 1);
    for (int d = 0; d < 3; ++d)
      local[6 * k + d] = p.x[i][d];
    local[6 * k + 3] = p.radius[i];
    local[6 * k + 4] = values[i];
    local[6 * k + 5] = 1;
  }
  MPI_Allreduce(local.data(), all.data(), 6 * n, MPI_DOUBLE, MPI_SUM, e.world);
  std::map<long long, std::pair<Sphere, double>> out;
  for (int k = 0; k < n; ++k) {
    REQUIRE(all[6 * k + 5] == 1.0);
    out[k + 1] = {{Vec3(all[6 * k], all[6 * k + 1], all[6 * k + 2]), all[6 * k + 3]}, all[6 * k + 4]};
  }
  return out;
}

}  // namespace

TEST_CASE("compute contact/atom: the overlaps of every particle on any number of ranks",
          "[contact_atom][mpi]") {
  for (const char* newton : {"on", "off"}) {
    INFO("newton " << newton);
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    // a jittered lattice of spheres of two sizes, 2.4 mm apart, periodic in x
    // and y: many overlaps, also across the periodic and rank boundaries
    s.cmds({"units si", "atom_style granular", "boundary p p f", std::string("newton ") + newton,
            "region box block 0 0.0192 0 0.0192 0 0.0192", "create_box 2 box"});
    int n = 0;
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 8; ++j)
        for (int k = 0; k < 8; ++k) {
          char line[160];
          std::snprintf(line, sizeof line, "create_atoms %d single %.6f %.6f %.6f",
                        1 + (i * 7 + j * 3 + k) % 2, 0.0012 + 0.0024 * i + 0.0002 * ((j * 5 + k) % 3),
                        0.0012 + 0.0024 * j + 0.0002 * (k % 2),
                        0.0012 + 0.0024 * k + 0.00015 * ((i + j) % 3));
          s.cmd(line);
          ++n;
        }
    s.cmds({"set type 1 diameter 0.0024 density 2500", "set type 2 diameter 0.0026 density 2500",
            "group big type 2", "neighbor 0.0005 bin", "compute nc big contact/atom",
            "compute ng all coord/gran", "run 0"});
    const auto big = gather(s.e, "nc", n);
    const auto all = gather(s.e, "ng", n);
    const Vec3 prd(0.0192, 0.0192, 0.0192);
    long long total = 0;
    for (const auto& [id, a] : all) {
      int expect = 0;
      for (const auto& [jd, b] : all) {
        if (jd == id) continue;
        Vec3 d = a.first.x - b.first.x;
        for (int q = 0; q < 2; ++q)  // periodic in x and y: the nearest image
          d[q] -= prd[q] * std::round(d[q] / prd[q]);
        if (d.norm() < a.first.r + b.first.r) ++expect;
      }
      INFO("particle " << id);
      CHECK(a.second == expect);
      CHECK(big.at(id).second == (a.first.r > 0.00125 ? expect : 0.0));  // 0 outside the group
      total += expect;
    }
    CHECK(total > n);  // the scene has contacts
  }
}

// LIGGGHTS 3.8 (dump custom of c_ca of compute contact/atom and of
// contact/atom/gran) gives 0 1 2 1 0 for these five spheres of diameter
// 10 mm: 1-2 and 2-4 overlap, 3 is 0.5 mm from 1 (within the skin), 5 is
// 0.1 mm from 1.
TEST_CASE("compute contact/atom: five spheres as LIGGGHTS 3.8", "[contact_atom][mpi][liggghts]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"units si", "atom_style granular", "boundary f f f", "region reg block -0.1 0.1 -0.1 0.1 -0.1 0.1",
          "create_box 1 reg", "neighbor 0.002 bin", "create_atoms 1 single 0 0 0",
          "create_atoms 1 single 0.0099 0 0", "create_atoms 1 single -0.0105 0 0",
          "create_atoms 1 single 0.0198 0 0", "create_atoms 1 single 0 0.0101 0",
          "set atom * diameter 0.01 density 2000"});
  std::vector<double> v;
  s.cmd("compute ca all contact/atom");
  CHECK_THROWS_WITH(s.e.compute_peratom("ca", 0, v), Contains("run 0"));  // no neighbour lists yet
  s.cmds({"compute cg all contact/atom/gran", "run 0"});
  const auto ca = gather(s.e, "ca", 5), cg = gather(s.e, "cg", 5);
  const double liggghts[5] = {1, 2, 0, 1, 0};
  for (int k = 0; k < 5; ++k) {
    CHECK(ca.at(k + 1).second == liggghts[k]);
    CHECK(cg.at(k + 1).second == liggghts[k]);
  }
  CHECK_THROWS_WITH(s.cmd("compute bad all contact/atom 1"), Contains("usage"));
}
