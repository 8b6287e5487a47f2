// Insertion of clumps gives the same bodies on 1, 2 and 4 MPI ranks.
//
// Run by ctest at 1, 2 and 4 ranks. Every rank first inserts alone
// (MPI_COMM_SELF) as the reference, then all ranks insert together on
// MPI_COMM_WORLD: fix insert/pack of the silo paper's cylinder clumps
// (potentials/cylinder_ellipse_50.clump) mixed with glass spheres
// (particledistribution/discrete, fractions volume) into a block that spans
// every subdomain. Insertion draws the same particles, positions and
// orientations on every rank, so the bodies (ids, first sphere ids, centres,
// quaternions) and the free spheres (ids, positions, radii) must be identical,
// bit for bit; with more than one rank some clumps have sub-spheres owned by
// different ranks (checked).
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "fix/fix_multisphere.h"
#include "core/modify.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

struct Body {
  long long first_id;
  granary::Vec3 x;
  Eigen::Quaterniond q;
};

struct Snapshot {
  std::map<long long, Body> bodies;                               // body id -> body
  std::map<long long, std::pair<granary::Vec3, double>> spheres;  // free sphere id -> (x, r)
  long long natoms = 0;
  int split_bodies = 0;  // clumps whose sub-spheres are owned by more than one rank
};

std::vector<std::string> scene() {
  return {"units si",
          "atom_style granular",
          "boundary f f f",
          "newton off",
          "processors * * 1",
          "region box block -0.012 0.012 -0.012 0.012 0.0 0.02 units box",
          "create_box 2 box",
          "neighbor 0.0005 bin",
          "neigh_modify delay 0",
          "fix m1 all property/global youngsModulus peratomtype 5.e6 5.e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.45 0.45",
          "fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.5 0.5 0.5",
          "pair_style gran model hertz tangential history rolling_friction cdt",
          "pair_coeff * *",
          std::string("include ") + GRANARY_SOURCE_DIR + "/potentials/silo_friction.in",
          "timestep 0.000001",
          std::string("fix cyl all particletemplate/multisphere 15485863 atom_type 1 density constant 1190 "
                      "nspheres 50 ntry 1000000 spheres file ") +
              GRANARY_SOURCE_DIR + "/potentials/cylinder_ellipse_50.clump scale 1.0 type 1",
          "fix glass all particletemplate/sphere 15485867 atom_type 2 density constant 2500 radius constant "
          "0.001",
          "fix pdd all particledistribution/discrete 32452843 2 cyl 0.9 glass 0.1 fractions volume",
          "fix integr all multisphere",
          "fix nve all nve/sphere",
          "region ins block -0.01 0.01 -0.01 0.01 0.001 0.019 units box",
          "fix ins all insert/pack seed 32452867 distributiontemplate pdd maxattempt 200 insert_every once "
          "overlapcheck yes all_in yes vel constant 0. 0. 0. region ins volumefraction_region 0.2",
          "run 1"};
}

Snapshot insert(MPI_Comm comm) {
  granary::Engine e(comm);
  e.logger->set_screen(false);
  granary::test::run(e, scene());
  Snapshot s;
  // a rank keeps current only the clumps it owns sub-spheres of: synchronise first
  auto* ms = dynamic_cast<granary::FixMultisphere*>(e.clumps);
  ms->sync_bodies();
  const granary::Bodies& b = ms->bodies();
  for (int k = 0; k < b.size(); ++k)
    s.bodies[b.tag[k]] = {b.first_id[k], b.xcm[k], b.quat[k]};
  // free spheres and, per body, a bit for "this rank owns one of its sub-spheres"
  const auto& p = *e.particles;
  std::vector<double> mine;
  std::vector<int> owns(b.size(), 0), owners(b.size(), 0);
  for (int i = 0; i < p.nlocal; ++i) {
    if (p.body[i] >= 0) {
      owns[b.find(p.body[i])] = 1;
      continue;
    }
    mine.insert(mine.end(), {static_cast<double>(p.id[i]), p.x[i][0], p.x[i][1], p.x[i][2], p.radius[i]});
  }
  MPI_Allreduce(owns.data(), owners.data(), b.size(), MPI_INT, MPI_SUM, comm);
  for (int o : owners)
    s.split_bodies += o > 1;
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(e.nprocs), displs(e.nprocs, 0);
  MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < e.nprocs; ++r)
    displs[r] = displs[r - 1] + counts[r - 1];
  std::vector<double> all(static_cast<std::size_t>(displs.back() + counts.back()));
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, comm);
  for (std::size_t k = 0; k + 4 < all.size(); k += 5) {
    s.spheres[static_cast<long long>(all[k])] = {granary::Vec3(all[k + 1], all[k + 2], all[k + 3]),
                                                 all[k + 4]};
  }
  long long nlocal = p.nlocal;
  MPI_Allreduce(&nlocal, &s.natoms, 1, MPI_LONG_LONG, MPI_SUM, comm);
  return s;
}

}  // namespace

TEST_CASE("insert/pack of clumps and spheres gives the same bodies on every rank count",
          "[insert][multisphere]") {
  const Snapshot ref = insert(MPI_COMM_SELF);
  const Snapshot par = insert(MPI_COMM_WORLD);
  REQUIRE(ref.bodies.size() > 50);
  REQUIRE(ref.spheres.size() > 20);
  REQUIRE(par.bodies.size() == ref.bodies.size());
  REQUIRE(par.spheres.size() == ref.spheres.size());
  CHECK(par.natoms == ref.natoms);
  CHECK(ref.natoms == static_cast<long long>(50 * ref.bodies.size() + ref.spheres.size()));
  double dx = 0.0, dq = 0.0;
  int id_mismatch = 0;
  for (const auto& kv : ref.bodies) {
    auto it = par.bodies.find(kv.first);
    REQUIRE(it != par.bodies.end());
    id_mismatch += it->second.first_id != kv.second.first_id;
    dx = std::max(dx, (it->second.x - kv.second.x).norm());
    dq = std::max(dq, (it->second.q.coeffs() - kv.second.q.coeffs()).norm());
  }
  for (const auto& kv : ref.spheres) {
    auto it = par.spheres.find(kv.first);
    REQUIRE(it != par.spheres.end());
    dx = std::max(dx, (it->second.first - kv.second.first).norm());
    CHECK(it->second.second == kv.second.second);
  }
  INFO("largest difference: position " << dx << " m, quaternion " << dq << "; split clumps "
                                       << par.split_bodies);
  CHECK(id_mismatch == 0);
  CHECK(dx == 0.0);
  CHECK(dq == 0.0);
  int nprocs = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
  if (nprocs > 1) CHECK(par.split_bodies > 0);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) {
    std::printf(
        "%d ranks: %zu clumps, %zu spheres, %d clumps split across ranks, largest difference %.3g m\n",
        nprocs, par.bodies.size(), par.spheres.size(), par.split_bodies, dx);
  }
}
