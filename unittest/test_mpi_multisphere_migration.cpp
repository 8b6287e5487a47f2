// Clumps that migrate between ranks many times keep the physics of 1 rank.
//
// Run by ctest at 1, 2 and 4 ranks. Each rank advances only the clumps with a
// sub-sphere it owns; a rank that receives a sub-sphere of a clump it did not
// advance fetches the clump's state at the neighbour-list rebuild, and the
// partial force sums of clumps split over ranks are exchanged between the
// ranks sharing them. Forty clumps (three-sphere and dumbbell templates) drift
// together through a fully periodic box, cut into slabs along x, at about
// 1.5 m/s along x, with relative velocities (up to 0.6 m/s) and spins so that
// they also collide: over 8000 steps every clump crosses 3 box lengths, so
// each clump moves between ranks about 6 (2 ranks) or 12 (4 ranks) times. Every rank first runs the system
// alone (MPI_COMM_SELF) as the reference. Checked:
// * the clumps collided (kinetic energy lost, restitution 0.8);
// * after 4000 + 4000 steps on all ranks, the clump count, the clumps' kinetic
//   energies (1e-6 relative) and centres (1e-7 m, against a clump size of
//   about 5 mm) agree with 1 rank, as in test_mpi_multisphere.cpp;
// * on more than one rank, clump states were fetched after migration (more
//   than 100 times in all) and clumps were split over ranks;
// * a restart written on all ranks after 4000 steps (every rank's clump
//   records synchronised for it) and continued for 4000 steps on all ranks
//   agrees with the uninterrupted run to 1e-10 m in the centres.
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

std::vector<std::string> physics() {
  return {
      "neighbor 0.001 bin",
      "neigh_modify delay 0",
      granary::test::materials(1, 5.e6, 0.45, 0.8, 0.5),
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 1e-5",
      "fix ms all multisphere",
      "compute ke all ke/multisphere",
      "compute rot all erotate/multisphere",
      "thermo_style custom step atoms c_ke c_rot",
      "thermo 1000",
  };
}

std::vector<std::string> scene() {
  std::vector<std::string> s = {
      "units si",
      "atom_style granular",
      "atom_modify map array",
      "boundary p p p",
      "processors * 1 1",
      "region box block 0 0.04 0 0.04 0 0.04 units box",
      "create_box 1 box",
      "fix tri all particletemplate/multisphere 15485863 atom_type 1 density constant 2500 nspheres 3 "
      "ntry 200000 spheres 0 0 0 0.002 0.003 0 0 0.0015 0 0.0025 0 0.001 type 1",
      "fix dumb all particletemplate/multisphere 15485867 atom_type 1 density constant 2500 nspheres 2 "
      "ntry 200000 spheres -0.001 0 0 0.001 0.001 0 0 0.001 type 1",
  };
  for (const auto& l : physics())
    s.push_back(l);
  // a 4 x 5 x 2 arrangement drifting along (1.5, 0.3, 0) m/s with relative
  // velocities and spins that vary from clump to clump
  int n = 0;
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 5; ++j) {
      for (int i = 0; i < 4; ++i, ++n) {
        const double x = 0.005 + 0.009 * i, y = 0.004 + 0.0075 * j, z = 0.008 + 0.016 * k;
        const double a = 0.37 * n, b = 0.91 * n;
        char line[400];
        std::snprintf(
            line, sizeof line,
            "create_clump %s %.6f %.6f %.6f quat %.6f %.6f %.6f %.6f vel %.3f %.3f %.3f omega %.2f %.2f %.2f",
            n % 2 ? "tri" : "dumb", x, y, z, std::cos(a), std::sin(a) * std::cos(b),
            std::sin(a) * std::sin(b), 0.3, 1.5 + 0.6 * std::sin(1.3 * n), 0.3 + 0.6 * std::cos(1.7 * n),
            0.2 - 0.3 * (n % 3), 20.0 * std::sin(n), 15.0 * std::cos(2.0 * n), 10.0);
        s.push_back(line);
      }
    }
  }
  return s;
}

struct Snapshot {
  int nbodies = 0;
  long long natoms = 0;
  double ke = 0.0, erot = 0.0;
  std::map<long long, granary::Vec3> xcm;
  long long fetched = 0;  // clump states fetched after migration, all ranks
  int shared = 0;         // the largest number of clumps one rank shared at the end
};

