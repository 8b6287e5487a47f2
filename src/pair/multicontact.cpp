// The multiple-contact model's records and formula (see multicontact.h).
#include "pair/multicontact.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "particles/particles.h"

namespace granary {

namespace {
const char* kField = "multicontact";
}  // namespace

MultiContact::MultiContact(Engine& engine, const std::string& owner, double gamma)
    : engine_(engine), owner_(owner), gamma_(gamma) {
  field_ = engine.particles->add_field(kField, kStride, true, true);
  engine.particles->extras[field_].history = true;
}

void MultiContact::release() {
  engine_.particles->release_field(kField);
  field_ = -1;
}

void MultiContact::set_materials(std::vector<double> youngs, std::vector<double> poisson) {
  youngs_ = std::move(youngs);
  poisson_ = std::move(poisson);
}

int MultiContact::wall_ordinal(const std::string& fix_id) {
  for (std::size_t k = 0; k < walls_.size(); ++k)
    if (walls_[k] == fix_id) return static_cast<int>(k);
  walls_.push_back(fix_id);
  return static_cast<int>(walls_.size()) - 1;
}

void MultiContact::begin() {
  Particles& p = *engine_.particles;
  engine_.comm->forward_comm_field(p.extras[field_].data, kStride);
  nnext_ = p.nlocal;
  next_.resize(static_cast<std::size_t>(nnext_) * kStride);
  for (int i = 0; i < nnext_; ++i)
    next_[static_cast<std::size_t>(i) * kStride] = 0.0;
}

void MultiContact::finish() {
  std::vector<double>& field = engine_.particles->extras[field_].data;
  for (int i = 0; i < nnext_; ++i) {
    const double* src = next_.data() + static_cast<std::size_t>(i) * kStride;
    double* dst = field.data() + static_cast<std::size_t>(i) * kStride;
    const int n = static_cast<int>(src[0]);
    std::copy(src, src + 1 + n * kRecord, dst);
    // the rest of the row is never read (the count says how many records hold)
  }
}

double MultiContact::shift(const Particles& p, int i, double exclude, const Vec3& point,
                           const Vec3& n_in) const {
  const double* row = p.extras[field_].data.data() + static_cast<std::size_t>(i) * kStride;
  const int n = static_cast<int>(row[0]);
  if (n == 0) return 0.0;
  const int t = p.type[i];
  const double nu = poisson_[t];
  const double pref = -gamma_ * (1.0 + nu) / (2.0 * M_PI * youngs_[t]);
  const double tiny = 1e-9 * p.radius[i];
  double s = 0.0;
  for (int k = 0; k < n; ++k) {
    const double* r = row + 1 + k * kRecord;
    if (r[0] == exclude) continue;
    const Vec3 q = p.x[i] + Vec3(r[1], r[2], r[3]);
    const Vec3 nk(r[4], r[5], r[6]);
    const Vec3 dv = point - q;
    const double d = dv.norm();
    if (!(d > tiny)) continue;  // the same point: no distance to act over
    const Vec3 u = dv / d;
    const double nku = nk.dot(u);
    // inward normals: for two points of one sphere n_ik.u >= 0, so the
    // denominator is at least 1 (it vanishes only for a point straight
    // outside contact ik, which a sphere does not have)
    const double den = 1.0 + nku;
    if (!(den > 1e-12)) continue;
    const double bracket =
        nku * n_in.dot(u) + (3.0 - 4.0 * nu) * nk.dot(n_in) - (1.0 - 2.0 * nu) * (nk + u).dot(n_in) / den;
    s += pref * r[7] / d * bracket;
  }
  return s;
}

void MultiContact::record(const Particles& p, int i, double key, const Vec3& rel_point, const Vec3& n_in,
                          double fn) {
  double* row = next_.data() + static_cast<std::size_t>(i) * kStride;
  const int n = static_cast<int>(row[0]);
  if (n >= kSlots)
    throw RunError(owner_ + ": particle " + std::to_string(p.id[i]) + " has more than " +
                   std::to_string(kSlots) + " contacts at once, more than this fix records");
  double* r = row + 1 + n * kRecord;
  r[0] = key;
  r[1] = rel_point[0];
  r[2] = rel_point[1];
  r[3] = rel_point[2];
  r[4] = n_in[0];
  r[5] = n_in[1];
  r[6] = n_in[2];
  r[7] = std::fabs(fn);
  row[0] = n + 1;
}

}  // namespace granary
