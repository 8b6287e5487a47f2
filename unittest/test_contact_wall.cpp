// Physics tests of a sphere resting on a flat wall under gravity, integrated
// here with a small velocity-Verlet loop that calls the contact kernels
// directly: a sliding sphere ends rolling at 5/7 of its initial speed, and
// rolling friction (cdt, epsd2) decelerates a rolling sphere at (5/7) mu_r g.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "contact/contact_kernels.h"
#include "contact/contact_model.h"

using namespace granary::contact;

namespace {

constexpr double kG = 9.81;
constexpr double kY = 5e7, kNu = 0.3, kDensity = 2500.0, kRadius = 0.01;

// A solid sphere on the wall z = 0 (normal +z), gravity along -z.
struct RollingSphere {
  double r = kRadius;
  double m = kDensity * 4.0 / 3.0 * M_PI * kRadius * kRadius * kRadius;
  double inertia = 0.4 * m * kRadius * kRadius;
  Vec3 x, v, w, f, t;
  ModelSpec spec;
  PairMaterial mat;
  std::vector<double> hist;
  double dt = 2e-5;

  RollingSphere(const ModelSpec& s, const PairMaterial& pm) : spec(s), mat(pm) {
    hist.assign(history_size(spec), 0.0);
    // Start at the static Hertz overlap (for Hooke, the linear one) so that
    // the sphere does not bounce: kn delta = m g.
    double delta = std::pow(m * kG / (4.0 / 3.0 * mat.Y_eff * std::sqrt(r)), 2.0 / 3.0);
    if (spec.normal == NormalModel::Hooke) {
      ContactState c = state();
      c.overlap = 1e-6;
      ContactResult res;
      std::vector<double> scratch(hist.size(), 0.0);
      PairMaterial elastic = mat;
      elastic.beta = 0.0;
      evaluate(spec, c, elastic, scratch.data(), res);
      delta = m * kG / (res.fn / c.overlap);
    }
    x = Vec3(0, 0, r - delta);
    v = w = Vec3::Zero();
    f = Vec3::Zero();  // contact balances gravity at the start
    t = Vec3::Zero();
  }

  ContactState state() const {
    ContactState c;
    c.n = Vec3::UnitZ();
    c.overlap = r - x.z();
    c.r_i = r;
    c.r_j = 0.0;
    c.r_eff = r;
    c.m_eff = m;
    c.i_roll = rolling_inertia(m, r, 0.0, 0.0);
    c.v_rel = v;
    c.omega_i = w;
    c.dt = dt;
    return c;
  }

  // One LAMMPS-style velocity-Verlet step.
  void step() {
    v += 0.5 * dt / m * f;
    w += 0.5 * dt / inertia * t;
    x += dt * v;
    ContactResult res;
    evaluate(spec, state(), mat, hist.data(), res);
    f = res.force + Vec3(0, 0, -m * kG);
    t = res.torque_i;
    v += 0.5 * dt / m * f;
    w += 0.5 * dt / inertia * t;
  }

  // Speed of the contact point relative to the wall (0 when rolling).
  double slip() const { return (v - (r - 0.5 * (r - x.z())) * w.cross(Vec3::UnitZ())).norm(); }
};

ModelSpec spec_of(NormalModel n, TangentialModel t, RollingModel r) {
  ModelSpec s;
  s.normal = n;
  s.tangential = t;
  s.rolling = r;
  return s;
}

// Least-squares slope of v_x(t) sampled over [t0, t1].
double deceleration(RollingSphere& s, double t0, double t1) {
  double time = 0.0, st = 0, sv = 0, stt = 0, stv = 0;
  int n = 0;
  while (time < t1) {
    s.step();
    time += s.dt;
    if (time >= t0) {
      st += time;
      sv += s.v.x();
      stt += time * time;
      stv += time * s.v.x();
      ++n;
    }
  }
  return (n * stv - st * sv) / (n * stt - st * st);
}

}  // namespace

