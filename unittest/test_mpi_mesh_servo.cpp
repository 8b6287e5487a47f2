// fix mesh/surface/stress/servo on 1, 2 and 4 ranks (run by ctest at each
// count): LIGGGHTS 3.8's approach of a servo plate pressing a sphere onto the
// floor (ctrlPV force) and turning onto it (ctrlPV torque), from
// unittest/scripts/servo (references unittest/reference/servo_*.liggghts.log);
// the Hertz equilibrium of the target force; the integral term; the state
// across a restart file; the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/modify.h"
#include "core/variable.h"
#include "fix/fix.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

namespace fs = std::filesystem;
using granary::test::world_rank;
using granary::test::world_size;

const fs::path kScripts = fs::path(GRANARY_SOURCE_DIR) / "unittest/scripts/servo";

// Runs unittest/scripts/servo/in.servo with these variables (index variables
// defined first win over the script's defaults).
void run_script(granary::test::ScriptEngine& s, const std::string& vars) {
  s.cmd("variable meshfile index " + (kScripts / "plate.stl").string());
  if (!vars.empty()) s.cmd(vars);
  s.cmd("include " + (kScripts / "in.servo").string());
}

struct Row {
  long step;
  double force, torque, com_z, z1;
};

// The rows of the thermo table of a LIGGGHTS log of in.servo
// (step atoms ke f_servo[3] f_servo[4] f_servo[9] v_z1).
std::vector<Row> liggghts_rows(const std::string& name) {
  std::ifstream in(fs::path(GRANARY_SOURCE_DIR) / "unittest/reference" / name);
  std::string line;
  std::vector<Row> rows;
  bool table = false;
  while (std::getline(in, line)) {
    if (line.find("Step") != std::string::npos && line.find("Atoms") != std::string::npos) {
      table = true;
      continue;
    }
    if (!table) continue;
    std::istringstream ls(line);
    Row r;
    double atoms, ke;
    if (!(ls >> r.step >> atoms >> ke >> r.force >> r.torque >> r.com_z >> r.z1)) break;
    rows.push_back(r);
  }
  return rows;
}

Row now(granary::test::ScriptEngine& s) {
  granary::Fix* f = s.e.modify->find_fix("servo");
  REQUIRE(f != nullptr);
  auto& v = s.e.input->variables();
  return Row{0, f->compute_vector(2), f->compute_vector(3), f->compute_vector(8), v.compute_equal("z1")};
}

void compare_with(const std::string& log, const std::string& vars, int every, double tol) {
  const auto ref = liggghts_rows(log);
  REQUIRE(ref.size() >= 10);
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  run_script(s, vars + "\nvariable nrun index 0");
  for (std::size_t k = 1; k < ref.size(); ++k) {
    s.cmd("run " + std::to_string(every));
    const Row g = now(s);
    INFO(log << ", step " << ref[k].step);
    // both programs integrate the same contacts with round-off differences
    // (and turn the mesh by different rotation formulas): `tol` relative
    CHECK(g.force == Approx(ref[k].force).epsilon(tol).margin(1e-12));
    CHECK(g.torque == Approx(ref[k].torque).epsilon(tol).margin(1e-14));
    CHECK(g.com_z == Approx(ref[k].com_z).epsilon(tol));
    CHECK(g.z1 == Approx(ref[k].z1).epsilon(tol));
  }
}

}  // namespace

TEST_CASE("servo wall, ctrlPV force: LIGGGHTS 3.8's approach of a plate pressing a sphere onto the floor",
          "[servo][mpi][liggghts]") {
  // observed: the same to the 10 digits LIGGGHTS prints
  compare_with("servo_force.liggghts.log", "", 4000, 1e-7);
}

TEST_CASE("servo wall, ctrlPV torque: LIGGGHTS 3.8's plate turning onto a sphere off the axis",
          "[servo][mpi][liggghts]") {
  // observed: 2e-6 at most (the rotation of the nodes)
  compare_with("servo_torque.liggghts.log",
               "variable ctrl index torque\nvariable ax index \"1 0 0\"\nvariable ys index 0.008\n"
               "variable tv index -0.002\nvariable kp index 0.1",
               2000, 2e-5);
}

TEST_CASE("servo wall, PID: LIGGGHTS 3.8's overshoot and return with integral and derivative terms",
          "[servo][mpi][liggghts]") {
  // observed: the same to the 10 digits LIGGGHTS prints
  compare_with("servo_pid.liggghts.log",
               "variable kp index 0.05\nvariable ki index 5\nvariable kd index 1e-7", 2000, 1e-7);
}

