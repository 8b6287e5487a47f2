// The info command: what each category prints, the destinations, the errors.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/engine.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A scene with one of each thing info lists.
void scene(granary::test::ScriptEngine& s) {
  s.cmds(granary::test::liggghts_head("-0.1 0.1 -0.1 0.1 0 0.2", 2));
  s.cmds({granary::test::materials(2, 5e6, 0.45, 0.5, 0.3), "pair_style gran model hertz tangential history",
          "pair_coeff * *", "timestep 1e-5", "neighbor 0.002 bin",
          "region upper block -0.1 0.1 -0.1 0.1 0.1 0.2 units box",
          "create_atoms 1 single 0 0 0.05 units box", "create_atoms 2 single 0 0 0.15 units box",
          "set group all diameter 0.01 density 2500", "group top region upper", "fix integr all nve/sphere",
          "compute rke top erotate/sphere", "dump d1 all custom 100 info_dump.txt id x y z",
          "variable seed index 42", "variable e equal step*2", "run 3"});
}

}  // namespace

TEST_CASE("info all writes every category of the present state to a file", "[info]") {
  granary::test::ScriptEngine s;
  scene(s);
  std::filesystem::remove("info_all.txt");
  s.cmd("info all out overwrite info_all.txt");
  const std::string t = slurp("info_all.txt");
  CHECK_THAT(t, Contains("Info-Info-Info"));
  // system
  CHECK_THAT(t, Contains("Units      = si"));
  CHECK_THAT(t, Contains("Atoms      = 2, types = 2"));
  CHECK_THAT(t, Contains("Orthogonal box = (-0.1 -0.1 0) to (0.1 0.1 0.2)"));
  CHECK_THAT(t, Contains("Boundaries = f,f,f"));
  CHECK_THAT(t, Contains("Pair style = gran model hertz tangential history"));
  CHECK_THAT(t, Contains("Newton pair = off"));
  CHECK_THAT(t, Contains("Timestep = 1e-05 s, step = 3"));
  CHECK_THAT(t, Contains("Neighbor skin = 0.002 m"));
  // communication
  CHECK_THAT(t, Contains("MPI ranks = 1"));
  CHECK_THAT(t, Contains("Processor grid = 1 x 1 x 1"));
  CHECK_THAT(t, Contains("Communication style = brick"));
  CHECK_THAT(t, Contains("MPI library level: MPI v"));
  // no NUL from the MPI library's version string (the screen copy stopped there)
  CHECK(t.find('\0') == std::string::npos);
  // styles, groups, regions, variables
  CHECK_THAT(t, Contains("Fix[4]: integr, style = nve/sphere, group = all"));
  CHECK_THAT(t, Contains("Compute[0]: rke, style = erotate/sphere, group = top"));
  CHECK_THAT(t, Contains("Dump[0]: d1, file = info_dump.txt, style = custom, group = all, every = 100"));
  CHECK_THAT(t, Contains("Group[0]: all"));
  CHECK_THAT(t, Contains("Group[1]: top"));
  CHECK_THAT(t, Contains("Region[1]: upper, style = block"));
  CHECK_THAT(t, Contains("seed, style = index, value = 42"));
  CHECK_THAT(t, Contains("e, style = equal\n"));
  // time, configuration
  CHECK_THAT(t, Contains("  CPU time: "));
  CHECK_THAT(t, Contains(" Wall time: "));
  CHECK_THAT(t, Contains("Libraries: VTK 9."));
  CHECK_THAT(t, Contains("Granary version: "));
  // the build's instruction set and the lanes of the pair loop agree
#if defined(__AVX2__)
  CHECK_THAT(t, Contains("Packed instructions: AVX2, 4 contacts at a time\n"));
#else
  CHECK_THAT(t, Contains("Packed instructions: SSE2, 2 contacts at a time\n"));
#endif
}

TEST_CASE("info: only the categories asked for, appended or to the log", "[info]") {
  granary::test::ScriptEngine s;
  scene(s);
  std::filesystem::remove("info_some.txt");
  s.cmd("info groups out overwrite info_some.txt");
  s.cmd("info regions variables out append info_some.txt");
  const std::string t = slurp("info_some.txt");
  CHECK_THAT(t, Contains("Group[1]: top"));
  CHECK_THAT(t, Contains("Region[1]: upper"));
  CHECK_THAT(t, Contains("Variable["));
  CHECK_THAT(t, !Contains("Fix["));
  CHECK_THAT(t, !Contains("Units"));
  // overwrite starts the file again
  s.cmd("info fixes out overwrite info_some.txt");
  const std::string u = slurp("info_some.txt");
  CHECK_THAT(u, Contains("Fix[0]: m1, style = property/global"));
  CHECK_THAT(u, !Contains("Group["));
  // out log: in the log file, not elsewhere
  s.cmd("log info_log.txt");
  s.cmd("info computes out log");
  s.cmd("log none");
  CHECK_THAT(slurp("info_log.txt"), Contains("Compute[0]: rke"));
  // before a box: info system says so
  granary::test::ScriptEngine fresh;
  fresh.cmd("info system out overwrite info_fresh.txt");
  CHECK_THAT(slurp("info_fresh.txt"), Contains("Box has not yet been created"));
}

TEST_CASE("info: errors name what is wrong", "[info]") {
  granary::test::ScriptEngine s;
  CHECK_THROWS_WITH(s.cmd("info"), Contains("info needs one or more of: all, system"));
  CHECK_THROWS_WITH(s.cmd("info systems"), Contains("unknown category 'systems'"));
  CHECK_THROWS_WITH(s.cmd("info all out"), Contains("info out needs a destination"));
  CHECK_THROWS_WITH(s.cmd("info all out append"), Contains("info out append needs a file name"));
  CHECK_THROWS_WITH(s.cmd("info all out printer"), Contains("info out 'printer'"));
  CHECK_THROWS_WITH(s.cmd("info all out overwrite no_such_dir/info.txt"), Contains("cannot write to"));
}
