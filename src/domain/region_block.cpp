// region ID block xlo xhi ylo yhi zlo zhi [keywords]: an axis-aligned box;
// any bound may be INF (unbounded) or EDGE (the simulation box face).
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/registry.h"
#include "domain/region.h"
#include "domain/region_util.h"

namespace granary {

namespace {

class RegionBlock : public Region {
 public:
  RegionBlock(Engine& engine, const Args& args) : Region(engine, args, 6) {
    for (int d = 0; d < 3; ++d) {
      lo_[d] = coord(args[2 + 2 * d], d, true);
      hi_[d] = coord(args[3 + 2 * d], d, false);
      if (lo_[d] > hi_[d]) {
        throw InputError("region " + id + " (block): the lower " + std::string(1, "xyz"[d]) +
                         " bound exceeds the upper one; give xlo xhi ylo yhi zlo zhi in this order");
      }
    }
  }

  bool inside(const Vec3& x) const override {
    for (int d = 0; d < 3; ++d)
      if (x[d] < lo_[d] || x[d] > hi_[d]) return false;
    return true;
  }

  bool bounds(Vec3& lo, Vec3& hi) const override {
    if (!interior || unbounded()) return false;
    lo = lo_;
    hi = hi_;
    return true;
  }

  double volume() const override {
    if (!interior || unbounded()) return -1.0;
    return (hi_ - lo_).prod();
  }

 protected:
  // every face closer than cutoff (infinite bounds have none)
  void surface_interior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const override {
    for (int d = 0; d < 3; ++d) {
      Vec3 e = Vec3::Zero();
      e[d] = 1.0;
      const double below = x[d] - lo_[d], above = hi_[d] - x[d];
      if (!region_util::is_infinite(lo_[d]) && below < cutoff) out.push_back({below, below * e});
      if (!region_util::is_infinite(hi_[d]) && above < cutoff) out.push_back({above, -above * e});
    }
  }
  // the nearest point of the box
  void surface_exterior(const Vec3& x, double cutoff, std::vector<SurfacePoint>& out) const override {
    Vec3 nearest;
    for (int d = 0; d < 3; ++d)
      nearest[d] = std::min(std::max(x[d], lo_[d]), hi_[d]);
    const Vec3 del = x - nearest;
    const double r = del.norm();
    if (r < cutoff) out.push_back({r, del});
  }

 private:
  bool unbounded() const {
    for (int d = 0; d < 3; ++d)
      if (region_util::is_infinite(lo_[d]) || region_util::is_infinite(hi_[d])) return true;
    return false;
  }
  Vec3 lo_, hi_;
};

}  // namespace

GRANARY_REGION_STYLE("block", RegionBlock);

}  // namespace granary
