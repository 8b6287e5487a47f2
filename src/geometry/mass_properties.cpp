#include "geometry/mass_properties.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace granary {

namespace {

struct Cell {
  Vec3 lo, hi;
  std::vector<int> candidates;  // spheres that cut the cell without containing it
};

enum class Kind { Outside, Inside, Surface };

/// Classify a cell against the spheres listed in `from` (all when null).
Kind classify(const Vec3& lo, const Vec3& hi, const std::vector<Vec3>& c, const std::vector<double>& r,
              const std::vector<int>* from, std::vector<int>& cut) {
  cut.clear();
  const int n = from ? static_cast<int>(from->size()) : static_cast<int>(c.size());
  for (int k = 0; k < n; ++k) {
    const int s = from ? (*from)[k] : k;
    double dmin2 = 0.0, dmax2 = 0.0;
    for (int d = 0; d < 3; ++d) {
      const double a = lo[d] - c[s][d], b = c[s][d] - hi[d];
      const double near = std::max({a, b, 0.0});
      const double far = std::max(std::fabs(a), std::fabs(b));
      dmin2 += near * near;
      dmax2 += far * far;
    }
    const double r2 = r[s] * r[s];
    if (dmax2 <= r2) return Kind::Inside;  // spheres are convex: all corners inside
    if (dmin2 < r2) cut.push_back(s);
  }
  return cut.empty() ? Kind::Outside : Kind::Surface;
}

/// Running sums of the moments about a fixed origin.
struct Moments {
  double v = 0.0;
  Vec3 s1{0, 0, 0};
  Eigen::Matrix3d s2 = Eigen::Matrix3d::Zero();
  double var_v = 0.0, var_t = 0.0;  // variance of the volume and of the trace of s2

  void add_box(const Vec3& lo, const Vec3& hi) {
    const Vec3 e = hi - lo, m = 0.5 * (lo + hi);
    const double vol = e[0] * e[1] * e[2];
    v += vol;
    s1 += vol * m;
    s2 += vol * m * m.transpose();
    for (int d = 0; d < 3; ++d)
      s2(d, d) += vol * e[d] * e[d] / 12.0;
  }
};

}  // namespace

bool inside_sphere_union(const std::vector<Vec3>& centres, const std::vector<double>& radii, const Vec3& x) {
  for (std::size_t k = 0; k < centres.size(); ++k)
    if ((x - centres[k]).squaredNorm() <= radii[k] * radii[k]) return true;
  return false;
}

