#include "fix/fix_multisphere.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <unordered_map>

#include "comm/comm.h"
#include "compute/compute.h"
#include "comm/collectives.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "fix/fix_particletemplate_multisphere.h"
#include "core/modify.h"
#include "neighbor/contact_history.h"
#include "core/force.h"
#include "pair/pair.h"
#include "particles/particles.h"

namespace granary {

namespace {

constexpr const char* kIndexField = "multisphere/index";

// The runs' bodies lie in id order, their sub-spheres in the order of the
// spatial sort: the loops along the runs ask the cache for the body data of
// the run this many runs ahead, so that it arrives while they work.
constexpr int kAhead = 4;

// every cache line of *p (write: the caller will store there)
template <bool write = false, class T>
inline void prefetch(const T* p) {
  const char* const c = reinterpret_cast<const char*>(p);
  for (std::size_t k = 0; k < sizeof(T); k += 64)
    __builtin_prefetch(c + k, write);
  __builtin_prefetch(c + sizeof(T) - 1, write);
}

/// cos and sin of x. NO_SQUISH's half angles are small (|omega| dt / 2, about
/// 1e-3): below 0.01 the Taylor series to x^6 / x^7 equals the functions to
/// well below one rounding unit (the first omitted terms are below
/// x^8 / 8! < 3e-21), at a fraction of the cost of a library call.
[[gnu::always_inline]] inline void cos_sin(double x, double& c, double& s) {
  if (std::fabs(x) < 0.01) {
    constexpr double k12 = 1.0 / 12, k30 = 1.0 / 30, k6 = 1.0 / 6, k20 = 1.0 / 20, k42 = 1.0 / 42;
    const double x2 = x * x;
    c = 1.0 - 0.5 * x2 * (1.0 - x2 * k12 * (1.0 - x2 * k30));
    s = x * (1.0 - x2 * k6 * (1.0 - x2 * k20 * (1.0 - x2 * k42)));
    return;
  }
  c = std::cos(x);
  s = std::sin(x);
}

/// Rotation by angle phi about body axis K, applied on the right of q (the
/// product q (cos phi/2, sin phi/2 e_K) written out); the body-frame angular
/// momentum turns by -phi about the same axis. cos and sin of phi follow from
/// those of the half angle by the double-angle identities.
template <int K>
[[gnu::always_inline]] inline void rotate_about_axis(Eigen::Quaterniond& q, Vec3& lb, double phi) {
  double c, s;
  cos_sin(0.5 * phi, c, s);
  const double w = q.w(), x = q.x(), y = q.y(), z = q.z();
  if constexpr (K == 0) {
    q = Eigen::Quaterniond(c * w - s * x, c * x + s * w, c * y + s * z, c * z - s * y);
  } else if constexpr (K == 1) {
    q = Eigen::Quaterniond(c * w - s * y, c * x - s * z, c * y + s * w, c * z + s * x);
  } else {
    q = Eigen::Quaterniond(c * w - s * z, c * x + s * y, c * y - s * x, c * z + s * w);
  }
  constexpr int a = (K + 1) % 3, b = (K + 2) % 3;
  const double cp = (c - s) * (c + s), sp = 2.0 * s * c;
  const double la = lb[a], lbb = lb[b];
  lb[a] = cp * la + sp * lbb;
  lb[b] = -sp * la + cp * lbb;
}

/// One NO_SQUISH sub-step about body axis K for time h, for n rotors at once:
/// the rotors' chains of dependent operations interleave, which keeps the
/// processor busy (one rotor alone waits on each result in turn).
template <int K, int N>
[[gnu::always_inline]] inline void rotate_many(Eigen::Quaterniond* q, Vec3* lb, const Vec3* inertia,
                                               double h) {
  for (int j = 0; j < N; ++j)
    if (inertia[j][K] > 0.0) rotate_about_axis<K>(q[j], lb[j], h * lb[j][K] / inertia[j][K]);
}

/// FixMultisphere::rotate_free for N rotors (identical operations per rotor).
template <int N>
void rotate_free_many(Eigen::Quaterniond* q, Vec3* lb, const Vec3* inertia, double dt) {
  const double h = 0.5 * dt;
  rotate_many<2, N>(q, lb, inertia, h);
  rotate_many<1, N>(q, lb, inertia, h);
  rotate_many<0, N>(q, lb, inertia, dt);
  rotate_many<1, N>(q, lb, inertia, h);
  rotate_many<2, N>(q, lb, inertia, h);
  for (int j = 0; j < N; ++j)
    q[j].normalize();
}

std::string fmt(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

FixMultisphere::FixMultisphere(Engine& engine, const Args& args) : Fix(engine, args) {
  const std::string usage = "fix ID group multisphere [allow_group_and_set yes|no] [allow_heatsource yes|no]";
  for (std::size_t k = 3; k < args.size(); k += 2) {
    const std::string& w = args[k];
    if (k + 1 >= args.size())
      throw InputError("fix multisphere keyword '" + w + "' needs a value; usage: " + usage);
    if (w == "allow_group_and_set" || w == "allow_heatsource") {
      parse_bool(args[k + 1], "fix multisphere " + w);  // accepted; Granary always allows both
    } else if (w == "CAddRhoFluid") {
      throw InputError(
          "fix multisphere CAddRhoFluid (added mass of a fluid) needs CFD coupling, which Granary "
          "does not have; remove the keyword");
    } else {
      throw InputError("unknown fix multisphere keyword '" + w + "'; usage: " + usage);
    }
  }
  time_integrate = true;
  scalar_flag = true;
  restart_global = true;
  if (engine.modify) {
    for (const auto& f : engine.modify->fixes) {
      if (!dynamic_cast<FixMultisphere*>(f.get())) continue;
      if (f->id != id) {
        throw InputError("fix " + f->style + " " + f->id +
                         " already integrates the clumps; use one fix multisphere (or multisphere/break)");
      }
      // the fix is being redefined: keep the clumps
      if (auto* old = dynamic_cast<FixMultisphere*>(f.get())) {
        old->sync_bodies();  // collective: every rank defines the fix
        bodies_ = old->bodies_;
      }
    }
  }
  find_fields();
  engine.clumps = this;
}

void FixMultisphere::find_fields() {
  Particles& p = *engine_.particles;
  index_field_ = p.add_field(kIndexField, 1, false, true);
  mass_field_ = p.add_field(kBodyMassField, 1, true, true);
}

FixMultisphere::~FixMultisphere() {
  if (engine_.clumps == this) engine_.clumps = nullptr;
}

void FixMultisphere::init() {
  find_fields();
  bodies_changed();
}

void FixMultisphere::bodies_changed() {
  shapes_stale_ = true;
  if (!engine_.modify) return;
  for (const auto& c : engine_.modify->computes)
    if (auto* out = dynamic_cast<BodyOutput*>(c.get())) out->bodies_changed(bodies_.size());
}

// ---------------------------------------------------------------- bodies

void FixMultisphere::add_body(tagint body_id, tagint first_id, const TemplateParticle& particle,
                              const Vec3& x_cm, const Eigen::Quaterniond& q, const Vec3& v,
                              const Vec3& omega) {
  try {
    bodies_.add(body_id, first_id, particle.type, particle.mass, particle.volume, particle.density,
                particle.inertia, particle.offsets, particle.radii, x_cm, q, v, omega);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("fix multisphere: ") + e.what());
  }
  pending_ = true;
  reindex_ = true;  // body indices may have moved
  bodies_changed();
}

tagint FixMultisphere::next_body_id() {
  const Particles& p = *engine_.particles;
  long long local = static_cast<long long>(bodies_.max_tag()), all = 0;
  for (int i = 0; i < p.nlocal; ++i)
    local = std::max(local, static_cast<long long>(p.body[i]));
  MPI_Allreduce(&local, &all, 1, MPI_LONG_LONG, MPI_MAX, engine_.world);
  return static_cast<tagint>(all + 1);
}

tagint FixMultisphere::create_clump(const TemplateParticle& particle, const Vec3& x,
                                    const Eigen::Quaterniond& q, const Vec3& v, const Vec3& omega) {
  Engine& e = engine_;
  Domain& dom = *e.domain;
  Particles& p = *e.particles;
  if (!dom.box_exist) throw InputError("create_clump needs the simulation box; use create_box first");
  if (particle.type < 1 || particle.type > p.ntypes) {
    throw InputError("create_clump: the template's atom type " + std::to_string(particle.type) +
                     " is outside 1.." + std::to_string(p.ntypes));
  }
  const Eigen::Quaterniond qn = q.normalized();
  const Eigen::Matrix3d r = qn.toRotationMatrix();
  const int ns = static_cast<int>(particle.offsets.size());
  std::vector<Vec3> pos(ns);
  std::vector<int> image(ns);
  for (int k = 0; k < ns; ++k) {
    pos[k] = x + r * particle.offsets[k];
    image[k] = Particles::image_pack(0, 0, 0);
    dom.remap(pos[k], image[k]);
    if (!dom.inside_box(pos[k])) {
      throw InputError("create_clump: sub-sphere " + std::to_string(k + 1) + " at (" + fmt(pos[k][0]) + ", " +
                       fmt(pos[k][1]) + ", " + fmt(pos[k][2]) + ") lies outside the box");
    }
  }
  long long local_max = static_cast<long long>(p.max_local_id()), max_id = 0;
  MPI_Allreduce(&local_max, &max_id, 1, MPI_LONG_LONG, MPI_MAX, e.world);
  const tagint first = static_cast<tagint>(max_id + 1);
  const tagint body_id = next_body_id();
  p.clear_ghosts();
  for (int k = 0; k < ns; ++k) {
    if (e.comm->owner_of(pos[k]) != e.rank) continue;
    const int i = p.add_local(first + k, particle.type, pos[k], particle.radii[k], particle.density);
    p.body[i] = body_id;
    p.image[i] = image[k];
  }
  add_body(body_id, first, particle, x, qn, v, omega);
  resolve_new_spheres();
  reindex();
  place_spheres(false);
  long long n = p.nlocal, total = 0;
  MPI_Allreduce(&n, &total, 1, MPI_LONG_LONG, MPI_SUM, e.world);
  p.natoms = total;
  p.map_clear();
  return body_id;
}

int FixMultisphere::body_of(int i, int& k) const {
  const Particles& p = *engine_.particles;
  if (p.body[i] < 0) return -1;
  const int b = bodies_.find(p.body[i]);
  if (b < 0) return -1;
  k = static_cast<int>(p.extras[index_field_].data[i]) - 1;
  return k >= 0 ? b : -1;
}

void FixMultisphere::resolve_new_spheres() {
  Particles& p = *engine_.particles;
  const Domain& dom = *engine_.domain;
  double* index = p.extras[index_field_].data.data();
  int bad = 0;
  for (int i = 0; i < p.nlocal; ++i) {
    if (p.body[i] < 0 || index[i] != 0.0) continue;
    const int b = bodies_.find(p.body[i]);
    if (b < 0) continue;
    const tagint k = p.id[i] - bodies_.first_id[b];
    if (k < 0 || k >= bodies_.nspheres[b]) {
      ++bad;
      continue;
    }
    index[i] = static_cast<double>(k + 1);
    // sub-spheres share the body mass so that per-particle body forces
    // (gravity) sum to the body's weight with no torque about its centre
    const int s0 = bodies_.sphere_start[b];
    p.rmass[i] = bodies_.mass[b] * bodies_.mass_share[s0 + k];
    // image flags that make x + image * prd the unwrapped position of the sub-sphere
    const Vec3 xu = bodies_.xcm[b] + bodies_.rotation(b) * bodies_.offsets[s0 + k];
    int img[3] = {0, 0, 0};
    for (int d = 0; d < 3; ++d)
      if (dom.periodic[d]) img[d] = static_cast<int>(std::lround((xu[d] - p.x[i][d]) / dom.prd[d]));
    p.image[i] = Particles::image_pack(img[0], img[1], img[2]);
  }
  int all = 0;
  MPI_Allreduce(&bad, &all, 1, MPI_INT, MPI_SUM, engine_.world);
  if (all > 0) {
    throw RunError("fix multisphere: " + std::to_string(all) +
                   " sub-sphere(s) carry a body id whose id range does not contain them; bodies must be "
                   "created with consecutive particle ids first_id .. first_id + n - 1");
  }
  pending_ = false;
  reindex_ = true;  // sub-spheres taken over
}

void FixMultisphere::fill_body_mass() {
  Particles& p = *engine_.particles;
  double* bm = p.extras[mass_field_].data.data();
  const int n = p.size();
  for (int i = 0; i < n; ++i) {
    const int b = p.body[i] >= 0 ? bodies_.find(p.body[i]) : -1;
    bm[i] = b >= 0 ? bodies_.mass[b] : 0.0;
  }
  // owned sub-spheres: their mass share again (`set mass|density|diameter` must not change body forces)
  for (int i = 0; i < p.nlocal; ++i) {
    int k;
    const int b = body_of(i, k);
    if (b >= 0) p.rmass[i] = bodies_.mass[b] * bodies_.mass_share[bodies_.sphere_start[b] + k];
  }
}

long long FixMultisphere::remove_incomplete_bodies() {
  Engine& e = engine_;
  Particles& p = *e.particles;
  // cheap test first: the total number of sub-spheres, and particles of unknown bodies
  long long local[2] = {0, 0}, all[2] = {0, 0};
  for (int i = 0; i < p.nlocal; ++i) {
    if (p.body[i] < 0) continue;
    if (bodies_.find(p.body[i]) >= 0)
      ++local[0];
    else
      ++local[1];
  }
  MPI_Allreduce(local, all, 2, MPI_LONG_LONG, MPI_SUM, e.world);
  if (all[1] > 0) {
    throw RunError("fix multisphere " + id + ": " + std::to_string(all[1]) +
                   " particle(s) belong to clumps this fix does not know; after read_restart define fix "
                   "multisphere with the ID it had when the restart file was written");
  }
  if (all[0] == bodies_.total_spheres()) return 0;

  const int nb = bodies_.size();
  std::vector<int> count(nb, 0), total(nb, 0);
  for (int i = 0; i < p.nlocal; ++i)
    if (p.body[i] >= 0) ++count[bodies_.find(p.body[i])];
  MPI_Allreduce(count.data(), total.data(), nb, MPI_INT, MPI_SUM, e.world);
  std::vector<char> doomed(nb, 0);
  long long ndoomed = 0;
  for (int b = 0; b < nb; ++b) {
    if (total[b] > bodies_.nspheres[b]) {
      throw RunError("fix multisphere: clump " + std::to_string(bodies_.tag[b]) + " has " +
                     std::to_string(total[b]) + " sub-spheres, more than its " +
                     std::to_string(bodies_.nspheres[b]) + "; particle ids or body ids were duplicated");
    }
    if (total[b] < bodies_.nspheres[b]) {
      doomed[b] = 1;
      ++ndoomed;
    }
  }
  std::vector<char> gone(p.nlocal, 0);
  for (int i = 0; i < p.nlocal; ++i)
    gone[i] = p.body[i] >= 0 && doomed[bodies_.find(p.body[i])];
  const long long removed = e.delete_particles(gone);
  long long removed_all = 0;
  MPI_Allreduce(&removed, &removed_all, 1, MPI_LONG_LONG, MPI_SUM, e.world);
  bodies_.remove(doomed);
  reindex_ = true;
  bodies_changed();
  p.natoms -= removed_all;
  p.map_clear();
  e.logger->print("fix multisphere " + id + ": removed " + std::to_string(ndoomed) +
                  " clump(s) that lost sub-spheres, with their remaining " + std::to_string(removed_all) +
                  " sub-sphere(s)\n");
  return ndoomed;
}

long long FixMultisphere::remove_bodies(const std::vector<tagint>& ids) {
  Engine& e = engine_;
  Particles& p = *e.particles;
  std::vector<char> doomed(bodies_.size(), 0);
  bool any = false;
  for (tagint t : ids) {
    const int b = bodies_.find(t);
    if (b >= 0) doomed[b] = 1;
    any = any || b >= 0;
  }
  if (!any) return 0;
  std::vector<char> gone(p.nlocal, 0);
  for (int i = 0; i < p.nlocal; ++i) {
    const int b = p.body[i] >= 0 ? bodies_.find(p.body[i]) : -1;
    gone[i] = b >= 0 && doomed[b];
  }
  const long long removed = e.delete_particles(gone);
  bodies_.remove(doomed);
  bodies_changed();
  reindex();  // body indices moved (collective: every rank removes the same bodies)
  p.map_clear();
  return removed;
}

long long FixMultisphere::release_bodies(const std::vector<tagint>& ids) {
  Particles& p = *engine_.particles;
  std::vector<char> doomed(bodies_.size(), 0);
  long long n = 0;
  for (tagint t : ids) {
    const int b = bodies_.find(t);
    if (b >= 0 && !doomed[b]) {
      doomed[b] = 1;
      ++n;
    }
  }
  if (n == 0) return 0;
  double* index = p.extras[index_field_].data.data();
  double* mass = p.extras[mass_field_].data.data();
  for (int i = 0; i < p.nlocal; ++i) {
    const int b = p.body[i] >= 0 ? bodies_.find(p.body[i]) : -1;
    if (b < 0 || !doomed[b]) continue;
    p.body[i] = -1;  // a free sphere from now on (fix nve/sphere integrates it)
    index[i] = 0.0;
    mass[i] = 0.0;
  }
  bodies_.remove(doomed);
  bodies_changed();
  reindex();  // body indices moved (collective: every rank releases the same bodies)
  return n;
}

Vec3 FixMultisphere::wrapped_centre(int b) const {
  Vec3 x = bodies_.xcm[b];
  int image = Particles::image_pack(0, 0, 0);
  engine_.domain->remap(x, image);
  return x;
}

// ------------------------------------------------------------ integration

void FixMultisphere::rotate_free(Eigen::Quaterniond& q, Vec3& lb, const Vec3& inertia, double dt) {
  rotate_free_many<1>(&q, &lb, &inertia, dt);
}

void FixMultisphere::compute_rotations() {
  rot_.resize(bodies_.size());
  for (int b : active_)
    rot_[b] = bodies_.rotation(b);
}

void FixMultisphere::index_spheres() {
  const Particles& p = *engine_.particles;
  const int n = p.nlocal;
  pbody_.resize(n);
  pslot_.resize(n);
  for (int i = 0; i < n; ++i) {
    int k;
    const int b = body_of(i, k);
    pbody_[i] = b;
    pslot_[i] = b >= 0 ? slot_[b] + k : -1;
  }
  std::vector<int> owned(bodies_.size(), 0);
  for (int i = 0; i < n; ++i)
    if (pbody_[i] >= 0 && slot_[pbody_[i]] >= 0) ++owned[pbody_[i]];
  partial_.clear();
  for (int b : active_)
    if (owned[b] != bodies_.nspheres[b]) partial_.push_back(b);
  // Bodies whole here whose sub-spheres lie in order at consecutive indices
  // are summed along their run (runs_; their particles' pslot_ set to -1),
  // the others through the slots (slotted_).
  std::vector<char> in_run(bodies_.size(), 0);
  runs_.clear();
  for (int i = 0; i < n;) {
    const int b = pbody_[i];
    if (b < 0 || owned[b] != bodies_.nspheres[b]) {
      ++i;
      continue;
    }
    const int len = bodies_.nspheres[b];
    int k = 0;
    while (k < len && i + k < n && pbody_[i + k] == b && pslot_[i + k] == slot_[b] + k)
      ++k;
    if (k < len) {
      ++i;
      continue;
    }
    runs_.push_back(i);
    in_run[b] = 1;
    std::fill_n(pslot_.begin() + i, len, -1);
    i += len;
  }
  slotted_.clear();
  for (int b : active_)
    if (!in_run[b]) slotted_.push_back(b);
  slotted_spheres_.clear();
  for (int i = 0; i < n; ++i)
    if (pslot_[i] >= 0) slotted_spheres_.push_back(i);
}

Vec3 FixMultisphere::omega_from(int b) const {
  return omega_from(rot_[b], b);
}

Vec3 FixMultisphere::omega_from(const Eigen::Matrix3d& r, int b) const {
  // R I^-1 R^T L with this step's R, the same operations as Bodies::omega_from_angmom
  const Vec3& inertia = bodies_.inertia[b];
  Vec3 lb = r.transpose() * bodies_.angmom[b];
  for (int d = 0; d < 3; ++d)
    lb[d] = inertia[d] > 0.0 ? lb[d] / inertia[d] : 0.0;
  return r * lb;
}

void FixMultisphere::find_shapes() {
  // Bodies of one template have the same offsets bit for bit (Bodies::add
  // makes them alike from the template's); found by a hash of the bits and
  // compared in full.
  const Bodies& B = bodies_;
  const int nb = B.size();
  shape_start_.resize(nb);
  std::unordered_map<std::uint64_t, std::vector<int>> seen;  // hash -> first bodies of their shapes
  for (int b = 0; b < nb; ++b) {
    const int s0 = B.sphere_start[b], ns = B.nspheres[b];
    const std::size_t bytes = sizeof(Vec3) * static_cast<std::size_t>(ns);
    const unsigned char* const bits = reinterpret_cast<const unsigned char*>(&B.offsets[s0]);
    std::uint64_t h = 1469598103934665603ull ^ static_cast<std::uint64_t>(ns);
    for (std::size_t c = 0; c + 8 <= bytes; c += 8) {
      std::uint64_t w;
      std::memcpy(&w, bits + c, 8);
      h = (h ^ w) * 1099511628211ull;
    }
    std::vector<int>& same_hash = seen[h];
    shape_start_[b] = s0;
    for (const int c : same_hash) {
      if (B.nspheres[c] == ns && std::memcmp(&B.offsets[B.sphere_start[c]], bits, bytes) == 0) {
        shape_start_[b] = B.sphere_start[c];
        break;
      }
    }
    if (shape_start_[b] == s0) same_hash.push_back(b);
  }
  shapes_stale_ = false;
}

void FixMultisphere::check_index() {
  if (shapes_stale_) find_shapes();
  if (reindex_) {
    reindex();
    return;
  }
  if (static_cast<int>(pbody_.size()) == engine_.particles->nlocal) return;
  // Owned particles changed outside a neighbour-list rebuild: the caches can
  // be refilled here, the active set (agreed collectively) cannot.
  index_spheres();
  for (int b : pbody_) {
    if (b >= 0 && !is_active_[b]) {
      throw RunError("fix multisphere " + id +
                     ": a rank gained a clump sub-sphere outside a neighbour-list rebuild");
    }
  }
}

void FixMultisphere::reindex() {
  const Particles& p = *engine_.particles;
  const int nb = bodies_.size();
  reindex_ = false;
  is_active_.assign(nb, 0);
  for (int i = 0; i < p.nlocal; ++i) {
    int k;
    const int b = body_of(i, k);
    if (b >= 0) is_active_[b] = 1;
  }
  active_.clear();
  slot_.assign(nb, -1);
  int nslots = 0;
  for (int b = 0; b < nb; ++b) {
    if (!is_active_[b]) continue;
    active_.push_back(b);
    slot_[b] = nslots;
    nslots += bodies_.nspheres[b];
  }
  part_.assign(6 * static_cast<std::size_t>(nslots), 0.0);
  fetch_state();
  compute_rotations();
  index_spheres();
  find_partners();
  invalidate_ = true;
}

void FixMultisphere::fetch_state() {
  // Bodies that became active here by migration (exchange) were advanced by
  // the ranks that owned their sub-spheres before; one of them answers.
  Engine& e = engine_;
  Bodies& B = bodies_;
  std::vector<long long> need;
  for (int b : active_)
    if (!B.current[b]) need.push_back(B.tag[b]);
  const int np = e.nprocs;
  std::vector<int> displs;
  const std::vector<long long> wanted = allgather(e.world, need, &displs);
  if (wanted.empty()) return;
  constexpr int kState = 1 + Bodies::kStateSize;  // id, then the dynamic state
  std::vector<double> reply;
  std::vector<char> sent(B.size(), 0);
  for (int r = 0; r < np; ++r) {
    if (r == e.rank) continue;
    for (int k = displs[r]; k < displs[r + 1]; ++k) {
      const int b = B.find(static_cast<tagint>(wanted[k]));
      if (b < 0 || !B.current[b] || sent[b]) continue;
      sent[b] = 1;
      reply.push_back(static_cast<double>(wanted[k]));
      reply.resize(reply.size() + Bodies::kStateSize);
      B.pack_state(b, reply.data() + reply.size() - Bodies::kStateSize);
    }
  }
  const std::vector<double> all = allgather(e.world, reply);
  for (std::size_t m = 0; m + kState <= all.size(); m += kState) {
    const int b = B.find(static_cast<tagint>(all[m]));
    if (b < 0 || B.current[b] || !is_active_[b]) continue;
    B.unpack_state(b, &all[m + 1]);
    ++fetched_;
  }
  for (int b : active_) {
    if (!B.current[b]) {
      throw RunError("fix multisphere " + id + ": no rank holds the current state of clump " +
                     std::to_string(B.tag[b]));
    }
  }
}

void FixMultisphere::find_partners() {
  // A body is shared when this rank owns some but not all of its sub-spheres.
  // Every rank publishes its shared bodies; the ranks listing the same body
  // exchange their sub-spheres' forces and torques for it every step.
  Engine& e = engine_;
  const Bodies& B = bodies_;
  const Particles& p = *e.particles;
  partners_.clear();
  shared_.clear();
  shared_start_.assign(1, 0);
  shared_src_.clear();
  if (e.nprocs == 1) return;
  std::vector<int> count(B.size(), 0);
  for (int i = 0; i < p.nlocal; ++i)
    if (pbody_[i] >= 0) ++count[pbody_[i]];
  std::vector<long long> mine;
  for (int b : active_)
    if (count[b] < B.nspheres[b]) mine.push_back(B.tag[b]);
  const int np = e.nprocs;
  std::vector<int> displs;
  const std::vector<long long> all = allgather(e.world, mine, &displs);
  if (all.empty() || mine.empty()) return;
  // the other ranks owning sub-spheres of each shared body, in ascending rank order
  std::vector<std::vector<std::pair<int, int>>> src(mine.size());
  for (int r = 0; r < np; ++r) {
    if (r == e.rank) continue;
    // both lists ascend by id: merge
    Partner partner;
    partner.rank = r;
    std::size_t a = 0;
    for (int k = displs[r]; k < displs[r + 1] && a < mine.size(); ++k) {
      while (a < mine.size() && mine[a] < all[k])
        ++a;
      if (a < mine.size() && mine[a] == all[k]) {
        src[a].emplace_back(static_cast<int>(partners_.size()), static_cast<int>(partner.bodies.size()));
        const int b = B.find(static_cast<tagint>(mine[a]));
        partner.start.push_back(
            partner.bodies.empty() ? 0 : partner.start.back() + 6 * B.nspheres[partner.bodies.back()]);
        partner.bodies.push_back(b);
      }
    }
    if (!partner.bodies.empty()) {
      const int last = partner.bodies.back();
      partner.send.resize(partner.start.back() + 6 * static_cast<std::size_t>(B.nspheres[last]));
      partner.recv.resize(partner.send.size());
      partners_.push_back(std::move(partner));
    }
  }
  for (std::size_t a = 0; a < mine.size(); ++a) {
    if (src[a].empty()) continue;  // no other rank owns its other sub-spheres (yet)
    shared_.push_back(B.find(static_cast<tagint>(mine[a])));
    shared_src_.insert(shared_src_.end(), src[a].begin(), src[a].end());
    shared_start_.push_back(static_cast<int>(shared_src_.size()));
  }
}

void FixMultisphere::place_spheres(bool positions) {
  check_index();
  Particles& p = *engine_.particles;
  const Domain& dom = *engine_.domain;
  const int* const pbody = pbody_.data();
  const int* const shape = shape_start_.data();
  const int* const nspheres = bodies_.nspheres.data();
  const Vec3* const offsets = bodies_.offsets.data();
  const Eigen::Matrix3d* const rot = rot_.data();
  const Vec3* const xcm = bodies_.xcm.data();
  const Vec3* const vcm = bodies_.vcm.data();
  const Vec3* const omega = bodies_.omega.data();
  const int* const image = p.image.data();
  Vec3* const x = p.x.data();
  Vec3* const v = p.v.data();
  Vec3* const w = p.omega.data();
  const int image0 = Particles::image_pack(0, 0, 0);
  // sub-sphere i of body b, at offset d in the body frame
  auto place = [&](int i, int b, const Vec3& d) {
    const Vec3 r = rot[b] * d;
    if (positions) {
      Vec3 xi = xcm[b] + r;
      if (image[i] != image0) {
        int img[3];
        Particles::image_unpack(image[i], img[0], img[1], img[2]);
        for (int c = 0; c < 3; ++c)
          if (dom.periodic[c]) xi[c] -= img[c] * dom.prd[c];
      }
      x[i] = xi;
    }
    v[i] = vcm[b] + omega[b].cross(r);
    w[i] = omega[b];
  };
  const int nruns = static_cast<int>(runs_.size());
  for (int j = 0; j < nruns; ++j) {
    if (j + kAhead < nruns) {
      const int ahead = pbody[runs_[j + kAhead]];
      prefetch(rot + ahead);
      prefetch(xcm + ahead);
      prefetch(vcm + ahead);
      prefetch(omega + ahead);
    }
    const int start = runs_[j];
    const int b = pbody[start];
    const Vec3* const d = offsets + shape[b];
    for (int k = 0; k < nspheres[b]; ++k)
      place(start + k, b, d[k]);
  }
  for (const int i : slotted_spheres_) {
    const int b = pbody[i];
    place(i, b, slotted_offset(i, b));
  }
}

void FixMultisphere::sum_forces() {
  // Each sub-sphere's force and torque go to its own slot; a body's total is
  // the sum over its slots in sub-sphere order. The additions are then the
  // same whichever ranks own the sub-spheres and in whatever order they are
  // stored, so bodies move bit for bit alike on any number of ranks.
  check_index();
  const Particles& p = *engine_.particles;
  sum_forces_runs();
  if (slotted_.empty()) return;
  double* const part = part_.data();
  // slots of sub-spheres owned elsewhere read zero
  for (int b : partial_)
    std::fill_n(part + 6 * static_cast<std::size_t>(slot_[b]), 6 * bodies_.nspheres[b], 0.0);
  const int* const pslot = pslot_.data();
  const int* const pbody = pbody_.data();
  const Eigen::Matrix3d* const rot = rot_.data();
  const Vec3* const f = p.f.data();
  const Vec3* const torque = p.torque.data();
  // (free spheres and the sub-spheres summed along their body's run have no slot)
  for (const int i : slotted_spheres_) {
    const int b = pbody[i];
    const Vec3 r = rot[b] * slotted_offset(i, b);
    const Vec3 t = r.cross(f[i]) + torque[i];
    double* s = part + 6 * static_cast<std::size_t>(pslot[i]);
    for (int d = 0; d < 3; ++d) {
      s[d] = f[i][d];
      s[3 + d] = t[d];
    }
  }
  if (!partners_.empty()) {
    // the slots of the shared bodies, with the ranks sharing them only
    const int* const nspheres = bodies_.nspheres.data();
    const int* const slot = slot_.data();
    std::vector<MPI_Request> req(2 * partners_.size());
    for (std::size_t k = 0; k < partners_.size(); ++k) {
      Partner& q = partners_[k];
      MPI_Irecv(q.recv.data(), static_cast<int>(q.recv.size()), MPI_DOUBLE, q.rank, 7, engine_.world,
                &req[2 * k]);
    }
    for (std::size_t k = 0; k < partners_.size(); ++k) {
      Partner& q = partners_[k];
      for (std::size_t m = 0; m < q.bodies.size(); ++m) {
        const double* s = part + 6 * static_cast<std::size_t>(slot[q.bodies[m]]);
        std::copy(s, s + 6 * nspheres[q.bodies[m]], q.send.begin() + q.start[m]);
      }
      MPI_Isend(q.send.data(), static_cast<int>(q.send.size()), MPI_DOUBLE, q.rank, 7, engine_.world,
                &req[2 * k + 1]);
    }
    MPI_Waitall(static_cast<int>(req.size()), req.data(), MPI_STATUSES_IGNORE);
    // every sub-sphere has one owner: adding the others' slots (zero where
    // they do not own the sub-sphere) to this rank's copies each value exactly
    for (std::size_t m = 0; m < shared_.size(); ++m) {
      const int b = shared_[m];
      double* s = part + 6 * static_cast<std::size_t>(slot[b]);
      const int len = 6 * nspheres[b];
      for (int k = shared_start_[m]; k < shared_start_[m + 1]; ++k) {
        const auto [partner, pos] = shared_src_[k];
        const Partner& q = partners_[partner];
        const double* r = &q.recv[q.start[pos]];
        for (int c = 0; c < len; ++c)
          s[c] += r[c];
      }
    }
  }
  for (int b : slotted_) {
    const double* s = part + 6 * static_cast<std::size_t>(slot_[b]);
    double total[6] = {0, 0, 0, 0, 0, 0};
    for (int k = 0; k < bodies_.nspheres[b]; ++k, s += 6)
      for (int d = 0; d < 6; ++d)
        total[d] += s[d];
    bodies_.fcm[b] = Vec3(total[0], total[1], total[2]);
    bodies_.torque[b] = Vec3(total[3], total[4], total[5]);
  }
}

void FixMultisphere::sum_forces_runs() {
  // every sub-sphere's six values added to its body's totals in sub-sphere
  // order, as sum_forces() adds the slots
  const Particles& p = *engine_.particles;
  const Vec3* const f = p.f.data();
  const Vec3* const torque = p.torque.data();
  const int* const nspheres = bodies_.nspheres.data();
  const int* const shape = shape_start_.data();
  const Vec3* const offsets = bodies_.offsets.data();
  const int nruns = static_cast<int>(runs_.size());
  for (int j = 0; j < nruns; ++j) {
    if (j + kAhead < nruns) {
      const int ahead = pbody_[runs_[j + kAhead]];
      prefetch(&rot_[ahead]);
      prefetch<true>(&bodies_.fcm[ahead]);
      prefetch<true>(&bodies_.torque[ahead]);
    }
    const int start = runs_[j];
    const int b = pbody_[start];
    const Eigen::Matrix3d& rot = rot_[b];
    const Vec3* const d = offsets + shape[b];
    double total[6] = {0, 0, 0, 0, 0, 0};
    for (int i = start; i < start + nspheres[b]; ++i) {
      const Vec3 r = rot * d[i - start];
      const Vec3 t = r.cross(f[i]) + torque[i];
      for (int d = 0; d < 3; ++d) {
        total[d] += f[i][d];
        total[3 + d] += t[d];
      }
    }
    bodies_.fcm[b] = Vec3(total[0], total[1], total[2]);
    bodies_.torque[b] = Vec3(total[3], total[4], total[5]);
  }
}

void FixMultisphere::sync_bodies() {
  // Each body's state is taken from the lowest rank where it is current (all
  // such ranks hold the same numbers); one reduction of ids, one of the state.
  Engine& e = engine_;
  if (!stale_) return;
  stale_ = false;
  Bodies& B = bodies_;
  const int nb = B.size();
  if (nb == 0) return;
  std::vector<int> holder(nb), first(nb);
  for (int b = 0; b < nb; ++b)
    holder[b] = B.current[b] ? e.rank : e.nprocs;
  MPI_Allreduce(holder.data(), first.data(), nb, MPI_INT, MPI_MIN, e.world);
  constexpr int kState = Bodies::kStateSize;
  std::vector<double> state(kState * static_cast<std::size_t>(nb), 0.0), all(state.size());
  for (int b = 0; b < nb; ++b)
    if (first[b] == e.rank) B.pack_state(b, &state[kState * static_cast<std::size_t>(b)]);
  MPI_Allreduce(state.data(), all.data(), static_cast<int>(all.size()), MPI_DOUBLE, MPI_SUM, e.world);
  for (int b = 0; b < nb; ++b) {
    if (B.current[b]) continue;
    if (first[b] >= e.nprocs) {
      throw RunError("fix multisphere " + id + ": no rank holds the current state of clump " +
                     std::to_string(B.tag[b]));
    }
    B.unpack_state(b, &all[kState * static_cast<std::size_t>(b)]);
  }
  invalidate_ = true;
}

void FixMultisphere::pre_neighbor() {
  // Ghosts exist here: removing particles drops them, so they are rebuilt.
  if (pending_) resolve_new_spheres();
  if (remove_incomplete_bodies() > 0) engine_.comm->borders();
  fill_body_mass();
  reindex();  // particles migrated and were reordered; bodies may have come or gone
  // A body whose sub-spheres all left this rank here misses this step's
  // second half kick on this rank: its record stops being current now (not
  // only at the next step), so that sync_bodies() at the end of this step
  // takes the body from a rank that advances it.
  if (engine_.nprocs > 1) {
    for (int b = 0; b < bodies_.size(); ++b)
      if (!is_active_[b]) bodies_.current[b] = 0;
    stale_ = true;  // on every rank: sync_bodies() is collective
  }
}

void FixMultisphere::setup() {
  if (pending_) resolve_new_spheres();
  check_index();
  sum_forces();
  place_spheres(false);
}

void FixMultisphere::initial_integrate() {
  if (pending_) resolve_new_spheres();
  check_index();
  Bodies& B = bodies_;
  const int nb = B.size();
  if (invalidate_) {
    // from now on only the active bodies are advanced here
    for (int b = 0; b < nb; ++b)
      B.current[b] = is_active_[b];
    invalidate_ = false;
  }
  if (engine_.nprocs > 1) stale_ = true;
  const double dt = engine_.update->dt, dtf = 0.5 * dt;
  rot_.resize(nb);
  // active bodies in groups of four (see rotate_many)
  constexpr int kGroup = 4;
  const int na = static_cast<int>(active_.size());
  for (int a0 = 0; a0 < na; a0 += kGroup) {
    const int m = std::min(kGroup, na - a0);
    const int* const act = &active_[a0];
    Vec3 lb[kGroup], inertia[kGroup];
    Eigen::Quaterniond q[kGroup];
    for (int j = 0; j < m; ++j) {
      const int b = act[j];
      B.vcm[b] += (dtf / B.mass[b]) * B.fcm[b];
      B.angmom[b] += dtf * B.torque[b];
      B.xcm[b] += dt * B.vcm[b];
      // torque-free rotation for dt; the space-frame angular momentum is
      // unchanged (rot_[b] is the rotation matrix of quat[b]: set at the end of
      // the last step, or by compute_rotations when the body became active)
      lb[j] = rot_[b].transpose() * B.angmom[b];
      q[j] = B.quat[b];
      inertia[j] = B.inertia[b];
    }
    if (m == kGroup) {
      rotate_free_many<kGroup>(q, lb, inertia, dt);
    } else {
      for (int j = 0; j < m; ++j)
        rotate_free(q[j], lb[j], inertia[j], dt);
    }
    for (int j = 0; j < m; ++j) {
      const int b = act[j];
      B.quat[b] = q[j];
      // the rotation matrix of the step, also used for omega (as omega_from_angmom)
      // (omega from the matrix in hand: read back from rot_ just after being
      // stored, it would wait for the stores)
      const Eigen::Matrix3d r = B.rotation(b);
      rot_[b] = r;
      B.omega[b] = omega_from(r, b);
    }
  }
  place_spheres(true);
}

void FixMultisphere::final_integrate() {
  sum_forces();
  const double dtf = 0.5 * engine_.update->dt;
  Bodies& B = bodies_;
  // The bodies' spins and the sub-spheres' velocities are set again at the
  // start of the next step, before any force uses them; here they are only
  // needed by whatever reads the bodies or particles at the end of this step.
  const bool observed = engine_.update->step_observed();
  for (int b : active_) {
    B.vcm[b] += (dtf / B.mass[b]) * B.fcm[b];
    B.angmom[b] += dtf * B.torque[b];
    if (observed) B.omega[b] = omega_from(b);
  }
  if (observed) place_spheres(false);
}

// ---------------------------------------------------------------- restart

void FixMultisphere::pack_restart(std::string& out) const {
  bodies_.pack(out);
}

void FixMultisphere::unpack_restart(const std::string& in) {
  try {
    bodies_.unpack(in);
  } catch (const std::runtime_error& e) {
    throw InputError("fix multisphere " + id + ": the restart file's clump data is unreadable (" + e.what() +
                     ")");
  }
  pending_ = false;
  reindex_ = true;
  stale_ = false;
  bodies_changed();
}

GRANARY_FIX_STYLE("multisphere", FixMultisphere);

}  // namespace granary
