// Tests of the partial-slip tangential model "tangential mindlin_deresiewicz"
// against Mindlin & Deresiewicz's closed forms at constant normal force:
// the virgin loading curve, the unloading branch from full slip, the
// hysteresis loop of a cycle below the Coulomb limit (its closure and
// Mindlin & Deresiewicz's energy loss per cycle), and the limit of a
// large friction coefficient, where the model is tangential history.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "contact/contact_model.h"

using namespace granary::contact;

namespace {

constexpr double kY = 5e7, kNu = 0.3;

ModelSpec mindlin() {
  ModelSpec s;
  s.normal = NormalModel::Hertz;
  s.tangential = TangentialModel::MindlinDeresiewicz;
  return s;
}

// A sphere of radius 2 mm pressed on a wall (normal +z) with a fixed overlap:
// constant normal force and contact radius.
ContactState wall_contact() {
  ContactState c;
  c.n = Vec3::UnitZ();
  c.overlap = 1e-5;
  c.r_i = 0.002;
  c.r_j = 0.0;
  c.r_eff = c.r_i;
  c.m_eff = 8.4e-5;
  return c;
}

// Mindlin's virgin curve: T(d) = mu N (1 - (1 - d/d_s)^(3/2)), d_s = 3 mu N / (2 kt),
// for d in [0, d_s]; mu N beyond.
double virgin(double d, double muN, double kt) {
  const double ds = 1.5 * muN / kt;
  if (d >= ds) return muN;
  return muN * (1.0 - std::pow(1.0 - d / ds, 1.5));
}

struct Drive {
  ModelSpec spec = mindlin();
  ContactState c = wall_contact();
  PairMaterial mat;
  std::vector<double> hist;
  double d = 0.0;  ///< tangential displacement of i along x
  double force = 0.0, fn = 0.0;
  double kt = 0.0;   ///< the no-slip stiffness 8 G* a
  double muN = 0.0;  ///< the Coulomb limit mu N
  double ds = 0.0;   ///< Mindlin's displacement at full slip, 3 mu N / (2 kt)
  explicit Drive(double mu) : mat(mix_materials(kY, kNu, kY, kNu, 1.0, mu, 0.0, 0.0)) {
    hist.assign(history_size(spec), 0.0);
    kt = 8.0 * mat.G_eff * std::sqrt(c.r_eff * c.overlap);
    move(0.0);  // first touch: the normal force, no tangential one
    muN = mu * fn;
    ds = 1.5 * muN / kt;
  }
  // one step moving i by `step` along x; the tangential force along x afterwards
  double move(double step) {
    c.dt = 1e-7;
    c.v_rel = Vec3(step / c.dt, 0.0, 0.0);
    ContactResult r;
    evaluate(spec, c, mat, hist.data(), r);
    d += step;
    force = r.ft.x();
    fn = r.fn;
    return force;
  }
};

}  // namespace

TEST_CASE("mindlin_deresiewicz: first loading follows Mindlin's curve up to full slip",
          "[contact][tangential][mindlin]") {
  // e = 1 (no dashpot); 20,000 equal steps up to 1.2 d_s. The force opposes
  // the displacement and follows -mu N (1 - (1 - d/d_s)^(3/2)) within 0.2 % of
  // mu N (explicit steps: the slope is evaluated at the start of each step);
  // beyond d_s it stays at the Coulomb limit (1e-12).
  Drive D(0.3);
  const double kt = D.kt, muN = D.muN, ds = D.ds;
  const int n = 20000;
  double worst = 0.0;
  for (int k = 0; k < n; ++k) {
    const double f = D.move(1.2 * ds / n);
    REQUIRE(f <= 0.0);
    REQUIRE(-f <= muN * (1 + 1e-12));
    worst = std::max(worst, std::abs(-f - virgin(D.d, muN, kt)) / muN);
    if (D.d > ds * 1.001) CHECK(-f == Approx(muN).epsilon(1e-12));
  }
  INFO("largest deviation from Mindlin's curve " << worst << " mu N");
  CHECK(worst < 2e-3);
  // the initial stiffness is the no-slip one: after one small step the force is -kt d (0.1 %)
  Drive E(0.3);
  CHECK(-E.move(1e-4 * ds) == Approx(kt * 1e-4 * ds).epsilon(1e-3));
}

TEST_CASE("mindlin_deresiewicz: unloading from full slip follows twice the virgin curve",
          "[contact][tangential][mindlin]") {
  // After sliding at the limit, reversing the displacement by e traces
  // T = mu N - 2 mu N (1 - (1 - e/(2 d_s))^(3/2)) (Masing), reaching the
  // opposite limit at e = 2 d_s: within 0.2 % of mu N.
  Drive D(0.3);
  const double kt = D.kt, muN = D.muN, ds = D.ds;
  const int n = 20000;
  for (int k = 0; k < n / 2; ++k)
    D.move(1.5 * ds / (n / 2));
  REQUIRE(-D.force == Approx(muN).epsilon(1e-12));
  const double d0 = D.d;
  double worst = 0.0;
  for (int k = 0; k < n; ++k) {
    const double f = -D.move(-2.4 * ds / n);  // along +x after the reversal: f = T
    const double e = d0 - D.d;
    const double expected = muN - 2.0 * virgin(0.5 * e, muN, kt);
    worst = std::max(worst, std::abs(f - expected) / muN);
  }
  INFO("largest deviation from the unloading branch " << worst << " mu N");
  CHECK(worst < 2e-3);
  CHECK(-D.force == Approx(-muN).epsilon(1e-12));  // slipping the other way
}

