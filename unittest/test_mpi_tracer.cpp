// Tracer particles on 1, 2 and 4 ranks (run by ctest at each count): fix
// property/atom/tracer (dirac and heaviside marking), compute
// nparticles/tracer/region (with and without unmarking what it counts) and
// fix property/atom/regiontracer/time against LIGGGHTS 3.8's thermo output of
// the same script (unittest/scripts/tracer/in.tracer, references
// unittest/reference/tracer_*.liggghts.log); residence times against their
// closed form; markers and times through a restart file; the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "fix/fix.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

namespace fs = std::filesystem;
const fs::path kRoot(GRANARY_SOURCE_DIR);
const std::string kScript = (kRoot / "unittest/scripts/tracer/in.tracer").string();

std::string read_text(const fs::path& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Sum of a per-atom fix value over all ranks.
double peratom_sum(granary::Engine& e, const std::string& fix, int col) {
  std::vector<double> v;
  e.modify->find_fix(fix)->peratom(col, v);
  double mine = 0.0, all = 0.0;
  for (double x : v)
    mine += x;
  MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE, MPI_SUM, e.world);
  return all;
}

}  // namespace

TEST_CASE("tracer marking, counting and residence times: LIGGGHTS 3.8's thermo", "[tracer][mpi][liggghts]") {
  for (const auto& [style, reset] : std::vector<std::pair<std::string, std::string>>{
           {"dirac", "yes"}, {"heaviside", "no"}, {"heaviside", "yes"}}) {
    const std::string name = "tracer_" + style + "_reset_" + reset;
    const auto ref =
        granary::test::thermo_rows(read_text(kRoot / "unittest/reference" / (name + ".liggghts.log")), 9);
    REQUIRE(ref.size() == 11);
    const std::string dir = granary::test::rank_count_dir(name);
    const std::string log = (fs::path(dir) / "log.txt").string();
    {
      granary::test::ScriptEngine s(MPI_COMM_WORLD);
      s.cmds({"log " + log, "variable style index " + style, "variable reset index " + reset,
              "include " + kScript});
      // residence time in the box: every particle since step 0
      CHECK(s.e.fix_value("rt", 1) == Approx(1000 * 1e-4).epsilon(1e-12));
      CHECK(peratom_sum(s.e, "rt", 1) == Approx(405 * 0.1).epsilon(1e-12));
      CHECK(s.e.fix_value("rt", 2) < s.e.fix_value("rt", 1));
      s.cmd("log none");
    }
    MPI_Barrier(MPI_COMM_WORLD);
    const auto mine = granary::test::thermo_rows(read_text(log), 9);
    REQUIRE(mine.size() == ref.size());
    for (std::size_t r = 0; r < ref.size(); ++r)
      for (std::size_t c = 0; c < 9; ++c) {
        INFO(name << ": step " << ref[r][0] << ", column " << c + 1);
        CHECK(mine[r][c] == Approx(ref[r][c]).epsilon(1e-7).margin(1e-12));  // LIGGGHTS prints 8 digits
      }
  }
}

TEST_CASE("tracer markers and residence times travel through a restart file", "[tracer][mpi]") {
  const std::string dir = granary::test::rank_count_dir("tracer_restart");
  const std::string file = (fs::path(dir) / "tracer.restart").string();
  double marked = 0.0, box_time = 0.0, region_time = 0.0;
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds({"variable nsteps index 300", "variable reset index no", "include " + kScript,
            "write_restart " + file});
    marked = peratom_sum(s.e, "tr", 0);
    box_time = peratom_sum(s.e, "rt", 1);
    region_time = peratom_sum(s.e, "rt", 2);
  }
  REQUIRE(marked == 45.0);
  granary::test::ScriptEngine r(MPI_COMM_WORLD);
  r.cmds({"read_restart " + file, "region mark block 0 0.05 0 0.1 0.02 0.057 units box",
          "region count block 0 0.1 0 0.1 0 0.07 units box",
          "fix tr all property/atom/tracer region_mark mark mark_step 15"});
  // the stored times have a region: the fix without it is refused
  CHECK_THROWS_WITH(r.cmd("fix rt all property/atom/regiontracer/time"),
                    Contains("give the fix the regions"));
  r.cmd("fix rt all property/atom/regiontracer/time add_region count check_region_every 5");
  CHECK(peratom_sum(r.e, "tr", 0) == marked);
  CHECK(peratom_sum(r.e, "rt", 1) == Approx(box_time).epsilon(1e-14));
  CHECK(peratom_sum(r.e, "rt", 2) == Approx(region_time).epsilon(1e-14));
  // dirac marking happened before the restart: nothing is marked again
  r.cmd("run 100");
  CHECK(peratom_sum(r.e, "tr", 0) == marked);
}

TEST_CASE("tracer styles refuse bad arguments", "[tracer][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"atom_style granular", "boundary f f f", "units si", "region b block 0 1 0 1 0 1 units box",
          "create_box 1 b"});
  CHECK_THROWS_WITH(s.cmd("fix t all property/atom/tracer region_mark nowhere mark_step 1"),
                    Contains("nowhere"));
  CHECK_THROWS_WITH(s.cmd("fix t all property/atom/tracer mark_step 1"), Contains("usage"));
  CHECK_THROWS_WITH(s.cmd("fix t all property/atom/tracer region_mark b mark_step 1 marker_style box"),
                    Contains("dirac or heaviside"));
  CHECK_THROWS_WITH(s.cmd("fix t all property/atom/tracer region_mark b mark_step 1 check_mark_every 0"),
                    Contains("positive"));
  CHECK_THROWS_WITH(s.cmd("fix t all property/atom/regiontracer/time add_region nowhere"),
                    Contains("nowhere"));
  CHECK_THROWS_WITH(s.cmd("fix t all property/atom/regiontracer/time every 5"), Contains("unknown keyword"));
  s.cmd("fix g all property/atom/regiontracer/time");
  CHECK_THROWS_WITH(s.cmd("compute c all nparticles/tracer/region region_count b tracer g"),
                    Contains("not the ID of a fix property/atom/tracer"));
  s.cmd("fix t all property/atom/tracer region_mark b mark_step 1");
  CHECK_THROWS_WITH(s.cmd("compute c all nparticles/tracer/region region_count b tracer t periodic q 1"),
                    Contains("x, y or z"));
  CHECK_THROWS_WITH(
      s.cmd("compute c all nparticles/tracer/region region_count b tracer t reset_marker maybe"),
      Contains("reset_marker"));
}
