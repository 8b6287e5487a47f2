// fix ID group spring tether K x y z R0
// fix ID group spring couple group2 K x y z R0
// A spring on the centre of mass of the group (positions unwrapped across
// periodic boundaries): tether ties it to the point (x, y, z), couple to the
// centre of mass of group2 displaced by (x, y, z). Any of x, y, z may be NULL:
// that direction is left out of the distance and of the force. With d the
// vector from the tether point (or from the displaced partner) to the group's
// centre of mass and r = |d|, the spring force on the group is
// -K (r - R0) d / r, shared among its particles by mass (couple: group2 gets
// the opposite force, shared by its masses). Global scalar: 1/2 K (r - R0)^2;
// global vector: the force on the group (x, y, z) and K (r - R0).
#include <cmath>
#include <string>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/groups.h"
#include "fix/fix.h"
#include "particles/particles.h"

namespace granary {

namespace {

class FixSpring : public Fix {
 public:
  FixSpring(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage =
        "fix ID group spring tether K x y z R0, or fix ID group spring couple group2 K x y z R0 "
        "(x, y, z may be NULL)";
    if (args.size() < 4) throw InputError("fix " + id + " spring: missing arguments; usage: " + usage);
    std::size_t k = 4;
    if (args[3] == "tether") {
      require_args(args, 9, 9, usage);
    } else if (args[3] == "couple") {
      require_args(args, 10, 10, usage);
      group2_ = engine.groups->find_or_error(args[4], "fix " + id + " spring couple");
      k = 5;
    } else {
      throw InputError("fix " + id + " spring: expected 'tether' or 'couple', got '" + args[3] +
                       "'; usage: " + usage);
    }
    k_ = parse_double(args[k], "the spring constant of fix " + id);
    if (!(k_ > 0.0)) throw InputError("fix " + id + " spring: the spring constant must be positive");
    for (int d = 0; d < 3; ++d) {
      const std::string& w = args[k + 1 + static_cast<std::size_t>(d)];
      on_[d] = w != "NULL";
      if (on_[d]) point_[d] = parse_double(w, std::string(1, "xyz"[d]) + " of fix " + id + " spring");
    }
    if (!on_[0] && !on_[1] && !on_[2])
      throw InputError("fix " + id + " spring: x, y and z are all NULL; the spring has no direction");
    r0_ = parse_double(args[k + 4], "R0 of fix " + id + " spring");
    if (!(r0_ >= 0.0)) throw InputError("fix " + id + " spring: R0 must be >= 0");
    scalar_flag = true;
    size_vector = 4;
  }

  unsigned hooks() const override { return POST_FORCE; }

  void post_force() override {
    Groups& g = *engine_.groups;
    const Vec3 xcm = g.xcm(igroup);
    const double mass = g.mass(igroup);
    Vec3 d = Vec3::Zero();
    double mass2 = 0.0;
    if (group2_ >= 0) {
      const Vec3 xcm2 = g.xcm(group2_);
      mass2 = g.mass(group2_);
      for (int c = 0; c < 3; ++c)
        if (on_[c]) d[c] = xcm[c] - xcm2[c] + point_[c];  // from the displaced partner to the group
    } else {
      for (int c = 0; c < 3; ++c)
        if (on_[c]) d[c] = xcm[c] - point_[c];
    }
    const double r = d.norm();
    const double dr = r - r0_;
    force_ = r > 0.0 ? Vec3((-k_ * dr / r) * d) : Vec3::Zero();  // on the group
    energy_ = 0.5 * k_ * dr * dr;
    signed_ = k_ * dr;
    Particles& p = *engine_.particles;
    const int bit2 = group2_ >= 0 ? g.bitmask(group2_) : 0;
    for (int i = 0; i < p.nlocal; ++i) {
      if ((p.mask[i] & groupbit) && mass > 0.0) p.f[i] += (p.rmass[i] / mass) * force_;
      if ((p.mask[i] & bit2) && mass2 > 0.0) p.f[i] -= (p.rmass[i] / mass2) * force_;
    }
  }

  double compute_scalar() override { return energy_; }
  double compute_vector(int i) override { return i < 3 ? force_[i] : signed_; }

 private:
  int group2_ = -1;
  double k_ = 0.0, r0_ = 0.0;
  bool on_[3] = {true, true, true};
  Vec3 point_ = Vec3::Zero();
  Vec3 force_ = Vec3::Zero();
  double energy_ = 0.0, signed_ = 0.0;
};

}  // namespace

GRANARY_FIX_STYLE("spring", FixSpring);

}  // namespace granary
