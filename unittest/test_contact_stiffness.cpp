// model hooke/stiffness and hertz/stiffness (kn, kt, gamman, gammat given
// directly) against LIGGGHTS 3.8: an oblique collision of two spheres of
// different types and sizes, and a sphere thrown at a wall/gran plane under
// gravity, give LIGGGHTS' velocities, position and spin to 13 digits in every
// variant (absolute_damping, tangential_damping off, limitForce). The stored
// figures are LIGGGHTS' thermo output (%22.16g) of the same script (this
// file's collision() and wall() scripts; `liggghts -in in.hs -var model ...`).
// Also: the material properties each model requires, and the timestep
// warning for linear springs.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

const std::vector<std::string> kMaterials = {
    "fix m1 all property/global kn peratomtypepair 2 1000 1200 1200 1500",
    "fix m2 all property/global kt peratomtypepair 2 800 900 900 1000",
    "fix m3 all property/global gamman peratomtypepair 2 30 35 35 40",
    "fix m4 all property/global gammat peratomtypepair 2 20 25 25 30",
    "fix m5 all property/global coefficientFriction peratomtypepair 2 0.3 0.3 0.3 0.3",
    "fix m6 all property/global gamman_abs peratomtypepair 2 0.01 0.012 0.012 0.014",
    "fix m7 all property/global gammat_abs peratomtypepair 2 0.005 0.006 0.006 0.007"};

std::vector<std::string> head() {
  return granary::test::liggghts_head("-0.05 0.05 -0.05 0.05 -0.05 0.05", 2);
}

struct State {
  Vec3 x1, v1, v2, w2;
};

State collision(const std::string& model, int steps) {
  granary::test::ScriptEngine s;
  s.cmds(head());
  s.cmds(kMaterials);
  s.cmds({"pair_style gran model " + model, "pair_coeff * *", "create_atoms 1 single 0 0 0",
          "create_atoms 2 single 0.0035 0.001 0", "set atom 1 diameter 0.004 density 2500",
          "set atom 2 diameter 0.003 density 2000", "velocity all set 0 0 0", "set atom 2 vx -0.5 vy 0.05",
          "timestep 1e-6", "fix integr all nve/sphere", "run " + std::to_string(steps)});
  const auto& p = s.p();
  const int a = p.id[0] == 1 ? 0 : 1, b = 1 - a;
  return {p.x[a], p.v[a], p.v[b], p.omega[b]};
}

void same(double granary, double liggghts) {
  CHECK(granary == Approx(liggghts).epsilon(1e-13).margin(1e-18));
}

}  // namespace

TEST_CASE("hooke/stiffness and hertz/stiffness collisions match LIGGGHTS 3.8",
          "[contact][liggghts_reference]") {
  struct Case {
    std::string model;
    int steps;
    double x1, vx1, vy1, vx2, vy2, wz2;  // LIGGGHTS 3.8, step `steps`
  };
  const std::vector<Case> cases = {
      {"hooke/stiffness tangential history", 3000, -0.0005667893038893488, -0.2270268184303157,
       -0.05308394803608481, 0.1726720546083427, 0.2072857719587692, 82.6866493096047},
      {"hooke/stiffness tangential history absolute_damping on", 3000, -0.0005401485381353545,
       -0.2153862425756881, -0.04945570063396118, 0.1381814594835209, 0.1965354092858108, 82.37964011123164},
      {"hooke/stiffness tangential history limitForce on", 3000, -0.0005667911607901773, -0.2270276317903022,
       -0.05308396258359181, 0.1726744645638581, 0.2072858150624936, 82.68780356536506},
      {"hertz/stiffness tangential history", 20000, -0.002090671153116495, -0.1439738065699959,
       -0.0889159728081331, -0.07341094349630303, 0.3134547342463229, 137.6589309142053},
      {"hertz/stiffness tangential history tangential_damping off", 20000, -0.002090676403983269,
       -0.1439743748614651, -0.08891575761694076, -0.07340925966973552, 0.3134540966427896,
       137.6616346306769},
  };
  for (const Case& c : cases) {
    INFO("model " << c.model);
    const State st = collision(c.model, c.steps);
    same(st.x1.x(), c.x1);
    same(st.v1.x(), c.vx1);
    same(st.v1.y(), c.vy1);
    same(st.v2.x(), c.vx2);
    same(st.v2.y(), c.vy2);
    same(st.w2.z(), c.wz2);
  }
}

