// Fixes gravity, freeze, viscous and property/global: free fall against the
// analytic trajectory, frozen particles, exponential viscous decay, and the
// checks of property tables against the number of atom types.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "script_engine.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "fix/fix_property_global.h"
#include "core/modify.h"
#include "particles/particles.h"

using Catch::Matchers::Contains;
using granary::Engine;
using granary::InputError;
using granary::Vec3;

namespace {

struct Sim : granary::test::ScriptEngine {
  Sim() : ScriptEngine(MPI_COMM_WORLD) {}
};

/// Position and velocity of particle `id`, wherever it lives.
void state(Engine& e, long long id, Vec3& x, Vec3& v) {
  REQUIRE(granary::test::particle_state(e, id, x, v));
}

const std::vector<std::string> kBox = granary::test::free_box();

}  // namespace

TEST_CASE("fix gravity: free fall follows x0 + v0 t - g t^2 / 2", "[fix]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0 0 0", "create_atoms 2 single 0.1 0 0",
          "set type 1 diameter 0.01 density 2000", "set type 2 diameter 0.02 density 1000",
          "velocity all set 0.1 0 1",
          "fix g all gravity 9.81 vector 0 0 -2",  // the direction is normalised
          "fix i all nve/sphere", "run 1000"});
  const double t = 0.1, g = 9.81;
  Vec3 x, v;
  state(s.e, 1, x, v);
  CHECK(x[0] == Approx(0.1 * t).epsilon(1e-9));
  CHECK(x[1] == 0.0);
  CHECK(x[2] == Approx(1.0 * t - 0.5 * g * t * t).epsilon(1e-9));
  CHECK(v[2] == Approx(1.0 - g * t).epsilon(1e-9));
  state(s.e, 2, x, v);  // heavier and larger: same trajectory
  CHECK(x[0] == Approx(0.1 + 0.1 * t).epsilon(1e-9));
  CHECK(x[2] == Approx(1.0 * t - 0.5 * g * t * t).epsilon(1e-9));

  // the scalar is the potential energy -sum m g.x
  const auto& p = *s.e.particles;
  double pe = 0.0;
  for (int i = 0; i < p.nlocal; ++i)
    pe += p.rmass[i] * g * p.x[i][2];
  double pe_all = 0.0;
  MPI_Allreduce(&pe, &pe_all, 1, MPI_DOUBLE, MPI_SUM, s.e.world);
  CHECK(s.e.fix_value("g", 0) == Approx(pe_all).epsilon(1e-12));
}

// Gravity and nve/sphere of group all read no group masks (every particle is
// in it); of another group they act on its particles only.
TEST_CASE("fix gravity and nve/sphere: group all, and a group that leaves particles out", "[fix]") {
  struct Groups {
    std::string gravity, nve;
  };
  for (const Groups groups : {Groups{"all", "all"}, Groups{"falling", "all"}, Groups{"all", "falling"}}) {
    INFO("fix gravity of group " << groups.gravity << ", nve/sphere of group " << groups.nve);
    Sim s;
    s.cmds(kBox);
    s.cmds({"create_atoms 1 single 0 0 0", "create_atoms 1 single 0.1 0 0", "create_atoms 1 single 0.2 0 0",
            "set type 1 diameter 0.01 density 2000", "velocity all set 0 0 1", "group falling id 1 3",
            "fix g " + groups.gravity + " gravity 9.81 vector 0 0 -1", "fix i " + groups.nve + " nve/sphere",
            "run 1000"});
    const double t = 0.1, g = 9.81;
    for (long long id : {1, 2, 3}) {
      INFO("particle " << id);
      Vec3 x, v;
      state(s.e, id, x, v);
      if (id != 2 || (groups.gravity == "all" && groups.nve == "all")) {  // falls
        CHECK(x[2] == Approx(1.0 * t - 0.5 * g * t * t).epsilon(1e-9));
        CHECK(v[2] == Approx(1.0 - g * t).epsilon(1e-9));
      } else if (groups.nve == "all") {  // moves, without gravity
        CHECK(x[2] == Approx(1.0 * t).epsilon(1e-12));
        CHECK(v[2] == 1.0);
      } else {  // not moved
        CHECK(x[2] == 0.0);
        CHECK(v[2] == 1.0);
      }
    }
  }
}

