// Bad input gives a clear error: the message names what is wrong and says how
// to fix it, and nothing runs. Errors while a run is under way (particles
// lost, timestep check) raise RunError, or a warning when the script asks for
// one. Errors in scripts run by the granary program end it with a non-zero
// exit status and "ERROR: file:line: ..." (with the include chain).
#include <sys/wait.h>

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
#include "core/update.h"
#include "particles/particles.h"

using Catch::Contains;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

struct Sim : granary::test::ScriptEngine {
  Sim() : ScriptEngine(MPI_COMM_SELF) {}
};

/// The message of the InputError that `line` raises (fails the test when it
/// raises nothing or something else).
std::string input_error(Sim& s, const std::string& line) {
  try {
    s.cmd(line);
  } catch (const granary::InputError& err) {
    return err.what();
  } catch (const std::exception& err) {
    FAIL("'" << line << "' raised something other than InputError: " << err.what());
  }
  FAIL("'" << line << "' raised no error");
  return "";
}

/// Same for RunError.
std::string run_error(Sim& s, const std::string& line) {
  try {
    s.cmd(line);
  } catch (const granary::RunError& err) {
    return err.what();
  } catch (const std::exception& err) {
    FAIL("'" << line << "' raised something other than RunError: " << err.what());
  }
  FAIL("'" << line << "' raised no error");
  return "";
}

std::string read_text(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

/// Box, material and granular pair style for one bead type (beads of
/// diameter 2 mm and density 2500 are set by the caller; Y = 5 MPa, nu = 0.3).
std::vector<std::string> granular_setup(const std::string& boundary = "m m m",
                                        const std::string& box = "0 0.01 0 0.01 0 0.01") {
  return {
      "units si",
      "atom_style granular",
      "boundary " + boundary,
      "region box block " + box + " units box",
      "create_box 1 box",
      "neighbor 0.001 bin",
      "fix m1 all property/global youngsModulus peratomtype 5e6",
      "fix m2 all property/global poissonsRatio peratomtype 0.3",
      "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5",
      "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5",
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
  };
}

// Rayleigh time of the beads above: pi r sqrt(rho/G)/(0.1631 nu + 0.8766) with
// G = Y/(2(1+nu)) = 1.923 MPa: 1.2244e-4 s.
double rayleigh_time() {
  const double r = 0.001, rho = 2500, Y = 5e6, nu = 0.3;
  const double G = Y / (2 * (1 + nu));
  return kPi * r * std::sqrt(rho / G) / (0.1631 * nu + 0.8766);
}

// Hertz time of fix check/timestep/gran, LIGGGHTS 3.8's estimate: a bead's own
// mass and radius at the largest speed v, 2.87 (m^2/(r Y*^2 v))^(1/5) with
// Y* = Y/(2(1-nu^2)) (on the pour of unittest/scripts/in.pour_small this gives
// LIGGGHTS' f_ID[2] at step 1000, 0.030757083, to all printed digits).
double hertz_time(double v) {
  const double r = 0.001, rho = 2500, Y = 5e6, nu = 0.3;
  const double m = rho * 4.0 / 3.0 * kPi * r * r * r;
  const double yeff = Y / (2 * (1 - nu * nu));
  return 2.87 * std::pow(m * m / (r * yeff * yeff * v), 0.2);
}

}  // namespace

// ---------------------------------------------------------------- commands and styles

TEST_CASE("unknown commands and styles suggest the closest name", "[errors]") {
  Sim s;
  CHECK_THAT(input_error(s, "timestpe 1e-5"),
             Contains("unknown command 'timestpe'") && Contains("did you mean 'timestep'?"));
  CHECK_THAT(input_error(s, "pair_style grann model hertz"),
             Contains("unknown pair style 'grann'") && Contains("did you mean 'gran'?"));
  CHECK_THAT(input_error(s, "region r blok 0 1 0 1 0 1 units box"),
             Contains("unknown region style 'blok'") && Contains("did you mean 'block'?"));
  s.lines({"units si", "atom_style granular", "region box block 0 1 0 1 0 1 units box", "create_box 1 box"});
  CHECK_THAT(input_error(s, "fix g all gravty 9.81 vector 0 0 -1"),
             Contains("unknown fix style 'gravty'") && Contains("did you mean 'gravity'?"));
  CHECK_THAT(input_error(s, "compute r all erotate/sphre"),
             Contains("unknown compute style 'erotate/sphre'") && Contains("did you mean 'erotate/sphere'?"));
  // nothing was created by the failed commands
  CHECK_THAT(input_error(s, "unfix g"), Contains("unknown fix ID 'g'"));
}

