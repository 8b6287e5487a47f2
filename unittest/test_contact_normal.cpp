// Physics tests of the normal contact laws (Hertz, Hooke): force law,
// coefficient of restitution, contact duration, energy and momentum
// conservation, limitForce. Collisions are integrated here with a small
// velocity-Verlet loop that calls the kernels directly (no engine).
#include <catch2/catch.hpp>

#include <cmath>
#include <functional>

#include "contact/contact_kernels.h"
#include "contact/contact_model.h"

using namespace granary::contact;

namespace {

struct Body {
  Vec3 x = Vec3::Zero(), v = Vec3::Zero(), w = Vec3::Zero();
  double m = 1.0, r = 1.0, inertia = 1.0;  // solid sphere: I = 2/5 m r^2
  Vec3 f = Vec3::Zero(), t = Vec3::Zero();
};

Body sphere(double r, double density) {
  Body b;
  b.r = r;
  b.m = density * 4.0 / 3.0 * M_PI * r * r * r;
  b.inertia = 0.4 * b.m * r * r;
  return b;
}

// Contact state of sphere a against sphere b, or against the plane z = 0
// (normal +z) when b is null.
ContactState make_state(const Body& a, const Body* b, double dt) {
  ContactState c;
  c.dt = dt;
  c.r_i = a.r;
  if (b) {
    const Vec3 d = a.x - b->x;
    const double dist = d.norm();
    c.n = d / dist;
    c.overlap = a.r + b->r - dist;
    c.r_j = b->r;
    c.r_eff = a.r * b->r / (a.r + b->r);
    c.m_eff = a.m * b->m / (a.m + b->m);
    c.v_rel = a.v - b->v;
    c.omega_j = b->w;
  } else {
    c.n = Vec3::UnitZ();
    c.overlap = a.r - a.x.z();
    c.r_j = 0.0;
    c.r_eff = a.r;
    c.m_eff = a.m;
    c.v_rel = a.v;
  }
  c.omega_i = a.w;
  return c;
}

// Velocity Verlet in the LAMMPS form (half kick, drift, force, half kick)
// for one sphere against another sphere or the wall z = 0. Runs until the
// contact has been made and broken again (or max_steps). `observe` sees the
// result of every force evaluation that found an overlap.
int collide(const ModelSpec& spec, const PairMaterial& mat, Body& a, Body* b, double dt, int max_steps,
            const std::function<void(const ContactResult&)>& observe = {}) {
  std::vector<double> hist(history_size(spec), 0.0);
  bool touched = false;
  int contact_steps = 0;
  for (int step = 0; step < max_steps; ++step) {
    for (Body* p : {&a, b}) {
      if (!p) continue;
      p->v += 0.5 * dt / p->m * p->f;
      p->w += 0.5 * dt / p->inertia * p->t;
      p->x += dt * p->v;
    }
    ContactState c = make_state(a, b, dt);
    ContactResult res;
    evaluate(spec, c, mat, hist.data(), res);
    a.f = res.force;
    a.t = res.torque_i;
    if (b) {
      b->f = -res.force;
      b->t = res.torque_j;
    }
    for (Body* p : {&a, b}) {
      if (!p) continue;
      p->v += 0.5 * dt / p->m * p->f;
      p->w += 0.5 * dt / p->inertia * p->t;
    }
    if (c.overlap > 0.0) {
      touched = true;
      ++contact_steps;
      if (observe) observe(res);
    } else if (touched) {
      break;
    }
  }
  return contact_steps;
}

// Hertz contact duration for an elastic head-on impact at relative speed v:
// with F = K delta^1.5, K = 4/3 Y* sqrt(R*), energy conservation gives the
// maximum overlap delta_m = (5 m* v^2 / (4 K))^(2/5) and
//   t_c = 2 (delta_m / v) int_0^1 dx / sqrt(1 - x^2.5)
//       = 2 (delta_m / v) sqrt(pi) Gamma(7/5) / Gamma(9/10)
//       = 2.9432 (15 m* / (16 Y* sqrt(R*)))^(2/5) v^(-1/5)
//       = 2.8683 (m*^2 / (R* Y*^2 v))^(1/5).
double hertz_contact_time(double m_eff, double r_eff, double y_eff, double v) {
  const double k = 4.0 / 3.0 * y_eff * std::sqrt(r_eff);
  const double delta_m = std::pow(5.0 * m_eff * v * v / (4.0 * k), 0.4);
  const double integral = std::sqrt(M_PI) * std::tgamma(1.4) / std::tgamma(0.9);
  return 2.0 * delta_m / v * integral;
}

ModelSpec spec_of(NormalModel n, TangentialModel t = TangentialModel::History,
                  RollingModel r = RollingModel::None, bool limit = false) {
  ModelSpec s;
  s.normal = n;
  s.tangential = t;
  s.rolling = r;
  s.limit_force = limit;
  return s;
}

constexpr double kY = 5e7, kNu = 0.3, kDensity = 2500.0;

}  // namespace

