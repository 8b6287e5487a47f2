#include "fix/fix_insert_rate_region.h"

#include <cmath>
#include <sstream>
#include <utility>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix_particledistribution_discrete.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group insert/rate/region seed SEED distributiontemplate DIST nparticles N|INF | mass M|INF "
    "particlerate R | massrate MR insert_every STEPS [maxattempt N] [start STEP] [overlapcheck yes|no] "
    "[all_in yes|no] [random_distribute exact|uncorrelated] [vel constant VX VY VZ] [omega constant WX WY "
    "WZ] "
    "[orientation random|template] region REGION [ntry_mc N]";

}  // namespace

FixInsertRateRegion::FixInsertRateRegion(Engine& engine, const Args& args)
    : FixInsertRateRegion(engine, args, {}, kUsage, false) {}

namespace {
std::map<std::string, int> with_rate_keywords(std::map<std::string, int> k) {
  k.insert({{"nparticles", 1}, {"mass", 1}, {"particlerate", 1}, {"massrate", 1}});
  return k;
}
}  // namespace

FixInsertRateRegion::FixInsertRateRegion(Engine& engine, const Args& args,
                                         std::map<std::string, int> style_keywords, const std::string& usage,
                                         bool stream)
    : FixInsert(engine, args, with_rate_keywords(std::move(style_keywords)), usage, !stream) {
  const std::string what = label();
  const bool has_n = style_values_.count("nparticles") > 0, has_m = style_values_.count("mass") > 0;
  if (has_n == has_m) throw InputError(what + ": give exactly one of nparticles and mass; usage: " + usage);
  by_mass_ = has_m;
  const std::string& amount = style_values_[has_m ? "mass" : "nparticles"][0];
  if (amount == "INF") {
    target_value_ = -1.0;
  } else if (has_m) {
    target_value_ = parse_double(amount, what + " mass");
    if (!(target_value_ > 0.0)) throw InputError(what + ": mass must be positive (or INF)");
  } else {
    const long long n = parse_int(amount, what + " nparticles");
    if (n < 1) throw InputError(what + ": nparticles must be positive (or INF)");
    target_value_ = static_cast<double>(n);
    target_n_ = n;
  }
  const bool has_pr = style_values_.count("particlerate") > 0, has_mr = style_values_.count("massrate") > 0;
  if (has_pr == has_mr)
    throw InputError(what + ": give exactly one of particlerate and massrate; usage: " + usage);
  rate_by_mass_ = has_mr;
  rate_ = parse_double(style_values_[has_mr ? "massrate" : "particlerate"][0],
                       what + (has_mr ? " massrate" : " particlerate"));
  if (!(rate_ > 0.0)) throw InputError(what + ": the insertion rate must be positive");
  for (std::size_t k = 3; k + 1 < args.size(); ++k)
    insert_every_given_ |= args[k] == "insert_every";
  if (stream) return;
  if (!insert_every_given_ || insert_every_ == 0) {
    throw InputError(what + ": insert_every STEPS (a positive number of steps between batches) is required");
  }
}

void FixInsertRateRegion::init() {
  FixInsert::init();
  // the number to insert for a mass target: the distribution's expected particle mass
  if (by_mass_ && target_value_ > 0.0 && target_n_ < 0) {
    target_n_ = std::max<long long>(1, std::llround(target_value_ / dist().mean_mass()));
  }
}

long long FixInsertRateRegion::count_to_insert() {
  const double per_second = rate_by_mass_ ? rate_ / dist().mean_mass() : rate_;
  const double x = per_second * engine_.update->dt * insert_every_ + carry_;
  long long n = static_cast<long long>(std::floor(x));
  carry_ = x - static_cast<double>(n);
  if (target_n_ >= 0) n = std::min(n, target_n_ - ninserted_);
  return std::max<long long>(n, 0);
}

void FixInsertRateRegion::inserted_batch(const Result& r) {
  if (verbose_ && r.requested > 0) {
    std::ostringstream os;
    os << "INFO: " << label() << " inserted " << r.placed << " particles (target " << r.requested
       << ") at step " << engine_.update->ntimestep << "; " << ninserted_ << " so far";
    if (target_n_ >= 0) os << " of " << target_n_;
    os << ", mass " << mass_inserted_ << " kg\n";
    engine_.logger->print(os.str());
  }
  if (r.placed < r.requested) {
    std::ostringstream os;
    os << label() << ": placed only " << r.placed << " of the " << r.requested
       << " particles of this batch in region " << region_id_ << " (maxattempt " << maxattempt_ << "); "
       << (target_n_ >= 0 ? "the rest follow after the last regular batch" : "they are skipped")
       << ". Enlarge the region, lower the rate or raise maxattempt";
    engine_.logger->warning(os.str());
  }
}

void FixInsertRateRegion::pack_restart(std::string& out) const {
  std::string base;
  FixInsert::pack_restart(base);
  std::ostringstream os;
  os.precision(17);
  os << carry_ << ' ' << target_n_ << ' ' << base;
  out = os.str();
}

void FixInsertRateRegion::unpack_restart(const std::string& in) {
  std::istringstream is(in);
  double carry = 0.0;
  long long target = -1;
  if (!(is >> carry >> target)) return;
  std::string rest;
  std::getline(is, rest, '\0');
  carry_ = carry;
  target_n_ = target;
  FixInsert::unpack_restart(rest);
}

GRANARY_FIX_STYLE("insert/rate/region", FixInsertRateRegion);

}  // namespace granary
