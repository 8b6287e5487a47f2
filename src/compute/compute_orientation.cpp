// compute ID group orientation axis AX AY AZ [region R] [bins N]
//
// Orientation of the clumps of fix multisphere relative to a direction A: for
// each clump whose centre of mass lies in region R (all clumps without one),
// theta is the angle between its long axis (the principal axis of the smallest
// moment of inertia, body axis x) and A, folded into [0, pi/2] because an axis
// has no sense. Global vector (size 4 + N):
//   1 mean theta [rad]   2 mean |cos theta|   3 order parameter <P2(cos theta)>
//   = <(3 cos^2 theta - 1) / 2> (1: all parallel to A, 0: isotropic, -1/2: all
//   perpendicular)   4 number of clumps counted   5..4+N fraction of them with
//   theta in bin k of N equal bins over [0, pi/2] (default N = 9, 10 degrees).
// Global scalar: the order parameter. The group is ignored.
#include <cmath>

#include "compute/compute.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "particles/clumps.h"
#include "core/modify.h"

namespace granary {

namespace {

class ComputeOrientation : public Compute {
 public:
  ComputeOrientation(Engine& engine, const Args& args) : Compute(engine, args) {
    const std::string usage = "compute ID group-ID orientation axis AX AY AZ [region R] [bins N]";
    if (args.size() < 7 || (args[3] != "axis" && args[3] != "AXIS")) throw InputError("usage: " + usage);
    for (int d = 0; d < 3; ++d)
      axis_[d] = parse_double(args[4 + d], "compute orientation axis");
    if (!(axis_.norm() > 0.0)) throw InputError("compute " + id + " orientation: the axis must not be zero");
    axis_.normalize();
    for (std::size_t k = 7; k < args.size(); k += 2) {
      if (k + 1 >= args.size())
        throw InputError("compute orientation keyword '" + args[k] + "' needs a value");
      if (args[k] == "region") {
        region_id_ = args[k + 1];
        engine.domain->region_or_error(region_id_, "compute " + id + " orientation");
      } else if (args[k] == "bins") {
        nbins_ = static_cast<int>(parse_int(args[k + 1], "compute orientation bins"));
        if (nbins_ < 1 || nbins_ > 100000) throw InputError("compute orientation bins must be in 1..100000");
      } else {
        throw InputError("unknown compute orientation keyword '" + args[k] + "'; usage: " + usage);
      }
    }
    scalar_flag = true;
    size_vector = 4 + nbins_;
  }

  void init() override {
    if (!engine_.clumps) {
      throw InputError("compute " + id + " orientation needs fix multisphere (it measures clump axes)");
    }
    if (!region_id_.empty()) engine_.domain->region_or_error(region_id_, "compute " + id + " orientation");
  }

  double compute_scalar() override {
    compute_vector();
    scalar = vector[2];
    return scalar;
  }

  void compute_vector() override {
    Clumps* ms = engine_.clumps;
    if (!ms) throw InputError("compute " + id + " orientation needs fix multisphere");
    ms->sync_bodies();
    const Region* region =
        region_id_.empty() ? nullptr
                           : engine_.domain->region_or_error(region_id_, "compute " + id + " orientation");
    const Bodies& B = ms->bodies();
    vector.assign(4 + nbins_, 0.0);
    double count = 0.0;
    // every rank holds every (synchronised) body: the same values everywhere
    for (int b = 0; b < B.size(); ++b) {
      if (region && !region->match(ms->wrapped_centre(b))) continue;
      const Vec3 long_axis = B.quat[b] * Vec3(1.0, 0.0, 0.0);
      const double c = std::min(1.0, std::fabs(long_axis.dot(axis_)));
      const double theta = std::acos(c);
      vector[0] += theta;
      vector[1] += c;
      vector[2] += 0.5 * (3.0 * c * c - 1.0);
      const int bin = std::min(nbins_ - 1, static_cast<int>(theta / (0.5 * M_PI) * nbins_));
      vector[4 + bin] += 1.0;
      count += 1.0;
    }
    vector[3] = count;
    if (count > 0) {
      for (int k = 0; k < 3; ++k)
        vector[k] /= count;
      for (int k = 0; k < nbins_; ++k)
        vector[4 + k] /= count;
    }
  }

 private:
  Vec3 axis_{0, 0, 1};
  std::string region_id_;
  int nbins_ = 9;
};

}  // namespace

GRANARY_COMPUTE_STYLE("orientation", ComputeOrientation);

}  // namespace granary
