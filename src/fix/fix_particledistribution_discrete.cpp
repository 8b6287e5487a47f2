#include "fix/fix_particledistribution_discrete.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/modify.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group particledistribution/discrete SEED N TEMPLATE1 WEIGHT1 ... TEMPLATEN WEIGHTN "
    "[fractions mass|number|volume]";

double uniform01(std::mt19937_64& gen) {
  return static_cast<double>(gen() >> 11) * 0x1.0p-53;
}

}  // namespace

FixParticleDistributionDiscrete::FixParticleDistributionDiscrete(Engine& engine, const Args& args)
    : Fix(engine, args) {
  const std::string what = "fix " + id + " " + style;
  if (args.size() < 5) throw InputError(std::string("wrong number of arguments; usage: ") + kUsage);
  if (style == "particledistribution/discrete/numberbased") fractions_ = Fractions::Number;
  const long long s = parse_int(args[3], what + " seed");
  if (s <= 0) throw InputError(what + ": the seed must be a positive integer");
  gen_.seed(static_cast<std::uint64_t>(s));
  const long long n = parse_int(args[4], what + " number of templates");
  if (n < 1) throw InputError(what + ": the number of templates must be at least 1");
  if (args.size() < 5 + 2 * static_cast<std::size_t>(n)) {
    throw InputError(what + ": " + std::to_string(n) + " templates need " + std::to_string(n) +
                     " pairs of template ID and weight; usage: " + kUsage);
  }
  for (long long i = 0; i < n; ++i) {
    const std::string& tid = args[5 + 2 * i];
    Fix* f = engine.modify->find_fix(tid);
    if (!f) {
      throw InputError(what + ": unknown particle template '" + tid +
                       "'; define it (fix ID group particletemplate/sphere ...) before the distribution");
    }
    if (!dynamic_cast<FixParticleTemplate*>(f)) {
      throw InputError(what + ": fix " + tid + " (" + f->style + ") is not a particle template");
    }
    if (std::find(template_ids_.begin(), template_ids_.end(), tid) != template_ids_.end()) {
      throw InputError(what + ": template " + tid + " is listed twice");
    }
    const double w = parse_double(args[6 + 2 * i], what + " weight of " + tid);
    if (!(w >= 0.0) || !std::isfinite(w))
      throw InputError(what + ": the weight of " + tid + " must not be negative");
    template_ids_.push_back(tid);
    weights_.push_back(w);
  }
  for (std::size_t k = 5 + 2 * static_cast<std::size_t>(n); k < args.size(); ++k) {
    if (args[k] != "fractions") {
      throw InputError(what + ": unexpected word '" + args[k] + "' after the " + std::to_string(n) +
                       " template/weight pairs; usage: " + kUsage);
    }
    if (k + 1 >= args.size()) throw InputError(what + ": fractions needs mass, number or volume");
    const std::string& m = args[++k];
    Fractions f;
    if (m == "mass")
      f = Fractions::Mass;
    else if (m == "number")
      f = Fractions::Number;
    else if (m == "volume")
      f = Fractions::Volume;
    else
      throw InputError(what + ": fractions must be mass, number or volume, got '" + m + "'");
    if ((style == "particledistribution/discrete/massbased" && f != Fractions::Mass) ||
        (style == "particledistribution/discrete/numberbased" && f != Fractions::Number)) {
      throw InputError(what +
                       ": the style already says what the weights are; use particledistribution/discrete "
                       "with fractions " +
                       m);
    }
    fractions_ = f;
  }
  const double sum = std::accumulate(weights_.begin(), weights_.end(), 0.0);
  if (!(sum > 0.0)) throw InputError(what + ": the weights must not all be zero");
  if (std::fabs(sum - 1.0) > 1e-10) {
    std::ostringstream os;
    os << what << ": the weights sum to " << sum << ", not 1; they are normalised";
    engine.logger->warning(os.str());
  }
  for (double& w : weights_)
    w /= sum;
  restart_global = true;
}

FixParticleTemplate& FixParticleDistributionDiscrete::templ(int i) const {
  Fix* f = engine_.modify->find_fix(template_ids_[i]);
  auto* t = f ? dynamic_cast<FixParticleTemplate*>(f) : nullptr;
  if (!t) {
    throw InputError("fix " + id + " " + style + ": particle template " + template_ids_[i] +
                     " no longer exists (or is no longer a particle template)");
  }
  return *t;
}

void FixParticleDistributionDiscrete::init() {
  for (int i = 0; i < ntemplates(); ++i)
    templ(i);  // every template still exists
}

std::vector<double> FixParticleDistributionDiscrete::number_probabilities() const {
  const int n = ntemplates();
  std::vector<double> p(n);
  for (int i = 0; i < n; ++i) {
    switch (fractions_) {
      case Fractions::Number:
        p[i] = weights_[i];
        break;
      case Fractions::Mass:
        p[i] = weights_[i] / templ(i).mean_mass();
        break;
      case Fractions::Volume:
        p[i] = weights_[i] / templ(i).mean_volume();
        break;
    }
  }
  const double sum = std::accumulate(p.begin(), p.end(), 0.0);
  for (double& v : p)
    v /= sum;
  return p;
}

