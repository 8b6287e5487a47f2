// fix wall/region on 1, 2 and 4 ranks (run by ctest at each count): the
// forces, energies and wall forces LIGGGHTS 3.8 gives for the lj93, lj126 and
// harmonic walls of a block, the outside of a sphere and the inside of a
// cylinder; the colloid wall against the derivative of its documented
// energy; energy conservation of a particle bouncing off a harmonic wall; and
// the errors.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/modify.h"
#include "fix/fix.h"
#include "particles/particles.h"
#include "script_engine.h"

using Catch::Matchers::Contains;
using granary::Vec3;

namespace {

// Force on particle `id`, wherever it lives (collective).
Vec3 force_of(granary::Engine& e, long long id) {
  Vec3 mine = Vec3::Zero(), all;
  const auto& p = *e.particles;
  for (int i = 0; i < p.nlocal; ++i)
    if (p.id[i] == id) mine = p.f[i];
  MPI_Allreduce(mine.data(), all.data(), 3, MPI_DOUBLE, MPI_SUM, e.world);
  return all;
}

double fval(granary::Engine& e, const std::string& id, int k) {
  granary::Fix* f = e.modify->find_fix(id);
  return k == 0 ? f->compute_scalar() : f->compute_vector(k - 1);
}

// The scene of the LIGGGHTS 3.8 script: three spheres (d = 2 mm) in the
// block -10..10 mm: sphere 1 2 mm from the +x face, sphere 2 1.5 mm from the
// -x face and 1.6 mm from the +y face, sphere 3 farther than the cutoff.
std::vector<std::string> block_scene(const std::string& wall) {
  return {"units si",
          "atom_style granular",
          "atom_modify map array",
          "boundary f f f",
          "newton off",
          "region domain block -0.05 0.05 -0.05 0.05 -0.05 0.05 units box",
          "create_box 1 domain",
          "neighbor 0.0005 bin",
          granary::test::materials(1, 5.e6, 0.45, 0.9, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 0.00001",
          "region box block -0.01 0.01 -0.01 0.01 -0.01 0.01 units box",
          "create_atoms 1 single 0.008 0.0 0.0 units box",
          "create_atoms 1 single -0.0085 0.0084 0.0 units box",
          "create_atoms 1 single 0.0 0.0 -0.001 units box",
          "set group all diameter 0.002 density 2500",
          "fix integr all nve/sphere",
          "fix w all wall/region box " + wall,
          "run 0"};
}

struct Reference {
  const char* wall;
  double energy, wall_fx, wall_fy, fx1, fx2, fy2;
};

}  // namespace

// LIGGGHTS 3.8, thermo at step 0 of f_w, f_w[1..3], fx[1], fx[2], fy[2], fx[3].
TEST_CASE("fix wall/region: lj93, lj126 and harmonic walls of a block as LIGGGHTS 3.8",
          "[wall_region][mpi][liggghts]") {
  const Reference refs[] = {
      {"lj93 1e-3 0.0008 0.0025", -0.00024165290010347, 0.204771644912991, -0.23291015625, 0.0958427136,
       -0.300614358512991, 0.23291015625},
      {"lj126 1e-3 0.0008 0.0025", -0.000154906737366197, 0.302526238186398, -0.22705078125, 0.048749346816,
       -0.351275585002398, 0.22705078125},
      {"harmonic 100 0 0.0025", 0.000206, -0.1, 0.18, -0.1, 0.2, -0.18},
  };
  for (const Reference& r : refs) {
    INFO(r.wall);
    granary::test::ScriptEngine s(MPI_COMM_WORLD);
    s.cmds(block_scene(r.wall));
    const Vec3 f1 = force_of(s.e, 1), f2 = force_of(s.e, 2), f3 = force_of(s.e, 3);
    CHECK(f1[0] == Approx(r.fx1).epsilon(1e-12));
    CHECK(f1[1] == 0.0);
    CHECK(f2[0] == Approx(r.fx2).epsilon(1e-12));
    CHECK(f2[1] == Approx(r.fy2).epsilon(1e-12));
    CHECK(f2[2] == 0.0);
    CHECK(f3.norm() == 0.0);
    CHECK(fval(s.e, "w", 0) == Approx(r.energy).epsilon(1e-12));
    CHECK(fval(s.e, "w", 1) == Approx(r.wall_fx).epsilon(1e-12));
    CHECK(fval(s.e, "w", 2) == Approx(r.wall_fy).epsilon(1e-12));
    CHECK(fval(s.e, "w", 3) == 0.0);
  }
}

// LIGGGHTS 3.8: harmonic walls (100 N/m^2 ... energy eps (r - rc)^2, rc =
// 2.5 mm) of the outside of a sphere and the inside of a cylinder (its
// curved face and its top face at once).
TEST_CASE("fix wall/region: the outside of a sphere and the inside of a cylinder as LIGGGHTS 3.8",
          "[wall_region][mpi][liggghts]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"units si",
          "atom_style granular",
          "boundary f f f",
          "region domain block -0.05 0.05 -0.05 0.05 -0.05 0.05 units box",
          "create_box 1 domain",
          "neighbor 0.0005 bin",
          granary::test::materials(1, 5.e6, 0.45, 0.9, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 0.00001",
          "region ball sphere 0.02 0.02 0.02 0.005 side out units box",
          "region can cylinder z -0.02 -0.02 0.01 -0.03 0.0 units box",
          "create_atoms 1 single 0.02 0.0265 0.021 units box",
          "create_atoms 1 single -0.012 -0.02 -0.0015 units box",
          "create_atoms 1 single -0.02 -0.02 -0.015 units box",
          "group g1 id 1",
          "group g2 id 2 3",
          "set group all diameter 0.002 density 2500",
          "fix integr all nve/sphere",
          "fix w1 g1 wall/region ball harmonic 100 0 0.0025",
          "fix w2 g2 wall/region can harmonic 100 0 0.0025",
          "run 0"});
  const Vec3 f1 = force_of(s.e, 1), f2 = force_of(s.e, 2), f3 = force_of(s.e, 3);
  CHECK(f1[0] == 0.0);
  CHECK(f1[1] == Approx(0.182557546475926).epsilon(1e-12));
  CHECK(f1[2] == Approx(0.0280857763809117).epsilon(1e-12));
  CHECK(f2[0] == Approx(-0.1).epsilon(1e-12));
  CHECK(f2[1] == 0.0);
  CHECK(f2[2] == Approx(-0.2).epsilon(1e-12));
  CHECK(f3.norm() == 0.0);  // on the axis, 15 mm from both ends
  CHECK(fval(s.e, "w1", 0) == Approx(8.52901715255711e-05).epsilon(1e-12));
  CHECK(fval(s.e, "w2", 0) == Approx(0.000125).epsilon(1e-12));
}

