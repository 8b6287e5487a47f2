// Tests of the tangential (history, no_history) and rolling (cdt, epsd2, epsd, epsd3)
// sub-models called directly on prescribed contact states: Coulomb limit,
// stick stiffness and damping, rolling torque laws, and the consistency of
// history_swap_signs when a contact is evaluated as (j,i) instead of (i,j).
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "contact/contact_kernels.h"
#include "contact/contact_model.h"

using namespace granary::contact;

namespace {

constexpr double kY = 5e7, kNu = 0.3;

ModelSpec spec_of(NormalModel n, TangentialModel t, RollingModel r = RollingModel::None) {
  ModelSpec s;
  s.normal = n;
  s.tangential = t;
  s.rolling = r;
  return s;
}

// A sphere of radius 2 mm pressed on a wall (normal +z) with a fixed overlap.
ContactState wall_contact(double overlap = 1e-5) {
  ContactState c;
  c.n = Vec3::UnitZ();
  c.overlap = overlap;
  c.r_i = 0.002;
  c.r_j = 0.0;
  c.r_eff = c.r_i;
  c.m_eff = 8.4e-5;
  c.dt = 1e-7;
  return c;
}

double hertz_kt(const ContactState& c, const PairMaterial& m) {
  return 8.0 * m.G_eff * std::sqrt(c.r_eff * c.overlap);
}
double hertz_kn(const ContactState& c, const PairMaterial& m) {
  return 4.0 / 3.0 * m.Y_eff * std::sqrt(c.r_eff * c.overlap);
}

}  // namespace

TEST_CASE("Tangential history: elastic stick, then Coulomb sliding", "[contact][tangential]") {
  // e = 1 (no damping): while sticking Ft = -kt * (accumulated displacement)
  // exactly (1e-12); |Ft| <= mu |Fn| at every step; once the spring reaches
  // the Coulomb limit, |Ft| == mu |Fn| (1e-12) and Ft opposes the sliding.
  const double mu = 0.4;
  const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 1.0, mu, 0.0, 0.0);
  const ModelSpec spec = spec_of(NormalModel::Hertz, TangentialModel::History);
  ContactState c = wall_contact();
  c.v_rel = Vec3(0.5, 0, -0.01);  // sliding along x; the normal part does not enter Ft
  const double kt = hertz_kt(c, mat);
  double hist[3] = {0, 0, 0};
  bool slid = false;
  for (int step = 1; step <= 400; ++step) {
    ContactResult res;
    evaluate(spec, c, mat, hist, res);
    const double limit = mu * std::abs(res.fn);
    REQUIRE(res.ft.norm() <= limit * (1 + 1e-12));
    CHECK(res.ft.dot(c.n) == Approx(0.0).margin(1e-15));
    const double spring = kt * step * c.dt * 0.5;
    if (spring < limit) {
      CHECK(res.ft.x() == Approx(-spring).epsilon(1e-12));
      CHECK(hist[0] == Approx(step * c.dt * 0.5).epsilon(1e-12));
    } else {
      slid = true;
      CHECK(res.ft.norm() == Approx(limit).epsilon(1e-12));
      CHECK(res.ft.x() < 0.0);
      CHECK(kt * Vec3(hist[0], hist[1], hist[2]).norm() == Approx(limit).epsilon(1e-12));
    }
  }
  CHECK(slid);
}

TEST_CASE("Tangential history: dashpot only while sticking", "[contact][tangential]") {
  // e = 0.5: in a sticking step Ft = -kt s - gamma_t vt with
  // gamma_t = -2 sqrt(5/6) beta sqrt(St m*); in slipping steps the damping
  // is dropped and |Ft| == mu |Fn| exactly; the spring part (kt |s|) never
  // exceeds mu |Fn|. With tangential_damping off, Ft = -kt s.
  const double mu = 0.3;
  const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 0.5, mu, 0.0, 0.0);
  ContactState c = wall_contact();
  const Vec3 vt(0.02, -0.01, 0);
  c.v_rel = vt;
  const double kt = hertz_kt(c, mat);
  const double gamma_t = -2.0 * std::sqrt(5.0 / 6.0) * mat.beta * std::sqrt(kt * c.m_eff);
  for (bool damping : {true, false}) {
    ModelSpec spec = spec_of(NormalModel::Hertz, TangentialModel::History);
    spec.tangential_damping = damping;
    double hist[3] = {0, 0, 0};
    ContactResult res;
    evaluate(spec, c, mat, hist, res);  // first step: sticks
    const Vec3 expected = -kt * c.dt * vt - (damping ? gamma_t : 0.0) * vt;
    CHECK((res.ft - expected).norm() <= 1e-12 * expected.norm());
    int slipping = 0;
    for (int step = 0; step < 4000; ++step) {
      evaluate(spec, c, mat, hist, res);
      const double limit = mu * std::abs(res.fn);
      CHECK(kt * Vec3(hist[0], hist[1], hist[2]).norm() <= limit * (1 + 1e-12));
      if (kt * Vec3(hist[0], hist[1], hist[2]).norm() >= limit * (1 - 1e-12)) {
        ++slipping;
        CHECK(res.ft.norm() == Approx(limit).epsilon(1e-12));
      }
    }
    CHECK(slipping > 2000);
  }
}

