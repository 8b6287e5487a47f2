// Per-particle kinetic energies: compute ID group ke/atom (1/2 m v^2) and
// compute ID group erotate/sphere/atom (1/2 I w^2 with I = 2/5 m r^2), in J;
// 0 for particles outside the group. Their sums over the group are compute
// ke and compute erotate/sphere.
#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "particles/particles.h"

namespace granary {

namespace {

class ComputeKEAtom : public Compute {
 public:
  ComputeKEAtom(Engine& engine, const Args& args) : Compute(engine, args) {
    require_args(args, 3, 3, "compute ID group-ID " + args[2]);
    peratom_flag = true;
    rotational_ = args[2] == "erotate/sphere/atom";
  }

  void compute_peratom() override {
    const Particles& p = *engine_.particles;
    vector_atom.assign(p.nlocal, 0.0);
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      vector_atom[i] = rotational_
                           ? 0.5 * 0.4 * p.rmass[i] * p.radius[i] * p.radius[i] * p.omega[i].squaredNorm()
                           : 0.5 * p.rmass[i] * p.v[i].squaredNorm();
    }
  }

 private:
  bool rotational_ = false;
};

}  // namespace

GRANARY_COMPUTE_STYLE("ke/atom", ComputeKEAtom);
GRANARY_COMPUTE_STYLE("erotate/sphere/atom", ComputeKEAtom);

}  // namespace granary
