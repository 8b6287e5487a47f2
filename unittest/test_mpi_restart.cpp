// A restart written on N ranks reads on any number of ranks (run by ctest at
// 1, 2 and 4 ranks): write on all ranks, read back on one rank (MPI_COMM_SELF)
// and on all ranks, continue, and compare with an uninterrupted run.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "particles/particles.h"
#include "restart_scene.h"
#include "script_engine.h"

namespace {

std::map<long long, std::vector<double>> gather(granary::Engine& e, MPI_Comm comm) {
  const auto& p = *e.particles;
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i) {
    mine.push_back(static_cast<double>(p.id[i]));
    for (const auto* a : {&p.x, &p.v})
      for (int d = 0; d < 3; ++d)
        mine.push_back((*a)[i][d]);
  }
  int nprocs = 1, n = static_cast<int>(mine.size());
  MPI_Comm_size(comm, &nprocs);
  std::vector<int> counts(nprocs), displs(nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < nprocs; ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(displs.back() + counts.back());
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, comm);
  std::map<long long, std::vector<double>> out;
  for (std::size_t k = 0; k < all.size(); k += 7)
    out[static_cast<long long>(all[k])] = std::vector<double>(all.begin() + k + 1, all.begin() + k + 7);
  return out;
}

double worst_relative(const std::map<long long, std::vector<double>>& a,
                      const std::map<long long, std::vector<double>>& b) {
  double worst = 0.0, scale = 0.0;
  for (const auto& kv : a)
    for (double v : kv.second)
      scale = std::max(scale, std::fabs(v));
  for (const auto& kv : a) {
    const auto& other = b.at(kv.first);
    for (std::size_t k = 0; k < kv.second.size(); ++k)
      worst = std::max(worst, std::fabs(kv.second[k] - other[k]) / scale);
  }
  return worst;
}

}  // namespace

TEST_CASE("a restart written on N ranks continues on 1 and on N ranks") {
  int rank = 0, nprocs = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
  const std::string file = "mpi_" + std::to_string(nprocs) + ".restart";

  std::map<long long, std::vector<double>> straight, on_world, on_self, balanced;
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    granary::test::run(e, restart_scene::fresh());
    e.input->one("run 1200");
    straight = gather(e, MPI_COMM_SELF);
  }
  {
    granary::Engine e(MPI_COMM_WORLD);
    e.logger->set_screen(false);
    granary::test::run(e, restart_scene::fresh());
    e.input->one("run 600");
    e.input->one("write_restart " + file);
  }
  std::string grid_said, grid_made;
  {
    granary::Engine e(MPI_COMM_WORLD);
    e.logger->set_screen(false);
    const std::string log = "mpi_" + std::to_string(nprocs) + ".read.log";
    e.logger->open_log(log, false);
    granary::test::run(e, restart_scene::restarted(file));
    e.logger->close_log();
    // read_restart says the grid it made, as LAMMPS does
    if (rank == 0) {
      std::ifstream in(log);
      for (std::string line; std::getline(in, line);)
        if (line.find("MPI processor grid") != std::string::npos) grid_said = line;
      std::remove(log.c_str());
    }
    grid_made = "  " + std::to_string(e.comm->procgrid[0]) + " by " + std::to_string(e.comm->procgrid[1]) +
                " by " + std::to_string(e.comm->procgrid[2]) + " MPI processor grid";
    e.input->one("run 600");
    on_world = gather(e, MPI_COMM_WORLD);
  }
  if (rank == 0) CHECK(grid_said == grid_made);
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    granary::test::run(e, restart_scene::restarted(file));
    e.input->one("run 600");
    on_self = gather(e, MPI_COMM_SELF);
  }
  {
    // the cuts move before the first run: particles change ranks while their
    // contact history still waits in the restart's store
    granary::Engine e(MPI_COMM_WORLD);
    e.logger->set_screen(false);
    granary::test::run(e, restart_scene::restarted(file));
    // each split dimension's cuts squeezed towards its low end
    std::string cmd = "balance 1.0";
    for (int d = 0; d < 3; ++d) {
      const int np = e.comm->procgrid[d];
      if (np < 2) continue;
      cmd += std::string(" ") + "xyz"[d];
      for (int k = 1; k < np; ++k)
        cmd += " " + std::to_string(0.7 * k / np);
    }
    if (nprocs > 1) e.input->one(cmd);
    e.input->one("run 600");
    balanced = gather(e, MPI_COMM_WORLD);
  }
  REQUIRE(straight.size() > 400);
  REQUIRE(on_world.size() == straight.size());
  REQUIRE(on_self.size() == straight.size());
  REQUIRE(balanced.size() == straight.size());
  const double d_world = worst_relative(straight, on_world), d_self = worst_relative(straight, on_self);
  const double d_balanced = worst_relative(straight, balanced);
  INFO("largest relative difference: read on " << nprocs << " rank(s) " << d_world << ", on 1 rank "
                                               << d_self);
  CHECK(d_world < 1e-10);
  CHECK(d_self < 1e-10);
  INFO("read on " << nprocs << " rank(s) with moved cuts: " << d_balanced);
  CHECK(d_balanced < 1e-10);
  if (nprocs == 1) CHECK(d_self == 0.0);
}
