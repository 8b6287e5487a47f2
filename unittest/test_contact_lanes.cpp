// The contact formulas of contact_kernels.h on two and four lanes against one lane, and
// the compiled hot kernels against the run-time sub-model slots: on random
// contact models (every field of ModelSpec drawn at random) and random contacts
// (pairs and walls; sticking and slipping, touching and not, relative spins at
// round-off level, epsd2 springs below and at their cap, cohesive pulls),
// every lane of the two- and four-lane evaluations must give the one-lane evaluation's
// force, torques, normal and tangential force and updated history to the last
// bit, and the kernel dispatch_model() picks must give what RuntimeKernel gives.
// A new field of ModelSpec breaks the compilation of random_spec() below, so
// that it is drawn here too: a switch that one path ignores fails this test.
#include <catch2/catch.hpp>

// Four-lane kernels are instantiated here in a build without AVX too (not in
// the program's): GCC notes their ABI (see lane.h); nothing here is a call
// across a library boundary.
#if !defined(__AVX__) && defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "contact/contact_kernels.h"
#include "contact/contact_model.h"
#include "contact/lane.h"
#include "same_bits.h"

using namespace granary::contact;
using lane::V3;

namespace {

using granary::test::same_bits;

using U = std::uniform_real_distribution<double>;

ModelSpec random_spec(std::mt19937_64& rng) {
  U u(0.0, 1.0);
  auto pick = [&](int n) { return std::min(static_cast<int>(u(rng) * n), n - 1); };
  ModelSpec spec;
  // Every field, by position: a field added to ModelSpec stops this from
  // compiling until it is drawn here as well.
  auto& [normal, tangential, rolling, cohesion, damping, surface, tangential_reduce, modify_lb_volume,
         limit_force, tangential_damping, kt_to_kn_user, absolute_damping] = spec;
  normal = std::array{NormalModel::Hertz, NormalModel::Hooke, NormalModel::HertzStiffness,
                      NormalModel::HookeStiffness, NormalModel::HookeHysteresis}[pick(5)];
  tangential = std::array{TangentialModel::None, TangentialModel::NoHistory, TangentialModel::History,
                          TangentialModel::MindlinDeresiewicz}[pick(4)];
  rolling = std::array{RollingModel::None, RollingModel::Cdt, RollingModel::Epsd2, RollingModel::Epsd,
                       RollingModel::Epsd3}[pick(5)];
  // (the liquid bridges, easo and washino, are not kernel models: pair/liquid_bridge.h)
  cohesion = std::array{CohesionModel::None, CohesionModel::Sjkr, CohesionModel::Sjkr2}[pick(3)];
  damping = pick(2) ? DampingModel::Viscoelastic : DampingModel::Restitution;
  // read by the contact loops only (the kernels ignore it)
  surface = pick(2) ? SurfaceModel::Multicontact : SurfaceModel::Sphere;
  tangential_reduce = pick(2);
  modify_lb_volume = pick(2);  // read by the liquid bridges only
  limit_force = pick(2);
  tangential_damping = pick(2);
  kt_to_kn_user = pick(2);
  absolute_damping = pick(2);
  // half of the specs hot ones, so the compiled kernels are compared often
  if (pick(2)) {
    normal = NormalModel::Hertz;
    tangential = TangentialModel::History;
    if (rolling_spring(rolling)) rolling = RollingModel::Cdt;
    cohesion = CohesionModel::None;
  }
  return spec;
}

struct Sample {
  GeometryT<double> g;
  MaterialT<double> mat;
  V3<double> v_rel, shear, roll;
  SlipT<double> slip;
};

Vec3 unit(std::mt19937_64& rng) {
  U u(-0.5, 0.5);
  Vec3 a(u(rng), u(rng), u(rng));
  return a / a.norm();
}
V3<double> v3(const Vec3& a) {
  return {a[0], a[1], a[2]};
}

// A random contact, its inputs built with the pair loop's arithmetic (n = d *
// (1/r), R* = r_i r_j / (r_i + r_j), m* = m_i m_j / (m_i + m_j)); a wall
// (r_j = 0) in one of five.
Sample random_contact(std::mt19937_64& rng, const Sample* first) {
  U u(0.0, 1.0);
  Sample q;
  GeometryT<double>& g = q.g;
  double m_i;
  if (first && u(rng) < 0.5) {  // a second contact of the same particle
    g.r_i = first->g.r_i;
    g.omega_i = first->g.omega_i;
    m_i = first->g.m_eff;
  } else {
    g.r_i = 0.4e-3 + 1.1e-3 * u(rng);
    g.omega_i = v3(100.0 * u(rng) * unit(rng));
    m_i = 1e-6 + 1e-4 * u(rng);
  }
  const bool wall = u(rng) < 0.2;
  const bool equal = u(rng) < 0.3;  // partners like i (the bed of equal spheres)
  const double r_j = wall ? 0.0 : equal ? g.r_i : 0.4e-3 + 1.1e-3 * u(rng);
  const double m_j = equal ? m_i : 1e-6 + 1e-4 * u(rng);
  double overlap = 1e-4 * u(rng) * u(rng);
  if (u(rng) < 0.05) overlap = -1e-6 * u(rng);  // listed but apart
  const Vec3 d = (g.r_i + r_j - overlap) * unit(rng);
  if (wall) {
    g.n = v3(unit(rng));
    g.overlap = overlap;
    g.r_eff = g.r_i;
    g.m_eff = m_i;
    g.omega_j = {0.0, 0.0, 0.0};
  } else {
    const double rsum = g.r_i + r_j;
    const double r = std::sqrt(d.squaredNorm());
    const double inv_r = 1.0 / r;
    g.n = v3(d * inv_r);
    g.overlap = rsum - r;
    g.r_eff = g.r_i * r_j / rsum;
    g.m_eff = m_i * m_j / (m_i + m_j);
    // relative spin zero or at round-off: the cdt tolerance path
    const Vec3 oi(g.omega_i.x, g.omega_i.y, g.omega_i.z);
    g.omega_j = u(rng) < 0.1 ? v3(oi * (1.0 + 1e-14 * (u(rng) - 0.5))) : v3(100.0 * u(rng) * unit(rng));
  }
  g.r_j = r_j;
  g.i_roll = rolling_inertia(m_i, g.r_i, wall ? 0.0 : m_j, r_j);
  PairMaterial pm = mix_materials(1e6 + 1e8 * u(rng), 0.45 * u(rng), 1e6 + 1e8 * u(rng), 0.45 * u(rng),
                                  0.05 + 0.95 * u(rng), u(rng), 0.3 * u(rng), 0.1 + u(rng));
  pm.dissipative_time = 1e-6 * u(rng);
  pm.cohesion_energy_density = u(rng) < 0.5 ? 1e5 * u(rng) : 1e8 * u(rng);
  pm.kn = 1e2 + 1e4 * u(rng);
  pm.kt = 1e2 + 1e4 * u(rng);
  pm.gamman = 1e2 * u(rng);
  pm.gammat = 1e2 * u(rng);
  pm.rolling_damping = u(rng);
  pm.rolling_stiffness = 0.5 + 2.0 * u(rng);
  pm.max_elastic_stiffness = 1.1 + 3.0 * u(rng);
  pm.adhesion_stiffness = 0.5 * u(rng);
  pm.plasticity_depth = 0.01 + 0.2 * u(rng);
  set_material(q.mat, 0, pm);
  q.v_rel = v3((u(rng) < 0.5 ? 1e-3 : 1.0) * u(rng) * unit(rng));
  q.shear = v3((u(rng) < 0.5 ? 1e-8 : 1e-5) * u(rng) * unit(rng));
  q.roll = v3((u(rng) < 0.5 ? 1e-9 : 1e-5) * u(rng) * unit(rng));
  // mindlin_deresiewicz: a force at a reversal either way, the last kt or none
  q.slip.turn = u(rng) < 0.3 ? 0.0 : 2e-5 * (u(rng) - 0.5);
  q.slip.t_max = u(rng) < 0.3 ? 0.0 : 2e-5 * u(rng);
  q.slip.kt_prev = u(rng) < 0.3 ? 0.0 : 1e2 + 1e5 * u(rng);
  // hooke/hysteresis: no plastic state yet, or a maximum overlap above or below this one
  q.slip.d_max = u(rng) < 0.3 ? 0.0 : 2e-4 * u(rng);
  return q;
}

struct Out {
  ResultT<double> r;
  V3<double> shear, roll;
  SlipT<double> slip;
};

template <class K>
Out one_lane(const ModelSpec& spec, const Sample& s, double dt) {
  PreparedT<double> q;
  prepare<K>(spec, s.g, s.mat, q);
  Out o{{}, s.shear, s.roll, s.slip};
  interact<K>(spec, q, s.v_rel, HistoryDt{dt, dt}, o.shear, o.slip, o.roll, o.r);
  return o;
}

// Lanes of S from one field of W samples.
template <class S, class F>
S pack(const Sample* s, F field) {
  S r;
  for (int l = 0; l < lane::width<S>(); ++l)
    r[l] = field(s[l]);
  return r;
}
template <class S, class F>
V3<S> pack3(const Sample* s, F field) {
  return {pack<S>(s, [&](const Sample& x) { return field(x).x; }),
          pack<S>(s, [&](const Sample& x) { return field(x).y; }),
          pack<S>(s, [&](const Sample& x) { return field(x).z; })};
}

// The W samples s[0..W-1] evaluated at once, lane l giving out[l].
template <class K, class S>
void lanes(const ModelSpec& spec, const Sample* s, double dt, Out* out) {
  constexpr int W = lane::width<S>();
#define GRANARY_PACK(field) pack<S>(s, [](const Sample& x) { return x.field; })
#define GRANARY_PACK3(field) pack3<S>(s, [](const Sample& x) { return x.field; })
  GeometryT<S> g;
  g.n = GRANARY_PACK3(g.n);
  g.overlap = GRANARY_PACK(g.overlap);
  g.r_i = GRANARY_PACK(g.r_i);
  g.r_j = GRANARY_PACK(g.r_j);
  g.r_eff = GRANARY_PACK(g.r_eff);
  g.m_eff = GRANARY_PACK(g.m_eff);
  g.i_roll = GRANARY_PACK(g.i_roll);
  g.omega_i = GRANARY_PACK3(g.omega_i);
  g.omega_j = GRANARY_PACK3(g.omega_j);
  MaterialT<S> m = {GRANARY_PACK(mat.Y_eff),
                    GRANARY_PACK(mat.G_eff),
                    GRANARY_PACK(mat.beta),
                    GRANARY_PACK(mat.friction),
                    GRANARY_PACK(mat.rolling_friction),
                    GRANARY_PACK(mat.char_velocity),
                    GRANARY_PACK(mat.cohesion_energy_density),
                    GRANARY_PACK(mat.dissipative_time),
                    GRANARY_PACK(mat.kn),
                    GRANARY_PACK(mat.kt),
                    GRANARY_PACK(mat.gamman),
                    GRANARY_PACK(mat.gammat),
                    GRANARY_PACK(mat.rolling_damping),
                    GRANARY_PACK(mat.rolling_stiffness),
                    GRANARY_PACK(mat.max_elastic_stiffness),
                    GRANARY_PACK(mat.adhesion_stiffness),
                    GRANARY_PACK(mat.plasticity_depth)};
  PreparedT<S> q;
  prepare<K>(spec, g, m, q);
  V3<S> shear = GRANARY_PACK3(shear), roll = GRANARY_PACK3(roll);
  SlipT<S> slip{GRANARY_PACK(slip.turn), GRANARY_PACK(slip.t_max), GRANARY_PACK(slip.kt_prev),
                GRANARY_PACK(slip.d_max)};
  ResultT<S> r;
  interact<K>(spec, q, GRANARY_PACK3(v_rel), HistoryDt{dt, dt}, shear, slip, roll, r);
#undef GRANARY_PACK
#undef GRANARY_PACK3
  for (int l = 0; l < W; ++l) {
    auto v = [l](const V3<S>& x) { return V3<double>{x.x[l], x.y[l], x.z[l]}; };
    out[l].r.force = v(r.force);
    out[l].r.torque_i = v(r.torque_i);
    out[l].r.torque_j = v(r.torque_j);
    out[l].r.ft = v(r.ft);
    out[l].r.fn = r.fn[l];
    out[l].shear = v(shear);
    out[l].roll = v(roll);
    out[l].slip = {slip.turn[l], slip.t_max[l], slip.kt_prev[l], slip.d_max[l]};
  }
}

Vec3 e(const V3<double>& a) {
  return Vec3(a.x, a.y, a.z);
}

bool same_bits(const Out& a, const Out& b) {
  return same_bits(e(a.r.force), e(b.r.force)) && same_bits(e(a.r.torque_i), e(b.r.torque_i)) &&
         same_bits(e(a.r.torque_j), e(b.r.torque_j)) && same_bits(e(a.r.ft), e(b.r.ft)) &&
         same_bits(a.r.fn, b.r.fn) && same_bits(e(a.shear), e(b.shear)) && same_bits(e(a.roll), e(b.roll)) &&
         same_bits(a.slip.turn, b.slip.turn) && same_bits(a.slip.t_max, b.slip.t_max) &&
         same_bits(a.slip.kt_prev, b.slip.kt_prev) && same_bits(a.slip.d_max, b.slip.d_max);
}

struct Counts {
  int hot = 0, runtime = 0, slip = 0, stick = 0, apart = 0, wall = 0, tiny_spin = 0, capped = 0, pulled = 0;
  int partial = 0;  ///< mindlin_deresiewicz contacts below the Coulomb limit
};

void check_spec(const ModelSpec& spec, std::mt19937_64& rng, Counts& counts) {
  const double dt = 1e-6;
  for (int trial = 0; trial < 200; ++trial) {
    // four contacts: each the first of a particle or a second contact of the
    // one before (the pair loop's lanes hold contacts of one particle or several)
    Sample s[4];
    s[0] = random_contact(rng, nullptr);
    for (int l = 1; l < 4; ++l)
      s[l] = random_contact(rng, &s[l - 1]);
    Out runtime[4], two_runtime[4], four_runtime[4], two_picked[4], four_picked[4];
    for (int l = 0; l < 4; ++l)
      runtime[l] = one_lane<RuntimeKernel>(spec, s[l], dt);
    lanes<RuntimeKernel, lane::D2>(spec, s, dt, two_runtime);
    lanes<RuntimeKernel, lane::D2>(spec, s + 2, dt, two_runtime + 2);
    lanes<RuntimeKernel, lane::D4>(spec, s, dt, four_runtime);
    dispatch_model(spec, [&](auto kernel) {
      using K = decltype(kernel);
      (K::compiled ? counts.hot : counts.runtime) += 1;
      lanes<K, lane::D2>(spec, s, dt, two_picked);
      lanes<K, lane::D2>(spec, s + 2, dt, two_picked + 2);
      lanes<K, lane::D4>(spec, s, dt, four_picked);
      for (int l = 0; l < 4; ++l) {
        const Out picked_one = one_lane<K>(spec, s[l], dt);
        INFO(model_words(spec) << "; trial " << trial << " lane " << l);
        REQUIRE(same_bits(picked_one, runtime[l]));
      }
    });
    for (int l = 0; l < 4; ++l) {
      INFO(model_words(spec) << "; trial " << trial << " lane " << l << " overlap " << s[l].g.overlap);
      REQUIRE(same_bits(two_runtime[l], runtime[l]));
      REQUIRE(same_bits(two_picked[l], runtime[l]));
      REQUIRE(same_bits(four_runtime[l], runtime[l]));
      REQUIRE(same_bits(four_picked[l], runtime[l]));
      // the branches the comparisons went through
      const Out& o = runtime[l];
      if (!(s[l].g.overlap > 0.0)) {
        ++counts.apart;
        continue;
      }
      counts.wall += s[l].g.r_j == 0.0;
      const double ft = e(o.r.ft).norm();
      if (spec.tangential == TangentialModel::History ||
          spec.tangential == TangentialModel::MindlinDeresiewicz) {
        const double fn_limit = std::abs(o.r.fn);
        if (spec.tangential == TangentialModel::MindlinDeresiewicz && ft < s[l].mat.friction * fn_limit)
          ++counts.partial;
        (ft >= (1.0 - 1e-9) * s[l].mat.friction * fn_limit && fn_limit > 0.0 ? counts.slip : counts.stick) +=
            1;
      }
      if (spec.rolling == RollingModel::Cdt && e(o.r.torque_i - o.r.torque_j).norm() == 0.0)
        ++counts.tiny_spin;
      if (rolling_spring(spec.rolling) && e(o.roll).norm() < e(s[l].roll).norm()) ++counts.capped;
      if (spec.cohesion != CohesionModel::None && o.r.fn < 0.0) ++counts.pulled;
    }
  }
}

}  // namespace