TEST_CASE("Hertz elastic force is (4/3) Y* sqrt(R*) delta^1.5", "[contact][normal]") {
  // No damping (e = 1): the normal force must be exactly the Hertz law, for
  // any normal velocity, for a sphere pair and for a sphere on a wall.
  const PairMaterial mat = mix_materials(kY, kNu, 2 * kY, 0.25, 1.0, 0.5, 0.0, 0.0);
  const ModelSpec spec = spec_of(NormalModel::Hertz);
  for (double r_j : {0.0, 0.003}) {
    for (double delta : {1e-7, 3e-6, 2e-5, 1e-4}) {
      ContactState c;
      c.n = Vec3(1, 2, 2) / 3.0;
      c.overlap = delta;
      c.r_i = 0.002;
      c.r_j = r_j;
      c.r_eff = r_j > 0 ? c.r_i * r_j / (c.r_i + r_j) : c.r_i;
      c.m_eff = 1e-4;
      c.v_rel = -0.7 * c.n;
      c.dt = 1e-7;
      double hist[3] = {0, 0, 0};
      ContactResult res;
      evaluate(spec, c, mat, hist, res);
      const double expected = 4.0 / 3.0 * mat.Y_eff * std::sqrt(c.r_eff) * std::pow(delta, 1.5);
      CHECK(res.fn == Approx(expected).epsilon(1e-12));
      CHECK((res.force - expected * c.n).norm() <= 1e-12 * expected);
    }
  }
}

TEST_CASE("Hertz and Hooke normal damping follow the LIGGGHTS coefficients", "[contact][normal]") {
  // Fn = kn delta - gamma_n vn with
  //   Hertz: kn = 4/3 Y* sqrt(R* delta), gamma_n = -2 sqrt(5/6) beta sqrt(2 Y* sqrt(R* delta) m*)
  //   Hooke: kn = 16/15 sqrt(R*) Y* (15 m* V^2 / (16 sqrt(R*) Y*))^(1/5),
  //          gamma_n = sqrt(4 m* kn / (1 + (pi / ln e)^2)).
  const double e = 0.4, vchar = 1.5;
  const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, e, 0.5, 0.0, vchar);
  ContactState c;
  c.n = Vec3::UnitX();
  c.overlap = 2e-5;
  c.r_i = c.r_j = 0.004;
  c.r_eff = 0.002;
  c.m_eff = 3e-4;
  c.v_rel = Vec3(-0.3, 0, 0);
  c.dt = 1e-7;
  double hist[3] = {0, 0, 0};
  ContactResult res;

  evaluate(spec_of(NormalModel::Hertz), c, mat, hist, res);
  const double s = std::sqrt(c.r_eff * c.overlap);
  const double kn_hz = 4.0 / 3.0 * mat.Y_eff * s;
  const double gn_hz = -2.0 * std::sqrt(5.0 / 6.0) * mat.beta * std::sqrt(2 * mat.Y_eff * s * c.m_eff);
  CHECK(res.fn == Approx(kn_hz * c.overlap + gn_hz * 0.3).epsilon(1e-12));

  evaluate(spec_of(NormalModel::Hooke), c, mat, hist, res);
  const double sr = std::sqrt(c.r_eff);
  const double kn_hk =
      16.0 / 15.0 * sr * mat.Y_eff * std::pow(15.0 * c.m_eff * vchar * vchar / (16.0 * sr * mat.Y_eff), 0.2);
  const double q = M_PI / std::log(e);
  const double gn_hk = std::sqrt(4.0 * c.m_eff * kn_hk / (1.0 + q * q));
  CHECK(res.fn == Approx(kn_hk * c.overlap + gn_hk * 0.3).epsilon(1e-12));
}

