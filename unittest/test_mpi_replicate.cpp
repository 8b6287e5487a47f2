// The replicate command on 1, 2 and 4 ranks (run by ctest at each count):
// LIGGGHTS 3.8's copies of two moving spheres (unittest/scripts/replicate,
// reference unittest/reference/replicate.liggghts.log) after replicate and
// after a run; the copies of a resting bed on a floor stay at rest with the
// original's weight per copy; the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/variable.h"
#include "domain/domain.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;

namespace {

namespace fs = std::filesystem;
const fs::path kRoot(GRANARY_SOURCE_DIR);

// "KEY name value name value ..." lines of the LIGGGHTS log.
std::map<std::string, double> printed(const std::string& key) {
  std::ifstream log(kRoot / "unittest/reference/replicate.liggghts.log");
  std::string line;
  std::map<std::string, double> out;
  while (std::getline(log, line)) {
    if (line.rfind(key + " ", 0) != 0) continue;
    std::istringstream in(line.substr(key.size()));
    std::string name;
    double v;
    while (in >> name >> v)
      out[name] = v;
  }
  return out;
}

}  // namespace

TEST_CASE("replicate: LIGGGHTS 3.8's copies of moving spheres, after replicate and after a run",
          "[replicate][mpi][liggghts]") {
  const auto after = printed("AFTER"), run = printed("RUN");
  REQUIRE(after.size() == 7);
  REQUIRE(run.size() == 7);
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  std::ifstream script(kRoot / "unittest/scripts/replicate/in.replicate");
  std::string line;
  std::vector<std::string> rest;
  bool replicated = false;
  while (std::getline(script, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("print", 0) == 0) continue;
    if (replicated) {
      rest.push_back(line);
      continue;
    }
    s.cmd(line);
    replicated = line.rfind("replicate", 0) == 0;
  }
  REQUIRE(replicated);
  const auto& d = *s.e.domain;
  CHECK(d.boxhi[0] == Approx(0.2));
  CHECK(d.boxhi[1] == Approx(0.3));
  CHECK(d.boxhi[2] == Approx(0.1));
  CHECK(s.e.particles->natoms == 12);
  auto& var = s.e.input->variables();
  // variables are defined after replicate in the script
  for (const auto& l : rest) {
    if (l.rfind("run", 0) == 0) {
      for (const auto& kv : after) {
        INFO("after replicate: " << kv.first);
        CHECK(var.compute_equal(kv.first) == Approx(kv.second).margin(1e-13));
      }
    }
    s.cmd(l);
  }
  for (const auto& kv : run) {
    INFO("after the run: " << kv.first);
    CHECK(var.compute_equal(kv.first) == Approx(kv.second).margin(1e-13));
  }
  CHECK(s.e.particles->natoms == 12);
}

TEST_CASE("replicate: the copies of a bed at rest on a floor stay at rest", "[replicate][mpi]") {
  // 4 spheres resting on the floor z = 0 in a periodic x-y cell, replicated
  // 3 x 2 x 1: 24 spheres, the floor carries 6 times the weight, nothing moves
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"units si",
          "atom_style granular",
          "atom_modify map array",
          "boundary p p f",
          "newton off",
          "communicate single vel yes",
          "region box block 0 0.04 0 0.04 0 0.04 units box",
          "create_box 1 box",
          granary::test::materials(1, 5e6, 0.45, 0.5, 0.3),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 1e-5",
          "neighbor 0.002 bin",
          "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0",
          "create_atoms 1 single 0.01 0.01 0.005 units box",
          "create_atoms 1 single 0.03 0.01 0.005 units box",
          "create_atoms 1 single 0.01 0.03 0.005 units box",
          "create_atoms 1 single 0.03 0.03 0.005 units box",
          "set group all diameter 0.01 density 2500",
          "fix grav all gravity 9.81 vector 0 0 -1",
          "fix integr all nve/sphere",
          "run 20000",
          "replicate 3 2 1",
          "run 2000"});
  CHECK(s.e.particles->natoms == 24);
  CHECK(s.e.domain->boxhi[0] == Approx(0.12));
  CHECK(s.e.domain->boxhi[1] == Approx(0.08));
  // every copy rests where its original rests: the same height, the same
  // place in its cell, at rest
  granary::Vec3 x1, v1;
  REQUIRE(granary::test::particle_state(s.e, 1, x1, v1));
  const auto& p = *s.e.particles;
  double local = 0.0, vmax = 0.0;
  int off = 0;
  for (int i = 0; i < p.nlocal; ++i) {
    local = std::max(local, p.v[i].norm());
    const double cx = std::fmod(p.x[i][0], 0.02), cy = std::fmod(p.x[i][1], 0.02);
    if (std::abs(p.x[i][2] - x1[2]) > 1e-9 || std::abs(cx - std::fmod(x1[0], 0.02)) > 1e-9 ||
        std::abs(cy - std::fmod(x1[1], 0.02)) > 1e-9)
      ++off;
  }
  MPI_Allreduce(&local, &vmax, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  int off_all = 0;
  MPI_Allreduce(&off, &off_all, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  CHECK(off_all == 0);
  CHECK(x1[2] < 0.005);  // resting on the floor, pressed into it by the weight
  CHECK(vmax < 1e-6);
}

TEST_CASE("replicate: errors name what is wrong", "[replicate][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(granary::test::liggghts_head("0 0.1 0 0.1 0 0.1", 1));
  s.cmds({"create_atoms 1 single 0.05 0.05 0.05 units box", "set group all diameter 0.01 density 2500"});
  struct Case {
    std::string args, expect;
  };
  const std::vector<Case> cases = {
      {"2 2", "wrong number of arguments; usage: replicate NX NY NZ"},
      {"0 1 1", "must be an integer >= 1"},
      {"2 1 x", "expected an integer"},
      {"2 1 1 offset 0.2 0.1 0.1", "offset: 0.2 along x is not the box length 0.1"},
      {"2 1 1 offset 0.1 0.1 0.1 shift 0.01 0 0", "shift: 0.01 is not 0"},
      {"2 1 1 stretch 1 1 1", "unknown keyword or missing values at 'stretch'"},
  };
  for (const auto& c : cases) {
    INFO(c.args);
    CHECK_THROWS_WITH(s.cmd("replicate " + c.args), Contains(c.expect));
  }
  CHECK(s.e.particles->natoms == 1);
  s.cmds(
      {"fix dumb all particletemplate/multisphere 15485867 atom_type 1 density constant 2500 nspheres 2 "
       "ntry 1000000 spheres -0.01 0 0 0.01 0.01 0 0 0.01 type 1",
       "fix ms all multisphere"});
  CHECK_THROWS_WITH(s.cmd("replicate 2 1 1"), Contains("clumps (fix multisphere) cannot be replicated"));
}
