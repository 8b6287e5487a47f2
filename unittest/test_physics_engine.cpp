// Engine-level physics: whole input scripts run through the engine (pair
// style, walls, integrator, gravity, neighbour lists) and compared with
// analytical results. Each test states its tolerance and where the expected
// value comes from.
//
// Common material unless a test says otherwise: glass-like beads of
// diameter 2 mm and density 2500 kg/m3 with a soft Young's modulus
// Y = 5 MPa and nu = 0.3, so that a contact lasts a few hundred steps of a
// microsecond timestep. For these values the Rayleigh time is
//   t_R = pi r sqrt(rho/G)/(0.1631 nu + 0.8766) = 1.22e-4 s  (G = Y/(2(1+nu)))
// and the Hertz contact time of a 1 m/s head-on impact is about 2.7e-4 s.
#include <Eigen/Geometry>  // cross products
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "script_engine.h"
#include "core/engine.h"
#include "core/input.h"
#include "core/logger.h"
#include "core/update.h"
#include "particles/particles.h"

namespace {

using granary::Vec3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadius = 0.001;  // [m]
constexpr double kDensity = 2500;  // [kg/m3]
constexpr double kYoung = 5.0e6;   // [Pa]
constexpr double kPoisson = 0.3;

/// A number written so that it reads back exactly.
std::string num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

/// n copies of one value, blank-separated.
std::string repeat(double v, int n) {
  std::string out;
  for (int k = 0; k < n; ++k)
    out += (k ? " " : "") + num(v);
  return out;
}

/// LIGGGHTS material set-up: every type has the same properties.
std::vector<std::string> materials(int ntypes, double e, double mu, double mu_r = -1.0) {
  std::vector<std::string> lines = {
      "fix m1 all property/global youngsModulus peratomtype " + repeat(kYoung, ntypes),
      "fix m2 all property/global poissonsRatio peratomtype " + repeat(kPoisson, ntypes),
      "fix m3 all property/global coefficientRestitution peratomtypepair " + std::to_string(ntypes) + " " +
          repeat(e, ntypes * ntypes),
      "fix m4 all property/global coefficientFriction peratomtypepair " + std::to_string(ntypes) + " " +
          repeat(mu, ntypes * ntypes),
  };
  if (mu_r >= 0.0) {
    lines.push_back("fix m5 all property/global coefficientRollingFriction peratomtypepair " +
                    std::to_string(ntypes) + " " + repeat(mu_r, ntypes * ntypes));
  }
  return lines;
}

/// One engine on this rank alone, screen output off.
struct Sim : granary::test::ScriptEngine {
  Sim() : ScriptEngine(MPI_COMM_SELF) {}
  /// Local index of the particle with this id (fails the test when absent).
  int index(long long id) const {
    for (int i = 0; i < p().nlocal; ++i)
      if (p().id[i] == id) return i;
    FAIL("no particle with id " << id);
    return -1;
  }
  Vec3 x(long long id) const { return p().x[index(id)]; }
  Vec3 v(long long id) const { return p().v[index(id)]; }
  Vec3 omega(long long id) const { return p().omega[index(id)]; }
};

std::vector<std::string> header(const std::string& boundary, const std::string& box, int ntypes) {
  return {"units si",
          "atom_style granular",
          "boundary " + boundary,
          "newton off",
          "region box block " + box + " units box",
          "create_box " + std::to_string(ntypes) + " box",
          "neighbor 0.0005 bin",
          "neigh_modify delay 0"};
}

void append(std::vector<std::string>& a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
}

// Effective Young's modulus of two equal materials, Y* = Y/(2(1-nu^2)).
double y_eff() {
  return kYoung / (2.0 * (1.0 - kPoisson * kPoisson));
}
double bead_mass() {
  return kDensity * 4.0 / 3.0 * kPi * kRadius * kRadius * kRadius;
}

// ---------------------------------------------------------------- restitution

struct PairImpact {
  Vec3 v1, v2, w1, w2;
  double gap;  // final surface gap (> 0: separated)
};

/// Two beads approach along x at +-0.5 m/s (plus an optional sideways offset
/// and spin of bead 2) and collide once; returns the final state.
PairImpact pair_impact(const std::string& pair_style, double e, double offset_y, double spin, double mu,
                       double mu_r, const std::string& coeff = "* *") {
  Sim s;
  auto script = header("m m m", "-0.01 0.01 -0.01 0.01 -0.01 0.01", 1);
  append(script, materials(1, e, mu, mu_r));
  append(script, {
                     "pair_style " + pair_style,
                     "pair_coeff " + coeff,
                     "timestep 1e-6",
                     "create_atoms 1 single -0.0011 0 0 units box",
                     "create_atoms 1 single 0.0011 " + num(offset_y) + " 0 units box",
                     "set type 1 diameter 0.002 density 2500",
                     "set atom 1 vx 0.5",
                     "set atom 2 vx -0.5 omega 0 0 " + num(spin),
                     "fix integr all nve/sphere",
                     "run 1200",
                 });
  s.lines(script);
  REQUIRE(s.p().nlocal == 2);
  PairImpact r;
  r.v1 = s.v(1);
  r.v2 = s.v(2);
  r.w1 = s.omega(1);
  r.w2 = s.omega(2);
  r.gap = (s.x(2) - s.x(1)).norm() - 2 * kRadius;
  return r;
}

}  // namespace

