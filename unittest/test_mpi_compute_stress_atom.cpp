// compute stress/atom on 1, 2 and 4 ranks (run by ctest at each count):
// LIGGGHTS 3.8's per-atom stress of a resting column of spheres and a thrown
// sphere (unittest/scripts/stress_atom, reference
// unittest/reference/stress_atom.liggghts.txt); the analytic pair virial of
// the column; the kinetic term alone; the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

namespace fs = std::filesystem;
const fs::path kRoot(GRANARY_SOURCE_DIR);

// id -> the six components on every rank (collective).
std::map<long long, std::vector<double>> stress_by_id(granary::Engine& e, const std::string& id) {
  const auto& p = *e.particles;
  std::vector<double> local(7 * static_cast<std::size_t>(p.natoms), 0.0), all(local.size());
  for (int c = 1; c <= 6; ++c) {
    std::vector<double> col;
    e.compute_peratom(id, c, col);
    for (int i = 0; i < p.nlocal; ++i)
      local[7 * static_cast<std::size_t>(p.id[i] - 1) + c] = col[i];
  }
  for (int i = 0; i < p.nlocal; ++i)
    local[7 * static_cast<std::size_t>(p.id[i] - 1)] = static_cast<double>(p.id[i]);
  MPI_Allreduce(local.data(), all.data(), static_cast<int>(all.size()), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  std::map<long long, std::vector<double>> out;
  for (std::size_t k = 0; k < static_cast<std::size_t>(p.natoms); ++k)
    out[static_cast<long long>(all[7 * k])] =
        std::vector<double>(all.begin() + 7 * k + 1, all.begin() + 7 * k + 7);
  return out;
}

}  // namespace

TEST_CASE("compute stress/atom: LIGGGHTS 3.8's stresses of a resting column and a thrown sphere",
          "[stress_atom][mpi][liggghts]") {
  std::ifstream ref(kRoot / "unittest/reference/stress_atom.liggghts.txt");
  std::string line;
  std::map<long long, std::vector<double>> liggghts;
  bool atoms = false;
  while (std::getline(ref, line)) {
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      atoms = true;
      continue;
    }
    if (!atoms) continue;
    std::istringstream in(line);
    long long id;
    std::vector<double> v(12);
    in >> id;
    for (double& x : v)
      in >> x;
    liggghts[id] = std::vector<double>(v.begin() + 6, v.end());
  }
  REQUIRE(liggghts.size() == 4);
  const std::string dir = "stress_atom_np" + std::to_string(granary::test::world_size());
  if (granary::test::world_rank() == 0) fs::create_directories(dir);
  MPI_Barrier(MPI_COMM_WORLD);
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmd("variable out index " + dir);
  s.cmd("include " + (kRoot / "unittest/scripts/stress_atom/in.stress_atom").string());
  const auto mine = stress_by_id(s.e, "s");
  double scale = 0.0;
  for (const auto& kv : liggghts)
    for (double v : kv.second)
      scale = std::max(scale, std::abs(v));
  for (const auto& kv : liggghts)
    for (int c = 0; c < 6; ++c) {
      INFO("particle " << kv.first << ", component " << c + 1);
      // the same contacts and motion to round-off: 1e-7 relative, 1e-9 of
      // the largest value for the near-zero components
      CHECK(mine.at(kv.first)[c] == Approx(kv.second[c]).epsilon(1e-7).margin(1e-9 * scale));
    }
}

TEST_CASE("compute stress/atom: the pair virial of a resting column, and the kinetic term alone",
          "[stress_atom][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  const std::string dir = "stress_atom_b_np" + std::to_string(granary::test::world_size());
  if (granary::test::world_rank() == 0) fs::create_directories(dir);
  MPI_Barrier(MPI_COMM_WORLD);
  s.cmd("variable out index " + dir);
  s.cmd("include " + (kRoot / "unittest/scripts/stress_atom/in.stress_atom").string());
  s.cmds({"compute k all stress/atom ke", "compute w all stress/atom pair bond angle kspace fix", "run 0"});
  const auto total = stress_by_id(s.e, "s"), ke = stress_by_id(s.e, "k"), pair = stress_by_id(s.e, "w");
  granary::Vec3 x[5], v[5];
  for (int id = 1; id <= 4; ++id)
    REQUIRE(granary::test::particle_state(s.e, id, x[id], v[id]));
  // at rest: the top contact carries m g, the lower one 2 m g; each particle
  // gets half of r_ij F_ij of each of its contacts (the floor is a wall: none)
  const double mg = 2500 * 4.0 / 3.0 * M_PI * 1.25e-7 * 9.81;
  const double d23 = x[3].z() - x[2].z(), d12 = x[2].z() - x[1].z();
  CHECK(total.at(3)[2] == Approx(-0.5 * d23 * mg).epsilon(1e-5));
  CHECK(total.at(2)[2] == Approx(-0.5 * d23 * mg - 0.5 * d12 * 2 * mg).epsilon(1e-5));
  CHECK(total.at(1)[2] == Approx(-0.5 * d12 * 2 * mg).epsilon(1e-5));
  // the thrown sphere: -m v_a v_b alone
  const double m = 2500 * 4.0 / 3.0 * M_PI * 1.25e-7;
  CHECK(ke.at(4)[0] == Approx(-m * v[4].x() * v[4].x()).epsilon(1e-12));
  CHECK(ke.at(4)[3] == Approx(-m * v[4].x() * v[4].y()).epsilon(1e-12));
  for (int id = 1; id <= 4; ++id)
    for (int c = 0; c < 6; ++c)
      CHECK(total.at(id)[c] == Approx(ke.at(id)[c] + pair.at(id)[c]).margin(1e-18));
  CHECK_THROWS_WITH(s.cmd("compute bad all stress/atom heat"), Contains("unknown keyword 'heat'"));
}
