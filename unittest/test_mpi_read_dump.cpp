// read_dump against LIGGGHTS 3.8 (unittest/scripts/read_dump/in.read_dump,
// references unittest/reference/read_dump_*.liggghts.dump): 100 spheres, then
// one snapshot with ids in and not in the system, positions across the
// periodic boundary, image flags, unscaled (step 500) and scaled (step 1000)
// coordinates, read with box no, trim yes, add yes and purge yes replace no
// add yes. The particles written afterwards (ids, types, positions, radii,
// velocities, image flags, the box) must equal LIGGGHTS' to the 12 printed
// digits (1e-15 absolute for zeros), on 1, 2 and 4 ranks. Then the file checks:
// truncated and malformed snapshots are refused and change nothing.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/update.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
const fs::path kDir = fs::path(GRANARY_SOURCE_DIR) / "unittest/scripts/read_dump";

int world_size() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

struct Dump {
  std::vector<double> box;
  std::vector<std::vector<double>> rows;
  long step = -1;
};

Dump read(const fs::path& file) {
  std::ifstream in(file);
  REQUIRE(in.good());
  Dump d;
  std::string line;
  while (std::getline(in, line)) {
    if (line == "ITEM: TIMESTEP") {
      std::getline(in, line);
      d.step = std::stol(line);
    } else if (line.rfind("ITEM: BOX BOUNDS", 0) == 0) {
      for (int k = 0; k < 3; ++k) {
        std::getline(in, line);
        std::istringstream ls(line);
        double lo, hi;
        ls >> lo >> hi;
        d.box.push_back(lo);
        d.box.push_back(hi);
      }
    } else if (line.rfind("ITEM: ATOMS", 0) == 0) {
      while (std::getline(in, line)) {
        std::istringstream ls(line);
        std::vector<double> r;
        double v;
        while (ls >> v)
          r.push_back(v);
        if (!r.empty()) d.rows.push_back(r);
      }
    }
  }
  return d;
}

void run_case(const std::string& name, const std::string& nstep, const std::string& opts) {
  const std::string prog = "granary_" + name + "_np" + std::to_string(world_size());
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmd("variable prog index " + prog);
    s.cmd("variable nstep index " + nstep);
    s.cmd("variable opts index \"" + opts + "\"");
    s.cmd("variable dir index " + kDir.string());
    s.e.input->file((kDir / "in.read_dump").string());
  }
  MPI_Barrier(MPI_COMM_WORLD);
  const Dump mine = read("dump.out." + prog);
  const Dump ref =
      read(fs::path(GRANARY_SOURCE_DIR) / ("unittest/reference/read_dump_" + name + ".liggghts.dump"));
  CHECK(mine.step == ref.step);
  REQUIRE(mine.box.size() == 6);
  REQUIRE(ref.box.size() == 6);
  for (int k = 0; k < 6; ++k)
    CHECK(mine.box[k] == Approx(ref.box[k]).margin(1e-15));
  REQUIRE(mine.rows.size() == ref.rows.size());
  double worst = 0.0;
  for (std::size_t r = 0; r < ref.rows.size(); ++r) {
    REQUIRE(mine.rows[r].size() == 12);
    REQUIRE(ref.rows[r].size() == 12);
    for (int c = 0; c < 12; ++c) {
      const double a = mine.rows[r][c], b = ref.rows[r][c];
      INFO(name << ": row " << r << " column " << c << ": Granary " << a << ", LIGGGHTS " << b);
      CHECK(std::fabs(a - b) <= 1e-11 * std::fabs(b) + 1e-15);
      worst = std::max(worst, std::fabs(a - b));
    }
  }
  if (granary::test::world_rank() == 0)
    std::printf("read_dump %s: %zu particles, largest difference from LIGGGHTS %.3g\n", name.c_str(),
                ref.rows.size(), worst);
}

}  // namespace

TEST_CASE("read_dump: replace (box no) matches LIGGGHTS 3.8", "[read_dump][mpi][liggghts]") {
  run_case("boxno", "500", "box no");
}

TEST_CASE("read_dump: trim yes with the snapshot's box matches LIGGGHTS 3.8", "[read_dump][mpi][liggghts]") {
  run_case("trim", "500", "trim yes");
}

TEST_CASE("read_dump: add yes from scaled coordinates matches LIGGGHTS 3.8", "[read_dump][mpi][liggghts]") {
  run_case("add", "1000", "add yes");
}

