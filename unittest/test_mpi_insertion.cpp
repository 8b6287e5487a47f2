// Insertion does not depend on the number of MPI ranks.
//
// Run by ctest at 1, 2 and 4 ranks. Every rank first runs the scene alone
// (MPI_COMM_SELF) as the reference, then all ranks run it together on
// MPI_COMM_WORLD. The particles placed by insert/pack (periodic in x and y,
// so candidates are checked against periodic images) must be the same ids at
// the same positions, bit for bit. Then the bed settles with contact history
// while insert/rate/region adds batches during the run (particles added on a
// reneighbouring step while ghosts and contacts exist); ids must agree and
// positions within round-off, as in test_mpi_invariance.cpp.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "neighbor/neighbor.h"
#include "neighbor/contact_history.h"
#include "core/force.h"
#include "pair/pair.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

using Snapshot = std::map<long long, granary::Vec3>;

Snapshot snapshot(granary::Engine& e) {
  const auto& p = *e.particles;
  std::vector<double> mine;
  for (int i = 0; i < p.nlocal; ++i)
    mine.insert(mine.end(), {static_cast<double>(p.id[i]), p.x[i][0], p.x[i][1], p.x[i][2]});
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(e.nprocs), displs(e.nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, e.world);
  for (int r = 1; r < e.nprocs; ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(static_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, e.world);
  Snapshot s;
  for (std::size_t k = 0; k + 3 < all.size(); k += 4) {
    const auto id = static_cast<long long>(all[k]);
    REQUIRE(s.count(id) == 0);  // every particle exists once
    s[id] = granary::Vec3(all[k + 1], all[k + 2], all[k + 3]);
  }
  return s;
}

struct Result {
  Snapshot packed, settled;
  long long contacts = 0, ghost_contacts = 0;  // at the end; with a ghost partner
};

Result run_scene(MPI_Comm comm) {
  granary::Engine e(comm);
  e.logger->set_screen(false);
  const std::vector<std::string> setup = {
      "units si",
      "atom_style granular",
      "boundary p p f",
      "newton off",
      "processors * * 1",
      "region box block 0 0.03 0 0.03 0 0.08 units box",
      "create_box 2 box",
      "neighbor 0.0006 bin",
      "neigh_modify delay 0",
      granary::test::materials(2, 5.e6, 0.45, 0.3, 0.5),
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 2e-5",
      "fix pts1 all particletemplate/sphere 15485863 atom_type 1 density constant 2500 radius constant 0.001",
      "fix pts2 all particletemplate/sphere 15485867 atom_type 2 density constant 2500 radius constant "
      "0.0015",
      "fix pdd all particledistribution/discrete 32452843 2 pts1 0.5 pts2 0.5",
      "region bed block 0 0.03 0 0.03 0.0 0.01 units box",
      "fix grav all gravity 9.81 vector 0.0 0.0 -1.0",
      "fix zwall all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
      "fix integr all nve/sphere",
      "fix ins all insert/pack seed 32452867 distributiontemplate pdd maxattempt 100 insert_every once "
      "overlapcheck yes vel constant 0 0 -0.5 region bed volumefraction_region 0.3",
      "run 1",
  };
  granary::test::run(e, setup);
  Result r;
  r.packed = snapshot(e);
  const std::vector<std::string> more = {
      "unfix ins",
      "run 600",
      "region top block 0 0.03 0 0.03 0.05 0.07 units box",
      "fix feed all insert/rate/region seed 15485927 distributiontemplate pdd nparticles 120 particlerate "
      "18400 "
      "insert_every 25 overlapcheck yes vel constant 0 0 -0.5 region top",
      "run 52",
  };
  granary::test::run(e, more);
  r.settled = snapshot(e);
  long long local[2] = {0, 0}, all[2];
  if (auto* h = e.force->pair->history()) {
    const auto& nb = *e.neighbor;
    for (int i = 0; i < e.particles->nlocal; ++i) {
      for (int k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
        if (!h->touched(k)) continue;
        ++local[0];
        if (nb.neigh[k] >= e.particles->nlocal) ++local[1];
      }
    }
  }
  MPI_Allreduce(local, all, 2, MPI_LONG_LONG, MPI_SUM, comm);
  r.contacts = all[0];
  r.ghost_contacts = all[1];
  return r;
}

}  // namespace

TEST_CASE("insertion gives the same particles on every rank count") {
  const Result ref = run_scene(MPI_COMM_SELF);
  const Result par = run_scene(MPI_COMM_WORLD);

  // insert/pack: the same ids at the same positions, bit for bit
  REQUIRE(ref.packed.size() > 200);
  REQUIRE(par.packed.size() == ref.packed.size());
  for (const auto& kv : ref.packed) {
    auto it = par.packed.find(kv.first);
    REQUIRE(it != par.packed.end());
    CHECK(it->second == kv.second);
  }

  // insert/rate/region during the run: 18400/s * 25 * 2e-5 s = 9.2 per batch
  // at steps 602, 627 and 652: floor(3 * 9.2) = 27 particles. (The comparison
  // ends soon after the bed landed: later, contacts that begin a step apart
  // because of round-off make runs on different rank counts drift apart.)
  REQUIRE(ref.settled.size() == ref.packed.size() + 27);
  REQUIRE(par.settled.size() == ref.settled.size());
  double worst = 0.0;
  for (const auto& kv : ref.settled) {
    auto it = par.settled.find(kv.first);
    REQUIRE(it != par.settled.end());
    worst = std::max(worst, (it->second - kv.second).norm());
  }
  INFO("largest position difference " << worst << " m, " << ref.packed.size() << " packed, " << ref.contacts
                                      << " contacts");
  CHECK(worst < 1e-9);
  INFO(par.ghost_contacts << " contacts with ghosts");
  CHECK(ref.contacts > 100);       // the bed is in contact, with tangential history
  CHECK(par.ghost_contacts > 10);  // across periodic and subdomain boundaries
  // the last batch was placed at the last step: bit for bit
  for (auto it = ref.settled.rbegin();
       it != ref.settled.rend() && it->first > ref.settled.rbegin()->first - 9; ++it) {
    CHECK(par.settled.at(it->first) == it->second);
  }
}
