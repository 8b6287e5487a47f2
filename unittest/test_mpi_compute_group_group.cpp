// compute group/group on 1, 2 and 4 ranks (run by ctest at each count): in a
// column of three spheres at rest on a floor each contact carries the weight
// above it; the force of one group on another is that weight, with the sign
// of which group is pushed; the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "core/engine.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

TEST_CASE("compute group/group: the weight above each contact of a resting column", "[group_group][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(granary::test::liggghts_head("-0.05 0.05 -0.05 0.05 0 0.1", 1));
  s.cmds({granary::test::materials(1, 5e6, 0.45, 0.3, 0.5), "pair_style gran model hertz tangential history",
          "pair_coeff * *", "timestep 1e-5", "neighbor 0.002 bin",
          "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0",
          // three spheres of 10 mm on top of each other, on the cut between ranks
          "create_atoms 1 single 0 0 0.005 units box", "create_atoms 1 single 0 0 0.015 units box",
          "create_atoms 1 single 0 0 0.025 units box", "set group all diameter 0.01 density 2500",
          "group bottom id 1", "group middle id 2", "group top id 3", "group upper id 2 3",
          "fix grav all gravity 9.81 vector 0 0 -1", "fix integr all nve/sphere",
          "compute tm top group/group middle", "compute mt middle group/group top",
          "compute ub upper group/group bottom pair yes kspace no boundary yes molecule off",
          "compute aa all group/group all", "compute tb top group/group bottom", "run 60000"});
  const double mg = 2500 * 4.0 / 3.0 * M_PI * 1.25e-7 * 9.81;
  // at rest: the middle sphere carries the top one, the bottom one both
  CHECK(s.e.compute_value("tm", 3) == Approx(mg).epsilon(1e-6));
  CHECK(s.e.compute_value("mt", 3) == Approx(-mg).epsilon(1e-6));
  CHECK(s.e.compute_value("ub", 3) == Approx(2 * mg).epsilon(1e-6));
  CHECK(std::abs(s.e.compute_value("tm", 1)) < 1e-9 * mg);
  CHECK(std::abs(s.e.compute_value("aa", 3)) < 1e-12 * mg);  // every contact both ways
  CHECK(s.e.compute_value("tb", 3) == 0.0);                  // no contact between them
}

TEST_CASE("compute group/group: errors name what is wrong", "[group_group][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(granary::test::liggghts_head("-0.05 0.05 -0.05 0.05 0 0.1", 1));
  struct Case {
    std::string args, expect;
  };
  const std::vector<Case> cases = {
      {"all group/group", "needs the second group"},
      {"all group/group nobody", "nobody"},
      {"all group/group all pair no", "pair no leaves nothing to sum"},
      {"all group/group all kspace yes", "no long-range forces"},
      {"all group/group all molecule inter", "no molecules"},
      {"all group/group all colour red", "unknown keyword 'colour'"},
  };
  for (const auto& c : cases) {
    INFO(c.args);
    CHECK_THROWS_WITH(s.cmd("compute gg " + c.args), Contains(c.expect));
  }
  // a granular pair style is needed when it computes
  s.cmd("compute gg all group/group all");
  CHECK_THROWS_WITH(s.e.compute_value("gg", 1), Contains("granular pair style"));
}
