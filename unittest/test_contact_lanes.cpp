// The two-lane Hertz / tangential history / (cdt or no) rolling kernel of
// contact_lanes.h against the scalar kernel it replaces in the pair loop:
// on random contacts (sticking and slipping, touching and not, relative spins
// at round-off level, several partners' radii and masses, both lanes for one
// particle or one for each of two) every lane must give
// the scalar kernel's force, torques and updated shear history to the last
// bit. The inputs are built with the pair loop's own arithmetic (n = d * (1/r),
// R* = r_i r_j / (r_i + r_j), m* = m_i m_j / (m_i + m_j)).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "contact/contact_kernels.h"
#include "contact/contact_lanes.h"
#include "contact/contact_model.h"

using namespace granary::contact;

namespace {

// Same IEEE operations in the same order: identical bits. A build that lets
// the compiler fuse multiplies and adds (-mfma, -march=native) may fuse the
// two versions differently; there they agree to round-off.
bool same(double a, double b) {
#if defined(__FMA__)
  return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b)) + 1e-300;
#else
  return (a == b && std::signbit(a) == std::signbit(b)) || (std::isnan(a) && std::isnan(b));
#endif
}

lanes::V3 pack2(const Vec3& a, const Vec3& b) {
  return {lanes::D{a[0], b[0]}, lanes::D{a[1], b[1]}, lanes::D{a[2], b[2]}};
}

bool same(const Vec3& a, const Vec3& b) {
  return same(a[0], b[0]) && same(a[1], b[1]) && same(a[2], b[2]);
}

struct Sample {
  Vec3 d, v_rel, omega_i, omega_j, shear;
  double r_i, r_j, m_i, m_j;
  PairMaterial mat;
};

struct Counts {
  int slip = 0, stick = 0, apart = 0, tiny_spin = 0;
};

