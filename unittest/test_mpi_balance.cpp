// Load balancing by moving the cut planes of the processor grid (run by ctest
// at 1, 2 and 4 ranks).
//
// A column of 2000 spheres fills the bottom quarter of a tall box decomposed
// into z slabs (processors 1 1 N). With equal slabs nearly all particles sit
// on rank 0; `balance ... shift z` must bring the imbalance factor (largest
// over average particle count per rank, measured from the ranks' particle
// counts after the migration) close to 1. Then the column collapses onto the
// floor while its bottom layer is drained away (delete_atoms between runs),
// with fix balance moving the cuts every 100 steps: the physics must agree
// with the same script on one rank within the tolerances of
// test_mpi_invariance, and the restart file written with balanced cuts must
// read on one rank. Weighting by measured time is checked for valid cuts only;
// weighting by neighbour counts must even out the neighbour-list entries of
// the ranks where a dense bed lies under a dilute gas.
#include <mpi.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "domain/domain.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

const int kParticles = 2000;

// Box, decomposition and particles (the static test; the start of the settling run).
std::vector<std::string> column_script() {
  return {
      "units si",
      "atom_style granular",
      "boundary f f f",
      "processors 1 1 *",
      "region box block 0 0.03 0 0.03 0 0.2 units box",
      "create_box 1 box",
      "region fill block 0.001 0.029 0.001 0.029 0.001 0.055 units box",
      "create_atoms 1 random " + std::to_string(kParticles) + " 4711 fill overlap 0.0021 maxtry 200",
      "set type 1 diameter 0.002 density 2500",
  };
}

// Contact model, walls, gravity and integrator (also after read_restart).
std::vector<std::string> physics() {
  return {
      "newton off",
      "neighbor 0.0006 bin",
      "neigh_modify delay 0",
      granary::test::materials(1, 5.e6, 0.45, 0.7, 0.5),
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 2e-5",
      "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
      "fix zwall all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
      "fix xwall1 all wall/gran model hertz tangential history primitive type 1 xplane 0.0",
      "fix xwall2 all wall/gran model hertz tangential history primitive type 1 xplane 0.03",
      "fix ywall1 all wall/gran model hertz tangential history primitive type 1 yplane 0.0",
      "fix ywall2 all wall/gran model hertz tangential history primitive type 1 yplane 0.03",
      "fix integr all nve/sphere",
  };
}

// The settled bed drains from the bottom: the particles below 3 mm are
// removed three times and the bed sinks after them, while fix balance moves
// the cuts every 100 steps (and at the setup of every run).
// With rcb the boxes are tiles of a recursive bisection (comm_style tiled).
std::vector<std::string> drain_script(const std::string& restart, bool rcb = false) {
  std::vector<std::string> s = {"atom_style granular", "processors 1 1 *", "read_restart " + restart};
  if (rcb) s.push_back("comm_style tiled");
  for (const auto& l : physics())
    s.push_back(l);
  for (const auto& l : std::vector<std::string>{
           rcb ? "fix bal all balance 100 1.02 rcb" : "fix bal all balance 100 1.02 shift z 10 1.02",
           "region outlet block 0 0.03 0 0.03 0 0.003 units box",
           "thermo_style custom step atoms ke f_bal f_bal[1] f_bal[2] f_bal[3]",
           "thermo 100",
           "run 400",
           "delete_atoms region outlet",
           "run 400",
           "delete_atoms region outlet",
           "run 400",
           "delete_atoms region outlet",
           "run 400",
       })
    s.push_back(l);
  return s;
}

/// Largest over average of a per-rank amount.
double imbalance_of(granary::Engine& e, double mine) {
  double most = 0.0, total = 0.0;
  MPI_Allreduce(&mine, &most, 1, MPI_DOUBLE, MPI_MAX, e.world);
  MPI_Allreduce(&mine, &total, 1, MPI_DOUBLE, MPI_SUM, e.world);
  return total > 0 ? most * e.nprocs / total : 1.0;
}