// Head-on impact of two equal beads at a relative speed of 1 m/s. Without
// tangential motion the normal force law alone acts, and the coefficient of
// restitution is the ratio of the relative normal speeds after and before,
//   e = (v2' - v1') / (v1 - v2).
// The Hertz spring-dashpot of LIGGGHTS (damping 2 sqrt(5/6) beta sqrt(Sn m*),
// beta = ln e / sqrt(ln^2 e + pi^2)) is built to reproduce e independently of
// the impact speed; with about 270 steps per contact the integration error is
// far below the 1% tolerance.
TEST_CASE("head-on sphere-sphere impact reproduces the coefficient of restitution", "[physics][engine]") {
  for (double e : {0.3, 0.6, 0.9}) {
    const PairImpact r = pair_impact("gran model hertz tangential history", e, 0.0, 0.0, 0.5, -1);
    INFO("e = " << e << ", final v1 = " << r.v1.transpose() << ", v2 = " << r.v2.transpose());
    REQUIRE(r.gap > 0.0);  // the contact is over
    const double e_measured = (r.v2[0] - r.v1[0]) / 1.0;
    CHECK(e_measured == Approx(e).epsilon(0.01));
    // momentum along x stays zero, nothing moves sideways or spins
    CHECK(std::fabs(r.v1[0] + r.v2[0]) < 1e-12);
    CHECK(r.v1.tail<2>().norm() < 1e-12);
    CHECK(r.w1.norm() < 1e-9);
  }
}

// `pair_style hertz/rolling` is Granary's name for `pair_style gran model hertz
// tangential history rolling_friction cdt`: both spellings must build the same
// kernel, so trajectories agree to rounding (compared to 1e-12 m/s and rad/s;
// in practice they are bitwise equal). Checked head-on (normal force only) and
// for an oblique, spinning impact that uses the tangential spring, the Coulomb
// limit and rolling friction.
TEST_CASE("pair_style hertz/rolling and gran model hertz give identical trajectories", "[physics][engine]") {
  auto same = [](const PairImpact& a, const PairImpact& b) {
    CHECK((a.v1 - b.v1).norm() < 1e-12);
    CHECK((a.v2 - b.v2).norm() < 1e-12);
    CHECK((a.w1 - b.w1).norm() < 1e-12);
    CHECK((a.w2 - b.w2).norm() < 1e-12);
  };
  for (double e : {0.3, 0.6, 0.9}) {
    INFO("head-on, e = " << e);
    same(pair_impact("gran model hertz tangential history rolling_friction cdt", e, 0.0, 0.0, 0.5, 0.1),
         pair_impact("hertz/rolling", e, 0.0, 0.0, 0.5, 0.1));
    same(pair_impact("gran model hertz tangential history", e, 0.0, 0.0, 0.5, -1),
         pair_impact("hertz/rolling rolling_friction off", e, 0.0, 0.0, 0.5, -1));
  }
  {
    INFO("oblique with spin");
    const PairImpact a =
        pair_impact("gran model hertz tangential history rolling_friction cdt", 0.6, 0.0008, 300.0, 0.3, 0.1);
    const PairImpact b = pair_impact("hertz/rolling", 0.6, 0.0008, 300.0, 0.3, 0.1);
    same(a, b);
    CHECK(a.w1.norm() > 1.0);  // the tangential force really acted
    const PairImpact c = pair_impact("gran model hertz tangential history", 0.6, 0.0008, 300.0, 0.3, -1);
    const PairImpact d = pair_impact("hertz/rolling rolling_friction off", 0.6, 0.0008, 300.0, 0.3, -1);
    same(c, d);
    CHECK((a.w2 - c.w2).norm() > 1e-6);  // and rolling friction made a difference
  }
}

// `pair_style hybrid` (and hybrid/overlay) with one granular sub-style, as
// LIGGGHTS 3.8 runs it (`pair_coeff * * gran`), and `pair_style bubble` and
// `gran_bubble` (LIGGGHTS' aliases of gran), on their own or as the sub-style: the same kernel as pair_style
// gran, so the same trajectories (bitwise in practice, checked to 1e-12); a second sub-style and a pair_coeff
// with another sub-style name are errors.
TEST_CASE("pair_style hybrid with one granular sub-style, bubble and gran_bubble are pair_style gran",
          "[physics][engine]") {
  const std::string model = "model hertz tangential history rolling_friction cdt";
  const PairImpact a = pair_impact("gran " + model, 0.6, 0.0008, 300.0, 0.3, 0.1);
  CHECK(a.w1.norm() > 1.0);
  for (const std::string sub : {"gran", "bubble", "gran_bubble"}) {
    {
      INFO("pair_style " << sub);  // LIGGGHTS' aliases of gran on their own
      const PairImpact b = pair_impact(sub + " " + model, 0.6, 0.0008, 300.0, 0.3, 0.1);
      CHECK((a.w2 - b.w2).norm() < 1e-12);
      CHECK((a.v2 - b.v2).norm() < 1e-12);
    }
    for (const std::string hyb : {"hybrid", "hybrid/overlay"}) {
      INFO(hyb << " " << sub);
      const PairImpact b =
          pair_impact(hyb + " " + sub + " " + model, 0.6, 0.0008, 300.0, 0.3, 0.1, "* * " + sub);
      CHECK((a.v1 - b.v1).norm() < 1e-12);
      CHECK((a.v2 - b.v2).norm() < 1e-12);
      CHECK((a.w1 - b.w1).norm() < 1e-12);
      CHECK((a.w2 - b.w2).norm() < 1e-12);
    }
  }
  Sim s;
  auto script = header("m m m", "-0.01 0.01 -0.01 0.01 -0.01 0.01", 1);
  append(script, materials(1, 0.5, 0.5, 0.1));
  s.lines(script);
  CHECK_THROWS_WITH(s.lines({"pair_style hybrid gran model hertz tangential history bubble model hertz "
                             "tangential no_history"}),
                    Catch::Contains("a second sub-style 'bubble'") && Catch::Contains("one contact law"));
  CHECK_THROWS_WITH(s.lines({"pair_style hybrid model hertz"}), Catch::Contains("one granular sub-style"));
  s.lines({"pair_style hybrid gran model hertz tangential history"});
  CHECK_THROWS_WITH(s.lines({"pair_coeff * * bubble"}), Catch::Contains("use pair_coeff * * gran"));
  CHECK_THROWS_WITH(s.lines({"pair_coeff * *"}), Catch::Contains("pair_coeff * * gran"));
}

