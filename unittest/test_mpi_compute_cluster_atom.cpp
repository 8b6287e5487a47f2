// compute cluster/atom against LIGGGHTS 3.8 (unittest/scripts/cluster_atom,
// reference unittest/reference/cluster_atom.liggghts.dump): 240 spheres at
// random points of a box periodic in x, clusters of a group at a cutoff of
// 1.6 mm (clusters that cross the periodic boundary and the subdomain
// boundaries); every label must equal LIGGGHTS', on 1, 2 and 4 ranks. Then
// chains on a line: a chain of n spheres spaced below the cutoff is one
// cluster labelled with its smallest id, however many ranks it crosses.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "core/engine.h"
#include "core/input.h"
#include "core/modify.h"
#include "compute/compute.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

namespace fs = std::filesystem;
const fs::path kDir = fs::path(GRANARY_SOURCE_DIR) / "unittest/scripts/cluster_atom";

std::map<long, double> labels(const fs::path& file) {
  std::ifstream in(file);
  REQUIRE(in.good());
  std::map<long, double> out;
  std::string line;
  bool atoms = false;
  while (std::getline(in, line)) {
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      atoms = true;
      continue;
    }
    if (!atoms) continue;
    std::istringstream ls(line);
    long id;
    int type;
    double x, y, z, c;
    if (ls >> id >> type >> x >> y >> z >> c) out[id] = c;
  }
  return out;
}

}  // namespace

TEST_CASE("compute cluster/atom: the clusters of random spheres equal LIGGGHTS 3.8's",
          "[compute][mpi][liggghts]") {
  int nprocs = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
  const std::string prog = "granary_np" + std::to_string(nprocs);
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmd("variable prog index " + prog);
    s.cmd("variable dir index " + kDir.string());
    s.e.input->file((kDir / "in.cluster_atom").string());
  }
  MPI_Barrier(MPI_COMM_WORLD);
  const auto mine = labels("dump.cluster." + prog);
  const auto ref = labels(fs::path(GRANARY_SOURCE_DIR) / "unittest/reference/cluster_atom.liggghts.dump");
  REQUIRE(ref.size() == 240);
  REQUIRE(mine.size() == ref.size());
  int clusters = 0, outside = 0;
  for (const auto& [id, c] : ref) {
    INFO("particle " << id);
    CHECK(mine.at(id) == c);
    if (c == static_cast<double>(id)) ++clusters;
    if (c == 0.0) ++outside;
  }
  CHECK(outside > 0);
  CHECK(clusters > 10);
}

TEST_CASE("compute cluster/atom: a chain across the ranks is one cluster with its smallest id",
          "[compute][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"atom_style granular", "atom_modify map array", "boundary f f f", "newton off",
          "communicate single vel yes", "units si", "region b block 0 0.04 0 0.01 0 0.01 units box",
          "create_box 1 b", "neighbor 0.0005 bin", granary::test::materials(1, 5e6, 0.45, 0.5, 0.5),
          "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 1e-6"});
  // two chains along x: ids 1-15 spaced 1.0 mm (below the cutoff 1.1 mm), then
  // a gap of 2 mm, ids 16-25 spaced 1.0 mm; a lone sphere 26 far off
  for (int k = 0; k < 15; ++k)
    s.cmd("create_atoms 1 single " + std::to_string(0.001 + 0.001 * k) + " 0.005 0.005 units box");
  for (int k = 0; k < 10; ++k)
    s.cmd("create_atoms 1 single " + std::to_string(0.017 + 0.001 * k) + " 0.005 0.005 units box");
  s.cmd("create_atoms 1 single 0.035 0.008 0.008 units box");
  s.cmds({"set group all diameter 0.0011 density 2500", "group odd id 1 3 5 7 9 11 13 15 17 19 21 23 25",
          "compute all_c all cluster/atom 0.0011", "compute odd_c odd cluster/atom 0.0011", "run 0"});
  granary::Compute* all_c = s.e.modify->find_compute("all_c");
  granary::Compute* odd_c = s.e.modify->find_compute("odd_c");
  REQUIRE(all_c != nullptr);
  REQUIRE(odd_c != nullptr);
  all_c->compute_peratom();
  odd_c->compute_peratom();
  const auto& p = s.p();
  for (int i = 0; i < p.nlocal; ++i) {
    const long id = static_cast<long>(p.id[i]);
    INFO("particle " << id);
    CHECK(all_c->vector_atom[i] == (id <= 15 ? 1.0 : id <= 25 ? 16.0 : 26.0));
    // in group odd the spheres are 2 mm apart: each is a cluster of its own, the others 0
    CHECK(odd_c->vector_atom[i] == (id % 2 == 1 ? static_cast<double>(id) : 0.0));
  }
}