TEST_CASE("Contact formulas: two and four lanes give one lane's bits, compiled kernels the run-time slots'",
          "[contact][lanes]") {
  std::mt19937_64 rng(20261125);
  Counts counts;
  for (int k = 0; k < 400; ++k)
    check_spec(random_spec(rng), rng, counts);
  INFO("hot " << counts.hot << " runtime " << counts.runtime << " slip " << counts.slip << " stick "
              << counts.stick << " apart " << counts.apart << " wall " << counts.wall << " tiny spin "
              << counts.tiny_spin << " capped " << counts.capped << " pulled " << counts.pulled
              << " partial slip " << counts.partial);
  // every branch of the formulas was taken, by both kinds of kernel
  CHECK(counts.hot > 10000);
  CHECK(counts.runtime > 10000);
  CHECK(counts.slip > 1000);
  CHECK(counts.stick > 1000);
  CHECK(counts.partial > 1000);
  CHECK(counts.apart > 1000);
  CHECK(counts.wall > 1000);
  CHECK(counts.tiny_spin > 100);
  CHECK(counts.capped > 100);
  CHECK(counts.pulled > 100);
}

// The masks' reductions (bits, any, all) against a lane-by-lane reading, for
// every pattern of true lanes, from comparisons as the formulas make them.
template <class S>
void check_mask_reductions() {
  constexpr int W = lane::width<S>();
  for (int t = 0; t < (1 << W); ++t) {
    S a = lane::splat<S>(1.0), b = lane::splat<S>(2.0);
    for (int l = 0; l < W; ++l)
      if ((t >> l) & 1) lane::set(a, l, 3.0);  // lane l: a > b
    const lane::Mask<S> m = a > b;
    CAPTURE(W, t);
    CHECK(lane::bits(m) == t);
    CHECK(lane::any(m) == (t != 0));
    CHECK(lane::all(m) == (t == (1 << W) - 1));
    CHECK(lane::bits(lane::mask_and(m, b < a)) == t);
    CHECK(lane::bits(lane::mask_andnot(m, a == a)) == ((1 << W) - 1 - t));
  }
}