TEST_CASE("Tangential history follows a rotating contact normal", "[contact][tangential]") {
  // The stored displacement is projected on the current tangent plane, so it
  // stays perpendicular to n when the contact rotates.
  const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 0.7, 0.5, 0.0, 0.0);
  const ModelSpec spec = spec_of(NormalModel::Hertz, TangentialModel::History);
  ContactState c = wall_contact();
  c.v_rel = Vec3(0.01, 0.02, 0);
  double hist[3] = {0, 0, 0};
  for (int step = 0; step < 200; ++step) {
    const double a = 0.002 * step;
    c.n = Vec3(std::sin(a), 0, std::cos(a));
    ContactResult res;
    evaluate(spec, c, mat, hist, res);
    CHECK(Vec3(hist[0], hist[1], hist[2]).dot(c.n) == Approx(0.0).margin(1e-18));
    CHECK(res.ft.dot(c.n) == Approx(0.0).margin(1e-12 * res.ft.norm()));
  }
}

TEST_CASE("Spin enters the contact-point velocity with lever arm r - delta/2", "[contact][tangential]") {
  // A sphere spinning about y on a wall (no centre velocity): its contact
  // point moves with -cr w (y x z) = -cr w x, cr = r - delta/2. After one step
  // Ft = kt cr w dt x and the torque -cr n x Ft = -kt cr^2 w dt y opposes the spin.
  const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 1.0, 0.5, 0.0, 0.0);
  const ModelSpec spec = spec_of(NormalModel::Hertz, TangentialModel::History);
  ContactState c = wall_contact();
  const double w = 30.0, cr = c.r_i - 0.5 * c.overlap, kt = hertz_kt(c, mat);
  c.omega_i = Vec3(0, w, 0);
  double hist[3] = {0, 0, 0};
  ContactResult res;
  evaluate(spec, c, mat, hist, res);
  CHECK(res.ft.x() == Approx(kt * cr * w * c.dt).epsilon(1e-12));
  CHECK(res.torque_i.y() == Approx(-kt * cr * cr * w * c.dt).epsilon(1e-12));
  CHECK(std::abs(res.torque_i.x()) + std::abs(res.torque_i.z()) < 1e-20);
}

TEST_CASE("Hooke tangential stiffness is kn, or 2/7 kn with ktToKnUser", "[contact][tangential]") {
  const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 1.0, 10.0, 0.0, 1.0);
  ContactState c = wall_contact();
  c.v_rel = Vec3(0.1, 0, 0);
  for (bool user : {false, true}) {
    ModelSpec spec = spec_of(NormalModel::Hooke, TangentialModel::History);
    spec.kt_to_kn_user = user;
    double hist[3] = {0, 0, 0};
    ContactResult res;
    evaluate(spec, c, mat, hist, res);
    const double kn = res.fn / c.overlap;  // e = 1: purely elastic
    CHECK(-res.ft.x() / (c.dt * 0.1) == Approx(user ? 2.0 / 7.0 * kn : kn).epsilon(1e-12));
  }
}

