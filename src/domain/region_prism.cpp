// region ID prism xlo xhi ylo yhi zlo zhi xy xz yz [keywords]: a
// parallelepiped with its origin at (xlo, ylo, zlo) and edge vectors
// A = (xhi - xlo, 0, 0), B = (xy, yhi - ylo, 0), C = (xz, yz, zhi - zlo). A
// point is inside when its coordinates in that frame all lie in [0, 1]. Bounds
// may be INF or EDGE, but a tilt pairing two dimensions needs finite bounds in
// both.
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/registry.h"
#include "domain/region.h"
#include "domain/region_util.h"

namespace granary {

namespace {

class RegionPrism : public Region {
 public:
  RegionPrism(Engine& engine, const Args& args) : Region(engine, args, 9) {
    const std::string what = "region " + id + " (prism)";
    for (int d = 0; d < 3; ++d) {
      lo_[d] = coord(args[2 + 2 * d], d, true);
      hi_[d] = coord(args[3 + 2 * d], d, false);
      if (!(lo_[d] < hi_[d])) {
        throw InputError(what + ": the lower " + std::string(1, "xyz"[d]) +
                         " bound must be below the upper one");
      }
    }
    xy_ = length(args[8], 0);
    xz_ = length(args[9], 0);
    yz_ = length(args[10], 1);
    auto infinite = [&](int d) {
      return region_util::is_infinite(lo_[d]) || region_util::is_infinite(hi_[d]);
    };
    if ((xy_ != 0.0 && (infinite(0) || infinite(1))) || (xz_ != 0.0 && (infinite(0) || infinite(2))) ||
        (yz_ != 0.0 && (infinite(1) || infinite(2)))) {
      throw InputError(what + ": a non-zero tilt needs finite bounds in both of its dimensions");
    }
    const double lx = hi_[0] - lo_[0], ly = hi_[1] - lo_[1], lz = hi_[2] - lo_[2];
    // the inverse of the upper triangular matrix [[lx, xy, xz], [0, ly, yz], [0, 0, lz]]
    inv_[0] = 1.0 / lx;
    inv_[1] = 1.0 / ly;
    inv_[2] = 1.0 / lz;
    inv_xy_ = -xy_ / (lx * ly);
    inv_yz_ = -yz_ / (ly * lz);
    inv_xz_ = (xy_ * yz_ - ly * xz_) / (lx * ly * lz);
  }

  bool inside(const Vec3& x) const override {
    const double dx = x[0] - lo_[0], dy = x[1] - lo_[1], dz = x[2] - lo_[2];
    const double a = inv_[0] * dx + inv_xy_ * dy + inv_xz_ * dz;
    const double b = inv_[1] * dy + inv_yz_ * dz;
    const double c = inv_[2] * dz;
    return a >= 0.0 && a <= 1.0 && b >= 0.0 && b <= 1.0 && c >= 0.0 && c <= 1.0;
  }

  bool bounds(Vec3& lo, Vec3& hi) const override {
    if (!interior) return false;
    for (int d = 0; d < 3; ++d)
      if (region_util::is_infinite(lo_[d]) || region_util::is_infinite(hi_[d])) return false;
    // the corners o + i A + j B + k C
    lo = hi = Vec3(lo_[0], lo_[1], lo_[2]);
    const Vec3 A(hi_[0] - lo_[0], 0, 0), B(xy_, hi_[1] - lo_[1], 0), C(xz_, yz_, hi_[2] - lo_[2]);
    for (int m = 1; m < 8; ++m) {
      const Vec3 p = Vec3(lo_[0], lo_[1], lo_[2]) + (m & 1 ? A : Vec3::Zero()) + (m & 2 ? B : Vec3::Zero()) +
                     (m & 4 ? C : Vec3::Zero());
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    return true;
  }

  double volume() const override {
    Vec3 l, h;
    if (!bounds(l, h)) return -1.0;
    return (hi_[0] - lo_[0]) * (hi_[1] - lo_[1]) * (hi_[2] - lo_[2]);
  }

 private:
  double lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};
  double xy_ = 0, xz_ = 0, yz_ = 0;
  double inv_[3] = {1, 1, 1}, inv_xy_ = 0, inv_yz_ = 0, inv_xz_ = 0;
};

}  // namespace

GRANARY_REGION_STYLE("prism", RegionPrism);

}  // namespace granary