TEST_CASE("fix gravity: spherical and chute directions, variables, errors", "[fix]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0 0 0", "set atom 1 diameter 0.01 density 2000"});
  const double m = 4.0 / 3.0 * M_PI * 1.25e-7 * 2000;
  auto force_after_setup = [&](const std::string& fix) {
    s.cmd(fix);
    s.cmd("run 0");
    Vec3 f(0, 0, 0);
    const auto& p = *s.e.particles;
    for (int i = 0; i < p.nlocal; ++i)
      f = p.f[i];
    double all[3];
    MPI_Allreduce(f.data(), all, 3, MPI_DOUBLE, MPI_SUM, s.e.world);
    s.cmd("unfix g");
    return Vec3(all[0], all[1], all[2]);
  };
  CHECK(force_after_setup("fix g all gravity 9.81 spherical 0 180").isApprox(Vec3(0, 0, -9.81 * m)));
  CHECK(force_after_setup("fix g all gravity 9.81 spherical 90 90").isApprox(Vec3(0, 9.81 * m, 0)));
  const double a = 30.0 * M_PI / 180.0;
  CHECK(force_after_setup("fix g all gravity 2 chute 30")
            .isApprox(Vec3(2 * m * std::sin(a), 0, -2 * m * std::cos(a))));
  s.cmd("variable gm equal 3.5");
  CHECK(force_after_setup("fix g all gravity v_gm vector 1 0 0").isApprox(Vec3(3.5 * m, 0, 0)));

  CHECK_THROWS_WITH(s.cmd("fix g all gravity 9.81 vector 0 0 0"), Contains("zero"));
  CHECK_THROWS_WITH(s.cmd("fix g all gravity 9.81 vektor 0 0 -1"), Contains("vector"));
  CHECK_THROWS_WITH(s.cmd("fix g all gravity 9.81 vector 0 0"), Contains("usage"));
  CHECK_THROWS_WITH(s.cmd("fix g all gravity v_nothing vector 0 0 -1"), Contains("nothing"));
}

TEST_CASE("fix freeze keeps its particles in place", "[fix]") {
  Sim s;
  s.cmds(kBox);
  s.cmds({"create_atoms 1 single 0 0 0", "create_atoms 2 single 0.1 0 0",
          "set type * diameter 0.01 density 2000", "velocity all set 0.5 0.5 0.5", "set atom 1 omega 1 2 3",
          "group frozen type 1", "fix g all gravity 9.81 vector 0 0 -1", "fix f frozen freeze",
          "fix i all nve/sphere", "run 200"});
  Vec3 x, v;
  state(s.e, 1, x, v);
  CHECK(x == Vec3(0, 0, 0));
  CHECK(v == Vec3(0, 0, 0));
  state(s.e, 2, x, v);
  CHECK(x[0] == Approx(0.1 + 0.5 * 0.02));
  CHECK(v[2] == Approx(0.5 - 9.81 * 0.02));
  const auto& p = *s.e.particles;
  for (int i = 0; i < p.nlocal; ++i)
    if (p.id[i] == 1) CHECK(p.omega[i] == Vec3(0, 0, 0));
  // the force removed from the group: its weight
  const double m = 4.0 / 3.0 * M_PI * 1.25e-7 * 2000;
  CHECK(s.e.fix_value("f", 3) == Approx(-9.81 * m));
  CHECK(s.e.fix_value("f", 1) == 0.0);
  CHECK_THROWS_WITH(s.cmd("fix f2 all freeze now"), Contains("usage"));
}

TEST_CASE("fix viscous: exponential decay at rate gamma / m", "[fix]") {
  Sim s;
  s.cmds(kBox);
  const double m = 4.0 / 3.0 * M_PI * 1.25e-7 * 2000;  // d = 0.01, rho = 2000
  const double tau = 0.01;                             // m / gamma
  const double gamma = m / tau;
  char line[256];
  std::snprintf(line, sizeof line, "fix visc all viscous %.17g scale 2 2.0", gamma);
  s.cmds({"create_atoms 1 single 0 0 0", "create_atoms 2 single 0.1 0 0",
          "set type * diameter 0.01 density 2000", "velocity all set 1 -2 0.5", line, "fix i all nve/sphere",
          "timestep 1e-5", "run 1000"});
  const double t = 0.01;
  Vec3 x, v;
  state(s.e, 1, x, v);
  const double f1 = std::exp(-t / tau);
  CHECK(v[0] == Approx(1.0 * f1).epsilon(0.01));
  CHECK(v[1] == Approx(-2.0 * f1).epsilon(0.01));
  CHECK(v[2] == Approx(0.5 * f1).epsilon(0.01));
  CHECK(x[0] == Approx(tau * (1 - f1)).epsilon(0.01));  // x = v0 tau (1 - exp(-t/tau))
  state(s.e, 2, x, v);                                  // type 2: twice the damping
  const double f2 = std::exp(-2 * t / tau);
  CHECK(v[0] == Approx(1.0 * f2).epsilon(0.01));
  CHECK(v[1] == Approx(-2.0 * f2).epsilon(0.01));

  CHECK_THROWS_WITH(s.cmd("fix v2 all viscous -1"), Contains(">= 0"));
  CHECK_THROWS_WITH(s.cmd("fix v2 all viscous 1 scale 3 2"), Contains("1..2"));
  CHECK_THROWS_WITH(s.cmd("fix v2 all viscous 1 scales 1 2"), Contains("scale"));
}