/// Largest over average particle count per rank, from the owned particles.
double rank_imbalance(granary::Engine& e) {
  return imbalance_of(e, e.particles->nlocal);
}

struct State {
  long long natoms = 0;
  double ke = 0.0;
  std::map<long long, granary::Vec3> x;
};

/// Every rank's `mine`, concatenated in rank order, on every rank.
std::vector<double> allgather(granary::Engine& e, const std::vector<double>& mine) {
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(e.nprocs), displs(e.nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, e.world);
  for (int r = 1; r < e.nprocs; ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(displs.back() + counts.back());
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, e.world);
  return all;
}

State snapshot(granary::Engine& e) {
  State s;
  const auto& p = *e.particles;
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i) {
    mine.push_back(static_cast<double>(p.id[i]));
    for (int d = 0; d < 3; ++d)
      mine.push_back(p.x[i][d]);
  }
  const std::vector<double> all = allgather(e, mine);
  for (std::size_t k = 0; k + 4 <= all.size(); k += 4)
    s.x[static_cast<long long>(all[k])] = granary::Vec3(all[k + 1], all[k + 2], all[k + 3]);
  s.natoms = static_cast<long long>(s.x.size());
  bool found = false;
  s.ke = e.thermo_keyword("ke", found);
  return s;
}

void check_cuts(const granary::Engine& e) {
  // identical on every rank, ordered, every slab at least the ghost cutoff wide
  const auto& cuts = e.comm->split[2];
  std::vector<double> first(cuts);
  MPI_Bcast(first.data(), static_cast<int>(first.size()), MPI_DOUBLE, 0, e.world);
  CHECK(first == cuts);
  const double cutoff = std::max(e.neighbor->cutneighmax, 2 * 0.001 + 0.0006);
  for (int k = 0; k < e.comm->procgrid[2]; ++k)
    CHECK(e.comm->cut_coord(2, k + 1) - e.comm->cut_coord(2, k) >= cutoff);
}

}  // namespace

TEST_CASE("balance shift z evens out a settled column") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(column_script());
  const int nprocs = s.e.nprocs;
  REQUIRE(s.e.particles->natoms == kParticles);
  REQUIRE(s.e.comm->procgrid[2] == nprocs);
  const double before = rank_imbalance(s.e);
  s.cmd("balance 1.05 shift z 20 1.01");
  const double after = rank_imbalance(s.e);
  INFO("imbalance factor on " << nprocs << " ranks: before " << before << ", after " << after);
  // the column fills z < 0.055 of 0.2 m: one rank of 2 holds all, of 4 about 90 %
  if (nprocs == 2) CHECK(before == Approx(2.0));
  if (nprocs == 4) CHECK(before > 3.4);
  CHECK(after < 1.02);
  if (nprocs == 1) CHECK(after == 1.0);
  check_cuts(s.e);
  // a second balance finds nothing to do above its threshold
  const auto cuts = s.e.comm->split[2];
  s.cmd("balance 1.05 shift z 20 1.01");
  CHECK(s.e.comm->split[2] == cuts);
  // explicit cuts and back to uniform
  if (nprocs == 2) {
    s.cmd("balance 0.5 z 0.3");  // all particles below the cut
    CHECK(s.e.comm->split[2][1] == 0.3);
    CHECK(rank_imbalance(s.e) == Approx(2.0));
    s.cmd("balance 0.5 z uniform");
    CHECK(s.e.comm->split[2][1] == 0.5);
  }
}