TEST_CASE("servo wall: at rest the plate holds the sphere with the Hertz overlap of the target force",
          "[servo][mpi]") {
  // Between the plate and the floor (same material, no gravity) the sphere
  // has the overlap d of F = 4/3 E* sqrt(R) d^1.5 at both contacts, with
  // 1/E* = 2 (1 - nu^2) / E: the plate stands at 2 R - 2 d.
  for (double target : {0.5, 0.2}) {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    std::ostringstream vars;
    vars << "variable kp index 0.1\nvariable tv index " << -target << "\nvariable nrun index 40000";
    run_script(s, vars.str());
    const double e_star = 5e6 / (2.0 * (1.0 - 0.45 * 0.45)), r = 1e-3;
    const double d = std::pow(target / (4.0 / 3.0 * e_star * std::sqrt(r)), 2.0 / 3.0);
    const Row g = now(s);
    INFO("target " << target << " N, overlap " << d);
    CHECK(g.force == Approx(target).epsilon(1e-9));
    CHECK(g.com_z == Approx(2.0 * r - 2.0 * d).epsilon(1e-9));
    CHECK(g.z1 == Approx(r - d).epsilon(1e-9));
  }
}

TEST_CASE("servo wall: fix_modify changes the target, the gains and vel_max, and stops the wall",
          "[servo][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  run_script(s, "variable kp index 0.1\nvariable nrun index 40000");
  const double e_star = 5e6 / (2.0 * (1.0 - 0.45 * 0.45)), r = 1e-3;
  auto overlap = [&](double f) { return std::pow(f / (4.0 / 3.0 * e_star * std::sqrt(r)), 2.0 / 3.0); };
  CHECK(now(s).com_z == Approx(2.0 * r - 2.0 * overlap(0.5)).epsilon(1e-9));
  // a new target: the new Hertz equilibrium
  s.cmds({"fix_modify servo servo/target_val -0.2 servo/ctrlParam 0.2 0 0 servo/vel_max 0.5", "run 40000"});
  CHECK(now(s).force == Approx(0.2).epsilon(1e-9));
  CHECK(now(s).com_z == Approx(2.0 * r - 2.0 * overlap(0.2)).epsilon(1e-9));
  // stopped: the wall stays where it is whatever the force
  const double z = now(s).com_z;
  s.cmds({"fix_modify servo servo/integrate stop servo/target_val -0.9", "run 5000"});
  CHECK(now(s).com_z == z);
  CHECK(now(s).force == Approx(0.2).epsilon(1e-9));
  s.cmds({"fix_modify servo servo/integrate start", "run 40000"});
  CHECK(now(s).force == Approx(0.9).epsilon(1e-6));
  // errors
  CHECK_THROWS_WITH(s.cmd("fix_modify servo servo/target_val 0"), Contains("must be a non-zero number"));
  CHECK_THROWS_WITH(s.cmd("fix_modify servo servo/ctrlParam 1 2"), Contains("needs 3 value(s)"));
  CHECK_THROWS_WITH(s.cmd("fix_modify servo servo/integrate maybe"), Contains("expected start or stop"));
  CHECK_THROWS_WITH(s.cmd("fix_modify servo colour red"), Contains("has no keyword 'colour'"));
  CHECK_THROWS_WITH(s.cmd("fix_modify servo energy yes"), Contains("contributes no potential energy"));
  s.cmd("fix_modify servo energy no");
  CHECK_THROWS_WITH(s.cmd("fix_modify nothing energy no"), Contains("nothing"));
  CHECK_THROWS_WITH(s.cmd("fix_modify floor servo/target_val 1"),
                    Contains("has no keyword 'servo/target_val'"));
}

TEST_CASE("servo wall: the integral term, its saturation and the proportional term before contact",
          "[servo][mpi]") {
  // Away from the particles the error is -1 (target -0.5, no force):
  // kp alone moves the plate at kp vel_max; ki alone accelerates it at
  // ki vel_max (z = z0 - ki vel_max t^2 / 2, t counted from the second step,
  // the first one's forces setting the first velocity) up to vel_max, where
  // the integral stops growing (anti-windup): a rate of vel_max at once
  // after the error changes sign.
  const double dt = 2e-6;
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    run_script(
        s,
        "variable zp index 0.01\nvariable kp index 0.02\nvariable vmax index 0.5\nvariable nrun index 1000");
    CHECK(now(s).com_z == Approx(0.01 - 0.02 * 0.5 * 999 * dt).epsilon(1e-12));
  }
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    run_script(
        s, "variable zp index 0.01\nvariable kp index 0\nvariable ki index 100\nvariable nrun index 1000");
    // velocity after n steps ki vmax n dt (n = 1..999), saturating at vmax
    double z = 0.01;
    for (int n = 1; n < 1000; ++n)
      z -= std::min(1.0, 100.0 * n * dt) * dt;
    CHECK(now(s).com_z == Approx(z).epsilon(1e-12));
  }
}

