#include "geometry/tri_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace granary {

void TriMesh::set_triangles(const std::vector<Vec3>& corners) {
  node_.clear();
  tri_.clear();
  std::map<std::array<double, 3>, int> ids;
  const std::size_t ncorner_sets = corners.size() / 3;
  for (std::size_t t = 0; t < ncorner_sets; ++t) {
    std::array<int, 3> tr{};
    for (int c = 0; c < 3; ++c) {
      const Vec3& v = corners[3 * t + c];
      auto res = ids.emplace(std::array<double, 3>{v[0], v[1], v[2]}, static_cast<int>(node_.size()));
      if (res.second) node_.push_back(v);
      tr[c] = res.first->second;
    }
    const Vec3 &a = node_[tr[0]], &b = node_[tr[1]], &c = node_[tr[2]];
    const double longest = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    const double area2 = (b - a).cross(c - a).norm();
    if (tr[0] == tr[1] || tr[1] == tr[2] || tr[0] == tr[2] || !(area2 > 1e-12 * longest)) {
      throw std::invalid_argument(
          "triangle " + std::to_string(t + 1) +
          " is degenerate (zero area: two corners coincide or all three lie on a line)");
    }
    tri_.push_back(tr);
  }

  // edges: the triangles sharing each pair of nodes
  std::map<std::pair<int, int>, std::vector<int>> edges;  // -> 3 * tri + local edge
  for (int t = 0; t < ntri(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = tri_[t][k], b = tri_[t][(k + 1) % 3];
      edges[{std::min(a, b), std::max(a, b)}].push_back(3 * t + k);
    }
  edge_start_.assign(3 * tri_.size() + 1, 0);
  edge_nbr_.clear();
  for (int t = 0; t < ntri(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = tri_[t][k], b = tri_[t][(k + 1) % 3];
      for (int code : edges[{std::min(a, b), std::max(a, b)}])
        if (code != 3 * t + k) edge_nbr_.push_back(code);
      edge_start_[3 * t + k + 1] = static_cast<int>(edge_nbr_.size());
    }
  // node neighbours (the other ends of the edges leaving a node)
  std::vector<std::vector<int>> nbr(node_.size());
  for (const auto& e : edges) {
    nbr[e.first.first].push_back(e.first.second);
    nbr[e.first.second].push_back(e.first.first);
  }
  node_start_.assign(node_.size() + 1, 0);
  node_nbr_.clear();
  for (std::size_t k = 0; k < node_.size(); ++k) {
    node_nbr_.insert(node_nbr_.end(), nbr[k].begin(), nbr[k].end());
    node_start_[k + 1] = static_cast<int>(node_nbr_.size());
  }
  tri_force.assign(tri_.size(), Vec3::Zero());
  update_geometry();
  bin_start_.clear();
}

void TriMesh::update_geometry() {
  normal_.resize(tri_.size());
  inward_.resize(tri_.size());
  for (std::size_t t = 0; t < tri_.size(); ++t) {
    const Vec3 &a = node_[tri_[t][0]], &b = node_[tri_[t][1]], &c = node_[tri_[t][2]];
    normal_[t] = (b - a).cross(c - a).normalized();
    for (int k = 0; k < 3; ++k) {
      const Vec3 e = node_[tri_[t][(k + 1) % 3]] - node_[tri_[t][k]];
      inward_[t][k] = normal_[t].cross(e).normalized();
    }
  }
}

void TriMesh::translate(const Vec3& d) {
  ++moves_;
  for (Vec3& v : node_)
    v += d;
  lo_ += d;
}

void TriMesh::set_nodes(const std::vector<Vec3>& nodes) {
  ++moves_;
  node_ = nodes;
  update_geometry();
  bin_start_.clear();
}

// Closest point on a triangle (Ericson, Real-Time Collision Detection, 5.1.5),
// reporting which feature (face, edge, corner) it lies on.
Vec3 TriMesh::closest_point(int t, const Vec3& x, Feature& feature) const {
  const Vec3 &a = node_[tri_[t][0]], &b = node_[tri_[t][1]], &c = node_[tri_[t][2]];
  const Vec3 ab = b - a, ac = c - a, ap = x - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    feature = kNode0;
    return a;
  }
  const Vec3 bp = x - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    feature = kNode1;
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    feature = kEdge0;
    return a + (d1 / (d1 - d3)) * ab;
  }
  const Vec3 cp = x - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    feature = kNode2;
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    feature = kEdge2;
    return a + (d2 / (d2 - d6)) * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    feature = kEdge1;
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  feature = kFace;
  // the projection onto the plane: x minus its normal component
  const Vec3& n = normal_[t];
  return x - n.dot(ap) * n;
}

bool TriMesh::contact_valid(int t, Feature feature, const Vec3& p, const Vec3& x, double tol) const {
  if (feature == kFace) return true;
  const Vec3 d = x - p;
  const double limit = tol * d.norm();
  if (feature <= kEdge2) {
    const int k = feature - kEdge0;
    if (d.dot(inward_[t][k]) > limit) return false;
    for (int m = edge_start_[3 * t + k]; m < edge_start_[3 * t + k + 1]; ++m) {
      const int code = edge_nbr_[m];
      if (d.dot(inward_[code / 3][code % 3]) > limit) return false;
    }
    return true;
  }
  const int v = tri_[t][feature - kNode0];
  for (int m = node_start_[v]; m < node_start_[v + 1]; ++m) {
    const Vec3 e = node_[node_nbr_[m]] - node_[v];
    if (d.dot(e) > limit * e.norm()) return false;
  }
  return true;
}

