// fix planeforce, lineforce, nve/noforce, spring/self and move on free particles,
// on any number of ranks, against their closed-form motion: under gravity
// along (0, 1, 1) a sphere with planeforce 0 0 1 falls along y only and one
// with lineforce 1 1 0 along the line; nve/noforce moves with its velocity
// whatever the force; spring/self makes a harmonic oscillator whose energy
// is conserved, in the chosen directions only, and keeps its anchors across a
// restart; fix move linear, wiggle and rotate give LIGGGHTS 3.8's motion.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "core/engine.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<std::string> scene(const std::string& boundary = "f f f") {
  return {"units si",
          "atom_style granular",
          "boundary " + boundary,
          "region reg block -1 1 -1 1 -1 1 units box",
          "create_box 1 reg",
          "create_atoms 1 single -0.5 -0.5 -0.5 units box",
          "create_atoms 1 single 0.5 0.5 0.5 units box",
          "create_atoms 1 single 0.5 -0.5 0.0 units box",
          "set atom * diameter 0.01 density 2000",
          granary::test::materials(1, 5e6, 0.3, 0.9, 0.3),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 1e-4"};
}

Vec3 position(granary::Engine& e, long long id, Vec3* v = nullptr) {
  Vec3 x, vel;
  REQUIRE(granary::test::particle_state(e, id, x, vel));
  if (v) *v = vel;
  return x;
}

/// A clump of two spheres (fix multisphere), for the fixes that refuse them.
void add_clump(granary::test::ScriptEngine& s) {
  s.cmds(
      {"fix dumb all particletemplate/multisphere 15485867 atom_type 1 density constant 2500 nspheres 2 "
       "ntry 1000000 spheres -0.01 0 0 0.01 0.01 0 0 0.01 type 1",
       "fix ms all multisphere", "create_clump dumb 0 0.5 0.5"});
}

}  // namespace

TEST_CASE("planeforce and lineforce keep the force in a plane or along a line", "[fix][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(scene());
  s.cmds({"group one id 1", "group two id 2", "fix gravi all gravity 9.81 vector 0 1 1",
          "fix plane one planeforce 0 0 2", "fix line two lineforce 1 1 0", "fix integr all nve/sphere",
          "run 1000"});
  const double t = 0.1, a = 9.81 / std::sqrt(2.0);
  const Vec3 p1 = position(s.e, 1), p2 = position(s.e, 2), p3 = position(s.e, 3);
  CHECK(p1.x() == -0.5);
  CHECK(p1.y() == Approx(-0.5 + 0.5 * a * t * t).epsilon(1e-12));
  CHECK(p1.z() == -0.5);  // no force along the normal
  // along (1, 1, 0)/sqrt(2): the component a/sqrt(2) of the gravity
  CHECK(p2.x() == Approx(0.5 + 0.5 * (a / 2) * t * t).epsilon(1e-12));
  CHECK(p2.y() == Approx(0.5 + 0.5 * (a / 2) * t * t).epsilon(1e-12));
  CHECK(p2.z() == 0.5);
  CHECK(p3.z() == Approx(0.5 * a * t * t).epsilon(1e-12));  // free
  CHECK_THROWS_WITH(s.cmd("fix bad all planeforce 0 0 0"), Contains("must not be zero"));
  CHECK_THROWS_WITH(s.cmd("fix bad all lineforce 1 0"), Contains("lineforce x y z"));
}

TEST_CASE("nve/noforce moves particles with their velocity only", "[fix][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(scene());
  s.cmds({"group one id 1", "group rest id 2 3", "velocity one set 0.3 -0.2 0.1",
          "fix gravi all gravity 9.81 vector 0 0 -1", "fix carried one nve/noforce",
          "fix integr rest nve/sphere", "run 1000"});
  Vec3 v;
  const Vec3 p1 = position(s.e, 1, &v);
  CHECK((p1 - Vec3(-0.5 + 0.03, -0.5 - 0.02, -0.5 + 0.01)).norm() < 1e-13);
  CHECK(v == Vec3(0.3, -0.2, 0.1));
  CHECK(position(s.e, 3).z() == Approx(-0.5 * 9.81 * 0.01).epsilon(1e-12));
  // spheres of a clump are moved by fix multisphere: refused
  add_clump(s);
  s.cmds({"group clump id > 3", "fix carried2 clump nve/noforce"});
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("are spheres of clumps"));
}

