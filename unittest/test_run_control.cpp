// Run control through scripts: run upto / start / stop / every, thermo output
// (counted in the log file), thermo normalisation, reset_timestep, timestep
// changes, neighbour-list rebuild policy and neigh_modify exclude.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "script_engine.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/modify.h"
#include "core/update.h"
#include "fix/fix.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"

using Catch::Contains;

namespace {

std::string num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

struct Sim : granary::test::ScriptEngine {
  Sim() : ScriptEngine(MPI_COMM_SELF) {}
  int index(long long id) const {
    for (int i = 0; i < p().nlocal; ++i)
      if (p().id[i] == id) return i;
    FAIL("no particle with id " << id);
    return -1;
  }
  double thermo(const std::string& key) {
    bool found = false;
    const double v = e.thermo_keyword(key, found);
    REQUIRE(found);
    return v;
  }
};

/// Granular set-up with `ntypes` types of the same material (diameter 2 mm,
/// density 2500, Y = 5 MPa, nu = 0.3, e = 0.5) in a shrink-wrapped box;
/// particles are added by the caller.
std::vector<std::string> setup(int ntypes = 1) {
  std::string y, nu, e, mu;
  for (int k = 0; k < ntypes; ++k) {
    y += " 5e6";
    nu += " 0.3";
  }
  for (int k = 0; k < ntypes * ntypes; ++k) {
    e += " 0.5";
    mu += " 0.5";
  }
  const std::string n = std::to_string(ntypes);
  return {"units si",
          "atom_style granular",
          "boundary m m m",
          "region box block -0.02 0.02 -0.02 0.02 -0.02 0.02 units box",
          "create_box " + n + " box",
          "neighbor 0.001 bin",
          "fix m1 all property/global youngsModulus peratomtype" + y,
          "fix m2 all property/global poissonsRatio peratomtype" + nu,
          "fix m3 all property/global coefficientRestitution peratomtypepair " + n + e,
          "fix m4 all property/global coefficientFriction peratomtypepair " + n + mu,
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 1e-5",
          "fix integr all nve/sphere"};
}

/// One bead moving at (vx, 0, 0), no forces.
void one_bead(Sim& s, double vx = 0.0) {
  s.lines(setup());
  s.lines({"create_atoms 1 single 0 0 0 units box", "set type 1 diameter 0.002 density 2500",
           "velocity all set " + num(vx) + " 0 0"});
}

std::string read_text(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// Lines of a log that start with `prefix`.
std::vector<std::string> lines_starting(const std::string& text, const std::string& prefix) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(prefix, 0) == 0) out.push_back(line);
  return out;
}

/// A log file in the current directory, removed at the end of the test.
struct LogFile {
  std::string path;
  explicit LogFile(const std::string& name) : path("test_run_control_" + name + ".log") {}
  ~LogFile() { std::remove(path.c_str()); }
  std::string close_and_read(Sim& s) {
    s.cmd("log none");
    return read_text(path);
  }
};

}  // namespace

// ---------------------------------------------------------------- run

TEST_CASE("run N upto runs to step N", "[run]") {
  Sim s;
  one_bead(s, 1.0);
  s.cmd("run 100");
  CHECK(s.e.update->ntimestep == 100);
  s.cmd("run 250 upto");
  CHECK(s.e.update->ntimestep == 250);
  CHECK(s.e.update->firststep == 100);  // that run made 150 steps
  s.cmd("run 250 upto");                // nothing left to do
  CHECK(s.e.update->ntimestep == 250);
  REQUIRE_THROWS_WITH(s.cmd("run 200 upto"), Contains("already passed"));
  CHECK(s.e.update->ntimestep == 250);
  // the bead moved 250 steps at 1 m/s
  CHECK(s.p().x[0][0] == Approx(250 * 1e-5).epsilon(1e-12));
}

