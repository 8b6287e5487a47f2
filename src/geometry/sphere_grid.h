// Spheres hashed into cells of the box, for overlap tests during insertion
// and random particle creation (periodic images included), and for the
// neighbours within a distance of compute coord/atom.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "core/vec3.h"
#include "domain/domain.h"

namespace granary {

/// Spheres of radius up to rmax in cells 2 rmax wide; queries include the
/// periodic images of the query sphere. The cells of the box (and two cells
/// around it) are a dense table of linked lists when there are not too many
/// of them; cells outside it, or all cells of a huge sparse box, are hashed.
class SphereGrid {
 public:
  SphereGrid(const Domain& dom, double rmax) : dom_(dom), rmax_(rmax), cell_(2.0 * rmax) {
    double total = 1.0;
    for (int d = 0; d < 3; ++d) {
      const double n = std::ceil(dom.prd[d] / cell_) + 2 * kMargin;
      n_[d] = n < 1e9 ? static_cast<long long>(n) : 0;
      total *= n;
    }
    if (total > 0.0 && total <= kMaxDense) head_.assign(static_cast<std::size_t>(total), -1);
  }

  /// Add a sphere; x must lie inside the box in periodic dimensions.
  void add(const Vec3& x, double r) {
    const int n = static_cast<int>(centres_.size());
    centres_.push_back(x);
    radii_.push_back(r);
    const auto c = cell(x);
    const long long at = dense_index(c);
    if (at >= 0) {
      next_.push_back(head_[at]);
      head_[at] = n;
    } else {
      next_.push_back(-1);
      cells_[key(c)].push_back(n);
    }
  }

  /// True when (x, r) overlaps a stored sphere (distance < sum of radii).
  bool overlaps(const Vec3& x, double r) const {
    return visit_overlapping(x, r, true, [](int) { return true; });
  }

  /// Call fn(n) for every stored sphere n (in the order added) that (x, r)
  /// overlaps, and with `images` for those its periodic images overlap, until
  /// fn returns true. Returns whether fn stopped the visit.
  template <class Fn>
  bool visit_overlapping(const Vec3& x, double r, bool images, Fn&& fn) const {
    int shifts[3][3], count[3];
    const double reach = r + rmax_;
    for (int d = 0; d < 3; ++d) {
      count[d] = 0;
      shifts[d][count[d]++] = 0;
      if (images && dom_.periodic[d]) {
        if (x[d] - dom_.boxlo[d] < reach) shifts[d][count[d]++] = 1;
        if (dom_.boxhi[d] - x[d] < reach) shifts[d][count[d]++] = -1;
      }
    }
    auto near = [&](int n, const Vec3& xs) {
      const double s = r + radii_[n];
      return (centres_[n] - xs).squaredNorm() < s * s && fn(n);
    };
    for (int a = 0; a < count[0]; ++a) {
      for (int b = 0; b < count[1]; ++b) {
        for (int c = 0; c < count[2]; ++c) {
          const Vec3 xs =
              x + Vec3(shifts[0][a] * dom_.prd[0], shifts[1][b] * dom_.prd[1], shifts[2][c] * dom_.prd[2]);
          const auto base = cell(xs);
          for (long long i = base[0] - 1; i <= base[0] + 1; ++i) {
            for (long long j = base[1] - 1; j <= base[1] + 1; ++j) {
              for (long long k = base[2] - 1; k <= base[2] + 1; ++k) {
                const long long at = dense_index({i, j, k});
                if (at >= 0) {
                  for (int n = head_[at]; n >= 0; n = next_[n])
                    if (near(n, xs)) return true;
                  continue;
                }
                if (cells_.empty()) continue;
                auto it = cells_.find(key({i, j, k}));
                if (it == cells_.end()) continue;
                for (int n : it->second)
                  if (near(n, xs)) return true;
              }
            }
          }
        }
      }
    }
    return false;
  }

 private:
  static constexpr long long kMargin = 2;     // dense cells beyond each box face
  static constexpr double kMaxDense = 8.0e6;  // largest dense table (cells)
  /// Position of cell c in the dense table, -1 when outside it (or no table).
  long long dense_index(const std::array<long long, 3>& c) const {
    if (head_.empty()) return -1;
    long long at = 0;
    for (int d = 2; d >= 0; --d) {
      const long long k = c[d] + kMargin;
      if (k < 0 || k >= n_[d]) return -1;
      at = at * n_[d] + k;
    }
    return at;
  }
  std::array<long long, 3> cell(const Vec3& x) const {
    std::array<long long, 3> c;
    for (int d = 0; d < 3; ++d)
      c[d] = static_cast<long long>(std::floor((x[d] - dom_.boxlo[d]) / cell_));
    return c;
  }
  static std::uint64_t key(const std::array<long long, 3>& c) {
    const std::uint64_t m = (1ull << 21) - 1;
    return (static_cast<std::uint64_t>(c[0]) & m) | (static_cast<std::uint64_t>(c[1]) & m) << 21 |
           (static_cast<std::uint64_t>(c[2]) & m) << 42;
  }
  const Domain& dom_;
  double rmax_, cell_;
  long long n_[3] = {0, 0, 0};  // dense table size per dimension
  std::vector<int> head_;       // first sphere of each dense cell, -1: none
  std::vector<int> next_;       // next sphere in the same dense cell
  std::vector<Vec3> centres_;
  std::vector<double> radii_;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

}  // namespace granary
