// region ID cylinder dim c1 c2 radius lo hi [keywords]: a circular cylinder
// with its axis along dim through (c1, c2); lo and hi may be INF or EDGE.
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/registry.h"
#include "domain/region.h"
#include "domain/region_util.h"

namespace granary {

namespace {

class RegionCylinder : public Region {
 public:
  RegionCylinder(Engine& engine, const Args& args) : Region(engine, args, 6) {
    axis_ = region_util::parse_axis(args[2], "the axis of region " + id + " (cylinder)");
    // the two other dimensions, in increasing order (x->y,z  y->x,z  z->x,y)
    a_ = axis_ == 0 ? 1 : 0;
    b_ = axis_ == 2 ? 1 : 2;
    c1_ = parse_double(args[3], "the first centre coordinate of region " + id) * scale[a_];
    c2_ = parse_double(args[4], "the second centre coordinate of region " + id) * scale[b_];
    radius_ = length(args[5], a_);
    if (!(radius_ > 0.0)) {
      throw InputError("region " + id + " (cylinder): the radius must be positive, got '" + args[5] + "'");
    }
    lo_ = coord(args[6], axis_, true);
    hi_ = coord(args[7], axis_, false);
    if (lo_ > hi_) {
      throw InputError("region " + id + " (cylinder): lo exceeds hi along the axis");
    }
  }

  bool inside(const Vec3& x) const override {
    const double d1 = x[a_] - c1_, d2 = x[b_] - c2_;
    return d1 * d1 + d2 * d2 <= radius_ * radius_ && x[axis_] >= lo_ && x[axis_] <= hi_;
  }

  bool bounds(Vec3& lo, Vec3& hi) const override {
    if (!interior || unbounded()) return false;
    region_util::axial_bounds(axis_, a_, b_, c1_, c2_, radius_, lo_, hi_, lo, hi);
    return true;
  }

  double volume() const override {
    if (!interior || unbounded()) return -1.0;
    return M_PI * radius_ * radius_ * (hi_ - lo_);
  }

 protected:
  // the curved face (radially) and the two end faces, each when closer than cutoff
  void surface_interior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const override {
    const double d1 = x[a_] - c1_, d2 = x[b_] - c2_;
    const double rho = std::sqrt(d1 * d1 + d2 * d2);
    const double r = radius_ - rho;
    if (r < cutoff && rho > 0.0) {
      Vec3 del = Vec3::Zero();
      del[a_] = -d1 / rho * r;
      del[b_] = -d2 / rho * r;
      out.push_back({r, del});
    }
    Vec3 e = Vec3::Zero();
    e[axis_] = 1.0;
    const double below = x[axis_] - lo_, above = hi_ - x[axis_];
    if (!region_util::is_infinite(lo_) && below < cutoff) out.push_back({below, below * e});
    if (!region_util::is_infinite(hi_) && above < cutoff) out.push_back({above, -above * e});
  }
  // the nearest point of the solid cylinder
  void surface_exterior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const override {
    const double d1 = x[a_] - c1_, d2 = x[b_] - c2_;
    const double rho = std::sqrt(d1 * d1 + d2 * d2);
    Vec3 nearest = x;
    nearest[axis_] = std::min(std::max(x[axis_], lo_), hi_);
    if (rho > radius_) {
      nearest[a_] = c1_ + d1 / rho * radius_;
      nearest[b_] = c2_ + d2 / rho * radius_;
    }
    const Vec3 del = x - nearest;
    const double r = del.norm();
    if (r < cutoff) out.push_back({r, del});
  }

 private:
  bool unbounded() const { return region_util::is_infinite(lo_) || region_util::is_infinite(hi_); }
  int axis_ = 2, a_ = 0, b_ = 1;
  double c1_ = 0, c2_ = 0, radius_ = 0, lo_ = 0, hi_ = 0;
};

}  // namespace

GRANARY_REGION_STYLE("cylinder", RegionCylinder);

}  // namespace granary
