// fix ID group freeze: the group's particles do not move or spin. Their force,
// torque, velocity and angular velocity are zeroed after the pair forces every
// step (and at the start of a run). The global vector (3 values) is the total
// force on the group that was removed on the last step [N].
#include <mpi.h>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixFreeze : public Fix {
 public:
  FixFreeze(Engine& engine, const Args& args) : Fix(engine, args) {
    require_args(args, 3, 3, "fix ID group freeze");
    size_vector = 3;
  }

  unsigned hooks() const override { return POST_FORCE; }

  void setup() override { zero(false); }
  void post_force() override { zero(true); }

  double compute_vector(int i) override {
    if (i < 0 || i > 2) return 0.0;
    double all[3];
    MPI_Allreduce(removed_, all, 3, MPI_DOUBLE, MPI_SUM, engine_.world);
    return all[i];
  }

 private:
  void zero(bool tally) {
    Particles& p = *engine_.particles;
    if (tally) removed_[0] = removed_[1] = removed_[2] = 0.0;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      if (tally)
        for (int d = 0; d < 3; ++d)
          removed_[d] += p.f[i][d];
      p.f[i].setZero();
      p.torque[i].setZero();
      p.v[i].setZero();
      p.omega[i].setZero();
    }
  }

  double removed_[3] = {0, 0, 0};
};

}  // namespace

GRANARY_FIX_STYLE("freeze", FixFreeze);

}  // namespace granary