// ramp(a,b) = a + (b - a) (step - begin)/(end - begin), where begin and end
// are the start and stop of the run (or of the run command when they are
// not given). Two runs of 100 steps with start 0 stop 200 ramp 0 -> 5 -> 10;
// a following plain run of 100 steps ramps 0 -> 10 on its own.
TEST_CASE("run N start S stop E sets the range of ramp()", "[run]") {
  LogFile log("ramp");
  Sim s;
  s.cmd("log " + log.path);
  one_bead(s);
  s.lines({"variable r equal ramp(0.0,10.0)", "thermo_style custom step v_r", "thermo 25",
           "run 100 start 0 stop 200", "run 100 start 0 stop 200", "run 100"});
  const auto rows = granary::test::thermo_rows(log.close_and_read(s), 2);
  // three runs: 5 lines each (steps 0/100/200 start a run, then every 25)
  REQUIRE(rows.size() == 15);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const double step = rows[k][0], r = rows[k][1];
    const double expected = k < 10 ? 10.0 * step / 200.0 : 10.0 * (step - 200.0) / 100.0;
    INFO("row " << k << ": step " << step << " ramp " << r);
    CHECK(r == Approx(expected).margin(1e-6));
  }
  CHECK(rows[4][0] == 100);
  CHECK(rows[4][1] == Approx(5.0));
  CHECK(rows[9][1] == Approx(10.0));
  CHECK(rows[14][1] == Approx(10.0));
}

// run N every M "commands": the run is cut into chunks of M steps (the last
// one shorter) and the commands execute after each chunk. Quoted text keeps
// its $-references until the command runs.
TEST_CASE("run N every M executes commands between chunks", "[run]") {
  LogFile log("every");
  Sim s;
  s.cmd("log " + log.path);
  one_bead(s);
  s.lines({"variable s equal step", "run 100 every 30 \"print 'marker A ${s}'\" \"print 'marker B ${s}'\""});
  const std::string text = log.close_and_read(s);
  CHECK(s.e.update->ntimestep == 100);
  const auto a = lines_starting(text, "marker A");
  const auto b = lines_starting(text, "marker B");
  REQUIRE(a.size() == 4);
  CHECK(a[0] == "marker A 30");
  CHECK(a[1] == "marker A 60");
  CHECK(a[2] == "marker A 90");
  CHECK(a[3] == "marker A 100");
  REQUIRE(b.size() == 4);
  CHECK(b[3] == "marker B 100");
  // NULL is no command
  s.cmd("run 20 every 10 NULL");
  CHECK(s.e.update->ntimestep == 120);
}

// ---------------------------------------------------------------- thermo

// thermo N prints a line every N steps plus the first and last step of each
// run; thermo 0 only those two.
// The timing report gives each fix with a timestep hook its own line: the
// time spent in its hooks, which the Modify and Neigh sections contain, reset
// by every run.
TEST_CASE("the timing report times each fix that has a timestep hook", "[run]") {
  LogFile log("fix_times");
  Sim s;
  s.cmd("log " + log.path);
  s.lines(setup());
  s.lines({"lattice sc 0.0025", "region cube block 0 3 0 3 0 3", "create_atoms 1 region cube",
           "set type 1 diameter 0.002 density 2500", "fix gravi all gravity 9.81 vector 0 0 -1",
           "fix floor all wall/gran model hertz tangential history primitive type 1 zplane -0.002",
           "run 2000"});
  const granary::Update& u = *s.e.update;
  const auto time_of = [&](const std::string& id) { return s.e.modify->find_fix(id)->run_time; };
  CHECK(time_of("integr") > 0);
  CHECK(time_of("gravi") > 0);
  CHECK(time_of("floor") > 0);
  CHECK(time_of("m1") == 0);  // property/global: no hook
  const double fixes = time_of("integr") + time_of("gravi") + time_of("floor");
  // the hooks run inside the Modify and Neigh sections, with the loop's own overhead around them
  CHECK(fixes <= u.timers[granary::Update::kModify] + u.timers[granary::Update::kNeigh]);
  CHECK(fixes > 0.5 * u.timers[granary::Update::kModify]);
  const double long_run = time_of("integr");
  s.cmd("run 20");
  CHECK(time_of("integr") < long_run);  // this run's time only
  const std::string text = log.close_and_read(s);
  CHECK(lines_starting(text, "Fix (ID style)").size() == 2);
  CHECK(lines_starting(text, "fix integr nve/sphere ").size() == 2);
  CHECK(lines_starting(text, "fix floor wall/gran ").size() == 2);
  CHECK(lines_starting(text, "fix m1 property/global").empty());  // (the log also echoes "fix m1 all ...")
}