TEST_CASE("servo wall: the run goes on across a restart file as if it had not stopped", "[servo][mpi]") {
  const std::string dir = "servo_np" + std::to_string(world_size());
  if (world_rank() == 0) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  const std::string vars = "variable kp index 0.05\nvariable ki index 5\nvariable kd index 1e-7";
  Row straight;
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    run_script(s, vars + "\nvariable nrun index 12000");
    straight = now(s);
  }
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    run_script(s, vars + "\nvariable nrun index 7000");
    s.cmd("write_restart " + dir + "/servo.restart");
  }
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"read_restart " + dir + "/servo.restart",
          "variable meshfile index " + (kScripts / "plate.stl").string(),
          "fix m1 all property/global youngsModulus peratomtype 5.e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.45",
          "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5",
          "fix m4 all property/global coefficientFriction peratomtypepair 1 0.3",
          "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 0.000002",
          "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
          "fix servo all mesh/surface/stress/servo file ${meshfile} type 1 move 0 0 0.0021 com 0 0 0.0021 "
          "ctrlPV force axis 0 0 1 target_val -0.5 vel_max 1.0 kp 0.05 ki 5 kd 1e-7",
          "fix walls all wall/gran model hertz tangential history mesh n_meshes 1 meshes servo",
          "fix integr all nve/sphere", "variable z1 equal z[1]", "run 5000"});
  const Row g = now(s);
  CHECK(g.force > 0.1);  // in contact
  CHECK(g.force == Approx(straight.force).epsilon(1e-9));
  CHECK(g.com_z == Approx(straight.com_z).epsilon(1e-12));
  CHECK(g.z1 == Approx(straight.z1).epsilon(1e-12));
}

TEST_CASE("servo wall: errors name what is wrong", "[servo][mpi]") {
  const std::string head =
      "fix s all mesh/surface/stress/servo file " + (kScripts / "plate.stl").string() + " type 1 ";
  const std::string full = "com 0 0 0 ctrlPV force axis 0 0 1 target_val -1 vel_max 1 ";
  struct Case {
    std::string args, expect;
  };
  const std::vector<Case> cases = {
      {"ctrlPV force axis 0 0 1 target_val -1 vel_max 1", "missing 'com CX CY CZ'"},
      {"com 0 0 0 ctrlPV force axis 0 0 1 vel_max 1", "missing 'target_val V'"},
      {"com 0 0 0 ctrlPV force axis 0 0 1 target_val -1", "missing 'vel_max VM'"},
      {"com 0 0 0 ctrlPV speed axis 0 0 1 target_val -1 vel_max 1", "ctrlPV must be 'force' or 'torque'"},
      {"com 0 0 0 ctrlPV force axis 0 0 0 target_val -1 vel_max 1", "non-zero vector"},
      {"com 0 0 0 ctrlPV force axis 0 0 1 target_val 0 vel_max 1", "target_val must be a non-zero number"},
      {full + "mode auto", "mode auto) is not supported"},
      {full + "kp -1", "kp must be a number >= 0"},
      {full + "reference_point 0 0 0", "the torque is taken about com"},
      {"com 0 0 0 ctrlPV force axis v_a 0 1 target_val -1 vel_max 1", "a variable is not supported here"},
      {"com 0 0 ctrlPV force", "'com' needs 3 value(s)"},
  };
  for (const auto& c : cases) {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(granary::test::liggghts_head("-0.04 0.04 -0.02 0.02 -0.01 0.02", 1));
    INFO(c.args);
    CHECK_THROWS_WITH(s.cmd(head + c.args), Contains(c.expect));
  }
  {  // too fast for the neighbour skin; moved by another fix
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    CHECK_THROWS_WITH(run_script(s, "variable vmax index 200\nvariable nrun index 0"),
                      Contains("vel_max 200 m/s moves the wall 0.0004 m in a step, not less than half the "
                               "neighbour skin (0.00025 m)"));
    CHECK_THROWS_WITH(s.cmd("fix mv all move/mesh mesh servo linear 0 0 1"), Contains("is a servo wall"));
  }
}