void TriMesh::build_bins(double margin) {
  margin_ = margin;
  bin_start_.clear();
  bin_tri_.clear();
  if (tri_.empty()) return;
  Vec3 lo = node_[0], hi = node_[0];
  for (const Vec3& v : node_) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const double size = (hi - lo).maxCoeff();
  // slack: bins are tested against the triangles with a little more than the
  // margin, so round-off in the bin index of a point never loses a triangle
  const double slack = 1e-6 * margin + 1e-9 * size;
  const double reach = margin + slack;
  lo -= Vec3::Constant(reach);
  hi += Vec3::Constant(reach);
  const Vec3 ext = hi - lo;
  // bins about two margins wide (a sphere's reach), at most ~2 million of them
  double h = std::max(2.0 * margin, ext.maxCoeff() / 256.0);
  for (;;) {
    double count = 1.0;
    for (int d = 0; d < 3; ++d)
      count *= std::max(1.0, std::ceil(ext[d] / h));
    if (count <= 2.0e6) break;
    h *= 1.25;
  }
  for (int d = 0; d < 3; ++d)
    nbin_[d] = static_cast<int>(std::max(1.0, std::ceil(ext[d] / h)));
  lo_ = lo;
  inv_h_ = 1.0 / h;
  const double half_diag = 0.5 * std::sqrt(3.0) * h;
  std::vector<std::pair<std::size_t, int>> entries;
  for (int t = 0; t < ntri(); ++t) {
    Vec3 tlo = corner(t, 0), thi = corner(t, 0);
    for (int c = 1; c < 3; ++c) {
      tlo = tlo.cwiseMin(corner(t, c));
      thi = thi.cwiseMax(corner(t, c));
    }
    int b0[3], b1[3];
    for (int d = 0; d < 3; ++d) {
      b0[d] = std::clamp(static_cast<int>(std::floor((tlo[d] - reach - lo_[d]) * inv_h_)), 0, nbin_[d] - 1);
      b1[d] = std::clamp(static_cast<int>(std::floor((thi[d] + reach - lo_[d]) * inv_h_)), 0, nbin_[d] - 1);
    }
    auto test = [&](int i, int j, int k) {
      const Vec3 centre = lo_ + h * Vec3(i + 0.5, j + 0.5, k + 0.5);
      Feature f;
      if ((closest_point(t, centre, f) - centre).norm() > reach + half_diag) return;
      entries.emplace_back((static_cast<std::size_t>(k) * nbin_[1] + j) * nbin_[0] + i, t);
    };
    // Only bin centres within reach + half_diag of the triangle's plane can
    // pass the test: along the axis a where the normal is largest, that is a
    // few bins per column of the other two axes, not the whole bounding box
    // (a large tilted triangle would otherwise cost the cube of its bins).
    const Vec3 c0 = corner(t, 0);
    const Vec3 nrm = (corner(t, 1) - c0).cross(corner(t, 2) - c0);
    const double len = nrm.norm();
    if (!(len > 0.0) || !std::isfinite(len)) {  // degenerate: every bin of the box
      for (int k = b0[2]; k <= b1[2]; ++k)
        for (int j = b0[1]; j <= b1[1]; ++j)
          for (int i = b0[0]; i <= b1[0]; ++i)
            test(i, j, k);
      continue;
    }
    const Vec3 n = nrm / len;
    int a = 0;
    for (int d = 1; d < 3; ++d)
      if (std::fabs(n[d]) > std::fabs(n[a])) a = d;
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    const double along = (reach + half_diag) / std::fabs(n[a]);  // >= the plane distance allowed, along a
    int idx[3];
    for (idx[u] = b0[u]; idx[u] <= b1[u]; ++idx[u])
      for (idx[v] = b0[v]; idx[v] <= b1[v]; ++idx[v]) {
        const double xu = lo_[u] + h * (idx[u] + 0.5), xv = lo_[v] + h * (idx[v] + 0.5);
        // the plane's coordinate along a above this column's centre line
        const double xa = c0[a] - (n[u] * (xu - c0[u]) + n[v] * (xv - c0[v])) / n[a];
        const double f0 = std::floor((xa - along - lo_[a]) * inv_h_ - 0.5) - 1.0;
        const double f1 = std::ceil((xa + along - lo_[a]) * inv_h_ - 0.5) + 1.0;
        if (!(f1 >= b0[a]) || !(f0 <= b1[a])) continue;
        const int k0 = std::max(b0[a], static_cast<int>(std::max(f0, static_cast<double>(b0[a]))));
        const int k1 = std::min(b1[a], static_cast<int>(std::min(f1, static_cast<double>(b1[a]))));
        for (idx[a] = k0; idx[a] <= k1; ++idx[a])
          test(idx[0], idx[1], idx[2]);
      }
  }
  std::sort(entries.begin(), entries.end());
  const std::size_t nbins = static_cast<std::size_t>(nbin_[0]) * nbin_[1] * nbin_[2];
  bin_start_.assign(nbins + 1, 0);
  bin_tri_.resize(entries.size());
  for (std::size_t m = 0; m < entries.size(); ++m) {
    ++bin_start_[entries[m].first + 1];
    bin_tri_[m] = entries[m].second;
  }
  for (std::size_t b = 0; b < nbins; ++b)
    bin_start_[b + 1] += bin_start_[b];
}

}  // namespace granary
