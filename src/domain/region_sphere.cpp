// region ID sphere x y z radius [keywords]: a ball.
#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/registry.h"
#include "domain/region.h"

namespace granary {

namespace {

class RegionSphere : public Region {
 public:
  RegionSphere(Engine& engine, const Args& args) : Region(engine, args, 4) {
    for (int d = 0; d < 3; ++d) {
      centre_[d] = parse_double(args[2 + d], "the centre of region " + id) * scale[d];
    }
    radius_ = length(args[5], 0);
    if (!(radius_ > 0.0)) {
      throw InputError("region " + id + " (sphere): the radius must be positive, got '" + args[5] + "'");
    }
  }

  bool inside(const Vec3& x) const override { return (x - centre_).squaredNorm() <= radius_ * radius_; }

  bool bounds(Vec3& lo, Vec3& hi) const override {
    if (!interior) return false;
    lo = centre_.array() - radius_;
    hi = centre_.array() + radius_;
    return true;
  }

  double volume() const override {
    if (!interior) return -1.0;
    return 4.0 / 3.0 * M_PI * radius_ * radius_ * radius_;
  }

 protected:
  void surface_interior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const override {
    const Vec3 d = x - centre_;
    const double dist = d.norm();
    const double r = radius_ - dist;
    if (r < cutoff && dist > 0.0) out.push_back({r, -(r / dist) * d});
  }
  void surface_exterior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const override {
    const Vec3 d = x - centre_;
    const double dist = d.norm();
    const double r = dist - radius_;
    if (r < cutoff) out.push_back({r, (r / dist) * d});
  }

 private:
  Vec3 centre_{0, 0, 0};
  double radius_ = 0.0;
};

}  // namespace

GRANARY_REGION_STYLE("sphere", RegionSphere);

}  // namespace granary
