// fix ID group planeforce x y z: the particles of the group keep only the
// part of their force that lies in the plane normal to (x, y, z), so that,
// starting with no velocity along the normal, they move in that plane.
// fix ID group lineforce x y z: they keep only the part along the line
// (x, y, z). Applied after the pair forces every step and at the start of a
// run, as LAMMPS does; velocities and torques are not changed.
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixPlaneForce : public Fix {
 public:
  FixPlaneForce(Engine& engine, const Args& args) : Fix(engine, args) {
    line_ = args[2] == "lineforce";
    require_args(args, 6, 6, "fix ID group " + args[2] + " x y z");
    for (int d = 0; d < 3; ++d)
      dir_[d] = parse_double(args[3 + d], "a component of the direction of fix " + id);
    const double n = dir_.norm();
    if (!(n > 0.0)) throw InputError("fix " + id + " " + args[2] + ": the direction must not be zero");
    dir_ /= n;
  }

  unsigned hooks() const override { return POST_FORCE; }

  void post_force() override {
    Particles& p = *engine_.particles;
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) continue;
      const double along = p.f[i].dot(dir_);
      p.f[i] = line_ ? Vec3(along * dir_) : Vec3(p.f[i] - along * dir_);
    }
  }

 private:
  bool line_ = false;
  Vec3 dir_{0, 0, 1};
};

}  // namespace

GRANARY_FIX_STYLE("planeforce", FixPlaneForce);
GRANARY_FIX_STYLE("lineforce", FixPlaneForce);

}  // namespace granary