TEST_CASE("wrong argument counts and bad numbers name the command and its usage", "[errors]") {
  Sim s;
  CHECK_THAT(input_error(s, "timestep"),
             Contains("wrong number of arguments (0, expected 1)") && Contains("usage: timestep DT"));
  CHECK_THAT(input_error(s, "timestep 1e-5 2e-5"), Contains("wrong number of arguments (2, expected 1)"));
  CHECK_THAT(input_error(s, "timestep abc"), Contains("expected a number for timestep, got 'abc'"));
  CHECK_THAT(input_error(s, "timestep -1e-5"), Contains("timestep must be positive"));
  CHECK_THAT(input_error(s, "run many"), Contains("expected an integer for run steps, got 'many'"));
  CHECK_THAT(input_error(s, "thermo 1.5"), Contains("expected an integer for thermo, got '1.5'"));
  CHECK(s.e.update->dt == 1e-8);  // unchanged
}

TEST_CASE("commands in the wrong order say what must come first", "[errors]") {
  {
    Sim s;
    CHECK_THAT(input_error(s, "run 10"), Contains("run needs a simulation box") && Contains("create_box"));
    CHECK(s.e.update->ntimestep == 0);
  }
  {
    Sim s;
    CHECK_THAT(input_error(s, "fix g all gravity 9.81 vector 0 0 -1"),
               Contains("fix needs the box") && Contains("create_box"));
  }
  {
    Sim s;
    s.lines(
        {"units si", "atom_style granular", "region box block 0 1 0 1 0 1 units box", "create_box 1 box"});
    CHECK_THAT(input_error(s, "pair_coeff * *"),
               Contains("pair_coeff needs a pair style: use pair_style first"));
    CHECK_THAT(input_error(s, "boundary p p p"), Contains("boundary must come before the box is created"));
  }
  {
    // a granular pair style without pair_coeff: the run stops before step 1
    Sim s;
    auto script = granular_setup();
    script.pop_back();
    s.lines(script);
    s.lines({"create_atoms 1 single 0.005 0.005 0.005 units box", "set type 1 diameter 0.002 density 2500",
             "fix integr all nve/sphere"});
    CHECK_THAT(input_error(s, "run 10"), Contains("needs 'pair_coeff * *' before run"));
    CHECK(s.e.update->ntimestep == 0);
  }
}

TEST_CASE("settings with a bad value are rejected with the accepted values", "[errors]") {
  Sim s;
  CHECK_THAT(input_error(s, "processors 2 1 1"),
             Contains("processors 2 1 1 does not divide the 1 MPI ranks"));
  CHECK_THAT(input_error(s, "thermo_style custom step kee"),
             Contains("unknown thermo keyword 'kee'") && Contains("did you mean 'ke'?"));
  CHECK_THAT(input_error(s, "neigh_modify evrey 5"),
             Contains("unknown neigh_modify keyword 'evrey'") && Contains("expected every, delay, check"));
  CHECK_THAT(input_error(s, "boundary f x f"), Contains("boundary letter 'x' is not one of p f s m"));
  CHECK_THAT(input_error(s, "thermo_modify lost maybe"), Contains("lost takes error, warn or ignore"));
  CHECK_THAT(input_error(s, "soft_particles maybe"), Contains("soft_particles"));
  CHECK_THAT(input_error(s, "hard_particles"), Contains("hard_particles yes|no"));
  s.cmds({"soft_particles yes", "hard_particles on"});  // accepted (Granary limits no Young's modulus)
  s.cmd("region half block INF INF 0 1 0 1 units box");
  CHECK_THAT(input_error(s, "create_box 1 half"),
             Contains("create_box needs a bounded region") && Contains("'half' has no finite bounds"));
  s.cmd("region wall plane 0 0 0 0 0 1 units box");
  CHECK_THAT(input_error(s, "create_box 1 wall"), Contains("create_box needs a bounded region"));
  CHECK_THAT(input_error(s, "create_box 1 nowhere"), Contains("unknown region 'nowhere'"));
  // the box was never made
  CHECK_THAT(input_error(s, "run 1"), Contains("run needs a simulation box"));
}

