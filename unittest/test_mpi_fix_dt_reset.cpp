// fix dt/reset on 1, 2 and 4 ranks (run by ctest at each count): the
// timestep that bounds the step's displacement by XMAX, taken over all
// ranks; the trajectory of a falling and a thrown sphere stays exact in the
// simulated time; TMIN and TMAX; the scalar; the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/update.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

// Sphere 1 at rest at (-0.5, 0, 0.5), sphere 2 thrown at 2 m/s along x from
// (0.5, 0, 0.5) (other ranks' subdomains), both falling under gravity.
void scene(granary::test::ScriptEngine& s) {
  s.cmds(granary::test::liggghts_head("-1 1 -1 1 -1 1", 1));
  s.cmds({granary::test::materials(1, 5e6, 0.45, 0.5, 0.3), "pair_style gran model hertz tangential history",
          "pair_coeff * *", "timestep 1e-5", "neighbor 0.01 bin",
          "create_atoms 1 single -0.5 0 0.5 units box", "create_atoms 1 single 0.5 0 0.5 units box",
          "set group all diameter 0.01 density 2500", "set atom 2 vx 2.0",
          "fix grav all gravity 9.81 vector 0 0 -1", "fix integr all nve/sphere"});
}

double bound_dt(double v, double a, double x) {
  return 2.0 * x / (v + std::sqrt(v * v + 2.0 * a * x));
}

}  // namespace

TEST_CASE("fix dt/reset: the timestep of the fastest particle, and exact free flight in the simulated time",
          "[dt_reset][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  scene(s);
  const double xmax = 1e-4, g = 9.81;
  s.cmds({"fix dt all dt/reset 1 NULL NULL 1e-4 units box", "run 2000"});
  const double t = s.e.update->time();
  Vec3 x1, v1, x2, v2;
  REQUIRE(granary::test::particle_state(s.e, 1, x1, v1));
  REQUIRE(granary::test::particle_state(s.e, 2, x2, v2));
  // velocity Verlet is exact for a constant force, whatever the timesteps
  CHECK(x1.z() == Approx(0.5 - 0.5 * g * t * t).epsilon(1e-12));
  CHECK(x2.x() == Approx(0.5 + 2.0 * t).epsilon(1e-12));
  CHECK(x2.z() == Approx(x1.z()).epsilon(1e-12));
  // the last reset: the bound of the faster sphere, from the present velocities
  CHECK(s.e.update->dt == Approx(bound_dt(v2.norm(), g, xmax)).epsilon(1e-14));
  CHECK(s.e.update->dt < bound_dt(v1.norm(), g, xmax));
  // the first step's timestep: from the thrown sphere at 2 m/s (about 5e-5 s)
  CHECK(t > 2000 * 0.9 * bound_dt(2.0 + g * t, g, xmax));
  CHECK(t < 2000 * bound_dt(2.0, g, xmax));
  CHECK(s.e.fix_value("dt", 0) == 2000.0);  // changed at every step (the speed grows)
}

TEST_CASE("fix dt/reset: TMIN and TMAX bound the timestep; every N steps", "[dt_reset][mpi]") {
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    scene(s);
    s.cmds({"fix dt all dt/reset 10 NULL 2e-5 1e-4 units box", "run 25"});
    CHECK(s.e.update->dt == 2e-5);
    CHECK(s.e.fix_value("dt", 0) == 10.0);  // set at step 10, the same since
    // 10 steps of 1e-5, then 15 of 2e-5
    CHECK(s.e.update->time() == Approx(10 * 1e-5 + 15 * 2e-5).epsilon(1e-12));
  }
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    scene(s);
    s.cmds({"fix dt all dt/reset 1 1e-3 NULL 1e-4 units box", "run 3"});
    CHECK(s.e.update->dt == 1e-3);
  }
  {  // lattice units: XMAX in lattice spacings
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    scene(s);
    s.cmds({"lattice sc 0.01", "fix dt all dt/reset 1 NULL NULL 0.01", "run 1"});
    Vec3 x, v;
    REQUIRE(granary::test::particle_state(s.e, 2, x, v));
    CHECK(s.e.update->dt == Approx(bound_dt(v.norm(), 9.81, 1e-4)).epsilon(1e-14));
  }
}

TEST_CASE("fix dt/reset: errors name what is wrong", "[dt_reset][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  scene(s);
  struct Case {
    std::string args, expect;
  };
  const std::vector<Case> cases = {
      {"1 NULL NULL", "wrong number of arguments"},
      {"0 NULL NULL 1e-4 units box", "N must be >= 1"},
      {"1 -1 NULL 1e-4 units box", "TMIN must be positive or NULL"},
      {"1 1e-3 1e-4 1e-4 units box", "TMIN 1e-3 is larger than TMAX 1e-4"},
      {"1 NULL NULL 0 units box", "XMAX must be positive"},
      {"1 NULL NULL 1e-4", "no lattice is defined; add 'units box'"},
      {"1 NULL NULL 1e-4 units cubits", "units must be box or lattice"},
      {"1 NULL NULL 1e-4 emax 1", "unknown keyword 'emax'"},
  };
  for (const auto& c : cases) {
    INFO(c.args);
    CHECK_THROWS_WITH(s.cmd("fix dt all dt/reset " + c.args), Contains(c.expect));
  }
}
