// Fixes nve/limit and wall/reflect: the displacement limit per step and the
// reflection at walls against their analytic results, and nve/limit against
// LIGGGHTS 3.8 for two overlapping spheres in contact.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Engine;
using granary::Vec3;

namespace {

/// Position, velocity and spin of particle `id` (one rank).
void state(const Engine& e, long long id, Vec3& x, Vec3& v, Vec3& w) {
  const auto& p = *e.particles;
  for (int i = 0; i < p.nlocal; ++i) {
    if (p.id[i] != id) continue;
    x = p.x[i];
    v = p.v[i];
    w = p.omega[i];
    return;
  }
  FAIL("particle " << id << " not found");
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

const std::vector<std::string> kBox = {"units si",         "atom_style granular",
                                       "boundary f f f",   "region box block -0.1 0.1 -0.1 0.1 -0.1 0.1",
                                       "create_box 2 box", "timestep 1e-4"};

}  // namespace

TEST_CASE("fix nve/limit: no particle moves more than the limit in one step", "[fix][nve_limit]") {
  granary::test::ScriptEngine s;
  s.cmds(kBox);
  // diameter 0.01 m, density 2000 kg/m^3: m = 1.0472e-3 kg
  const double m = 4.0 / 3.0 * M_PI * 1.25e-7 * 2000;
  s.cmds({"create_atoms 1 single 0 0 0", "create_atoms 2 single 0 0.05 0",
          "set type * diameter 0.01 density 2000", "group fast type 1", "group slow type 2",
          "fix push fast addforce " + num(1000 * m) + " 0 0",  // a = 1000 m/s^2
          "fix pull slow addforce 0 0 " + num(-0.1 * m),       // a = -0.1 m/s^2
          "fix lim all nve/limit absolute 1e-6", "run 100"});
  Vec3 x, v, w;
  // fast: a dt / 2 = 0.05 m/s > 1e-6 / 1e-4 = 0.01 m/s from the first half-kick on
  state(s.e, 1, x, v, w);
  CHECK(x[0] == Approx(100 * 1e-6).epsilon(1e-12));
  CHECK(v[0] == Approx(0.01).epsilon(1e-12));
  // slow: v = a t stays below 0.01 m/s: exact velocity Verlet
  state(s.e, 2, x, v, w);
  CHECK(x[2] == Approx(-0.5 * 0.1 * 0.01 * 0.01).epsilon(1e-9));
  CHECK(v[2] == Approx(-0.1 * 0.01).epsilon(1e-9));
  // two limited half-kicks per step of particle 1, counted again from 0 in each run
  CHECK(s.e.fix_value("lim", 0) == 200.0);
  s.cmd("run 10");
  CHECK(s.e.fix_value("lim", 0) == 20.0);

  // radius_ratio: at most 1e-3 radius per step
  s.cmds({"unfix lim", "fix lim all nve/limit radius_ratio 1e-3", "run 50"});
  state(s.e, 1, x, v, w);
  CHECK(x[0] == Approx(110 * 1e-6 + 50 * 1e-3 * 0.005).epsilon(1e-12));

  CHECK_THROWS_WITH(s.cmd("fix l2 all nve/limit absolut 1e-6"), Contains("absolute"));
  CHECK_THROWS_WITH(s.cmd("fix l2 all nve/limit absolute -1"), Contains("positive"));
  CHECK_THROWS_WITH(s.cmd("fix l2 all nve/limit absolute"), Contains("usage"));
}

// The same script in both programs: two spheres overlapping by 0.1 mm that
// slide past each other at 0.2 m/s (Hertz with tangential history). LIGGGHTS 3.8 (thermo_modify format float
// %20.15g) gives for sphere 2 after steps 1..5 x, vx and vy, and the count of limited half-kicks; it
// integrates no spin (omega stays 0).
TEST_CASE("fix nve/limit: two spheres in contact as LIGGGHTS 3.8", "[fix][nve_limit][liggghts]") {
  const std::vector<std::string> script = {
      "atom_style granular",
      "atom_modify map array",
      "boundary f f f",
      "newton off",
      "communicate single vel yes",
      "units si",
      "region reg block -0.1 0.1 -0.1 0.1 -0.1 0.1 units box",
      "create_box 1 reg",
      "neighbor 0.002 bin",
      "neigh_modify delay 0",
      "fix m1 all property/global youngsModulus peratomtype 5.e6",
      "fix m2 all property/global poissonsRatio peratomtype 0.45",
      "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.3",
      "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5",
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 0.00001",
      "create_atoms 1 single 0 0 0",
      "set atom 1 diameter 0.01 density 2000",
      "create_atoms 1 single 0.0099 0 0",
      "set atom 2 diameter 0.01 density 2000",
      "velocity all set 0 0.1 0",
      "set atom 2 vy -0.1",
      "fix lim all nve/limit absolute 0.0000001"};
  const double ref[5][4] = {{0.00990000100455065, 0.00109745842500416, -0.00993005784411905, 2},
                            {0.00990002178169383, 0.00300365337831337, -0.00953824231097882, 6},
                            {0.00990006056765261, 0.00467889023067922, -0.00883787226708185, 10},
                            {0.00990011468573634, 0.00606355717048961, -0.00795193526383383, 14},
                            {0.00990018114135557, 0.00715179683498852, -0.00698940641478575, 18}};
  // one run of n steps each (a run split in two would recompute the
  // velocity-dependent contact forces at its second start)
  for (int step = 0; step < 5; ++step) {
    granary::test::ScriptEngine s;
    s.cmds(script);
    s.cmd("run " + std::to_string(step + 1));
    Vec3 x, v, w;
    state(s.e, 2, x, v, w);
    INFO("step " << step + 1);
    CHECK(x[0] - 0.0099 == Approx(ref[step][0] - 0.0099).epsilon(1e-6));  // x has 15 digits
    CHECK(v[0] == Approx(ref[step][1]).epsilon(1e-9));
    CHECK(v[1] == Approx(ref[step][2]).epsilon(1e-9));
    CHECK(w == Vec3(0, 0, 0));
    CHECK(s.e.fix_value("lim", 0) == ref[step][3]);
  }
}

TEST_CASE("fix wall/reflect: the position and normal velocity are reflected", "[fix][wall_reflect]") {
  granary::test::ScriptEngine s;
  s.cmds({"units si", "atom_style granular", "boundary f f f", "region box block -0.1 0.1 -0.1 0.1 -0.1 0.1",
          "create_box 1 box", "timestep 1e-3", "lattice sc 0.002", "create_atoms 1 single 0 0 0 units box",
          "create_atoms 1 single 0 0.05 0 units box", "create_atoms 1 single 0 0 0.0505 units box",
          "set type 1 diameter 0.002 density 2000", "velocity all set -1 0 0 units box",
          "set atom 2 vx 0 vy -1", "set atom 3 vx 0 vz 2",
          // ylo moves up at 0.5 m/s from 0.0393 m (in lattice spacings of 2 mm, the default units)
          "variable yw equal 19.65+250*time", "fix w all wall/reflect xlo -5.25 ylo v_yw zhi EDGE",
          "fix i all nve/sphere", "run 30"});
  Vec3 x, v, w;
  // 1: x = -t passes the wall at -0.0105 m in step 11 (x = -0.011 -> -0.010), then moves back at +1 m/s
  state(s.e, 1, x, v, w);
  CHECK(x[0] == Approx(-0.010 + 19 * 1e-3).epsilon(1e-12));
  CHECK(v == Vec3(1, 0, 0));
  // 2: y = 0.05 - t meets the wall 0.0393 + 0.5 t in step 8 (y = 0.042 < 0.0433 -> 0.0446)
  state(s.e, 2, x, v, w);
  CHECK(x[1] == Approx(0.0446 + 22 * 1e-3).epsilon(1e-12));
  CHECK(v == Vec3(0, 1, 0));
  // 3: z = 0.0505 + 2 t passes the box face 0.1 in step 25 (0.1005 -> 0.0995)
  state(s.e, 3, x, v, w);
  CHECK(x[2] == Approx(0.0995 - 5 * 2e-3).epsilon(1e-12));
  CHECK(v == Vec3(0, 0, -2));

  CHECK_THROWS_WITH(s.cmd("fix w2 all wall/reflect xmin 0"), Contains("xlo"));
  CHECK_THROWS_WITH(s.cmd("fix w2 all wall/reflect xlo 0 xlo 1"), Contains("twice"));
  CHECK_THROWS_WITH(s.cmd("fix w2 all wall/reflect xlo v_nothing"), Contains("nothing"));
  CHECK_THROWS_WITH(s.cmd("fix w2 all wall/reflect units box"), Contains("at least one wall"));
  granary::test::ScriptEngine p;
  p.cmds({"units si", "atom_style granular", "boundary p f f", "region box block -1 1 -1 1 -1 1",
          "create_box 1 box"});
  CHECK_THROWS_WITH(p.cmd("fix w all wall/reflect xlo EDGE"), Contains("periodic"));
  CHECK_THROWS_WITH(p.cmd("fix w all wall/reflect ylo 0 units lattice"), Contains("lattice"));
}
