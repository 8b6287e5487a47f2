// fix ave/spatial against LIGGGHTS 3.8 (unittest/scripts/in.ave_spatial,
// reference files unittest/reference/ave_spatial/s1..s4.txt) on 1, 2 and 4
// ranks: spheres that never touch slide through a box periodic in x and y
// and fall; 1d, 2d and 3d bins, norm all and sample, ave one, running and
// window, units box and reduced, a region, titles.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/logger.h"
#include "script_engine.h"

namespace {

namespace fs = std::filesystem;
using granary::test::world_rank;
using granary::test::world_size;

const std::string kScripts = std::string(GRANARY_SOURCE_DIR) + "/unittest/scripts";
const std::string kReference = std::string(GRANARY_SOURCE_DIR) + "/unittest/reference/ave_spatial";

std::vector<std::string> lines_of(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);)
    out.push_back(line);
  return out;
}

// Compare two output files: the same lines, numbers within a relative 1e-5
// (both print 6 significant digits); `skip_col` (0-based, counted on lines of
// bins) is left out, and so are the bin lines of the outputs of `skip_steps`.
void compare(const std::string& name, const std::string& ours, int skip_col = -1,
             const std::vector<long>& skip_steps = {}) {
  const auto a = lines_of(kReference + "/" + name), b = lines_of(ours);
  REQUIRE(a.size() == b.size());
  long step = -1;
  for (std::size_t k = 0; k < a.size(); ++k) {
    INFO(name << " line " << k + 1 << "\n  LIGGGHTS: " << a[k] << "\n  Granary:  " << b[k]);
    if (a[k].rfind('#', 0) == 0) {
      CHECK(a[k] == b[k]);
      continue;
    }
    std::istringstream sa(a[k]), sb(b[k]);
    std::vector<double> va, vb;
    for (double v; sa >> v;)
      va.push_back(v);
    for (double v; sb >> v;)
      vb.push_back(v);
    REQUIRE(va.size() == vb.size());
    if (va.size() == 2) {  // "step nbins"
      step = static_cast<long>(va[0]);
      CHECK(va == vb);
      continue;
    }
    if (std::find(skip_steps.begin(), skip_steps.end(), step) != skip_steps.end()) continue;
    for (std::size_t c = 0; c < va.size(); ++c) {
      if (static_cast<int>(c) == skip_col) continue;
      CHECK(vb[c] == Approx(va[c]).epsilon(1e-5).margin(1e-12));
    }
  }
}

}  // namespace

