// fix adapt atom diameter: the schedule of changes LIGGGHTS 3.8 follows (at
// the start of every run and every N steps), scale yes against the diameter
// at the start of the run, masses at constant density, contacts of grown
// particles found on any number of ranks, and the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "core/engine.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

struct State {
  double radius = 0, mass = 0;
  granary::Vec3 v{0, 0, 0};
};

/// Radius, mass and velocity of particle `id`, wherever it lives (collective).
State state(granary::Engine& e, long long id) {
  double local[6] = {0, 0, 0, 0, 0, 0}, all[6];
  const auto& p = *e.particles;
  for (int i = 0; i < p.nlocal; ++i) {
    if (p.id[i] != id) continue;
    local[0] = p.radius[i];
    local[1] = p.rmass[i];
    for (int d = 0; d < 3; ++d)
      local[2 + d] = p.v[i][d];
    local[5] = 1;
  }
  MPI_Allreduce(local, all, 6, MPI_DOUBLE, MPI_SUM, e.world);
  REQUIRE(all[5] == 1.0);
  return {all[0], all[1], granary::Vec3(all[2], all[3], all[4])};
}

std::vector<std::string> scene() {
  return {"units si", "atom_style granular", "boundary f f f",
          "region reg block -0.05 0.05 -0.05 0.05 -0.05 0.05 units box", "create_box 1 reg",
          "neighbor 0.002 bin", "fix m1 all property/global youngsModulus peratomtype 5.e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.45",
          "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.7",
          "fix m4 all property/global coefficientFriction peratomtypepair 1 0.05",
          "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 0.00001",
          // one each side of x = 0: on 2 and 4 ranks owned by different ranks
          "create_atoms 1 single -0.0025 0 0 units box", "create_atoms 1 single 0.0025 0 0 units box",
          "create_atoms 1 single 0.03 0.03 0.03 units box", "set atom * diameter 0.004 density 2500",
          "group pair id 1 2", "fix integr all nve/sphere"};
}

}  // namespace

TEST_CASE("fix adapt: diameters at the start of every run and every N steps, as LIGGGHTS 3.8",
          "[adapt][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(scene());
  // LIGGGHTS 3.8 on two spheres of 1 mm radius with this fix (N = 10, x 1.01
  // per change) prints a largest radius of 0.00101 at step 0 and
  // 0.00111566834666532 at step 100: 11 changes, the first at the run's start
  // (here x 1.03 per change)
  s.cmds({"compute rad all property/atom radius", "variable dg atom 1.03*2.*c_rad",
          "fix grow all adapt 10 atom diameter v_dg", "run 100"});
  const double pi = 3.14159265358979323846;
  for (long long id : {1LL, 2LL, 3LL}) {
    const State st = state(s.e, id);
    CHECK(st.radius == Approx(0.002 * std::pow(1.03, 11)).epsilon(1e-13));
    CHECK(st.mass == Approx(4.0 / 3.0 * pi * std::pow(st.radius, 3) * 2500).epsilon(1e-13));
  }
  // the two spheres, 1 mm apart at first, touch from the change at step 70
  // on: they push each other apart, symmetrically, on any number of ranks
  const State a = state(s.e, 1), b = state(s.e, 2);
  CHECK(a.v.x() < -1e-4);
  CHECK(b.v.x() == Approx(-a.v.x()).epsilon(1e-9));
  // a second run changes them again at its start: 3 more changes by step 120
  s.cmd("run 20");
  CHECK(state(s.e, 3).radius == Approx(0.002 * std::pow(1.03, 14)).epsilon(1e-13));
}

TEST_CASE("fix adapt: equal-style variable, scale yes, N = 0", "[adapt][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(scene());
  // scale yes: the value multiplies the diameter at the start of the run, so
  // every change of a run gives the same diameter
  s.cmds({"variable two equal 1.5", "fix grow pair adapt 5 atom diameter v_two scale yes", "run 20"});
  CHECK(state(s.e, 1).radius == Approx(0.003).epsilon(1e-14));
  CHECK(state(s.e, 3).radius == Approx(0.002).epsilon(1e-14));  // outside the group
  s.cmds({"unfix grow", "variable d equal 0.001", "fix set all adapt 0 atom diameter v_d", "run 10"});
  for (long long id : {1LL, 2LL, 3LL})
    CHECK(state(s.e, id).radius == Approx(0.0005).epsilon(1e-14));
}

TEST_CASE("fix adapt: errors leave the diameters unchanged", "[adapt][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(scene());
  s.cmds({"variable neg atom 0.004-2*id*0.001", "fix bad all adapt 1 atom diameter v_neg"});
  CHECK_THROWS_WITH(s.cmd("run 5"), Contains("not positive") && Contains("no diameter was changed"));
  for (long long id : {1LL, 2LL, 3LL})
    CHECK(state(s.e, id).radius == 0.002);
  s.cmd("unfix bad");
  CHECK_THROWS_WITH(s.cmd("fix a all adapt 1 pair soft a * * v_neg"), Contains("'pair' is not supported"));
  CHECK_THROWS_WITH(s.cmd("fix a all adapt 1 atom charge v_neg"), Contains("only diameter"));
  CHECK_THROWS_WITH(s.cmd("fix a all adapt 1 atom diameter v_neg reset yes"),
                    Contains("reset yes is not supported"));
  CHECK_THROWS_WITH(s.cmd("fix a all adapt -1 atom diameter v_neg"), Contains("N must be >= 0"));
  CHECK_THROWS_WITH(s.cmd("fix a all adapt 1 atom diameter 0.003"), Contains("variable v_name"));
  s.cmd("fix a all adapt 1 atom diameter v_nosuch");
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("'nosuch' does not exist"));
}