double FixParticleDistributionDiscrete::mean_volume() const {
  const auto p = number_probabilities();
  double v = 0.0;
  for (int i = 0; i < ntemplates(); ++i)
    v += p[i] * templ(i).mean_volume();
  return v;
}

double FixParticleDistributionDiscrete::mean_mass() const {
  const auto p = number_probabilities();
  double m = 0.0;
  for (int i = 0; i < ntemplates(); ++i)
    m += p[i] * templ(i).mean_mass();
  return m;
}

double FixParticleDistributionDiscrete::max_bounding_radius() const {
  double r = 0.0;
  for (int i = 0; i < ntemplates(); ++i)
    r = std::max(r, templ(i).max_bounding_radius());
  return r;
}

bool FixParticleDistributionDiscrete::any_multisphere() const {
  for (int i = 0; i < ntemplates(); ++i)
    if (templ(i).multisphere()) return true;
  return false;
}

int FixParticleDistributionDiscrete::draw_template() {
  const auto p = number_probabilities();
  const double u = uniform01(gen_);
  double c = 0.0;
  for (int i = 0; i < ntemplates(); ++i) {
    c += p[i];
    if (u < c) return i;
  }
  // round-off at the top end: the last template with a non-zero probability
  for (int i = ntemplates() - 1; i >= 0; --i)
    if (p[i] > 0.0) return i;
  return 0;
}

TemplateParticle FixParticleDistributionDiscrete::draw() {
  return templ(draw_template()).draw();
}

std::vector<FixParticleDistributionDiscrete::Drawn> FixParticleDistributionDiscrete::draw_batch(long long n,
                                                                                                bool exact) {
  std::vector<Drawn> out;
  if (n <= 0) return out;
  out.reserve(static_cast<std::size_t>(n));
  const int nt = ntemplates();
  auto make = [&](int i) {
    FixParticleTemplate& t = templ(i);
    Drawn d;
    d.particle = t.draw();
    d.groupbits = 1 | groupbit | t.groupbit;
    d.template_index = i;
    out.push_back(std::move(d));
  };
  if (!exact) {
    for (long long k = 0; k < n; ++k)
      make(draw_template());
    return out;
  }
  // counts n p_i rounded down; the remaining particles go to templates chosen
  // with probability proportional to the remainders (each at most once)
  const auto p = number_probabilities();
  std::vector<long long> count(nt);
  std::vector<double> rest(nt);
  long long assigned = 0;
  for (int i = 0; i < nt; ++i) {
    const double x = static_cast<double>(n) * p[i];
    count[i] = static_cast<long long>(std::floor(x));
    rest[i] = x - static_cast<double>(count[i]);
    assigned += count[i];
  }
  while (assigned > n) {  // round-off: take back from the largest count
    const int i = static_cast<int>(std::max_element(count.begin(), count.end()) - count.begin());
    --count[i];
    --assigned;
  }
  for (; assigned < n; ++assigned) {
    const double total = std::accumulate(rest.begin(), rest.end(), 0.0);
    int pick = -1;
    if (total > 0.0) {
      const double u = uniform01(gen_) * total;
      double c = 0.0;
      for (int i = 0; i < nt; ++i) {
        if (rest[i] <= 0.0) continue;
        c += rest[i];
        pick = i;
        if (u < c) break;
      }
    }
    if (pick < 0) pick = static_cast<int>(std::max_element(p.begin(), p.end()) - p.begin());
    ++count[pick];
    rest[pick] = 0.0;
  }
  // largest templates first: they are the hardest to place
  std::vector<int> order(nt);
  std::iota(order.begin(), order.end(), 0);
  std::vector<double> rb(nt);
  for (int i = 0; i < nt; ++i)
    rb[i] = templ(i).max_bounding_radius();
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return rb[a] > rb[b]; });
  for (int i : order)
    for (long long k = 0; k < count[i]; ++k)
      make(i);
  return out;
}

void FixParticleDistributionDiscrete::pack_restart(std::string& out) const {
  std::ostringstream os;
  os << gen_;
  out = os.str();
}

void FixParticleDistributionDiscrete::unpack_restart(const std::string& in) {
  std::istringstream is(in);
  std::mt19937_64 g;
  if (is >> g) gen_ = g;
}

GRANARY_FIX_STYLE("particledistribution/discrete", FixParticleDistributionDiscrete);
GRANARY_FIX_STYLE("particledistribution/discrete/massbased", FixParticleDistributionDiscrete);
GRANARY_FIX_STYLE("particledistribution/discrete/numberbased", FixParticleDistributionDiscrete);

}  // namespace granary
