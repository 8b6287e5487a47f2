// Rigid clumps (fix multisphere): torque-free rotation, stability of the
// principal axes, a clump settling on a plane, collisions, deletion of whole
// clumps, the computes and restart continuation.
#include <mpi.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "script_engine.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/update.h"
#include "fix/fix_multisphere.h"
#include "core/modify.h"
#include "particles/particles.h"

using granary::Bodies;
using granary::Engine;
using granary::FixMultisphere;
using granary::Vec3;

namespace {

struct Sim : granary::test::ScriptEngine {
  Sim() : ScriptEngine(MPI_COMM_WORLD) {}
  const Bodies& bodies() { return dynamic_cast<FixMultisphere*>(e.clumps)->bodies(); }
};

// Box, materials (restitution e, friction mu), Hertz contacts, dt = 1e-5 s.
std::vector<std::string> setup(double e = 0.5, double mu = 0.5, const std::string& boundary = "f f f") {
  return {"units si",
          "atom_style granular",
          "boundary " + boundary,
          "region box block -0.05 0.05 -0.05 0.05 -0.05 0.05",
          "create_box 1 box",
          "neighbor 0.001 bin",
          "neigh_modify delay 0",
          "fix m1 all property/global youngsModulus peratomtype 5.e6",
          "fix m2 all property/global poissonsRatio peratomtype 0.45",
          "fix m3 all property/global coefficientRestitution peratomtypepair 1 " + std::to_string(e),
          "fix m4 all property/global coefficientFriction peratomtypepair 1 " + std::to_string(mu),
          "pair_style gran model hertz tangential history",
          "pair_coeff * *",
          "timestep 1e-5"};
}

// Three spheres of different sizes: three distinct principal moments
// (about 2.2e-10, 4.0e-10 and 4.6e-10 kg m^2).
const char* kTriple =
    "fix tri all particletemplate/multisphere 15485863 atom_type 1 density constant 2500 nspheres 3 ntry "
    "1000000 "
    "spheres 0 0 0 0.002 0.003 0 0 0.0015 0 0.0025 0 0.001 type 1";
// Two equal spheres 2 mm apart (a dumbbell, long axis = body x).
const char* kDumbbell =
    "fix dumb all particletemplate/multisphere 15485867 atom_type 1 density constant 2500 nspheres 2 ntry "
    "1000000 "
    "spheres -0.001 0 0 0.001 0.001 0 0 0.001 type 1";

Vec3 total_angular_momentum(const Bodies& b) {
  Vec3 l(0, 0, 0);
  for (int k = 0; k < b.size(); ++k)
    l += b.angmom[k] + b.mass[k] * b.xcm[k].cross(b.vcm[k]);
  return l;
}

Vec3 total_momentum(const Bodies& b) {
  Vec3 p(0, 0, 0);
  for (int k = 0; k < b.size(); ++k)
    p += b.mass[k] * b.vcm[k];
  return p;
}

// Clumps bouncing on the floor of the box of setup(), unsorted, in the order
// `clumps` (templates and create_clump commands) made them or, with
// `reverse`, stored in reverse order: no body's sub-spheres in sub-sphere
// order, so that fix multisphere sums them through slots, not along runs.
void clumps_on_floor(Sim& s, const std::vector<std::string>& clumps, bool reverse) {
  std::vector<std::string> c = setup();
  c.insert(c.end(), {"atom_modify sort 0 0", "fix g all gravity 9.81 vector 0 0 -1",
                     "fix floor all wall/gran model hertz tangential history primitive type 1 zplane -0.05",
                     "fix ms all multisphere", "fix nve all nve/sphere"});
  c.insert(c.end(), clumps.begin(), clumps.end());
  s.cmds(c);
  if (!reverse) return;
  granary::Particles& p = *s.e.particles;
  std::vector<int> order(p.nlocal);
  for (int i = 0; i < p.nlocal; ++i)
    order[i] = p.nlocal - 1 - i;
  p.permute(order);
}

double rotational_energy(const Bodies& b) {
  double e = 0.0;
  for (int k = 0; k < b.size(); ++k)
    e += b.kinetic_rotational(k);
  return e;
}

}  // namespace