// A bead falls onto a zplane wall/gran of the same material at 0.5 m/s
// (no gravity). For a flat wall m* = m and R* = r, and the wall is at rest, so
// e = -vz'/vz. Tolerance 1% as for the pair impact.
TEST_CASE("sphere-wall impact reproduces the coefficient of restitution", "[physics][engine]") {
  for (double e : {0.3, 0.6, 0.9}) {
    Sim s;
    auto script = header("m m m", "-0.005 0.005 -0.005 0.005 0 0.005", 1);
    append(script, materials(1, e, 0.5));
    append(script, {
                       "pair_style gran model hertz tangential history",
                       "pair_coeff * *",
                       "timestep 1e-6",
                       "create_atoms 1 single 0 0 0.0011 units box",
                       "set type 1 diameter 0.002 density 2500",
                       "velocity all set 0 0 -0.5",
                       "fix wall all wall/gran model hertz tangential history primitive type 1 zplane 0.0",
                       "fix integr all nve/sphere",
                       "run 1000",
                   });
    s.lines(script);
    const Vec3 v = s.v(1);
    INFO("e = " << e << ", final v = " << v.transpose() << ", z = " << s.x(1)[2]);
    REQUIRE(s.x(1)[2] > kRadius);  // off the wall again
    CHECK(v[2] / 0.5 == Approx(e).epsilon(0.01));
    CHECK(v.head<2>().norm() < 1e-12);
  }
}

// ---------------------------------------------------------------- energy

namespace {
/// Deterministic numbers in [0, 1) (64-bit LCG, top 53 bits).
struct Lcg {
  std::uint64_t s;
  explicit Lcg(std::uint64_t seed) : s(seed) {}
  double next() {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(s >> 11) * (1.0 / 9007199254740992.0);
  }
};
}  // namespace

