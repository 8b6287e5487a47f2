// Contact model description and the public entry points of the contact physics:
// which sub-models a pair style or wall uses (ModelSpec), the mixed material
// parameters of a pair of types (PairMaterial), the geometric and kinematic
// state of one contact (ContactState) and its result (ContactResult).
//
// Everything here is SI in, SI out and stateless: the per-contact history
// (tangential displacement, rolling spring torque) is owned by the caller and
// passed in as a plain array of doubles. The templated kernels behind
// evaluate() live in contact_kernels.h; the formulas are documented in
// doc/contact_models.md.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products of Vec3
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace granary::contact {

using Vec3 = Eigen::Vector3d;

/// Normal force law ("model hertz" / "model hooke", the stiffness forms
/// "model hertz/stiffness" / "model hooke/stiffness", whose spring and dashpot
/// coefficients are given directly as kn, kt, gamman, gammat, and "model
/// hooke/hysteresis": Luding's elastic-plastic spring with adhesion on the
/// stiffness of model hooke).
enum class NormalModel { Hertz, Hooke, HertzStiffness, HookeStiffness, HookeHysteresis };
/// Tangential force law: "tangential off", "tangential no_history",
/// "tangential history" (Hertz-Mindlin without micro-slip: the elastic spring
/// kt times the accumulated displacement, capped by Coulomb), and
/// "tangential mindlin_deresiewicz" (partial slip: the tangent stiffness falls
/// as the force nears the Coulomb limit and after every reversal of the
/// loading, so small tangential oscillations lose energy; Granary only).
enum class TangentialModel { None, NoHistory, History, MindlinDeresiewicz };
/// Rolling resistance: "rolling_friction off", "rolling_friction cdt", and the
/// elastic-plastic springs "rolling_friction epsd2" (stiffness kt R*^2, no
/// dashpot), "rolling_friction epsd" (stiffness 2.25 kn mu_r^2 R*^2 and a
/// rolling dashpot) and "rolling_friction epsd3" (epsd with the prefactor
/// rollingStiffness instead of 2.25).
enum class RollingModel { None, Cdt, Epsd2, Epsd, Epsd3 };
/// Whether the rolling model keeps a spring torque in the history.
constexpr bool rolling_spring(RollingModel r) {
  return r == RollingModel::Epsd2 || r == RollingModel::Epsd || r == RollingModel::Epsd3;
}
/// Whether the rolling model has the dashpot of epsd (and needs I_r).
constexpr bool rolling_dashpot(RollingModel r) {
  return r == RollingModel::Epsd || r == RollingModel::Epsd3;
}
/// Cohesion: "cohesion off", "cohesion sjkr" (simplified JKR, F = k * contact
/// area, the area of the circle where the spheres intersect), "cohesion sjkr2"
/// (the same with the area 2 pi delta 2R*), and the liquid bridges
/// "cohesion easo/capillary/viscous" and "cohesion washino/capillary/viscous"
/// (pair_style gran only: a capillary and a viscous force between spheres that
/// touch or nearly touch, computed by pair/liquid_bridge.h, not by the kernels).
enum class CohesionModel { None, Sjkr, Sjkr2, Easo, Washino };
/// Whether the cohesion model is a liquid bridge (acts beyond contact; not in the kernels).
constexpr bool liquid_bridge(CohesionModel c) {
  return c == CohesionModel::Easo || c == CohesionModel::Washino;
}
/// Normal (and tangential) damping of the Hertz model: "damping restitution"
/// (LIGGGHTS' constant coefficient of restitution, the default) or
/// "damping viscoelastic" (Brilliantov et al. 1996: dashpot proportional to the
/// contact stiffness, restitution falls with impact speed).
enum class DampingModel { Restitution, Viscoelastic };
/// Surface model: "surface default" (= sphere) or "surface multicontact"
/// (Brodu et al. 2015: each contact's overlap grows or shrinks by the
/// deformation that the particle's other contacts cause, computed by fix
/// multicontact/halfspace; the contact law itself is unchanged).
enum class SurfaceModel { Sphere, Multicontact };

/// Which sub-model fills each slot, plus the model switches of the input syntax.
struct ModelSpec {
  NormalModel normal = NormalModel::Hertz;
  TangentialModel tangential = TangentialModel::History;
  RollingModel rolling = RollingModel::None;
  CohesionModel cohesion = CohesionModel::None;
  /// Read at run time inside the normal sub-model (not a template parameter).
  DampingModel damping = DampingModel::Restitution;
  /// Read by the contact loops (pair and walls), not by the kernels.
  SurfaceModel surface = SurfaceModel::Sphere;
  /// Cohesion: the Coulomb and epsd2 limits see the cohesive pull as well
  /// ("tangential_reduce on"); default off: they see the contact force only.
  bool tangential_reduce = false;
  /// washino/capillary/viscous: the bridge volume is lbVolumeFraction (fix
  /// property/global) times the liquid of both spheres ("modifyLbVolume on");
  /// default off: 0.05 times it.
  bool modify_lb_volume = false;
  /// Forbid attraction: the total normal force is clamped at >= 0 ("limitForce on").
  bool limit_force = false;
  /// Viscous damping of the tangential force ("tangential_damping", default on).
  bool tangential_damping = true;
  /// Hooke only: kt = 2/7 kn instead of kt = kn ("ktToKnUser on").
  bool kt_to_kn_user = false;
  /// hooke/stiffness only: the dashpots are gamman_abs, gammat_abs as given
  /// instead of gamman m*, gammat m* ("absolute_damping on").
  bool absolute_damping = false;
};

/// Whether the normal model takes its coefficients from kn, kt, gamman, gammat.
inline bool stiffness_model(NormalModel n) {
  return n == NormalModel::HertzStiffness || n == NormalModel::HookeStiffness;
}

/// Number of history doubles per contact this model needs (tangential history:
/// 3 for the shear displacement; mindlin_deresiewicz: 3 for the elastic
/// tangential force and 3 for its loading state; epsd2: 3 for the spring torque).
int history_size(const ModelSpec&);

/// Where each sub-model keeps its values inside one contact's history array
/// (-1 when that sub-model stores nothing).
struct HistoryLayout {
  /// tangential history: the displacement vector [m]; mindlin_deresiewicz:
  /// the elastic tangential force on i [N]; 3 doubles
  int shear = -1;
  /// mindlin_deresiewicz: the force at the last reversal of the loading,
  /// signed along the stored force [N], the largest force reached on the
  /// virgin curve [N], and the stiffness kt of the last step [N/m]; 3 doubles
  int slip = -1;
  int rolling = -1;     ///< epsd2, epsd, epsd3: rolling spring torque acting on i [N m], 3 doubles
  int hysteresis = -1;  ///< hooke/hysteresis: the plastic state delta_max [m], 1 double
  int size = 0;         ///< total number of doubles (== history_size)
};
/// The layout for a normal, a tangential and a rolling sub-model: [shear
/// x,y,z if tangential history or mindlin_deresiewicz][reversal force, last
/// kt if mindlin_deresiewicz][rolling torque x,y,z if epsd2, epsd,
/// epsd3][delta_max if hooke/hysteresis]. The one definition, used by
/// history_layout() and by the kernels (compile-time for the compiled ones).
constexpr HistoryLayout history_layout_of(NormalModel nm, TangentialModel t, RollingModel r) {
  HistoryLayout layout;
  if (t == TangentialModel::History || t == TangentialModel::MindlinDeresiewicz) {
    layout.shear = layout.size;
    layout.size += 3;
  }
  if (t == TangentialModel::MindlinDeresiewicz) {
    layout.slip = layout.size;
    layout.size += 3;
  }
  if (rolling_spring(r)) {
    layout.rolling = layout.size;
    layout.size += 3;
  }
  if (nm == NormalModel::HookeHysteresis) {
    layout.hysteresis = layout.size;
    layout.size += 1;
  }
  return layout;
}
inline HistoryLayout history_layout(const ModelSpec& spec) {
  return history_layout_of(spec.normal, spec.tangential, spec.rolling);
}

/// Sign applied to each history value when the roles of i and j are swapped
/// (-1 for the shear displacement or force and the rolling torque, +1 for the
/// mindlin_deresiewicz loading state, which is measured along the stored
/// force and so turns with it), used when history
/// stored for (i,j) is looked up as (j,i). `signs` has history_size() entries.
void history_swap_signs(const ModelSpec&, double* signs);

/// Parse LIGGGHTS contact-model words starting at args[pos], e.g.
///   model hertz tangential history rolling_friction cdt limitForce on
/// Recognised slots: model, tangential, cohesion (off, sjkr), rolling_friction,
/// surface (default/sphere, multicontact), damping (restitution, viscoelastic; hertz
/// only); settings: limitForce, tangential_damping, tangential_reduce (sjkr),
/// ktToKnUser (hooke), and the LIGGGHTS bookkeeping switches (accepted as "off").
/// Slots that are not given take the LIGGGHTS defaults: model hertz,
/// tangential off, rolling_friction off.
/// Parsing stops at the first word that is neither a slot nor a model setting
/// (e.g. "primitive" of fix wall/gran); pos is left on that word and the caller
/// decides whether it is valid there (pair_style gran: pos must reach the end).
/// Throws std::invalid_argument with a clear message on an unknown or
/// unsupported model name, a missing or invalid value, or a repeated slot.
ModelSpec parse_model_words(const std::vector<std::string>& args, std::size_t& pos);

/// The sub-model names parse_model_words accepts, per slot: "model",
/// "tangential", "rolling_friction", "cohesion", "surface", "damping" (the
/// words "off" and "default", which select no sub-model or the default one,
/// are not listed).
std::vector<std::pair<std::string, std::vector<std::string>>> model_names();

/// The LIGGGHTS words that describe `spec` (round-trips through parse_model_words).
std::string model_words(const ModelSpec& spec);

/// Mixed material parameters of one pair of atom types (or an atom type and a wall type).
struct PairMaterial {
  double Y_eff = 0.0;             ///< Y* = 1/((1-nu_i^2)/Y_i + (1-nu_j^2)/Y_j) [Pa]
  double G_eff = 0.0;             ///< G* = 1/(2(2-nu_i)(1+nu_i)/Y_i + 2(2-nu_j)(1+nu_j)/Y_j) [Pa]
  double restitution = 1.0;       ///< e
  double beta = 0.0;              ///< ln(e)/sqrt(ln(e)^2 + pi^2) (e = 1 gives 0)
  double friction = 0.0;          ///< Coulomb mu
  double rolling_friction = 0.0;  ///< mu_r
  /// epsd, epsd3: coefficientRollingViscousDamping eta_r (the rolling dashpot
  /// is eta_r times its critical value)
  double rolling_damping = 0.0;
  /// epsd: 2.25; epsd3: rollingStiffness; k_r = this kn mu_r^2 R*^2
  double rolling_stiffness = 0.0;
  /// hooke/hysteresis: coefficientMaxElasticStiffness (k2max / k1, > 1),
  /// coefficientAdhesionStiffness (kc / k1, >= 0), coefficientPlasticityDepth (phi_f, > 0)
  double max_elastic_stiffness = 0.0, adhesion_stiffness = 0.0, plasticity_depth = 0.0;
  double char_velocity = 0.0;  ///< Hooke only: characteristicVelocity [m/s]
  /// cohesion sjkr: cohesionEnergyDensity k [J/m^3]; the cohesive pull is k * contact area
  double cohesion_energy_density = 0.0;
  /// damping viscoelastic: dissipativeTimeConstant A [s] of Brilliantov et al. (1996)
  double dissipative_time = 0.0;
  /// hooke/stiffness, hertz/stiffness: the property/global values kn, kt,
  /// gamman, gammat (or gamman_abs, gammat_abs with absolute_damping on)
  double kn = 0.0, kt = 0.0, gamman = 0.0, gammat = 0.0;
};

/// Mix the properties of type i and type j. Throws std::invalid_argument for
/// Y <= 0, nu outside (-1, 0.5], e outside (0, 1], or negative mu, mu_r, char_vel.
PairMaterial mix_materials(double Y_i, double nu_i, double Y_j, double nu_j, double e, double mu, double mu_r,
                           double char_vel);

/// Geometric and kinematic state of one contact, SI units.
struct ContactState {
  Vec3 n = Vec3::Zero();        ///< unit normal pointing from j to i
  double overlap = 0.0;         ///< delta = r_i + r_j - |x_i - x_j| (> 0 in contact) [m]
  double r_i = 0.0, r_j = 0.0;  ///< radii; r_j = 0 means j is a wall (flat, infinite radius)
  double r_eff = 0.0;           ///< R* = r_i r_j/(r_i+r_j), or r_i for a wall
  double m_eff = 0.0;           ///< m* = m_i m_j/(m_i+m_j), or m_i for a wall
  /// epsd, epsd3 only: the rolling inertia I_r (rolling_inertia()) [kg m^2]
  double i_roll = 0.0;
  Vec3 v_rel = Vec3::Zero();    ///< v_i - v_j (centre velocities; wall: its velocity at the contact)
  Vec3 omega_i = Vec3::Zero();  ///< spin of i [rad/s]
  Vec3 omega_j = Vec3::Zero();  ///< spin of j (0 for a wall)
  double dt = 0.0;              ///< timestep, for history integration [s]
};

/// What one contact does to i and j.
struct ContactResult {
  Vec3 force = Vec3::Zero();     ///< total force on i (j receives -force)
  Vec3 torque_i = Vec3::Zero();  ///< torque on i about its centre
  Vec3 torque_j = Vec3::Zero();  ///< torque on j about its centre
  double fn = 0.0;         ///< signed normal force (elastic + damping, after limit_force, minus cohesion)
  Vec3 ft = Vec3::Zero();  ///< tangential part of `force` (0 without a tangential model)
};

/// How far a contact's history advances in one force evaluation [s]: the
/// tangential history by `tangential`, the rolling spring (epsd2, epsd, epsd3)
/// by `rolling`. Both are the timestep during a run. The force evaluation of a
/// run's setup advances neither history (what it writes is put back), but its
/// rolling torque is that of a spring advanced by one step, as in LIGGGHTS 3.8
/// (measured): there `tangential` is 0 and `rolling` the timestep.
struct HistoryDt {
  double tangential = 0.0, rolling = 0.0;
};

/// The rolling inertia of epsd and epsd3 for two solid spheres (I = 2/5 m r^2):
/// I_r = 1 / (1/(I_i + m_i r_i^2) + 1/(I_j + m_j r_j^2)); m_j = 0: a wall
/// (I_r = I_i + m_i r_i^2).
inline double rolling_inertia(double m_i, double r_i, double m_j, double r_j) {
  const double a = 1.4 * m_i * r_i * r_i;
  if (!(m_j > 0.0)) return a;
  const double b = 1.4 * m_j * r_j * r_j;
  return a * b / (a + b);
}

/// Evaluate one contact. `history` points to history_size(spec) doubles owned by
/// the caller (zero at first touch); it is updated in place. A state with
/// overlap <= 0 yields a zero result and zeroes the history.
void evaluate(const ModelSpec&, const ContactState&, const PairMaterial&, double* history, ContactResult&);

/// Signature of one compiled kernel (see contact_kernels.h).
using KernelFn = void (*)(const ModelSpec&, const ContactState&, const PairMaterial&, double*,
                          ContactResult&);
/// The compiled kernel for `spec`; resolve once per run and call it per contact
/// to skip the dispatch. Equivalent to evaluate().
KernelFn select_kernel(const ModelSpec& spec);

}  // namespace granary::contact
