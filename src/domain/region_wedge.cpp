// region ID wedge axis dim center c1 c2 radius r bounds lo hi angle0 a0 angle a
// [keywords] (LIGGGHTS): the sector of a circular cylinder with its axis along
// dim that starts at the angle a0 (degrees, counter-clockwise) and spans a
// degrees. The centre and the angles are taken in the cyclic order of the
// other two dimensions: (y, z) about x, (z, x) about y, (x, y) about z, the
// angle from the first of them towards the second.
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/registry.h"
#include "domain/region.h"
#include "domain/region_util.h"

namespace granary {

namespace {

class RegionWedge : public Region {
 public:
  RegionWedge(Engine& engine, const Args& args) : Region(engine, args, 14) {
    const std::string what = "region " + id + " (wedge)";
    const char* keys[] = {"axis", "center", "radius", "bounds", "angle0", "angle"};
    const int at[] = {2, 4, 7, 9, 12, 14};
    for (int k = 0; k < 6; ++k) {
      if (args[at[k]] != keys[k]) {
        throw InputError(
            what + ": expected '" + keys[k] + "' as argument " + std::to_string(at[k] - 1) + ", got '" +
            args[at[k]] +
            "'; usage: region ID wedge axis x|y|z center C1 C2 radius R bounds LO HI angle0 A0 angle A");
      }
    }
    axis_ = region_util::parse_axis(args[3], "the axis of " + what);
    a_ = (axis_ + 1) % 3;  // cyclic: x -> (y, z), y -> (z, x), z -> (x, y)
    b_ = (axis_ + 2) % 3;
    c1_ = parse_double(args[5], "the first centre coordinate of " + what) * scale[a_];
    c2_ = parse_double(args[6], "the second centre coordinate of " + what) * scale[b_];
    radius_ = length(args[8], a_);
    if (!(radius_ > 0.0)) throw InputError(what + ": the radius must be positive, got '" + args[8] + "'");
    lo_ = coord(args[10], axis_, true);
    hi_ = coord(args[11], axis_, false);
    if (lo_ > hi_) throw InputError(what + ": lo exceeds hi along the axis");
    angle0_ = parse_double(args[13], "angle0 of " + what);
    angle_ = parse_double(args[15], "the angle of " + what);
    if (!(angle_ > 0.0 && angle_ <= 360.0)) {
      throw InputError(what + ": the angle must be in (0, 360] degrees, got '" + args[15] + "'");
    }
  }

  bool inside(const Vec3& x) const override {
    const double h = x[axis_];
    if (h < lo_ || h > hi_) return false;
    const double d1 = x[a_] - c1_, d2 = x[b_] - c2_;
    if (d1 * d1 + d2 * d2 > radius_ * radius_) return false;
    if (angle_ >= 360.0 || (d1 == 0.0 && d2 == 0.0)) return true;  // the axis belongs to every sector
    // the angle from the starting face, counter-clockwise, in [0, 360)
    double phi = std::atan2(d2, d1) * (180.0 / M_PI) - angle0_;
    phi = std::fmod(phi, 360.0);
    if (phi < 0.0) phi += 360.0;
    return phi <= angle_;
  }

  bool bounds(Vec3& lo, Vec3& hi) const override {
    if (!interior || region_util::is_infinite(lo_) || region_util::is_infinite(hi_)) return false;
    region_util::axial_bounds(axis_, a_, b_, c1_, c2_, radius_, lo_, hi_, lo, hi);  // the whole cylinder's
    return true;
  }

  double volume() const override {
    if (!interior || region_util::is_infinite(lo_) || region_util::is_infinite(hi_)) return -1.0;
    return M_PI * radius_ * radius_ * (hi_ - lo_) * angle_ / 360.0;
  }

 private:
  int axis_ = 2, a_ = 0, b_ = 1;
  double c1_ = 0, c2_ = 0, radius_ = 0, lo_ = 0, hi_ = 0, angle0_ = 0, angle_ = 360;
};

}  // namespace

GRANARY_REGION_STYLE("wedge", RegionWedge);

}  // namespace granary