TEST_CASE("balance shift xz evens out particles in a corner of a 2 x 1 x 2 grid") {
  int nprocs = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
  if (nprocs != 4) return;
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({
      "units si",
      "atom_style granular",
      "boundary f f f",
      "processors 2 1 2",
      "region box block 0 0.06 0 0.03 0 0.2 units box",
      "create_box 1 box",
      "region fill block 0.001 0.012 0.001 0.029 0.001 0.08 units box",
      "create_atoms 1 random 1500 4711 fill overlap 0.0021 maxtry 200",
      "set type 1 diameter 0.002 density 2500",
  });
  const double before = rank_imbalance(s.e);
  s.cmd("balance 1.1 shift xz 20 1.01");
  const double after = rank_imbalance(s.e);
  INFO("imbalance factor before " << before << ", after " << after);
  CHECK(before == Approx(4.0));  // every particle in the lower-left cell
  CHECK(after < 1.02);
  CHECK(s.e.comm->split[0][1] < 0.2);  // x cut inside the filled 12 mm
  CHECK(s.e.comm->split[2][1] < 0.4);  // z cut inside the filled 80 mm
}

// A bed that is not a slab: a column 20 mm wide and 80 mm high beside a
// layer 40 mm wide and 20 mm high, 750 particles each. Cut planes shared by
// a 2 x 1 x 2 grid cannot split both evenly; recursive bisection can.
TEST_CASE("balance rcb evens out a column beside a layer, which grid cuts cannot") {
  int nprocs = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
  double grid = 0.0, tiled = 0.0, before = 0.0;
  for (const bool rcb : {false, true}) {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds({
        "units si",
        "atom_style granular",
        "boundary f f f",
        nprocs == 4 ? "processors 2 1 2" : "processors * 1 *",
        "region box block 0 0.06 0 0.03 0 0.2 units box",
        "create_box 1 box",
        "region column block 0.001 0.019 0.001 0.029 0.001 0.08 units box",
        "region layer block 0.021 0.059 0.001 0.029 0.001 0.02 units box",
        "create_atoms 1 random 750 4711 column overlap 0.0021 maxtry 200",
        "create_atoms 1 random 750 4713 layer overlap 0.0021 maxtry 200",
        "set type 1 diameter 0.002 density 2500",
    });
    REQUIRE(s.e.particles->natoms == 1500);
    before = rank_imbalance(s.e);
    if (rcb) {
      s.cmd("comm_style tiled");
      s.cmd("balance 1.0 rcb");
      tiled = rank_imbalance(s.e);
      // every particle sits inside its owner's box; the boxes fill the box without overlap
      granary::Vec3 lo, hi;
      double volume = 0.0;
      for (int r = 0; r < s.e.nprocs; ++r) {
        s.e.comm->rank_box(r, lo, hi);
        volume += (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
      }
      CHECK(volume == Approx(0.06 * 0.03 * 0.2).epsilon(1e-12));
      const auto& p = *s.e.particles;
      int outside = 0;
      for (int i = 0; i < p.nlocal; ++i)
        for (int d = 0; d < 3; ++d)
          outside += p.x[i][d] < s.e.domain->sublo[d] || p.x[i][d] >= s.e.domain->subhi[d];
      CHECK(outside == 0);
      // a run on the tiles: ghosts found, nothing lost
      s.cmds({granary::test::materials(1, 5.e6, 0.45, 0.7, 0.5),
              "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 2e-5",
              "fix integr all nve/sphere", "run 10"});
      CHECK(s.e.particles->natoms == 1500);
      if (s.e.nprocs > 1) CHECK(s.e.particles->nghost > 0);
      // back to the grid: the particles return to the grid's owners
      s.cmd("comm_style brick");
      CHECK(s.e.comm->rcb_tree().empty());
      CHECK(rank_imbalance(s.e) == Approx(before));
    } else {
      s.cmd("balance 1.0 shift xz 30 1.0");
      grid = rank_imbalance(s.e);
    }
  }
  INFO(nprocs << " ranks: imbalance factor " << before << ", after shift xz " << grid << ", after rcb "
              << tiled);
  CHECK(tiled < 1.02);
  if (nprocs == 1) CHECK(tiled == 1.0);
  if (nprocs == 4) CHECK(grid > 1.2);
}

namespace {

/// Largest over average number of neighbour-list entries per rank (both ends
/// of a pair count; the lists of the last build).
double list_imbalance(granary::Engine& e) {
  const auto& nb = *e.neighbor;
  const int n = e.particles->nlocal;
  double mine = 0.0;
  for (int i = 0; i < n; ++i)
    for (int k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      mine += nb.neigh[k] < n ? 2.0 : 1.0;
  return imbalance_of(e, mine);
}

// 1500 touching beads in a dense layer at the bottom (spacing 2.1 mm, a
// neighbour skin of 0.6 mm reaches the next beads) under 1000 beads spread
// through the rest of the box (few neighbours).
std::vector<std::string> bed_and_gas_script() {
  std::vector<std::string> s = {
      "units si",
      "atom_style granular",
      "boundary f f f",
      "processors 1 1 *",
      "region box block 0 0.03 0 0.03 0 0.2 units box",
      "create_box 1 box",
      "region bed block 0.001 0.029 0.001 0.029 0.001 0.012 units box",
      "region gas block 0.001 0.029 0.001 0.029 0.02 0.199 units box",
      "create_atoms 1 random 1500 4711 bed overlap 0.00201 maxtry 500",
      "create_atoms 1 random 1000 4712 gas overlap 0.0021 maxtry 200",
      "set type 1 diameter 0.002 density 2500",
  };
  for (const auto& l : physics())
    s.push_back(l);
  return s;
}

}  // namespace

TEST_CASE("balance weight neigh evens out the neighbour-list entries of a bed under a gas") {
  double by_count = 0.0, by_neigh = 0.0;
  for (const bool neigh : {false, true}) {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(bed_and_gas_script());
    s.cmd("run 0");
    s.cmd(neigh ? "balance 1.0 shift z 30 1.01 weight neigh 1.0" : "balance 1.0 shift z 30 1.01");
    s.cmd("run 0");
    check_cuts(s.e);
    (neigh ? by_neigh : by_count) = list_imbalance(s.e);
    if (s.e.nprocs > 1 && neigh) {
      // the weighted cut lies inside the bed (below half the particles)
      CHECK(rank_imbalance(s.e) > 1.1);
    }
  }
  int nprocs = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
  INFO("list-entry imbalance on " << nprocs << " ranks: balanced by count " << by_count << ", by neighbours "
                                  << by_neigh);
  if (nprocs == 1) {
    CHECK(by_count == 1.0);
    CHECK(by_neigh == 1.0);
  } else {
    CHECK(by_count > 1.3);
    CHECK(by_neigh < 1.1);
  }
}

TEST_CASE("balance rcb weight neigh evens out the neighbour-list entries of a bed under a gas") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(bed_and_gas_script());
  s.cmds({"comm_style tiled", "run 0", "balance 1.0 rcb", "run 0"});
  const double by_count = list_imbalance(s.e), count_ranks = rank_imbalance(s.e);
  s.cmds({"balance 1.0 rcb weight neigh 1.0", "run 0"});
  const double by_neigh = list_imbalance(s.e), neigh_ranks = rank_imbalance(s.e);
  INFO("list-entry imbalance on " << s.e.nprocs << " ranks: rcb by count " << by_count << " (particles "
                                  << count_ranks << "), by neighbours " << by_neigh << " (particles "
                                  << neigh_ranks << ")");
  if (s.e.nprocs == 1) {
    CHECK(by_neigh == 1.0);
  } else {
    CHECK(count_ranks < 1.01);
    CHECK(by_count > 1.3);
    CHECK(by_neigh < 1.1);
    CHECK(neigh_ranks > 1.1);  // the boxes of the bed hold fewer particles than those of the gas
  }
}

TEST_CASE("fix balance weight neigh moves the cuts during a run") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(bed_and_gas_script());
  s.cmd("fix bal all balance 50 1.02 shift z 30 1.01 weight neigh 1.0");
  s.cmd("run 100");
  check_cuts(s.e);
  if (s.e.nprocs > 1) {
    INFO("list-entry imbalance " << list_imbalance(s.e));
    CHECK(list_imbalance(s.e) < 1.15);
    CHECK(rank_imbalance(s.e) > 1.1);
  }
}

