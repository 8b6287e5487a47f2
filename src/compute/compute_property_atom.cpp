// compute ID group property/atom name1 name2 ...: per-atom values of particle
// properties. One name gives a per-atom vector, several a per-atom array with
// one column per name (c_ID[1], c_ID[2], ...). Particles outside the group get 0.

#include "compute/compute.h"
#include "core/atom_properties.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage =
    "compute ID group-ID property/atom name ...  (id type body mass radius diameter density x y z xs ys zs "
    "xu yu zu ix iy iz vx vy vz fx fy fz omegax omegay omegaz tqx tqy tqz)";

class ComputePropertyAtom : public Compute {
 public:
  ComputePropertyAtom(Engine& engine, const Args& args) : Compute(engine, args) {
    require_args(args, 4, 10000, kUsage);
    names_.assign(args.begin() + 3, args.end());
    for (const auto& name : names_) {
      if (!find_atom_property(name)) {
        const std::string hint = did_you_mean(name, atom_property_names());
        throw InputError("unknown property '" + name + "' in compute " + id + " property/atom" +
                         (hint.empty() ? "" : "; " + hint) + "; usage: " + kUsage);
      }
    }
    peratom_flag = true;
    peratom_cols = names_.size() == 1 ? 0 : static_cast<int>(names_.size());
  }

  void compute_peratom() override {
    if (peratom_cols == 0) {
      fill(names_[0], vector_atom);
    } else {
      array_atom.resize(names_.size());
      for (std::size_t c = 0; c < names_.size(); ++c)
        fill(names_[c], array_atom[c]);
    }
  }

 private:
  void fill(const std::string& name, std::vector<double>& out) {
    const Particles& p = *engine_.particles;
    engine_.atom_vector(name, out);
    for (int i = 0; i < p.nlocal; ++i)
      if (!(p.mask[i] & groupbit)) out[i] = 0.0;
  }

  std::vector<std::string> names_;
};

}  // namespace

GRANARY_COMPUTE_STYLE("property/atom", ComputePropertyAtom);

}  // namespace granary