// 48 beads with random velocities (components in [-0.5, 0.5] m/s) in a closed
// 12 mm box bounded by six wall/gran planes; e = 1 (no normal damping, and
// tangential damping is proportional to beta = 0 as well), no friction, no
// rolling friction, no gravity. The total energy
//   E = sum 1/2 m v^2 + 1/2 I w^2 + sum_contacts 8/15 Y* sqrt(R*) delta^(5/2)
// (the last term is the Hertz elastic energy of the contacts open at the end)
// is then a constant of the motion. Velocity Verlet is symplectic: its energy
// error stays bounded, of order (omega dt)^2 while a contact is open
// (omega^2 ~ dF/ddelta / m*), and what is left after each collision is much
// smaller. With dt = 2e-6 s a contact spans about 125 steps, so 1e-3 relative
// after 10000 steps and some hundred collisions is a safe bound.
TEST_CASE("elastic frictionless beads in a closed box conserve energy", "[physics][engine]") {
  const double L = 0.012;
  Sim s;
  auto script = header("f f f", "0 0.012 0 0.012 0 0.012", 1);
  append(script, materials(1, 1.0, 0.0));
  append(script, {"pair_style gran model hertz tangential history", "pair_coeff * *", "timestep 2e-6"});
  Lcg rng(20240611);
  int n = 0;
  for (int ix = 0; ix < 4; ++ix)
    for (int iy = 0; iy < 4; ++iy)
      for (int iz = 0; iz < 3; ++iz) {
        const double x = 0.0015 + 0.003 * ix + 0.0006 * (rng.next() - 0.5);
        const double y = 0.0015 + 0.003 * iy + 0.0006 * (rng.next() - 0.5);
        const double z = 0.002 + 0.004 * iz + 0.0006 * (rng.next() - 0.5);
        script.push_back("create_atoms 1 single " + num(x) + " " + num(y) + " " + num(z) + " units box");
        ++n;
      }
  script.push_back("set type 1 diameter 0.002 density 2500");
  for (int id = 1; id <= n; ++id) {
    script.push_back("set atom " + std::to_string(id) + " vx " + num(rng.next() - 0.5) + " vy " +
                     num(rng.next() - 0.5) + " vz " + num(rng.next() - 0.5));
  }
  const char* planes[6] = {"xplane 0",     "xplane 0.012", "yplane 0",
                           "yplane 0.012", "zplane 0",     "zplane 0.012"};
  for (int k = 0; k < 6; ++k) {
    script.push_back("fix w" + std::to_string(k) +
                     " all wall/gran model hertz tangential history primitive type 1 " + planes[k]);
  }
  script.push_back("fix integr all nve/sphere");
  script.push_back("run 0");
  s.lines(script);
  const auto& p = s.p();
  REQUIRE(p.nlocal == n);

  // Hertz elastic energy 8/15 Y* sqrt(R*) delta^2.5 of every open contact.
  const double ys = y_eff();
  auto contacts = [&](std::set<std::pair<long long, long long>>& pairs,
                      std::set<std::pair<long long, int>>& walls) {
    double pe = 0.0;
    pairs.clear();
    walls.clear();
    for (int i = 0; i < p.nlocal; ++i) {
      for (int j = i + 1; j < p.nlocal; ++j) {
        const double delta = p.radius[i] + p.radius[j] - (p.x[i] - p.x[j]).norm();
        if (delta <= 0) continue;
        const double rs = p.radius[i] * p.radius[j] / (p.radius[i] + p.radius[j]);
        pe += 8.0 / 15.0 * ys * std::sqrt(rs) * std::pow(delta, 2.5);
        pairs.emplace(std::min(p.id[i], p.id[j]), std::max(p.id[i], p.id[j]));
      }
      for (int d = 0; d < 3; ++d) {
        for (int side = 0; side < 2; ++side) {
          const double delta = p.radius[i] - (side ? L - p.x[i][d] : p.x[i][d]);
          if (delta <= 0) continue;
          pe += 8.0 / 15.0 * ys * std::sqrt(p.radius[i]) * std::pow(delta, 2.5);
          walls.emplace(p.id[i], 2 * d + side);
        }
      }
    }
    return pe;
  };
  auto kinetic = [&]() {
    double ke = 0.0;
    for (int i = 0; i < p.nlocal; ++i) {
      ke += 0.5 * p.rmass[i] * p.v[i].squaredNorm();
      ke += 0.5 * 0.4 * p.rmass[i] * p.radius[i] * p.radius[i] * p.omega[i].squaredNorm();
    }
    return ke;
  };
  std::set<std::pair<long long, long long>> pairs, pairs_before;
  std::set<std::pair<long long, int>> walls, walls_before;
  const double e0 = kinetic() + contacts(pairs_before, walls_before);
  REQUIRE(pairs_before.empty());
  long long pair_collisions = 0, wall_collisions = 0;
  // Advance in chunks of 5 steps (a contact lasts > 100) and count contacts that open.
  const int chunk = 5, steps = 10000;
  double pe = 0.0;
  for (int done = 0; done < steps; done += chunk) {
    s.e.update->run(chunk, false, false);
    pe = contacts(pairs, walls);
    for (const auto& c : pairs)
      pair_collisions += pairs_before.count(c) == 0;
    for (const auto& c : walls)
      wall_collisions += walls_before.count(c) == 0;
    std::swap(pairs, pairs_before);
    std::swap(walls, walls_before);
  }
  REQUIRE(p.nlocal == n);
  const double e1 = kinetic() + pe;
  INFO("pair collisions " << pair_collisions << ", wall collisions " << wall_collisions << ", E0 = " << e0
                          << " J, E1 = " << e1 << " J, relative change " << (e1 - e0) / e0);
  CHECK(pair_collisions > 100);
  CHECK(wall_collisions > 50);
  CHECK(std::fabs(e1 - e0) < 1e-3 * e0);
}

// ---------------------------------------------------------------- momentum

