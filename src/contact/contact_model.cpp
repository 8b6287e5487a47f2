// Contact model set-up: parsing of the LIGGGHTS model words, history layout,
// material mixing, and the runtime dispatch onto the templated kernels of
// contact_kernels.h.
#include "contact/contact_model.h"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "contact/contact_kernels.h"

namespace granary::contact {

// ---------------------------------------------------------------------------
// History (layout: history_layout_of in contact_model.h)

int history_size(const ModelSpec& spec) {
  return history_layout(spec).size;
}

void history_swap_signs(const ModelSpec& spec, double* signs) {
  // Both stored vectors are odd under i <-> j: the shear displacement is the
  // integral of the relative contact-point velocity of i with respect to j
  // (mindlin_deresiewicz: the tangential force on i), and the rolling spring
  // torque is the torque on i (j carries its negative). The loading state of
  // mindlin_deresiewicz is measured along the stored force: even.
  const HistoryLayout layout = history_layout(spec);
  for (int h = 0; h < layout.size; ++h)
    signs[h] = -1.0;
  if (layout.slip >= 0) signs[layout.slip] = signs[layout.slip + 1] = signs[layout.slip + 2] = 1.0;
  if (layout.hysteresis >= 0) signs[layout.hysteresis] = 1.0;  // delta_max: the same seen from j
}

// ---------------------------------------------------------------------------
// Parsing

namespace {

[[noreturn]] void fail(const std::string& message) {
  throw std::invalid_argument("contact model: " + message);
}

// Value of a slot or setting: the word after args[pos].
const std::string& value_of(const std::vector<std::string>& args, std::size_t pos) {
  if (pos + 1 >= args.size()) fail("missing value after '" + args[pos] + "'");
  return args[pos + 1];
}

bool on_off(const std::vector<std::string>& args, std::size_t pos) {
  const std::string& v = value_of(args, pos);
  if (v == "on") return true;
  if (v == "off") return false;
  fail("expected 'on' or 'off' after '" + args[pos] + "', got '" + v + "'");
}

// The sub-models of each slot, by the name scripts use. "off" (no sub-model)
// is accepted besides these in the tangential, rolling_friction and cohesion
// slots, "default" (= sphere) in the surface slot.
const std::vector<std::pair<std::string, NormalModel>> kNormalNames = {
    {"hertz", NormalModel::Hertz},
    {"hooke", NormalModel::Hooke},
    {"hertz/stiffness", NormalModel::HertzStiffness},
    {"hooke/stiffness", NormalModel::HookeStiffness},
    {"hooke/hysteresis", NormalModel::HookeHysteresis}};
const std::vector<std::pair<std::string, TangentialModel>> kTangentialNames = {
    {"history", TangentialModel::History},
    {"no_history", TangentialModel::NoHistory},
    {"mindlin_deresiewicz", TangentialModel::MindlinDeresiewicz}};
const std::vector<std::pair<std::string, RollingModel>> kRollingNames = {{"cdt", RollingModel::Cdt},
                                                                         {"epsd", RollingModel::Epsd},
                                                                         {"epsd2", RollingModel::Epsd2},
                                                                         {"epsd3", RollingModel::Epsd3}};
const std::vector<std::pair<std::string, CohesionModel>> kCohesionNames = {
    {"sjkr", CohesionModel::Sjkr},
    {"sjkr2", CohesionModel::Sjkr2},
    {"easo/capillary/viscous", CohesionModel::Easo},
    {"washino/capillary/viscous", CohesionModel::Washino}};
const std::vector<std::pair<std::string, DampingModel>> kDampingNames = {
    {"restitution", DampingModel::Restitution}, {"viscoelastic", DampingModel::Viscoelastic}};
const std::vector<std::pair<std::string, SurfaceModel>> kSurfaceNames = {
    {"sphere", SurfaceModel::Sphere}, {"multicontact", SurfaceModel::Multicontact}};

template <class Enum>
std::vector<std::string> names_of(const std::vector<std::pair<std::string, Enum>>& table) {
  std::vector<std::string> out;
  for (const auto& entry : table)
    out.push_back(entry.first);
  return out;
}

// "a, b, c" (the list printed after "supported: ").
std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names)
    s += (s.empty() ? "" : ", ") + n;
  return s;
}

// LIGGGHTS sub-models that exist there but are not implemented here.
bool is_known_unsupported(const std::string& slot, const std::string& name) {
  static const std::vector<std::pair<std::string, std::string>> known = {{"surface", "superquadric"}};
  for (const auto& k : known)
    if (k.first == slot && k.second == name) return true;
  return false;
}

[[noreturn]] void bad_model(const std::string& slot, const std::string& name, const std::string& supported) {
  if (is_known_unsupported(slot, name))
    fail("'" + slot + " " + name + "' is not supported (supported: " + supported + ")");
  const std::string what = slot == "model" ? "normal" : slot;
  fail("unknown " + what + " model '" + name + "' (supported: " + supported + ")");
}

