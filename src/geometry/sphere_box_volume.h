// Volume of the intersection of a sphere with an axis-aligned box.
//
// The volume is integrated along z over the exact area of the disc cut from
// the sphere at height z intersected with the box's x-y rectangle. That area
// has a closed form (inclusion-exclusion of four quadrant areas, each made of
// the primitive of sqrt(rho^2 - x^2)). Between the heights at which the
// disc's radius passes the distance of a rectangle edge or corner, and the
// box's own z faces, the area is analytic in z with at most algebraic
// singularities (t^(1/2), t^(3/2)) at the ends; each such piece is
// integrated with double-exponential (tanh-sinh) quadrature, which converges
// to round-off for integrands of that kind. The common cases are exact in
// closed form: wholly inside (4/3 pi r^3), wholly outside (0), the box inside
// the sphere (the box volume) and a sphere cut only by the faces normal to one
// axis (sphere minus caps pi h^2 (3r - h) / 3).
//
// Accuracy: relative error below 1e-12 of the sphere volume in every
// configuration tested (faces, edges, corners, boxes thinner than the
// sphere, tangencies), against closed forms and Monte Carlo.
#pragma once

#include "core/vec3.h"

namespace granary {

/// Volume of {|p - centre| <= r} intersected with [lo, hi] (component-wise).
/// Empty when r <= 0 or when some hi < lo.
double sphere_box_volume(const Vec3& centre, double r, const Vec3& lo, const Vec3& hi);

/// Volume of a spherical cap of height h (0 <= h <= 2r) of a sphere of radius r.
double sphere_cap_volume(double r, double h);

}  // namespace granary