// Two beads of different size and density collide obliquely, with spin, with
// Coulomb friction (mu = 0.5), tangential history and cdt rolling friction;
// no walls, no gravity. Every contact force acts with opposite signs on the
// two beads, so the total momentum is conserved to rounding (1e-12 relative).
// The contact force acts at the contact point: with lever arms r_i - delta/2
// and r_j - delta/2 summing to |x_i - x_j|, the torques of the tangential force
// balance the moment of the pair force, and the rolling torques are equal and
// opposite; velocity Verlet then preserves the total angular momentum
//   L = sum x_i x m_i v_i + I_i w_i   (about the origin, I = 2/5 m r^2)
// exactly up to rounding as well (each step changes L by dt/2 times the total
// torque about the origin, which vanishes up to the rounding of the lever
// arms). 1e-9 relative leaves ample room for that rounding over 3000 steps.
TEST_CASE("oblique impact with friction and rolling friction conserves momentum and angular momentum",
          "[physics][engine]") {
  Sim s;
  auto script = header("m m m", "-0.01 0.01 -0.01 0.01 -0.01 0.01", 2);
  script.push_back("fix m1 all property/global youngsModulus peratomtype 5e6 8e6");
  script.push_back("fix m2 all property/global poissonsRatio peratomtype 0.3 0.25");
  script.push_back("fix m3 all property/global coefficientRestitution peratomtypepair 2 0.5 0.6 0.6 0.7");
  script.push_back("fix m4 all property/global coefficientFriction peratomtypepair 2 0.5 0.5 0.5 0.5");
  script.push_back("fix m5 all property/global coefficientRollingFriction peratomtypepair 2 0.1 0.1 0.1 0.1");
  append(script, {
                     "pair_style gran model hertz tangential history rolling_friction cdt",
                     "pair_coeff * *",
                     "timestep 1e-6",
                     "create_atoms 1 single 0.0030 0.0020 -0.0010 units box",
                     "create_atoms 2 single 0.0058 0.0029 -0.0006 units box",
                     "set atom 1 diameter 0.002 density 2500 vx 0.8 vy 0.1 vz 0.05 omega 40 -120 300",
                     "set atom 2 diameter 0.003 density 1500 vx -0.3 vy -0.05 vz 0.0 omega -200 90 -50",
                     "fix integr all nve/sphere",
                 });
  s.lines(script);
  const auto& p = s.p();
  auto momenta = [&](Vec3& P, Vec3& L) {
    P.setZero();
    L.setZero();
    for (int i = 0; i < p.nlocal; ++i) {
      P += p.rmass[i] * p.v[i];
      L += p.rmass[i] * p.x[i].cross(p.v[i]) + 0.4 * p.rmass[i] * p.radius[i] * p.radius[i] * p.omega[i];
    }
  };
  s.cmd("run 0");
  Vec3 P0, L0, P1, L1;
  momenta(P0, L0);
  s.cmd("run 3000");
  momenta(P1, L1);
  REQUIRE(p.nlocal == 2);
  // the collision happened: both beads changed velocity and spin
  const Vec3 w1 = s.omega(1);
  INFO("P0 = " << P0.transpose() << ", relative change " << (P1 - P0).norm() / P0.norm()
               << "; L0 = " << L0.transpose() << ", relative change " << (L1 - L0).norm() / L0.norm()
               << "; w1 = " << w1.transpose());
  CHECK((s.v(1) - Vec3(0.8, 0.1, 0.05)).norm() > 0.1);
  CHECK((w1 - Vec3(40, -120, 300)).norm() > 10);
  CHECK((P1 - P0).norm() < 1e-12 * P0.norm());
  CHECK((L1 - L0).norm() < 1e-9 * L0.norm());
}

// ---------------------------------------------------------------- sliding and rolling

namespace {
/// A bead resting on a zplane wall under gravity, at its equilibrium overlap
/// (m g = 4/3 Y* sqrt(r) delta^1.5), then started with (vx, omega_y).
struct Roller {
  Sim s;
  /// model: the rolling_friction model; extra: lines after the materials
  Roller(double mu, double mu_r, double vx, double wy, const std::string& model = "cdt",
         const std::vector<std::string>& extra = {}) {
    const double g = 9.81;
    const double delta = std::pow(bead_mass() * g / (4.0 / 3.0 * y_eff() * std::sqrt(kRadius)), 2.0 / 3.0);
    auto script = header("m m m", "-0.01 0.3 -0.005 0.005 0 0.005", 1);
    append(script, materials(1, 0.5, mu, mu_r));
    append(script, extra);
    const std::string rolling = mu_r >= 0 ? " rolling_friction " + model : "";
    append(script, {
                       "pair_style gran model hertz tangential history" + rolling,
                       "pair_coeff * *",
                       "timestep 1e-5",
                       "create_atoms 1 single 0 0 " + num(kRadius - delta) + " units box",
                       "set type 1 diameter 0.002 density 2500",
                       "set atom 1 vx " + num(vx) + " omega 0 " + num(wy) + " 0",
                       "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
                       "fix wall all wall/gran model hertz tangential history" + rolling +
                           " primitive type 1 zplane 0.0",
                       "fix integr all nve/sphere",
                   });
    s.lines(script);
  }
};
}  // namespace

// A bead launched along the wall at v0 = 0.5 m/s without spin slides, and
// Coulomb friction mu m g decelerates it (dv/dt = -mu g) while spinning it up
// (dw/dt = mu m g r / I = 5 mu g / (2 r)). Sliding stops when v = r w:
//   v0 - mu g t = 5/2 mu g t  ->  t = 2 v0 / (7 mu g),  v = 5/7 v0,
// independent of mu; afterwards it rolls at constant speed (no rolling
// friction). Sliding lasts 0.029 s here; 0.08 s are simulated. The tangential
// spring makes the end of sliding slightly soft, far below the 1% tolerance.
TEST_CASE("a sliding sphere on a wall ends rolling at 5/7 of its initial speed", "[physics][engine]") {
  const double v0 = 0.5;
  Roller r(0.5, -1, v0, 0.0);
  r.s.cmd("run 8000");
  const Vec3 v = r.s.v(1), w = r.s.omega(1);
  INFO("v = " << v.transpose() << ", omega = " << w.transpose());
  CHECK(v[0] == Approx(5.0 / 7.0 * v0).epsilon(0.01));
  CHECK(w[1] * kRadius == Approx(v[0]).epsilon(0.01));  // rolling without slip (omega_y r = vx)
  CHECK(std::fabs(v[2]) < 1e-3);                        // still on the wall
}

