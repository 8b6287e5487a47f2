#include "fix/fix_insert_pack.h"

#include <cmath>
#include <sstream>
#include <string>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix_particledistribution_discrete.h"
#include "domain/region.h"

namespace granary {

// ============================================================ FixInsertPack

namespace {
const char* kPackUsage =
    "fix ID group insert/pack seed SEED distributiontemplate DIST [maxattempt N] [insert_every once|N] "
    "[start STEP] [overlapcheck yes|no] [all_in yes|no] [random_distribute exact|uncorrelated] "
    "[vel constant VX VY VZ] [omega constant WX WY WZ] [orientation random|template] region REGION "
    "volumefraction_region PHI | particles_in_region N | mass_in_region M [ntry_mc N]";
}  // namespace

FixInsertPack::FixInsertPack(Engine& engine, const Args& args)
    : FixInsert(engine, args,
                {{"volumefraction_region", 1}, {"particles_in_region", 1}, {"mass_in_region", 1}},
                kPackUsage) {
  const std::string what = label();
  int ntargets = 0;
  if (style_values_.count("volumefraction_region")) {
    ++ntargets;
    target_ = Target::VolumeFraction;
    target_value_ = parse_double(style_values_["volumefraction_region"][0], what + " volumefraction_region");
    if (!(target_value_ > 0.0 && target_value_ < 1.0)) {
      throw InputError(what + ": volumefraction_region must lie between 0 and 1");
    }
  }
  if (style_values_.count("particles_in_region")) {
    ++ntargets;
    target_ = Target::Particles;
    const long long n = parse_int(style_values_["particles_in_region"][0], what + " particles_in_region");
    if (n < 1) throw InputError(what + ": particles_in_region must be a positive number");
    target_value_ = static_cast<double>(n);
  }
  if (style_values_.count("mass_in_region")) {
    ++ntargets;
    target_ = Target::Mass;
    target_value_ = parse_double(style_values_["mass_in_region"][0], what + " mass_in_region");
    if (!(target_value_ > 0.0)) throw InputError(what + ": mass_in_region must be positive");
  }
  if (ntargets != 1) {
    throw InputError(what +
                     ": give exactly one of volumefraction_region, particles_in_region and mass_in_region");
  }
}

void FixInsertPack::init() {
  FixInsert::init();
  if (target_ == Target::VolumeFraction && target_value_ > 0.74) {
    engine_.logger->warning(
        label() + ": a volume fraction of " + format_number(target_value_) +
        " cannot be reached by random insertion (random loose packing is below about 0.6)");
  }
}

long long FixInsertPack::count_to_insert() {
  count_in_region(existing_number_, existing_mass_, existing_volume_);
  FixParticleDistributionDiscrete& d = dist();
  long long n = 0;
  switch (target_) {
    case Target::VolumeFraction:
      n = round_stochastic((target_value_ * region_volume_ - existing_volume_) / d.mean_volume());
      break;
    case Target::Particles:
      n = std::max<long long>(0, static_cast<long long>(std::llround(target_value_ - existing_number_)));
      break;
    case Target::Mass:
      n = round_stochastic((target_value_ - existing_mass_) / d.mean_mass());
      break;
  }
  requested_ = n;
  return n;
}

void FixInsertPack::inserted_batch(const Result& r) {
  const double number = existing_number_ + static_cast<double>(r.placed);
  const double mass = existing_mass_ + r.mass;
  const double phi = (existing_volume_ + r.volume) / region_volume_;
  std::string target;
  switch (target_) {
    case Target::VolumeFraction:
      target = "volume fraction " + format_number(target_value_);
      break;
    case Target::Particles:
      target = format_number(target_value_) + " particles";
      break;
    case Target::Mass:
      target = "mass " + format_number(target_value_) + " kg";
      break;
  }
  if (verbose_) {
    std::ostringstream os;
    os << "INFO: " << label() << " inserted " << r.placed << " particles (target " << r.requested
       << ") at step " << engine_.update->ntimestep << "; region " << region_id_ << " now holds " << number
       << " particles, mass " << format_number(mass) << " kg, volume fraction " << format_number(phi)
       << " (target: " << target << ")\n";
    engine_.logger->print(os.str());
  }
  if (r.placed < r.requested) {
    std::ostringstream os;
    os << label() << ": placed only " << r.placed << " of the " << r.requested
       << " particles requested in region " << region_id_ << " (maxattempt " << maxattempt_
       << (all_in_ ? ", all_in yes" : "") << "); the region now holds volume fraction " << format_number(phi)
       << " (target: " << target << "). Enlarge the region, lower the target or raise maxattempt";
    engine_.logger->warning(os.str());
  }
}

GRANARY_FIX_STYLE("insert/pack", FixInsertPack);

}  // namespace granary