// Sizes that would overflow a count (found by fuzz_run: 5000000 types squared)
// are refused with the limit, and a wrong value count names the product.
TEST_CASE("property/global refuses absurd sizes and names the value count it needs", "[errors]") {
  Sim s;
  s.cmd("region b block 0 1 0 1 0 1 units box");
  s.cmd("create_box 2 b");
  CHECK_THAT(input_error(s, "fix m all property/global coefficientFriction peratomtypepair 5000000 0.3"),
             Contains("size 5000000 is too large (at most 100000)"));
  CHECK_THAT(input_error(s, "fix m all property/global k matrix 3000000000 1"), Contains("is too large"));
  CHECK_THAT(input_error(s, "fix m all property/global coefficientFriction peratomtypepair 3 0.3"),
             Contains("needs 9 values (3 x 3), got 1"));
  CHECK_THAT(input_error(s, "fix m all property/global coefficientFriction peratomtypepair 0 0.3"),
             Contains("needs a positive size"));
}

// ---------------------------------------------------------------- timestep

// dt = 2e-4 s exceeds the Rayleigh time 1.22e-4 s of the beads: the pair style
// refuses to start the run and proposes 20% of the Rayleigh time.
TEST_CASE("a timestep longer than the Rayleigh time stops the run before it starts", "[errors]") {
  Sim s;
  s.lines(granular_setup());
  s.lines({"create_atoms 1 single 0.005 0.005 0.005 units box", "set type 1 diameter 0.002 density 2500",
           "fix integr all nve/sphere", "timestep 2e-4"});
  const std::string msg = input_error(s, "run 100");
  CHECK_THAT(msg, Contains("Rayleigh time") && Contains("Use a timestep below"));
  char expected[64];
  std::snprintf(expected, sizeof expected, "%g s", rayleigh_time());
  CHECK_THAT(msg, Contains(expected));  // the Rayleigh time itself
  CHECK(s.e.update->ntimestep == 0);
  // with a timestep below the Rayleigh time it runs
  s.cmd("timestep 2e-5");
  s.cmd("run 100");
  CHECK(s.e.update->ntimestep == 100);
}

// One bead flying at 1 m/s with dt = 3e-5 s: dt/t_R = 3e-5/1.2244e-4 = 0.245
// is above the fraction 0.2 and dt/t_H = 3e-5/t_H(1 m/s) = 0.087 above 0.08, so
// the fix warns (default) and reports both ratios as f_ID[1] and f_ID[2];
// f_ID[3] = 2 v dt / skin = 2 * 1 * 3e-5 / 0.001 = 0.06.
TEST_CASE("fix check/timestep/gran reports the Rayleigh and Hertz ratios and warns", "[errors]") {
  const std::string log = "test_errors_check_timestep.log";
  Sim s;
  s.cmd("log " + log);
  s.lines(granular_setup());
  s.lines({"create_atoms 1 single 0.005 0.005 0.005 units box", "set type 1 diameter 0.002 density 2500",
           "velocity all set 0.6 0.0 0.8", "fix integr all nve/sphere", "timestep 3e-5",
           "fix ts all check/timestep/gran 10 0.2 0.08", "run 50", "log none"});
  const double ratio_r = 3e-5 / rayleigh_time(), ratio_h = 3e-5 / hertz_time(1.0);
  INFO("expected dt/t_R = " << ratio_r << ", dt/t_H = " << ratio_h);
  CHECK(s.e.fix_value("ts", 1) == Approx(ratio_r).epsilon(1e-12));
  CHECK(s.e.fix_value("ts", 2) == Approx(ratio_h).epsilon(1e-9));
  CHECK(ratio_r == Approx(0.245).epsilon(0.01));
  CHECK(ratio_h > 0.08);
  CHECK(s.e.fix_value("ts", 3) == Approx(2 * 1.0 * 3e-5 / 0.001).epsilon(1e-12));
  CHECK(s.e.update->ntimestep == 50);  // a warning does not stop the run
  const std::string text = read_text(log);
  std::remove(log.c_str());
  CHECK_THAT(text, Contains("WARNING: step 0: timestep 3e-05 s is 24.5% of the Rayleigh time (limit 20%)"));
  CHECK_THAT(text, Contains("reduce the timestep"));
}