// A bead rolling without slip (vx = r w_y) on a wall with cdt rolling
// friction feels the constant resisting torque M = mu_r Fn r with Fn = m g.
// With F the static friction force at the contact point (in +x),
//   m dv/dt = F,   I dw/dt = -F r - mu_r m g r,   dv/dt = r dw/dt,
// so (I/r^2 + m) dv/dt = -mu_r m g, i.e. with I = 2/5 m r^2
//   dv/dt = -(5/7) mu_r g.
// mu_r = 0.1 gives 0.7007 m/s^2. The deceleration is measured between 0.02 s
// (after the start-up oscillation of the tangential spring has died away) and
// 0.2 s; 2% tolerance.
TEST_CASE("a rolling sphere decelerates at 5/7 mu_r g with cdt rolling friction", "[physics][engine]") {
  const double v0 = 0.5, mu_r = 0.1, g = 9.81;
  Roller r(0.5, mu_r, v0, v0 / kRadius);
  r.s.cmd("run 2000");
  const double t1 = r.s.e.update->time(), v1 = r.s.v(1)[0];
  r.s.cmd("run 18000");
  const double t2 = r.s.e.update->time(), v2 = r.s.v(1)[0];
  const Vec3 w = r.s.omega(1);
  const double decel = (v1 - v2) / (t2 - t1);
  INFO("v(" << t1 << ") = " << v1 << ", v(" << t2 << ") = " << v2 << ", omega = " << w.transpose());
  CHECK(decel == Approx(5.0 / 7.0 * mu_r * g).epsilon(0.02));
  CHECK(w[1] * kRadius == Approx(v2).epsilon(0.01));  // still rolling
}

// cdt does not stop at zero spin. A bead spinning on a wall without sliding
// friction (mu = 0: only the rolling torque acts on its spin) is stopped by
// the torque mu_r (m g) r within a few steps; from then on the torque flips
// its sign every step: the half-step spin that the torque is computed from
// alternates between two values Delta = mu_r m g r dt / I apart, while the
// full-step spin stays constant (|w| < Delta / 2) and the bead does not turn
// on average. epsd's elastic spring and its dashpot instead bring the spin
// to rest and the torque to zero (doc/contact_models.md).
TEST_CASE("cdt rolling torque flips every step at rest, epsd comes to rest", "[physics][engine]") {
  const double mu_r = 0.1, g = 9.81, w0 = 1.0;  // w0 / (mu_r m g r / I) = 0.41 ms to stop
  const double I = 0.4 * bead_mass() * kRadius * kRadius;
  const double torque = mu_r * bead_mass() * g * kRadius;
  const double delta = torque * 1e-5 / I;  // 0.0245 rad/s
  for (const std::string model : {std::string("cdt"), std::string("epsd")}) {
    Roller r(0.0, mu_r, 0.0, w0, model,
             {"fix m6 all property/global coefficientRollingViscousDamping peratomtypepair 1 0.3"});
    r.s.cmd("run 3000");
    std::vector<double> ty, wy;
    for (int k = 0; k < 6; ++k) {
      r.s.cmd("run 1 pre no post no");  // step by step, without a setup's force computation in between
      ty.push_back(r.s.p().torque[r.s.index(1)][1]);
      wy.push_back(r.s.omega(1)[1]);
    }
    INFO(model << ": torque_y " << ty[0] << " " << ty[1] << " " << ty[2] << " " << ty[3] << ", omega_y "
               << wy[0] << " " << wy[1] << " " << wy[2] << " " << wy[3] << "; mu_r m g r = " << torque
               << ", Delta = " << delta);
    if (model == "cdt") {
      for (int k = 0; k < 6; ++k) {
        CHECK(std::fabs(ty[k]) == Approx(torque).epsilon(1e-3));  // the full torque, whatever the spin
        if (k > 0) CHECK(ty[k] * ty[k - 1] < 0);                  // of the other sign each step
        CHECK(std::fabs(wy[k]) < 0.5 * delta);
        CHECK(wy[k] == Approx(wy[0]).margin(1e-6 * delta));  // the full-step spin does not change
      }
    } else {
      for (int k = 0; k < 6; ++k) {
        CHECK(std::fabs(ty[k]) < 1e-3 * torque);  // no torque left: the bead rests
        CHECK(std::fabs(wy[k]) < 1e-3 * delta);
      }
    }
  }
}