TEST_CASE("Head-on impact reproduces the coefficient of restitution", "[contact][normal]") {
  // Tolerance 1% on e for e = 0.3, 0.6, 0.9, both normal laws, sphere-sphere
  // (unequal sizes) and sphere-wall. dt = t_c / 2000.
  for (NormalModel nm : {NormalModel::Hertz, NormalModel::Hooke}) {
    for (double e : {0.3, 0.6, 0.9}) {
      for (bool wall : {false, true}) {
        const double v0 = 0.8;
        const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, e, 0.5, 0.0, v0);
        Body a = sphere(0.003, kDensity), b = sphere(0.005, kDensity);
        const double m_eff = wall ? a.m : a.m * b.m / (a.m + b.m);
        const double r_eff = wall ? a.r : a.r * b.r / (a.r + b.r);
        const double dt = hertz_contact_time(m_eff, r_eff, mat.Y_eff, v0) / 2000.0;
        if (wall) {
          a.x = Vec3(0, 0, a.r + 1e-6);
          a.v = Vec3(0, 0, -v0);
        } else {
          a.x = Vec3(-a.r - 1e-6, 0, 0);
          b.x = Vec3(b.r, 0, 0);
          a.v = Vec3(v0 * b.m / (a.m + b.m), 0, 0);
          b.v = Vec3(-v0 * a.m / (a.m + b.m), 0, 0);
        }
        const Vec3 n = wall ? Vec3::UnitZ() : Vec3(-1, 0, 0);  // from b to a
        const double vn_before = (wall ? a.v : Vec3(a.v - b.v)).dot(n);
        collide(spec_of(nm), mat, a, wall ? nullptr : &b, dt, 100000);
        const double vn_after = (wall ? a.v : Vec3(a.v - b.v)).dot(n);
        const double e_measured = -vn_after / vn_before;
        INFO("model " << (nm == NormalModel::Hertz ? "hertz" : "hooke") << " e " << e << " wall " << wall
                      << " measured " << e_measured);
        CHECK(e_measured == Approx(e).epsilon(0.01));
      }
    }
  }
}

TEST_CASE("Hertz contact duration matches the elastic theory", "[contact][normal]") {
  // e = 1; tolerance 2% (the integration with dt = t_c/5000 is far better).
  for (double v0 : {0.1, 1.0, 5.0}) {
    const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 1.0, 0.0, 0.0, 0.0);
    Body a = sphere(0.002, kDensity), b = sphere(0.004, kDensity);
    const double m_eff = a.m * b.m / (a.m + b.m), r_eff = a.r * b.r / (a.r + b.r);
    const double tc = hertz_contact_time(m_eff, r_eff, mat.Y_eff, v0);
    // The closed form quoted in the literature.
    CHECK(tc ==
          Approx(2.8683 * std::pow(m_eff * m_eff / (r_eff * mat.Y_eff * mat.Y_eff * v0), 0.2)).epsilon(1e-4));
    const double dt = tc / 5000.0;
    a.x = Vec3(0, -a.r, 0);
    b.x = Vec3(0, b.r, 0);
    a.v = Vec3(0, v0 * b.m / (a.m + b.m), 0);
    b.v = Vec3(0, -v0 * a.m / (a.m + b.m), 0);
    const int steps = collide(spec_of(NormalModel::Hertz), mat, a, &b, dt, 100000);
    INFO("v0 " << v0 << " theory " << tc << " measured " << steps * dt);
    CHECK(steps * dt == Approx(tc).epsilon(0.02));
  }
}

TEST_CASE("Elastic head-on impact conserves kinetic energy", "[contact][normal]") {
  // e = 1, dt = t_c / 20000: kinetic energy after == before within 1e-6.
  for (NormalModel nm : {NormalModel::Hertz, NormalModel::Hooke}) {
    for (bool wall : {false, true}) {
      const double v0 = 1.2;
      const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 1.0, 0.3, 0.0, v0);
      Body a = sphere(0.002, kDensity), b = sphere(0.003, 3 * kDensity);
      const double m_eff = wall ? a.m : a.m * b.m / (a.m + b.m);
      const double r_eff = wall ? a.r : a.r * b.r / (a.r + b.r);
      const double dt = hertz_contact_time(m_eff, r_eff, mat.Y_eff, v0) / 20000.0;
      if (wall) {
        a.x = Vec3(0, 0, a.r);
        a.v = Vec3(0, 0, -v0);
      } else {
        a.x = Vec3(0, 0, a.r);
        b.x = Vec3(0, 0, -b.r);
        a.v = Vec3(0, 0, -0.5 * v0);
        b.v = Vec3(0, 0, 0.5 * v0);
      }
      auto ke = [&]() {
        return 0.5 * a.m * a.v.squaredNorm() + (wall ? 0.0 : 0.5 * b.m * b.v.squaredNorm());
      };
      const double before = ke();
      collide(spec_of(nm), mat, a, wall ? nullptr : &b, dt, 1000000);
      INFO("wall " << wall << " hooke " << (nm == NormalModel::Hooke));
      CHECK(ke() == Approx(before).epsilon(1e-6));
    }
  }
}