TEST_CASE("fix property/global: values, lookups and count checks", "[fix]") {
  Sim s;
  s.cmds(kBox);  // 2 atom types
  s.cmds({"fix m1 all property/global youngsModulus peratomtype 5e6 6e6",
          "fix m2 all property/global coefficientRestitution peratomtypepair 2 0.1 0.2 0.3 0.4",
          "fix m3 all property/global characteristicVelocity scalar 2.5",
          "fix m4 all property/global table matrix 3 1 2 3 4 5 6",
          "fix m5 all property/global list vector 7 8 9"});
  using granary::FixPropertyGlobal;
  const auto& modify = *s.e.modify;
  auto* ym = FixPropertyGlobal::find(modify, "youngsModulus");
  REQUIRE(ym != nullptr);
  CHECK(ym->kind == "peratomtype");
  CHECK(ym->per_type(1) == 5e6);
  CHECK(ym->per_type(2) == 6e6);
  auto* e = FixPropertyGlobal::find(modify, "coefficientRestitution");
  CHECK(e->per_pair(1, 2) == 0.2);
  CHECK(e->per_pair(2, 1) == 0.3);
  CHECK(e->per_pair(2, 2) == 0.4);
  auto* table = FixPropertyGlobal::find(modify, "table");
  CHECK(table->ncols == 3);
  CHECK(table->per_pair(2, 1) == 4.0);
  CHECK_THROWS_AS(table->per_pair(3, 1), InputError);
  CHECK(s.e.fix_value("m3", 0) == 2.5);
  CHECK(s.e.fix_value("m5", 2) == 8.0);
  CHECK(s.e.fix_value("m2", 4) == 0.4);
  CHECK(FixPropertyGlobal::find(modify, "poissonsRatio") == nullptr);
  CHECK_THROWS_WITH(FixPropertyGlobal::require(modify, "poissonsRatio", "pair gran"),
                    Contains("fix ID all property/global poissonsRatio peratomtype"));
  CHECK_THROWS_WITH(FixPropertyGlobal::require(modify, "youngModulus", "pair gran"),
                    Contains("youngsModulus"));
  // a later definition of the same property wins
  s.cmd("fix m6 all property/global youngsModulus peratomtype 1e7 1e7");
  CHECK(FixPropertyGlobal::find(modify, "youngsModulus")->per_type(1) == 1e7);

  CHECK_THROWS_WITH(s.cmd("fix b all property/global youngsModulus peratomtype 5e6"),
                    Contains("one value per atom type: 2"));
  CHECK_THROWS_WITH(s.cmd("fix b all property/global youngsModulus peratomtype 5e6 5e6 5e6"),
                    Contains("one value per atom type: 2"));
  CHECK_THROWS_WITH(s.cmd("fix b all property/global coefficientFriction peratomtypepair 2 0.5 0.5 0.5"),
                    Contains("needs 4 values"));
  CHECK_THROWS_WITH(s.cmd("fix b all property/global coefficientFriction peratomtypepair 1 0.5"),
                    Contains("number of atom types, 2"));
  CHECK_THROWS_WITH(s.cmd("fix b all property/global characteristicVelocity scalar 1 2"),
                    Contains("exactly one value"));
  CHECK_THROWS_WITH(s.cmd("fix b all property/global t matrix 2 1 2 3"), Contains("multiple of 2"));
  CHECK_THROWS_WITH(s.cmd("fix b all property/global t peratomtypes 1 2"), Contains("peratomtype"));
  CHECK_THROWS_WITH(s.cmd("fix b all property/global t scalar abc"), Contains("abc"));
  CHECK_THROWS_WITH(s.cmd("fix b all property/global t vector"), Contains("usage"));
}