TEST_CASE("multisphere: torque-free rotation conserves energy and angular momentum", "[multisphere]") {
  // 1e5 steps of omega dt = 5e-4 rad: about each principal axis, and a
  // tumbling start. NO_SQUISH keeps |L| exactly and the energy to O(dt^2):
  // both must hold to 1e-6 relative; 1e5 steps of one body must take < 5 s.
  const Vec3 spins[4] = {Vec3(50, 0, 0), Vec3(0, 50, 0), Vec3(0, 0, 50), Vec3(30, 40, 20)};
  for (const Vec3& w : spins) {
    Sim s;
    s.cmds(setup());
    s.cmds({kTriple, "fix ms all multisphere"});
    char line[200];
    std::snprintf(line, sizeof line, "create_clump tri 0 0 0 omega %g %g %g", w[0], w[1], w[2]);
    s.cmd(line);
    s.cmd("run 0");
    const double e0 = rotational_energy(s.bodies());
    const Vec3 l0 = total_angular_momentum(s.bodies());
    const double t0 = MPI_Wtime();
    s.cmd("run 100000");
    const double seconds = MPI_Wtime() - t0;
    INFO("spin " << w.transpose() << ": " << seconds << " s for 1e5 steps");
    CHECK(seconds < 5.0);
    CHECK(rotational_energy(s.bodies()) == Approx(e0).epsilon(1e-6));
    CHECK((total_angular_momentum(s.bodies()) - l0).norm() <= 1e-6 * l0.norm());
    CHECK(s.bodies().vcm[0].norm() == 0.0);  // no force: the centre stays at rest
  }
}

TEST_CASE("multisphere: rotation about the intermediate axis is unstable", "[multisphere]") {
  // Spin 50 rad/s about body axis k with a 1e-3 perturbation on the other two
  // axes. About the smallest and largest moments the axis stays within a few
  // perturbation angles of where it started; about the intermediate one the
  // perturbation grows (rate ~15/s here) until the body flips over.
  double wander[3];
  for (int k = 0; k < 3; ++k) {
    Sim s;
    s.cmds(setup());
    s.cmds({kTriple, "fix ms all multisphere"});
    Vec3 w = Vec3::Constant(0.05);
    w[k] = 50.0;
    char line[200];
    std::snprintf(line, sizeof line, "create_clump tri 0 0 0 omega %g %g %g", w[0], w[1], w[2]);
    s.cmd(line);
    Vec3 axis0(0, 0, 0);
    axis0[k] = 1.0;
    double worst = 0.0;
    for (int chunk = 0; chunk < 100; ++chunk) {
      s.cmd("run 1000 pre no post no");
      const Vec3 axis = s.bodies().quat[0] * axis0;
      worst = std::max(worst, std::acos(std::min(1.0, axis.dot(axis0))));
    }
    wander[k] = worst;
  }
  INFO("largest axis excursions [rad]: " << wander[0] << " " << wander[1] << " " << wander[2]);
  CHECK(wander[0] < 0.05);
  CHECK(wander[2] < 0.05);
  CHECK(wander[1] > 1.0);
}

TEST_CASE("multisphere: a dumbbell dropped tilted comes to rest lying on the plane", "[multisphere]") {
  // Both spheres (r = 1 mm) end on the plane z = 0: centre of mass at
  // r - delta, with delta the Hertz overlap under half the weight each
  // (about 3 micrometres here); the clump is then at rest.
  Sim s;
  s.cmds(setup(0.3, 0.5));
  s.cmds({kDumbbell, "fix ms all multisphere", "fix g all gravity 9.81 vector 0 0 -1",
          "fix floor all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
          // tilted by 30 degrees about y, 5 mm above the plane
          "create_clump dumb 0 0 0.005 quat 0.9659258 0 0.2588190 0", "run 60000"});
  const Bodies& b = s.bodies();
  // Hertz: F = 4/3 E* sqrt(R) delta^1.5, E* = E / (2 (1 - nu^2)), F = m g / 2
  const double estar = 5e6 / (2 * (1 - 0.45 * 0.45));
  const double delta = std::pow(3 * 0.5 * b.mass[0] * 9.81 / (4 * estar * std::sqrt(0.001)), 2.0 / 3.0);
  INFO("centre height " << b.xcm[0][2] << " m, static overlap " << delta << " m, speed " << b.vcm[0].norm());
  CHECK(b.xcm[0][2] == Approx(0.001 - delta).margin(0.2 * delta));
  const Vec3 axis = b.quat[0] * Vec3(1, 0, 0);
  CHECK(std::fabs(axis[2]) < 1e-3);  // lying flat
  CHECK(b.vcm[0].norm() < 1e-4);
  CHECK(b.omega[0].norm() < 0.1);
}