// The colloid wall follows its documented energy: F = -dE/dr with
// E(D) = eps [s^6/7560 ((6R-D)/D^7 + (D+8R)/(D+2R)^7)
//             - (2R(D+R) + D(D+2R)(ln D - ln(D+2R))) / (6 D (D+2R))], D = r - R,
// shifted to 0 at the cutoff: an attraction at these distances. (LIGGGHTS 3.8
// gives forces of the same magnitude pointing away from the wall, and
// energies near 10667 per particle.)
TEST_CASE("fix wall/region: the colloid wall is the derivative of its energy", "[wall_region][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(block_scene("colloid 1e-3 0.0005 0.0025"));
  const double eps = 1e-3, sig = 0.0005, R = 0.001, rc = 0.0025;
  auto energy = [&](double r) {
    const double D = r - R, d2 = D + 2 * R;
    return eps * (std::pow(sig, 6) / 7560 * ((6 * R - D) / std::pow(D, 7) + (D + 8 * R) / std::pow(d2, 7)) -
                  (2 * R * (D + R) + D * d2 * (std::log(D) - std::log(d2))) / (6 * D * d2));
  };
  auto force = [&](double r) {  // central difference, relative step 1e-6
    const double h = 1e-6 * (r - R);
    return -(energy(r + h) - energy(r - h)) / (2 * h);
  };
  const Vec3 f1 = force_of(s.e, 1), f2 = force_of(s.e, 2);
  // sphere 1: 2 mm from the +x face (the force is +x: towards it)
  CHECK(f1[0] == Approx(-force(0.002)).epsilon(1e-7));
  CHECK(f1[0] == Approx(0.0739996504114017).epsilon(1e-12));  // LIGGGHTS' magnitude
  CHECK(f2[0] == Approx(force(0.0015)).epsilon(1e-7));
  CHECK(f2[0] == Approx(-0.406031668825397).epsilon(1e-12));
  CHECK(f2[1] == Approx(-force(0.0016)).epsilon(1e-7));
  const double shifted =
      (energy(0.002) - energy(rc)) + (energy(0.0015) - energy(rc)) + (energy(0.0016) - energy(rc));
  CHECK(fval(s.e, "w", 0) == Approx(shifted).epsilon(1e-12));
}