Snapshot snapshot(granary::Engine& e, MPI_Comm comm) {
  Snapshot s;
  auto* ms = dynamic_cast<granary::FixMultisphere*>(e.clumps);
  ms->sync_bodies();  // every rank's record of every clump current
  const granary::Bodies& b = ms->bodies();
  s.nbodies = b.size();
  s.natoms = static_cast<long long>(e.particles->natoms);
  s.ke = e.compute_value("ke", 0);
  s.erot = e.compute_value("rot", 0);
  for (int k = 0; k < b.size(); ++k)
    s.xcm[b.tag[k]] = b.xcm[k];
  const long long fetched = ms->fetched_states();
  MPI_Allreduce(&fetched, &s.fetched, 1, MPI_LONG_LONG, MPI_SUM, comm);
  const int shared = ms->shared_bodies();
  MPI_Allreduce(&shared, &s.shared, 1, MPI_INT, MPI_MAX, comm);
  return s;
}

double worst_distance(const Snapshot& a, const Snapshot& b) {
  double worst = 0.0;
  for (const auto& kv : a.xcm) {
    auto it = b.xcm.find(kv.first);
    if (it == b.xcm.end()) return 1e300;
    worst = std::max(worst, (it->second - kv.second).norm());
  }
  return worst;
}

}  // namespace

TEST_CASE("clumps migrating between ranks many times keep the 1-rank physics") {
  int nprocs = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &nprocs);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const std::string file = "mpi_ms_migration_" + std::to_string(nprocs) + ".restart";
  Snapshot ref, par, restarted;
  long long fetched_first = 0;
  double ke0 = 0.0;
  {
    granary::Engine e(MPI_COMM_SELF);
    e.logger->set_screen(false);
    granary::test::run(e, scene());
    e.input->one("run 0");
    ke0 = e.compute_value("ke", 0) + e.compute_value("rot", 0);
    e.input->one("run 4000");
    e.input->one("run 4000");
    ref = snapshot(e, MPI_COMM_SELF);
  }
  {
    granary::Engine e(MPI_COMM_WORLD);
    e.logger->set_screen(false);
    granary::test::run(e, scene());
    e.input->one("run 4000");
    e.input->one("write_restart " + file);
    fetched_first = snapshot(e, MPI_COMM_WORLD).fetched;
    e.input->one("run 4000");
    par = snapshot(e, MPI_COMM_WORLD);
  }
  {
    granary::Engine e(MPI_COMM_WORLD);
    e.logger->set_screen(false);
    e.input->one("atom_style granular");
    e.input->one("atom_modify map array");
    e.input->one("read_restart " + file);
    granary::test::run(e, physics());
    e.input->one("run 4000");
    restarted = snapshot(e, MPI_COMM_WORLD);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank == 0) std::remove(file.c_str());

  REQUIRE(ref.nbodies == 40);
  CHECK(ref.natoms == 100);
  CHECK(par.nbodies == ref.nbodies);
  CHECK(par.natoms == ref.natoms);
  CHECK(par.ke == Approx(ref.ke).epsilon(1e-6));
  CHECK(par.erot == Approx(ref.erot).epsilon(1e-6));
  const double d_par = worst_distance(ref, par), d_restart = worst_distance(par, restarted);
  INFO("largest clump centre difference: "
       << nprocs << " ranks against 1: " << d_par << " m, restarted against straight: " << d_restart
       << " m; clump states fetched " << par.fetched << " (" << fetched_first
       << " in the first 4000 steps), clumps shared by one rank " << par.shared << ", ke " << ref.ke
       << " erot " << ref.erot);
  CHECK(d_par < 1e-7);
  CHECK(restarted.nbodies == par.nbodies);
  CHECK(d_restart < 1e-10);
  CHECK(restarted.ke == Approx(par.ke).epsilon(1e-9));
  // the drift (momentum is conserved) carries the clumps 0.12 m, 3 box lengths along x
  CHECK(ref.ke > 0.5 * 40 * 1e-5 * 1.5 * 1.5 * 0.5);
  // collisions happened: they alone dissipate (restitution 0.8)
  INFO("kinetic energy at the start " << ke0 << " J, at the end " << ref.ke + ref.erot << " J");
  CHECK(ref.ke + ref.erot < (1.0 - 1e-3) * ke0);
  if (nprocs > 1) {
    CHECK(par.fetched > 100);
    CHECK(fetched_first > 50);
  } else {
    CHECK(par.fetched == 0);
  }
}