TEST_CASE("Tangential no_history: viscous friction capped by Coulomb", "[contact][tangential]") {
  // Ft = -min(gamma_t |vt|, mu |Fn|) vt/|vt|: linear in vt at low speed,
  // exactly mu |Fn| at high speed, never above.
  const double mu = 0.35;
  const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 0.4, mu, 0.0, 0.0);
  const ModelSpec spec = spec_of(NormalModel::Hertz, TangentialModel::NoHistory);
  REQUIRE(history_size(spec) == 0);
  ContactState c = wall_contact();
  const double gamma_t = -2.0 * std::sqrt(5.0 / 6.0) * mat.beta * std::sqrt(hertz_kt(c, mat) * c.m_eff);
  const Vec3 dir = Vec3(3, -4, 0) / 5.0;
  bool saw_viscous = false, saw_coulomb = false;
  for (double speed = 1e-5; speed < 10.0; speed *= 1.5) {
    c.v_rel = speed * dir + Vec3(0, 0, -0.02);
    ContactResult res;
    evaluate(spec, c, mat, nullptr, res);
    const double limit = mu * std::abs(res.fn);
    CHECK(res.ft.norm() <= limit * (1 + 1e-12));
    CHECK((res.ft.normalized() + dir).norm() < 1e-12);
    if (gamma_t * speed < limit) {
      saw_viscous = true;
      CHECK(res.ft.norm() == Approx(gamma_t * speed).epsilon(1e-12));
    } else {
      saw_coulomb = true;
      CHECK(res.ft.norm() == Approx(limit).epsilon(1e-12));
    }
  }
  CHECK(saw_viscous);
  CHECK(saw_coulomb);
  // e = 1: no damping, hence no tangential force at all.
  const PairMaterial elastic = mix_materials(kY, kNu, kY, kNu, 1.0, mu, 0.0, 0.0);
  ContactResult res;
  evaluate(spec, c, elastic, nullptr, res);
  CHECK(res.ft.norm() == 0.0);
}

TEST_CASE("Rolling cdt: constant torque mu_r (kn delta) R* against the rolling spin", "[contact][rolling]") {
  // Uses the elastic normal force kn delta (not the damped one). The torque
  // opposes the tangential part w_t of w_r = w_i - w_j and is divided by |w_r|
  // (twist included), as LIGGGHTS 3.8 does (in.three_spheres agrees with it
  // to every printed digit only this way).
  const double mu_r = 0.15;
  const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 0.5, 0.5, mu_r, 0.0);
  const ModelSpec spec = spec_of(NormalModel::Hertz, TangentialModel::None, RollingModel::Cdt);
  ContactState c;
  c.n = Vec3::UnitX();
  c.overlap = 2e-5;
  c.r_i = 0.002;
  c.r_j = 0.003;
  c.r_eff = 0.0012;
  c.m_eff = 5e-5;
  c.v_rel = Vec3(-0.2, 0, 0);  // damping makes fn differ from kn delta
  c.dt = 1e-7;
  // pure rolling: full torque mu_r kn delta R*, against w_t
  c.omega_i = Vec3(0, 3, -4);
  c.omega_j = Vec3::Zero();
  ContactResult res;
  evaluate(spec, c, mat, nullptr, res);
  const double expected = mu_r * hertz_kn(c, mat) * c.overlap * c.r_eff;
  REQUIRE(res.fn > hertz_kn(c, mat) * c.overlap * 1.01);
  CHECK(res.torque_i.norm() == Approx(expected).epsilon(1e-12));
  CHECK((res.torque_i.normalized() + Vec3(0, 3, -4) / 5.0).norm() < 1e-12);
  CHECK((res.torque_i + res.torque_j).norm() == 0.0);
  // The torque does not depend on the spin magnitude.
  c.omega_i = Vec3(0, 3e-3, -4e-3);
  evaluate(spec, c, mat, nullptr, res);
  CHECK(res.torque_i.norm() == Approx(expected).epsilon(1e-12));
  // Rolling with twist: scaled by |w_t| / |w_r|.
  c.omega_i = Vec3(50, 3, -4);
  c.omega_j = Vec3(-20, 0, 0);
  evaluate(spec, c, mat, nullptr, res);
  CHECK(res.torque_i.norm() == Approx(expected * 5.0 / Vec3(70, 3, -4).norm()).epsilon(1e-12));
  CHECK((res.torque_i.normalized() + Vec3(0, 3, -4) / 5.0).norm() < 1e-12);
  // No rolling, no torque.
  c.omega_i = Vec3(7, 0, 0);
  c.omega_j = Vec3::Zero();
  evaluate(spec, c, mat, nullptr, res);
  CHECK(res.torque_i.norm() == 0.0);
}