TEST_CASE("thermo N controls the number of output lines in the log", "[run][thermo]") {
  struct Case {
    int every, steps;
    std::size_t lines;
  };
  for (const Case c : {Case{10, 100, 11}, Case{30, 100, 5}, Case{0, 100, 2}, Case{1, 20, 21}}) {
    INFO("thermo " << c.every << ", run " << c.steps);
    LogFile log("thermo");
    Sim s;
    s.cmd("log " + log.path);
    one_bead(s, 0.5);
    s.lines({"thermo_style custom step atoms ke time", "thermo " + std::to_string(c.every),
             "run " + std::to_string(c.steps)});
    const auto rows = granary::test::thermo_rows(log.close_and_read(s), 4);
    REQUIRE(rows.size() == c.lines);
    CHECK(rows.front()[0] == 0);
    CHECK(rows.back()[0] == c.steps);
    for (const auto& r : rows) {
      CHECK(r[1] == 1);                                  // atoms
      CHECK(r[3] == Approx(r[0] * 1e-5).margin(1e-12));  // time = step dt
    }
  }
}

// ke is sum 1/2 m v^2 [J]; with thermo_modify norm yes it is divided by the
// number of particles.
TEST_CASE("thermo_modify norm yes divides ke by the particle count", "[run][thermo]") {
  Sim s;
  s.lines(setup());
  s.lines({"create_atoms 1 single -0.01 0 0 units box", "create_atoms 1 single 0 0 0 units box",
           "create_atoms 1 single 0.01 0 0 units box", "set type 1 diameter 0.002 density 2500",
           "set atom 1 vx 1.0", "set atom 2 vy -2.0", "set atom 3 vz 0.5 vx 0.5", "run 0"});
  const double m = 2500 * 4.0 / 3.0 * M_PI * 1e-9;
  const double ke = 0.5 * m * (1.0 + 4.0 + 0.5);
  CHECK(s.thermo("ke") == Approx(ke).epsilon(1e-12));
  s.cmd("thermo_modify norm yes");
  CHECK(s.thermo("ke") == Approx(ke / 3).epsilon(1e-12));
  s.cmd("thermo_modify norm no");
  CHECK(s.thermo("ke") == Approx(ke).epsilon(1e-12));
}

// ---------------------------------------------------------------- step and time

TEST_CASE("reset_timestep changes the step but not the simulated time", "[run]") {
  Sim s;
  one_bead(s, 1.0);
  s.cmd("run 50");
  CHECK(s.thermo("time") == Approx(50 * 1e-5).epsilon(1e-12));
  s.cmd("reset_timestep 1000");
  CHECK(s.e.update->ntimestep == 1000);
  CHECK(s.thermo("step") == 1000);
  CHECK(s.thermo("time") == Approx(50 * 1e-5).epsilon(1e-12));
  s.cmd("run 10");
  CHECK(s.e.update->ntimestep == 1010);
  CHECK(s.thermo("time") == Approx(60 * 1e-5).epsilon(1e-12));
  CHECK(s.p().x[0][0] == Approx(60 * 1e-5).epsilon(1e-12));  // 60 steps at 1 m/s
  REQUIRE_THROWS_WITH(s.cmd("reset_timestep -1"), Contains("N >= 0"));
}

// 100 steps of 1e-5 s then 100 steps of 2e-5 s: t = 1e-3 + 2e-3 s, and a bead
// at 1 m/s has moved t metres.
TEST_CASE("changing the timestep keeps the simulated time continuous", "[run]") {
  Sim s;
  one_bead(s, 1.0);
  s.cmd("run 100");
  CHECK(s.thermo("time") == Approx(1e-3).epsilon(1e-12));
  s.cmd("timestep 2e-5");
  CHECK(s.thermo("time") == Approx(1e-3).epsilon(1e-12));
  CHECK(s.thermo("dt") == 2e-5);
  s.cmd("run 100");
  CHECK(s.e.update->ntimestep == 200);
  CHECK(s.thermo("time") == Approx(3e-3).epsilon(1e-12));
  CHECK(s.p().x[0][0] == Approx(3e-3).epsilon(1e-12));
  s.cmd("timestep 5e-6");
  s.cmd("run 100");
  CHECK(s.thermo("time") == Approx(3.5e-3).epsilon(1e-12));
}

// ---------------------------------------------------------------- neighbour lists

namespace {
/// List builds of one run (the build at set-up included).
long long builds(Sim& s, const std::string& modify, int steps) {
  if (!modify.empty()) s.cmd("neigh_modify " + modify);
  const long long before = s.e.neighbor->nbuilds;
  s.cmd("run " + std::to_string(steps));
  return s.e.neighbor->nbuilds - before;
}
}  // namespace