MassProperties sphere_union_properties(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                       long long ntry, std::uint64_t seed) {
  if (centres.empty() || centres.size() != radii.size()) {
    throw std::invalid_argument("mass properties need one radius per sphere and at least one sphere");
  }
  for (double r : radii)
    if (!(r > 0.0)) throw std::invalid_argument("sphere radii must be positive");
  ntry = std::max(ntry, 1000LL);

  // bounding box; moments are summed about its centre to limit round-off
  Vec3 lo = centres[0] - Vec3::Constant(radii[0]), hi = centres[0] + Vec3::Constant(radii[0]);
  for (std::size_t k = 1; k < centres.size(); ++k) {
    lo = lo.cwiseMin(centres[k] - Vec3::Constant(radii[k]));
    hi = hi.cwiseMax(centres[k] + Vec3::Constant(radii[k]));
  }
  const Vec3 origin = 0.5 * (lo + hi);
  std::vector<Vec3> c(centres.size());
  for (std::size_t k = 0; k < c.size(); ++k)
    c[k] = centres[k] - origin;
  lo -= origin;
  hi -= origin;

  MassProperties out;
  Moments m;
  std::vector<Cell> level;
  {
    Cell root{lo, hi, {}};
    const Kind kind = classify(lo, hi, c, radii, nullptr, root.candidates);
    if (kind == Kind::Inside) m.add_box(lo, hi);  // cannot happen for spheres, kept for clarity
    if (kind == Kind::Surface) level.push_back(std::move(root));
  }

  // Refine while the next level is expected to keep >= 8 samples per cell
  // (surface cells multiply by about 4 per level); the surface cells of the
  // last level are sampled.
  constexpr int kMaxLevels = 40;
  std::vector<int> cut;
  std::mt19937_64 gen(seed);
  auto uniform01 = [&gen]() { return static_cast<double>(gen() >> 11) * 0x1.0p-53; };
  // Jittered sampling of one surface cell with k^3 points.
  auto sample = [&](const Vec3& clo, const Vec3& chi, const std::vector<int>& candidates, int k) {
    const int npts = k * k * k;
    const Vec3 e = chi - clo;
    const double vol = e[0] * e[1] * e[2];
    const double w = vol / npts;
    out.volume_bound += vol;
    int inside = 0;
    double sum_t = 0.0, sum_t2 = 0.0;
    for (int ix = 0; ix < k; ++ix) {
      for (int iy = 0; iy < k; ++iy) {
        for (int iz = 0; iz < k; ++iz) {
          const Vec3 x(clo[0] + (ix + uniform01()) * e[0] / k, clo[1] + (iy + uniform01()) * e[1] / k,
                       clo[2] + (iz + uniform01()) * e[2] / k);
          bool in = false;
          for (int s : candidates) {
            if ((x - c[s]).squaredNorm() <= radii[s] * radii[s]) {
              in = true;
              break;
            }
          }
          if (!in) continue;
          ++inside;
          m.v += w;
          m.s1 += w * x;
          m.s2 += w * x * x.transpose();
          const double t = x.squaredNorm();
          sum_t += t;
          sum_t2 += t * t;
        }
      }
    }
    out.samples += npts;
    // sample variances of the indicator and of |x|^2 times the indicator
    const double p = static_cast<double>(inside) / npts;
    const double var_in = p * (1.0 - p) * npts / (npts - 1.0);
    const double mean_t = sum_t / npts;
    const double var_t = std::max(0.0, (sum_t2 / npts - mean_t * mean_t) * npts / (npts - 1.0));
    m.var_v += vol * vol * var_in / npts;
    m.var_t += vol * vol * var_t / npts;
  };
  auto samples_per_cell = [&](std::size_t ncells) {
    const double per_cell = static_cast<double>(ntry) / static_cast<double>(ncells);
    return std::max(2, static_cast<int>(std::floor(std::cbrt(per_cell) + 1e-9)));
  };
  auto octant = [](const Cell& cell, int oct, Vec3& a, Vec3& b) {
    const Vec3 mid = 0.5 * (cell.lo + cell.hi);
    for (int d = 0; d < 3; ++d) {
      const bool upper = (oct >> d) & 1;
      a[d] = upper ? mid[d] : cell.lo[d];
      b[d] = upper ? cell.hi[d] : mid[d];
    }
  };
  // (The root is refined: ntry >= 1000 >= 32 cells. Every later level is
  // refined only while the test below says it is not the last.)
  while (!level.empty()) {
    // Count the next level's surface cells first: when it is the last level
    // (too many cells to refine further) its cells are sampled as they are
    // made instead of being stored, which would take most of the memory.
    std::size_t nnext = 0;
    Vec3 a, b;
    for (const Cell& cell : level) {
      for (int oct = 0; oct < 8; ++oct) {
        octant(cell, oct, a, b);
        if (classify(a, b, c, radii, &cell.candidates, cut) == Kind::Surface) ++nnext;
      }
    }
    const bool last = nnext == 0 || out.levels + 1 >= kMaxLevels ||
                      32.0 * static_cast<double>(nnext) > static_cast<double>(ntry);
    std::vector<Cell> next;
    if (!last) next.reserve(nnext);
    const int k = last && nnext > 0 ? samples_per_cell(nnext) : 0;
    // interior boxes of the whole level first, then the samples (the order
    // in which the moments are summed)
    for (const Cell& cell : level) {
      for (int oct = 0; oct < 8; ++oct) {
        octant(cell, oct, a, b);
        const Kind kind = classify(a, b, c, radii, &cell.candidates, cut);
        if (kind == Kind::Inside)
          m.add_box(a, b);
        else if (kind == Kind::Surface && !last)
          next.push_back(Cell{a, b, cut});
      }
    }
    ++out.levels;
    if (last) {
      for (const Cell& cell : level) {
        for (int oct = 0; oct < 8; ++oct) {
          octant(cell, oct, a, b);
          if (classify(a, b, c, radii, &cell.candidates, cut) == Kind::Surface) sample(a, b, cut, k);
        }
      }
      break;
    }
    level.swap(next);
  }
  if (!(m.v > 0.0)) throw std::invalid_argument("the spheres enclose no volume");

  out.volume = m.v;
  const Vec3 cm = m.s1 / m.v;
  out.centre = origin + cm;
  const Eigen::Matrix3d s = m.s2 - m.v * cm * cm.transpose();
  out.inertia = s.trace() * Eigen::Matrix3d::Identity() - s;
  out.inertia = 0.5 * (out.inertia + out.inertia.transpose()).eval();
  out.volume_error = std::sqrt(m.var_v);
  // trace(inertia) = 2 trace(S): its error follows from that of the |x|^2 integral
  out.inertia_error = 2.0 * std::sqrt(m.var_t);

  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(out.inertia);
  out.principal = eig.eigenvalues();
  out.axes = eig.eigenvectors();
  if (out.axes.determinant() < 0.0) out.axes.col(2) *= -1.0;
  return out;
}

}  // namespace granary
