// Mass properties of a union of (possibly overlapping) spheres by numerical
// integration: volume, centroid, inertia tensor and principal axes.
//
// The bounding box of the spheres is refined as an octree. A cell that lies
// inside one sphere is integrated exactly (box moments), a cell that touches no
// sphere is dropped, and cells on the surface are refined while the budget
// allows. The surface cells of the last level are integrated by stratified
// (jittered) Monte Carlo sampling with about `ntry` points in all. The estimate
// comes with a standard error computed from the sample variance of each cell
// (an upper estimate: jittering is more accurate than independent sampling)
// and a hard bound (the volume of the sampled cells).
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <vector>

#include "core/vec3.h"

namespace granary {

struct MassProperties {
  double volume = 0.0;   // [m^3]
  Vec3 centre{0, 0, 0};  // centroid [m]
  /// Inertia tensor about the centroid for unit density, tr(S) 1 - S with
  /// S = integral of (r - c)(r - c)^T dV [m^5]; multiply by the density.
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  Vec3 principal{0, 0, 0};  // eigenvalues of `inertia`, ascending [m^5]
  /// Principal axes as columns (right-handed rotation): a vector d in the
  /// principal frame is axes * d in the input frame.
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();

  double volume_error = 0.0;   // one standard error of the volume estimate [m^3]
  double inertia_error = 0.0;  // one standard error of trace(inertia) [m^5]
  double volume_bound = 0.0;   // total volume of the sampled cells: |error| <= this [m^3]
  long long samples = 0;       // points sampled
  int levels = 0;              // octree levels refined

  double relative_volume_error() const { return volume > 0 ? volume_error / volume : 0.0; }
  double relative_inertia_error() const {
    const double t = inertia.trace();
    return t > 0 ? inertia_error / t : 0.0;
  }
};

/// Integrate the union of spheres (centres, radii > 0) with about `ntry`
/// sample points (at least 8 per surface cell); deterministic for a given seed.
MassProperties sphere_union_properties(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                       long long ntry, std::uint64_t seed);

/// True when x lies inside at least one of the spheres.
bool inside_sphere_union(const std::vector<Vec3>& centres, const std::vector<double>& radii, const Vec3& x);

}  // namespace granary