TEST_CASE("nve integrates positions and velocities, not spins", "[fix][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(scene());
  // particle 1 spins at 3 rad/s and falls; velocity Verlet is exact for a constant force
  s.cmds({"group one id 1", "velocity one set 0.3 -0.2 0.1", "velocity one setAngular 0 0 3",
          "fix gravi all gravity 9.81 vector 0 0 -1", "fix integr all nve", "compute rot all erotate/sphere",
          "run 0"});
  const double spin_energy = s.e.compute_value("rot", 0);
  REQUIRE(spin_energy > 0.0);
  s.cmd("run 1000");
  Vec3 v;
  const Vec3 p1 = position(s.e, 1, &v);
  const double t = 0.1;  // 1000 steps of 0.1 ms
  CHECK(p1.x() == Approx(-0.5 + 0.3 * t).epsilon(1e-13));
  CHECK(p1.y() == Approx(-0.5 - 0.2 * t).epsilon(1e-13));
  CHECK(p1.z() == Approx(-0.5 + 0.1 * t - 0.5 * 9.81 * t * t).epsilon(1e-12));
  CHECK(v.z() == Approx(0.1 - 9.81 * t).epsilon(1e-12));
  CHECK(s.e.compute_value("rot", 0) == spin_energy);  // the spin is kept as it was
  add_clump(s);
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("are spheres of clumps"));
}

TEST_CASE("spring/self makes harmonic oscillators in the chosen directions and keeps its anchors in restarts",
          "[fix][mpi][restart]") {
  const std::string dir = granary::test::shared_temp_dir("granary_spring_");
  const double m = 2000 * 4.0 / 3.0 * kPi * 0.005 * 0.005 * 0.005, K = 0.05;
  const double w = std::sqrt(K / m);
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(scene("p p p"));
    s.cmds({"group one id 1", "group two id 2", "velocity one set 0.1 0.2 0 units box",
            "velocity two set 0.1 8 0 units box", "fix tie one spring/self 0.05",
            "fix tiez two spring/self 0.05 x", "fix integr all nve/sphere", "run 2000"});
    const double t = 0.2;
    Vec3 v;
    const Vec3 p1 = position(s.e, 1, &v);
    // x(t) = x0 + v0 sin(w t) / w; velocity Verlet's phase error is (w dt)^2 / 24 per unit phase
    CHECK(p1.x() == Approx(-0.5 + 0.1 * std::sin(w * t) / w).epsilon(1e-5));
    CHECK(p1.y() == Approx(-0.5 + 0.2 * std::sin(w * t) / w).epsilon(1e-5));
    const double energy = 0.5 * m * v.squaredNorm() + s.e.fix_value("tie", 0);
    CHECK(energy == Approx(0.5 * m * (0.01 + 0.04)).epsilon(1e-6));
    // x only: y moves freely and wraps through the periodic face
    const Vec3 p2 = position(s.e, 2);
    CHECK(p2.x() == Approx(0.5 + 0.1 * std::sin(w * t) / w).epsilon(1e-5));
    CHECK(p2.y() == Approx(0.5 + 8 * t - 2.0).epsilon(1e-9));
    s.cmd("write_restart " + dir + "/spring.restart");
  }
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"read_restart " + dir + "/spring.restart", granary::test::materials(1, 5e6, 0.3, 0.9, 0.3),
          "pair_style gran model hertz tangential history", "pair_coeff * *", "group one id 1",
          "fix tie one spring/self 0.05", "fix integr all nve/sphere", "run 2000"});
  const Vec3 p1 = position(s.e, 1);
  CHECK(p1.x() == Approx(-0.5 + 0.1 * std::sin(w * 0.4) / w).epsilon(1e-5));  // the anchor kept
  CHECK(s.e.particles->find_field("spring/self/tie") >= 0);
  s.cmd("unfix tie");
  CHECK(s.e.particles->find_field("spring/self/tie") < 0);
  CHECK_THROWS_WITH(s.cmd("fix bad all spring/self -1"), Contains("must be positive"));
  CHECK_THROWS_WITH(s.cmd("fix bad all spring/self 1 xw"), Contains("directions must be"));
  MPI_Barrier(MPI_COMM_WORLD);
  if (granary::test::world_rank() == 0) std::filesystem::remove_all(dir);
}