// The sub-model called `name` in the table of `slot`; with `off` set, "off"
// selects `off_value`.
template <class Enum>
Enum lookup(const std::vector<std::pair<std::string, Enum>>& table, const std::string& slot,
            const std::string& name, const Enum* off_value) {
  for (const auto& entry : table)
    if (entry.first == name) return entry.second;
  if (off_value && name == "off") return *off_value;
  std::vector<std::string> accepted = names_of(table);
  if (off_value) accepted.push_back("off");
  bad_model(slot, name, join(accepted));
}

// Model settings of LIGGGHTS that only switch on bookkeeping or features not
// implemented here: accepted when "off", rejected when "on".
bool is_unsupported_setting(const std::string& w) {
  static const std::vector<std::string> names = {"heating_normal_hertz",
                                                 "heating_normal_hooke",
                                                 "heating_tangential_history",
                                                 "heating_tracking",
                                                 "computeElasticPotential",
                                                 "computeDissipatedEnergy",
                                                 "viscous",
                                                 "disableNormalWhenBonded"};
  for (const auto& n : names)
    if (n == w) return true;
  return false;
}

}  // namespace

ModelSpec parse_model_words(const std::vector<std::string>& args, std::size_t& pos) {
  ModelSpec spec;
  spec.normal = NormalModel::Hertz;         // LIGGGHTS default "model hertz"
  spec.tangential = TangentialModel::None;  // LIGGGHTS default "tangential off"
  spec.rolling = RollingModel::None;        // LIGGGHTS default "rolling_friction off"
  bool seen_model = false, seen_tangential = false, seen_rolling = false;
  bool seen_cohesion = false, seen_surface = false, seen_kt_to_kn = false, seen_damping = false;
  bool seen_reduce = false, seen_absolute = false, seen_lb_volume = false, seen_limit_liquid = false;

  auto once = [](bool& seen, const std::string& word) {
    if (seen) fail("'" + word + "' given twice");
    seen = true;
  };

  while (pos < args.size()) {
    const std::string& w = args[pos];
    if (w == "model") {
      once(seen_model, w);
      spec.normal = lookup<NormalModel>(kNormalNames, w, value_of(args, pos), nullptr);
    } else if (w == "tangential") {
      once(seen_tangential, w);
      const TangentialModel off = TangentialModel::None;
      spec.tangential = lookup(kTangentialNames, w, value_of(args, pos), &off);
    } else if (w == "rolling_friction") {
      once(seen_rolling, w);
      const RollingModel off = RollingModel::None;
      spec.rolling = lookup(kRollingNames, w, value_of(args, pos), &off);
    } else if (w == "cohesion") {
      once(seen_cohesion, w);
      const CohesionModel off = CohesionModel::None;
      spec.cohesion = lookup(kCohesionNames, w, value_of(args, pos), &off);
    } else if (w == "damping") {
      once(seen_damping, w);
      spec.damping = lookup<DampingModel>(kDampingNames, w, value_of(args, pos), nullptr);
    } else if (w == "tangential_reduce") {
      spec.tangential_reduce = on_off(args, pos);
      seen_reduce = true;
    } else if (w == "modifyLbVolume") {
      spec.modify_lb_volume = on_off(args, pos);
      seen_lb_volume = true;
    } else if (w == "limitLiquidContent") {
      if (on_off(args, pos))
        fail(
            "'limitLiquidContent on' (a cap on the liquid content of washino/capillary/viscous) is not "
            "supported; leave it out or give off");
      seen_limit_liquid = true;
    } else if (w == "surface") {
      once(seen_surface, w);
      const std::string& v = value_of(args, pos);
      if (v == "default")
        spec.surface = SurfaceModel::Sphere;
      else
        spec.surface = lookup<SurfaceModel>(kSurfaceNames, w, v, nullptr);
    } else if (w == "limitForce") {
      spec.limit_force = on_off(args, pos);
    } else if (w == "tangential_damping") {
      spec.tangential_damping = on_off(args, pos);
    } else if (w == "ktToKnUser") {
      spec.kt_to_kn_user = on_off(args, pos);
      seen_kt_to_kn = true;
    } else if (w == "absolute_damping") {
      spec.absolute_damping = on_off(args, pos);
      seen_absolute = true;
    } else if (is_unsupported_setting(w)) {
      if (on_off(args, pos)) fail("'" + w + " on' is not supported (only 'off')");
    } else {
      break;  // not a model word: the caller goes on from here
    }
    pos += 2;
  }
  if (seen_kt_to_kn && spec.normal != NormalModel::Hooke && spec.normal != NormalModel::HookeHysteresis)
    fail("'ktToKnUser' applies only to 'model hooke' and 'model hooke/hysteresis'");
  if (seen_absolute && spec.normal != NormalModel::HookeStiffness)
    fail("'absolute_damping' applies only to 'model hooke/stiffness'");
  if (spec.damping == DampingModel::Viscoelastic && spec.normal != NormalModel::Hertz)
    fail("'damping viscoelastic' applies only to 'model hertz'");
  if (seen_reduce && spec.cohesion == CohesionModel::None)
    fail("'tangential_reduce' applies only with a cohesion model ('cohesion sjkr' or 'sjkr2')");
  if (spec.tangential_reduce && liquid_bridge(spec.cohesion))
    fail(
        "'tangential_reduce on' is not supported with the liquid-bridge cohesion models (their force "
        "does not enter the Coulomb limit: LIGGGHTS' default 'off'); leave it out or give off");
  if ((seen_lb_volume || seen_limit_liquid) && spec.cohesion != CohesionModel::Washino)
    fail(std::string("'") + (seen_lb_volume ? "modifyLbVolume" : "limitLiquidContent") +
         "' applies only with 'cohesion washino/capillary/viscous'");
  return spec;
}

