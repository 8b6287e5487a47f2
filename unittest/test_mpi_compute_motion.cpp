// The motion computes against particles in free flight, on any number of
// ranks: 27 spheres in a periodic box, each layer of nine moving along x and y
// at its own speed (so no two spheres ever meet) and spinning at a rate set
// from its id. After t seconds every displacement is v t, unwrapped across
// the periodic faces (displace/atom, msd with and without com), the centre of
// mass has moved by vcm t (com), the radius of gyration follows from the
// unwrapped positions (gyration), and the per-particle kinetic energies sum
// to compute ke and erotate/sphere (ke/atom, erotate/sphere/atom). The
// original positions survive a restart under the same compute ID; a particle
// created after the compute starts from where it is first seen; uncompute
// releases the field.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "core/engine.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;
using granary::test::world_rank;

namespace {

constexpr double kDt = 1e-4;

Vec3 velocity_of_layer(double z) {
  const int layer = static_cast<int>(std::floor(z / 0.0333 + 0.5));
  return Vec3(0.3 * layer - 0.2, 0.05 * (layer + 1), 0.0);
}
Vec3 spin_of(long long id) {
  return Vec3(std::sin(static_cast<double>(id)), 2.0, 0.1 * static_cast<double>(id));
}

std::vector<std::string> scene() {
  return {"units si",
          "atom_style granular",
          "boundary p p p",
          "region reg block 0 0.1 0 0.1 0 0.1 units box",
          "create_box 1 reg",
          "lattice sc 0.0333",
          "region fill block -0.001 0.09 -0.001 0.09 -0.001 0.09 units box",
          "create_atoms 1 region fill",
          "set atom * diameter 0.002 density 2500",
          granary::test::materials(1, 5e6, 0.3, 0.9, 0.3),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 1e-4",
          "fix integr all nve/sphere"};
}

void set_motion(granary::Engine& e) {
  auto& p = *e.particles;
  for (int i = 0; i < p.nlocal; ++i) {
    p.v[i] = velocity_of_layer(p.x[i][2]);
    p.omega[i] = spin_of(p.id[i]);
  }
}

/// Sum over the ranks.
double sum(double v) {
  double all = 0;
  MPI_Allreduce(&v, &all, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  return all;
}

}  // namespace

TEST_CASE("displace/atom, msd, com and gyration follow particles in free flight", "[compute][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(scene());
  set_motion(s.e);
  s.cmds({"compute d all displace/atom", "compute m all msd", "compute mc all msd com yes",
          "compute c all com", "compute g all gyration", "compute n all msd/nongauss",
          "compute nc all msd/nongauss com yes"});
  const Vec3 c0(s.e.compute_value("c", 1), s.e.compute_value("c", 2), s.e.compute_value("c", 3));
  CHECK(s.e.compute_value("m", 4) == 0.0);
  CHECK(s.e.compute_value("n", 3) == 0.0);  // no displacement yet: 0, not a division by 0
  s.cmd("run 1000");
  const double t = 1000 * kDt;
  const auto& p = s.p();
  REQUIRE(s.p().natoms == 27);
  std::vector<double> dx, dy, dz, dn;
  s.e.compute_peratom("d", 1, dx);
  s.e.compute_peratom("d", 2, dy);
  s.e.compute_peratom("d", 3, dz);
  s.e.compute_peratom("d", 4, dn);
  double vx2 = 0, vy2 = 0, v4 = 0;
  Vec3 vsum(0, 0, 0);
  int crossed = 0;
  for (int i = 0; i < p.nlocal; ++i) {
    const Vec3 v = p.v[i];
    CHECK(dx[i] == Approx(v[0] * t).margin(1e-13));
    CHECK(dy[i] == Approx(v[1] * t).margin(1e-13));
    CHECK(std::fabs(dz[i]) < 1e-13);
    CHECK(dn[i] == Approx(v.norm() * t).margin(1e-13));
    vx2 += v[0] * v[0];
    vy2 += v[1] * v[1];
    v4 += v.squaredNorm() * v.squaredNorm();
    vsum += v;
    int ix, iy, iz;
    granary::Particles::image_unpack(p.image[i], ix, iy, iz);
    crossed += ix != 0 || iy != 0;
  }
  CHECK(sum(crossed) == 6);  // the first and third columns of two layers crossed the periodic faces
  vx2 = sum(vx2) / 27;
  vy2 = sum(vy2) / 27;
  const Vec3 vcm(sum(vsum[0]) / 27, sum(vsum[1]) / 27, sum(vsum[2]) / 27);
  CHECK(s.e.compute_value("m", 1) == Approx(vx2 * t * t).epsilon(1e-10));
  CHECK(s.e.compute_value("m", 2) == Approx(vy2 * t * t).epsilon(1e-10));
  CHECK(s.e.compute_value("m", 3) == Approx(0.0).margin(1e-24));
  CHECK(s.e.compute_value("m", 4) == Approx((vx2 + vy2) * t * t).epsilon(1e-10));
  // msd/nongauss: <dr^2>, <dr^4> and the non-Gaussian parameter 3 <dr^4> / (5 <dr^2>^2) - 1
  const double r2 = (vx2 + vy2) * t * t, r4 = sum(v4) / 27 * t * t * t * t;
  CHECK(s.e.compute_value("n", 1) == Approx(r2).epsilon(1e-10));
  CHECK(s.e.compute_value("n", 2) == Approx(r4).epsilon(1e-10));
  CHECK(s.e.compute_value("n", 3) == Approx(3 * r4 / (5 * r2 * r2) - 1).epsilon(1e-9));
  CHECK(s.e.compute_value("n", 3) > -0.4);  // its lower bound: all displacements of one length
  CHECK(s.e.compute_value("nc", 1) == Approx(s.e.compute_value("mc", 4)).epsilon(1e-12));
  // with com yes the mean flow is taken out: the variance of the velocities
  const double varx = vx2 - vcm[0] * vcm[0], vary = vy2 - vcm[1] * vcm[1];
  CHECK(s.e.compute_value("mc", 1) == Approx(varx * t * t).epsilon(1e-9));
  CHECK(s.e.compute_value("mc", 4) == Approx((varx + vary) * t * t).epsilon(1e-9));
  // centre of mass (equal masses): moved by vcm t, unwrapped
  for (int d = 0; d < 3; ++d)
    CHECK(s.e.compute_value("c", d + 1) == Approx(c0[d] + vcm[d] * t).margin(1e-13));
  // gyration from the unwrapped positions
  double local[6] = {0, 0, 0, 0, 0, 0};
  const Vec3 cm(s.e.compute_value("c", 1), s.e.compute_value("c", 2), s.e.compute_value("c", 3));
  for (int i = 0; i < p.nlocal; ++i) {
    int ix, iy, iz;
    granary::Particles::image_unpack(p.image[i], ix, iy, iz);
    const Vec3 r = p.x[i] + Vec3(0.1 * ix, 0.1 * iy, 0.1 * iz) - cm;
    const double comp[6] = {r[0] * r[0], r[1] * r[1], r[2] * r[2], r[0] * r[1], r[0] * r[2], r[1] * r[2]};
    for (int k = 0; k < 6; ++k)
      local[k] += comp[k];
  }
  for (int k = 0; k < 6; ++k)
    CHECK(s.e.compute_value("g", k + 1) == Approx(sum(local[k]) / 27).epsilon(1e-12));
  CHECK(s.e.compute_value("g", 0) ==
        Approx(std::sqrt((sum(local[0]) + sum(local[1]) + sum(local[2])) / 27)).epsilon(1e-12));
  // the xy component is not zero: layers move apart along x
  CHECK(std::fabs(s.e.compute_value("g", 5)) > 1e-6);
}

TEST_CASE("ke/atom and erotate/sphere/atom give each particle's energy and sum to ke and erotate/sphere",
          "[compute][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(scene());
  set_motion(s.e);
  s.cmds({"group low id <> 1 9", "compute k all ke/atom", "compute r low erotate/sphere/atom",
          "compute ktot all ke", "compute rtot low erotate/sphere", "run 10"});
  const auto& p = s.p();
  std::vector<double> k, r;
  s.e.compute_peratom("k", 0, k);
  s.e.compute_peratom("r", 0, r);
  double ksum = 0, rsum = 0;
  const double pi = 3.14159265358979323846, m = 2500 * 4.0 / 3.0 * pi * 1e-9;
  for (int i = 0; i < p.nlocal; ++i) {
    CHECK(k[i] == Approx(0.5 * m * velocity_of_layer(p.x[i][2]).squaredNorm()).epsilon(1e-12));
    const double expect = p.id[i] <= 9 ? 0.5 * 0.4 * m * 1e-6 * spin_of(p.id[i]).squaredNorm() : 0.0;
    CHECK(r[i] == Approx(expect).epsilon(1e-12));
    ksum += k[i];
    rsum += r[i];
  }
  CHECK(sum(ksum) == Approx(s.e.compute_value("ktot", 0)).epsilon(1e-12));
  CHECK(sum(rsum) == Approx(s.e.compute_value("rtot", 0)).epsilon(1e-12));
  CHECK(s.e.compute_value("rtot", 0) > 0.0);
}

TEST_CASE("displace/atom keeps its origins across a restart and starts new particles where first seen",
          "[compute][mpi][restart]") {
  const std::string dir = granary::test::shared_temp_dir("granary_displace_");
  {
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(scene());
    set_motion(s.e);
    s.cmds({"compute d all displace/atom", "run 500", "write_restart " + dir + "/half.restart"});
  }
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"read_restart " + dir + "/half.restart", granary::test::materials(1, 5e6, 0.3, 0.9, 0.3),
          "pair_style gran model hertz tangential history", "pair_coeff * *", "fix integr all nve/sphere",
          "compute d all displace/atom", "compute fresh all displace/atom",
          // a new particle at rest in the middle of an empty column: starts from where it is first seen
          "create_atoms 1 single 0.005 0.005 0.005 units box", "set atom 28 diameter 0.002 density 2500",
          "run 500"});
  const auto& p = s.p();
  std::vector<double> d, f;
  s.e.compute_peratom("d", 1, d);
  s.e.compute_peratom("fresh", 1, f);
  for (int i = 0; i < p.nlocal; ++i) {
    INFO("particle " << p.id[i]);
    if (p.id[i] == 28) {
      CHECK(d[i] == 0.0);
      CHECK(f[i] == 0.0);
      continue;
    }
    CHECK(d[i] == Approx(p.v[i][0] * 1000 * kDt).margin(1e-13));  // from the first run's origin
    CHECK(f[i] == Approx(p.v[i][0] * 500 * kDt).margin(1e-13));   // from the restart
  }
  CHECK(s.e.particles->find_field("origin/d") >= 0);
  s.cmd("uncompute d");
  CHECK(s.e.particles->find_field("origin/d") < 0);
  CHECK(s.e.particles->find_field("origin/fresh") >= 0);
  CHECK_THROWS_WITH(s.cmd("compute bad all msd com maybe"), Contains("compute msd com"));
  CHECK_THROWS_WITH(s.cmd("compute bad all msd average yes"),
                    Contains("unknown compute msd keyword 'average'"));
  CHECK_THROWS_WITH(s.cmd("compute bad all displace/atom extra"), Contains("displace/atom"));
  CHECK(s.e.particles->find_field("origin/bad") < 0);  // nothing left behind by a refused compute
  MPI_Barrier(MPI_COMM_WORLD);
  if (world_rank() == 0) std::filesystem::remove_all(dir);
}
