// The benchmark scripts of examples/bench, shortened: each runs unchanged
// (variables set beforehand take precedence over the scripts' `index`
// defaults) and its first steps are checked against what they must do.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "comm/comm.h"
#include "core/update.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

using granary::test::ScriptEngine;

const std::string kBench = std::string(GRANARY_SOURCE_DIR) + "/examples/bench";

double thermo(ScriptEngine& s, const std::string& key) {
  bool found = false;
  const double v = s.e.thermo_keyword(key, found);
  REQUIRE(found);
  return v;
}

// Sub-spheres of clumps and single spheres among the owned particles.
struct Kinds {
  long long clump_spheres = 0, singles = 0;
};
Kinds count_kinds(const granary::Particles& p) {
  Kinds k;
  for (int i = 0; i < p.nlocal; ++i)
    (p.body[i] >= 0 ? k.clump_spheres : k.singles) += 1;
  return k;
}

}  // namespace

TEST_CASE("bench_spheres: the lattice falls freely for its first 300 steps", "[example]") {
  // bcc lattice of 2 mm spheres 2.165 mm apart, lowest layer 5.1 mm above the
  // floor: nothing touches for 3 ms, so every sphere moves at 0.5 m/s + g t
  // (velocity Verlet is exact for a constant force)
  ScriptEngine s;
  s.cmds({"variable nsteps index 300", "include " + kBench + "/in.bench_spheres"});
  REQUIRE(s.p().natoms == 20184);
  const double t = 300 * 1e-5, v = 0.5 + 9.81 * t;
  const double m = 2500.0 * 4.0 / 3.0 * M_PI * 1e-9;
  const double ke = 20184 * 0.5 * m * v * v;
  CHECK(thermo(s, "ke") == Approx(ke).epsilon(1e-10));
  CHECK(s.e.compute_value("rke", 0) == 0.0);  // no contact: no spin
}

TEST_CASE("bench_silo: clumps and glass spheres fill the silo and fall without loss", "[example]") {
  ScriptEngine s;
  s.cmds({"variable nfill index 100", "variable nsteps index 50", "variable dir index " + kBench,
          "include " + kBench + "/in.bench_silo"});
  const auto& p = s.p();
  // about 2700 particles at phi = 0.3 of the fill region: cylinders of 10 spheres and single spheres
  const auto [clump_spheres, singles] = count_kinds(p);
  INFO(clump_spheres << " clump spheres, " << singles << " glass spheres");
  CHECK(clump_spheres % 10 == 0);
  CHECK(clump_spheres > 20000);
  CHECK(singles > 200);
  CHECK(p.natoms == clump_spheres + singles);  // nothing left the box in 150 steps
  // inserted at 0.5 m/s downwards and falling: the kinetic energy grows
  const double v = 0.5 + 9.81 * 150 * 1e-5;
  const double mass = s.e.group_function("mass", {"all"});
  CHECK(thermo(s, "ke") > 0.5 * mass * 0.25);
  CHECK(thermo(s, "ke") < 0.5 * mass * v * v * 1.001);
}

TEST_CASE("bench_silo_balanced: fill, balance and discharge run, and one rank keeps the whole box",
          "[example]") {
  ScriptEngine s;
  s.cmds({"variable nfill index 60", "variable nsteps index 20", "variable dir index " + kBench,
          "include " + kBench + "/in.bench_silo_balanced"});
  CHECK(s.p().natoms > 20000);
  CHECK(s.e.update->ntimestep == 80);
  CHECK(s.e.comm->split[2] == std::vector<double>({0.0, 1.0}));
}

TEST_CASE("bench_silo_balanced with bal rcb and every: tiled boxes, fix balance during the discharge",
          "[example]") {
  ScriptEngine s;
  s.cmds({"variable nfill index 60", "variable nsteps index 20", "variable bal index rcb",
          "variable every index 10", "variable dir index " + kBench,
          "include " + kBench + "/in.bench_silo_balanced"});
  CHECK(s.p().natoms > 20000);
  CHECK(s.e.update->ntimestep == 80);
  CHECK(s.e.comm->tiled());
  // one rank: nothing to balance, the imbalance factor is 1 before and after
  CHECK(s.e.fix_value("lb", 3) == 1.0);
  CHECK(s.e.fix_value("lb", 0) == 1.0);
}