TEST_CASE("fix balance during a draining column keeps the physics of one rank") {
  int nprocs = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  State ref, par;
  double fix_after = 0, fix_before = 0, fix_max = 0, final_imbalance = 0, uniform_imbalance = 0;
  double weighted_imbalance = 0;
  std::vector<double> final_cuts;
  long long migrated_contacts = 0;
  // The bed is poured and settled once, on one rank; both runs start from it.
  const std::string settled = "balance_settled_" + std::to_string(nprocs) + ".restart";
  const std::string file = "balance_" + std::to_string(nprocs) + ".restart";
  if (rank == 0) {
    granary::test::ScriptEngine s(MPI_COMM_SELF);
    s.cmds(column_script());
    s.cmds(physics());
    s.cmds({"velocity all set 0.0 0.0 -0.5", "run 4000", "write_restart " + settled});
  }
  MPI_Barrier(MPI_COMM_WORLD);
  {
    granary::test::ScriptEngine s(MPI_COMM_SELF);
    s.cmds(drain_script(settled));
    ref = snapshot(s.e);
  }
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(drain_script(settled));
    par = snapshot(s.e);
    fix_after = s.e.fix_value("bal", 0);
    fix_max = s.e.fix_value("bal", 1);
    fix_before = s.e.fix_value("bal", 3);
    final_imbalance = rank_imbalance(s.e);
    final_cuts = s.e.comm->split[2];
    check_cuts(s.e);
    MPI_Allreduce(&s.e.comm->migrated_contacts, &migrated_contacts, 1, MPI_LONG_LONG, MPI_SUM, s.e.world);
    s.cmd("write_restart " + file);
    // the same particles on equal slabs
    s.cmd("balance 0.5 z uniform");
    uniform_imbalance = rank_imbalance(s.e);
    // weighted by the measured pair and neighbour time per particle of each
    // rank (not reproducible, so only the cuts' validity is checked)
    s.cmds({"thermo_style custom step atoms ke", "unfix bal",
            "fix wbal all balance 50 1.0 shift z 10 1.0 weight time 0.5", "run 200"});
    check_cuts(s.e);
    CHECK(s.e.particles->natoms == par.natoms);
    if (nprocs > 1) CHECK(s.e.fix_value("wbal", 2) > 0);  // iterations at the last rebalancing
    weighted_imbalance = rank_imbalance(s.e);
  }
  // the same with recursive bisection (comm_style tiled, fix balance rcb)
  State tiled;
  double rcb_imbalance = 0.0, rcb_fix_before = 0.0;
  long long rcb_contacts = 0;
  int cut_dims = 0;  // dimensions (bit mask) along which the tree cuts
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(drain_script(settled, true));
    tiled = snapshot(s.e);
    rcb_imbalance = rank_imbalance(s.e);
    rcb_fix_before = s.e.fix_value("bal", 3);
    MPI_Allreduce(&s.e.comm->migrated_contacts, &rcb_contacts, 1, MPI_LONG_LONG, MPI_SUM, s.e.world);
    for (const auto& node : s.e.comm->rcb_tree())
      if (node.rank < 0) cut_dims |= 1 << node.dim;
  }
  REQUIRE(ref.natoms > 1000);
  REQUIRE(ref.natoms < kParticles);  // the outlet removed particles
  REQUIRE(par.natoms == ref.natoms);
  REQUIRE(tiled.natoms == ref.natoms);
  CHECK(par.ke == Approx(ref.ke).epsilon(1e-6));
  CHECK(tiled.ke == Approx(ref.ke).epsilon(1e-6));
  double worst = 0.0, worst_tiled = 0.0;
  for (const auto& kv : ref.x) {
    auto it = par.x.find(kv.first);
    REQUIRE(it != par.x.end());
    worst = std::max(worst, (it->second - kv.second).norm());
    auto jt = tiled.x.find(kv.first);
    REQUIRE(jt != tiled.x.end());
    worst_tiled = std::max(worst_tiled, (jt->second - kv.second).norm());
  }
  INFO("rcb: largest position difference " << worst_tiled << " m, imbalance " << rcb_fix_before << " -> "
                                           << rcb_imbalance << ", migrated contacts " << rcb_contacts
                                           << ", cut dimensions (bits xyz) " << cut_dims);
  CHECK(worst_tiled < 2.5e-10);
  if (nprocs > 1) {
    CHECK(rcb_imbalance < 1.05);
    CHECK(rcb_contacts > 10);
  }
  // at 4 ranks the column (28 mm wide, about 50 mm high) is cut across z, then each half along x or y
  if (nprocs == 4) CHECK(cut_dims != 4);
  INFO("ranks " << nprocs << ": largest position difference " << worst << " m; fix balance: before "
                << fix_before << ", after " << fix_after << ", max " << fix_max << "; final imbalance "
                << final_imbalance << " (equal slabs " << uniform_imbalance << ", weighted by time "
                << weighted_imbalance << "); migrated contacts " << migrated_contacts);
  CHECK(worst < 2.5e-10);
  if (nprocs > 1) {
    // the cuts moved with the compacting column, carrying contact history across them
    CHECK(final_cuts[1] < 0.1);
    CHECK(migrated_contacts > 10);
    CHECK(fix_after <= fix_before);
    CHECK(final_imbalance < 1.1);
    CHECK(uniform_imbalance > 1.9);
  }
  // the restart file (cuts are not stored) reads on one rank
  if (rank == 0) {
    granary::test::ScriptEngine r(MPI_COMM_SELF);
    r.cmd("read_restart " + file);
    CHECK(r.e.particles->natoms == ref.natoms);
    CHECK(r.e.comm->split[2] == std::vector<double>({0.0, 1.0}));
    std::remove(file.c_str());
    std::remove(settled.c_str());
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST_CASE("balance and fix balance refuse bad arguments") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  CHECK_THROWS_WITH(s.cmd("balance 1.1 shift z 10 1.05"), Catch::Contains("needs a simulation box"));
  s.cmds(column_script());
  using Catch::Contains;
  CHECK_THROWS_WITH(s.cmd("balance 1.1 shift"), Contains("DIMSTR NITER STOPTHRESH"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 shift q 10 1.05"), Contains("only contain the letters x, y and z"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 shift zz 10 1.05"), Contains("names z twice"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 shift z 0 1.05"), Contains("NITER must be between 1 and 1000"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 shift z 10 0.9"), Contains("STOPTHRESH must be >= 1.0"));
  CHECK_THROWS_WITH(s.cmd("balance 0 shift z 10 1.05"), Contains("THRESH must be positive"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 rcb"), Contains("needs comm_style tiled"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 rcb weight mass 1"), Contains("'weight neigh FACTOR'"));
  CHECK_THROWS_WITH(s.cmd("comm_style grid"), Contains("unknown comm_style 'grid'"));
  CHECK_THROWS_WITH(s.cmd("comm_style"), Contains("comm_style brick|tiled"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 bisect z"), Contains("unknown balance style 'bisect'"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 shift z 10 1.05 weight neigh 0.5"),
                    Contains("needs the neighbour lists of the current particles"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 shift z 10 1.05 weight mass 0.5"), Contains("'weight neigh FACTOR'"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 shift z 10 1.05 weight neigh 0"), Contains("must be in (0, 1]"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 shift z 10 1.05 weight time 1.5"), Contains("must be in (0, 1]"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 shift z 10 1.05 extra"), Contains("unknown balance keyword 'extra'"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 z uniform weight time 0.5"), Contains("needs the shift style"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 z 0.5 0.4 0.3"), Contains("z"));
  CHECK_THROWS_WITH(s.cmd("balance 1.1 z uniform z uniform"), Contains("given twice"));
  CHECK_THROWS_WITH(s.cmd("fix b all balance 100 1.1 shift"), Contains("DIMSTR NITER STOPTHRESH"));
  CHECK_THROWS_WITH(s.cmd("fix b all balance 100"), Contains("too few arguments"));
  CHECK_THROWS_WITH(s.cmd("fix b all balance -1 1.1 shift z 10 1.05"), Contains("NEVERY must be >= 0"));
  CHECK_THROWS_WITH(s.cmd("fix b all balance 100 1.1 rcb"), Contains("needs comm_style tiled"));
  s.cmd("comm_style tiled");
  CHECK_THROWS_WITH(s.cmd("fix b all balance 100 1.1 rcb x"), Contains("unknown fix balance keyword 'x'"));
  s.cmd("fix b all balance 100 1.1 rcb");
  s.cmd("comm_style brick");
  CHECK_THROWS_WITH(s.cmd("run 0"), Contains("needs comm_style tiled"));
  s.cmd("unfix b");
  CHECK_THROWS_WITH(s.cmd("fix b all balance 100 1.1 shift xy 10 0.5"), Contains("STOPTHRESH"));
  CHECK_THROWS_WITH(s.cmd("fix b all balance 100 1.1 shift z 10 1.05 out f.txt"),
                    Contains("'out' is not supported"));
  CHECK_THROWS_WITH(s.cmd("fix b all balance 100 1.1 shift z 10 1.05 weight time 0"),
                    Contains("must be in (0, 1]"));
  if (s.e.nprocs == 4) {
    // a first slab 0.2 mm wide is narrower than the ghost cutoff (3 mm: default skin 1 mm)
    CHECK_THROWS_WITH(s.cmd("balance 0.5 z 0.001 0.5 0.6"), Contains("exceeds the width"));
  }
}