TEST_CASE("Mask reductions: bits, any and all of two and four lanes", "[contact][lanes]") {
  check_mask_reductions<lane::D2>();
  check_mask_reductions<lane::D4>();
  CHECK(lane::bits(true) == 1);
  CHECK(lane::bits(false) == 0);
}

// nonnegative_bits() against a lane-by-lane test: every pattern of signs of
// W values (0, 7 and INT32_MAX count as not negative, -1 and INT32_MIN as
// negative), read through indices in another order than the values'.
template <int W>
void check_nonnegative_bits() {
  const std::int32_t nonnegative[3] = {0, 7, INT32_MAX};
  const std::int32_t negative[2] = {-1, INT32_MIN};
  for (int pattern = 0; pattern < (1 << W); ++pattern) {
    std::int32_t a[2 * W];
    int idx[W];
    int expect = 0;
    for (int l = 0; l < W; ++l) {
      const bool nonneg = (pattern >> l) & 1;
      idx[l] = 2 * W - 1 - 2 * l;  // reversed, every other value
      a[idx[l]] = nonneg ? nonnegative[l % 3] : negative[l % 2];
      a[idx[l] - 1] = nonneg ? -1 : 5;  // the neighbours say the opposite
      expect |= static_cast<int>(nonneg) << l;
    }
    INFO("W = " << W << ", pattern " << pattern);
    CHECK(lane::nonnegative_bits<W>(a, idx) == expect);
  }
}