TEST_CASE("fix ave/spatial: bins of LIGGGHTS' script agree with LIGGGHTS on any number of ranks",
          "[fix][ave/spatial][mpi][liggghts]") {
  const std::string dir = "ave_spatial_np" + std::to_string(world_size());
  if (world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  std::vector<std::string> script;
  for (std::string line : lines_of(kScripts + "/in.ave_spatial")) {
    const auto at = line.find(" file s");
    if (at != std::string::npos) line.replace(at, 6, " file " + dir + "/");
    script.push_back(line);
  }
  {
    granary::Engine e(MPI_COMM_WORLD);
    e.logger->set_screen(false);
    granary::test::run(e, script);
  }
  if (world_rank() != 0) return;
  compare("s1.txt", dir + "/s1.txt");  // 1d, norm all, densities
  compare("s2.txt", dir + "/s2.txt");  // 2d, norm sample, ave running, a column and an atom variable
  compare("s4.txt", dir + "/s4.txt");  // a region, title1 set and title2 left out
  // 3d in reduced units, ave window 2: LIGGGHTS 3.8 prints 0 for the densities
  // in reduced units (column 5) and leaves a particle that has crossed a
  // periodic face in the last bin until it is wrapped back (the output of
  // steps 200, 300 and 400 here); the densities are checked
  // on their own below
  compare("s3.txt", dir + "/s3.txt", 5, {200, 300, 400});
  // Granary's density/mass in reduced units: count x mass / bin volume, the
  // bin 0.25 x 0.5 x 0.2 of the 0.04 x 0.02 x 0.06 m box; every particle
  // below z = 0 has d = 2 mm (2500 kg/m^3)
  const auto ours = lines_of(dir + "/s3.txt");
  const double m = 2500.0 * M_PI / 6.0 * 8e-9, vol = 0.25 * 0.04 * 0.5 * 0.02 * 0.2 * 0.06;
  std::istringstream row(ours[5]);  // step 100, bin 2: z from 0.2 to 0.4 of the box
  double bin, c1, c2, c3, count, dens;
  row >> bin >> c1 >> c2 >> c3 >> count >> dens;
  REQUIRE(c3 == Approx(0.3));
  REQUIRE(count > 0.0);
  CHECK(dens == Approx(count * m / vol).epsilon(1e-5));
}

TEST_CASE("fix ave/spatial: a particle past a periodic face is binned where it wraps to",
          "[fix][ave/spatial]") {
  // (one file name per rank count, since ctest runs them at once, and per
  // rank: each rank runs this serial engine on its own)
  const std::string tag =
      "ave_spatial_wrap_np" + std::to_string(world_size()) + "_r" + std::to_string(world_rank()) + "_";
  granary::test::ScriptEngine s;
  s.cmds({"units si", "atom_style granular", "atom_modify map array", "boundary p f f", "newton off",
          "communicate single vel yes", "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box",
          "create_box 1 box", "neighbor 0.004 bin", "timestep 0.0001"});
  s.cmds(
      {"create_atoms 1 single 0.0095 0.0 0.0 units box", "set group all diameter 0.002 density 2500",
       "velocity all set 1.0 0.0 0.0 units box", "fix integr all nve/sphere",
       "fix a all ave/spatial 10 1 10 x lower 0.5 density/number units reduced file " + tag + "reduced.txt",
       "fix b all ave/spatial 10 1 10 x lower 0.01 density/number file " + tag + "box.txt", "run 10"});
  // moved 1 mm in 10 steps: at x = 0.0105, past the face at 0.01, not yet
  // wrapped (the 4 mm skin needs no re-neighbouring)
  for (const std::string f : {tag + "reduced.txt", tag + "box.txt"}) {
    INFO(f);
    const auto lines = lines_of(f);
    const auto at = std::find(lines.begin(), lines.end(), "10 2");  // the output of step 10 (after step 0's)
    REQUIRE(lines.end() - at >= 3);
    std::istringstream first(*(at + 1)), second(*(at + 2));
    double b1, x1, n1, b2, x2, n2;
    first >> b1 >> x1 >> n1;
    second >> b2 >> x2 >> n2;
    CHECK(n1 == 1.0);  // the first bin: the particle's image at x = -0.0095
    CHECK(n2 == 0.0);
    std::remove(f.c_str());
  }
}

TEST_CASE("fix ave/spatial input errors", "[fix][ave/spatial]") {
  using Catch::Matchers::Contains;
  granary::test::ScriptEngine s;
  s.cmds(granary::test::liggghts_head("-0.01 0.01 -0.01 0.01 -0.01 0.01", 1));
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"fix a all ave/spatial 10 1 10 vx density/number", "needs Nevery, Nrepeat, Nfreq, a dim"},
      {"fix a all ave/spatial 10 1 10 vx density/number norm all", "need a dimension x, y or z"},
      {"fix a all ave/spatial 10 1 10 z lower 0 vx", "bin thickness must be positive"},
      {"fix a all ave/spatial 10 1 10 z lower 0.001 z lower 0.002 vx", "binned twice"},
      {"fix a all ave/spatial 10 1 10 z lower 0.001 norm all", "at least one value"},
      {"fix a all ave/spatial 10 1 10 z lower 0.001 vx norm some", "norm must be all or sample"},
      {"fix a all ave/spatial 10 1 10 z lower 0.001 vx units lattice", "no lattice is defined"},
      {"fix a all ave/spatial 10 1 10 z lower 0.001 vx overwrite", "overwrite needs ave running"},
      {"fix a all ave/spatial 10 1 10 z lower 0.001 vx std 1 5 f.txt", "std keyword"},
      {"fix a all ave/spatial 10 1 10 z lower 0.001 vx region nowhere", "nowhere"},
      {"fix a all ave/spatial 10 1 15 z lower 0.001 vx", "multiple of"},
  };
  for (const auto& [line, message] : bad) {
    INFO(line);
    CHECK_THROWS_WITH(s.cmd(line), Contains(message));
  }
}
