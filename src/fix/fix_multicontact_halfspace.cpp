// fix ID group multicontact/halfspace [geometric_prefactor GAMMA]
// (see fix_multicontact_halfspace.h and doc/fixes/multicontact_halfspace.md)
#include "fix/fix_multicontact_halfspace.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/force.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/global_property.h"
#include "particles/particles.h"

namespace granary {

namespace {
const char* kUsage = "fix ID group multicontact/halfspace [geometric_prefactor GAMMA]";
const char* kField = "multicontact";
}  // namespace

FixMulticontactHalfspace::FixMulticontactHalfspace(Engine& engine, const Args& args) : Fix(engine, args) {
  for (std::size_t k = 3; k < args.size(); k += 2) {
    if (args[k] != "geometric_prefactor")
      throw InputError("fix multicontact/halfspace: unknown keyword '" + args[k] + "'; usage: " + kUsage);
    if (k + 1 >= args.size())
      throw InputError("fix multicontact/halfspace: geometric_prefactor needs a value; usage: " +
                       std::string(kUsage));
    gamma_ = parse_double(args[k + 1], "the geometric prefactor");
    if (!(gamma_ > 0.0))
      throw InputError("fix multicontact/halfspace: geometric_prefactor must be > 0, got " + args[k + 1]);
  }
  Force& force = *engine.force;
  if (force.multicontact && force.multicontact != this)
    throw InputError("fix multicontact/halfspace: there is already one (fix " + force.multicontact->id +
                     "); a simulation has at most one");
  force.multicontact = this;
  field_ = engine.particles->add_field(kField, kStride, true, true);
  engine.particles->extras[field_].history = true;
}

FixMulticontactHalfspace::~FixMulticontactHalfspace() {
  if (engine_.force && engine_.force->multicontact == this) engine_.force->multicontact = nullptr;
}

void FixMulticontactHalfspace::unfixed() {
  engine_.particles->release_field(kField);
  field_ = -1;
  if (engine_.force->multicontact == this) engine_.force->multicontact = nullptr;
}

void FixMulticontactHalfspace::init() {
  const std::string user = "fix " + id + " multicontact/halfspace";
  if (engine_.force->newton_pair)
    throw InputError(user +
                     " needs 'newton off': with newton on the contacts of a ghost particle are "
                     "computed on one rank only and its owner would not record them");
  const GlobalProperty& Y = engine_.modify->require_property("youngsModulus", user);
  const GlobalProperty& nu = engine_.modify->require_property("poissonsRatio", user);
  const int nt = engine_.particles->ntypes;
  youngs_.assign(static_cast<std::size_t>(nt) + 1, 0.0);
  poisson_.assign(static_cast<std::size_t>(nt) + 1, 0.0);
  for (int t = 1; t <= nt; ++t) {
    youngs_[t] = Y.per_type(t);
    poisson_[t] = nu.per_type(t);
    if (!(youngs_[t] > 0.0))
      throw InputError(user + ": youngsModulus of type " + std::to_string(t) + " must be > 0");
  }
}

int FixMulticontactHalfspace::wall_ordinal(const std::string& fix_id) {
  for (std::size_t k = 0; k < walls_.size(); ++k)
    if (walls_[k] == fix_id) return static_cast<int>(k);
  walls_.push_back(fix_id);
  return static_cast<int>(walls_.size()) - 1;
}

void FixMulticontactHalfspace::begin() {
  Particles& p = *engine_.particles;
  engine_.comm->forward_comm_field(p.extras[field_].data, kStride);
  nnext_ = p.nlocal;
  next_.resize(static_cast<std::size_t>(nnext_) * kStride);
  for (int i = 0; i < nnext_; ++i)
    next_[static_cast<std::size_t>(i) * kStride] = 0.0;
}

void FixMulticontactHalfspace::finish() {
  std::vector<double>& field = engine_.particles->extras[field_].data;
  for (int i = 0; i < nnext_; ++i) {
    const double* src = next_.data() + static_cast<std::size_t>(i) * kStride;
    double* dst = field.data() + static_cast<std::size_t>(i) * kStride;
    const int n = static_cast<int>(src[0]);
    std::copy(src, src + 1 + n * kRecord, dst);
    // the rest of the row is never read (the count says how many records hold)
  }
}

double FixMulticontactHalfspace::shift(const Particles& p, int i, double exclude, const Vec3& point,
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

void FixMulticontactHalfspace::record(const Particles& p, int i, double key, const Vec3& rel_point,
                                      const Vec3& n_in, double fn) {
  double* row = next_.data() + static_cast<std::size_t>(i) * kStride;
  const int n = static_cast<int>(row[0]);
  if (n >= kSlots)
    throw RunError("fix " + id + " multicontact/halfspace: particle " + std::to_string(p.id[i]) +
                   " has more than " + std::to_string(kSlots) +
                   " contacts at once, more than this fix records");
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

GRANARY_FIX_STYLE("multicontact/halfspace", FixMulticontactHalfspace);

}  // namespace granary
