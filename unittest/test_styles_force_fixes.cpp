// Fixes addforce, setforce and aveforce on free spheres against the analytic
// motion under constant, time-dependent and per-particle forces; the input
// errors of fix momentum (its physics: test_mpi_force_fixes.cpp).
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "fix/fix.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

using granary::test::particle_state;
using World = granary::test::ScriptEngine;  // on MPI_COMM_WORLD
const std::vector<std::string> kBox = granary::test::free_box();

// diameter 0.01 m, density 2000 kg/m^3
const double kMass = 4.0 / 3.0 * M_PI * 1.25e-7 * 2000;

}  // namespace

TEST_CASE("fix addforce: a free particle accelerates at F/m", "[fix][addforce]") {
  World s(MPI_COMM_WORLD);
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0 0 0", "create_atoms 2 single 0.1 0 0", "create_atoms 1 single 0 0.1 0",
          "set type * diameter 0.01 density 2000", "region half block -0.05 0.05 -0.05 0.05 -0.05 0.05",
          "variable fx atom 1e-3*type", "variable fz equal 2e-3*time",
          "fix push all addforce v_fx NULL v_fz region half", "fix i all nve/sphere", "run 1000"});
  const double t = 0.1;
  Vec3 x, v;
  // particle 1: fx = 1e-3 N (atom-style, by type), fz = 2e-3 t N (linear in
  // time: velocity Verlet integrates it exactly)
  REQUIRE(particle_state(s.e, 1, x, v));
  CHECK(v[0] == Approx(1e-3 / kMass * t).epsilon(1e-10));
  CHECK(x[0] == Approx(0.5e-3 / kMass * t * t).epsilon(1e-10));
  CHECK(v[1] == 0.0);
  CHECK(v[2] == Approx(1e-3 / kMass * t * t).epsilon(1e-10));
  // particles 2 and 3 are outside the region: no force
  REQUIRE(particle_state(s.e, 2, x, v));
  CHECK(v == Vec3(0, 0, 0));
  REQUIRE(particle_state(s.e, 3, x, v));
  CHECK(v == Vec3(0, 0, 0));
}

TEST_CASE("fix addforce: constant force, energy and total force outputs", "[fix][addforce]") {
  World s(MPI_COMM_WORLD);
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0 0 0", "create_atoms 2 single 0.05 0 0.02",
          "set type * diameter 0.01 density 2000", "fix g all gravity 9.81 vector 0 0 -1",
          "fix push all addforce 1e-3 0 -2e-3", "fix i all nve/sphere", "run 500"});
  const double t = 0.05;
  Vec3 x, v;
  REQUIRE(particle_state(s.e, 2, x, v));
  const Vec3 a(1e-3 / kMass, 0, -2e-3 / kMass - 9.81);
  CHECK(v.isApprox(a * t, 1e-10));
  CHECK(x.isApprox(Vec3(0.05, 0, 0.02) + 0.5 * a * t * t, 1e-10));
  // scalar: -sum x.F; vector: the force before the addition (the weight)
  Vec3 x1, v1;
  REQUIRE(particle_state(s.e, 1, x1, v1));
  const Vec3 f(1e-3, 0, -2e-3);
  // the scalar is the energy at the last force evaluation (positions of the last step)
  CHECK(s.e.fix_value("push", 0) == Approx(-(x + x1).dot(f)).epsilon(1e-12));
  CHECK(s.e.fix_value("push", 3) == Approx(-2 * 9.81 * kMass).epsilon(1e-12));
  CHECK(s.e.fix_value("push", 1) == 0.0);
}

TEST_CASE("fix addforce: input errors", "[fix][addforce]") {
  World s(MPI_COMM_WORLD);
  s.cmds(kBox);
  CHECK_THROWS_WITH(s.cmd("fix push all addforce 1 0"), Contains("three force components"));
  CHECK_THROWS_WITH(s.cmd("fix push all addforce 1 0 x"), Contains("fz"));
  CHECK_THROWS_WITH(s.cmd("fix push all addforce v_none 0 0"), Contains("none"));
  CHECK_THROWS_WITH(s.cmd("fix push all addforce 1 0 0 region nowhere"), Contains("nowhere"));
  CHECK_THROWS_WITH(s.cmd("fix push all addforce 1 0 0 energy v_e"), Contains("constant"));
  CHECK_THROWS_WITH(s.cmd("fix push all addforce 1 0 0 every 2"), Contains("usage"));
}

