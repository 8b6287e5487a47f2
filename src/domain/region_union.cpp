// region ID union N reg-ID1 ... reg-IDN [keywords]: the points in any of the
// N regions; region ID intersect N reg-ID1 ... reg-IDN: the points in all of
// them. Each sub-region counts with its own `side`; the combined region's
// `side out` inverts the result. The sub-regions are looked up by ID at each
// use; a sub-region cannot be deleted while a combination uses it. Bounds:
// of the union, the box around all sub-regions when every one is bounded; of
// the intersection, the overlap of the bounded ones. The volume is not known
// in closed form (insertion fixes measure it by Monte Carlo, see fix
// insert/pack).
#include <algorithm>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "domain/region.h"

namespace granary {

namespace {

/// 1 + N: the count and the N region IDs.
std::size_t shape_args(const Args& args) {
  if (args.size() < 3) return 1;
  long long n = 0;
  try {
    n = parse_int(args[2], "the number of regions of region " + args[0]);
  } catch (const InputError&) {
    // reported in the constructor: hand it every word before the keywords
    std::size_t k = 2;
    while (k < args.size() && args[k] != "side" && args[k] != "units")
      ++k;
    return k - 2;
  }
  return n < 1 ? 1 : static_cast<std::size_t>(1 + std::min<long long>(n, 1000));
}

class RegionCombined : public Region {
 public:
  RegionCombined(Engine& engine, const Args& args) : Region(engine, args, shape_args(args)) {
    union_ = style == "union";
    const long long n = parse_int(args[2], "the number of regions of region " + id);
    if (n < 2 || n > 1000)
      throw InputError("region " + id + " (" + style + ") combines 2 to 1000 regions, got " + args[2]);
    for (long long k = 0; k < n; ++k) {
      const std::string& sub = args[3 + static_cast<std::size_t>(k)];
      if (sub == id) throw InputError("region " + id + " (" + style + ") cannot contain itself");
      engine.domain->region_or_error(sub, "region " + id + " (" + style + ")");
      ids_.push_back(sub);
    }
  }

  bool inside(const Vec3& x) const override {
    for (const std::string& sub : ids_) {
      const bool in = region(sub)->match(x);
      if (union_ && in) return true;
      if (!union_ && !in) return false;
    }
    return !union_;
  }

  bool uses(const std::string& other) const override {
    return std::find(ids_.begin(), ids_.end(), other) != ids_.end();
  }

  bool bounds(Vec3& lo, Vec3& hi) const override {
    if (!interior) return false;
    bool any = false;
    for (const std::string& sub : ids_) {
      Vec3 l, h;
      const bool bounded = region(sub)->bounds(l, h);
      if (!bounded) {
        if (union_) return false;  // one unbounded part: the union is unbounded
        continue;
      }
      if (!any) {
        lo = l;
        hi = h;
      } else {
        for (int d = 0; d < 3; ++d) {
          lo[d] = union_ ? std::min(lo[d], l[d]) : std::max(lo[d], l[d]);
          hi[d] = union_ ? std::max(hi[d], h[d]) : std::min(hi[d], h[d]);
        }
      }
      any = true;
    }
    return any;
  }

 private:
  const Region* region(const std::string& sub) const {
    return engine_.domain->region_or_error(sub, "region " + id + " (" + style + ")");
  }

  bool union_ = true;
  std::vector<std::string> ids_;
};

}  // namespace

GRANARY_REGION_STYLE("union", RegionCombined);
GRANARY_REGION_STYLE("intersect", RegionCombined);

}  // namespace granary