// epsd and epsd3 in a script: the material properties each needs, and a
// rolling sphere decelerating at 5/7 mu_r g once the rolling spring is fully
// mobilised (its dashpot is off then). epsd3's prefactor is read as
// rollingStiffness (what LIGGGHTS 3.8 reads) or coeffRollingStiffness (the
// name in LIGGGHTS' manual), a scalar.
TEST_CASE("rolling_friction epsd and epsd3 need their properties and decelerate at 5/7 mu_r g",
          "[physics][engine]") {
  const double v0 = 0.5, mu_r = 0.1, g = 9.81;
  const std::string damping =
      "fix m6 all property/global coefficientRollingViscousDamping peratomtypepair 1 0.3";
  {
    Roller r(0.5, mu_r, v0, v0 / kRadius, "epsd");
    CHECK_THROWS_WITH(r.s.cmd("run 1"), Catch::Matchers::Contains("coefficientRollingViscousDamping"));
  }
  {
    Roller r(0.5, mu_r, v0, v0 / kRadius, "epsd3", {damping});
    CHECK_THROWS_WITH(r.s.cmd("run 1"), Catch::Matchers::Contains("rollingStiffness"));
  }
  {
    Roller r(0.5, mu_r, v0, v0 / kRadius, "epsd3",
             {damping, "fix m7 all property/global rollingStiffness peratomtypepair 1 1.5"});
    CHECK_THROWS_WITH(r.s.cmd("run 1"), Catch::Matchers::Contains("must be defined as 'scalar VALUE'"));
  }
  for (const std::string& stiffness :
       {std::string(""), std::string("rollingStiffness"), std::string("coeffRollingStiffness")}) {
    std::vector<std::string> extra = {damping};
    if (!stiffness.empty()) extra.push_back("fix m7 all property/global " + stiffness + " scalar 1.5");
    Roller r(0.5, mu_r, v0, v0 / kRadius, stiffness.empty() ? "epsd" : "epsd3", extra);
    r.s.cmd("run 2000");
    const double t1 = r.s.e.update->time(), v1 = r.s.v(1)[0];
    r.s.cmd("run 18000");
    const double t2 = r.s.e.update->time(), v2 = r.s.v(1)[0];
    const double decel = (v1 - v2) / (t2 - t1);
    INFO((stiffness.empty() ? "epsd" : "epsd3 with " + stiffness)
         << ": v(" << t1 << ") = " << v1 << ", v(" << t2 << ") = " << v2);
    CHECK(decel == Approx(5.0 / 7.0 * mu_r * g).epsilon(0.02));
    CHECK(r.s.omega(1)[1] * kRadius == Approx(v2).epsilon(0.01));  // still rolling
  }
}

// model hooke/hysteresis in a script: its three properties are required and
// checked (the physics: unittest/test_contact_normal.cpp and the LIGGGHTS
// agreement test on in.hysteresis_pairs).
TEST_CASE("model hooke/hysteresis needs its properties with valid values", "[physics][engine]") {
  auto script = [](const std::vector<std::string>& extra) {
    auto lines = header("m m m", "-0.01 0.01 -0.01 0.01 0 0.01", 1);
    append(lines, materials(1, 0.5, 0.5, -1.0));
    lines.push_back("fix m9 all property/global characteristicVelocity scalar 2.0");
    append(lines, extra);
    append(lines, {"pair_style gran model hooke/hysteresis tangential history", "pair_coeff * *",
                   "timestep 1e-6", "create_atoms 1 single 0 0 0.005 units box",
                   "set type 1 diameter 0.002 density 2500", "fix integr all nve/sphere"});
    return lines;
  };
  const std::string k2 = "fix h1 all property/global coefficientMaxElasticStiffness peratomtypepair 1 ";
  const std::string kc = "fix h2 all property/global coefficientAdhesionStiffness peratomtypepair 1 0.2";
  const std::string phi = "fix h3 all property/global coefficientPlasticityDepth peratomtypepair 1 0.05";
  {
    Sim s;
    s.lines(script({kc, phi}));
    CHECK_THROWS_WITH(s.cmd("run 1"), Catch::Matchers::Contains("coefficientMaxElasticStiffness"));
  }
  {
    Sim s;
    s.lines(script({k2 + "1.0", kc, phi}));
    CHECK_THROWS_WITH(s.cmd("run 1"),
                      Catch::Matchers::Contains("coefficientMaxElasticStiffness must be > 1"));
  }
  {
    Sim s;
    s.lines(script({k2 + "2.0", kc, phi}));
    s.cmd("run 10");
    CHECK(s.e.update->ntimestep == 10);
  }
}

// ---------------------------------------------------------------- free fall

// Under a constant force velocity Verlet is exact: x_{n+1} = x_n + dt v_n +
// dt^2/2 a and v_{n+1} = v_n + dt a reproduce x0 + v0 t - g t^2/2 and v0 - g t
// at t = n dt with no truncation error, so only rounding is left (1e-9
// relative). No contact: the bead flies alone in a shrink-wrapped box.
TEST_CASE("free fall under fix gravity is exact with nve/sphere", "[physics][engine]") {
  Sim s;
  auto script = header("m m m", "-0.1 0.1 -0.1 0.1 0 0.6", 1);
  append(script, materials(1, 0.5, 0.5));
  append(script, {
                     "pair_style gran model hertz tangential history",
                     "pair_coeff * *",
                     "timestep 1e-4",
                     "create_atoms 1 single 0.01 0.02 0.5 units box",
                     "set type 1 diameter 0.002 density 2500",
                     "velocity all set 0.3 -0.2 1.0",
                     "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
                     "fix integr all nve/sphere",
                     "run 2000",
                 });
  s.lines(script);
  const double t = s.e.update->time();
  REQUIRE(t == Approx(0.2).epsilon(1e-12));
  const Vec3 x0(0.01, 0.02, 0.5), v0(0.3, -0.2, 1.0), g(0, 0, -9.81);
  const Vec3 x_exact = x0 + v0 * t + 0.5 * g * t * t;
  const Vec3 v_exact = v0 + g * t;
  const Vec3 x = s.x(1), v = s.v(1);
  INFO("x = " << x.transpose() << " exact " << x_exact.transpose());
  for (int d = 0; d < 3; ++d) {
    CHECK(std::fabs(x[d] - x_exact[d]) <= 1e-9 * std::fabs(x_exact[d]));
    CHECK(std::fabs(v[d] - v_exact[d]) <= 1e-9 * v_exact.norm());
  }
}

