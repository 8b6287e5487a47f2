// compute rdf and fix ave/time mode vector on 1, 2 and 4 ranks (run by ctest
// at each count): LIGGGHTS 3.8's rdf.txt of 400 spheres of two sizes in a
// periodic cube (unittest/scripts/rdf, reference
// unittest/reference/rdf.liggghts.txt); the coordination number against a
// direct count of the pairs; averages over several samples; the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/modify.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

namespace fs = std::filesystem;
const fs::path kRoot(GRANARY_SOURCE_DIR);

// The rows of the last block of a mode-vector ave/time file.
std::vector<std::vector<double>> last_block(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::vector<double>> rows;
  long expect = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::vector<double> v;
    double x;
    while (ls >> x)
      v.push_back(x);
    if (expect == 0) {  // "step rows"
      REQUIRE(v.size() == 2);
      expect = static_cast<long>(v[1]);
      rows.clear();
    } else {
      rows.push_back(v);
      --expect;
    }
  }
  return rows;
}

void run_script(granary::test::ScriptEngine& s, const std::string& dir) {
  s.cmd("variable out index " + dir);
  s.cmd("variable datadir index " + (kRoot / "unittest/scripts/rdf").string());
  s.cmd("include " + (kRoot / "unittest/scripts/rdf/in.rdf").string());
}

}  // namespace

TEST_CASE("compute rdf with fix ave/time mode vector: LIGGGHTS 3.8's g(r) and coordination numbers",
          "[rdf][mpi][liggghts]") {
  const auto ref = last_block(kRoot / "unittest/reference/rdf.liggghts.txt");
  REQUIRE(ref.size() == 40);
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  const std::string dir = granary::test::rank_count_dir("rdf");
  run_script(s, fs::absolute(dir).string());
  MPI_Barrier(MPI_COMM_WORLD);
  const auto mine = last_block(fs::path(dir) / "rdf.txt");
  REQUIRE(mine.size() == 40);
  for (std::size_t r = 0; r < 40; ++r) {
    REQUIRE(mine[r].size() == 10);
    for (std::size_t c = 0; c < 10; ++c) {
      INFO("row " << r + 1 << ", column " << c);
      // both print %g (6 significant digits)
      CHECK(mine[r][c] == Approx(ref[r][c]).epsilon(2e-6).margin(1e-12));
    }
  }
  // the coordination number at the cutoff: the pairs closer than 2 rmax, counted directly
  granary::Compute* c = s.e.modify->find_compute("r");
  REQUIRE(c != nullptr);
  REQUIRE(c->size_array_rows == 40);
  REQUIRE(c->size_array_cols == 3);
  const auto& p = *s.e.particles;
  std::vector<double> x(3 * 400, 0.0);
  for (int i = 0; i < p.nlocal; ++i)
    for (int d = 0; d < 3; ++d)
      x[3 * (p.id[i] - 1) + d] = p.x[i][d];
  MPI_Allreduce(MPI_IN_PLACE, x.data(), 1200, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  const double L = 0.01, cut = 0.002;
  long pairs = 0;
  for (int i = 0; i < 400; ++i)
    for (int j = 0; j < 400; ++j) {
      if (i == j) continue;
      double r2 = 0.0;
      for (int d = 0; d < 3; ++d) {
        double dx = x[3 * i + d] - x[3 * j + d];
        dx -= L * std::round(dx / L);  // periodic
        r2 += dx * dx;
      }
      pairs += r2 < cut * cut;
    }
  CHECK(c->array[39 * 3 + 2] == Approx(pairs / 400.0).epsilon(1e-12));
  CHECK(pairs > 1000);
}

TEST_CASE("fix ave/time mode vector averages over samples; errors", "[rdf][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  const std::string dir = granary::test::rank_count_dir("rdf_b");
  run_script(s, fs::absolute(dir).string());
  // three samples of the same (motionless: no integrator) particles average to one
  s.cmds(
      {"fix b all ave/time 2 3 6 c_rp[2] c_rp[3] mode vector ave running file " + dir + "/b.txt", "run 12"});
  MPI_Barrier(MPI_COMM_WORLD);
  const auto one = last_block(fs::path(dir) / "rdf.txt");
  const auto avg = last_block(fs::path(dir) / "b.txt");
  REQUIRE(avg.size() == 40);
  for (std::size_t r = 0; r < 40; ++r) {
    CHECK(avg[r][0] == r + 1);
    CHECK(avg[r][1] == Approx(one[r][4]).epsilon(1e-6));
    CHECK(avg[r][2] == Approx(one[r][5]).epsilon(1e-6));
  }
  CHECK_THROWS_WITH(s.cmd("compute bad all rdf 40 1"), Contains("come in pairs"));
  CHECK_THROWS_WITH(s.cmd("compute bad all rdf 0"), Contains("Nbin must be at least 1"));
  s.cmd("variable one equal 1");
  CHECK_THROWS_WITH(s.cmd("fix bad all ave/time 1 1 1 v_one mode vector"), Contains("is a variable"));
  s.cmd("fix bad all ave/time 1 1 1 c_r[4] mode vector");
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("gives no global array with 4 columns"));
}
