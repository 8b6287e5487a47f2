// fix store/state on particles in free fall, on any number of ranks:
// attributes stored when the fix is defined and never again with N = 0, a
// velocity stored every N steps, a per-atom compute stored at the start of the
// first run, positions relative to the centre of mass with com yes, zeros
// outside the group, and the stored values kept across a restart under the
// same ID.
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

namespace {

constexpr double kG = 9.81, kDt = 1e-4;

std::vector<std::string> scene() {
  std::vector<std::string> s = {"units si", "atom_style granular", "boundary f f f",
                                "region reg block -1 1 -1 1 -1 1 units box", "create_box 1 reg"};
  const std::vector<std::string> rest = {"create_atoms 1 single -0.5 0.1 0.2 units box",
                                         "create_atoms 1 single 0.5 -0.3 0.4 units box",
                                         "create_atoms 1 single 0.1 0.6 -0.2 units box",
                                         "set atom * diameter 0.01 density 2000",
                                         granary::test::materials(1, 5e6, 0.3, 0.9, 0.3),
                                         "pair_style gran model hertz tangential history",
                                         "pair_coeff * *",
                                         "timestep 1e-4",
                                         "group two id 1 2",
                                         "velocity all set 0.3 0 0.5 units box",
                                         "fix gravi all gravity 9.81 vector 0 0 -1",
                                         "fix integr all nve/sphere"};
  s.insert(s.end(), rest.begin(), rest.end());
  return s;
}

/// f_ID (col 0) or f_ID[col] by particle id (index id - 1), from every rank.
std::vector<double> stored(granary::Engine& e, const std::string& fix, int col) {
  std::vector<double> local;
  e.fix_peratom(fix, col, local);
  std::vector<double> mine(3, 0.0), all(3, 0.0);
  for (int i = 0; i < e.particles->nlocal; ++i)
    mine[e.particles->id[i] - 1] = local[i];
  MPI_Allreduce(mine.data(), all.data(), 3, MPI_DOUBLE, MPI_SUM, e.world);
  return all;
}

}  // namespace

TEST_CASE("store/state keeps attributes, samples every N steps and stores computes at the first run",
          "[fix][mpi][store_state]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(scene());
  s.cmds({"fix s two store/state 0 x z", "fix v all store/state 100 vz", "compute k all ke/atom",
          "fix kk all store/state 0 c_k", "fix c all store/state 0 xu yu zu com yes", "run 250"});
  const std::vector<double> x = stored(s.e, "s", 1), z = stored(s.e, "s", 2);
  CHECK(x == std::vector<double>{-0.5, 0.5, 0.0});  // particle 3 is outside the group
  CHECK(z == std::vector<double>{0.2, 0.4, 0.0});   // never updated (N = 0)
  const std::vector<double> vz = stored(s.e, "v", 0);
  for (double v : vz)
    CHECK(v == Approx(0.5 - kG * 200 * kDt).epsilon(1e-12));  // stored at step 200
  const double m = 2000 * 4.0 / 3.0 * 3.14159265358979323846 * 1.25e-7;
  for (double k : stored(s.e, "kk", 0))
    CHECK(k == Approx(0.5 * m * (0.09 + 0.25)).epsilon(1e-12));  // at the start of the run
  // com yes: positions relative to the centre (0.0333.., 0.1333.., 0.1333..)
  CHECK(stored(s.e, "c", 1)[0] == Approx(-0.5 - 0.1 / 3).epsilon(1e-12));
  CHECK(stored(s.e, "c", 3)[2] == Approx(-0.2 - 0.4 / 3).epsilon(1e-12));
  CHECK_THROWS_WITH(s.cmd("fix bad all store/state 0 xx"), Contains("unknown input 'xx'"));
  CHECK_THROWS_WITH(s.cmd("fix bad all store/state -1 x"), Contains("N must be 0"));
  std::vector<double> out;
  CHECK_THROWS_WITH(s.e.fix_peratom("s", 3, out), Contains("column 3 of f_s is out of range"));
}

TEST_CASE("store/state keeps its values across a restart under the same ID",
          "[fix][mpi][store_state][restart]") {
  const std::string dir = granary::test::shared_temp_dir("granary_store_");
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(scene());
    s.cmds({"fix s all store/state 0 z vz", "run 100", "write_restart " + dir + "/s.restart"});
  }
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"read_restart " + dir + "/s.restart", "fix s all store/state 0 z vz",
          "fix fresh all store/state 0 vz"});
  CHECK(stored(s.e, "s", 1) == std::vector<double>{0.2, 0.4, -0.2});
  CHECK(stored(s.e, "s", 2) == std::vector<double>{0.5, 0.5, 0.5});
  for (double v : stored(s.e, "fresh", 0))
    CHECK(v == Approx(0.5 - kG * 100 * kDt).epsilon(1e-12));  // stored from the restart's state
  MPI_Barrier(MPI_COMM_WORLD);
  if (granary::test::world_rank() == 0) std::filesystem::remove_all(dir);
}