TEST_CASE("mindlin_deresiewicz: a load cycle below the limit closes and loses Mindlin's energy",
          "[contact][tangential][mindlin]") {
  // Displacement cycles 0 -> a -> -a -> a at constant normal force, amplitude
  // T_a = 0.1 and 0.2 mu N. The loop closes (the force at the end equals the
  // force at the first turning point, 0.1 % of T_a), and the work done on the
  // contact over the closed loop is Mindlin & Deresiewicz's energy loss per
  // cycle, W = (9 mu^2 N^2 / (10 a G*)) g(T_a / (mu N)) with
  // g(t) = 1 - (1 - t)^(5/3) - (5 t / 6)(1 + (1 - t)^(2/3)) and 8 G* a = kt
  // (1 %); so it grows nearly as T_a^3 (ratio 8.62 between the two, 0.5 %).
  auto cycle = [](double t, double& loss, double& mindlin_loss) {
    Drive D(0.3);
    const double kt = D.kt, muN = D.muN, ds = D.ds;
    const double a = ds * (1.0 - std::pow(1.0 - t, 2.0 / 3.0));  // virgin(a) = t mu N
    const int n = 20000;
    for (int k = 0; k < n; ++k)
      D.move(a / n);
    const double top = -D.force;
    CHECK(top == Approx(t * muN).epsilon(2e-3));
    double work = 0.0;  // work of the external load -F on the contact
    auto leg = [&](double step) {
      for (int k = 0; k < 2 * n; ++k) {
        const double before = -D.force;
        D.move(step);
        work += 0.5 * (before - D.force) * step;
      }
    };
    leg(-a / n);
    leg(a / n);
    CHECK(-D.force == Approx(top).epsilon(1e-3));
    loss = work;
    const double g =
        1.0 - std::pow(1.0 - t, 5.0 / 3.0) - (5.0 * t / 6.0) * (1.0 + std::pow(1.0 - t, 2.0 / 3.0));
    mindlin_loss = 9.0 * muN * muN / (10.0 * kt / 8.0) * g;
  };
  double w1, m1, w2, m2;
  cycle(0.1, w1, m1);
  cycle(0.2, w2, m2);
  INFO("loss per cycle " << w1 << " J (Mindlin " << m1 << "), " << w2 << " J (Mindlin " << m2 << ")");
  CHECK(w1 > 0.0);
  CHECK(w1 == Approx(m1).epsilon(0.01));
  CHECK(w2 == Approx(m2).epsilon(0.01));
  CHECK(w2 / w1 == Approx(8.6238).epsilon(5e-3));
}

TEST_CASE("mindlin_deresiewicz: far from the Coulomb limit it is tangential history",
          "[contact][tangential][mindlin]") {
  // mu = 1e9: theta = 1 to 1e-10, so on a growing and shrinking contact with a
  // turning tangential motion the force equals tangential history's
  // -kt(a) times the accumulated displacement (1e-8 relative).
  ModelSpec hist_spec;
  hist_spec.normal = NormalModel::Hertz;
  hist_spec.tangential = TangentialModel::History;
  const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 0.7, 1e9, 0.0, 0.0);
  ContactState c = wall_contact();
  c.dt = 1e-6;
  std::vector<double> h_md(history_size(mindlin()), 0.0), h_hist(3, 0.0);
  for (int k = 0; k < 400; ++k) {
    const double t = k * c.dt;
    c.overlap = 1e-5 * (1.0 + 0.8 * std::sin(2e4 * t));
    c.v_rel = Vec3(0.3 * std::cos(3e4 * t), 0.2 * std::sin(1e4 * t), -0.1);
    ContactResult r_md, r_hist;
    evaluate(mindlin(), c, mat, h_md.data(), r_md);
    evaluate(hist_spec, c, mat, h_hist.data(), r_hist);
    INFO("step " << k);
    REQUIRE((r_md.force - r_hist.force).norm() <= 1e-8 * r_hist.force.norm());
    REQUIRE((r_md.ft - r_hist.ft).norm() <= 1e-8 * r_hist.ft.norm() + 1e-300);
  }
}

TEST_CASE("mindlin_deresiewicz: model words and history layout", "[contact][tangential][mindlin]") {
  std::vector<std::string> words = {"model", "hertz", "tangential", "mindlin_deresiewicz", "rolling_friction",
                                    "epsd2"};
  std::size_t pos = 0;
  const ModelSpec spec = parse_model_words(words, pos);
  CHECK(spec.tangential == TangentialModel::MindlinDeresiewicz);
  CHECK(model_words(spec) == "model hertz tangential mindlin_deresiewicz rolling_friction epsd2");
  const HistoryLayout layout = history_layout(spec);
  CHECK(layout.shear == 0);
  CHECK(layout.slip == 3);
  CHECK(layout.rolling == 6);
  CHECK(layout.size == 9);
  std::vector<double> signs(layout.size);
  history_swap_signs(spec, signs.data());
  CHECK(signs == std::vector<double>{-1, -1, -1, 1, 1, 1, -1, -1, -1});
}
