#include "geometry/sphere_box_volume.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace granary {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Primitive of sqrt(rho^2 - t^2) from -rho to x (x clamped to [-rho, rho]).
double half_disc_primitive(double x, double rho) {
  if (x <= -rho) return 0.0;
  if (x >= rho) return 0.5 * kPi * rho * rho;
  const double s = std::sqrt(std::max(0.0, rho * rho - x * x));
  return 0.5 * (x * s + rho * rho * std::asin(std::clamp(x / rho, -1.0, 1.0))) + 0.25 * kPi * rho * rho;
}

/// Area of the disc of radius rho centred at the origin with x < a and y < b.
double quadrant_area(double a, double b, double rho) {
  if (a <= -rho || b <= -rho) return 0.0;
  const double u = std::min(a, rho);
  if (b >= rho) return 2.0 * half_disc_primitive(u, rho);
  const double c = std::sqrt(std::max(0.0, rho * rho - b * b));  // |x| < c: the line y = b cuts the disc
  if (b >= 0.0) {
    // 2 s(x) outside |x| < c, b + s(x) inside
    double area = 2.0 * half_disc_primitive(u, rho);
    if (u > -c) {
      const double m = std::min(u, c);
      area -= (half_disc_primitive(m, rho) - half_disc_primitive(-c, rho)) - b * (m + c);
    }
    return area;
  }
  // b < 0: only |x| < c contributes, b + s(x)
  if (u <= -c) return 0.0;
  const double m = std::min(u, c);
  return (half_disc_primitive(m, rho) - half_disc_primitive(-c, rho)) + b * (m + c);
}

/// Area of the disc of radius rho centred at the origin inside [x0,x1] x [y0,y1].
double disc_rect_area(double rho, double x0, double x1, double y0, double y1) {
  if (rho <= 0.0) return 0.0;
  const double a = quadrant_area(x1, y1, rho) - quadrant_area(x0, y1, rho) - quadrant_area(x1, y0, rho) +
                   quadrant_area(x0, y0, rho);
  return std::max(0.0, a);
}

/// Tanh-sinh nodes on (-1, 1): distance of each node from its nearer end
/// (computed without cancellation), its sign, and its weight.
struct TanhSinh {
  std::vector<double> gap, weight;
  std::vector<int> side;  // -1: measured from -1, +1: from +1, 0: the centre
  TanhSinh() {
    const double h = 1.0 / 16.0;
    for (int k = -64; k <= 64; ++k) {
      const double t = k * h;
      const double v = 0.5 * kPi * std::sinh(std::fabs(t));
      const double e = std::exp(-2.0 * v);
      const double g = 2.0 * e / (1.0 + e);  // 1 - tanh(v)
      const double ch = std::cosh(v);
      const double w = h * 0.5 * kPi * std::cosh(t) / (ch * ch);
      if (w < 1e-300 || g <= 0.0) continue;
      gap.push_back(g);
      weight.push_back(w);
      side.push_back(k < 0 ? -1 : (k > 0 ? 1 : 0));
    }
  }
};

const TanhSinh& nodes() {
  static const TanhSinh ts;
  return ts;
}

}  // namespace

double sphere_cap_volume(double r, double h) {
  h = std::clamp(h, 0.0, 2.0 * r);
  return kPi * h * h * (3.0 * r - h) / 3.0;
}

double sphere_box_volume(const Vec3& centre, double r, const Vec3& lo_in, const Vec3& hi_in) {
  if (!(r > 0.0)) return 0.0;
  // box relative to the centre
  std::array<double, 3> lo, hi;
  for (int d = 0; d < 3; ++d) {
    lo[d] = lo_in[d] - centre[d];
    hi[d] = hi_in[d] - centre[d];
    if (!(hi[d] >= lo[d])) return 0.0;
    if (hi[d] <= -r || lo[d] >= r) return 0.0;  // no overlap along d
  }
  const double vsphere = 4.0 / 3.0 * kPi * r * r * r;
  // dimensions along which a face cuts the sphere
  int ncut = 0, cut_dim = -1;
  for (int d = 0; d < 3; ++d) {
    if (lo[d] > -r || hi[d] < r) {
      ++ncut;
      cut_dim = d;
    }
  }
  if (ncut == 0) return vsphere;
  if (ncut == 1) {
    // slab: the sphere minus the caps beyond the two faces
    const int d = cut_dim;
    return std::max(0.0, vsphere - (lo[d] > -r ? sphere_cap_volume(r, lo[d] + r) : 0.0) -
                             (hi[d] < r ? sphere_cap_volume(r, r - hi[d]) : 0.0));
  }
  // box inside the sphere: its farthest corner is within r
  {
    double far2 = 0.0;
    for (int d = 0; d < 3; ++d)
      far2 += std::max(lo[d] * lo[d], hi[d] * hi[d]);
    if (far2 <= r * r) return (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  }
  // integrate along the axis z over the disc-rectangle area
  const double x0 = lo[0], x1 = hi[0], y0 = lo[1], y1 = hi[1];
  const double za = std::max(lo[2], -r), zb = std::min(hi[2], r);
  if (!(zb > za)) return 0.0;
  // heights where the disc radius passes an edge line or a corner distance
  std::vector<double> breaks = {za, zb};
  auto add_distance = [&](double dist2) {
    if (dist2 < r * r) {
      const double z = std::sqrt(r * r - dist2);
      for (double zz : {z, -z})
        if (zz > za && zz < zb) breaks.push_back(zz);
    }
  };
  for (double x : {x0, x1})
    add_distance(x * x);
  for (double y : {y0, y1})
    add_distance(y * y);
  for (double x : {x0, x1})
    for (double y : {y0, y1})
      add_distance(x * x + y * y);
  if (0.0 > za && 0.0 < zb) breaks.push_back(0.0);
  std::sort(breaks.begin(), breaks.end());
  const TanhSinh& ts = nodes();
  auto area = [&](double z) {
    const double rho2 = r * r - z * z;
    return rho2 > 0.0 ? disc_rect_area(std::sqrt(rho2), x0, x1, y0, y1) : 0.0;
  };
  double volume = 0.0;
  for (std::size_t k = 0; k + 1 < breaks.size(); ++k) {
    const double a = breaks[k], b = breaks[k + 1];
    const double half = 0.5 * (b - a);
    if (!(half > 0.0)) continue;
    double sum = 0.0;
    for (std::size_t n = 0; n < ts.gap.size(); ++n) {
      double z;
      if (ts.side[n] < 0)
        z = a + half * ts.gap[n];
      else if (ts.side[n] > 0)
        z = b - half * ts.gap[n];
      else
        z = a + half;
      sum += ts.weight[n] * area(z);
    }
    volume += half * sum;
  }
  return std::clamp(volume, 0.0, vsphere);
}

}  // namespace granary