TEST_CASE("nonnegative_bits: the lanes whose indexed values are not negative", "[contact][lanes]") {
  check_nonnegative_bits<1>();
  check_nonnegative_bits<2>();
  check_nonnegative_bits<4>();
}

// compress(): for every pattern of W lanes, the values of the set lanes
// first, in lane order, and their number; differ_bits(): the lanes whose
// 64-bit key differs from the one given.
template <int W>
void check_compress() {
  for (int t = 0; t < (1 << W); ++t) {
    std::int32_t in[W], out[W];
    std::vector<std::int32_t> expect;
    for (int l = 0; l < W; ++l) {
      in[l] = 100 + 7 * l;
      out[l] = -1;
      if ((t >> l) & 1) expect.push_back(in[l]);
    }
    INFO("W = " << W << ", lanes " << t);
    CHECK(lane::compress<W>(in, t, out) == static_cast<int>(expect.size()));
    CHECK(std::vector<std::int32_t>(out, out + expect.size()) == expect);
  }
}

template <class S>
void check_differ_bits() {
  constexpr int W = lane::width<S>();
  const std::int64_t key = 0x123456789abLL;
  for (int t = 0; t < (1 << W); ++t) {
    std::int64_t k[W];
    // differing keys: one bit of the high half, one of the low half, all bits
    const std::int64_t other[3] = {key ^ (std::int64_t{1} << 40), key ^ 8, ~key};
    for (int l = 0; l < W; ++l)
      k[l] = (t >> l) & 1 ? other[l % 3] : key;
    INFO("W = " << W << ", lanes " << t);
    CHECK(lane::differ_bits<S>(k, lane::splat_int<S>(key)) == t);
  }
}