template <RollingModel R, bool Limit>
void compare(const ModelSpec& spec, std::mt19937_64& rng, Counts& counts) {
  using K = Kernel<NormalModel::Hertz, TangentialModel::History, R, Limit, CohesionModel::None>;
  static_assert(lanes::W == 2, "the samples fill two lanes");
  static_assert(lanes::supported<K>(), "kernel has a two-lane version");
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto unit = [&]() {
    Vec3 a(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    return Vec3(a / a.norm());
  };
  const double dt = 1e-6;
  for (int trial = 0; trial < 4000; ++trial) {
    // two contacts: of one particle i (as within a particle's row) or of two
    // (as where one particle's contacts end and the next one's begin)
    const bool one_particle = u(rng) < 0.5;
    Sample s[2];
    for (int l = 0; l < 2; ++l) {
      Sample& q = s[l];
      if (l == 0 || !one_particle) {
        q.r_i = 0.4e-3 + 1.1e-3 * u(rng);
        q.m_i = 1e-6 + 1e-4 * u(rng);
        q.omega_i = 100.0 * u(rng) * unit();
      } else {
        q.r_i = s[0].r_i;
        q.m_i = s[0].m_i;
        q.omega_i = s[0].omega_i;
      }
      const double r_i = q.r_i, m_i = q.m_i;
      const Vec3 omega_i = q.omega_i;
      // a few partners equal to i's radius and mass (the bed of equal spheres)
      const bool equal = u(rng) < 0.3;
      q.r_j = equal ? r_i : 0.4e-3 + 1.1e-3 * u(rng);
      q.m_j = equal ? m_i : 1e-6 + 1e-4 * u(rng);
      const double pick = u(rng);
      double overlap = 1e-4 * u(rng) * u(rng);
      if (pick < 0.05) overlap = -1e-6 * u(rng);  // listed but apart
      q.d = (r_i + q.r_j - overlap) * unit();
      q.v_rel = (u(rng) < 0.5 ? 1e-3 : 1.0) * u(rng) * unit();
      // relative spin zero or at round-off: the cdt tolerance path
      q.omega_j = u(rng) < 0.1 ? Vec3(omega_i * (1.0 + 1e-14 * (u(rng) - 0.5))) : Vec3(100.0 * u(rng) * unit());
      q.shear = (u(rng) < 0.5 ? 1e-8 : 1e-5) * u(rng) * unit();
      q.mat = mix_materials(1e6 + 1e8 * u(rng), 0.45 * u(rng), 1e6 + 1e8 * u(rng), 0.45 * u(rng),
                            0.05 + 0.95 * u(rng), u(rng), 0.3 * u(rng), 0.0);
      q.mat.dissipative_time = 1e-6 * u(rng);
    }

    // the scalar kernel, as the pair loop feeds it
    ContactResult ref[2];
    Vec3 ref_shear[2];
    for (int l = 0; l < 2; ++l) {
      const Sample& q = s[l];
      const double r_i = q.r_i, m_i = q.m_i;
      const Vec3 omega_i = q.omega_i;
      ContactState c;
      const double rsum = r_i + q.r_j;
      const double r = std::sqrt(q.d.squaredNorm());
      const double inv_r = 1.0 / r;
      c.n = q.d * inv_r;
      c.overlap = rsum - r;
      c.r_i = r_i;
      c.r_j = q.r_j;
      c.r_eff = r_i * q.r_j / rsum;
      c.m_eff = m_i * q.m_j / (m_i + q.m_j);
      c.v_rel = q.v_rel;
      c.omega_i = omega_i;
      c.omega_j = q.omega_j;
      c.dt = dt;
      double h[3] = {q.shear[0], q.shear[1], q.shear[2]};
      K::evaluate(spec, c, q.mat, h, ref[l]);
      ref_shear[l] = Vec3(h[0], h[1], h[2]);
      if (!(c.overlap > 0.0)) {
        ++counts.apart;
      } else {
        const double kt = 8.0 * q.mat.G_eff * std::sqrt(c.r_eff * c.overlap);
        // slipped when the stored displacement was cut back to the Coulomb limit
        if (std::abs(kt * ref_shear[l].norm() - q.mat.friction * std::abs(ref[l].fn)) <=
            1e-9 * (kt * ref_shear[l].norm()))
          ++counts.slip;
        else
          ++counts.stick;
      }
      if ((omega_i - q.omega_j).norm() <= 1e-10 * (omega_i.norm() + q.omega_j.norm())) ++counts.tiny_spin;
    }

    // both lanes at once
    lanes::PairInput in;
    in.d = pack2(s[0].d, s[1].d);
    in.r_i = lanes::D{s[0].r_i, s[1].r_i};
    in.r_j = lanes::D{s[0].r_j, s[1].r_j};
    in.m_i = lanes::D{s[0].m_i, s[1].m_i};
    in.m_j = lanes::D{s[0].m_j, s[1].m_j};
    in.omega_i = pack2(s[0].omega_i, s[1].omega_i);
    in.omega_j = pack2(s[0].omega_j, s[1].omega_j);
    in.Y_eff = lanes::D{s[0].mat.Y_eff, s[1].mat.Y_eff};
    in.G_eff = lanes::D{s[0].mat.G_eff, s[1].mat.G_eff};
    in.beta = lanes::D{s[0].mat.beta, s[1].mat.beta};
    in.friction = lanes::D{s[0].mat.friction, s[1].mat.friction};
    in.rolling_friction = lanes::D{s[0].mat.rolling_friction, s[1].mat.rolling_friction};
    in.dissipative_time = lanes::D{s[0].mat.dissipative_time, s[1].mat.dissipative_time};
    lanes::effective_radius_mass(in);
    lanes::Prepared q;
    lanes::prepare<R>(spec, in, q);
    lanes::V3 shear = pack2(s[0].shear, s[1].shear);
    lanes::PairOutput out;
    lanes::hertz_history<R, Limit>(q, pack2(s[0].v_rel, s[1].v_rel), in.omega_i, dt, shear, out);

    for (int l = 0; l < 2; ++l) {
      INFO("trial " << trial << " lane " << l << " overlap " << (s[l].r_i + s[l].r_j - s[l].d.norm()));
      REQUIRE(same(lanes::lane(out.force, l), ref[l].force));
      REQUIRE(same(lanes::lane(out.torque_i, l), ref[l].torque_i));
      REQUIRE(same(lanes::lane(out.torque_j, l), ref[l].torque_j));
      REQUIRE(same(lanes::lane(shear, l), ref_shear[l]));
    }
  }
}

template <RollingModel R>
void compare_all(std::mt19937_64& rng) {
  for (const DampingModel damping : {DampingModel::Restitution, DampingModel::Viscoelastic}) {
    for (const bool tangential_damping : {true, false}) {
      ModelSpec spec;
      spec.rolling = R;
      spec.damping = damping;
      spec.tangential_damping = tangential_damping;
      Counts counts;
      compare<R, false>(spec, rng, counts);
      compare<R, true>(spec, rng, counts);
      // every branch of the scalar kernel was taken
      CHECK(counts.slip > 100);
      CHECK(counts.stick > 100);
      CHECK(counts.apart > 100);
      CHECK(counts.tiny_spin > 100);
    }
  }
}

}  // namespace

TEST_CASE("Two-lane Hertz history kernel gives the scalar kernel's bits (no rolling)", "[contact][lanes]") {
  std::mt19937_64 rng(20261121);
  compare_all<RollingModel::None>(rng);
}

TEST_CASE("Two-lane Hertz history kernel gives the scalar kernel's bits (cdt rolling)", "[contact][lanes]") {
  std::mt19937_64 rng(7);
  compare_all<RollingModel::Cdt>(rng);
}

TEST_CASE("Two-lane kernel covers the models of the pair loop's fast path", "[contact][lanes]") {
  using HH = Kernel<NormalModel::Hertz, TangentialModel::History, RollingModel::Cdt, false>;
  using HE = Kernel<NormalModel::Hertz, TangentialModel::History, RollingModel::Epsd2, false>;
  using HN = Kernel<NormalModel::Hertz, TangentialModel::NoHistory, RollingModel::None, false>;
  using KH = Kernel<NormalModel::Hooke, TangentialModel::History, RollingModel::None, false>;
  using HC = Kernel<NormalModel::Hertz, TangentialModel::History, RollingModel::None, false, CohesionModel::Sjkr>;
  CHECK(lanes::supported<HH>());
  CHECK_FALSE(lanes::supported<HE>());
  CHECK_FALSE(lanes::supported<HN>());
  CHECK_FALSE(lanes::supported<KH>());
  CHECK_FALSE(lanes::supported<HC>());
}
