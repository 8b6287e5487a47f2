// region ID cone dim c1 c2 radlo radhi lo hi [keywords]: a truncated circular
// cone with its axis along dim through (c1, c2), radius radlo at lo and radhi
// at hi, linear in between (one of the radii may be 0); lo and hi may be INF or
// EDGE only where the radii are equal (elsewhere the radius would be unbounded).
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/registry.h"
#include "domain/region.h"
#include "domain/region_util.h"

namespace granary {

namespace {

class RegionCone : public Region {
 public:
  RegionCone(Engine& engine, const Args& args) : Region(engine, args, 7) {
    const std::string what = "region " + id + " (cone)";
    axis_ = region_util::parse_axis(args[2], "the axis of " + what);
    a_ = axis_ == 0 ? 1 : 0;
    b_ = axis_ == 2 ? 1 : 2;
    c1_ = parse_double(args[3], "the first centre coordinate of " + what) * scale[a_];
    c2_ = parse_double(args[4], "the second centre coordinate of " + what) * scale[b_];
    rlo_ = length(args[5], a_);
    rhi_ = length(args[6], a_);
    if (!(rlo_ >= 0.0) || !(rhi_ >= 0.0) || !(rlo_ > 0.0 || rhi_ > 0.0)) {
      throw InputError(what + ": the radii must be >= 0 and not both 0, got '" + args[5] + "' and '" +
                       args[6] + "'");
    }
    lo_ = coord(args[7], axis_, true);
    hi_ = coord(args[8], axis_, false);
    if (!(lo_ < hi_)) throw InputError(what + ": lo must be below hi along the axis");
    if (unbounded() && rlo_ != rhi_) {
      throw InputError(what +
                       ": INF bounds need equal radii (the radius would grow without bound); use "
                       "finite lo and hi");
    }
  }

  /// Radius of the cone at axial coordinate h (lo <= h <= hi).
  double radius_at(double h) const {
    if (unbounded()) return rlo_;
    return rlo_ + (rhi_ - rlo_) * (h - lo_) / (hi_ - lo_);
  }

  bool inside(const Vec3& x) const override {
    const double h = x[axis_];
    if (h < lo_ || h > hi_) return false;
    const double d1 = x[a_] - c1_, d2 = x[b_] - c2_;
    const double r = radius_at(h);
    return d1 * d1 + d2 * d2 <= r * r;
  }

  bool bounds(Vec3& lo, Vec3& hi) const override {
    if (!interior || unbounded()) return false;
    region_util::axial_bounds(axis_, a_, b_, c1_, c2_, std::max(rlo_, rhi_), lo_, hi_, lo, hi);
    return true;
  }

  double volume() const override {
    if (!interior || unbounded()) return -1.0;
    return M_PI * (hi_ - lo_) * (rlo_ * rlo_ + rlo_ * rhi_ + rhi_ * rhi_) / 3.0;
  }

 protected:
  // In the half-plane through the axis and x: rho (distance from the axis)
  // and h (along the axis). The cone's section there is the quadrilateral
  // (0, lo), (rlo, lo), (rhi, hi), (0, hi).
  struct Plane {
    double rho, h, d1, d2;
  };
  Plane to_plane(const Vec3& x) const {
    const double d1 = x[a_] - c1_, d2 = x[b_] - c2_;
    return {std::sqrt(d1 * d1 + d2 * d2), x[axis_], d1, d2};
  }
  // the 3-d point at (rho, h) of x's half-plane
  Vec3 from_plane(const Plane& p, double rho, double h, const Vec3& x) const {
    Vec3 q = x;
    q[axis_] = h;
    if (p.rho > 0.0) {
      q[a_] = c1_ + p.d1 / p.rho * rho;
      q[b_] = c2_ + p.d2 / p.rho * rho;
    } else {
      q[a_] = c1_;
      q[b_] = c2_;
    }
    return q;
  }
  // closest point of the segment (r0, h0)-(r1, h1) to (rho, h)
  static void closest_on_segment(double rho, double h, double r0, double h0, double r1, double h1, double& cr,
                                 double& ch) {
    const double er = r1 - r0, eh = h1 - h0;
    const double len2 = er * er + eh * eh;
    double t = len2 > 0.0 ? ((rho - r0) * er + (h - h0) * eh) / len2 : 0.0;
    t = std::min(std::max(t, 0.0), 1.0);
    cr = r0 + t * er;
    ch = h0 + t * eh;
  }

  // the slanted face (its nearest point) and the two end faces, each when closer than cutoff
  void surface_interior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const override {
    const Plane p = to_plane(x);
    if (p.rho > 0.0) {
      double cr, ch;
      if (unbounded()) {
        cr = rlo_;
        ch = p.h;
      } else {
        closest_on_segment(p.rho, p.h, rlo_, lo_, rhi_, hi_, cr, ch);
      }
      const Vec3 del = x - from_plane(p, cr, ch, x);
      const double r = del.norm();
      if (r < cutoff) out.push_back({r, del});
    }
    Vec3 e = Vec3::Zero();
    e[axis_] = 1.0;
    const double below = x[axis_] - lo_, above = hi_ - x[axis_];
    if (!region_util::is_infinite(lo_) && rlo_ > 0.0 && below < cutoff) out.push_back({below, below * e});
    if (!region_util::is_infinite(hi_) && rhi_ > 0.0 && above < cutoff) out.push_back({above, -above * e});
  }

  // the nearest point of the solid cone: of the faces of its section
  void surface_exterior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const override {
    const Plane p = to_plane(x);
    double best_r = -1.0, br = 0.0, bh = 0.0;
    auto consider = [&](double r0, double h0, double r1, double h1) {
      double cr, ch;
      closest_on_segment(p.rho, p.h, r0, h0, r1, h1, cr, ch);
      const double d = std::hypot(p.rho - cr, p.h - ch);
      if (best_r < 0.0 || d < best_r) {
        best_r = d;
        br = cr;
        bh = ch;
      }
    };
    if (unbounded()) {
      consider(rlo_, std::max(std::min(p.h, hi_), lo_), rlo_, std::max(std::min(p.h, hi_), lo_));
    } else {
      consider(0.0, lo_, rlo_, lo_);
      consider(rlo_, lo_, rhi_, hi_);
      consider(rhi_, hi_, 0.0, hi_);
    }
    const Vec3 del = x - from_plane(p, br, bh, x);
    const double r = del.norm();
    if (r < cutoff) out.push_back({r, del});
  }

 private:
  bool unbounded() const { return region_util::is_infinite(lo_) || region_util::is_infinite(hi_); }
  int axis_ = 2, a_ = 0, b_ = 1;
  double c1_ = 0, c2_ = 0, rlo_ = 0, rhi_ = 0, lo_ = 0, hi_ = 0;
};

}  // namespace

GRANARY_REGION_STYLE("cone", RegionCone);

}  // namespace granary