TEST_CASE("bench_silo_large: insert, settle from the restart, then discharge with balancing", "[example]") {
  const double dt = 1e-5;
  double mass = 0.0;
  long long n = 0;
  {
    ScriptEngine s;  // a tenth of the bed's volume fraction, one step
    s.cmds({"variable nfill index 1", "variable vf index 0.03", "variable out index bench_large_1.restart",
            "variable dir index " + kBench, "include " + kBench + "/in.bench_silo_large"});
    const auto& p = s.p();
    const auto [clump_spheres, singles] = count_kinds(p);
    INFO(clump_spheres << " clump spheres, " << singles << " glass spheres");
    CHECK(clump_spheres % 10 == 0);
    // the full bed (vf 0.3) has 17,383 clumps and 23,985 spheres: a tenth, within the draw's scatter
    CHECK(clump_spheres / 10 == Approx(1738).margin(120));
    CHECK(singles == Approx(2398).margin(150));
    n = p.natoms;
  }
  {
    // the fill goes on from the restart: apart, at one speed, nothing touches yet
    ScriptEngine s;
    s.cmds({"variable in index bench_large_1.restart", "variable open index 0", "variable save index 1",
            "variable nsteps index 50", "variable out index bench_large_2.restart",
            "variable dir index " + kBench, "include " + kBench + "/in.bench_silo_large_run"});
    REQUIRE(s.p().natoms == n);
    mass = s.e.group_function("mass", {"all"});
    // inserted during step 1, then 50 steps of free fall: between 50 and 51
    // steps' worth of gravity, and no contact has spun anything
    const double v50 = 0.5 + 9.81 * 50 * dt, v51 = 0.5 + 9.81 * 51 * dt;
    CHECK(thermo(s, "ke") > 0.5 * mass * v50 * v50);
    CHECK(thermo(s, "ke") < 0.5 * mass * v51 * v51 * (1 + 1e-12));
    CHECK(s.e.compute_value("rke", 0) == 0.0);
  }
  {
    ScriptEngine s;
    s.cmds({"variable in index bench_large_2.restart", "variable balance index 2", "variable nsteps index 20",
            "variable dir index " + kBench, "include " + kBench + "/in.bench_silo_large_run"});
    CHECK(s.p().natoms == n);
    CHECK(s.e.update->ntimestep == 71);
    CHECK(s.e.group_function("mass", {"all"}) == Approx(mass).epsilon(1e-12));
  }
  for (const char* balance : {"3", "4", "5"}) {
    // weight time (grid or rcb) and rcb by counts: the same particles and mass
    // after 20 steps, and the imbalance factors printed (1 rank: even)
    INFO("balance " << balance);
    ScriptEngine s;
    s.cmds({"variable in index bench_large_2.restart", std::string("variable balance index ") + balance,
            "variable nsteps index 20", "variable dir index " + kBench,
            "include " + kBench + "/in.bench_silo_large_run"});
    CHECK(s.e.comm->tiled() == (std::string(balance) != "3"));
    CHECK(s.p().natoms == n);
    CHECK(s.e.update->ntimestep == 71);
    CHECK(s.e.group_function("mass", {"all"}) == Approx(mass).epsilon(1e-12));
    CHECK(s.e.fix_value("lb", 0) == Approx(1.0));
    CHECK(s.e.fix_value("lb", 3) == Approx(1.0));
  }
  std::remove("bench_large_1.restart");
  std::remove("bench_large_2.restart");
}

TEST_CASE("bench_drain: the frozen floor stays in place while the grains settle and drain", "[example]") {
  ScriptEngine s;
  s.cmds({"variable nsettle index 200", "variable ncycle index 200", "variable ncycles index 1",
          "variable balance index yes", "include " + kBench + "/in.bench_drain"});
  const auto& p = s.p();
  int floor = 0;
  double worst = 0.0;
  for (int i = 0; i < p.nlocal; ++i) {
    if (p.type[i] != 2) continue;
    ++floor;
    // lattice sites of the floor plate: z = 0, x and y multiples of 4 mm
    worst = std::max({worst, std::fabs(p.x[i][2]), std::fabs(std::remainder(p.x[i][0], 0.004)),
                      std::fabs(std::remainder(p.x[i][1], 0.004))});
  }
  CHECK(floor > 100);
  CHECK(worst < 1e-12);
  CHECK(s.e.update->ntimestep == 400);
  CHECK(p.natoms > 4000);
}