std::vector<std::pair<std::string, std::vector<std::string>>> model_names() {
  return {{"model", names_of(kNormalNames)},
          {"tangential", names_of(kTangentialNames)},
          {"rolling_friction", names_of(kRollingNames)},
          {"cohesion", names_of(kCohesionNames)},
          {"surface", names_of(kSurfaceNames)},
          {"damping", names_of(kDampingNames)}};
}

// The script name of `value` in `table`, or `none` when the table has no entry for it.
template <class Enum>
std::string name_of(const std::vector<std::pair<std::string, Enum>>& table, Enum value, const char* none) {
  for (const auto& entry : table)
    if (entry.second == value) return entry.first;
  return none;
}

std::string model_words(const ModelSpec& spec) {
  std::string s = "model " + name_of(kNormalNames, spec.normal, "");
  s += " tangential " + name_of(kTangentialNames, spec.tangential, "off");
  if (spec.rolling != RollingModel::None)
    s += " rolling_friction " + name_of(kRollingNames, spec.rolling, "");
  if (spec.cohesion == CohesionModel::Sjkr) s += " cohesion sjkr";
  if (spec.cohesion == CohesionModel::Sjkr2) s += " cohesion sjkr2";
  if (spec.cohesion == CohesionModel::Easo) s += " cohesion easo/capillary/viscous";
  if (spec.cohesion == CohesionModel::Washino) s += " cohesion washino/capillary/viscous";
  if (spec.modify_lb_volume) s += " modifyLbVolume on";
  if (spec.damping == DampingModel::Viscoelastic) s += " damping viscoelastic";
  if (spec.surface == SurfaceModel::Multicontact) s += " surface multicontact";
  if (spec.limit_force) s += " limitForce on";
  if (spec.tangential_reduce) s += " tangential_reduce on";
  if (!spec.tangential_damping) s += " tangential_damping off";
  if (spec.kt_to_kn_user) s += " ktToKnUser on";
  if (spec.absolute_damping) s += " absolute_damping on";
  return s;
}

// ---------------------------------------------------------------------------
// Materials

PairMaterial mix_materials(double Y_i, double nu_i, double Y_j, double nu_j, double e, double mu, double mu_r,
                           double char_vel) {
  auto check = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("contact material: " + what);
  };
  check(Y_i > 0.0 && Y_j > 0.0, "Young's modulus must be > 0");
  check(nu_i > -1.0 && nu_i <= 0.5 && nu_j > -1.0 && nu_j <= 0.5, "Poisson's ratio must be in (-1, 0.5]");
  check(e > 0.0 && e <= 1.0, "coefficient of restitution must be in (0, 1]");
  check(mu >= 0.0, "coefficient of friction must be >= 0");
  check(mu_r >= 0.0, "coefficient of rolling friction must be >= 0");
  check(char_vel >= 0.0, "characteristic velocity must be >= 0");

  PairMaterial m;
  m.Y_eff = 1.0 / ((1.0 - nu_i * nu_i) / Y_i + (1.0 - nu_j * nu_j) / Y_j);
  m.G_eff = 1.0 / (2.0 * (2.0 - nu_i) * (1.0 + nu_i) / Y_i + 2.0 * (2.0 - nu_j) * (1.0 + nu_j) / Y_j);
  m.restitution = e;
  const double log_e = std::log(e);
  m.beta = log_e / std::sqrt(log_e * log_e + M_PI * M_PI);  // e = 1: log_e = 0, beta = 0
  m.friction = mu;
  m.rolling_friction = mu_r;
  m.char_velocity = char_vel;
  return m;
}

// ---------------------------------------------------------------------------
// Dispatch

KernelFn select_kernel(const ModelSpec& spec) {
  return dispatch_model(spec, [](auto kernel) -> KernelFn { return &evaluate_with<decltype(kernel)>; });
}

void evaluate(const ModelSpec& spec, const ContactState& c, const PairMaterial& m, double* history,
              ContactResult& out) {
  dispatch_model(spec, [&](auto kernel) { evaluate_with<decltype(kernel)>(spec, c, m, history, out); });
}

}  // namespace granary::contact
