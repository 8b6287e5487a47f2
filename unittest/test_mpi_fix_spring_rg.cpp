// fix spring/rg: the breathing of free spheres held by a restraint on their
// radius of gyration. With E = K (Rg - RG0)^2 and F_i = -2 K (1 - RG0/Rg)
// (m_i/M) (x_i - xcm), every particle moves along x_i - xcm and the group
// scales about its fixed centre of mass: M Rg'' = -2 K (Rg - RG0), so
// Rg(t) = RG0 + (Rg(0) - RG0) cos(w t) with w = sqrt(2 K / M). Checked on 1, 2
// and 4 ranks (a lattice of 27 spheres of two sizes and densities, one outside
// the group; no contacts): Rg after half a period equals 2 RG0 - Rg(0) within
// 1e-5 relative (velocity Verlet, about 4000 steps per period), the centre of mass
// stays put (1e-15 m), kinetic plus restraint energy is conserved (1e-5
// relative), the particle outside the group does not move; RG0 NULL exerts no
// force; the first forces equal the formula to 1e-12. Input errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/input.h"
#include "core/modify.h"
#include "domain/groups.h"
#include "fix/fix.h"
#include "particles/particles.h"
#include "script_engine.h"

namespace {

using Catch::Matchers::Contains;

void scene(granary::test::ScriptEngine& s) {
  s.cmds({"atom_style granular",
          "atom_modify map array",
          "boundary f f f",
          "newton off",
          "communicate single vel yes",
          "units si",
          "region b block -0.05 0.05 -0.05 0.05 -0.05 0.05 units box",
          "create_box 2 b",
          "neighbor 0.001 bin",
          "neigh_modify delay 0",
          granary::test::materials(2, 5e6, 0.45, 0.5, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "lattice sc 0.006",
          "region l block -0.009 0.009 -0.009 0.009 -0.009 0.009 units box",
          "create_atoms 1 region l",
          "set group all diameter 0.001 density 2500",
          "group heavy id 5 8 11 14 17 20 23",
          "set group heavy type 2 diameter 0.0016 density 1200",
          "group far id 27",
          "group g subtract all far",
          "displace_atoms far move 0.02 0.02 0.02 units box",
          "timestep 1e-5"});
}

double rg_of(granary::test::ScriptEngine& s, int igroup, double& mass) {
  auto& g = *s.e.groups;
  mass = g.mass(igroup);
  const auto xcm = g.xcm(igroup);
  const auto& p = s.p();
  double local = 0.0, all = 0.0;
  for (int i = 0; i < p.nlocal; ++i)
    if (p.mask[i] & g.bitmask(igroup)) local += p.rmass[i] * (p.x[i] - xcm).squaredNorm();
  MPI_Allreduce(&local, &all, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  return std::sqrt(all / mass);
}

}  // namespace

TEST_CASE("fix spring/rg: free spheres breathe about RG0 with w = sqrt(2K/M)", "[fix][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  scene(s);
  const int ig = s.e.groups->find("g");
  double mass = 0.0;
  const double rg_start = rg_of(s, ig, mass);
  const double rg0 = 1.08 * rg_start, k = 0.5;
  const double w = std::sqrt(2.0 * k / mass), half_period = M_PI / w;
  const auto xcm0 = s.e.groups->xcm(ig);
  char cmd[200];
  std::snprintf(cmd, sizeof cmd, "fix r g spring/rg %.17g %.17g", k, rg0);
  s.cmds({cmd, "fix integr all nve/sphere", "compute ke all ke", "run 0"});
  // the first forces: the formula
  {
    const auto& p = s.p();
    const double term = 2.0 * k * (1.0 - rg0 / rg_start) / mass;
    for (int i = 0; i < p.nlocal; ++i) {
      const granary::Vec3 want = (p.mask[i] & s.e.groups->bitmask(ig))
                                     ? granary::Vec3(-term * p.rmass[i] * (p.x[i] - xcm0))
                                     : granary::Vec3(0, 0, 0);
      CHECK((p.f[i] - want).norm() <= 1e-12 * (want.norm() + 1e-12));
    }
  }
  granary::Fix* fix = s.e.modify->find_fix("r");
  REQUIRE(fix != nullptr);
  const double e0 = fix->compute_scalar();
  CHECK(e0 == Approx(k * (rg_start - rg0) * (rg_start - rg0)).epsilon(1e-12));
  const long steps = std::lround(half_period / 1e-5);
  s.cmd("run " + std::to_string(steps));
  const double rg_half = rg_of(s, ig, mass);
  const double t = steps * 1e-5;
  const double want = rg0 + (rg_start - rg0) * std::cos(w * t);
  INFO("Rg from " << rg_start << " to " << rg_half << " m after " << t << " s (analytic " << want << ")");
  CHECK(rg_half == Approx(want).epsilon(1e-5));
  CHECK(std::fabs(rg_half - rg0) > 0.9 * std::fabs(rg_start - rg0));  // it really swung through
  CHECK((s.e.groups->xcm(ig) - xcm0).norm() < 1e-15);
  // energy: kinetic (translation; no spin without contacts) + restraint
  s.cmd("run 0");
  granary::Compute* ke = s.e.modify->find_compute("ke");
  REQUIRE(ke != nullptr);
  const double e1 = ke->compute_scalar() + fix->compute_scalar();
  CHECK(e1 == Approx(e0).epsilon(1e-5));
  // the particle outside the group stays where it was put
  for (int i = 0; i < s.p().nlocal; ++i)
    if (s.p().id[i] == 27) CHECK(s.p().v[i].norm() == 0.0);
}

TEST_CASE("fix spring/rg: RG0 NULL holds the group at its radius of gyration; input errors", "[fix][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  scene(s);
  s.cmds({"fix r g spring/rg 0.001 NULL", "run 0"});
  for (int i = 0; i < s.p().nlocal; ++i)
    CHECK(s.p().f[i].norm() < 1e-18);
  CHECK(s.e.modify->find_fix("r")->compute_scalar() < 1e-30);
  CHECK_THROWS_WITH(s.cmd("fix bad g spring/rg 0 0.01"), Contains("K must be positive"));
  CHECK_THROWS_WITH(s.cmd("fix bad g spring/rg 0.001 -1"), Contains("RG0 must be >= 0 or NULL"));
  CHECK_THROWS_WITH(s.cmd("fix bad g spring/rg 0.001"), Contains("usage"));
  s.cmd("group none empty");
  CHECK_THROWS_WITH(s.cmd("fix bad none spring/rg 0.001 NULL"), Contains("needs particles in group"));
}
