// fix multisphere/break on 1, 2 and 4 ranks (run by ctest at each count): a
// spinning dumbbell (two touching spheres) that breaks flies apart as two
// free spheres with the velocities they had (the analytic separation and the
// unchanged centre of mass); trigger_timeStep; a per-atom fix value as the
// trigger; the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "core/engine.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

// A dumbbell of two spheres (radius 0.01, centres 0.02 apart along x) at the
// origin, moving at (0.3, 0.2, 0) m/s and spinning at 10 rad/s about z, no
// gravity, no walls.
void scene(granary::test::ScriptEngine& s, const std::string& fix_line) {
  s.cmds(granary::test::liggghts_head("-0.5 0.5 -0.5 0.5 -0.5 0.5", 1));
  s.cmds({granary::test::materials(1, 5e6, 0.45, 0.5, 0.3), "pair_style gran model hertz tangential history",
          "pair_coeff * *", "timestep 1e-5", "neighbor 0.005 bin",
          "fix dumb all particletemplate/multisphere 15485867 atom_type 1 density constant 2500 nspheres 2 "
          "ntry 1000000 spheres -0.01 0 0 0.01 0.01 0 0 0.01 type 1",
          fix_line, "fix integr all nve/sphere", "create_clump dumb 0 0 0 vel 0.3 0.2 0 omega 0 0 10"});
}

struct Pair {
  Vec3 a, b;
};

Pair spheres(granary::Engine& e) {
  Pair out;
  Vec3 v;
  REQUIRE(granary::test::particle_state(e, 1, out.a, v));
  REQUIRE(granary::test::particle_state(e, 2, out.b, v));
  return out;
}

}  // namespace

TEST_CASE("multisphere/break: a spinning dumbbell that breaks flies apart as two free spheres",
          "[multisphere][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  scene(s,
        "fix ms all multisphere/break allow_group_and_set yes trigger_threshold 500 trigger_name v_step_now");
  s.cmds({"variable step_now atom step", "run 400"});
  // rigid so far: the spheres 0.02 apart, one clump
  Pair p = spheres(s.e);
  CHECK((p.a - p.b).norm() == Approx(0.02).epsilon(1e-9));
  CHECK(s.e.fix_value("ms", 0) == 1.0);
  s.cmd("run 1600");
  CHECK(s.e.fix_value("ms", 0) == 0.0);
  // the trigger (step > 500) fires after step 501; the spheres are free from
  // step 502 on, with v_cm + omega x r: they separate as
  // d(tau) = d0 sqrt(1 + (omega tau)^2) over tau = (2000 - 502) dt
  p = spheres(s.e);
  const double tau = (2000 - 502) * 1e-5, d0 = 0.02, w = 10.0;
  CHECK((p.a - p.b).norm() == Approx(d0 * std::sqrt(1.0 + w * w * tau * tau)).epsilon(1e-6));
  // the midpoint goes on as the centre of mass did (up to the Monte Carlo
  // error of the template's centre of mass and mass shares, ntry 1e6: 2e-7 m)
  const Vec3 com = 0.5 * (p.a + p.b);
  CHECK(com.x() == Approx(0.3 * 2000 * 1e-5).margin(1e-6));
  CHECK(com.y() == Approx(0.2 * 2000 * 1e-5).margin(1e-6));
  CHECK(std::abs(com.z()) < 1e-6);
  CHECK(s.e.particles->natoms == 2);
}

TEST_CASE("multisphere/break: nothing breaks before trigger_timeStep; a fix property/atom as the trigger",
          "[multisphere][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  scene(s, "fix ms all multisphere/break trigger_threshold 1 trigger_timeStep 300 trigger_name f_crack");
  // the trigger is above the threshold from the start: the clump waits for step 300
  s.cmds({"fix crack all property/atom crack scalar yes no no 0", "set atom 2 property/atom crack 2",
          "run 299"});
  CHECK(s.e.fix_value("ms", 0) == 1.0);
  s.cmd("run 3");
  CHECK(s.e.fix_value("ms", 0) == 0.0);
  s.cmd("run 100");
  const Pair p = spheres(s.e);
  CHECK((p.a - p.b).norm() > 0.02 * (1.0 + 1e-6));
}

TEST_CASE("multisphere/break: errors name what is wrong", "[multisphere][mpi]") {
  struct Case {
    std::string fix, expect;
  };
  const std::vector<Case> cases = {
      {"fix ms all multisphere/break trigger_name v_x", "missing 'trigger_threshold X'"},
      {"fix ms all multisphere/break trigger_threshold 1", "missing 'trigger_name"},
      {"fix ms all multisphere/break trigger_threshold 1 trigger_name c_x", "must be a per-atom fix value"},
      {"fix ms all multisphere/break trigger_threshold 1 trigger_name v_x trigger_timeStep -2",
       "trigger_timeStep must be >= 0"},
      {"fix ms all multisphere/break trigger_threshold", "'trigger_threshold' needs a value"},
  };
  for (const auto& c : cases) {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    INFO(c.fix);
    CHECK_THROWS_WITH(scene(s, c.fix), Contains(c.expect));
  }
  {  // the trigger must exist, and be per-atom
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    scene(s, "fix ms all multisphere/break trigger_threshold 1 trigger_name v_none");
    CHECK_THROWS_WITH(s.cmd("run 1"), Contains("no variable 'none'"));
    s.cmd("variable none equal 1");
    CHECK_THROWS_WITH(s.cmd("run 1"), Contains("is not atom-style"));
  }
  {  // one integrator of clumps
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    scene(s, "fix ms all multisphere");
    CHECK_THROWS_WITH(s.cmd("fix ms2 all multisphere/break trigger_threshold 1 trigger_name v_x"),
                      Contains("already integrates the clumps"));
  }
}