TEST_CASE("compress and differ_bits: the lanes kept, in order, and the keys that differ",
          "[contact][lanes]") {
  check_compress<1>();
  check_compress<2>();
  check_compress<4>();
  check_differ_bits<double>();
  check_differ_bits<lane::D2>();
  check_differ_bits<lane::D4>();
}

TEST_CASE("Only the hot models are compiled kernels", "[contact][lanes]") {
  auto compiled = [](const char* words) {
    std::vector<std::string> w;
    std::string s(words), t;
    for (char c : s + " ") {
      if (c == ' ') {
        if (!t.empty()) w.push_back(t);
        t.clear();
      } else {
        t += c;
      }
    }
    std::size_t pos = 0;
    const ModelSpec spec = parse_model_words(w, pos);
    return dispatch_model(spec, [](auto kernel) { return decltype(kernel)::compiled; });
  };
  CHECK(compiled("model hertz tangential history"));
  CHECK(compiled("model hertz tangential history rolling_friction cdt"));
  CHECK(compiled("model hertz tangential history rolling_friction cdt limitForce on"));
  CHECK(compiled("model hertz tangential history damping viscoelastic tangential_damping off"));
  CHECK_FALSE(compiled("model hertz tangential history rolling_friction epsd2"));
  CHECK_FALSE(compiled("model hertz tangential no_history"));
  CHECK_FALSE(compiled("model hooke tangential history"));
  CHECK_FALSE(compiled("model hertz tangential history cohesion sjkr"));
}