TEST_CASE("Pair collisions conserve linear and angular momentum", "[contact][normal]") {
  // Oblique impact with spins, friction, damping and rolling resistance.
  // Forces are equal and opposite and the lever arms r - delta/2 put both
  // tangential forces at the same contact point, so the total linear momentum
  // and the total angular momentum about the origin are conserved to
  // round-off (1e-12 relative).
  for (RollingModel rm : {RollingModel::None, RollingModel::Cdt, RollingModel::Epsd2, RollingModel::Epsd,
                          RollingModel::Epsd3}) {
    for (TangentialModel tm : {TangentialModel::NoHistory, TangentialModel::History}) {
      for (NormalModel nm : {NormalModel::Hertz, NormalModel::Hooke, NormalModel::HookeHysteresis}) {
        PairMaterial mat = mix_materials(kY, kNu, kY, 0.2, 0.5, 0.4, 0.2, 1.0);
        mat.rolling_stiffness = 1.5;      // epsd, epsd3
        mat.max_elastic_stiffness = 2.0;  // hooke/hysteresis
        mat.adhesion_stiffness = 0.2;
        mat.plasticity_depth = 0.05;
        Body a = sphere(0.002, kDensity), b = sphere(0.0035, 2 * kDensity);
        a.x = Vec3(0.001, 0.0004, 0.0021);
        b.x = Vec3(0.0002, -0.0003, -0.0035);
        a.v = Vec3(-0.3, 0.2, -0.9);
        b.v = Vec3(0.1, -0.05, 0.2);
        a.w = Vec3(100, -40, 25);
        b.w = Vec3(-20, 60, 10);
        auto momentum = [&]() { return Vec3(a.m * a.v + b.m * b.v); };
        auto angular = [&]() {
          return Vec3(a.x.cross(a.m * a.v) + a.inertia * a.w + b.x.cross(b.m * b.v) + b.inertia * b.w);
        };
        const Vec3 p0 = momentum(), l0 = angular();
        const double tc = hertz_contact_time(a.m * b.m / (a.m + b.m), 0.0013, kY, 1.0);
        const int steps = collide(spec_of(nm, tm, rm), mat, a, &b, tc / 2000.0, 100000);
        REQUIRE(steps > 100);
        CHECK((momentum() - p0).norm() <= 1e-12 * p0.norm());
        CHECK((angular() - l0).norm() <= 1e-12 * l0.norm());
        // Something actually happened: spins were changed by the contact.
        CHECK((a.w - Vec3(100, -40, 25)).norm() > 1.0);
      }
    }
  }
}

TEST_CASE("limitForce forbids attractive normal forces", "[contact][normal]") {
  // e = 0.3 makes the dashpot outweigh the spring at the end of the impact:
  // without limitForce the total normal force turns attractive, with it the
  // force stays >= 0 at every step.
  for (NormalModel nm : {NormalModel::Hertz, NormalModel::Hooke}) {
    for (bool limit : {false, true}) {
      const PairMaterial mat = mix_materials(kY, kNu, kY, kNu, 0.3, 0.5, 0.0, 1.0);
      Body a = sphere(0.002, kDensity);
      a.x = Vec3(0, 0, a.r);
      a.v = Vec3(0, 0, -1.0);
      double fn_min = 0.0;
      const double dt = hertz_contact_time(a.m, a.r, mat.Y_eff, 1.0) / 2000.0;
      collide(spec_of(nm, TangentialModel::History, RollingModel::None, limit), mat, a, nullptr, dt, 100000,
              [&](const ContactResult& r) {
                fn_min = std::min(fn_min, r.fn);
                CHECK(r.force.dot(Vec3::UnitZ()) == Approx(r.fn).margin(1e-15));
              });
      if (limit) {
        CHECK(fn_min == 0.0);
      } else {
        CHECK(fn_min < 0.0);
      }
      CHECK(a.v.z() > 0.0);  // it still bounces
    }
  }
}