TEST_CASE("fix wall/region: a sphere bouncing off a harmonic wall keeps its energy", "[wall_region][mpi]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds({"units si",
          "atom_style granular",
          "boundary f f f",
          "region domain block -0.05 0.05 -0.05 0.05 -0.05 0.05 units box",
          "create_box 1 domain",
          "neighbor 0.0005 bin",
          granary::test::materials(1, 5.e6, 0.45, 0.9, 0.5),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 0.00001",
          "region floor plane 0 0 -0.01 0 0.2 1 units box",
          "create_atoms 1 single 0.01 0.0 -0.004 units box",
          "set group all diameter 0.002 density 2500",
          "velocity all set 0.1 0.05 -0.5",
          "fix integr all nve/sphere",
          "fix w all wall/region floor harmonic 50 0 0.004",
          "compute ke all ke",
          "variable etot equal c_ke+f_w",
          "thermo_style custom step c_ke f_w v_etot",
          "thermo 100",
          "run 0"});
  const double e0 = fval(s.e, "w", 0) + s.e.compute_value("ke", 0);
  double emin = e0, emax = e0, wall_max = 0.0;
  for (int k = 0; k < 60; ++k) {
    s.cmd("run 50");
    const double w = fval(s.e, "w", 0), e = w + s.e.compute_value("ke", 0);
    emin = std::min(emin, e);
    emax = std::max(emax, e);
    wall_max = std::max(wall_max, w);
  }
  CHECK(wall_max > 0.3 * e0);  // it came close to the wall and went back
  // velocity Verlet with 200 steps per oscillation of the spring: the energy
  // oscillates by about (omega dt)^2 / 8 = 1.2e-4 during the contact
  CHECK((emax - emin) < 1e-3 * e0);
  CHECK(fval(s.e, "w", 0) == 0.0);                                // it has left the wall again
  CHECK(s.e.compute_value("ke", 0) == Approx(e0).epsilon(1e-3));  // 2e-4 from the time step
  // it left along the reflection of its velocity about the plane's normal
  Vec3 x, v;
  REQUIRE(granary::test::particle_state(s.e, 1, x, v));
  const Vec3 n = Vec3(0, 0.2, 1).normalized(), v0(0.1, 0.05, -0.5);
  CHECK((v - (v0 - 2 * v0.dot(n) * n)).norm() < 1e-4 * v0.norm());
}

TEST_CASE("fix wall/region: errors say what to change", "[wall_region][mpi][errors]") {
  granary::test::ScriptEngine s(MPI_COMM_WORLD);
  s.cmds(block_scene("harmonic 100 0 0.0025"));
  const std::string f = "fix w2 all wall/region ";
  CHECK_THROWS_WITH(s.cmd(f + "nowhere harmonic 100 0 0.0025"), Contains("nowhere"));
  CHECK_THROWS_WITH(s.cmd(f + "box lj87 1 1 1"), Contains("lj93, lj126, colloid or harmonic"));
  CHECK_THROWS_WITH(s.cmd(f + "box lj93 1 1"), Contains("usage"));
  CHECK_THROWS_WITH(s.cmd(f + "box lj93 1 1 0"), Contains("cutoff must be positive"));
  CHECK_THROWS_WITH(s.cmd(f + "box lj93 1 0 0.001"), Contains("sigma must be positive"));
  CHECK_THROWS_WITH(s.cmd(f + "box lj93 1 abc 0.001"), Contains("sigma"));
  // a particle outside the region's side of the surface: an error of the
  // rank that owns it (one engine per rank here)
  granary::test::ScriptEngine one;
  one.cmds(block_scene("harmonic 100 0 0.0025"));
  one.cmds({"region small block -0.005 0.005 -0.005 0.005 -0.005 0.005 units box",
            "fix w2 all wall/region small harmonic 100 0 0.0025"});
  CHECK_THROWS_WITH(one.cmd("run 0"), Contains("particle 1") && Contains("is not in region small"));
}
