// Clumps give the same physics on 1, 2 and 4 MPI ranks, on the processor
// grid and on the boxes of recursive bisection (comm_style tiled).
//
// Run by ctest at 1, 2 and 4 ranks. Every rank first runs the whole system
// alone (MPI_COMM_SELF) as the reference, then all ranks run it together on
// MPI_COMM_WORLD. Sixty clumps (three-sphere and dumbbell templates) are
// thrown into a box periodic in x and y with a floor, so they collide with
// each other and the floor, cross subdomain boundaries (sub-spheres of one
// clump on different ranks) and periodic boundaries. After 6000 steps the
// number of clumps and particles must agree exactly, the translational and
// rotational kinetic energies of the clumps to 1e-6 relative and every clump
// centre to 1e-7 m (1e-4 of a clump's size). Per-body force sums are in
// sub-sphere order on every decomposition, but the pair forces of a particle
// with several contacts are summed in an order that depends on it, so results
// may differ by round-off, which the collisions amplify; the tolerances allow
// for that.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "fix/fix_multisphere.h"
#include "core/modify.h"
#include "neighbor/contact_history.h"
#include "core/force.h"
#include "pair/pair.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

struct Snapshot {
  long long natoms = 0;
  int nbodies = 0;
  double ke = 0.0, erot = 0.0;
  std::map<long long, granary::Vec3> xcm;
  long long migrated = 0;
  long long contacts = 0;  // sphere-sphere contacts (clump against clump), summed over 12 checkpoints
  int split_bodies = 0;    // clumps whose sub-spheres are owned by more than one rank
  int wrapped_bodies = 0;  // clumps whose centre left the periodic box (unwrapped)
};

// tiled: comm_style tiled, the boxes recut by recursive bisection every 500 steps
std::vector<std::string> scene(const std::string& newton, bool tiled = false) {
  std::vector<std::string> s = {
      "units si",
      "atom_style granular",
      "boundary p p f",
      "newton " + newton,
      "processors * * 1",
      tiled ? "comm_style tiled" : "comm_style brick",
      "region box block 0 0.04 0 0.04 0 0.04 units box",
      "create_box 1 box",
      "neighbor 0.001 bin",
      "neigh_modify delay 0",
      granary::test::materials(1, 5.e6, 0.45, 0.6, 0.5),
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 1e-5",
      "fix tri all particletemplate/multisphere 15485863 atom_type 1 density constant 2500 nspheres 3 "
      "ntry 200000 spheres 0 0 0 0.002 0.003 0 0 0.0015 0 0.0025 0 0.001 type 1",
      "fix dumb all particletemplate/multisphere 15485867 atom_type 1 density constant 2500 nspheres 2 "
      "ntry 200000 spheres -0.001 0 0 0.001 0.001 0 0 0.001 type 1",
      "fix ms all multisphere",
      "fix g all gravity 9.81 vector 0 0 -1",
      "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
      "compute ke all ke/multisphere",
      "compute rot all erotate/multisphere",
      "thermo_style custom step atoms c_ke c_rot",
      "thermo 500",
  };
  // a 4 x 5 x 3 arrangement with velocities and orientations that vary from clump to clump
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 5; ++j) {
      for (int i = 0; i < 4; ++i, ++n) {
        const double x = 0.005 + 0.009 * i, y = 0.004 + 0.0075 * j, z = 0.005 + 0.009 * k;
        const double a = 0.37 * n, b = 0.91 * n;
        char line[400];
        std::snprintf(
            line, sizeof line,
            "create_clump %s %.6f %.6f %.6f quat %.6f %.6f %.6f %.6f vel %.3f %.3f %.3f omega %.2f %.2f %.2f",
            n % 2 ? "tri" : "dumb", x, y, z, std::cos(a), std::sin(a) * std::cos(b),
            std::sin(a) * std::sin(b), 0.3, 0.8 * std::sin(1.3 * n), 0.8 * std::cos(1.7 * n), -0.3 * (n % 3),
            20.0 * std::sin(n), 15.0 * std::cos(2.0 * n), 10.0);
        s.push_back(line);
      }
    }
  }
  if (tiled) s.push_back("fix bal all balance 500 1.0 rcb");
  return s;
}