TEST_CASE("hooke/hysteresis follows Luding's loading, unloading and adhesive branches", "[contact][normal]") {
  // Prescribed overlap path on two equal spheres (R* = 1 mm) with no damping
  // (e = 1): load to delta_1, unload into the adhesive branch, reload past
  // the first maximum. Expected (Luding 2008), with k1 = kn of model hooke:
  //   loading (delta at its maximum)  f = k1 delta
  //   unloading / reloading           f = k2 (delta - delta_0),
  //     k2 = k1 + (k2max - k1) min(delta_max / delta*, 1),
  //     delta_0 = (1 - k1/k2) delta_max, delta* = k2max / (k2max - k1) phi_f 2 R*
  //   adhesion at most                f = -kc delta,
  //     where delta_max moves so that the k2 line passes through (delta, -kc delta)
  PairMaterial mat = mix_materials(5e6, 0.45, 5e6, 0.45, 1.0, 0.0, 0.0, 2.0);
  mat.max_elastic_stiffness = 2.0;
  mat.adhesion_stiffness = 0.2;
  mat.plasticity_depth = 0.05;
  ModelSpec spec;
  spec.normal = NormalModel::HookeHysteresis;
  spec.tangential = TangentialModel::None;
  REQUIRE(history_size(spec) == 1);
  ContactState c;
  c.n = Vec3::UnitX();
  c.r_i = c.r_j = 0.002;
  c.r_eff = 0.001;
  c.m_eff = 4e-5;
  c.dt = 1e-6;
  double h = 0.0;
  ContactResult res;
  auto force_at = [&](double delta) {
    c.overlap = delta;
    evaluate(spec, c, mat, &h, res);
    return res.fn;
  };
  // k1: the stiffness of model hooke
  const double k1 = force_at(1e-6) / 1e-6;
  const double kn_hooke = 16.0 / 15.0 * std::sqrt(c.r_eff) * mat.Y_eff *
                          std::pow(15.0 * c.m_eff * 4.0 / (16.0 * std::sqrt(c.r_eff) * mat.Y_eff), 0.2);
  CHECK(k1 == Approx(kn_hooke).epsilon(1e-12));
  const double k2max = 2.0 * k1, kc = 0.2 * k1, d_star = 2.0 * 0.05 * 2.0 * c.r_eff;  // 2e-4 m
  auto k2_of = [&](double dmax) { return k1 + (k2max - k1) * std::min(dmax / d_star, 1.0); };
  // loading to 1.2e-4 (below delta*): f = k1 delta all the way
  for (double d = 2e-6; d <= 1.2e-4 + 1e-12; d += 2e-6)
    CHECK(force_at(d) == Approx(k1 * d).epsilon(1e-12));
  CHECK(h == Approx(1.2e-4).epsilon(1e-12));  // delta_max
  // unloading on k2 = k1 (1 + 0.6) down to where k2 (delta - delta_0) = -kc delta
  const double dmax = 1.2e-4, k2 = k2_of(dmax), d0 = (1.0 - k1 / k2) * dmax;
  const double d_adh = k2 * d0 / (k2 + kc);  // the start of the adhesive branch
  double d = dmax;
  for (; d > d_adh + 1e-6; d -= 1e-6)
    CHECK(force_at(d) == Approx(k2 * (d - d0)).epsilon(1e-9).margin(1e-15));
  CHECK(force_at(d_adh - 2e-6) == Approx(-kc * (d_adh - 2e-6)).epsilon(1e-12));
  // on the adhesive branch down to 1.5e-5; delta_max moves with it
  for (d = d_adh - 2e-6; d > 1.5e-5; d -= 1e-6)
    CHECK(force_at(d) == Approx(-kc * d).epsilon(1e-12));
  const double turn = d + 1e-6;
  const double dmax_new = h;
  const double k2_new = k2_of(dmax_new), d0_new = (1.0 - k1 / k2_new) * dmax_new;
  CHECK(k2_new * (turn - d0_new) == Approx(-kc * turn).epsilon(1e-9));  // through the turning point
  CHECK(dmax_new < dmax);
  // reloading on the new k2 line up to the virgin curve, then on k1 delta again
  for (d = turn + 1e-6; d < dmax_new - 1e-6; d += 1e-6)
    CHECK(force_at(d) == Approx(k2_new * (d - d0_new)).epsilon(1e-9).margin(1e-15));
  for (d = dmax_new + 1e-6; d < 1.8e-4; d += 1e-6)
    CHECK(force_at(d) == Approx(k1 * d).epsilon(1e-12));
  // beyond delta*, k2 = k2max: loading to 3e-4, unloading on k2max
  for (d = 1.8e-4; d <= 3e-4 + 1e-12; d += 1e-6)
    force_at(d);
  CHECK(force_at(2.5e-4) == Approx(k2max * (2.5e-4 - 0.5 * h)).epsilon(1e-9));
  // apart: no force, history cleared
  CHECK(force_at(-1e-7) == 0.0);
  CHECK(h == 0.0);
}