TEST_CASE("A sliding sphere ends rolling at 5/7 of its initial speed", "[contact][wall]") {
  // Sliding friction at the contact point spins the sphere up until it rolls.
  // Angular momentum about the contact point is conserved meanwhile:
  //   m v0 r = m v r + (2/5) m r^2 (v / r)  =>  v = 5/7 v0.
  // (With the lever arm r - delta/2 the correction is O(delta/r) ~ 1e-3.)
  // Tolerance 1% on the final speed, averaged over the last 20 ms.
  for (NormalModel nm : {NormalModel::Hertz, NormalModel::Hooke}) {
    const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 0.5, 0.3, 0.0, 1.0);
    RollingSphere s(spec_of(nm, TangentialModel::History, RollingModel::None), mat);
    const double v0 = 1.0;
    s.v = Vec3(v0, 0, 0);
    // Sliding phase lasts 2 v0 / (7 mu g) = 0.097 s; run 0.3 s.
    double v_avg = 0.0;
    int n = 0;
    for (double time = 0.0; time < 0.3; time += s.dt) {
      s.step();
      if (time > 0.28) {
        v_avg += s.v.x();
        ++n;
      }
    }
    v_avg /= n;
    INFO("hooke " << (nm == NormalModel::Hooke) << " final speed " << v_avg);
    CHECK(v_avg == Approx(5.0 / 7.0 * v0).epsilon(0.01));
    CHECK(s.slip() < 0.01 * v0);
    CHECK(std::abs(s.v.y()) + std::abs(s.v.z()) < 1e-3 * v0);
  }
}

TEST_CASE("Rolling friction decelerates a rolling sphere at (5/7) mu_r g", "[contact][wall]") {
  // Rolling without slip on a flat wall, with friction force F_t at the
  // contact point and rolling torque of magnitude M = mu_r R* Fn (R* = r for a
  // wall, Fn = m g; cdt uses the elastic force kn delta = m g at rest in the
  // normal direction, epsd2, epsd and epsd3 when fully mobilised use |Fn| = m g, and the
  // dashpot of epsd and epsd3 is off then):
  //   m a = F_t,   I alpha = -r F_t - M,   a = r alpha
  //   =>  (m + I / r^2) a = -M / r  =>  a = -mu_r m g / (m (1 + 2/5)) = -(5/7) mu_r g.
  // Tolerance 2% on the least-squares deceleration over 0.05 .. 0.35 s.
  const double mu_r = 0.1;
  for (RollingModel rm : {RollingModel::Cdt, RollingModel::Epsd2, RollingModel::Epsd, RollingModel::Epsd3}) {
    for (NormalModel nm : {NormalModel::Hertz, NormalModel::Hooke}) {
      PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 0.5, 0.5, mu_r, 1.0);
      mat.rolling_stiffness = rm == RollingModel::Epsd ? 2.25 : 1.5;  // epsd, epsd3
      mat.rolling_damping = 0.3;                                      // epsd, epsd3
      RollingSphere s(spec_of(nm, TangentialModel::History, rm), mat);
      const double v0 = 0.5;
      s.v = Vec3(v0, 0, 0);
      s.w = Vec3(0, v0 / (s.r - 0.5 * (s.r - s.x.z())), 0);  // no slip
      const double a = deceleration(s, 0.05, 0.35);
      INFO("rolling " << model_words(spec_of(nm, TangentialModel::History, rm)) << " hooke "
                      << (nm == NormalModel::Hooke) << " deceleration " << a);
      CHECK(a == Approx(-5.0 / 7.0 * mu_r * kG).epsilon(0.02));
      CHECK(s.slip() < 1e-3 * v0);
      CHECK(s.v.x() > 0.0);
    }
  }
}

TEST_CASE("Without rolling friction a rolling sphere keeps its speed", "[contact][wall]") {
  // Control for the test above: same set-up, no rolling model; the speed stays
  // constant to 1e-4 over 0.3 s.
  const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 0.5, 0.5, 0.1, 1.0);
  RollingSphere s(spec_of(NormalModel::Hertz, TangentialModel::History, RollingModel::None), mat);
  s.v = Vec3(0.5, 0, 0);
  s.w = Vec3(0, 0.5 / (s.r - 0.5 * (s.r - s.x.z())), 0);
  for (double time = 0.0; time < 0.3; time += s.dt)
    s.step();
  CHECK(s.v.x() == Approx(0.5).epsilon(1e-4));
}
