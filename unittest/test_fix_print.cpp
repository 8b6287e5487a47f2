// fix print: the lines written at multiples of N with the variables of that
// step, to the file (with its title), the log file and not the screen with
// `screen no`; the same lines LIGGGHTS 3.8 writes for the same script.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

std::vector<std::string> lines_of(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);)
    out.push_back(l);
  return out;
}

struct TempDir {
  std::string path;
  TempDir() {
    auto t = granary::test::temp_template("granary_print_");
    REQUIRE(::mkdtemp(t.data()) != nullptr);
    path = t.data();
  }
  ~TempDir() { std::filesystem::remove_all(path); }
};

}  // namespace

TEST_CASE("fix print: text with variables every N steps, to file, log and screen", "[fix][print]") {
  TempDir dir;
  const std::string out = dir.path + "/out.txt", app = dir.path + "/app.txt", log = dir.path + "/log.txt";
  {
    std::ofstream pre(app);
    pre << "kept\n";
  }
  granary::test::ScriptEngine s;
  // a particle of mass m = 2000 * 4/3 pi (0.005 m)^3 pushed by -1e-3 N along z
  s.cmds({"log " + log, "units si", "atom_style granular", "boundary f f f",
          "region reg block -0.1 0.1 -0.1 0.1 -0.1 0.1 units box", "create_box 1 reg", "timestep 0.001",
          "create_atoms 1 single 0 0 0", "set atom 1 diameter 0.01 density 2000", "fix integr all nve/sphere",
          "variable s equal step", "variable z equal z[1]",
          "fix p all print 3 \"step $s z ${z} $(v_s*2)\" file " + out,
          "fix p2 all print 4 \"other $s\" append " + app + " screen no title \"hello there\"",
          "fix ap all addforce 0 0 -1e-3", "run 10", "run 5"});
  s.cmd("log none");
  const double m = 2000 * 4.0 / 3.0 * M_PI * 1.25e-7;
  // LIGGGHTS 3.8 writes for this script (out.txt):
  //   # Fix print output for fix p
  //   step 3 z -4.29718346348117e-06 6   ... step 15 z -0.000107429586587029 30
  const auto lines = lines_of(out);
  REQUIRE(lines.size() == 6);
  CHECK(lines[0] == "# Fix print output for fix p");
  for (int k = 1; k <= 5; ++k) {
    const int step = 3 * k;
    int st = 0, twice = 0;
    double z = 0;
    INFO(lines[k]);
    REQUIRE(std::sscanf(lines[k].c_str(), "step %d z %lf %d", &st, &z, &twice) == 3);
    CHECK(st == step);
    CHECK(twice == 2 * step);
    const double t = step * 0.001;
    CHECK(z == Approx(-0.5 * 1e-3 / m * t * t).epsilon(1e-12));
  }
  CHECK(lines[1] == "step 3 z -4.29718346348117e-06 6");  // %.15g as LIGGGHTS
  CHECK(lines_of(app) == std::vector<std::string>{"kept", "hello there", "other 4", "other 8", "other 12"});
  // screen and log: the lines of p, not those of p2 (screen no)
  std::stringstream ss;
  ss << std::ifstream(log).rdbuf();
  CHECK_THAT(ss.str(), Contains("step 9 z") && Contains("step 15 z"));
  CHECK(ss.str().find("other 4") == std::string::npos);
}

TEST_CASE("fix print: input errors", "[fix][print]") {
  granary::test::ScriptEngine s;
  s.cmds({"units si", "atom_style granular", "boundary f f f", "region reg block -1 1 -1 1 -1 1",
          "create_box 1 reg"});
  CHECK_THROWS_WITH(s.cmd("fix p all print 0 \"x\""), Contains("positive"));
  CHECK_THROWS_WITH(s.cmd("fix p all print 10"), Contains("usage"));
  CHECK_THROWS_WITH(s.cmd("fix p all print 10 \"x\" fiel a.txt"), Contains("file"));
  CHECK_THROWS_WITH(s.cmd("fix p all print 10 \"x\" file /nonexistent/dir/a.txt"), Contains("cannot open"));
  s.cmd("fix p all print 10 \"value ${nothing}\"");
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("nothing"));
}
