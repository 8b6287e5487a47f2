// fix ID group spring/self K [xyz|xy|xz|yz|x|y|z]: each particle of the group
// is tied to its original position by a spring of stiffness K [N/m],
// F = -K (xu - x0) in the chosen directions (default all three), with xu the
// position unwrapped across periodic boundaries. The original positions are
// those when the fix is defined (a particle created later: where the fix
// first sees it), kept per particle and written to restart files (the fix
// defined again with the same ID after read_restart keeps them; see
// domain/origin_field.h). The global scalar is the springs' energy
// sum 1/2 K d^2 [J]. Applied after the pair forces every step and at the
// start of a run.
#include <mpi.h>

#include <memory>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/groups.h"
#include "domain/origin_field.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixSpringSelf : public Fix {
 public:
  FixSpringSelf(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage = "fix ID group spring/self K [xyz|xy|xz|yz|x|y|z]";
    require_args(args, 4, 5, usage);
    k_ = parse_double(args[3], "the spring constant of fix " + id);
    if (!(k_ > 0.0)) throw InputError("fix " + id + " spring/self: the spring constant must be positive");
    if (args.size() == 5) {
      const std::string& w = args[4];
      if (w.empty() || w.size() > 3 || w.find_first_not_of("xyz") != std::string::npos)
        throw InputError("fix " + id + " spring/self: directions must be xyz, xy, xz, yz, x, y or z, got '" +
                         w + "'; usage: " + usage);
      for (int d = 0; d < 3; ++d)
        on_[d] = w.find("xyz"[d]) != std::string::npos;
    }
    scalar_flag = true;
    origin_ = std::make_unique<OriginField>(engine, "spring/self/" + id);
  }

  unsigned hooks() const override { return POST_FORCE; }
  void unfixed() override { origin_->release(); }

  void post_force() override {
    Particles& p = *engine_.particles;
    energy_ = 0.0;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const Vec3 d = engine_.groups->unwrapped(i) - origin_->at(i);
      for (int c = 0; c < 3; ++c) {
        if (!on_[c]) continue;
        p.f[i][c] -= k_ * d[c];
        energy_ += 0.5 * k_ * d[c] * d[c];
      }
    }
  }

  double compute_scalar() override {
    double all = 0.0;
    MPI_Allreduce(&energy_, &all, 1, MPI_DOUBLE, MPI_SUM, engine_.world);
    return all;
  }

 private:
  double k_ = 0.0;
  bool on_[3] = {true, true, true};
  double energy_ = 0.0;
  std::unique_ptr<OriginField> origin_;
};

}  // namespace

GRANARY_FIX_STYLE("spring/self", FixSpringSelf);

}  // namespace granary