TEST_CASE("fix setforce: the set component moves at fx/m, the NULL ones are left alone", "[fix][setforce]") {
  World s(MPI_COMM_WORLD);
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0 0 0", "create_atoms 2 single 0.1 0 0",
          "set type * diameter 0.01 density 2000", "velocity all set 0 0.2 0", "group one type 1",
          "fix g all gravity 9.81 vector 0 0 -1", "fix push all addforce 1e-3 1e-3 0",
          "variable fy atom 2e-4*id", "fix set one setforce 5e-4 v_fy NULL", "fix i all nve/sphere",
          "run 1000"});
  const double t = 0.1;
  Vec3 x, v;
  REQUIRE(particle_state(s.e, 1, x, v));
  CHECK(v[0] == Approx(5e-4 / kMass * t).epsilon(1e-10));        // set
  CHECK(v[1] == Approx(0.2 + 2e-4 / kMass * t).epsilon(1e-10));  // set by an atom-style variable
  CHECK(v[2] == Approx(-9.81 * t).epsilon(1e-10));               // NULL: gravity acts
  CHECK(x[1] == Approx(0.2 * t + 1e-4 / kMass * t * t).epsilon(1e-10));
  REQUIRE(particle_state(s.e, 2, x, v));  // not in the group
  CHECK(v[0] == Approx(1e-3 / kMass * t).epsilon(1e-10));
  // vector: the force on the group before it was set (addforce + weight)
  CHECK(s.e.fix_value("set", 1) == Approx(1e-3).epsilon(1e-12));
  CHECK(s.e.fix_value("set", 3) == Approx(-9.81 * kMass).epsilon(1e-12));

  CHECK_THROWS_WITH(s.cmd("fix set2 all setforce 0 0 0 energy v_fy"), Contains("usage"));
}

TEST_CASE("fix aveforce: the group moves as one under the mean force plus the extra one", "[fix][aveforce]") {
  World s(MPI_COMM_WORLD);
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0 0 0", "create_atoms 1 single 0.05 0 0", "create_atoms 1 single 0.1 0 0",
          "create_atoms 2 single 0 0.1 0", "set type * diameter 0.01 density 2000", "group lid type 1",
          "variable fx atom 3e-4*id", "fix push all addforce v_fx 0 0", "variable fz equal -1e-3",
          "fix ave lid aveforce 0.0 NULL v_fz", "fix i all nve/sphere", "run 1000"});
  const double t = 0.1;
  // lid: ids 1..3 with fx = 3e-4, 6e-4, 9e-4: mean 6e-4; z: mean 0 plus -1e-3
  const Vec3 a(6e-4 / kMass, 0, -1e-3 / kMass);
  for (long long id = 1; id <= 3; ++id) {
    Vec3 x, v;
    REQUIRE(particle_state(s.e, id, x, v));
    CHECK(v.isApprox(a * t, 1e-10));
    CHECK(x[0] == Approx(0.05 * (id - 1) + 0.5 * a[0] * t * t).epsilon(1e-10));
  }
  Vec3 x, v;
  REQUIRE(particle_state(s.e, 4, x, v));  // outside the group: its own force
  CHECK(v[0] == Approx(1.2e-3 / kMass * t).epsilon(1e-10));
  CHECK(s.e.fix_value("ave", 1) == Approx(1.8e-3).epsilon(1e-12));

  CHECK_THROWS_WITH(s.cmd("fix ave2 lid aveforce v_fx 0 0\nrun 1"), Contains("atom-style"));
}

TEST_CASE("fix setforce, aveforce and momentum refuse spheres of clumps",
          "[fix][setforce][aveforce][momentum]") {
  for (const char* style : {"setforce 0 0 0", "aveforce 0 0 0", "momentum 1 linear 1 1 1"}) {
    World s(MPI_COMM_WORLD);
    s.cmds(kBox);
    s.cmds(
        {"fix dumb all particletemplate/multisphere 15485867 atom_type 1 density constant 2500 nspheres 2 "
         "ntry 1000000 spheres -0.001 0 0 0.001 0.001 0 0 0.001 type 1",
         "fix ms all multisphere", "create_clump dumb 0 0 0", std::string("fix f all ") + style});
    const std::string name = std::string(style).substr(0, std::string(style).find(' '));
    CHECK_THROWS_WITH(s.cmd("run 1"), Contains("clump") && Contains(name));
  }
}

TEST_CASE("fix momentum: input errors", "[fix][momentum]") {
  World s(MPI_COMM_WORLD);
  s.cmds(kBox);
  CHECK_THROWS_WITH(s.cmd("fix m all momentum 0 linear 1 1 1"), Contains("positive"));
  CHECK_THROWS_WITH(s.cmd("fix m all momentum 10 linear 1 1"), Contains("three flags"));
  CHECK_THROWS_WITH(s.cmd("fix m all momentum 10 linear 1 2 1"), Contains("0 or 1"));
  CHECK_THROWS_WITH(s.cmd("fix m all momentum 10 angualr"), Contains("angular"));
  CHECK_THROWS_WITH(s.cmd("fix m all momentum 10"), Contains("usage"));
}