TEST_CASE("Rolling epsd2: spring k_r = kt R*^2 up to mu_r R* |Fn|", "[contact][rolling]") {
  // Constant relative rolling spin: M grows by -k_r w dt per step (1e-12),
  // saturates at mu_r R* |Fn| (1e-12), then unloads elastically with k_r
  // when the spin is reversed.
  const double mu_r = 0.1;
  const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 0.6, 0.5, mu_r, 0.0);
  const ModelSpec spec = spec_of(NormalModel::Hertz, TangentialModel::History, RollingModel::Epsd2);
  const HistoryLayout layout = history_layout(spec);
  REQUIRE(layout.rolling == 3);
  ContactState c = wall_contact();
  c.dt = 1e-6;
  const Vec3 w(0, 4, 0);
  c.omega_i = w + Vec3(0, 0, 11);   // twisting part ignored
  c.v_rel = Vec3(0.002 * 4, 0, 0);  // centre moves with the rolling (no slip)
  const double kt = hertz_kt(c, mat), kr = kt * c.r_eff * c.r_eff;
  std::vector<double> hist(layout.size, 0.0);
  ContactResult res;
  double m_max = 0.0;
  int steps_elastic = 0;
  for (int step = 1; step <= 2000; ++step) {
    evaluate(spec, c, mat, hist.data(), res);
    m_max = mu_r * c.r_eff * std::abs(res.fn);
    const Vec3 m(hist[3], hist[4], hist[5]);
    REQUIRE(m.norm() <= m_max * (1 + 1e-12));
    if (kr * step * c.dt * 4 < m_max) {
      ++steps_elastic;
      CHECK(m.y() == Approx(-kr * step * c.dt * 4).epsilon(1e-12));
    } else {
      CHECK(m.norm() == Approx(m_max).epsilon(1e-12));
      CHECK(m.y() < 0.0);
    }
  }
  REQUIRE(steps_elastic > 10);
  REQUIRE(steps_elastic < 1900);
  // Reverse the spin: elastic unloading from -m_max.
  c.omega_i = -w;
  c.v_rel = -c.v_rel;
  for (int step = 1; step <= 5; ++step) {
    evaluate(spec, c, mat, hist.data(), res);
    CHECK(hist[4] == Approx(-m_max + kr * step * c.dt * 4).epsilon(1e-9));
  }
}

TEST_CASE("Rolling epsd and epsd3: spring k_r = c kn mu_r^2 R*^2 and a dashpot C_r below the cap",
          "[contact][rolling]") {
  // Constant rolling spin w on a wall: the spring torque grows by -k_r w dt
  // per step up to mu_r R* |Fn|, k_r = 2.25 kn mu_r^2 R*^2 (epsd) or
  // rollingStiffness kn mu_r^2 R*^2 (epsd3); the torque on i is the spring plus
  // the dashpot -C_r w, C_r = eta_r 2 sqrt(I_r k_r) with I_r = 7/5 m r^2 for a
  // sphere on a wall, as long as the spring is below the cap, and the spring
  // alone once it is capped. The dashpot is found as the difference of the
  // torques with eta_r = 0.4 and eta_r = 0 (the tangential torque cancels).
  const double mu_r = 0.3;
  for (RollingModel rm : {RollingModel::Epsd, RollingModel::Epsd3}) {
    INFO((rm == RollingModel::Epsd ? "epsd" : "epsd3"));
    PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 0.6, 0.5, mu_r, 0.0);
    const double prefactor = rm == RollingModel::Epsd ? 2.25 : 1.5;
    mat.rolling_stiffness = prefactor;
    PairMaterial undamped = mat;
    mat.rolling_damping = 0.4;
    const ModelSpec spec = spec_of(NormalModel::Hertz, TangentialModel::History, rm);
    const HistoryLayout layout = history_layout(spec);
    REQUIRE(layout.rolling == 3);
    REQUIRE(layout.size == 6);
    ContactState c = wall_contact();
    c.dt = 1e-6;
    c.i_roll = rolling_inertia(c.m_eff, c.r_i, 0.0, 0.0);
    CHECK(c.i_roll == Approx(1.4 * c.m_eff * c.r_i * c.r_i).epsilon(1e-15));
    const Vec3 w(0, 4, 0);
    c.omega_i = w + Vec3(0, 0, 11);   // twisting part ignored
    c.v_rel = Vec3(0.002 * 4, 0, 0);  // centre moves with the rolling (no slip)
    const double kn = hertz_kn(c, mat);
    const double kr = prefactor * kn * mu_r * mu_r * c.r_eff * c.r_eff;
    const double cr = 0.4 * 2.0 * std::sqrt(c.i_roll * kr);
    std::vector<double> h1(layout.size, 0.0), h0(layout.size, 0.0);
    ContactResult res1, res0;
    int elastic = 0, capped = 0;
    for (int step = 1; step <= 3000; ++step) {
      evaluate(spec, c, mat, h1.data(), res1);
      evaluate(spec, c, undamped, h0.data(), res0);
      const double m_max = mu_r * c.r_eff * std::abs(res1.fn);
      const Vec3 m(h1[3], h1[4], h1[5]);
      REQUIRE(m.norm() <= m_max * (1 + 1e-12));
      CHECK(h0[4] == h1[4]);  // the dashpot does not enter the spring
      const double damping = res1.torque_i.y() - res0.torque_i.y();
      if (kr * step * c.dt * 4 < m_max) {
        ++elastic;
        CHECK(m.y() == Approx(-kr * step * c.dt * 4).epsilon(1e-12));
        CHECK(damping == Approx(-cr * 4).epsilon(1e-9));
      } else {
        ++capped;
        CHECK(m.norm() == Approx(m_max).epsilon(1e-12));
        CHECK(damping == 0.0);
      }
    }
    CHECK(elastic > 10);
    CHECK(capped > 10);
  }
  // I_r of two spheres: 1 / (1/(7/5 m_i r_i^2) + 1/(7/5 m_j r_j^2))
  CHECK(rolling_inertia(2.0, 0.5, 1.0, 1.0) == Approx(1.0 / (1.0 / 0.7 + 1.0 / 1.4)).epsilon(1e-15));
}

