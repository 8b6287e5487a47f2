// fix ID group drag x y z fmag delta
// A force of magnitude fmag on every particle of the group, towards the point
// (x, y, z), unless the particle is within delta of it (LIGGGHTS/LAMMPS `fix
// drag`). Any of x, y, z may be NULL: that direction is left out of the
// distance and of the force. Along a periodic dimension the nearest image of
// the point counts. Global vector: the total drag force on the group (x, y, z).
#include <mpi.h>

#include <cmath>
#include <string>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixDrag : public Fix {
 public:
  FixDrag(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage = "fix ID group drag x y z fmag delta (x, y, z may be NULL)";
    require_args(args, 8, 8, usage);
    for (int d = 0; d < 3; ++d) {
      const std::string& w = args[3 + static_cast<std::size_t>(d)];
      on_[d] = w != "NULL";
      if (on_[d]) point_[d] = parse_double(w, std::string(1, "xyz"[d]) + " of fix " + id + " drag");
    }
    fmag_ = parse_double(args[6], "fmag of fix " + id + " drag");
    delta_ = parse_double(args[7], "delta of fix " + id + " drag");
    if (!(delta_ >= 0.0)) throw InputError("fix " + id + " drag: delta must be >= 0 (got " + args[7] + ")");
    size_vector = 3;
  }

  unsigned hooks() const override { return POST_FORCE; }

  void post_force() override {
    Particles& p = *engine_.particles;
    const Domain& dom = *engine_.domain;
    Vec3 total = Vec3::Zero();
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      Vec3 d = Vec3::Zero();
      for (int c = 0; c < 3; ++c) {
        if (!on_[c]) continue;
        d[c] = p.x[i][c] - point_[c];
        if (dom.periodic[c]) {  // the nearest image
          const double half = 0.5 * dom.prd[c];
          if (d[c] > half) d[c] -= dom.prd[c];
          if (d[c] < -half) d[c] += dom.prd[c];
        }
      }
      const double r = d.norm();
      if (!(r > delta_)) continue;
      const Vec3 f = (-fmag_ / r) * d;
      p.f[i] += f;
      total += f;
    }
    local_ = total;
    summed_ = false;
  }

  double compute_vector(int i) override {
    if (!summed_) {
      MPI_Allreduce(local_.data(), sum_.data(), 3, MPI_DOUBLE, MPI_SUM, engine_.world);
      summed_ = true;
    }
    return i >= 0 && i < 3 ? sum_[i] : 0.0;
  }

 private:
  bool on_[3] = {true, true, true};
  Vec3 point_ = Vec3::Zero();
  double fmag_ = 0.0, delta_ = 0.0;
  Vec3 local_ = Vec3::Zero(), sum_ = Vec3::Zero();
  bool summed_ = true;
};

}  // namespace

GRANARY_FIX_STYLE("drag", FixDrag);

}  // namespace granary