TEST_CASE("fix store/force: the force as it was at the fix's turn", "[fix][store_force]") {
  World s(MPI_COMM_WORLD);
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0 0 0", "create_atoms 2 single 0.1 0 0",
          "set type * diameter 0.01 density 2000", "group one type 1", "fix g all gravity 9.81 vector 0 0 -1",
          "fix push all addforce 1e-3 0 0", "fix st one store/force", "fix hold all setforce 0 0 0",
          "fix i all nve/sphere", "run 10"});
  // held in place by setforce, but the stored force is weight + push of the group's particle
  std::vector<double> f[3];
  for (int c = 0; c < 3; ++c)
    s.e.fix_peratom("st", c + 1, f[c]);
  const auto& p = *s.e.particles;
  for (int i = 0; i < p.nlocal; ++i) {
    if (p.id[i] == 1) {
      CHECK(f[0][i] == Approx(1e-3).epsilon(1e-12));
      CHECK(f[1][i] == 0.0);
      CHECK(f[2][i] == Approx(-9.81 * kMass).epsilon(1e-12));
      CHECK(p.x[i] == Vec3(0, 0, 0));
    } else {
      CHECK(f[0][i] == 0.0);  // not in the group
      CHECK(f[2][i] == 0.0);
    }
  }
  std::vector<double> out;
  CHECK_THROWS_WITH(s.e.fix_peratom("st", 0, out), Contains("column"));
  CHECK_THROWS_WITH(s.cmd("fix st2 all store/force now"), Contains("usage"));
}

TEST_CASE("fix spring tether: the centre of mass oscillates with period 2 pi sqrt(M/K) about the rest length",
          "[fix][spring]") {
  // two free particles (no pair style: no contacts) tethered by their centre
  // of mass to (0, 0, 0) with rest length 0.02 m along x only (y, z NULL);
  // released at rest 0.05 m out, the centre of mass moves as
  // x(t) = 0.02 + 0.03 cos(w t), w = sqrt(K / M), the pair keeps its shape
  World s(MPI_COMM_WORLD);
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0.04 0.01 0", "create_atoms 2 single 0.06 -0.01 0.03",
          "set type * diameter 0.01 density 2000", "fix ta all spring tether 2e-3 0.0 NULL NULL 0.02",
          "fix i all nve/sphere", "run 0"});
  const double K = 2e-3, M = 2 * kMass, w = std::sqrt(K / M);
  CHECK(s.e.modify->find_fix("ta")->compute_scalar() == Approx(0.5 * K * 0.03 * 0.03).epsilon(1e-12));
  CHECK(s.e.modify->find_fix("ta")->compute_vector(0) == Approx(-K * 0.03).epsilon(1e-12));
  CHECK(s.e.modify->find_fix("ta")->compute_vector(3) == Approx(K * 0.03).epsilon(1e-12));
  const int steps = 4000;  // t = 0.4 s
  s.cmd("run " + std::to_string(steps));
  const double t = steps * 1e-4;
  Vec3 x1, v1, x2, v2;
  REQUIRE(particle_state(s.e, 1, x1, v1));
  REQUIRE(particle_state(s.e, 2, x2, v2));
  CHECK(0.5 * (x1[0] + x2[0]) == Approx(0.02 + 0.03 * std::cos(w * t)).epsilon(1e-5));
  CHECK(x2[0] - x1[0] == Approx(0.02).epsilon(1e-12));  // forces shared by mass: no deformation
  CHECK(v1[1] == 0.0);
  CHECK(v1[2] == 0.0);
}

TEST_CASE("fix spring: input errors", "[fix][spring]") {
  World s(MPI_COMM_WORLD);
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0 0 0", "set type * diameter 0.01 density 2000", "group one id 1"});
  CHECK_THROWS_WITH(s.cmd("fix s all spring pull 1 0 0 0 0"), Contains("expected 'tether' or 'couple'"));
  CHECK_THROWS_WITH(s.cmd("fix s all spring tether 1 0 0 0"), Contains("usage"));
  CHECK_THROWS_WITH(s.cmd("fix s all spring tether -1 0 0 0 0"), Contains("must be positive"));
  CHECK_THROWS_WITH(s.cmd("fix s all spring tether 1 NULL NULL NULL 0"), Contains("all NULL"));
  CHECK_THROWS_WITH(s.cmd("fix s all spring tether 1 0 0 0 -0.1"), Contains("R0 must be >= 0"));
  CHECK_THROWS_WITH(s.cmd("fix s all spring couple nosuch 1 0 0 0 0"), Contains("nosuch"));
  s.cmd("fix s all spring couple one 1 0 0 NULL 0");
}