TEST_CASE("multisphere: colliding clumps conserve momentum and angular momentum", "[multisphere]") {
  // Two clumps meet off-centre at 1 m/s. Without friction every contact force
  // is central, so momentum and angular momentum are kept to round-off
  // (1e-12 of the initial values); with friction momentum still is, angular
  // momentum up to the torque of the tangential force about the overlap
  // (checked to 1e-3 relative).
  for (double mu : {0.0, 0.5}) {
    Sim s;
    s.cmds(setup(0.5, mu));
    s.cmds({kTriple, kDumbbell, "fix ms all multisphere",
            "create_clump tri -0.006 0.001 0 vel 0.5 0 0 omega 0 0 10",
            "create_clump dumb 0.006 -0.001 0.0005 quat 0.9238795 0 0 0.3826834 vel -0.5 0 0"});
    s.cmd("run 0");
    const Vec3 p0 = total_momentum(s.bodies());
    const Vec3 l0 = total_angular_momentum(s.bodies());
    const double pscale = s.bodies().mass[0] * 0.5 + s.bodies().mass[1] * 0.5;
    s.cmd("run 2000");
    const Bodies& b = s.bodies();
    INFO("friction " << mu << ": velocities " << b.vcm[0].transpose() << " | " << b.vcm[1].transpose());
    REQUIRE(std::fabs(b.vcm[0][0] - 0.5) > 0.1);  // they did collide
    CHECK((total_momentum(b) - p0).norm() <= 1e-12 * pscale);
    const double ltol = mu == 0.0 ? 1e-12 : 1e-3;
    CHECK((total_angular_momentum(b) - l0).norm() <= ltol * l0.norm());
  }
}

