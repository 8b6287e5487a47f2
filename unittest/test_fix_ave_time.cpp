// fix ave/time: averages of known time series (variables of the step and of
// time, a compute of a particle in uniform motion, another fix), ave one,
// running and window, the file in LAMMPS' format, outputs for variables, the
// restart of a running average, and the errors for bad arguments.
#include <mpi.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/variable.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

struct Sim : granary::test::ScriptEngine {
  Sim() : ScriptEngine(MPI_COMM_WORLD) {}
  double var(const std::string& formula) { return e.input->variables().evaluate(formula); }
};

const std::vector<std::string> kMaterials = {granary::test::materials(1, 5.e6, 0.45, 0.5, 0.5),
                                             "pair_style gran model hertz tangential history",
                                             "pair_coeff * *", "timestep 1e-3"};

// One sphere moving at vx = 2 m/s in an empty box (no gravity), dt = 1e-3 s.
void setup(Sim& s) {
  s.cmds({"units si", "atom_style granular", "boundary f f f", "region box block 0 100 0 1 0 1",
          "create_box 1 box"});
  s.cmds(kMaterials);
  s.cmds({"create_atoms 1 single 1 0.5 0.5", "set atom 1 diameter 0.1 density 1000 vx 2",
          "fix nve all nve/sphere", "variable s equal step", "variable t equal time",
          "variable q equal step*step"});
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("granary_avetime_" + std::to_string(::getpid()) + "_" + name);
}

}  // namespace

TEST_CASE("fix ave/time: averages of a known time series", "[fix][ave/time]") {
  Sim s;
  setup(s);
  // samples at steps 6, 8, 10 (then 16, 18, 20, ...), averaged on multiples of 10
  s.cmds({"fix a all ave/time 2 3 10 v_s v_t v_q", "fix b all ave/time 2 3 10 v_s ave running",
          "fix w all ave/time 2 3 10 v_s ave window 2", "fix one all ave/time 5 1 5 v_s",
          "compute x all reduce sum x vx", "fix c all ave/time 1 10 10 c_x[1] c_x[2]",
          "fix f all ave/time 10 1 10 f_a[1]", "variable av equal f_a[3]", "variable bv equal f_b"});
  s.cmd("run 0");
  CHECK(s.var("f_a[1]") == 0.0);  // no output yet
  CHECK(s.var("f_one") == 0.0);   // step 0 sampled: its average is 0
  s.cmd("run 10");
  CHECK(s.var("f_a[1]") == Approx(8.0));
  CHECK(s.var("f_a[2]") == Approx(0.008));
  CHECK(s.var("v_av") == Approx((36.0 + 64.0 + 100.0) / 3.0));
  CHECK(s.var("f_one") == Approx(10.0));
  // x = 1 + 2 t: mean over steps 1..10 = 1 + 2 * 5.5e-3
  CHECK(s.var("f_c[1]") == Approx(1.0 + 2.0 * 5.5e-3).epsilon(1e-12));
  CHECK(s.var("f_c[2]") == Approx(2.0));
  CHECK(s.var("f_f") == Approx(8.0));  // the other fix's output of the same step
  s.cmd("run 20");                     // outputs at 20 and 30
  CHECK(s.var("f_a[1]") == Approx(28.0));
  CHECK(s.var("v_bv") == Approx((8.0 + 18.0 + 28.0) / 3.0));
  CHECK(s.var("f_w") == Approx((18.0 + 28.0) / 2.0));
  CHECK(s.var("f_a[3]") == Approx((26.0 * 26 + 28.0 * 28 + 30.0 * 30) / 3.0));
  // a run that ends inside a sampling window continues it in the next run
  s.cmd("run 7");  // step 37: samples 36 taken
  s.cmd("run 3");  // 38, 40 -> output at 40
  CHECK(s.var("f_a[1]") == Approx(38.0));
  CHECK(s.var("f_one") == Approx(40.0));
}

TEST_CASE("fix ave/time: file in LAMMPS' format and start", "[fix][ave/time]") {
  const fs::path file = temp_file("a.dat"), file2 = temp_file("b.dat");
  {
    Sim s;
    setup(s);
    s.cmds({"fix a all ave/time 1 2 5 v_s v_q start 12 file " + file.string(),
            "fix b all ave/time 5 1 5 v_t file " + file2.string() +
                " format \" %.3f\" title1 \"# my data\" title2 \"# step time\" title3 \"# third\"",
            "run 20"});
  }
  // start 12: the first window is 14, 15
  CHECK(read_text(file) ==
        "# Time-averaged data for fix a\n# TimeStep v_s v_q\n15 14.5 210.5\n20 19.5 380.5\n");
  CHECK(read_text(file2) ==
        "# my data\n# step time\n# third\n0 0.000\n5 0.005\n10 0.010\n15 0.015\n20 0.020\n");
  fs::remove(file);
  fs::remove(file2);
}

TEST_CASE("fix ave/time: a running average continues across a restart", "[fix][ave/time][restart]") {
  const fs::path restart = temp_file("run.restart");
  Sim s;
  setup(s);
  s.cmds({"fix b all ave/time 2 3 10 v_s ave running", "run 20", "write_restart " + restart.string()});
  CHECK(s.var("f_b") == Approx(13.0));
  s.cmds({"clear", "read_restart " + restart.string()});
  s.cmds(kMaterials);
  s.cmd("fix b all ave/time 2 3 10 v_s ave running");
  CHECK(s.var("f_b") == Approx(13.0));  // restored output
  s.cmds({"fix nve all nve/sphere", "run 10"});
  CHECK(s.var("f_b") == Approx((8.0 + 18.0 + 28.0) / 3.0));
  fs::remove(restart);
}

TEST_CASE("fix ave/time: errors", "[fix][ave/time]") {
  Sim s;
  setup(s);
  // the conditions of LAMMPS: Nfreq a multiple of Nevery, Nrepeat*Nevery <= Nfreq, all > 0
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 3 2 10 v_s"), Contains("multiple of Nevery"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 2 6 10 v_s"), Contains("must not exceed Nfreq"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 0 1 10 v_s"), Contains("positive"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 1 1 0 v_s"), Contains("positive"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 1 1 10"), Contains("usage"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 1 1 10 ke"), Contains("at least one value"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 1 1 10 v_s bogus 1"), Contains("unknown fix ave/time keyword"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 1 1 10 v_s mode vector"), Contains("'v_s' is a variable"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 1 1 10 v_s mode matrix"), Contains("scalar or vector"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 1 1 10 v_s ave window 0"), Contains("positive"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 1 1 10 c_x[0]"), Contains(">= 1"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 1 1 10 v_s format %d"), Contains("format"));
  CHECK_THROWS_WITH(s.cmd("fix e all ave/time 1 1 10 v_s file /nonexistent/dir/x.dat"),
                    Contains("cannot write '/nonexistent/dir/x.dat': No such file or directory"));
  // references are checked at the run
  s.cmd("fix e all ave/time 1 1 10 c_nothere");
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("nothere"));
  s.cmds({"unfix e", "variable a atom x", "fix e all ave/time 1 1 10 v_a"});
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("atom-style"));
}
