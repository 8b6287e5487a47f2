// Liquid bridges of pair_style gran (see liquid_bridge.h).
#include "pair/liquid_bridge.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/force.h"
#include "core/global_property.h"
#include "core/modify.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"

namespace granary {

namespace {
const char* kContentField = "surfaceLiquidContent";
const char* kBridgeField = "liquidBridge";

double sphere_volume(double r) {
  return 4.0 / 3.0 * M_PI * r * r * r;
}

// The part of a sphere's surface inside the cone from its centre tangent to
// the other sphere: (1 - cos a)/2 with sin a = r_other / (r + r_other).
double cap_fraction(double r, double r_other) {
  const double s = r_other / (r + r_other);
  return 0.5 * (1.0 - std::sqrt(1.0 - s * s));
}
}  // namespace

LiquidBridge::LiquidBridge(Engine& engine, contact::CohesionModel model, bool modify_lb_volume,
                           std::string user)
    : engine_(engine), model_(model), modify_lb_volume_(modify_lb_volume), user_(std::move(user)) {}

double LiquidBridge::easo_volume(double ri, double rj, double ci, double cj) {
  return ci * sphere_volume(ri) * cap_fraction(ri, rj) + cj * sphere_volume(rj) * cap_fraction(rj, ri);
}

double LiquidBridge::capillary(double ri, double rj, double s, double vb, double theta) const {
  if (model_ == contact::CohesionModel::Easo) {
    const double r2 = std::max(ri, rj);
    const double vs = vb / (r2 * r2 * r2);
    const double l = std::log(vs);
    const double a = -1.1 * std::pow(vs, -0.53);
    const double b = (-0.148 * l - 0.96) * theta * theta - 0.0082 * l + 0.48;
    const double c = 0.0018 * l + 0.078;
    return M_PI * gamma_ * std::sqrt(ri * rj) * (std::exp(a * std::max(s, 0.0) / r2 + b) + c);
  }
  const double reff = ri * rj / (ri + rj);
  // overlapping: LIGGGHTS 3.8's force (measured: exact at overlaps of 1e-7
  // to 5e-5 m for bridge volumes 1e-3 to 1 times apart), which grows with the
  // overlap from the limit of Rabinovich's first term at contact
  if (s <= 0.0)
    return 2.0 * M_PI * reff * gamma_ * std::cos(theta) * (1.0 - s / std::sqrt(2.0 * vb / (M_PI * reff)));
  const double p = -1.0 + std::sqrt(1.0 + 2.0 * vb / (M_PI * reff * s * s));
  const double alpha = std::sqrt(s * p / reff);
  // s / (2 d) with d = s p / 2 is 1 / p
  return 2.0 * M_PI * reff * gamma_ *
         (std::cos(theta) / (1.0 + 1.0 / p) + std::sin(alpha) * std::sin(alpha + theta));
}

void LiquidBridge::init() {
  const Modify& m = *engine_.modify;
  Particles& p = *engine_.particles;
  const std::string by = user_;
  auto scalar = [&](const char* name) { return m.require_property(name, by).scalar(); };
  min_sep_ = scalar("minSeparationDistanceRatio");
  max_sep_ = scalar("maxSeparationDistanceRatio");
  c0_ = scalar("surfaceLiquidContentInitial");
  gamma_ = scalar("surfaceTension");
  mu_ = scalar("fluidViscosity");
  if (modify_lb_volume_) lb_fraction_ = scalar("lbVolumeFraction");
  auto bad = [&](const std::string& what) { throw InputError(by + ": " + what + " (fix property/global)"); };
  if (!(min_sep_ >= 1.0)) bad("minSeparationDistanceRatio must be >= 1 (recommended 1.01)");
  if (!(max_sep_ > 1.0)) bad("maxSeparationDistanceRatio must be > 1 (recommended 1.1)");
  if (!(c0_ >= 0.0)) bad("surfaceLiquidContentInitial must be >= 0 (% of the solid volume)");
  if (!(gamma_ >= 0.0)) bad("surfaceTension must be >= 0 [N/m]");
  if (!(mu_ >= 0.0)) bad("fluidViscosity must be >= 0 [Pa s]");
  if (!(lb_fraction_ > 0.0)) bad("lbVolumeFraction must be > 0");
  const GlobalProperty& angle = m.require_property("contactAngle", by);
  angle_.assign(p.ntypes + 1, 0.0);
  for (int t = 1; t <= p.ntypes; ++t) {
    const double deg = angle.per_type(t);
    if (!(deg >= 0.0 && deg <= 180.0)) bad("contactAngle must lie in [0, 180] degrees");
    angle_[t] = deg * M_PI / 180.0;
  }
  if (model_ == contact::CohesionModel::Easo && engine_.force->newton_pair)
    throw InputError(by +
                     ": cohesion easo/capillary/viscous needs 'newton off' (each rank keeps the "
                     "bridges of its own particles); put 'newton off' before the run");

  // the liquid content, as LIGGGHTS' fix property/atom surfaceLiquidContent
  // (one defined already, by the script or an earlier run, keeps its values)
  if (engine_.modify->find_fix(kContentField)) {
    if (p.find_field(kContentField) < 0 || p.extras[p.find_field(kContentField)].ncomp != 1)
      throw InputError(by + ": fix ID " + kContentField +
                       " is taken by another fix; the liquid content needs it (a scalar property/atom)");
  } else {
    char c0[64];
    std::snprintf(c0, sizeof c0, "%.17g", c0_);
    engine_.modify->add_fix(
        {kContentField, "all", "property/atom", kContentField, "scalar", "yes", "yes", "no", c0});
  }
  content_ = p.find_field(kContentField);
  p.extras[content_].history = true;  // transfers of a run's setup forces are undone
  if (model_ == contact::CohesionModel::Easo) {
    bridges_ = p.add_field(kBridgeField, kStride, false, true);
    p.extras[bridges_].history = true;
  }
  engine_.neighbor->range_factor = max_sep_;
}

int LiquidBridge::find(int i, double partner) const {
  const double* row = engine_.particles->extras[bridges_].data.data() + static_cast<std::size_t>(i) * kStride;
  const int n = static_cast<int>(row[0]);
  for (int s = 0; s < n; ++s)
    if (row[1 + s] == partner) return s;
  return -1;
}

void LiquidBridge::add(int i, double partner) {
  Particles& p = *engine_.particles;
  double* row = p.extras[bridges_].data.data() + static_cast<std::size_t>(i) * kStride;
  const int n = static_cast<int>(row[0]);
  if (n >= kSlots)
    throw RunError(user_ + ": particle " + std::to_string(p.id[i]) + " has more than " +
                   std::to_string(kSlots) +
                   " liquid bridges at once; Granary keeps at most that many per particle (spheres far "
                   "smaller than their neighbours: use a narrower size distribution)");
  row[1 + n] = partner;
  row[0] = n + 1;
  seen_[static_cast<std::size_t>(i) * kSlots + n] = 1;
}

// The last record takes the place of the removed one (its seen flag with it).
void LiquidBridge::remove(int i, int slot) {
  double* row = engine_.particles->extras[bridges_].data.data() + static_cast<std::size_t>(i) * kStride;
  const int last = static_cast<int>(row[0]) - 1;
  row[1 + slot] = row[1 + last];
  unsigned char* seen = seen_.data() + static_cast<std::size_t>(i) * kSlots;
  seen[slot] = seen[last];
  seen[last] = 0;
  row[0] = last;
}

void LiquidBridge::compute() {
  Particles& p = *engine_.particles;
  const Neighbor& list = *engine_.neighbor;
  const bool easo = model_ == contact::CohesionModel::Easo;
  const bool newton = engine_.force->newton_pair;
  const int nlocal = p.nlocal;
  engine_.comm->forward_comm_field(p.extras[content_].data, 1);
  const double* const c = p.extras[content_].data.data();
  dcontent_.assign(nlocal, 0.0);
  if (easo) seen_.assign(static_cast<std::size_t>(nlocal) * kSlots, 0);
  const Vec3* const x = p.x.data();
  const Vec3* const v = p.v.data();
  const Vec3* const omega = p.omega.data();
  const double* const radius = p.radius.data();
  const int* const type = p.type.data();
  const double visc = 6.0 * M_PI * mu_;

  for (int i = 0; i < nlocal; ++i) {
    const double idi = static_cast<double>(p.id[i]);
    for (int k = list.offset[i]; k < list.offset[i + 1]; ++k) {
      const int j = list.neigh[k];
      const Vec3 d = x[i] - x[j];
      const double r = d.norm();
      if (r == 0.0) continue;
      const double ri = radius[i], rj = radius[j], rsum = ri + rj;
      const double s = r - rsum;
      const double theta = 0.5 * angle_[type[i]] * angle_[type[j]];
      double vb;
      if (easo) {
        const double idj = static_cast<double>(p.id[j]);
        const int slot_i = find(i, idj);
        const int slot_j = j < nlocal ? find(j, idi) : -1;
        if (slot_i < 0 && s >= 0.0) continue;  // an easo bridge forms when the spheres touch
        // its volume from the liquid the spheres carry now
        const double vi = sphere_volume(ri), vj = sphere_volume(rj);
        const double own_i = c[i] * vi * cap_fraction(ri, rj), own_j = c[j] * vj * cap_fraction(rj, ri);
        vb = own_i + own_j;
        if (slot_i < 0) {
          if (!(vb > 0.0)) continue;
          add(i, idj);
          if (j < nlocal) add(j, idi);
        } else {
          seen_[static_cast<std::size_t>(i) * kSlots + slot_i] = 1;
          if (slot_j >= 0) seen_[static_cast<std::size_t>(j) * kSlots + slot_j] = 1;
          const double reach = std::min((1.0 + 0.5 * theta) * std::cbrt(vb), (max_sep_ - 1.0) * rsum);
          if (s > reach || !(vb > 0.0)) {
            // the bridge breaks: its liquid goes back to the two spheres in
            // proportion to their solid volumes
            dcontent_[i] += (vb * vi / (vi + vj) - own_i) / vi;
            remove(i, slot_i);
            if (slot_j >= 0) {
              dcontent_[j] += (vb * vj / (vi + vj) - own_j) / vj;
              remove(j, slot_j);
            }
            continue;
          }
        }
      } else {
        vb = lb_fraction_ * (c[i] * sphere_volume(ri) + c[j] * sphere_volume(rj));
        if (!(vb > 0.0)) continue;
        const double reach = std::min((1.0 + 0.5 * theta) * std::cbrt(vb), (max_sep_ - 1.0) * rsum);
        if (s > reach) continue;
      }
      // the force on i: capillary pull, viscous resistance of the relative
      // motion at the contact point (n from j to i)
      const Vec3 n = d * (1.0 / r);
      const double reff = ri * rj / rsum;
      const double sv = std::max(s, min_sep_ * reff);
      const double half = 0.5 * std::min(s, 0.0);  // contact point in the middle of an overlap
      const Vec3 arm_i = -(ri + half) * n, arm_j = (rj + half) * n;
      const Vec3 vc = v[i] + omega[i].cross(arm_i) - v[j] - omega[j].cross(arm_j);
      const double vn = vc.dot(n);
      const Vec3 vt = vc - vn * n;
      const Vec3 ft = -(visc * reff * (8.0 / 15.0 * std::log(reff / sv) + 0.9588)) * vt;
      const Vec3 force = -(capillary(ri, rj, s, vb, theta) + visc * reff * reff * vn / sv) * n + ft;
      p.f[i] += force;
      p.torque[i] += arm_i.cross(ft);
      if (newton || j < nlocal) {
        p.f[j] -= force;
        p.torque[j] += arm_j.cross(-ft);
      }
    }
  }
  if (easo) {
    // a bridge whose partner was not met (deleted or lost: a listed pair
    // cannot outrun the list's range between two builds) ends; the liquid of
    // the sphere that remains stays as it is
    const double* const rows = p.extras[bridges_].data.data();
    for (int i = 0; i < nlocal; ++i) {
      for (int slot = static_cast<int>(rows[static_cast<std::size_t>(i) * kStride]) - 1; slot >= 0; --slot)
        if (!seen_[static_cast<std::size_t>(i) * kSlots + slot]) remove(i, slot);
    }
  }
  double* const content = p.extras[content_].data.data();
  for (int i = 0; i < nlocal; ++i)
    content[i] += dcontent_[i];
}

}  // namespace granary
