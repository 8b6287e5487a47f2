// fix nve/sphere makes the second half kick of a step that nothing observes
// together with the next step's first kick and drift (one pass over the
// particles instead of two). The operations are the same, in the same order,
// so the trajectory must be the same to the last bit as with every step
// observed, what is observed must be the full step's state, and a fix whose
// initial_integrate comes first and may touch the velocities must turn the
// deferral off.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "script_engine.h"
#include "core/engine.h"
#include "core/modify.h"
#include "particles/particles.h"

using granary::Vec3;

namespace {

struct State {
  std::map<long long, Vec3> x, v, omega;
};

// 60 beads (two sizes) poured onto a plane wall in a box periodic in x and y,
// with rolling friction and walls; `thermo` is the thermo interval and
// `extra` lines come before fix nve/sphere.
State pour(int thermo, const std::vector<std::string>& extra, int steps = 900,
           const std::vector<std::string>& after = {}) {
  granary::test::ScriptEngine s(MPI_COMM_SELF);
  s.cmds(
      {"units si",
       "atom_style granular",
       "atom_modify map array",
       "boundary p p f",
       "newton off",
       "communicate single vel yes",
       "region box block 0 0.008 0 0.008 0 0.03 units box",
       "create_box 2 box",
       "neighbor 0.0005 bin",
       "neigh_modify delay 0",
       granary::test::materials(2, 5.e6, 0.45, 0.5, 0.5),
       "pair_style gran model hertz tangential history rolling_friction cdt",
       "pair_coeff * *",
       "fix rf all property/global coefficientRollingFriction peratomtypepair 2 0.1 0.1 0.1 0.1",
       "timestep 2e-5",
       "region fill block 0 0.008 0 0.008 0.001 0.025 units box",
       "create_atoms 1 random 40 4711 fill overlap 0.0021 maxtry 200",
       "create_atoms 2 random 20 4713 fill overlap 0.0021 maxtry 200",
       "set type 1 diameter 0.002 density 2500",
       "set type 2 diameter 0.0012 density 2500",
       "velocity all set 0.0 0.0 -0.5",
       "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
       "fix zwall all wall/gran model hertz tangential history rolling_friction cdt primitive type 1 zplane "
       "0.0",
       "thermo " + std::to_string(thermo)});
  s.cmds(extra);
  s.cmd("fix integr all nve/sphere");
  s.cmds(after);
  s.cmd("run " + std::to_string(steps));
  State out;
  const auto& p = s.p();
  for (int i = 0; i < p.nlocal; ++i) {
    out.x[p.id[i]] = p.x[i];
    out.v[p.id[i]] = p.v[i];
    out.omega[p.id[i]] = p.omega[i];
  }
  return out;
}

// Bit for bit: every component equal (==, not within a tolerance).
void require_same(const State& a, const State& b) {
  REQUIRE(a.x.size() == 60);
  REQUIRE(b.x.size() == 60);
  int differ = 0;
  for (const auto& [id, x] : a.x) {
    const bool same = x == b.x.at(id) && a.v.at(id) == b.v.at(id) && a.omega.at(id) == b.omega.at(id);
    differ += !same;
  }
  CHECK(differ == 0);
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Lines that turn the deferral off without changing the motion: a fix
// whose initial_integrate comes before nve/sphere's (fix nve) on an empty
// group. With it, nve/sphere finishes every step as it always did: the
// reference the deferred runs are compared with.
const std::vector<std::string> kNoDeferral = {"region far block 1 2 1 2 1 2 units box",
                                              "group nobody region far", "fix off nobody nve"};

std::vector<std::string> joined(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

}  // namespace

TEST_CASE("fix nve/sphere: unobserved steps give the same trajectory to the last bit", "[fix][nve_sphere]") {
  const State reference = pour(1000, kNoDeferral);
  const State every = pour(1, {});  // every step observed (thermo 1): nothing deferred
  const State sparse = pour(1000, {});
  // the beads moved and touched: the comparison means something
  double wmax = 0.0;
  for (const auto& kv : reference.omega)
    wmax = std::max(wmax, kv.second.norm());
  CHECK(wmax > 1.0);  // rad/s: spun up by contacts
  require_same(reference, every);
  require_same(reference, sparse);
}

TEST_CASE("fix nve/sphere: an end-of-step fix sees the full step's velocities", "[fix][nve_sphere]") {
  // fix ave/time reads the kinetic energies of translation and rotation every
  // 7 steps (all digits); the steps between are not observed
  auto ave = [](const std::string& file) {
    return std::vector<std::string>{"compute ke all ke", "compute rke all erotate/sphere",
                                    "fix kes all ave/time 7 1 7 c_ke c_rke format \" %.17g\" file " + file};
  };
  const State reference = pour(1000, joined(kNoDeferral, ave("ke_deferred_reference.txt")));
  const State sparse = pour(1000, ave("ke_deferred_sparse.txt"));
  require_same(reference, sparse);
  const std::string a = slurp("ke_deferred_reference.txt"), b = slurp("ke_deferred_sparse.txt");
  CHECK(std::count(a.begin(), a.end(), '\n') >= 128);  // 900 / 7 samples
  CHECK(a == b);
  std::remove("ke_deferred_reference.txt");
  std::remove("ke_deferred_sparse.txt");
}

TEST_CASE("fix nve/sphere: no kick deferred beside another integrator", "[fix][nve_sphere]") {
  // fix nve/limit also integrates the beads (particles integrated twice, as
  // a script might do by mistake), defined before or after nve/sphere; its
  // limit (2 um per step, 0.1 m/s) depends on the velocities it reads between
  // nve/sphere's kicks, so nve/sphere must finish its steps as before: the
  // same bits as with every step observed
  for (const bool before : {true, false}) {
    const std::vector<std::string> nve = {"fix twice all nve/limit absolute 0.000002"}, none;
    const State every = pour(1, before ? nve : none, 300, before ? none : nve);
    const State sparse = pour(1000, before ? nve : none, 300, before ? none : nve);
    INFO((before ? "fix nve/limit before nve/sphere" : "fix nve/limit after nve/sphere"));
    require_same(every, sparse);
  }
}

TEST_CASE("fix ave/*: a step is observed only where the fix samples", "[fix][ave/time][ave/atom]") {
  // Modify::end_of_step_due decides which steps may defer work; the averaging
  // fixes run their end_of_step every step but read the state only at their
  // sampling steps (Nevery 2, Nrepeat 3, Nfreq 10: steps 6, 8, 10, 16, 18, 20)
  const std::vector<std::pair<std::string, std::vector<int>>> fixes = {
      {"fix a all ave/time 2 3 10 c_ke", {6, 8, 10, 16, 18, 20}},
      {"fix a all ave/atom 2 3 10 vx", {6, 8, 10, 16, 18, 20}},
      {"fix a all ave/histo 2 3 10 0 1 5 c_ke", {6, 8, 10, 16, 18, 20}},
      {"fix a all ave/spatial 2 3 10 z lower 0.001 vx", {6, 8, 10, 16, 18, 20}},
      // (ave/correlate samples every Nevery steps)
      {"fix a all ave/correlate 2 3 10 c_ke", {2, 4, 6, 8, 10, 12, 14, 16, 18, 20}},
  };
  for (const auto& [line, due] : fixes) {
    granary::test::ScriptEngine s(MPI_COMM_SELF);
    s.cmds({"units si", "atom_style granular", "boundary f f f", "region box block 0 1 0 1 0 1 units box",
            "create_box 1 box", "create_atoms 1 single 0.5 0.5 0.5 units box",
            "set type 1 diameter 0.01 density 1000", "timestep 1e-4", "fix integr all nve/sphere",
            "compute ke all ke", line, "run 0"});
    // asked before each step, as Update::step_observed does within the step
    std::vector<int> got;
    for (int step = 1; step <= 20; ++step) {
      if (s.e.modify->end_of_step_due(step)) got.push_back(step);
      s.cmd("run 1 pre no post no");
    }
    INFO(line);
    CHECK(got == due);
  }
}