TEST_CASE("hooke/stiffness and hertz/stiffness against a wall/gran plane match LIGGGHTS 3.8",
          "[contact][liggghts_reference]") {
  struct Case {
    std::string model;
    double z, vx, vz, wy;  // LIGGGHTS 3.8 after 20000 steps
  };
  const std::vector<Case> cases = {
      {"hooke/stiffness", -0.0006476822621743273, 0.1310897432950233, 0.3429445091556399, 83.45073357738519},
      // the softer Hertzian spring lets the sphere through the plane in both programs
      {"hertz/stiffness", -0.01871296263997803, 0.1484583802830444, -0.6925220336350332, -0.596163804790079}};
  for (const Case& c : cases) {
    INFO("model " << c.model);
    granary::test::ScriptEngine s;
    s.cmds(head());
    s.cmds({kMaterials[0], kMaterials[1], kMaterials[2], kMaterials[3], kMaterials[4]});
    s.cmds({"pair_style gran model " + c.model + " tangential history", "pair_coeff * *",
            "fix wall all wall/gran model " + c.model + " tangential history primitive type 2 zplane -0.01",
            "create_atoms 1 single 0 0 -0.007", "set atom 1 diameter 0.004 density 2500",
            "velocity all set 0.2 0 -0.5", "timestep 1e-6", "fix integr all nve/sphere",
            "fix gravi all gravity 9.81 vector 0 0 -1", "run 20000"});
    const auto& p = s.p();
    same(p.x[0].z(), c.z);
    same(p.v[0].x(), c.vx);
    same(p.v[0].z(), c.vz);
    same(p.omega[0].y(), c.wy);
  }
}

TEST_CASE("the stiffness models' materials, keywords and timestep warning", "[contact][errors]") {
  granary::test::ScriptEngine s;
  s.cmds(head());
  s.cmds({"create_atoms 1 single 0 0 0", "set atom 1 diameter 0.004 density 2500", "timestep 1e-6",
          "fix integr all nve/sphere"});
  s.cmds({kMaterials[0], kMaterials[2], kMaterials[3], kMaterials[4]});
  s.cmds({"pair_style gran model hooke/stiffness tangential history", "pair_coeff * *"});
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("'kt'"));
  s.cmd(kMaterials[1]);
  s.cmd("run 1");  // youngsModulus, poissonsRatio and coefficientRestitution are not needed
  s.cmd("pair_style gran model hooke/stiffness tangential history absolute_damping on");
  s.cmd("pair_coeff * *");
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("gamman_abs"));
  CHECK_THROWS_WITH(s.cmd("pair_style gran model hertz/stiffness absolute_damping on"),
                    Contains("'absolute_damping' applies only to 'model hooke/stiffness'"));
  s.cmds({"pair_style gran model hooke/stiffness tangential history", "pair_coeff * *",
          "fix y all property/global youngsModulus peratomtype 5e6 5e6"});
  CHECK_THROWS_WITH(s.cmd("run 1"), Contains("must be given together"));
  s.cmd("fix nu all property/global poissonsRatio peratomtype 0.3 0.3");
  s.cmd("run 1");
  // a timestep longer than 20 % of the springs' contact time pi sqrt(m / (2 kn)) warns
  const double m = 2500 * 4.0 / 3.0 * 3.14159265358979323846 * 8e-9;
  const double tc = 3.14159265358979323846 * std::sqrt(m / (2 * 1000));
  const std::string log = "test_contact_stiffness.log";
  s.cmd("log " + log);
  s.cmd("timestep " + std::to_string(0.19 * tc));
  s.cmd("run 1");
  s.cmd("timestep " + std::to_string(0.3 * tc));
  s.cmd("run 1");
  s.cmd("log none");
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string warning = "the contact time pi sqrt(m/(2 kn)) of the stiffest linear spring";
  const auto first = text.find(warning);
  CHECK(first != std::string::npos);
  CHECK(text.find(warning, first + 1) == std::string::npos);  // once, for the longer timestep
  CHECK(text.find("30%") != std::string::npos);
}