TEST_CASE("multisphere: fix nve/sphere leaves the spheres of clumps to fix multisphere", "[multisphere]") {
  // Two clumps collide and a free sphere falls beside them, once with
  // `fix nve/sphere` on all particles and once on the free sphere only: the
  // same trajectories to the last bit (LIGGGHTS 3.8 would integrate the clump
  // spheres a second time in the first case), and a note says so once.
  auto run = [](bool all, std::string& logtext) {
    Sim s;
    const std::string log = granary::test::temp_template("nve_note_").data();
    s.cmd("log " + log);
    s.cmds(setup(0.5, 0.5));
    s.cmds({kTriple, kDumbbell, "fix ms all multisphere", "fix g all gravity 9.81 vector 0 0 -1",
            "create_clump tri -0.006 0.001 0 vel 0.5 0 0 omega 0 0 10",
            "create_clump dumb 0.006 -0.001 0.0005 quat 0.9238795 0 0 0.3826834 vel -0.5 0 0",
            "create_atoms 1 single 0 0.01 0 units box", "set atom 6 diameter 0.002 density 2500",
            "group free id 6", all ? "fix integr all nve/sphere" : "fix integr free nve/sphere", "run 1000",
            "run 1000"});
    s.cmd("log none");
    std::ifstream in(log);
    std::stringstream ss;
    ss << in.rdbuf();
    logtext = ss.str();
    std::remove(log.c_str());
    std::vector<Vec3> x;
    const auto& p = s.p();
    std::vector<std::pair<long, Vec3>> byid;
    for (int i = 0; i < p.nlocal; ++i)
      byid.emplace_back(static_cast<long>(p.id[i]), p.x[i]);
    std::sort(byid.begin(), byid.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [id, xi] : byid)
      x.push_back(xi);
    return x;
  };
  std::string log_all, log_free;
  const std::vector<Vec3> a = run(true, log_all), f = run(false, log_free);
  REQUIRE(a.size() == 6);
  REQUIRE(f.size() == a.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    CHECK(a[i] == f[i]);
  // the free sphere was integrated: free fall from rest, z = -g t^2 / 2 after 0.02 s
  CHECK(f[5][2] == Approx(-0.5 * 9.81 * 0.02 * 0.02).epsilon(1e-6));
  const std::string note = "5 particles of its group are spheres of clumps";
  CHECK(log_all.find(note) != std::string::npos);
  CHECK(log_all.find(note, log_all.find(note) + 1) == std::string::npos);  // once, not at every run
  CHECK(log_free.find("spheres of clumps") == std::string::npos);
}

TEST_CASE("multisphere: deleting one sub-sphere deletes its whole clump", "[multisphere]") {
  Sim s;
  s.cmds(setup());
  s.cmds({kTriple, "fix ms all multisphere", "create_clump tri -0.01 0 0", "create_clump tri 0.01 0 0",
          "region one sphere -0.01 0 0 0.001", "delete_atoms region one compress no", "run 10"});
  CHECK(s.bodies().size() == 1);
  CHECK(s.bodies().xcm[0][0] == Approx(0.01));
  CHECK(s.e.particles->natoms == 3);
  // particles lost through a fixed boundary take their clump with them
  s.cmds({"thermo_modify lost ignore", "create_clump tri 0.045 0.0 0 vel 5 0 0", "run 2000"});
  CHECK(s.bodies().size() == 1);
  CHECK(s.e.particles->natoms == 3);
}

TEST_CASE("multisphere: computes ke, erotate, multisphere and orientation", "[multisphere]") {
  Sim s;
  s.cmds(setup());
  s.cmds({kDumbbell, "fix ms all multisphere",
          // long axis along z (90 degrees about y), and along x
          "create_clump dumb 0 0 0.01 quat 0.70710678 0 0.70710678 0 vel 1 2 0 omega 0 0 3",
          "create_clump dumb 0 0 -0.01 vel 0 0 0", "compute ke all ke/multisphere",
          "compute rot all erotate/multisphere", "compute b all multisphere",
          "compute o all orientation axis 0 0 1 bins 3", "region upper block INF INF INF INF 0 INF",
          "compute ou all orientation axis 0 0 1 region upper", "compute keu all ke/multisphere region upper",
          "compute rotu all erotate/multisphere region upper", "region lower block INF INF INF INF INF 0",
          "compute rotd all erotate/multisphere region lower", "run 0"});
  const Bodies& b = s.bodies();
  const double m = b.mass[0];
  CHECK(s.e.compute_value("ke", 0) == Approx(0.5 * m * 5.0));
  CHECK(s.e.compute_value("rot", 0) == Approx(0.5 * b.omega[0].dot(b.angmom[0])));
  CHECK(s.e.compute_value("rot", 0) > 0.0);
  // region keyword: only the upper clump (moving and spinning) is in `upper`, the lower one rests
  CHECK(s.e.compute_value("keu", 0) == Approx(0.5 * m * 5.0));
  CHECK(s.e.compute_value("rotu", 0) == Approx(s.e.compute_value("rot", 0)));
  CHECK(s.e.compute_value("rotd", 0) == 0.0);
  CHECK_THROWS_WITH(s.cmd("compute bad all ke/multisphere region nowhere"),
                    Catch::Matchers::Contains("nowhere"));
  // 13 values per clump: xcm vcm omega quat
  CHECK(s.e.compute_value("b", 3) == Approx(0.01));
  CHECK(s.e.compute_value("b", 4) == Approx(1.0));
  CHECK(s.e.compute_value("b", 9) == Approx(3.0));
  CHECK(s.e.compute_value("b", 13 + 3) == Approx(-0.01));
  CHECK_THROWS_AS(s.e.compute_value("b", 27), granary::InputError);  // 2 clumps x 13 values
  // one axis parallel (theta 0, P2 = 1), one perpendicular (theta pi/2, P2 = -1/2)
  CHECK(s.e.compute_value("o", 1) == Approx(M_PI / 4));
  CHECK(s.e.compute_value("o", 2) == Approx(0.5).margin(1e-7));
  CHECK(s.e.compute_value("o", 3) == Approx(0.25).margin(1e-7));
  CHECK(s.e.compute_value("o", 4) == 2.0);
  CHECK(s.e.compute_value("o", 5) == 0.5);  // first bin [0, 30) degrees
  CHECK(s.e.compute_value("o", 7) == 0.5);  // last bin [60, 90] degrees
  CHECK(s.e.compute_value("ou", 4) == 1.0);
  CHECK(s.e.compute_value("ou", 0) == Approx(1.0).margin(1e-7));
  // per-atom: every sub-sphere carries its clump's values
  std::vector<double> vx;
  s.e.compute_peratom("b", 4, vx);
  for (int i = 0; i < s.e.particles->nlocal; ++i)
    CHECK(vx[i] == (s.e.particles->x[i][2] > 0 ? 1.0 : 0.0));
}

TEST_CASE("multisphere: compute multisphere/single, compute rigid and the principal axes", "[multisphere]") {
  Sim s;
  s.cmds(setup());
  s.cmds({kDumbbell, "fix ms all multisphere",
          // long axis (the smallest principal moment, the first axis) along z: 90 degrees about y
          "create_clump dumb 0 0 0.01 quat 0.70710678 0 0.70710678 0 vel 1 2 0 omega 0 0 3",
          "create_clump dumb 0 0 -0.01 vel 0 0 0",
          "compute one all multisphere/single id 2 property xcm id_multisphere",
          "compute none all multisphere/single id 9 property masstotal",
          "compute ax all rigid property ex_space ey_space ez_space", "run 0"});
  const Bodies& b = s.bodies();
  REQUIRE(b.size() == 2);
  const int second = b.find(2);
  REQUIRE(second >= 0);
  // the one clump's values, as a global vector
  CHECK(s.e.compute_value("one", 3) == Approx(b.xcm[second].z()));
  CHECK(s.e.compute_value("one", 3) == Approx(-0.01));
  CHECK(s.e.compute_value("one", 4) == 2.0);
  CHECK_THROWS_AS(s.e.compute_value("one", 5), granary::InputError);
  CHECK(s.e.compute_value("none", 1) == 0.0);  // no clump 9
  // principal axes in space: R_y(90 deg) takes x to -z, y to y, z to x
  const int first = b.find(1);
  REQUIRE(first >= 0);
  const int base = 9 * first;
  CHECK(s.e.compute_value("ax", base + 3) == Approx(-1.0).margin(1e-7));
  CHECK(s.e.compute_value("ax", base + 5) == Approx(1.0).margin(1e-7));
  CHECK(s.e.compute_value("ax", base + 7) == Approx(1.0).margin(1e-7));
  CHECK(std::abs(s.e.compute_value("ax", base + 1)) < 1e-7);
  CHECK_THROWS_WITH(s.cmd("compute bad all multisphere/single 3"), Catch::Matchers::Contains("usage"));
  CHECK_THROWS_WITH(s.cmd("compute bad all multisphere/single id 0"),
                    Catch::Matchers::Contains("the clump id must be >= 1"));
  CHECK_THROWS_WITH(s.cmd("compute bad all rigid property clumptype"),
                    Catch::Matchers::Contains("the template of a clump is not kept"));
  // compute slice: the z of each clump out of the 13 values per clump of c_b
  s.cmds({"compute b all multisphere", "compute zs all slice 3 26 13 c_b",
          "compute one3 all slice 2 3 5 c_one"});
  CHECK(s.e.compute_value("zs", 1) == Approx(b.xcm[b.find(1)].z()));
  CHECK(s.e.compute_value("zs", 2) == Approx(b.xcm[b.find(2)].z()));
  CHECK_THROWS_AS(s.e.compute_value("zs", 3), granary::InputError);  // 2 values
  CHECK(s.e.compute_value("one3", 1) == b.xcm[b.find(2)].y());       // the y of clump 2 only
  s.cmd("compute far all slice 1 40 1 c_b");
  CHECK_THROWS_WITH(s.e.compute_value("far", 1),
                    Catch::Matchers::Contains("NSTOP 40 is beyond the 26 values"));
  CHECK_THROWS_WITH(s.cmd("compute bad all slice 3 2 1 c_b"), Catch::Matchers::Contains("NSTART <= NSTOP"));
  CHECK_THROWS_WITH(s.cmd("compute bad all slice 1 2 1 c_b c_one"),
                    Catch::Matchers::Contains("one input per compute slice"));
  CHECK_THROWS_WITH(s.cmd("compute bad all slice 1 2 1 c_b[2]"), Catch::Matchers::Contains("global array"));
  CHECK_THROWS_WITH(s.cmd("compute bad all slice 1 2 1 v_x"),
                    Catch::Matchers::Contains("must be c_ID or f_ID"));
}

TEST_CASE("multisphere: ke and erotate count clumps as bodies, erotate/sphere leaves them out",
          "[multisphere]") {
  // LIGGGHTS 3.8, measured on its tutorial multisphere_stone_restitution with
  // `compute erotate/sphere`, `erotate` and `erotate/multisphere`: the first
  // is 0 for the tumbling stones, the second equals the third. Here a
  // spinning clump beside a spinning free sphere: erotate/sphere is the free
  // sphere's 1/2 (2/5 m r^2) w^2 only, erotate the sum of that and the clump's
  // 1/2 w.L (1e-12). Likewise LIGGGHTS' ke (compute and thermo keyword) equals
  // ke/multisphere there: here ke is the sphere's 1/2 m v^2 plus the clump's
  // 1/2 M v_cm^2, not the sum over its sub-spheres (which adds their motion
  // about the centre of mass).
  Sim s;
  s.cmds(setup());
  s.cmds({kDumbbell, "fix ms all multisphere", "create_clump dumb 0 0 0.01 vel 0.5 -0.2 0.1 omega 3 -1 7",
          "create_atoms 1 single 0.02 0 0 units box", "set atom 3 diameter 0.004 density 2000",
          "set atom 3 omegax 10 omegay 20 omegaz -30", "compute rs all erotate/sphere",
          "compute r all erotate", "compute rm all erotate/multisphere", "compute k all ke", "run 0"});
  const Bodies& b = s.bodies();
  REQUIRE(b.size() == 1);
  const double m = 2000.0 * 4.0 / 3.0 * M_PI * std::pow(0.002, 3);
  const double free = 0.5 * 0.4 * m * 0.002 * 0.002 * (100.0 + 400.0 + 900.0);
  const double clump = 0.5 * b.omega[0].dot(b.angmom[0]);
  CHECK(clump > 0.0);
  CHECK(s.e.compute_value("rs", 0) == Approx(free).epsilon(1e-12));
  CHECK(s.e.compute_value("rm", 0) == Approx(clump).epsilon(1e-12));
  CHECK(s.e.compute_value("r", 0) == Approx(free + clump).epsilon(1e-12));
  // translational: the free sphere at rest, the clump moving
  s.cmds({"set atom 3 vx 1 vy 2 vz -2", "run 0"});
  const double ke = 0.5 * m * 9.0 + 0.5 * b.mass[0] * b.vcm[0].squaredNorm();
  CHECK(b.vcm[0].norm() > 0.1);
  CHECK(s.e.compute_value("k", 0) == Approx(ke).epsilon(1e-12));
  bool found = false;
  CHECK(s.e.thermo_keyword("ke", found) == Approx(ke).epsilon(1e-12));
  CHECK(found);
}

TEST_CASE("multisphere: a restarted run continues the clumps bit for bit", "[multisphere]") {
  // A spinning, falling clump bouncing on the floor next to a free sphere:
  // 2000 steps straight against 1000 + write_restart + read_restart + 1000.
  auto physics = [](Sim& s) {
    s.cmds({"neighbor 0.001 bin", "neigh_modify delay 0", granary::test::materials(1, 5.e6, 0.45, 0.5, 0.5),
            "pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 1e-5",
            "fix g all gravity 9.81 vector 0 0 -1",
            "fix floor all wall/gran model hertz tangential history primitive type 1 zplane -0.05",
            "fix ms all multisphere", "fix nve all nve/sphere"});
  };
  auto scene = [&](Sim& s) {
    s.cmds({"units si", "atom_style granular", "boundary f f f",
            "region box block -0.05 0.05 -0.05 0.05 -0.05 0.05", "create_box 1 box"});
    physics(s);
    s.cmds({kTriple, "create_clump tri 0 0 -0.0465 omega 20 30 -10 vel 0.1 0 -0.3",
            "create_atoms 1 single 0.004 0 -0.048", "set atom 4 diameter 0.002 density 2500"});
  };
  Vec3 x_straight, l_straight;
  double ke_straight = 0.0;
  {
    Sim s;
    scene(s);
    s.cmd("run 2000");
    x_straight = s.bodies().xcm[0];
    l_straight = s.bodies().angmom[0];
    ke_straight = s.bodies().kinetic_translational(0) + s.bodies().kinetic_rotational(0);
  }
  {
    Sim s;
    scene(s);
    s.cmd("run 1000");
    s.cmd("write_restart multisphere_test.restart");
  }
  Sim s;
  s.cmds({"atom_style granular", "read_restart multisphere_test.restart"});
  physics(s);
  REQUIRE(s.bodies().size() == 1);
  s.cmd("run 1000");
  const Bodies& b = s.bodies();
  CHECK(b.xcm[0] == x_straight);  // identical to the bit
  CHECK(b.angmom[0] == l_straight);
  CHECK(b.kinetic_translational(0) + b.kinetic_rotational(0) == ke_straight);
  if (s.e.rank == 0) std::remove("multisphere_test.restart");
}

TEST_CASE("multisphere: clumps inserted by fix insert/pack are taken over", "[multisphere]") {
  // Twelve clumps of two templates poured by insert/pack into a box with a
  // floor: every one becomes a body with all its spheres, the sphere masses
  // are shares of the body mass (summing to it), and gravity gives each
  // falling clump exactly g (no torque: the shares' centre is the centre of mass).
  Sim s;
  s.cmds(setup());
  s.cmds({kTriple, kDumbbell, "fix pdd all particledistribution/discrete 15485869 2 tri 0.5 dumb 0.5",
          "fix ms all multisphere", "region fill block -0.03 0.03 -0.03 0.03 0.0 0.04",
          "fix ins all insert/pack seed 32452843 distributiontemplate pdd vel constant 0 0 -0.1 "
          "insert_every once overlapcheck yes all_in yes region fill particles_in_region 12",
          "fix g all gravity 9.81 vector 0 0 -1",
          "fix floor all wall/gran model hertz tangential history primitive type 1 zplane -0.05", "run 200"});
  const Bodies& b = s.bodies();
  REQUIRE(b.size() == 12);
  CHECK(s.e.particles->natoms == b.total_spheres());
  // per-body sums of the sphere masses (over all ranks)
  std::vector<double> local(b.size(), 0.0), sum(b.size(), 0.0);
  const auto& p = *s.e.particles;
  for (int i = 0; i < p.nlocal; ++i) {
    REQUIRE(p.body[i] >= 0);
    local[b.find(p.body[i])] += p.rmass[i];
  }
  MPI_Allreduce(local.data(), sum.data(), b.size(), MPI_DOUBLE, MPI_SUM, s.e.world);
  for (int k = 0; k < b.size(); ++k) {
    CHECK(sum[k] == Approx(b.mass[k]).epsilon(1e-12));
    // in free fall since the insertion at step 1 (which gets only the second
    // half kick): v = -0.1 - g 199.5 dt, no rotation (inserted without spin)
    INFO("clump " << b.tag[k] << " (" << b.nspheres[k] << " spheres): v " << b.vcm[k].transpose()
                  << ", omega " << b.omega[k].transpose() << ", force " << b.fcm[k].transpose() << ", torque "
                  << b.torque[k].transpose());
    CHECK(b.vcm[k][2] == Approx(-0.1 - 9.81 * 199.5 * 1e-5).epsilon(1e-9));
    CHECK(b.omega[k].norm() < 1e-9);
  }
}

TEST_CASE("multisphere: body sums alike whether its sub-spheres lie in order or scattered", "[multisphere]") {
  // Two spinning three-sphere clumps bounce on the floor, apart from each
  // other. fix multisphere sums a body's forces along its sub-spheres when
  // they lie at consecutive indices in sub-sphere order, and through per
  // sub-sphere slots otherwise: both must add the same values in the same
  // order. The particles created in order (runs) against the same particles
  // in reverse order (no body in sub-sphere order: slots), no spatial sort;
  // the floor's forces depend on each particle alone.
  auto run = [](bool reverse) {
    Sim s;
    clumps_on_floor(s,
                    {kTriple, "create_clump tri -0.02 0 -0.0465 omega 20 30 -10 vel 0.1 0 -0.3",
                     "create_clump tri 0.02 0.01 -0.046 omega -15 5 25 vel -0.05 0.1 -0.2"},
                    reverse);
    REQUIRE(s.e.particles->nlocal == 6);
    s.cmd("run 2000");
    const Bodies& b = s.bodies();
    REQUIRE(b.size() == 2);
    // some floor contact happened: the clumps were turned and slowed
    CHECK(b.vcm[0].z() > -0.3);
    return std::vector<Vec3>{b.xcm[0], b.xcm[1], b.vcm[0], b.vcm[1], b.angmom[0], b.angmom[1]};
  };
  const std::vector<Vec3> in_order = run(false), scattered = run(true);
  for (std::size_t k = 0; k < in_order.size(); ++k)
    CHECK(in_order[k] == scattered[k]);  // to the bit
}

TEST_CASE("multisphere: clumps of different templates keep their own shapes", "[multisphere]") {
  // Clumps of templates with the same number and sizes of spheres but other
  // offsets (dumbbells 2 and 3 mm long) tumble on the floor together. fix
  // multisphere reads the offsets of all clumps of one template from one
  // place: each sub-sphere must still sit where its own body's offsets put
  // it (x = xcm + R d, the same operations: to the bit), with the
  // sub-spheres in order (summed along runs) and in reverse order (slots).
  const char* kLong =
      "fix long all particletemplate/multisphere 15485863 atom_type 1 density constant 2500 nspheres 2 ntry "
      "1000000 spheres -0.0015 0 0 0.001 0.0015 0 0 0.001 type 1";
  for (const bool reverse : {false, true}) {
    Sim s;
    clumps_on_floor(s,
                    {kDumbbell, kLong, "create_clump dumb -0.02 0 -0.046 omega 20 30 -10 vel 0.1 0 -0.3",
                     "create_clump long -0.0165 0.0005 -0.04 omega -15 5 25 vel -0.05 0.1 -0.2",
                     "create_clump dumb 0.02 0.01 -0.046 omega 5 -40 10 vel 0 0.05 -0.25",
                     "create_clump long 0.017 0.01 -0.04 omega 30 10 -20 vel 0.05 -0.1 -0.3"},
                    reverse);
    const granary::Particles& p = *s.e.particles;
    REQUIRE(p.nlocal == 8);
    s.cmd("run 3000");
    const Bodies& b = s.bodies();
    REQUIRE(b.size() == 4);
    int placed = 0;
    for (int i = 0; i < p.nlocal; ++i) {
      const int k = b.find(p.body[i]);
      REQUIRE(k >= 0);
      const int d = b.sphere_start[k] + static_cast<int>(p.id[i] - b.first_id[k]);
      const Vec3 expected = b.xcm[k] + b.rotation(k) * b.offsets[d];
      CHECK(p.x[i] == expected);
      placed += p.x[i] == expected;
    }
    CHECK(placed == 8);
    // the dumbbells met each other or the floor: spun and slowed
    CHECK(b.vcm[0].z() > -0.3);
  }
}