// The end-of-run report counts the builds of that run (its set-up included),
// as LAMMPS and LIGGGHTS do, not those since the start.
TEST_CASE("the run report counts the list builds of its own run", "[run][neighbor]") {
  Sim s;
  one_bead(s, 0.0);
  s.cmd("atom_modify sort 0 0.0");
  s.cmd("neigh_modify every 10 delay 0 check no");
  LogFile log("builds");
  s.cmd("log " + log.path);
  s.cmd("run 100");
  s.cmd("run 50");
  const auto rows = lines_starting(log.close_and_read(s), "Neighbor list builds");
  REQUIRE(rows.size() == 2);
  CHECK(rows[0] == "Neighbor list builds = 11");  // set-up, steps 10, 20, ..., 100
  CHECK(rows[1] == "Neighbor list builds = 6");   // set-up, steps 110, ..., 150
}

// A build happens when at least `delay` steps have passed since the last one,
// the step count since then is a multiple of `every`, and (check yes) some
// particle has moved more than half the skin. Spatial sorting is switched off
// (atom_modify sort 0) so that it forces no extra builds.
TEST_CASE("neigh_modify every, delay and check control the list rebuilds", "[run][neighbor]") {
  SECTION("resting beads") {
    Sim s;
    one_bead(s, 0.0);
    s.cmd("atom_modify sort 0 0.0");
    CHECK(builds(s, "every 1 delay 0 check no", 100) == 1 + 100);
    CHECK(builds(s, "every 10 delay 0 check no", 100) == 1 + 10);
    CHECK(builds(s, "every 1 delay 20 check no", 100) == 1 + 5);  // steps 20, 40, ..., 100
    CHECK(builds(s, "every 5 delay 12 check no", 100) == 1 + 6);  // every 15 steps
    CHECK(builds(s, "every 1 delay 0 check yes", 100) == 1);      // nothing moves
    CHECK(builds(s, "every 1 delay 0 check no once yes", 100) == 1);
  }
  SECTION("a moving bead") {
    // 0.7 m/s with dt = 1e-5 s: 7e-6 m per step; half the skin (5e-4 m) is
    // exceeded 72 steps after each build: builds at 72, 144, ..., 432 in 500
    // steps. Checking only every 10 steps: at 80, 160, ..., 480.
    Sim s;
    one_bead(s, 0.7);
    s.cmd("atom_modify sort 0 0.0");
    CHECK(builds(s, "every 1 delay 0 check yes", 500) == 1 + 6);
    CHECK(builds(s, "every 10 delay 0 check yes", 500) == 1 + 6);
    CHECK(builds(s, "every 1 delay 100 check yes", 500) == 1 + 5);  // at 100, 200, ..., 500
  }
}

// Two beads of types 1 and 2 fly head-on at 0.5 m/s each (relative 1 m/s)
// through the same line; a pair of type-1 beads does the same further away.
// With neigh_modify exclude type 1 2 the mixed pair never enters the
// neighbour list: they pass through each other with unchanged velocities,
// while the type-1 pair still bounces (relative speed e = 0.5 times 1 m/s).
TEST_CASE("neigh_modify exclude type removes contacts between those types", "[run][neighbor]") {
  for (const bool exclude : {false, true}) {
    INFO((exclude ? "excluded" : "not excluded"));
    Sim s;
    s.lines(setup(2));
    s.lines({"create_atoms 1 single -0.0015 0 0 units box", "create_atoms 2 single 0.0015 0 0 units box",
             "create_atoms 1 single -0.0015 0.01 0 units box",
             "create_atoms 1 single 0.0015 0.01 0 units box", "set group all diameter 0.002 density 2500",
             "set atom 1 vx 0.5", "set atom 2 vx -0.5", "set atom 3 vx 0.5", "set atom 4 vx -0.5"});
    if (exclude) s.cmd("neigh_modify exclude type 1 2");
    s.cmd("run 1500");  // 15 ms: about 5 mm of travel each
    const auto& p = s.p();
    const int a = s.index(1), b = s.index(2), c = s.index(3), d = s.index(4);
    if (exclude) {
      CHECK(p.v[a][0] == 0.5);  // untouched
      CHECK(p.v[b][0] == -0.5);
      CHECK(p.x[a][0] > p.x[b][0] + 0.002);  // passed through each other
    } else {
      CHECK(p.v[b][0] - p.v[a][0] == Approx(0.5).epsilon(0.02));
      CHECK(p.x[a][0] < p.x[b][0]);
    }
    // the type-1 pair bounces either way
    CHECK(p.v[d][0] - p.v[c][0] == Approx(0.5).epsilon(0.02));
    CHECK(p.x[c][0] < p.x[d][0]);
  }
}