TEST_CASE("read_dump: purge yes replace no add yes matches LIGGGHTS 3.8", "[read_dump][mpi][liggghts]") {
  run_case("purge", "1000", "purge yes replace no add yes");
}

TEST_CASE("read_dump: bad files and arguments are refused and change nothing", "[read_dump][mpi]") {
  const std::string bad = "read_dump_bad_np" + std::to_string(world_size()) + ".txt";
  auto write = [&](const std::string& text) {
    if (granary::test::world_rank() == 0) std::ofstream(bad) << text;
    MPI_Barrier(MPI_COMM_WORLD);
  };
  const std::string head =
      "ITEM: TIMESTEP\n7\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\nITEM: ATOMS id "
      "type x y z\n";
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"atom_style granular", "boundary f f f", "units si",
          "region b block 0 0.01 0 0.01 0 0.01 units box", "create_box 1 b",
          "create_atoms 1 single 0.005 0.005 0.005 units box", "set atom 1 diameter 0.001 density 2500"});
  struct Case {
    std::string file, args, expect;
  };
  const std::vector<Case> cases = {
      {head + "1 1 0.5 0.5 0.5\n", "7 x y z", "ends after 1 of 2 atoms (truncated file)"},
      {head + "1 1 0.5 0.5 0.5\n2 1 0.5 0.5\n", "7 x y z", "fewer than the 5 columns"},
      {head + "1 1 0.5 0.5 0.5\n2 1 0.5 0.5 0.5 9\n", "7 x y z", "more than the 5 columns"},
      {head + "1 1 0.5 0.5 0.5\n1 1 0.5 0.5 0.5\n", "7 x y z", "holds atom id 1 twice"},
      {head + "1 1 0.5 0.5 0.5\n2 1 0.5 nan 0.5\n", "7 x y z", "is not a finite number"},
      {head + "1 1 0.5 0.5 0.5\n2 1 0.5 0.5 0.5\n", "8 x y z", "has no snapshot of step 8"},
      {head + "1 1 0.5 0.5 0.5\n2 1 0.5 0.5 0.5\n", "7 x y z radius", "no column for field radius"},
      {head + "1 1 0.5 0.5 0.5\n2 3 0.5 0.5 0.5\n", "7 x y z add yes", "atom type 3"},
      {head + "1 1 0.5 0.5 0.5\n2 1 0.5 0.5 0.5\n", "7 x y z q", "carry no charge"},
      {head + "1 1 0.5 0.5 0.5\n2 1 0.5 0.5 0.5\n", "7 x y z format xyz", "add 'box no'"},
      {head + "1 1 0.5 0.5 0.5\n2 1 0.5 0.5 0.5\n", "7 x y z format native box no",
       "must be the last keyword"},
      {head + "1 1 0.5 0.5 0.5\n2 1 0.5 0.5 0.5\n", "7 x y z purge yes add yes", "add 'replace no'"},
      {head + "1 1 0.5 0.5 0.5\n2 1 0.5 0.5 0.5\n", "7 x y z purge yes replace no", "add yes"},
      {head + "1 1 0.5 0.5 0.5\n2 1 0.5 0.5 0.5\n", "7 x y z bogus yes", "unknown field or keyword 'bogus'"},
  };
  for (const auto& c : cases) {
    write(c.file);
    INFO("read_dump " << c.args);
    CHECK_THROWS_WITH(s.cmd("read_dump " + bad + " " + c.args), Contains(c.expect));
    // nothing changed: the box, the particle and the step
    CHECK(s.e.update->ntimestep == 0);
    long long n = s.p().nlocal, all = 0;
    MPI_Allreduce(&n, &all, 1, MPI_LONG_LONG, MPI_SUM, MPI_COMM_WORLD);
    CHECK(all == 1);
    for (int i = 0; i < s.p().nlocal; ++i)
      CHECK(s.p().x[i][0] == 0.005);
  }
  CHECK_THROWS_WITH(s.cmd("read_dump missing_file.txt 7 x y z"),
                    Contains("cannot open dump file 'missing_file.txt'"));
  // a good snapshot read with box no: the particle with id 1 moves
  write(head + "1 1 0.002 0.003 0.004\n2 1 0.5 0.5 0.5\n");
  s.cmd("read_dump " + bad + " 7 x y z box no");
  CHECK(s.e.update->ntimestep == 7);
  for (int i = 0; i < s.p().nlocal; ++i) {
    CHECK(s.p().x[i][0] == 0.002);
    CHECK(s.p().x[i][2] == 0.004);
  }
}
