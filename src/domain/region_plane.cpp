// region ID plane px py pz nx ny nz [keywords]: the half-space on the side of
// the plane through p that the normal n points to (points on the plane count as inside).
#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/registry.h"
#include "domain/region.h"

namespace granary {

namespace {

class RegionPlane : public Region {
 public:
  RegionPlane(Engine& engine, const Args& args) : Region(engine, args, 6) {
    for (int d = 0; d < 3; ++d) {
      point_[d] = parse_double(args[2 + d], "the point of region " + id) * scale[d];
      normal_[d] = parse_double(args[5 + d], "the normal of region " + id) * scale[d];
    }
    const double n = normal_.norm();
    if (!(n > 0.0)) {
      throw InputError("region " + id + " (plane): the normal vector must not be zero");
    }
    normal_ /= n;
  }

  bool inside(const Vec3& x) const override { return (x - point_).dot(normal_) >= 0.0; }
  bool bounds(Vec3&, Vec3&) const override { return false; }

 protected:
  void surface_interior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const override {
    const double r = (x - point_).dot(normal_);
    if (r < cutoff) out.push_back({r, r * normal_});
  }
  void surface_exterior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const override {
    const double r = -(x - point_).dot(normal_);
    if (r < cutoff) out.push_back({r, -r * normal_});
  }

 private:
  Vec3 point_{0, 0, 0}, normal_{0, 0, 1};
};

}  // namespace

GRANARY_REGION_STYLE("plane", RegionPlane);

}  // namespace granary