// vmax V: the speed of the Hertz estimate is at least V (a bead at rest here),
// and a step in which particles may approach by more than the skin is reported.
TEST_CASE("fix check/timestep/gran vmax keyword and the skin check", "[errors]") {
  Sim s;
  s.lines(granular_setup());
  s.lines({"create_atoms 1 single 0.005 0.005 0.005 units box", "set type 1 diameter 0.002 density 2500",
           "fix integr all nve/sphere", "timestep 1e-5", "fix ts all check/timestep/gran 10 0.9 0.9 vmax 2.0",
           "run 10"});
  CHECK(s.e.fix_value("ts", 2) == Approx(1e-5 / hertz_time(2.0)).epsilon(1e-9));
  CHECK(s.e.fix_value("ts", 3) == Approx(2 * 2.0 * 1e-5 / 0.001).epsilon(1e-12));
  // 2 v dt = 2 * 60 * 1e-5 = 1.2 mm > skin 1 mm
  s.lines({"velocity all set 60.0 0.0 0.0", "fix ts all check/timestep/gran 1 0.99 0.99 error yes"});
  CHECK_THAT(run_error(s, "run 1"), Contains("neighbour skin"));
}

// `error yes` turns the warning into a RunError. The bead falls from 1 m/s
// under gravity, so t_H shrinks as v^(-1/5); the limit on dt/t_H is set 3%
// above its value at the start, which is crossed when v = 1.03^5 = 1.159 m/s,
// i.e. at t = 0.159/9.81 s = step 812 of 2e-5 s. The fix checks every 10 steps,
// so the run stops at step 820.
TEST_CASE("fix check/timestep/gran with error yes stops the run", "[errors]") {
  const double dt = 2e-5, g = 9.81;
  const double limit = 1.03 * dt / hertz_time(1.0);
  long long expected = 0;
  for (long long n = 10; expected == 0; n += 10)
    if (dt / hertz_time(1.0 + g * n * dt) > limit) expected = n;
  REQUIRE(expected == 820);
  Sim s;
  s.lines(granular_setup());
  s.lines({"create_atoms 1 single 0.005 0.005 0.005 units box", "set type 1 diameter 0.002 density 2500",
           "velocity all set 0.0 0.0 -1.0", "fix gravi all gravity 9.81 vector 0 0 -1",
           "fix integr all nve/sphere", "timestep " + num(dt),
           "fix ts all check/timestep/gran 10 0.5 " + num(limit) + " error yes"});
  const std::string msg = run_error(s, "run 2000");
  CHECK_THAT(msg, Contains("step " + std::to_string(expected) + ":") && Contains("of the Hertz time"));
  CHECK(s.e.update->ntimestep == expected);
}

// ---------------------------------------------------------------- lost particles

namespace {
/// Two beads in a fixed box 0..0.01; bead 2 is shot out through x = 0.01 at
/// 5 m/s. It crosses the face at step 100 (dt = 1e-5 s) and is found outside
/// at the next neighbour-list rebuild (about every 11 steps for a skin of 1 mm).
void shoot_out(Sim& s, const std::string& lost) {
  s.lines(granular_setup("f f f"));
  s.lines({"create_atoms 1 single 0.002 0.005 0.005 units box",
           "create_atoms 1 single 0.005 0.005 0.005 units box", "set type 1 diameter 0.002 density 2500",
           "set atom 2 vx 5.0", "fix integr all nve/sphere", "timestep 1e-5",
           "thermo_style custom step atoms ke"});
  if (!lost.empty()) s.cmd("thermo_modify lost " + lost);
}
}  // namespace

