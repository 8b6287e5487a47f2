// fix clog-detect gives the same counts and avalanche log on any number of
// ranks. Run by ctest at 1, 2 and 4 ranks: every rank first runs the scene
// alone (MPI_COMM_SELF) as the reference, then all ranks run it together.
// Bodies fall freely (no contacts, so the trajectories are the same to the
// bit on any decomposition) across subdomain boundaries in two bursts: free
// spheres (type 2) and dumbbell clumps (type 1), removed as they pass.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "fix/fix_multisphere.h"
#include "core/modify.h"
#include "particles/particles.h"
#include "clog_scene.h"
#include "script_engine.h"

namespace {

std::vector<std::string> scene(const std::string& file) {
  std::vector<std::string> s = clog_scene::dumbbell_box(0.07);
  clog_scene::append(s, {"create_clump dumb 0.01 0.01 0.0 quat 0.9 0.1 0.3 0.2",
                         "create_clump dumb 0.0099 0.002 0.04 quat 0.7 0.5 0.1 0.3"});
  for (int k = 0; k < 6; ++k)
    s.push_back("create_atoms 2 single " + std::to_string(0.003 + 0.003 * k) + " 0.005 " +
                std::to_string(-0.006 + 0.0002 * k) + " units box");
  for (int k = 0; k < 4; ++k)
    s.push_back("create_atoms 2 single " + std::to_string(0.004 + 0.004 * k) + " 0.015 0.06 units box");
  s.push_back("group free type 2");
  s.push_back("set type 2 diameter 0.002 density 2500");
  s.push_back("fix integr free nve/sphere");
  s.push_back("region out block 0 0.02 0 0.02 -0.02 -0.01 units box");
  s.push_back("fix clog all clog-detect outlet out timeout 0.035 action none file " + file);
  s.push_back("run 3400");
  return s;
}

struct Result {
  std::vector<std::string> rows;
  std::vector<double> values;
  long long natoms = 0;
  int bodies = 0;
};

Result run(MPI_Comm comm, const std::string& file) {
  granary::test::ScriptEngine s(comm);
  s.cmds(scene(file));
  Result r;
  for (int i = 0; i <= 12; ++i)
    r.values.push_back(s.e.fix_value("clog", i));
  r.natoms = s.e.particles->natoms;
  r.bodies = dynamic_cast<granary::FixMultisphere*>(s.e.clumps)->bodies().size();
  MPI_Barrier(comm);
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#') r.rows.push_back(line);
  return r;
}

}  // namespace

TEST_CASE("clog-detect: the same counts and avalanche log on any number of ranks") {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const std::string dir = std::filesystem::temp_directory_path().string();
  const std::string self = dir + "/clog_mpi_self_" + std::to_string(::getpid()) + ".csv";
  // one name for the world run, chosen by rank 0
  char world[512] = {0};
  if (rank == 0) std::snprintf(world, sizeof world, "%s/clog_mpi_world_%d.csv", dir.c_str(), ::getpid());
  MPI_Bcast(world, sizeof world, MPI_CHAR, 0, MPI_COMM_WORLD);
  const Result ref = run(MPI_COMM_SELF, self);
  const Result all = run(MPI_COMM_WORLD, world);
  // 2 clumps and 10 spheres passed: a clump in each burst
  REQUIRE(ref.rows.size() == 3);  // header + 2 avalanches
  CHECK(ref.values[5] == 12);
  CHECK(ref.natoms == 0);
  CHECK(ref.bodies == 0);
  CHECK(all.rows == ref.rows);
  CHECK(all.values == ref.values);
  CHECK(all.natoms == ref.natoms);
  CHECK(all.bodies == ref.bodies);
  std::remove(self.c_str());
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank == 0) std::remove(world);
}
