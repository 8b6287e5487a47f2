// fix ID group viscous GAMMA [scale TYPE RATIO ...]: a damping force
// f = -gamma v on every particle of the group [gamma in kg/s]; `scale` multiplies
// gamma by RATIO for particles of one type.
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage = "fix ID group viscous GAMMA [scale TYPE RATIO] ...";

class FixViscous : public Fix {
 public:
  FixViscous(Engine& engine, const Args& args) : Fix(engine, args) {
    if (args.size() < 4) throw InputError(std::string("wrong number of arguments; usage: ") + kUsage);
    const double gamma = parse_double(args[3], "the damping coefficient gamma");
    if (gamma < 0.0) throw InputError("fix viscous needs gamma >= 0");
    const int ntypes = engine.particles->ntypes;
    gamma_.assign(static_cast<std::size_t>(ntypes) + 1, gamma);
    for (std::size_t k = 4; k < args.size(); k += 3) {
      if (args[k] != "scale")
        throw InputError("unknown fix viscous keyword '" + args[k] + "'; usage: " + kUsage);
      if (k + 2 >= args.size()) throw InputError("fix viscous scale needs TYPE and RATIO");
      const long long t = parse_int(args[k + 1], "the type of fix viscous scale");
      if (t < 1 || t > ntypes) {
        throw InputError("fix viscous scale type " + args[k + 1] + " is outside 1.." +
                         std::to_string(ntypes));
      }
      gamma_[t] = gamma * parse_double(args[k + 2], "the ratio of fix viscous scale");
    }
  }

  unsigned hooks() const override { return POST_FORCE; }

  void post_force() override {
    Particles& p = *engine_.particles;
    const int nt = static_cast<int>(gamma_.size());
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const int t = p.type[i];
      p.f[i] -= (t > 0 && t < nt ? gamma_[t] : gamma_[0]) * p.v[i];
    }
  }

 private:
  std::vector<double> gamma_;  // per type (index 0: the default)
};

}  // namespace

GRANARY_FIX_STYLE("viscous", FixViscous);

}  // namespace granary