TEST_CASE("a particle leaving a fixed box is an error naming the particle and the step", "[errors]") {
  Sim s;
  shoot_out(s, "");  // lost error is the default
  const std::string msg = run_error(s, "run 200");
  INFO(msg);
  CHECK_THAT(msg, Contains("1 particle(s) left the box through a fixed boundary at step"));
  CHECK_THAT(msg, Contains("(first: particle 2 at (0.01"));
  CHECK_THAT(msg, Contains("thermo_modify lost ignore"));  // how to go on
  const auto at = msg.find("at step ");
  REQUIRE(at != std::string::npos);
  const long long step = std::atoll(msg.c_str() + at + 8);
  CHECK(step > 100);
  CHECK(step <= 112);
  CHECK(s.e.update->ntimestep == step);  // the run stopped there
}

TEST_CASE("thermo_modify lost warn and lost ignore drop the particle and go on", "[errors]") {
  for (const std::string mode : {"warn", "ignore"}) {
    INFO("lost " << mode);
    const std::string log = "test_errors_lost_" + mode + ".log";
    Sim s;
    s.cmd("log " + log);
    shoot_out(s, mode);
    s.cmd("run 200");
    s.cmd("log none");
    const std::string text = read_text(log);
    std::remove(log.c_str());
    CHECK(s.e.update->ntimestep == 200);
    CHECK(s.e.particles->nlocal == 1);
    CHECK(s.e.particles->natoms == 1);
    bool found = false;
    CHECK(s.e.thermo_keyword("atoms", found) == 1.0);
    if (mode == "warn") {
      CHECK_THAT(text, Contains("WARNING: 1 particle(s) left the box through a fixed boundary at step"));
      CHECK_THAT(text, Contains("particle 2 at"));
    } else {
      CHECK_THAT(text, !Contains("WARNING"));
    }
  }
}

// ---------------------------------------------------------------- the program

namespace {
struct Program {
  int status = -1;
  std::string output;  // stdout and stderr together
};

/// Run the granary program on a script in the current directory, with a clean
/// environment (it must not take this MPI process's settings for its own).
Program run_program(const std::string& script) {
  const std::string out = script + ".out";
  const std::string cmd = "env -i PATH=\"$PATH\" HOME=\"$HOME\" " GRANARY_BINARY " -in " + script +
                          " -log none > " + out + " 2>&1 < /dev/null";
  const int rc = std::system(cmd.c_str());
  Program p;
  p.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : 128;
  p.output = read_text(out);
  std::remove(out.c_str());
  return p;
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}
}  // namespace

TEST_CASE("the program reports script errors with file and line and exits non-zero", "[errors][cli]") {
  const std::string main = "test_errors_main.in";
  write_file(main,
             "units si\n"
             "atom_style granular\n"
             "# a typo\n"
             "timestpe 1e-5\n"
             "print \"not reached\"\n");
  const Program p = run_program(main);
  std::remove(main.c_str());
  INFO(p.output);
  CHECK(p.status != 0);
  CHECK_THAT(p.output, Contains("ERROR: " + main + ":4: timestpe: unknown command 'timestpe'"));
  CHECK_THAT(p.output, Contains("did you mean 'timestep'?"));
  CHECK_THAT(p.output, !Contains("not reached"));
}