Snapshot run_scene(MPI_Comm comm, const std::string& newton, bool tiled = false) {
  granary::Engine e(comm);
  e.logger->set_screen(false);
  granary::test::run(e, scene(newton, tiled));
  Snapshot s;
  // 6000 steps in 12 runs; sphere-sphere contacts are counted at the end of each
  auto touching = [&]() {
    long long local = 0, all = 0;
    if (auto* h = e.force->pair->history()) local = static_cast<long long>(h->contacts());
    MPI_Allreduce(&local, &all, 1, MPI_LONG_LONG, MPI_SUM, comm);
    return all;
  };
  e.input->one("run 500");
  s.contacts = touching();
  for (int chunk = 1; chunk < 12; ++chunk) {
    e.input->one("run 500 pre no post no");
    s.contacts += touching();
  }
  auto* ms = dynamic_cast<granary::FixMultisphere*>(e.clumps);
  ms->sync_bodies();  // every rank's record of every clump current
  const granary::Bodies& b = ms->bodies();
  s.nbodies = b.size();
  s.natoms = static_cast<long long>(e.particles->natoms);
  s.ke = e.compute_value("ke", 0);
  s.erot = e.compute_value("rot", 0);
  for (int k = 0; k < b.size(); ++k) {
    s.xcm[b.tag[k]] = b.xcm[k];
    for (int d = 0; d < 2; ++d)
      if (b.xcm[k][d] < 0.0 || b.xcm[k][d] >= 0.04) ++s.wrapped_bodies;
  }
  // ranks owning sub-spheres of each body
  int nprocs = 1;
  MPI_Comm_size(comm, &nprocs);
  std::vector<int> mine(b.size(), 0), owners(b.size(), 0);
  const auto& p = *e.particles;
  for (int i = 0; i < p.nlocal; ++i)
    if (p.body[i] >= 0) mine[b.find(p.body[i])] = 1;
  MPI_Allreduce(mine.data(), owners.data(), b.size(), MPI_INT, MPI_SUM, comm);
  for (int o : owners)
    s.split_bodies += o > 1;
  MPI_Allreduce(&e.comm->migrated_particles, &s.migrated, 1, MPI_LONG_LONG, MPI_SUM, comm);
  return s;
}

void compare(const Snapshot& ref, const Snapshot& par) {
  REQUIRE(ref.nbodies == 60);
  CHECK(ref.natoms == 150);
  CHECK(par.nbodies == ref.nbodies);
  CHECK(par.natoms == ref.natoms);
  CHECK(par.ke == Approx(ref.ke).epsilon(1e-6));
  CHECK(par.erot == Approx(ref.erot).epsilon(1e-6));
  double worst = 0.0;
  for (const auto& kv : ref.xcm) {
    auto it = par.xcm.find(kv.first);
    REQUIRE(it != par.xcm.end());
    worst = std::max(worst, (it->second - kv.second).norm());
  }
  INFO("largest clump centre difference " << worst << " m; ke " << ref.ke << " erot " << ref.erot);
  CHECK(worst < 1e-7);
  CHECK(ref.wrapped_bodies > 0);  // some clumps crossed a periodic boundary
  INFO("clump-clump contacts seen at the checkpoints: " << ref.contacts);
  CHECK(ref.contacts > 10);
  int nprocs = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
  if (nprocs > 1) {
    INFO("migrated particles " << par.migrated << ", clumps split over ranks " << par.split_bodies);
    CHECK(par.migrated > 10);
    CHECK(par.split_bodies > 0);
  }
}

}  // namespace

TEST_CASE("clumps give the same physics on every rank count (newton off)") {
  const Snapshot ref = run_scene(MPI_COMM_SELF, "off");
  const Snapshot par = run_scene(MPI_COMM_WORLD, "off");
  compare(ref, par);
}

TEST_CASE("clumps give the same physics on every rank count (newton on)") {
  const Snapshot ref = run_scene(MPI_COMM_SELF, "on");
  const Snapshot par = run_scene(MPI_COMM_WORLD, "on");
  compare(ref, par);
}

TEST_CASE("clumps give the same physics on tiles of recursive bisection (comm_style tiled, newton on)") {
  const Snapshot ref = run_scene(MPI_COMM_SELF, "on");
  const Snapshot par = run_scene(MPI_COMM_WORLD, "on", true);
  compare(ref, par);
}