TEST_CASE("Swapping i and j with history_swap_signs gives the opposite contact", "[contact][history]") {
  // Every model combination: run a few steps as (i,j), copy the history with
  // the swap signs, and evaluate the mirrored state (n, v_rel negated, radii
  // and spins exchanged). Forces must be opposite, torques exchanged and the
  // updated histories mirror images (1e-12 relative).
  PairMaterial mat = mix_materials(kY, kNu, 2 * kY, 0.2, 0.6, 0.3, 0.1, 0.9);
  mat.rolling_stiffness = 1.5;      // epsd, epsd3
  mat.max_elastic_stiffness = 2.0;  // hooke/hysteresis
  mat.adhesion_stiffness = 0.2;
  mat.plasticity_depth = 0.05;
  for (NormalModel nm : {NormalModel::Hertz, NormalModel::Hooke, NormalModel::HookeHysteresis}) {
    for (TangentialModel tm : {TangentialModel::None, TangentialModel::NoHistory, TangentialModel::History,
                               TangentialModel::MindlinDeresiewicz}) {
      for (RollingModel rm : {RollingModel::None, RollingModel::Cdt, RollingModel::Epsd2, RollingModel::Epsd,
                              RollingModel::Epsd3}) {
        for (bool limit : {false, true}) {
          ModelSpec spec = spec_of(nm, tm, rm);
          spec.limit_force = limit;
          const int nh = history_size(spec);
          std::vector<double> h_ij(nh, 0.0), h_ji(nh), signs(nh);
          history_swap_signs(spec, signs.data());
          ContactState ij;
          ij.n = Vec3(2, -1, 2) / 3.0;
          ij.overlap = 1.5e-5;
          ij.r_i = 0.002;
          ij.r_j = 0.003;
          ij.r_eff = 0.0012;
          ij.m_eff = 5e-5;
          ij.v_rel = Vec3(0.3, 0.2, -0.4);
          ij.omega_i = Vec3(20, -10, 5);
          ij.omega_j = Vec3(-8, 12, 30);
          ij.dt = 2e-6;
          ContactResult r_ij, r_ji;
          for (int k = 0; k < 3; ++k)
            evaluate(spec, ij, mat, h_ij.data(), r_ij);
          for (int h = 0; h < nh; ++h)
            h_ji[h] = signs[h] * h_ij[h];
          ContactState ji = ij;
          ji.n = -ij.n;
          ji.v_rel = -ij.v_rel;
          std::swap(ji.r_i, ji.r_j);
          std::swap(ji.omega_i, ji.omega_j);
          evaluate(spec, ij, mat, h_ij.data(), r_ij);
          evaluate(spec, ji, mat, h_ji.data(), r_ji);
          const double f = r_ij.force.norm(), t = r_ij.torque_i.norm() + r_ij.torque_j.norm();
          INFO("spec: " << model_words(spec));
          CHECK((r_ij.force + r_ji.force).norm() <= 1e-12 * f);
          CHECK((r_ij.torque_i - r_ji.torque_j).norm() <= 1e-12 * t);
          CHECK((r_ij.torque_j - r_ji.torque_i).norm() <= 1e-12 * t);
          CHECK(r_ij.fn == Approx(r_ji.fn).epsilon(1e-12));
          for (int h = 0; h < nh; ++h)
            CHECK(h_ji[h] == Approx(signs[h] * h_ij[h]).epsilon(1e-12).margin(1e-30));
        }
      }
    }
  }
}
