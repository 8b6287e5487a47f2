// A triangle surface mesh used as a granular wall (fix mesh/surface).
//
// The mesh is small (hundreds to thousands of triangles) and replicated on
// every rank. It keeps:
//  * shared nodes and triangles as node triples (duplicate STL corners merged);
//  * per triangle: unit normal, and for each edge the unit in-plane vector
//    perpendicular to it pointing into the triangle, plus the triangles across
//    that edge; per node: its neighbour nodes. These drive the test that keeps
//    only the edge and corner contacts a sphere really has (see contact_valid);
//  * a uniform bin grid: every bin lists (in ascending order) the triangles
//    that come within `margin` of any point of the bin, so the triangles a
//    sphere of radius <= margin may touch are read from the one bin holding
//    its centre;
//  * the current velocity field of the wall material: a rigid motion
//    (translation velocity plus angular velocity about an origin, set by fix
//    move/mesh) and an optional per-triangle surface velocity (a conveyor belt,
//    fix mesh/surface surface_vel) that moves the material without moving the
//    nodes; and per-triangle forces of the current step (summed by the wall fixes).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/vec3.h"

namespace granary {

class TriMesh {
 public:
  /// Where the closest point of a triangle to a point lies.
  enum Feature : int { kFace = 0, kEdge0 = 1, kEdge1 = 2, kEdge2 = 3, kNode0 = 4, kNode1 = 5, kNode2 = 6 };

  /// Build from triangle corners (3 per triangle). Corners with identical
  /// coordinates become one node. Throws std::invalid_argument naming the
  /// first degenerate (zero-area) triangle.
  void set_triangles(const std::vector<Vec3>& corners);

  int ntri() const { return static_cast<int>(tri_.size()); }
  int nnodes() const { return static_cast<int>(node_.size()); }
  const Vec3& node(int k) const { return node_[k]; }
  const std::array<int, 3>& tri(int t) const { return tri_[t]; }
  const Vec3& corner(int t, int c) const { return node_[tri_[t][c]]; }
  const Vec3& normal(int t) const { return normal_[t]; }
  /// Area of triangle t [m^2].
  double area(int t) const {
    return 0.5 * (corner(t, 1) - corner(t, 0)).cross(corner(t, 2) - corner(t, 0)).norm();
  }

  /// Rigid translation of every node (the bin grid moves along).
  void translate(const Vec3& d);
  /// Node k at reference[k] + shift (a rigid translation of a reference
  /// configuration with the same node count; the bin grid moves along).
  void place(const std::vector<Vec3>& reference, const Vec3& shift) {
    ++moves_;
    lo_ += (reference[0] + shift) - node_[0];
    for (std::size_t k = 0; k < node_.size(); ++k)
      node_[k] = reference[k] + shift;
  }
  /// Replace all node positions (same count); normals and bins are rebuilt.
  void set_nodes(const std::vector<Vec3>& nodes);

  /// Closest point of triangle t to x and the feature it lies on.
  Vec3 closest_point(int t, const Vec3& x, Feature& feature) const;
  /// Whether a sphere centre x whose closest point on triangle t is p on
  /// `feature` lies in the Voronoi region of that feature on the whole mesh:
  /// faces always; an edge only if x is not on the inner side of any triangle
  /// sharing the edge; a node only if x makes no acute angle with any edge
  /// leaving the node. An edge between coplanar triangles (or a node inside a
  /// flat region) thus never makes a contact of its own.
  bool contact_valid(int t, Feature feature, const Vec3& p, const Vec3& x, double tol) const;

  /// Triangles that may come within `margin` of x (ascending indices); sets n.
  /// Valid for spheres of radius <= margin(); call ensure_margin first.
  const int* near(const Vec3& x, int& n) const {
    n = 0;
    if (bin_start_.empty()) return nullptr;
    int ijk[3];
    for (int d = 0; d < 3; ++d) {
      const double s = (x[d] - lo_[d]) * inv_h_;
      if (!(s >= 0.0) || s >= nbin_[d]) return nullptr;
      ijk[d] = static_cast<int>(s);
    }
    const std::size_t b = (static_cast<std::size_t>(ijk[2]) * nbin_[1] + ijk[1]) * nbin_[0] + ijk[0];
    n = bin_start_[b + 1] - bin_start_[b];
    return bin_tri_.data() + bin_start_[b];
  }
  double margin() const { return margin_; }
  /// Counts the changes of node positions (translate, place, set_nodes), so
  /// users can tell whether the geometry moved since they last looked.
  long long moves() const { return moves_; }
  /// Rebuild the bins when spheres of radius r are larger than the current margin.
  void ensure_margin(double r) {
    if (r > margin_ || bin_start_.empty()) build_bins(r > margin_ ? r : margin_);
  }

  /// Velocity of the wall material at point p of triangle t [m/s]: the rigid
  /// motion velocity + omega x (p - origin), plus the triangle's surface velocity.
  Vec3 velocity_at(int t, const Vec3& p) const {
    Vec3 v = velocity + omega.cross(p - origin);
    if (!surface_velocity.empty()) v += surface_velocity[t];
    return v;
  }

  Vec3 velocity = Vec3::Zero();        ///< translation velocity of the mesh [m/s]
  Vec3 omega = Vec3::Zero();           ///< angular velocity of the mesh about `origin` [rad/s]
  Vec3 origin = Vec3::Zero();          ///< a point on the rotation axis [m]
  std::vector<Vec3> surface_velocity;  ///< per triangle, tangential (empty: none) [m/s]
  std::vector<Vec3> tri_force;         ///< force of the particles on each triangle this step (this rank) [N]
  /// Moment about the coordinate origin of those forces, each taken at its
  /// contact point (this rank; sized by the stress meshes, empty otherwise) [N m]
  std::vector<Vec3> tri_moment;
  /// Finnie wear of each triangle accumulated by this rank's contacts (fix
  /// mesh/surface/stress wear finnie; empty otherwise) [kg/m^2]
  std::vector<double> tri_wear;

 private:
  void update_geometry();
  void build_bins(double margin);

  std::vector<Vec3> node_;
  std::vector<std::array<int, 3>> tri_;
  std::vector<Vec3> normal_;
  std::vector<std::array<Vec3, 3>> inward_;  // per edge k (corner k -> k+1): in-plane, into the triangle
  // triangles across edge k of triangle t: edge_nbr_[edge_start_[3t+k] .. edge_start_[3t+k+1])
  std::vector<int> edge_start_, edge_nbr_;
  // neighbour nodes of node k: node_nbr_[node_start_[k] .. node_start_[k+1])
  std::vector<int> node_start_, node_nbr_;

  long long moves_ = 0;
  Vec3 lo_ = Vec3::Zero();
  double inv_h_ = 1.0, margin_ = 0.0;
  int nbin_[3] = {0, 0, 0};
  std::vector<int> bin_start_, bin_tri_;
};

}  // namespace granary
