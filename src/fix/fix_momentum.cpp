// fix ID group momentum N [linear XFLAG YFLAG ZFLAG] [angular]
//
// Every N steps (at the end of the step) removes the group's centre-of-mass
// velocity from each of its particles (linear, in the dimensions whose flag is
// 1) and/or the rigid rotation that carries the group's orbital angular
// momentum about its centre of mass (angular): v -= w x (x_u - x_cm) with
// w = I^-1 L, I and L those of point masses at the unwrapped positions x_u.
// Sums run over all ranks. Spins are not changed. Clumps are refused.
#include <mpi.h>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/groups.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage = "fix ID group momentum N [linear XFLAG YFLAG ZFLAG] [angular]  (flags 0 or 1)";

class FixMomentum : public Fix {
 public:
  FixMomentum(Engine& engine, const Args& args) : Fix(engine, args) {
    if (args.size() < 5) throw InputError(std::string("wrong number of arguments; usage: ") + kUsage);
    const long long n = parse_int(args[3], "the period N of fix momentum");
    if (n <= 0) throw InputError("fix momentum: N must be positive (got " + args[3] + ")");
    nevery = static_cast<int>(n);
    for (std::size_t k = 4; k < args.size();) {
      if (args[k] == "linear") {
        if (k + 3 >= args.size())
          throw InputError("fix momentum linear needs three flags; usage: " + std::string(kUsage));
        for (int d = 0; d < 3; ++d) {
          const long long flag = parse_int(args[k + 1 + d], "a flag of fix momentum linear");
          if (flag != 0 && flag != 1)
            throw InputError("fix momentum linear flags must be 0 or 1 (got " + args[k + 1 + d] + ")");
          flags_[d] = flag == 1;
        }
        linear_ = true;
        k += 4;
      } else if (args[k] == "angular") {
        angular_ = true;
        ++k;
      } else {
        const std::string hint = did_you_mean(args[k], {"linear", "angular"});
        throw InputError("unknown fix momentum keyword '" + args[k] + "'" +
                         (hint.empty() ? "" : "; " + hint) + "; usage: " + kUsage);
      }
    }
    if (!linear_ && !angular_)
      throw InputError(std::string("fix momentum needs linear or angular; usage: ") + kUsage);
  }

  unsigned hooks() const override { return END_OF_STEP; }

  void end_of_step() override {
    Particles& p = *engine_.particles;
    const int bit = groupbit;
    for (int i = 0; i < p.nlocal; ++i) {
      if ((p.mask[i] & bit) && p.body[i] >= 0)
        throw RunError("fix " + id + " (momentum): particle " + std::to_string(p.id[i]) +
                       " of its group is a sphere of clump " + std::to_string(p.body[i]) + " at step " +
                       std::to_string(engine_.update->ntimestep) +
                       "; fix momentum cannot change the velocities of clumps (fix multisphere sets them). "
                       "Use a group of free spheres");
    }
    if (linear_) {
      const Vec3 vcm = engine_.groups->vcm(igroup);
      for (int i = 0; i < p.nlocal; ++i) {
        if (!(p.mask[i] & bit)) continue;
        for (int d = 0; d < 3; ++d)
          if (flags_[d]) p.v[i][d] -= vcm[d];
      }
    }
    if (angular_) remove_rotation();
  }

 private:
  void remove_rotation() {
    Particles& p = *engine_.particles;
    const Groups& groups = *engine_.groups;
    const Vec3 xcm = groups.xcm(igroup);
    const Vec3 omega = groups.omega(igroup, xcm);
    for (int i = 0; i < p.nlocal; ++i)
      if (p.mask[i] & groupbit) p.v[i] -= omega.cross(groups.unwrapped(i) - xcm);
  }

  bool linear_ = false, angular_ = false;
  bool flags_[3] = {true, true, true};
};

}  // namespace

GRANARY_FIX_STYLE("momentum", FixMomentum);

}  // namespace granary