// A recut by recursive bisection in the middle of a poured bed, with
// tangential history everywhere, moves particles and their contacts between
// ranks; the ten steps after it must be those without it to round-off
// (measured: 2e-18 m at 2 and 4 ranks with 3000-5000 contacts moved).
TEST_CASE("rcb recut in a poured bed changes nothing beyond round-off in the next steps") {
  int nprocs = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const std::string file = "rcb_recut_" + std::to_string(nprocs) + ".restart";
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(column_script());
    s.cmds(physics());
    s.cmds({"velocity all set 0.0 0.0 -0.5", "run 2500", "write_restart " + file});
  }
  State plain, recut;
  long long moved = 0, contacts = 0;
  for (const bool rcb : {false, true}) {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds({"atom_style granular", "processors 1 1 *", "read_restart " + file});
    s.cmds(physics());
    if (rcb) {
      s.cmds({"comm_style tiled", "balance 1.0 rcb"});
      MPI_Allreduce(&s.e.comm->migrated_particles, &moved, 1, MPI_LONG_LONG, MPI_SUM, s.e.world);
      MPI_Allreduce(&s.e.comm->migrated_contacts, &contacts, 1, MPI_LONG_LONG, MPI_SUM, s.e.world);
    }
    s.cmd("run 10");
    (rcb ? recut : plain) = snapshot(s.e);
  }
  REQUIRE(recut.natoms == kParticles);
  REQUIRE(plain.natoms == kParticles);
  double worst = 0.0;
  for (const auto& kv : plain.x)
    worst = std::max(worst, (recut.x.at(kv.first) - kv.second).norm());
  INFO(nprocs << " ranks: " << moved << " particles with " << contacts
              << " contacts moved by the recut; largest position difference " << worst << " m");
  CHECK(worst < 1e-15);
  CHECK(recut.ke == Approx(plain.ke).epsilon(1e-12));
  if (nprocs > 1) {
    CHECK(moved > 100);
    CHECK(contacts > 100);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank == 0) std::remove(file.c_str());
}