namespace {

std::vector<std::string> move_scene() {
  std::vector<std::string> s = granary::test::liggghts_head("-0.05 0.05 -0.05 0.05 -0.05 0.05", 1);
  const std::vector<std::string> rest = {
      "fix m1 all property/global youngsModulus peratomtype 5e6",
      "fix m2 all property/global poissonsRatio peratomtype 0.3",
      "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5",
      "fix m4 all property/global coefficientFriction peratomtypepair 1 0.4",
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "create_atoms 1 single -0.03 0 0.02",
      "create_atoms 1 single 0 0 0",
      "create_atoms 1 single 0.0041 0.001 0",
      "create_atoms 1 single 0.02 0 -0.02",
      "set atom * diameter 0.004 density 2500",
      "group a1 id 1",
      "group a2 id 2",
      "group a3 id 3",
      "group a4 id 4",
      "velocity a3 set -0.1 0 0",
      "fix grav all gravity 9.81 vector 0 0 -1",
      "timestep 1e-6"};
  s.insert(s.end(), rest.begin(), rest.end());
  return s;
}

const std::vector<std::string> kMoves = {
    "fix mv1 a1 move linear 0.1 0 NULL", "fix mv2 a2 move wiggle 0.002 0 0 0.01",
    "fix mv4 a4 move rotate 0 0 0 0 0 1 0.05", "fix integr a3 nve/sphere"};

void check_move_state(granary::Engine& e) {
  // LIGGGHTS 3.8 after 20000 steps of the same script (thermo %22.16g)
  Vec3 v1, v2, v3, v4;
  const Vec3 x1 = position(e, 1, &v1), x2 = position(e, 2, &v2), x3 = position(e, 3, &v3),
             x4 = position(e, 4, &v4);
  CHECK(x1.x() == Approx(-0.028).epsilon(1e-14));               // linear 0.1 m/s in x
  CHECK(x1.z() == Approx(0.01803800000000018).epsilon(1e-13));  // NULL z: falls under gravity
  CHECK(std::fabs(x2.x()) < 1e-15);                             // wiggle: a whole period
  CHECK(v2.x() == Approx(1.256637061435917).epsilon(1e-13));
  CHECK(x3.x() == Approx(0.04029059184767045).epsilon(1e-12));  // knocked by the wiggling sphere
  CHECK(v3.x() == Approx(1.851189127731431).epsilon(1e-12));
  CHECK(x4.x() == Approx(-0.01618033988749895).epsilon(1e-13));  // rotate: 0.4 of a turn
  CHECK(x4.y() == Approx(0.01175570504584946).epsilon(1e-13));
  CHECK(v4.y() == Approx(-2.033281476926104).epsilon(1e-13));
  double w[4] = {0, 0, 0, 0}, all[4];
  const auto& p = *e.particles;
  for (int i = 0; i < p.nlocal; ++i)
    w[p.id[i] - 1] = p.omega[i].z();
  MPI_Allreduce(w, all, 4, MPI_DOUBLE, MPI_SUM, e.world);
  CHECK(all[1] == 0.0);  // a wiggling sphere does not spin (torque ignored)
  CHECK(all[2] == Approx(107.0028266860977).epsilon(1e-12));
  CHECK(all[3] == Approx(125.6637061435917).epsilon(1e-13));  // rotate sets the spin: 2 pi / 0.05
}

}  // namespace

// fix move linear (with a NULL component under gravity), wiggle and rotate,
// and a free sphere knocked by the wiggling one: LIGGGHTS 3.8's positions,
// velocities and spins, on any rank count, and the same after a restart in the
// middle (the fixes defined again with their IDs keep their origins and start
// time).
TEST_CASE("fix move linear, wiggle and rotate follow LIGGGHTS 3.8 and continue across a restart",
          "[fix][mpi][move][restart]") {
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(move_scene());
    s.cmds(kMoves);
    s.cmd("run 20000");
    check_move_state(s.e);
  }
  const std::string dir = granary::test::shared_temp_dir("granary_move_");
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(move_scene());
    s.cmds(kMoves);
    s.cmds({"run 12000", "write_restart " + dir + "/move.restart"});
  }
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"read_restart " + dir + "/move.restart", "fix m1 all property/global youngsModulus peratomtype 5e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.3",
          "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5",
          "fix m4 all property/global coefficientFriction peratomtypepair 1 0.4",
          "pair_style gran model hertz tangential history", "pair_coeff * *",
          "fix grav all gravity 9.81 vector 0 0 -1"});
  s.cmds(kMoves);
  s.cmd("run 8000");
  check_move_state(s.e);
  CHECK_THROWS_WITH(s.cmd("fix bad all move variable v_a NULL NULL NULL NULL NULL"),
                    Contains("variable style is not supported"));
  CHECK_THROWS_WITH(s.cmd("fix bad all move wiggle 1 0 0 0"), Contains("period must be positive"));
  CHECK_THROWS_WITH(s.cmd("fix bad all move rotate 0 0 0 0 0 0 1"), Contains("axis must not be zero"));
  CHECK_THROWS_WITH(s.cmd("fix bad all move wobble 1 0 0"), Contains("unknown fix move style"));
  CHECK(s.e.particles->find_field("move/mv1") >= 0);
  s.cmd("unfix mv1");
  CHECK(s.e.particles->find_field("move/mv1") < 0);
  MPI_Barrier(MPI_COMM_WORLD);
  if (granary::test::world_rank() == 0) std::filesystem::remove_all(dir);
}
