// Keywords shared by the particle templates (seed, atom_type, density).
#include "fix/fix_particle_template.h"

#include <string>

#include "core/engine.h"
#include "core/error.h"
#include "domain/domain.h"
#include "particles/particles.h"

namespace granary {

unsigned FixParticleTemplate::parse_seed(const std::string& what) const {
  const long long s = parse_int(args_[3], what + " seed");
  if (s <= 0) throw InputError(what + ": the seed must be a positive integer");
  return static_cast<unsigned>(s);
}

bool FixParticleTemplate::parse_common_keyword(std::size_t& k, const std::string& what, double& density) {
  const std::string& w = args_[k];
  if (w != "atom_type" && w != "density") return false;
  auto value = [&](const char* name) -> const std::string& {
    if (k + 1 >= args_.size()) throw InputError(what + ": keyword '" + w + "' needs " + name);
    return args_[++k];
  };
  if (w == "atom_type") {
    const long long t = parse_int(value("a type"), what + " atom_type");
    if (t < 1) throw InputError(what + ": atom_type must be at least 1");
    if (engine_.domain->box_exist && t > engine_.particles->ntypes) {
      throw InputError(what + ": atom_type " + std::to_string(t) + " is outside 1.." +
                       std::to_string(engine_.particles->ntypes) +
                       " (the number of atom types given to create_box)");
    }
    atom_type = static_cast<int>(t);
    return true;
  }
  const std::string& style = value("a style (constant)");
  if (style != "constant") throw InputError(what + ": density takes 'constant RHO', got '" + style + "'");
  density = parse_double(value("a value"), what + " density");
  if (!(density > 0.0)) throw InputError(what + ": the density must be positive");
  return true;
}

}  // namespace granary