namespace {

// Per-particle values of a per-atom compute, by particle id, from all ranks.
std::map<long long, double> peratom_by_id(granary::Engine& e, const std::string& compute) {
  std::vector<double> mine;
  const auto& p = *e.particles;
  std::vector<double> values;
  e.compute_peratom(compute, 0, values);
  for (int i = 0; i < p.nlocal; ++i) {
    mine.push_back(static_cast<double>(p.id[i]));
    mine.push_back(values[i]);
  }
  const std::vector<double> all = allgather(e, mine);
  std::map<long long, double> out;
  for (std::size_t k = 0; k + 1 < all.size(); k += 2)
    out[static_cast<long long>(all[k])] = all[k + 1];
  return out;
}

}  // namespace

// Extra per-particle fields travel forward (cluster labels) and backward
// (contact counts summed from ghosts with newton on) on the rcb tiles as on
// the grid.
TEST_CASE("per-particle fields communicated on rcb tiles equal those on the grid") {
  std::map<long long, double> contacts[2], clusters[2];
  for (const bool rcb : {false, true}) {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    auto script = bed_and_gas_script();
    for (auto& line : script)
      if (line == "newton off") line = "newton on";
    s.cmds(script);
    // beads of the bed lie 2.01 mm or more apart: grown to 2.05 mm, neighbours overlap
    s.cmds({"set type 1 diameter 0.00205", "compute ca all contact/atom",
            "compute cl all cluster/atom 0.00204"});
    if (rcb) s.cmds({"comm_style tiled", "balance 1.0 rcb"});
    s.cmd("run 0");
    contacts[rcb] = peratom_by_id(s.e, "ca");
    clusters[rcb] = peratom_by_id(s.e, "cl");
  }
  REQUIRE(contacts[0].size() > 1500);  // create_atoms placed what fits of 2500
  REQUIRE(contacts[1].size() == contacts[0].size());
  double total = 0.0;
  for (const auto& kv : contacts[0])
    total += kv.second;
  INFO("contacts counted at both ends: " << total);
  CHECK(total > 200);  // the bed touches
  CHECK(contacts[1] == contacts[0]);
  int joined = 0;  // particles labelled by another particle of their cluster
  for (const auto& kv : clusters[0])
    joined += static_cast<long long>(kv.second) != kv.first;
  CHECK(joined > 100);
  CHECK(clusters[1] == clusters[0]);
}

// Parts without particles are cut in proportion to their ranks: every rank
// keeps a box of its own (of positive volume) and no rank holds two particles.
TEST_CASE("rcb with fewer particles than ranks gives every rank a box of its own") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"units si", "atom_style granular", "boundary f f f", "comm_style tiled",
          "region box block 0 0.06 0 0.03 0 0.2 units box", "create_box 1 box",
          "region fill block 0.001 0.02 0.001 0.029 0.001 0.02 units box",
          "create_atoms 1 random 3 4711 fill", "set type 1 diameter 0.002 density 2500", "balance 1.0 rcb"});
  double most = 0.0, mine = s.e.particles->nlocal;
  MPI_Allreduce(&mine, &most, 1, MPI_DOUBLE, MPI_MAX, s.e.world);
  CHECK(most == (s.e.nprocs >= 3 ? 1.0 : std::ceil(3.0 / s.e.nprocs)));
  double volume = 0.0;
  for (int r = 0; r < s.e.nprocs; ++r) {
    granary::Vec3 lo, hi;
    s.e.comm->rank_box(r, lo, hi);
    const double v = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    CHECK(v > 0.0);
    volume += v;
  }
  CHECK(volume == Approx(0.06 * 0.03 * 0.2).epsilon(1e-12));
}