TEST_CASE("an error in an included file shows the include chain", "[errors][cli]") {
  const std::string main = "test_errors_outer.in", sub = "test_errors_inner.in";
  write_file(main,
             "units si\n"
             "include " +
                 sub +
                 "\n"
                 "print \"not reached\"\n");
  write_file(sub,
             "atom_style granular\n"
             "\n"
             "boundary f q f\n");
  const Program p = run_program(main);
  std::remove(main.c_str());
  std::remove(sub.c_str());
  INFO(p.output);
  CHECK(p.status != 0);
  CHECK_THAT(p.output, Contains("ERROR: " + sub + ":3: boundary letter 'q' is not one of p f s m"));
  CHECK_THAT(p.output, Contains("included from " + main + ":2"));
  CHECK_THAT(p.output, !Contains("not reached"));
}

// ---------------------------------------------------------------- the default timestep check

namespace {
int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
    ++n;
  return n;
}
}  // namespace

// Without fix check/timestep/gran every run compares its timestep with the
// smallest Rayleigh time of the particles (1.2244e-4 s for these beads): 3e-5 s
// is 24.5 % of it, above 20 %, and warns once for that timestep however many
// runs follow; a new timestep above the limit warns again; 2.4e-5 s (19.6 %)
// does not warn.
TEST_CASE("every run warns once when its timestep is above 20% of the Rayleigh time", "[errors]") {
  const std::string log = "test_errors_default_rayleigh.log";
  const std::string warning = "of the smallest Rayleigh time of the particles";
  Sim s;
  s.cmd("log " + log);
  s.lines(granular_setup());
  s.lines({"create_atoms 1 single 0.005 0.005 0.005 units box", "set type 1 diameter 0.002 density 2500",
           "fix integr all nve/sphere", "timestep 2.4e-5", "run 10"});
  CHECK(count(read_text(log), warning) == 0);
  s.lines({"timestep 3e-5", "run 10", "run 10"});
  std::string text = read_text(log);
  CHECK(count(text, warning) == 1);
  char expected[160];
  std::snprintf(expected, sizeof expected, "WARNING: step 10: timestep 3e-05 s is 24.5%% %s, %g s",
                warning.c_str(), rayleigh_time());
  CHECK_THAT(text, Contains(expected));
  CHECK(3e-5 / rayleigh_time() == Approx(0.245).epsilon(0.01));
  s.lines({"timestep 3.1e-5", "run 10", "log none"});
  text = read_text(log);
  std::remove(log.c_str());
  CHECK(count(text, warning) == 2);
  CHECK(s.e.update->ntimestep == 40);  // warnings do not stop runs
}

// The Hertz time of an impact shrinks as v^(-1/5): with dt = 2.4e-5 s (19.6 % of
// the Rayleigh time, no warning) a bead at 150 m/s has t_H = 1.128e-4 s, so dt
// is 21 % of it and the run warns; at 100 m/s (t_H = 1.22e-4 s, 19.7 %) it does not.
TEST_CASE("every run warns when its timestep is above 20% of the Hertz time at the highest speed",
          "[errors]") {
  for (const double v : {100.0, 150.0}) {
    INFO("v = " << v << " m/s, dt/t_H = " << 2.4e-5 / hertz_time(v));
    const std::string log = "test_errors_default_hertz.log";
    Sim s;
    s.cmd("log " + log);
    s.lines(granular_setup("m m m", "0 1 0 1 0 1"));
    s.lines({"create_atoms 1 single 0.5 0.5 0.5 units box", "set type 1 diameter 0.002 density 2500",
             "velocity all set " + num(v) + " 0 0", "fix integr all nve/sphere", "timestep 2.4e-5", "run 10",
             "log none"});
    const std::string text = read_text(log);
    std::remove(log.c_str());
    CHECK(count(text, "Rayleigh time") == 0);
    if (v < 120) {
      CHECK(2.4e-5 / hertz_time(v) < 0.2);
      CHECK(count(text, "of the Hertz time") == 0);
    } else {
      CHECK(2.4e-5 / hertz_time(v) > 0.2);
      char expected[128];
      std::snprintf(expected, sizeof expected,
                    "of the Hertz time of an impact at 150 m/s, the highest speed seen, %g s", hertz_time(v));
      CHECK_THAT(text, Contains(expected));
    }
  }
}

