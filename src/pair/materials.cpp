#include "pair/materials.h"

#include <mpi.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/global_property.h"
#include "core/modify.h"
#include "particles/particles.h"

namespace granary {

void MaterialTable::build(Engine& engine, const contact::ModelSpec& spec, const std::string& user) {
  const Modify& modify = *engine.modify;
  const int n = engine.particles->ntypes;
  stride_ = n + 1;
  table_.assign(static_cast<std::size_t>(stride_) * stride_, contact::PairMaterial{});
  youngs_.assign(stride_, 0.0);
  poisson_.assign(stride_, 0.0);
  // The stiffness models take kn, kt, gamman, gammat as given: Young's
  // modulus and Poisson's ratio are then optional (the Rayleigh time check
  // uses them when they are there), the restitution unused.
  const bool stiffness = contact::stiffness_model(spec.normal);
  const GlobalProperty* Y =
      stiffness ? modify.find_property("youngsModulus") : &modify.require_property("youngsModulus", user);
  const GlobalProperty* nu =
      stiffness ? modify.find_property("poissonsRatio") : &modify.require_property("poissonsRatio", user);
  if (stiffness && (Y == nullptr) != (nu == nullptr)) {
    throw InputError(user +
                     ": youngsModulus and poissonsRatio are optional with the stiffness models but "
                     "must be given together (they set the Rayleigh time check)");
  }
  // With viscoelastic damping the restitution follows from the dissipative
  // time constant; coefficientRestitution is then optional (unused).
  const bool viscoelastic = spec.damping == contact::DampingModel::Viscoelastic;
  const GlobalProperty* e = viscoelastic || stiffness
                                ? modify.find_property("coefficientRestitution")
                                : &modify.require_property("coefficientRestitution", user);
  const GlobalProperty *kn = nullptr, *kt = nullptr, *gn = nullptr, *gt = nullptr;
  if (stiffness) {
    const std::string suffix = spec.absolute_damping ? "_abs" : "";
    kn = &modify.require_property("kn", user);
    kt = &modify.require_property("kt", user);
    gn = &modify.require_property("gamman" + suffix, user);
    gt = &modify.require_property("gammat" + suffix, user);
  }
  const GlobalProperty* coh = nullptr;
  if (spec.cohesion != contact::CohesionModel::None) {
    coh = &modify.require_property("cohesionEnergyDensity", user);
  }
  const GlobalProperty* diss = nullptr;
  if (viscoelastic) diss = &modify.require_property("dissipativeTimeConstant", user);
  const GlobalProperty* mu = nullptr;
  if (spec.tangential != contact::TangentialModel::None) {
    mu = &modify.require_property("coefficientFriction", user);
  }
  const GlobalProperty* mur = nullptr;
  if (spec.rolling != contact::RollingModel::None) {
    mur = &modify.require_property("coefficientRollingFriction", user);
  }
  // epsd, epsd3: the rolling dashpot, and epsd3's prefactor of k_r (LIGGGHTS
  // 3.8 reads it as rollingStiffness; its manual calls it coeffRollingStiffness)
  const GlobalProperty *rdamp = nullptr, *rstiff = nullptr;
  if (contact::rolling_dashpot(spec.rolling)) {
    rdamp = &modify.require_property("coefficientRollingViscousDamping", user);
  }
  if (spec.rolling == contact::RollingModel::Epsd3) {
    rstiff = modify.find_property("coeffRollingStiffness");
    if (!rstiff) rstiff = &modify.require_property("rollingStiffness", user);
    if (rstiff->kind != "scalar") {
      throw InputError(user + ": " + rstiff->name + " (fix " + rstiff->owner_id +
                       ") must be defined as 'scalar VALUE' for rolling_friction epsd3, not " + rstiff->kind);
    }
  }
  // hooke/hysteresis: Luding's k2max / k1, kc / k1 and phi_f
  const GlobalProperty *k2max = nullptr, *kc = nullptr, *phif = nullptr;
  if (spec.normal == contact::NormalModel::HookeHysteresis) {
    k2max = &modify.require_property("coefficientMaxElasticStiffness", user);
    kc = &modify.require_property("coefficientAdhesionStiffness", user);
    phif = &modify.require_property("coefficientPlasticityDepth", user);
  }
  double vchar = 0.0;
  if (spec.normal == contact::NormalModel::Hooke || spec.normal == contact::NormalModel::HookeHysteresis) {
    vchar = modify.require_property("characteristicVelocity", user).scalar();
  }
  // A restart file remembers the materials of the run that wrote it.
  for (const GlobalProperty* prop :
       {Y, nu, e, mu, mur, coh, diss, kn, kt, gn, gt, rdamp, rstiff, k2max, kc, phif}) {
    if (!prop) continue;
    auto it = modify.restart_materials.find(prop->name);
    if (it == modify.restart_materials.end()) continue;
    if (it->second != prop->values) {
      engine.logger->warning("material property " + prop->name + " (fix " + prop->owner_id +
                             ") differs from the one stored in the restart file");
    }
    engine.modify->restart_materials.erase(prop->name);
  }
  for (int a = 1; a <= n; ++a) {
    youngs_[a] = Y ? Y->per_type(a) : 0.0;
    poisson_[a] = nu ? nu->per_type(a) : 0.0;
  }
  for (const GlobalProperty* prop : {e, mu, mur, coh, diss, kn, kt, gn, gt, rdamp, k2max, kc, phif}) {
    if (!prop) continue;
    for (int a = 1; a <= n; ++a)
      for (int b = a + 1; b <= n; ++b)
        if (prop->per_pair(a, b) != prop->per_pair(b, a)) {
          throw InputError(user + ": " + prop->name + " must be symmetric, but the value for types " +
                           std::to_string(a) + "," + std::to_string(b) + " differs from " +
                           std::to_string(b) + "," + std::to_string(a) + " (fix " + prop->owner_id + ")");
        }
  }
  for (int a = 1; a <= n; ++a) {
    for (int b = 1; b <= n; ++b) {
      try {
        contact::PairMaterial& pm = table_[a * stride_ + b];
        if (Y) {
          pm = contact::mix_materials(youngs_[a], poisson_[a], youngs_[b], poisson_[b],
                                      e ? e->per_pair(a, b) : 1.0, mu ? mu->per_pair(a, b) : 0.0,
                                      mur ? mur->per_pair(a, b) : 0.0, vchar);
        } else {
          // a stiffness model without Young's modulus: friction only
          pm = contact::PairMaterial{};
          pm.friction = mu ? mu->per_pair(a, b) : 0.0;
          pm.rolling_friction = mur ? mur->per_pair(a, b) : 0.0;
          if (!(pm.friction >= 0.0)) throw std::invalid_argument("coefficient of friction must be >= 0");
          if (!(pm.rolling_friction >= 0.0))
            throw std::invalid_argument("coefficient of rolling friction must be >= 0");
        }
        if (stiffness) {
          pm.kn = kn->per_pair(a, b);
          pm.kt = kt->per_pair(a, b);
          pm.gamman = gn->per_pair(a, b);
          pm.gammat = gt->per_pair(a, b);
          if (!(pm.kn > 0.0)) throw std::invalid_argument("kn must be > 0");
          if (!(pm.kt >= 0.0)) throw std::invalid_argument("kt must be >= 0");
          if (!(pm.gamman >= 0.0)) throw std::invalid_argument(gn->name + " must be >= 0");
          if (!(pm.gammat >= 0.0)) throw std::invalid_argument(gt->name + " must be >= 0");
        }
        if (coh) {
          pm.cohesion_energy_density = coh->per_pair(a, b);
          if (!(pm.cohesion_energy_density >= 0.0))
            throw std::invalid_argument("cohesionEnergyDensity must be >= 0");
        }
        if (rdamp) {
          pm.rolling_damping = rdamp->per_pair(a, b);
          if (!(pm.rolling_damping >= 0.0))
            throw std::invalid_argument("coefficientRollingViscousDamping must be >= 0");
        }
        if (spec.rolling == contact::RollingModel::Epsd) pm.rolling_stiffness = 2.25;
        if (k2max) {
          pm.max_elastic_stiffness = k2max->per_pair(a, b);
          pm.adhesion_stiffness = kc->per_pair(a, b);
          pm.plasticity_depth = phif->per_pair(a, b);
          if (!(pm.max_elastic_stiffness > 1.0))
            throw std::invalid_argument(
                "coefficientMaxElasticStiffness must be > 1 (k2max / k1: unloading is stiffer than loading)");
          if (!(pm.adhesion_stiffness >= 0.0))
            throw std::invalid_argument("coefficientAdhesionStiffness must be >= 0");
          if (!(pm.plasticity_depth > 0.0))
            throw std::invalid_argument("coefficientPlasticityDepth must be > 0");
        }
        if (rstiff) {
          pm.rolling_stiffness = rstiff->scalar();
          if (!(pm.rolling_stiffness >= 0.0)) throw std::invalid_argument(rstiff->name + " must be >= 0");
        }
        if (diss) {
          pm.dissipative_time = diss->per_pair(a, b);
          if (!(pm.dissipative_time >= 0.0))
            throw std::invalid_argument("dissipativeTimeConstant must be >= 0");
        }
      } catch (const std::invalid_argument& ex) {
        throw InputError(user + ": material of types " + std::to_string(a) + " and " + std::to_string(b) +
                         ": " + ex.what());
      }
    }
  }
}

ContactTimes contact_times(Engine& engine, const MaterialTable& materials, const contact::ModelSpec& spec,
                           double vmax, int groupbit) {
  const Particles& p = *engine.particles;
  const bool hooke_stiffness = spec.normal == contact::NormalModel::HookeStiffness;
  const bool hertz_stiffness = spec.normal == contact::NormalModel::HertzStiffness;
  // Hertz time is smallest where q = m^2 / (r Y*^2) is: one power at the end;
  // the linear spring's contact time where m / kn is
  double local[3] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                     std::numeric_limits<double>::max()};
  for (int i = 0; i < p.nlocal; ++i) {
    const int t = p.type[i];
    if (t < 1 || t > materials.ntypes()) continue;
    const double Y = materials.youngs(t), nu = materials.poisson(t);
    const double r = p.radius[i], m = p.rmass[i];
    if (Y > 0.0) {
      const double G = Y / (2.0 * (1.0 + nu));
      local[0] = std::min(local[0], M_PI * r * std::sqrt(p.density[i] / G) / (0.1631 * nu + 0.8766));
    }
    if (!(p.mask[i] & groupbit)) continue;
    if (hooke_stiffness) {
      local[2] = std::min(local[2], m / materials(t, t).kn);
    } else {
      // hertz/stiffness: F = kn sqrt(R*) delta^(3/2), Hertz with Y* = 3 kn / 4
      const double y_eff = hertz_stiffness ? 0.75 * materials(t, t).kn : materials(t, t).Y_eff;
      if (y_eff > 0.0) local[1] = std::min(local[1], m * m / (r * y_eff * y_eff));
    }
  }
  double all[3];
  MPI_Allreduce(local, all, 3, MPI_DOUBLE, MPI_MIN, engine.world);
  ContactTimes times;
  if (all[0] < std::numeric_limits<double>::max()) times.rayleigh = all[0];
  if (vmax > 0 && all[1] < std::numeric_limits<double>::max())
    times.hertz = 2.87 * std::pow(all[1] / vmax, 0.2);
  // two equal particles: m* = m/2, half a period of the undamped spring
  if (all[2] < std::numeric_limits<double>::max()) times.spring = M_PI * std::sqrt(0.5 * all[2]);
  return times;
}

}  // namespace granary
