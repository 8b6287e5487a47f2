// Smoothing kernels of the SPH styles (pair_style sph/artVisc/tensCorr and the
// fix sph/... styles): LIGGGHTS' names cubicspline, cubicspline2d, wendland,
// wendland2d. Support 2h; W and dW/dr as functions of the distance r and the
// smoothing length h, normalised to unit integral in their dimension.
#pragma once

#include <cmath>
#include <string>

namespace granary::sph {

enum class Kernel { CubicSpline, CubicSpline2d, Wendland, Wendland2d };

/// The kernel of a LIGGGHTS name; false for an unknown name.
inline bool kernel_from_name(const std::string& name, Kernel& k) {
  if (name == "cubicspline")
    k = Kernel::CubicSpline;
  else if (name == "cubicspline2d")
    k = Kernel::CubicSpline2d;
  else if (name == "wendland")
    k = Kernel::Wendland;
  else if (name == "wendland2d")
    k = Kernel::Wendland2d;
  else
    return false;
  return true;
}

inline const char* kernel_names() {
  return "cubicspline, cubicspline2d, wendland or wendland2d";
}

inline bool kernel_is_2d(Kernel k) {
  return k == Kernel::CubicSpline2d || k == Kernel::Wendland2d;
}

/// Normalisation: 1/(pi h^3) and 10/(7 pi h^2) for the cubic spline (Monaghan
/// 1992), 21/(16 pi h^3) and 7/(4 pi h^2) for Wendland's C2 function.
inline double kernel_sigma(Kernel k, double h) {
  switch (k) {
    case Kernel::CubicSpline:
      return 1.0 / (M_PI * h * h * h);
    case Kernel::CubicSpline2d:
      return 10.0 / (7.0 * M_PI * h * h);
    case Kernel::Wendland:
      return 21.0 / (16.0 * M_PI * h * h * h);
    case Kernel::Wendland2d:
      return 7.0 / (4.0 * M_PI * h * h);
  }
  return 0.0;
}

/// W(r, h); zero for r >= 2h.
inline double kernel_w(Kernel k, double r, double h) {
  const double q = r / h;
  if (q >= 2.0) return 0.0;
  const double s = kernel_sigma(k, h);
  if (k == Kernel::CubicSpline || k == Kernel::CubicSpline2d) {
    if (q < 1.0) return s * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
    const double t = 2.0 - q;
    return s * 0.25 * t * t * t;
  }
  const double t = 1.0 - 0.5 * q;
  return s * t * t * t * t * (2.0 * q + 1.0);
}

/// dW/dr (r, h): negative inside the support, zero for r >= 2h.
inline double kernel_dw(Kernel k, double r, double h) {
  const double q = r / h;
  if (q >= 2.0) return 0.0;
  const double s = kernel_sigma(k, h) / h;
  if (k == Kernel::CubicSpline || k == Kernel::CubicSpline2d) {
    if (q < 1.0) return s * (-3.0 * q + 2.25 * q * q);
    const double t = 2.0 - q;
    return -s * 0.75 * t * t;
  }
  const double t = 1.0 - 0.5 * q;
  return -s * 5.0 * q * t * t * t;
}

}  // namespace granary::sph