// A timestep of 0.95 Rayleigh times (the case that once passed without a
// word): beads driven at 10 m/s onto a floor wall, a contact the timestep
// cannot resolve, leave the fixed box (thrown back out through its top, at
// about half their speed). The run warns at its start; with lost ignore
// the loss is explained by a warning, with lost error the error names the
// timestep as the cause.
TEST_CASE("particles lost with a dangerous timestep: the warning and the error name the timestep",
          "[errors]") {
  const double dt = 0.95 * rayleigh_time();
  for (const std::string mode : {"ignore", "error"}) {
    INFO("lost " << mode);
    const std::string log = "test_errors_lost_timestep.log";
    Sim s;
    s.cmd("log " + log);
    s.lines(granular_setup("f f f", "0 0.01 0 0.01 0 0.01"));
    s.lines({"create_atoms 1 single 0.0025 0.0025 0.006 units box",
             "create_atoms 1 single 0.0075 0.0025 0.006 units box",
             "create_atoms 1 single 0.0025 0.0075 0.006 units box",
             "create_atoms 1 single 0.0075 0.0075 0.006 units box", "set type 1 diameter 0.002 density 2500",
             "velocity all set 0 0 -10",
             "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.003",
             "fix integr all nve/sphere", "timestep " + num(dt), "thermo_modify lost " + mode});
    std::string msg;
    if (mode == "ignore")
      s.cmd("run 100");
    else
      msg = run_error(s, "run 100");
    s.cmd("log none");
    const std::string text = read_text(log);
    std::remove(log.c_str());
    CHECK_THAT(text,
               Contains("WARNING: step 0: timestep") && Contains("is 95% of the smallest Rayleigh time"));
    if (mode == "ignore") {
      CHECK(s.e.particles->natoms < 4);  // lost
      CHECK(count(text, "(thermo_modify lost ignore): the timestep") == 1);
      CHECK_THAT(text, Contains("95% of the Rayleigh time") && Contains("reduce the timestep"));
    } else {
      INFO(msg);
      CHECK_THAT(msg, Contains("left the box through a fixed boundary") && Contains("the timestep") &&
                          Contains("95% of the Rayleigh time") && Contains("pass through walls"));
    }
  }
}

// With a safe timestep (10 % of the Rayleigh time) a bead shot at 200 m/s moves
// 2.4 mm per step, more than its radius: the loss names the speed.
TEST_CASE("particles lost at a speed that crosses a radius per step: the error names the speed", "[errors]") {
  Sim s;
  s.lines(granular_setup("f f f"));
  s.lines({"create_atoms 1 single 0.005 0.005 0.005 units box", "set type 1 diameter 0.002 density 2500",
           "velocity all set 200 0 0", "fix integr all nve/sphere", "timestep 1.2e-5"});
  const std::string msg = run_error(s, "run 10");
  INFO(msg);
  CHECK_THAT(msg, Contains("the fastest particle seen (200 m/s) moves 0.0024 m in one step, more than the "
                           "smallest radius 0.001 m"));
}

// The lost-particle set-up above, run by the program: the RunError ends it.
TEST_CASE("the program stops with an error when a run fails", "[errors][cli]") {
  const std::string main = "test_errors_run.in";
  std::string script;
  auto lines = granular_setup("f f f");
  lines.insert(lines.end(),
               {"create_atoms 1 single 0.002 0.005 0.005 units box",
                "create_atoms 1 single 0.005 0.005 0.005 units box", "set type 1 diameter 0.002 density 2500",
                "set atom 2 vx 5.0", "fix integr all nve/sphere", "timestep 1e-5", "run 200",
                "print \"not reached\""});
  int run_line = 0;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    script += lines[k] + "\n";
    if (lines[k] == "run 200") run_line = static_cast<int>(k) + 1;
  }
  write_file(main, script);
  const Program p = run_program(main);
  std::remove(main.c_str());
  INFO(p.output);
  CHECK(p.status != 0);
  CHECK_THAT(p.output, Contains("ERROR: " + main + ":" + std::to_string(run_line) +
                                ": run: 1 particle(s) left the box through a fixed boundary"));
  CHECK_THAT(p.output, !Contains("not reached"));
}
