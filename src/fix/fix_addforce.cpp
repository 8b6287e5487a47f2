// fix ID group addforce fx fy fz [region R] [energy v_E]
//
// Adds (fx, fy, fz) [N] to the force of every particle of the group (in the
// region, with `region`) after the pair forces. A component may be an
// equal-style or atom-style variable v_name, evaluated every step. Spheres of
// clumps get the force too, and fix multisphere adds it to their clump's force
// and torque. Global scalar: the potential energy of the added field
// (-sum x_u.F for constant components with x_u the unwrapped position; the sum
// of the atom-style energy variable otherwise, 0 without one). Global vector:
// the total force on those particles before the addition.
#include <mpi.h>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "fix/force_components.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group addforce fx fy fz [region REGION] [energy v_name]  (fx fy fz: N, v_name or NULL)";

class FixAddForce : public FixForceComponents {
 public:
  FixAddForce(Engine& engine, const Args& args)
      : FixForceComponents(engine, args, kUsage,
                           {/*allow_null*/ true, /*allow_atom*/ true, /*allow_energy*/ true}) {
    scalar_flag = true;
  }

  void post_force() override {
    comp_.update();
    Particles& p = *engine_.particles;
    const Domain& dom = *engine_.domain;
    const bool energy_var = !comp_.energy_variable().empty();
    energy_ = 0.0;
    before_[0] = before_[1] = before_[2] = 0.0;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!comp_.selected(i, groupbit)) continue;
      for (int d = 0; d < 3; ++d)
        before_[d] += p.f[i][d];
      if (energy_var) {
        energy_ += comp_.energy_values()[i];
      } else if (comp_.constant()) {
        int image[3];
        Particles::image_unpack(p.image[i], image[0], image[1], image[2]);
        for (int d = 0; d < 3; ++d)
          if (comp_.kind(d) != ForceComponents::NONE)
            energy_ -= (p.x[i][d] + image[d] * dom.prd[d]) * comp_.value(d, i);
      }
      for (int d = 0; d < 3; ++d)
        if (comp_.kind(d) != ForceComponents::NONE) p.f[i][d] += comp_.value(d, i);
    }
  }

  double compute_scalar() override {
    double all = 0.0;
    MPI_Allreduce(&energy_, &all, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
    return all;
  }

 private:
  double energy_ = 0.0;  // this rank's part of the scalar
};

}  // namespace

GRANARY_FIX_STYLE("addforce", FixAddForce);

}  // namespace granary
