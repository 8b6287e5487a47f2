// Tests of the contact model set-up: parsing of the LIGGGHTS model words,
// history layout, material mixing, and the equivalence of the runtime
// dispatch (evaluate, select_kernel) with the templated kernels.
#include <catch2/catch.hpp>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "contact/contact_kernels.h"
#include "contact/contact_model.h"

using namespace granary::contact;

namespace {

std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> out;
  std::size_t p = 0;
  while (p < line.size()) {
    const std::size_t q = line.find(' ', p);
    const std::size_t end = q == std::string::npos ? line.size() : q;
    if (end > p) out.push_back(line.substr(p, end - p));
    p = end + 1;
  }
  return out;
}

ModelSpec parse_all(const std::string& line) {
  const auto args = words(line);
  std::size_t pos = 0;
  const ModelSpec spec = parse_model_words(args, pos);
  REQUIRE(pos == args.size());
  return spec;
}

std::string parse_error(const std::string& line) {
  const auto args = words(line);
  std::size_t pos = 0;
  try {
    parse_model_words(args, pos);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("Model words of LIGGGHTS are parsed", "[contact][parse]") {
  ModelSpec s = parse_all("model hertz tangential history rolling_friction cdt limitForce on");
  CHECK(s.normal == NormalModel::Hertz);
  CHECK(s.tangential == TangentialModel::History);
  CHECK(s.rolling == RollingModel::Cdt);
  CHECK(s.limit_force);
  CHECK(s.tangential_damping);

  s = parse_all(
      "model hooke tangential no_history rolling_friction epsd2 ktToKnUser on "
      "tangential_damping off");
  CHECK(s.normal == NormalModel::Hooke);
  CHECK(s.tangential == TangentialModel::NoHistory);
  CHECK(s.rolling == RollingModel::Epsd2);
  CHECK_FALSE(s.limit_force);
  CHECK(s.kt_to_kn_user);
  CHECK_FALSE(s.tangential_damping);

  // LIGGGHTS defaults: model hertz, tangential off, rolling_friction off.
  s = parse_all("");
  CHECK(s.normal == NormalModel::Hertz);
  CHECK(s.tangential == TangentialModel::None);
  CHECK(s.rolling == RollingModel::None);
  s = parse_all("model hooke");
  CHECK(s.tangential == TangentialModel::None);

  // Slots that only accept their default, and bookkeeping switches set off.
  s = parse_all(
      "model hertz tangential history cohesion off rolling_friction off surface default "
      "heating_normal_hertz off computeElasticPotential off");
  CHECK(s.rolling == RollingModel::None);
}

TEST_CASE("Parsing stops at the first word that is not a model word", "[contact][parse]") {
  // fix wall/gran continues with its own keywords after the model words.
  const auto args = words("wall/gran model hertz tangential history primitive type 1 zplane 0.0");
  std::size_t pos = 1;
  const ModelSpec s = parse_model_words(args, pos);
  CHECK(s.tangential == TangentialModel::History);
  REQUIRE(pos == 5);
  CHECK(args[pos] == "primitive");
}

TEST_CASE("Bad model words give clear errors", "[contact][parse]") {
  CHECK_THAT(parse_error("model hertzz"),
             Catch::Contains("unknown normal model 'hertzz'") && Catch::Contains("hertz, hooke"));
  CHECK_THAT(parse_error("model hertz tangential sticky"),
             Catch::Contains("unknown tangential model 'sticky'"));
  CHECK_THAT(parse_error("model hertz surface superquadric"),
             Catch::Contains("'surface superquadric' is not supported"));
  CHECK_THAT(parse_error("model hertz cohesion easo/capillary/viscous tangential_reduce on"),
             Catch::Contains("'tangential_reduce on' is not supported with the liquid-bridge"));
  CHECK_THAT(parse_error("model hertz cohesion washino/capillary/viscous limitLiquidContent on"),
             Catch::Contains("'limitLiquidContent on'"));
  CHECK_THAT(parse_error("model hertz cohesion sjkr modifyLbVolume on"),
             Catch::Contains("applies only with 'cohesion washino/capillary/viscous'"));
  CHECK_THAT(parse_error("model hooke damping viscoelastic"), Catch::Contains("only to 'model hertz'"));
  CHECK_THAT(parse_error("model hertz tangential"), Catch::Contains("missing value after"));
  CHECK_THAT(parse_error("model hertz limitForce yes"),
             Catch::Contains("expected 'on' or 'off' after 'limitForce'"));
  CHECK_THAT(parse_error("model hertz model hooke"), Catch::Contains("given twice"));
  CHECK_THAT(parse_error("model hertz ktToKnUser on"), Catch::Contains("only to 'model hooke'"));
  CHECK_THAT(parse_error("model hertz heating_normal_hertz on"), Catch::Contains("not supported"));
}

TEST_CASE("model_names lists the sub-models the parser accepts", "[contact][parse]") {
  const auto slots = granary::contact::model_names();
  std::vector<std::string> slot_names;
  for (const auto& slot : slots)
    slot_names.push_back(slot.first);
  CHECK(slot_names == std::vector<std::string>{"model", "tangential", "rolling_friction", "cohesion",
                                               "surface", "damping"});
  for (const auto& [slot, names] : slots) {
    CHECK(!names.empty());
    for (const auto& name : names) {
      INFO(slot << " " << name);
      const auto args = words(slot + " " + name);
      std::size_t pos = 0;
      CHECK_NOTHROW(parse_model_words(args, pos));
      CHECK(pos == 2);
    }
  }
  // Each name selects its own sub-model.
  CHECK(parse_all("tangential no_history").tangential == TangentialModel::NoHistory);
  CHECK(parse_all("rolling_friction epsd2").rolling == RollingModel::Epsd2);
  CHECK(parse_all("model hooke").normal == NormalModel::Hooke);
  // The lists in the messages are the same names ("off" where it is allowed).
  CHECK_THAT(parse_error("model hertz tangential sticky"),
             Catch::Contains("(supported: history, no_history, mindlin_deresiewicz, off)"));
  CHECK_THAT(
      parse_error("model hertz cohesion x"),
      Catch::Contains("(supported: sjkr, sjkr2, easo/capillary/viscous, washino/capillary/viscous, off)"));
  CHECK(parse_all("model hertz surface multicontact").surface == SurfaceModel::Multicontact);
  CHECK(parse_all("model hertz surface default").surface == SurfaceModel::Sphere);
  CHECK_THAT(parse_error("model hertz surface superquadric"),
             Catch::Contains("'surface superquadric' is not supported (supported: sphere, multicontact)"));
}

TEST_CASE("model_words round-trips through the parser", "[contact][parse]") {
  for (NormalModel nm : {NormalModel::Hertz, NormalModel::Hooke, NormalModel::HookeHysteresis}) {
    for (TangentialModel tm : {TangentialModel::None, TangentialModel::NoHistory, TangentialModel::History}) {
      for (RollingModel rm : {RollingModel::None, RollingModel::Cdt, RollingModel::Epsd2, RollingModel::Epsd,
                              RollingModel::Epsd3}) {
        for (int flags = 0; flags < 128; ++flags) {
          ModelSpec s;
          s.normal = nm;
          s.tangential = tm;
          s.rolling = rm;
          s.limit_force = flags & 1;
          s.tangential_damping = flags & 2;
          s.kt_to_kn_user = (flags & 4) && nm == NormalModel::Hooke;
          s.cohesion = (flags & 8) ? CohesionModel::Sjkr : CohesionModel::None;
          s.tangential_reduce = (flags & 16) && s.cohesion == CohesionModel::Sjkr;
          s.damping = (flags & 32) && nm == NormalModel::Hertz ? DampingModel::Viscoelastic
                                                               : DampingModel::Restitution;
          s.surface = (flags & 64) ? SurfaceModel::Multicontact : SurfaceModel::Sphere;
          const ModelSpec t = parse_all(model_words(s));
          CHECK(t.surface == s.surface);
          CHECK(t.cohesion == s.cohesion);
          CHECK(t.tangential_reduce == s.tangential_reduce);
          CHECK(t.damping == s.damping);
          CHECK(t.normal == s.normal);
          CHECK(t.tangential == s.tangential);
          CHECK(t.rolling == s.rolling);
          CHECK(t.limit_force == s.limit_force);
          CHECK(t.tangential_damping == s.tangential_damping);
          CHECK(t.kt_to_kn_user == s.kt_to_kn_user);
        }
      }
    }
  }
  // the liquid bridges and washino's modifyLbVolume
  for (CohesionModel c : {CohesionModel::Easo, CohesionModel::Washino}) {
    for (bool lb : {false, true}) {
      ModelSpec s;
      s.tangential = TangentialModel::History;
      s.cohesion = c;
      s.modify_lb_volume = lb && c == CohesionModel::Washino;
      const ModelSpec t = parse_all(model_words(s));
      CHECK(t.cohesion == c);
      CHECK(t.modify_lb_volume == s.modify_lb_volume);
    }
  }
}

TEST_CASE("History layout and swap signs", "[contact][history]") {
  ModelSpec s;
  s.tangential = TangentialModel::History;
  s.rolling = RollingModel::Epsd2;
  HistoryLayout h = history_layout(s);
  CHECK(h.shear == 0);
  CHECK(h.rolling == 3);
  CHECK(h.size == 6);
  CHECK(history_size(s) == 6);
  double signs[6];
  history_swap_signs(s, signs);
  for (double x : signs)
    CHECK(x == -1.0);

  s.tangential = TangentialModel::NoHistory;
  h = history_layout(s);
  CHECK(h.shear == -1);
  CHECK(h.rolling == 0);
  CHECK(h.size == 3);
  s.rolling = RollingModel::Cdt;
  CHECK(history_size(s) == 0);
  s.tangential = TangentialModel::History;
  CHECK(history_size(s) == 3);
  CHECK(history_layout(s).rolling == -1);
}

TEST_CASE("Material mixing", "[contact][material]") {
  const double y1 = 7e10, n1 = 0.25, y2 = 2e11, n2 = 0.3;
  const PairMaterial m = mix_materials(y1, n1, y2, n2, 0.5, 0.4, 0.05, 2.0);
  CHECK(m.Y_eff == Approx(1.0 / ((1 - n1 * n1) / y1 + (1 - n2 * n2) / y2)).epsilon(1e-14));
  CHECK(m.G_eff ==
        Approx(1.0 / (2 * (2 - n1) * (1 + n1) / y1 + 2 * (2 - n2) * (1 + n2) / y2)).epsilon(1e-14));
  CHECK(m.beta ==
        Approx(std::log(0.5) / std::sqrt(std::log(0.5) * std::log(0.5) + M_PI * M_PI)).epsilon(1e-14));
  CHECK(m.restitution == 0.5);
  CHECK(m.friction == 0.4);
  CHECK(m.rolling_friction == 0.05);
  CHECK(m.char_velocity == 2.0);
  // Symmetric in i and j; e = 1 gives no damping.
  const PairMaterial r = mix_materials(y2, n2, y1, n1, 1.0, 0.4, 0.05, 2.0);
  CHECK(r.Y_eff == Approx(m.Y_eff).epsilon(1e-15));
  CHECK(r.G_eff == Approx(m.G_eff).epsilon(1e-15));
  CHECK(r.beta == 0.0);

  CHECK_THROWS_AS(mix_materials(0.0, 0.3, y2, n2, 0.5, 0.4, 0, 0), std::invalid_argument);
  CHECK_THROWS_AS(mix_materials(y1, 0.6, y2, n2, 0.5, 0.4, 0, 0), std::invalid_argument);
  CHECK_THROWS_AS(mix_materials(y1, n1, y2, n2, 0.0, 0.4, 0, 0), std::invalid_argument);
  CHECK_THROWS_AS(mix_materials(y1, n1, y2, n2, 1.2, 0.4, 0, 0), std::invalid_argument);
  CHECK_THROWS_AS(mix_materials(y1, n1, y2, n2, 0.5, -0.1, 0, 0), std::invalid_argument);
}

TEST_CASE("Runtime dispatch matches the templated kernels", "[contact][dispatch]") {
  PairMaterial mat = mix_materials(5e7, 0.3, 5e7, 0.3, 0.5, 0.3, 0.1, 1.0);
  mat.cohesion_energy_density = 1e4;  // used by the sjkr kernels only
  mat.rolling_stiffness = 1.5;        // epsd, epsd3 only
  mat.rolling_damping = 0.2;          // epsd, epsd3 only
  mat.max_elastic_stiffness = 2.0;    // hooke/hysteresis only
  mat.adhesion_stiffness = 0.2;
  mat.plasticity_depth = 0.05;
  ContactState c;
  c.n = Vec3(0, 0.6, 0.8);
  c.overlap = 1e-5;
  c.r_i = 0.002;
  c.r_j = 0.002;
  c.r_eff = 0.001;
  c.m_eff = 4e-5;
  c.i_roll = rolling_inertia(8e-5, 0.002, 8e-5, 0.002);
  c.v_rel = Vec3(0.1, -0.2, 0.05);
  c.omega_i = Vec3(3, 1, -2);
  c.omega_j = Vec3(-1, 4, 0);
  c.dt = 1e-6;
  for (NormalModel nm : {NormalModel::Hertz, NormalModel::Hooke, NormalModel::HookeHysteresis}) {
    for (TangentialModel tm : {TangentialModel::None, TangentialModel::NoHistory, TangentialModel::History}) {
      for (RollingModel rm : {RollingModel::None, RollingModel::Cdt, RollingModel::Epsd2, RollingModel::Epsd,
                              RollingModel::Epsd3}) {
        for (int flags = 0; flags < 4; ++flags) {
          const bool limit = flags & 1;
          const CohesionModel cm = (flags & 2) ? CohesionModel::Sjkr : CohesionModel::None;
          ModelSpec s;
          s.normal = nm;
          s.tangential = tm;
          s.rolling = rm;
          s.limit_force = limit;
          s.cohesion = cm;
          const int nh = history_size(s);
          std::vector<double> h1(nh, 0.0), h2(nh, 0.0), h3(nh, 0.0);
          ContactResult a, b, d;
          for (int k = 0; k < 3; ++k) {
            evaluate(s, c, mat, h1.data(), a);
            select_kernel(s)(s, c, mat, h2.data(), b);
            dispatch_model(s, [&](auto kernel) {
              using K = decltype(kernel);
              CHECK(K::history_size(s) == nh);
              CHECK(K::normal(s) == nm);
              CHECK(K::tangential(s) == tm);
              CHECK(K::rolling(s) == rm);
              CHECK(K::limit_force(s) == limit);
              CHECK(K::cohesion(s) == cm);
              evaluate_with<K>(s, c, mat, h3.data(), d);
            });
          }
          CHECK(a.force == b.force);
          CHECK(a.force == d.force);
          CHECK(a.torque_i == d.torque_i);
          CHECK(a.torque_j == d.torque_j);
          CHECK(h1 == h2);
          CHECK(h1 == h3);
          CHECK(a.force.norm() > 0.0);
          CHECK((tm == TangentialModel::None) == (a.ft.norm() == 0.0));
          CHECK((rm == RollingModel::None && tm == TangentialModel::None) == (a.torque_i.norm() == 0.0));
        }
      }
    }
  }
  // A template instantiation called directly.
  ModelSpec s;
  std::vector<double> h1(3, 0.0), h2(3, 0.0);
  ContactResult a, b;
  evaluate(s, c, mat, h1.data(), a);
  evaluate_with<Kernel<NormalModel::Hertz, TangentialModel::History, RollingModel::None, false>>(
      s, c, mat, h2.data(), b);
  CHECK(a.force == b.force);
}

TEST_CASE("No overlap gives no force and clears the history", "[contact][dispatch]") {
  const PairMaterial mat = mix_materials(5e7, 0.3, 5e7, 0.3, 0.5, 0.3, 0.1, 1.0);
  ModelSpec s;
  s.rolling = RollingModel::Epsd2;
  ContactState c;
  c.n = Vec3::UnitZ();
  c.overlap = -1e-6;
  c.r_i = 0.002;
  c.r_eff = 0.002;
  c.m_eff = 1e-4;
  c.v_rel = Vec3(1, 0, -1);
  c.omega_i = Vec3(0, 5, 0);
  c.dt = 1e-6;
  std::vector<double> h = {1, 2, 3, 4, 5, 6};
  ContactResult r;
  r.force = Vec3::Ones();
  evaluate(s, c, mat, h.data(), r);
  CHECK(r.force.norm() == 0.0);
  CHECK(r.torque_i.norm() == 0.0);
  CHECK(r.torque_j.norm() == 0.0);
  CHECK(r.fn == 0.0);
  for (double x : h)
    CHECK(x == 0.0);
}