// ---------------------------------------------------------------- newton

namespace {
/// 40 beads poured onto a wall in a box periodic in x and y (so that a single
/// rank has ghost images), final positions by id (index 0 unused).
struct PileSetup {
  std::string rolling;  // "" or " rolling_friction cdt"
  double e, vz, fill_top;
  int steps;
};

struct PileState {
  std::vector<Vec3> x, omega;  // by id (index 0 unused)
  long long contacts = 0;      // at the end, including contacts with periodic images
};

PileState pile(const std::string& newton, const PileSetup& setup) {
  const std::string& rolling = setup.rolling;
  Sim s;
  std::vector<std::string> script = {
      "units si",
      "atom_style granular",
      "boundary p p f",
      "newton " + newton,
      "region box block 0 0.008 0 0.008 0 0.03 units box",
      "create_box 1 box",
      "neighbor 0.0005 bin",
      "neigh_modify delay 0",
  };
  append(script, materials(1, setup.e, 0.5, 0.1));
  append(script, {
                     "pair_style gran model hertz tangential history" + rolling,
                     "pair_coeff * *",
                     "timestep 2e-5",
                     "region fill block 0 0.008 0 0.008 0.001 " + num(setup.fill_top) + " units box",
                     "create_atoms 1 random 40 4711 fill overlap 0.0021 maxtry 200",
                     "set type 1 diameter 0.002 density 2500",
                     "velocity all set 0.0 0.0 " + num(setup.vz),
                     "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
                     "fix zwall all wall/gran model hertz tangential history" + rolling +
                         " primitive type 1 zplane 0.0",
                     "fix integr all nve/sphere",
                     "run " + std::to_string(setup.steps),
                 });
  s.lines(script);
  const auto& p = s.p();
  REQUIRE(p.nlocal == 40);
  PileState state;
  state.x.assign(p.nlocal + 1, Vec3::Zero());
  state.omega.assign(p.nlocal + 1, Vec3::Zero());
  for (int i = 0; i < p.nlocal; ++i) {
    REQUIRE(p.id[i] >= 1);
    REQUIRE(p.id[i] <= p.nlocal);
    state.x[p.id[i]] = p.x[i];
    state.omega[p.id[i]] = p.omega[i];
  }
  for (int i = 0; i < p.nlocal; ++i)
    for (int j = i + 1; j < p.size(); ++j)
      if ((p.x[i] - p.x[j]).norm() < p.radius[i] + p.radius[j]) ++state.contacts;
  return state;
}

/// Compare two piles: largest distance between the same bead (minimum image
/// in x and y) to 1e-10 m, largest spin difference to 1e-4 rad/s (spins reach
/// some 100 rad/s, and grow rounding differences faster than positions do).
void compare_piles(const PileState& a, const PileState& b) {
  REQUIRE(a.x.size() == b.x.size());
  double dx = 0.0, dw = 0.0;
  for (std::size_t k = 1; k < a.x.size(); ++k) {
    Vec3 d = a.x[k] - b.x[k];
    for (int dim = 0; dim < 2; ++dim)
      d[dim] -= 0.008 * std::round(d[dim] / 0.008);
    dx = std::max(dx, d.norm());
    dw = std::max(dw, (a.omega[k] - b.omega[k]).norm());
  }
  INFO("largest position difference " << dx << " m, spin difference " << dw << " rad/s, contacts "
                                      << a.contacts << " / " << b.contacts);
  CHECK(dx < 1e-10);
  CHECK(dw < 1e-4);
}
}  // namespace

// With `newton on` each contact with a periodic image is computed once and
// its reaction sent back by reverse communication; with `newton off` both
// sides compute it. The forces agree to rounding (the two sides sum in a
// different order), so the piles must agree to 1e-10 m. A dense granular
// flow amplifies rounding differences by about 10x every 150-200 steps here
// (1e-21 m at the first contacts, 1e-12 m after 1500 steps, 1e-10 m after
// about 2000), so the comparison is made after 1500 steps, when the beads have
// landed and are in contact (including contacts across the periodic boundaries).
TEST_CASE("newton on and newton off give the same pile", "[physics][engine]") {
  const PileSetup setup{"", 0.3, -1.0, 0.02, 700};
  const PileState on = pile("on", setup), off = pile("off", setup);
  CHECK(on.contacts > 20);
  compare_piles(on, off);
}

// The same comparison with cdt rolling friction, in a pile where two beads
// without spin first touch across the periodic boundary at step 298. The cdt
// torque -mu_r kn delta R* w/|w| has full size for any nonzero relative rolling
// spin w; the tangential force gives two equal beads equal spins, which differ
// only by rounding between newton on and off. The kernel treats a relative spin
// at the rounding level of the spins as zero (kRollingSpinTolerance), so the
// two runs must agree as closely as without rolling friction.
TEST_CASE("newton on and newton off give the same pile with cdt rolling friction", "[physics][engine]") {
  const PileSetup setup{" rolling_friction cdt", 0.7, -0.5, 0.025, 400};
  const PileState on = pile("on", setup), off = pile("off", setup);
  compare_piles(on, off);
}
