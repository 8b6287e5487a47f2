#include "fix/fix_particletemplate_sphere.h"

#include <cmath>
#include <sstream>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group particletemplate/sphere SEED [atom_type T] [density constant RHO] "
    "[radius constant R | radius uniform LO HI] [volume_limit V] [relative no]";

double uniform01(std::mt19937_64& gen) {
  return static_cast<double>(gen() >> 11) * 0x1.0p-53;
}

}  // namespace

FixParticleTemplateSphere::FixParticleTemplateSphere(Engine& engine, const Args& args)
    : FixParticleTemplate(engine, args) {
  if (args.size() < 4) throw InputError(std::string("wrong number of arguments; usage: ") + kUsage);
  const std::string what = "fix " + id + " particletemplate/sphere";
  seed = parse_seed(what);
  gen_.seed(static_cast<std::uint64_t>(seed));
  restart_global = true;
  for (std::size_t k = 4; k < args.size(); ++k) {
    if (parse_common_keyword(k, what, density_)) continue;
    const std::string& w = args[k];
    auto value = [&](const char* name) -> const std::string& {
      if (k + 1 >= args.size()) throw InputError(what + ": keyword '" + w + "' needs " + name);
      return args[++k];
    };
    if (w == "radius") {
      const std::string& style = value("a style (constant or uniform)");
      if (style == "constant") {
        radius_ = parse_double(value("a value"), what + " radius");
        if (!(radius_ > 0.0)) throw InputError(what + ": the radius must be positive");
        uniform_ = false;
      } else if (style == "uniform") {
        radius_lo_ = parse_double(value("LO and HI"), what + " radius uniform LO");
        radius_hi_ = parse_double(value("HI"), what + " radius uniform HI");
        if (!(radius_lo_ > 0.0) || !(radius_hi_ >= radius_lo_)) {
          throw InputError(what + ": radius uniform needs 0 < LO <= HI");
        }
        uniform_ = true;
      } else {
        const std::string hint = did_you_mean(style, {"constant", "uniform"});
        throw InputError(what + ": unknown radius style '" + style + "'" + (hint.empty() ? "" : "; " + hint) +
                         "; use 'constant R' or 'uniform LO HI'");
      }
    } else if (w == "volume_limit") {
      volume_limit_ = parse_double(value("a value"), what + " volume_limit");
      if (!(volume_limit_ >= 0.0)) throw InputError(what + ": volume_limit must not be negative");
    } else if (w == "relative") {
      if (parse_bool(value("yes or no"), what + " relative")) {
        throw InputError(what + ": relative yes (radii relative to a reference radius) is not supported");
      }
    } else {
      const std::string hint =
          did_you_mean(w, {"atom_type", "density", "radius", "volume_limit", "relative"});
      throw InputError(what + ": unknown keyword '" + w + "'" + (hint.empty() ? "" : "; " + hint) +
                       "; usage: " + kUsage);
    }
  }
  const double rmin = uniform_ ? radius_lo_ : radius_;
  if (4.0 / 3.0 * M_PI * rmin * rmin * rmin < volume_limit_) {
    throw InputError(what + ": the particle volume " + format_number(4.0 / 3.0 * M_PI * rmin * rmin * rmin) +
                     " is below volume_limit " + format_number(volume_limit_) +
                     " (check the units: radii are in m), or lower volume_limit");
  }
}

void FixParticleTemplateSphere::init() {
  if (atom_type > engine_.particles->ntypes) {
    throw InputError("fix " + id + " particletemplate/sphere: atom_type " + std::to_string(atom_type) +
                     " is outside 1.." + std::to_string(engine_.particles->ntypes) +
                     " (the number of atom types given to create_box)");
  }
}

TemplateParticle FixParticleTemplateSphere::sphere(int type, double r, double rho) {
  TemplateParticle t;
  t.type = type;
  t.density = rho;
  t.offsets = {Vec3(0, 0, 0)};
  t.radii = {r};
  t.volume = 4.0 / 3.0 * M_PI * r * r * r;
  t.mass = rho * t.volume;
  const double moment = 0.4 * t.mass * r * r;
  t.inertia = Vec3(moment, moment, moment);
  t.bounding_radius = r;
  t.multisphere = false;
  return t;
}

TemplateParticle FixParticleTemplateSphere::draw() {
  double r = radius_;
  if (uniform_) r = radius_lo_ + uniform01(gen_) * (radius_hi_ - radius_lo_);
  return sphere(atom_type, r, density_);
}

double FixParticleTemplateSphere::mean_volume() const {
  if (!uniform_) return 4.0 / 3.0 * M_PI * radius_ * radius_ * radius_;
  if (radius_hi_ == radius_lo_) return 4.0 / 3.0 * M_PI * radius_lo_ * radius_lo_ * radius_lo_;
  // mean of r^3 for r uniform in [lo, hi]
  const double r3 = (std::pow(radius_hi_, 4) - std::pow(radius_lo_, 4)) / (4.0 * (radius_hi_ - radius_lo_));
  return 4.0 / 3.0 * M_PI * r3;
}

void FixParticleTemplateSphere::pack_restart(std::string& out) const {
  std::ostringstream os;
  os << gen_;
  out = os.str();
}

void FixParticleTemplateSphere::unpack_restart(const std::string& in) {
  std::istringstream is(in);
  std::mt19937_64 g;
  if (is >> g) gen_ = g;
}

GRANARY_FIX_STYLE("particletemplate/sphere", FixParticleTemplateSphere);

}  // namespace granary
