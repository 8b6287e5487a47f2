// dump local on 1, 2 and 4 ranks (run by ctest at each count): the contacts
// of compute pair/gran/local and wall/gran/local of a settled bed, every row
// once with an index 1..N, in the LAMMPS text format; formats, sorting, one
// file of several frames, and the errors.
#include <mpi.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/modify.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

namespace fs = std::filesystem;

using granary::test::world_rank;
using granary::test::world_size;

std::string fresh_dir(const std::string& name) {
  const std::string dir = "dump_local_np" + std::to_string(world_size()) + "/" + name;
  if (world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return dir;
}

using Row = std::vector<double>;

// The local rows of compute `id` of every rank, on every rank (collective).
std::vector<Row> all_rows(granary::Engine& e, const std::string& id) {
  granary::Compute* c = e.modify->find_compute(id);
  REQUIRE(c);
  c->compute_local();
  const int ncols = std::max(1, c->size_local_cols);
  const std::vector<double>& mine = c->array_local;
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(world_size()), displs(world_size(), 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (int r = 1; r < world_size(); ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(displs.back() + counts.back());
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                 MPI_COMM_WORLD);
  std::vector<Row> rows;
  for (std::size_t k = 0; k + ncols <= all.size(); k += ncols)
    rows.emplace_back(all.begin() + k, all.begin() + k + ncols);
  return rows;
}

struct Frame {
  long long step = -1;
  std::vector<std::string> header;  // the 9 lines before the rows
  std::vector<std::string> lines;   // the rows as written
  std::vector<Row> rows;
};

// The frames of a dump local file.
std::vector<Frame> read_frames(const std::string& file) {
  std::ifstream in(file);
  std::vector<Frame> frames;
  std::string line;
  while (std::getline(in, line)) {
    if (line == "ITEM: TIMESTEP") {
      frames.emplace_back();
      Frame& f = frames.back();
      f.header.push_back(line);
      for (int k = 0; k < 8 && std::getline(in, line); ++k)
        f.header.push_back(line);
      f.step = std::stoll(f.header[1]);
      const long long n = std::stoll(f.header[3]);
      for (long long r = 0; r < n && std::getline(in, line); ++r) {
        f.lines.push_back(line);
        std::istringstream ss(line);
        Row row;
        double v;
        while (ss >> v)
          row.push_back(v);
        f.rows.push_back(row);
      }
    }
  }
  return frames;
}

// A bed of spheres of two sizes settled on a floor (primitive wall), periodic
// in x and y: contacts between spheres, across the periodic boundaries and
// with the floor, on every rank.
std::vector<std::string> bed() {
  return {"units si",
          "atom_style granular",
          "boundary p p f",
          "newton off",
          "communicate single vel yes",
          "region box block 0 0.02 0 0.02 0 0.03 units box",
          "create_box 2 box",
          "neighbor 0.0005 bin",
          granary::test::materials(2, 5.e6, 0.45, 0.5, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 1e-5",
          "region fill block 0.001 0.019 0.001 0.019 0.001 0.012 units box",
          "create_atoms 1 random 150 4711 fill overlap 0.0021 maxtry 200",
          "create_atoms 2 random 60 815 fill overlap 0.0021 maxtry 200",
          "set type 1 diameter 0.002 density 2500",
          "set type 2 diameter 0.0015 density 2000",
          "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
          "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
          "fix integr all nve/sphere",
          "run 6000"};
}

}  // namespace

TEST_CASE("dump local: every contact once, with an index, in the LAMMPS text format", "[dump_local][mpi]") {
  const std::string dir = fresh_dir("bed");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(bed());
  s.cmds({"compute pairs all pair/gran/local id force delta", "compute walls all wall/gran/local id delta",
          "dump dp all local 50 " + dir + "/pairs*.txt index c_pairs[1] c_pairs[2] c_pairs[3] c_pairs[7]",
          "dump dw all local 50 " + dir + "/walls.txt c_walls[3] c_walls[4] index",
          "dump_modify dw format line \"%.17g %.17g %5d\"", "run 100"});
  const std::vector<Row> pairs = all_rows(s.e, "pairs"), walls = all_rows(s.e, "walls");
  REQUIRE(pairs.size() > 100);
  REQUIRE(walls.size() > 20);
  if (world_rank() != 0) return;
  // the pair contacts at step 6100: each once, index 1..N
  const auto frames = read_frames(dir + "/pairs6100.txt");
  REQUIRE(frames.size() == 1);
  const Frame& f = frames[0];
  CHECK(f.header[0] == "ITEM: TIMESTEP");
  CHECK(f.step == 6100);
  CHECK(f.header[2] == "ITEM: NUMBER OF ENTRIES");
  CHECK(f.header[4] == "ITEM: BOX BOUNDS pp pp ff");
  CHECK(std::stod(f.header[7].substr(f.header[7].find(' '))) == 0.03);
  CHECK(f.header[8] == "ITEM: ENTRIES index c_pairs[1] c_pairs[2] c_pairs[3] c_pairs[7]");
  REQUIRE(f.rows.size() == pairs.size());
  std::map<std::pair<long long, long long>, double> want;
  for (const Row& r : pairs)
    want[{static_cast<long long>(r[0]), static_cast<long long>(r[1])}] = r[6];
  std::set<std::pair<long long, long long>> seen;
  for (std::size_t k = 0; k < f.rows.size(); ++k) {
    const Row& r = f.rows[k];
    REQUIRE(r.size() == 5);
    CHECK(r[0] == k + 1);  // index, written as an integer
    CHECK(f.lines[k].rfind(std::to_string(k + 1) + " ", 0) == 0);
    const std::pair<long long, long long> key{static_cast<long long>(r[1]), static_cast<long long>(r[2])};
    CHECK(seen.insert(key).second);
    REQUIRE(want.count(key));
    CHECK(r[4] == Approx(want[key]).epsilon(1e-5));  // %g: 6 digits
  }
  // one file with the frames of steps 6000, 6050 and 6100, formats as asked
  const auto wf = read_frames(dir + "/walls.txt");
  REQUIRE(wf.size() == 3);
  CHECK(wf[0].step == 6000);
  CHECK(wf[2].step == 6100);
  CHECK(wf[2].header[8] == "ITEM: ENTRIES c_walls[3] c_walls[4] index");
  REQUIRE(wf[2].rows.size() == walls.size());
  std::map<long long, double> overlap;
  for (const Row& r : walls)
    overlap[static_cast<long long>(r[2])] = r[3];
  for (std::size_t k = 0; k < wf[2].rows.size(); ++k) {
    const Row& r = wf[2].rows[k];
    REQUIRE(overlap.count(static_cast<long long>(r[0])));
    CHECK(r[1] == overlap[static_cast<long long>(r[0])]);  // %.17g: exact
    char index[16];
    std::snprintf(index, sizeof index, "%5d", static_cast<int>(k + 1));
    CHECK(wf[2].lines[k].substr(wf[2].lines[k].size() - 5) == index);
  }
}

TEST_CASE("dump local: sort, label and precision", "[dump_local][mpi]") {
  const std::string dir = fresh_dir("sort");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(bed());
  s.cmds({"compute walls all wall/gran/local id delta",
          "dump dw all local 100 " + dir + "/walls*.txt c_walls[3] c_walls[4]", "dump_modify dw sort -2",
          "dump_modify dw label CONTACTS precision 3", "run 0"});
  if (world_rank() != 0) return;
  const auto f = read_frames(dir + "/walls6000.txt");
  REQUIRE(f.size() == 1);
  CHECK(f[0].header[8] == "ITEM: CONTACTS c_walls[3] c_walls[4]");
  REQUIRE(f[0].rows.size() > 20);
  for (std::size_t k = 1; k < f[0].rows.size(); ++k)
    CHECK(f[0].rows[k - 1][1] >= f[0].rows[k][1]);  // descending overlaps
  // three significant digits: the values read back write the same with %.3g
  for (const std::string& line : f[0].lines) {
    const std::string value = line.substr(line.find(' ') + 1);
    char again[32];
    std::snprintf(again, sizeof again, "%.3g", std::stod(value));
    CHECK(value == again);
  }
}

TEST_CASE("dump local: errors say what to change", "[dump_local][mpi][errors]") {
  const std::string dir = fresh_dir("errors");
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"units si", "atom_style granular", "boundary f f f", "region box block 0 0.01 0 0.01 0 0.01",
          "create_box 1 box", granary::test::materials(1, 5.e6, 0.45, 0.5, 0.5),
          "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 1e-5",
          "create_atoms 1 single 0.005 0.005 0.0009", "create_atoms 1 single 0.0069 0.005 0.0009",
          "set atom * diameter 0.002 density 2500",
          "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
          "compute pairs all pair/gran/local id", "compute walls all wall/gran/local id",
          "compute delta all wall/gran/local delta", "compute ke all ke"});
  const std::string d = "dump d all local 1 " + dir + "/a.txt ";
  CHECK_THROWS_WITH(s.cmd(d + "c_pairs[1] speed"), Contains("unknown value 'speed'"));
  CHECK_THROWS_WITH(s.cmd(d + "f_floor"), Contains("no fix of Granary gives local values"));
  CHECK_THROWS_WITH(s.cmd(d + "c_nothing[1]"), Contains("no compute 'nothing'"));
  CHECK_THROWS_WITH(s.cmd(d + "c_ke"), Contains("gives no local values"));
  CHECK_THROWS_WITH(s.cmd(d + "c_pairs[0]"), Contains("1 or more"));
  CHECK_THROWS_WITH(s.cmd("dump d all local 1 " + dir + "/a.txt"), Contains("usage"));
  CHECK_THROWS_WITH(s.cmd("dump d all local 1 " + dir + "/a%.txt index"), Contains("'%'"));
  CHECK_THROWS_WITH(s.cmd("dump d all local 1 " + dir + "/nodir/a.txt index"), Contains("does not exist"));
  // the shape of the computes is checked when the dump writes
  s.cmd(d + "c_pairs");
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("local array of 3 columns") && Contains("c_pairs[1]"));
  s.cmd("undump d");
  s.cmd(d + "c_pairs[4]");
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("gives 3 columns"));
  s.cmd("undump d");
  // one value per contact: a local vector, as in LIGGGHTS
  s.cmd(d + "c_delta[1]");
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("local vector (write c_delta)"));
  s.cmd("undump d");
  // one contact between the spheres, two with the floor
  s.cmd(d + "c_pairs[1] c_walls[3]");
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("different numbers of local rows"));
  s.cmd("undump d");
  s.cmd(d + "index c_delta");
  CHECK_THROWS_WITH(s.cmd("dump_modify d format line \"%d\""), Contains("1 conversions for 2 columns"));
  s.cmd("run 0");
  if (world_rank() == 0) {
    const auto f = read_frames(dir + "/a.txt");
    REQUIRE(f.size() == 1);
    REQUIRE(f[0].rows.size() == 2);
    CHECK(f[0].rows[1][0] == 2);
    CHECK(f[0].rows[1][1] == Approx(0.0001).epsilon(1e-5));
  }
}
