#include "fix/fix_wall_gran.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "comm/collectives.h"
#include "contact/contact_block.h"
#include "contact/contact_kernels.h"
#include "core/force.h"
#include "pair/multicontact.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix_mesh_surface.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"

namespace granary {

namespace {

/// One contact of a particle with a wall, collected for a block.
struct WallContact {
  int i;                  ///< the particle
  double overlap, m_eff;  ///< m_eff: the particle's (or its clump's) mass
  double overlap0;        ///< the geometric overlap (surface multicontact changes `overlap`)
  double r;               ///< the radius the contact law sees (surface multicontact: changed)
  double key;             ///< surface multicontact: the contact's key
  Vec3 n, v_rel;          ///< normal towards the centre; velocity relative to the wall at the contact
  const contact::PairMaterial* mat;  ///< particle type and wall type
  double* h;                         ///< the contact's history doubles
  int mesh, tri;                     ///< mesh walls: the mesh and triangle (for their forces)
};

/// Contacts gathered before a block is evaluated.
constexpr int kWallBlock = 64;
/// Room for the copies of a block's last contact that fill its last group (pad_block()).
constexpr int kWallPad = contact::lane::width<contact::lane::Wide>() - 1;

// GCC 12 takes the lanes of the material, filled one at a time from the
// contacts, for maybe uninitialized in the run-time kernel's instance (they are
// value-initialized in evaluate_block); the pair loop's same code does not warn.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
/// The n wall contacts of blk through the pair loop's block machinery
/// (contact/contact_block.h), W at a time; then apply(contact, force,
/// torque) for each, in blk's order. blk has room for W - 1 more (the copies
/// of the last contact that fill the last group).
template <class K, class S, class Apply>
void evaluate_wall_block(const contact::ModelSpec& spec, contact::HistoryDt dt, WallContact* blk, int n,
                         const double* radius, const Vec3* omega, Apply&& apply) {
  using namespace contact;
  using lane::V3;
  constexpr int W = lane::width<S>();
  pad_block<W>(blk, n);
  PreparedT<S> prep[(kWallBlock + FixWallGran::kMeshSlots + W - 1) / W];
  // a wall: r_j = 0, R* = r_i, m* = m_i, no spin
  auto geometry = [&](int m, GeometryT<S>& g, MaterialT<S>& mat) __attribute__((always_inline)) {
    const PairMaterial* pm[W];
    for (int l = 0; l < W; ++l) {
      const WallContact& w = blk[m + l];
      lane::set(g.n, l, w.n);
      lane::set(g.overlap, l, w.overlap);
      lane::set(g.r_i, l, w.r);
      lane::set(g.m_eff, l, w.m_eff);
      lane::set(g.omega_i, l, omega[w.i]);
      pm[l] = w.mat;
    }
    set_materials(mat, pm);
    g.r_j = lane::splat<S>(0.0);
    g.r_eff = g.r_i;
    g.omega_j = lane::zero3<S>();
    // epsd, epsd3: I_r = I_i + m_i r_i^2 of a solid sphere
    g.i_roll = rolling_dashpot(K::rolling(spec)) ? S(1.4 * g.m_eff * g.r_i * g.r_i) : lane::splat<S>(0.0);
  };
  auto load = [&](int m, V3<S>& v_rel, V3<S>& shear, SlipT<S>& slip, V3<S>& roll)
      __attribute__((always_inline)) {
    const double* h[W];
    for (int l = 0; l < W; ++l) {
      const WallContact& w = blk[m + l];
      lane::set(v_rel, l, w.v_rel);
      h[l] = w.h;
    }
    load_history<K>(spec, h, shear, slip, roll);
  };
  auto store = [&](int m, int nvalid, const GroupOut<S>& r) __attribute__((always_inline)) {
    for (int l = 0; l < nvalid; ++l) {
      const WallContact& w = blk[m + l];
      store_history<K>(spec, r, l, w.h);
      apply(w, GroupOut<S>::at(r.force, l), GroupOut<S>::at(r.torque_i, l));
    }
  };
  evaluate_block<K, S>(spec, n, dt, prep, geometry, load, store);
}
#pragma GCC diagnostic pop

}  // namespace

FixWallGran::FixWallGran(Engine& engine, const Args& args) : Fix(engine, args) {
  const std::string usage =
      "fix ID group wall/gran model hertz tangential history [rolling_friction cdt] primitive type T "
      "xplane|yplane|zplane POS | zcylinder RADIUS CX CY";
  std::vector<std::string> words(args.begin() + 3, args.end());
  std::size_t pos = 0;
  try {
    spec_ = contact::parse_model_words(words, pos);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("fix wall/gran: ") + e.what());
  }
  if (contact::liquid_bridge(spec_.cohesion))
    throw InputError(
        "fix wall/gran: the liquid-bridge cohesion models (easo/capillary/viscous, "
        "washino/capillary/viscous) act between particles only (pair_style gran), as in "
        "LIGGGHTS; use another cohesion model or none for the wall");
  if (pos >= words.size()) throw InputError("fix wall/gran needs a wall; usage: " + usage);
  if (words[pos] == "mesh") {
    // mesh n_meshes N meshes M1 ... MN
    const std::string mesh_usage = "fix ID group wall/gran model ... mesh n_meshes N meshes M1 M2 ...";
    ++pos;
    if (pos + 1 >= words.size() || words[pos] != "n_meshes")
      throw InputError("fix wall/gran mesh needs 'n_meshes N'; usage: " + mesh_usage);
    const long long n = parse_int(words[pos + 1], "fix wall/gran n_meshes");
    if (n < 1) throw InputError("fix wall/gran: n_meshes must be at least 1");
    pos += 2;
    if (pos >= words.size() || words[pos] != "meshes")
      throw InputError("fix wall/gran mesh needs 'meshes M1 ...' after n_meshes; usage: " + mesh_usage);
    ++pos;
    if (words.size() - pos != static_cast<std::size_t>(n)) {
      throw InputError("fix wall/gran: n_meshes is " + std::to_string(n) + " but " +
                       std::to_string(words.size() - pos) + " mesh ID(s) follow 'meshes'");
    }
    for (; pos < words.size(); ++pos) {
      FixMeshSurface::find(*engine.modify, words[pos], "fix " + id + " wall/gran");
      mesh_ids_.push_back(words[pos]);
    }
    mesh_ = true;
    size_vector = 3;
    nhist_ = contact::history_size(spec_);
    if (nhist_ > 0) {
      // slots of (triangle key, contact point, history); the name records the layout
      const int ncomp = kInlineSlots * (kSlotHeader + nhist_);
      field_name_ =
          "mesh_wall_history/" + id + "/" + std::to_string(kInlineSlots) + "/" + std::to_string(nhist_);
      restart_global = true;  // the extra slots (see extra_)
      field_ = engine.particles->add_field(field_name_, ncomp, false, true);
      engine.particles->extras[field_].history = true;
      count_name_ = "mesh_wall_contacts/" + id;
      count_field_ = engine.particles->add_field(count_name_, 1, false, true);
      engine.particles->extras[count_field_].history = true;
    }
    return;
  }
  if (words[pos] != "primitive") {
    throw InputError("fix wall/gran: expected 'primitive', got '" + words[pos] + "'; usage: " + usage);
  }
  ++pos;
  if (pos + 1 >= words.size() || words[pos] != "type")
    throw InputError("fix wall/gran primitive needs 'type T'; usage: " + usage);
  wall_type_ = static_cast<int>(parse_int(words[pos + 1], "wall type"));
  if (wall_type_ < 1 || wall_type_ > engine.particles->ntypes) {
    throw InputError("fix wall/gran: wall type " + words[pos + 1] + " is outside 1.." +
                     std::to_string(engine.particles->ntypes));
  }
  pos += 2;
  if (pos >= words.size()) throw InputError("fix wall/gran: missing wall shape; usage: " + usage);
  const std::string& shape = words[pos++];
  auto need = [&](std::size_t n) {
    if (pos + n > words.size())
      throw InputError("fix wall/gran " + shape + " needs " + std::to_string(n) +
                       " value(s); usage: " + usage);
  };
  if (shape == "xplane" || shape == "yplane" || shape == "zplane") {
    need(1);
    shape_ = shape == "xplane" ? Shape::XPlane : shape == "yplane" ? Shape::YPlane : Shape::ZPlane;
    pos_ = parse_double(words[pos++], shape + " position");
  } else if (shape == "zcylinder") {
    need(3);
    shape_ = Shape::ZCylinder;
    cyl_r_ = parse_double(words[pos++], "zcylinder radius");
    cyl_cx_ = parse_double(words[pos++], "zcylinder centre x");
    cyl_cy_ = parse_double(words[pos++], "zcylinder centre y");
    if (cyl_r_ <= 0) throw InputError("fix wall/gran zcylinder radius must be positive");
  } else {
    throw InputError("fix wall/gran: unknown primitive '" + shape +
                     "'; expected xplane, yplane, zplane or zcylinder");
  }
  if (pos != words.size())
    throw InputError("fix wall/gran: unexpected word '" + words[pos] + "'; usage: " + usage);
  nhist_ = contact::history_size(spec_);
  if (nhist_ > 0) {
    field_name_ = "wall_history/" + id + "/" + std::to_string(nhist_);
    field_ = engine.particles->add_field(field_name_, nhist_, false, true);
    engine.particles->extras[field_].history = true;
  }
}

void FixWallGran::unfixed() {
  if (!field_name_.empty()) engine_.particles->release_field(field_name_);
  if (!count_name_.empty()) engine_.particles->release_field(count_name_);
  extra_.clear();
  incoming_.clear();
}

// ------------------------------------------------ extra mesh contact slots

void FixWallGran::pack_extra(std::vector<double>& out) const {
  const int stride = kSlotHeader + nhist_;
  for (const auto& [tag, slots] : extra_) {
    out.push_back(static_cast<double>(tag));
    out.push_back(static_cast<double>(slots.size() / stride));
    out.insert(out.end(), slots.begin(), slots.end());
  }
}

void FixWallGran::pre_exchange() {
  if (!mesh_ || nhist_ == 0 || engine_.nprocs == 1) return;
  long long mine = static_cast<long long>(extra_.size()), any = 0;
  MPI_Allreduce(&mine, &any, 1, MPI_LONG_LONG, MPI_MAX, engine_.world);
  if (any == 0) return;
  std::vector<double> local;
  pack_extra(local);
  extra_.clear();
  const std::vector<double> all = allgather(engine_.world, local);
  incoming_.insert(incoming_.end(), all.begin(), all.end());
}

void FixWallGran::adopt_extra() {
  if (incoming_.empty() && extra_.empty()) return;
  Particles& p = *engine_.particles;
  std::unordered_map<tagint, int> local;
  local.reserve(static_cast<std::size_t>(p.nlocal));
  for (int i = 0; i < p.nlocal; ++i)
    local.emplace(p.id[i], i);
  // records of particles no longer here (migrated, deleted) are dropped
  for (auto it = extra_.begin(); it != extra_.end();)
    it = local.count(it->first) ? std::next(it) : extra_.erase(it);
  const std::size_t stride = static_cast<std::size_t>(kSlotHeader + nhist_);
  for (std::size_t m = 0; m + 2 <= incoming_.size();) {
    const tagint tag = static_cast<tagint>(incoming_[m]);
    const std::size_t n = static_cast<std::size_t>(incoming_[m + 1]) * stride;
    if (m + 2 + n > incoming_.size()) break;
    if (local.count(tag)) extra_[tag].assign(incoming_.begin() + m + 2, incoming_.begin() + m + 2 + n);
    m += 2 + n;
  }
  incoming_.clear();
}

void FixWallGran::convert_inline_slots() {
  Particles& p = *engine_.particles;
  const std::string prefix = "mesh_wall_history/" + id + "/", suffix = "/" + std::to_string(nhist_);
  const int stride = kSlotHeader + nhist_;
  for (std::size_t f = 0; f < p.extras.size(); ++f) {
    const std::string name = p.extras[f].name;
    if (name == field_name_ || name.size() <= prefix.size() + suffix.size() || name.rfind(prefix, 0) != 0 ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string k_text = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    if (k_text.empty() || k_text.find_first_not_of("0123456789") != std::string::npos) continue;
    const int k = std::stoi(k_text);
    if (k < 1 || p.extras[f].ncomp != k * stride) continue;
    // every particle's slots in order: the old inline ones, then its extra
    // record (the slots after them); the first kInlineSlots stay inline
    const std::vector<double> old = std::move(p.extras[f].data);
    p.release_field(name);
    double* const h = p.extras[field_].data.data();
    std::vector<double> slots;
    for (int i = 0; i < p.nlocal; ++i) {
      const double* o = &old[static_cast<std::size_t>(i) * k * stride];
      slots.clear();
      for (int q = 0; q < k && o[static_cast<std::size_t>(q) * stride] != 0.0; ++q)
        slots.insert(slots.end(), o + q * stride, o + (q + 1) * stride);
      if (auto it = extra_.find(p.id[i]); it != extra_.end()) {
        slots.insert(slots.end(), it->second.begin(), it->second.end());
        extra_.erase(it);
      }
      const std::size_t inline_values = static_cast<std::size_t>(kInlineSlots) * stride;
      double* const hi = h + static_cast<std::size_t>(i) * inline_values;
      std::fill_n(hi, inline_values, 0.0);
      std::copy_n(slots.begin(), std::min(slots.size(), inline_values), hi);
      if (slots.size() > inline_values) extra_[p.id[i]].assign(slots.begin() + inline_values, slots.end());
    }
    engine_.logger->print("fix " + id + " wall/gran: mesh contact history of the restart file (" +
                          std::to_string(k) + " slot(s) per particle) moved to " +
                          std::to_string(kInlineSlots) + "\n");
  }
}

void FixWallGran::clear_slots(int i, double* hist, double* count) {
  const int stride = kSlotHeader + nhist_;
  if (count[i] > kInlineSlots) extra_.erase(engine_.particles->id[i]);
  double* h = hist + static_cast<std::size_t>(i) * kInlineSlots * stride;
  for (int q = 0; q < kInlineSlots * stride; ++q)
    h[q] = 0.0;
  count[i] = 0.0;
}

void FixWallGran::prepare_restart() {
  restart_extra_.clear();
  if (!mesh_ || nhist_ == 0) return;
  std::vector<double> local;
  pack_extra(local);
  restart_extra_ = allgather(engine_.world, local);
}

void FixWallGran::pack_restart(std::string& out) const {
  const std::uint64_t n = restart_extra_.size();
  out.append(reinterpret_cast<const char*>(&n), sizeof n);
  out.append(reinterpret_cast<const char*>(restart_extra_.data()), n * sizeof(double));
}

void FixWallGran::unpack_restart(const std::string& in) {
  std::uint64_t n = 0;
  if (in.size() < sizeof n) return;
  std::memcpy(&n, in.data(), sizeof n);
  if (in.size() != sizeof n + n * sizeof(double)) {
    throw InputError("fix " + id + " wall/gran: the restart file's mesh contact data is unreadable");
  }
  const std::size_t at = incoming_.size();
  incoming_.resize(at + n);
  std::memcpy(incoming_.data() + at, in.data() + sizeof n, n * sizeof(double));
}

void FixWallGran::init() {
  materials_.build(engine_, spec_, "fix " + id + " wall/gran");
  mc_ = nullptr;
  if (spec_.surface == contact::SurfaceModel::Multicontact) {
    mc_ = engine_.force->multicontact;
    if (!mc_)
      throw InputError(
          "fix " + id +
          " wall/gran with 'surface multicontact' needs fix multicontact/halfspace (e.g. fix mc all "
          "multicontact/halfspace geometric_prefactor 1.125)");
    mc_ordinal_ = mc_->wall_ordinal(id);
  }
  body_mass_ = FieldRef(*engine_.particles, kBodyMassField);
  if (nhist_ > 0) field_ = engine_.particles->find_field(field_name_);
  if (mesh_ && nhist_ > 0) {
    // the slot counts follow from the slots (also for files that lack them)
    Particles& p = *engine_.particles;
    count_field_ = p.find_field(count_name_);
    const int stride = kSlotHeader + nhist_;
    adopt_extra();  // records read from a restart file
    convert_inline_slots();
    const double* h = p.extras[field_].data.data();
    double* count = p.extras[count_field_].data.data();
    for (int i = 0; i < p.nlocal; ++i) {
      int n = 0;
      while (n < kInlineSlots && h[(static_cast<std::size_t>(i) * kInlineSlots + n) * stride] != 0.0)
        ++n;
      if (n == kInlineSlots) {
        auto it = extra_.find(p.id[i]);
        if (it != extra_.end()) n += static_cast<int>(it->second.size()) / stride;
      }
      count[i] = n;
    }
  }
  if (mesh_) {
    meshes_.clear();
    key_base_.clear();
    int base = 0;
    for (const auto& m : mesh_ids_) {
      FixMeshSurface& fm = FixMeshSurface::find(*engine_.modify, m, "fix " + id + " wall/gran");
      if (fm.wall_type > materials_.ntypes()) {
        throw InputError("fix " + id + " wall/gran: mesh " + m + " has type " + std::to_string(fm.wall_type) +
                         ", which has no material");
      }
      meshes_.push_back(&fm);
      key_base_.push_back(base);
      base += fm.mesh.ntri();
    }
  }
  initialized_ = true;
}

double FixWallGran::compute_vector(int i) {
  if (!mesh_ || i < 0 || i > 2) return 0.0;
  double all[3];
  MPI_Allreduce(force_, all, 3, MPI_DOUBLE, MPI_SUM, engine_.world);
  return all[i];
}

bool FixWallGran::contact(const Vec3& x, double r, double& overlap, Vec3& n) const {
  if (shape_ == Shape::ZCylinder) {
    const double dx = x[0] - cyl_cx_, dy = x[1] - cyl_cy_;
    const double rho = std::sqrt(dx * dx + dy * dy);
    const double gap = std::fabs(rho - cyl_r_);
    if (gap >= r || rho == 0.0) return false;
    overlap = r - gap;
    const double sign = rho < cyl_r_ ? -1.0 : 1.0;  // inside: pushed towards the axis
    n = Vec3(sign * dx / rho, sign * dy / rho, 0.0);
    return true;
  }
  const int d = shape_ == Shape::XPlane ? 0 : shape_ == Shape::YPlane ? 1 : 2;
  const double dist = x[d] - pos_;
  if (std::fabs(dist) >= r) return false;
  overlap = r - std::fabs(dist);
  n.setZero();
  n[d] = dist >= 0 ? 1.0 : -1.0;
  return true;
}

double FixWallGran::gap(const Vec3& x) const {
  if (shape_ == Shape::ZCylinder) {
    const double dx = x[0] - cyl_cx_, dy = x[1] - cyl_cy_;
    return std::fabs(std::sqrt(dx * dx + dy * dy) - cyl_r_);
  }
  const int d = shape_ == Shape::XPlane ? 0 : shape_ == Shape::YPlane ? 1 : 2;
  return std::fabs(x[d] - pos_);
}

// Between two neighbour-list builds no particle moves more than half the skin
// when the list is checked every step (neigh_modify every 1 delay 0, the
// default): Neighbor::decide() rebuilds as soon as one has. So only particles
// closer to the wall than their radius plus the skin (twice the margin
// needed) can touch it before the next build; post_force visits just those.
// The others get their wall history cleared here, as post_force would have
// done when they left the wall. With other neigh_modify settings post_force
// visits every particle.
void FixWallGran::post_neighbor() {
  near_.clear();
  near_build_ = -1;
  if (mesh_ && nhist_ > 0) adopt_extra();
  const Neighbor& nb = *engine_.neighbor;
  if (nb.every != 1 || nb.delay != 0 || nb.once) return;
  if (mesh_) {
    list_near_mesh();
    return;
  }
  Particles& p = *engine_.particles;
  const double skin = nb.skin;
  double* const hist = nhist_ > 0 ? p.extras[field_].data.data() : nullptr;
  for (int i = 0; i < p.nlocal; ++i) {
    if (gap(p.x[i]) < p.radius[i] + skin) {
      near_.push_back(i);
    } else if (hist) {
      double* h = hist + static_cast<std::size_t>(i) * nhist_;
      for (int q = 0; q < nhist_; ++q)
        h[q] = 0.0;
    }
  }
  near_build_ = nb.nbuilds;
}

// Mesh form: a particle is listed when a triangle of one of the meshes lies
// within its radius plus the skin. The list holds only while no mesh moves
// (fix move/mesh changes the nodes every step): post_force checks the meshes'
// move counters and visits every particle when one changed.
void FixWallGran::list_near_mesh() {
  Particles& p = *engine_.particles;
  const double skin = engine_.neighbor->skin;
  double rmax = 0.0;
  for (int i = 0; i < p.nlocal; ++i)
    rmax = std::max(rmax, p.radius[i]);
  moves_.clear();
  for (FixMeshSurface* m : meshes_) {
    m->mesh.ensure_margin(rmax + skin);
    moves_.push_back(m->mesh.moves());
  }
  double* const hist = nhist_ > 0 ? p.extras[field_].data.data() : nullptr;
  double* const count = nhist_ > 0 ? p.extras[count_field_].data.data() : nullptr;
  for (int i = 0; i < p.nlocal; ++i) {
    const Vec3 xi = p.x[i];
    const double reach = p.radius[i] + skin;
    bool close = false;
    for (FixMeshSurface* m : meshes_) {
      const TriMesh& mesh = m->mesh;
      int nnear = 0;
      const int* near = mesh.near(xi, nnear);
      for (int q = 0; q < nnear && !close; ++q) {
        const int t = near[q];
        const double dn = (xi - mesh.corner(t, 0)).dot(mesh.normal(t));
        if (dn >= reach || dn <= -reach) continue;
        TriMesh::Feature feature;
        close = (mesh.closest_point(t, xi, feature) - xi).squaredNorm() < reach * reach;
      }
      if (close) break;
    }
    if (close) {
      near_.push_back(i);
    } else if (hist && count[i] != 0.0) {
      clear_slots(i, hist, count);
    }
  }
  near_build_ = engine_.neighbor->nbuilds;
}

bool FixWallGran::near_current() const {
  if (near_build_ < 0 || near_build_ != engine_.neighbor->nbuilds) return false;
  if (!mesh_) return true;
  if (moves_.size() != meshes_.size()) return false;
  for (std::size_t m = 0; m < meshes_.size(); ++m)
    if (meshes_[m]->mesh.moves() != moves_[m]) return false;
  return true;
}

void FixWallGran::post_force() {
  if (mesh_) {
    post_force_mesh();
    return;
  }
  Particles& p = *engine_.particles;
  const contact::HistoryDt dt{engine_.update->history_dt(), engine_.update->dt};
  double* hist_base = nhist_ > 0 ? p.extras[field_].data.data() : nullptr;
  // sub-spheres of clumps use their body's mass (field filled by fix multisphere)
  const double* body_mass = body_mass_.data(p);
  // Planes are tested inline (one coordinate per particle); this loop runs for
  // every particle near the wall on every step, so no calls or stores unless in contact.
  const bool plane = shape_ != Shape::ZCylinder;
  const int dim = shape_ == Shape::XPlane ? 0 : shape_ == Shape::YPlane ? 1 : 2;
  // local copies: the loop stores forces and history, which would otherwise
  // force the compiler to reload members and vector pointers each iteration
  const Vec3* const x = p.x.data();
  const Vec3* const v = p.v.data();
  const Vec3* const omega = p.omega.data();
  Vec3* const f = p.f.data();
  Vec3* const torque = p.torque.data();
  const double* const radius = p.radius.data();
  const double* const rmass = p.rmass.data();
  const int* const mask = p.mask.data();
  const int* const type = p.type.data();
  const int bit = groupbit;
  const double pos = pos_;
  const int wall_type = wall_type_;
  const contact::ModelSpec spec = spec_;
  const MaterialTable& materials = materials_;
  // the particles near the wall when the list is current, else all of them
  const bool use_near = near_current();
  const int* const near = near_.data();
  const int nvisit = use_near ? static_cast<int>(near_.size()) : p.nlocal;
  contact::dispatch_model(spec, [&](auto kernel) {
    using K = decltype(kernel);
    const int nh = K::history_size(spec);
    double dummy[contact::kMaxHistory] = {};
    // the contacts, a block at a time (contact/contact_block.h)
    WallContact blk[kWallBlock + kWallPad];
    int nblk = 0;
    MultiContact* const mc = mc_;
    const double mc_key = MultiContact::wall_key(mc_ordinal_, 0);
    auto apply = [&](const WallContact& w, const Vec3& force, const Vec3& tq) {
      f[w.i] += force;
      torque[w.i] += tq;
      if (mc)
        mc->record(p, w.i, w.key, MultiContact::offset(radius[w.i], w.overlap0, w.n), w.n, force.dot(w.n));
    };
    for (int m = 0; m < nvisit; ++m) {
      const int i = use_near ? near[m] : m;
      if (!(mask[i] & bit)) continue;
      double* h = nh > 0 ? hist_base + static_cast<std::size_t>(i) * nh : dummy;
      const double r = radius[i];
      double overlap = 0.0;
      Vec3 n;
      bool touching;
      if (plane) {
        const double dist = x[i][dim] - pos;
        touching = dist < r && dist > -r;
        if (touching) {
          overlap = r - std::fabs(dist);
          n.setZero();
          n[dim] = dist >= 0 ? 1.0 : -1.0;
        }
      } else {
        touching = contact(x[i], r, overlap, n);
      }
      if (!touching) {
        if (nh > 0) {
          bool stale = false;
          for (int q = 0; q < nh; ++q)
            stale |= h[q] != 0.0;
          if (stale)
            for (int q = 0; q < nh; ++q)
              h[q] = 0.0;
        }
        continue;
      }
      WallContact& w = blk[nblk++];
      w.i = i;
      w.overlap = overlap;
      w.overlap0 = overlap;
      w.r = r;
      if (mc) {
        // multicontact: the radius changed by the particle's other contacts
        w.key = mc_key;
        const double s = mc->shift(p, i, mc_key, x[i] + MultiContact::offset(r, overlap, n), n);
        w.r += s;
        w.overlap += s;
      }
      w.m_eff = body_mass && body_mass[i] > 0.0 ? body_mass[i] : rmass[i];
      w.n = n;
      w.v_rel = v[i];
      w.mat = &materials(type[i], wall_type);
      w.h = h;
      if (nblk == kWallBlock) {
        evaluate_wall_block<K, contact::lane::Wide>(spec, dt, blk, nblk, radius, omega, apply);
        nblk = 0;
      }
    }
    if (nblk > 0) evaluate_wall_block<K, contact::lane::Wide>(spec, dt, blk, nblk, radius, omega, apply);
  });
}

// The contacts a sphere (centre xi, radius r) physically has with the meshes
// (see post_force_mesh): every triangle within reach is a candidate, then
// face contacts are kept first, edge and corner contacts after them, dropping
// duplicates. Returns the number kept; their indices into cand are in kept.
int FixWallGran::mesh_contacts(const Vec3& xi, double r, tagint tag, Candidate* cand, int* kept) const {
  const int nmesh = static_cast<int>(meshes_.size());
  int ncand = 0;
  for (int m = 0; m < nmesh; ++m) {
    TriMesh& mesh = meshes_[m]->mesh;
    mesh.ensure_margin(r);
    int nnear = 0;
    const int* near = mesh.near(xi, nnear);
    for (int q = 0; q < nnear; ++q) {
      const int t = near[q];
      const double dn = (xi - mesh.corner(t, 0)).dot(mesh.normal(t));
      if (dn >= r || dn <= -r) continue;  // beyond the triangle's plane reach
      TriMesh::Feature feature;
      const Vec3 cp = mesh.closest_point(t, xi, feature);
      const Vec3 d = xi - cp;
      const double d2 = d.squaredNorm();
      if (d2 >= r * r) continue;
      Candidate cd;
      cd.mesh = m;
      cd.tri = t;
      cd.point = cp;
      cd.face = feature == TriMesh::kFace;
      if (cd.face) {
        cd.overlap = r - std::fabs(dn);
        cd.n = dn >= 0 ? mesh.normal(t) : Vec3(-mesh.normal(t));
      } else {
        if (!mesh.contact_valid(t, feature, cp, xi, 1e-10)) continue;
        const double dist = std::sqrt(d2);
        if (!(dist > 0.0)) continue;  // centre on the mesh: no direction
        cd.overlap = r - dist;
        cd.n = d * (1.0 / dist);
      }
      if (ncand == kMaxCandidates) {
        throw RunError("fix " + id + " wall/gran: particle " + std::to_string(tag) + " touches more than " +
                       std::to_string(kMaxCandidates) +
                       " mesh triangles; the mesh is much finer than the particles");
      }
      cand[ncand++] = cd;
    }
  }
  if (ncand == 0) return 0;
  // faces first, then edges and corners; drop duplicates
  const double eps = 1e-9 * r;
  int nkept = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (int a = 0; a < ncand; ++a) {
      const Candidate& ca = cand[a];
      if (ca.face != (pass == 0)) continue;
      bool drop = false;
      for (int b = 0; b < nkept && !drop; ++b) {
        const Candidate& cb = cand[kept[b]];
        if ((ca.point - cb.point).squaredNorm() <= eps * eps) drop = true;
        if (!drop && !ca.face && cb.face) {
          TriMesh::Feature ft;
          const TriMesh& mb = meshes_[cb.mesh]->mesh;
          drop = (mb.closest_point(cb.tri, ca.point, ft) - ca.point).squaredNorm() <= eps * eps;
        }
      }
      if (!drop) kept[nkept++] = a;
    }
  }
  return nkept;
}

// Finnie's erosion model as LIGGGHTS' mesh/surface/stress `wear finnie`
// defines it (doc/fixes/mesh_surface_stress.md): while the particle
// approaches the wall (its velocity relative to the wall has a component
// towards the contact point), the triangle gains
//   2 k v f(gamma) |F| dt / A,
// v the speed relative to the wall, gamma the impact angle between that
// velocity and the triangle's plane (tan gamma = v_n / v_t), f(gamma) =
// sin(2 gamma) - 3 sin^2(gamma) for tan gamma <= 1/3 and cos^2(gamma) / 3
// above, |F| the contact force, A the triangle's area, k = k_finnie of the
// particle's and the wall's types.
static void add_finnie_wear(FixMeshSurface& fm, const WallContact& w, const Vec3& force, int type,
                            double dt) {
  const double vn = -w.v_rel.dot(w.n);  // > 0: towards the contact point
  if (!(vn > 0.0)) return;
  const double v2 = w.v_rel.squaredNorm();
  const double v = std::sqrt(v2);
  const double vt = std::sqrt(std::max(0.0, v2 - vn * vn));
  double fg;
  if (3.0 * vn > vt) {
    const double c = vt / v;  // cos(gamma)
    fg = c * c / 3.0;
  } else {
    const double sg = vn / v, cg = vt / v;
    fg = 2.0 * sg * cg - 3.0 * sg * sg;
  }
  TriMesh& mesh = fm.mesh;
  mesh.tri_wear[w.tri] += 2.0 * fm.k_finnie[type] * v * fg * force.norm() * dt / mesh.area(w.tri);
}

// Sphere-triangle contacts of the mesh form. For each particle: the triangles
// near its centre (bin grid), the closest point on each, and then the contacts
// the sphere physically has, in this order:
//  1. face contacts (closest point inside a triangle): normal = the
//     triangle's normal (towards the centre), overlap = r - plane distance,
//     exactly as for a plane;
//  2. edge and corner contacts, only where the centre lies in the Voronoi
//     region of that edge or corner on the whole mesh (TriMesh::contact_valid:
//     an edge between coplanar triangles never counts), normal from the
//     closest point to the centre;
//  a contact is dropped when its point coincides with one already kept, and an
//  edge or corner contact also when its point lies on a triangle with a face
//  contact. So a sphere on a flat region made of many triangles has one
//  contact, in a concave corner one per face, on a convex edge one edge contact.
// History: up to kMeshSlots contacts per particle, each stored with its
// triangle key and contact point. A contact continues the history of the same
// triangle; a new contact without one takes over the history of the nearest
// contact of the previous step that ended (within half a radius), so a sphere
// rolling or sliding onto a neighbouring triangle keeps its tangential spring.
void FixWallGran::post_force_mesh() {
  Particles& p = *engine_.particles;
  const contact::HistoryDt dt{engine_.update->history_dt(), engine_.update->dt};
  const double* body_mass = body_mass_.data(p);
  double* hist_base = nhist_ > 0 ? p.extras[field_].data.data() : nullptr;
  double* const count = nhist_ > 0 ? p.extras[count_field_].data.data() : nullptr;
  const Vec3* const x = p.x.data();
  const Vec3* const v = p.v.data();
  const Vec3* const omega = p.omega.data();
  Vec3* const f = p.f.data();
  Vec3* const torque = p.torque.data();
  const double* const radius = p.radius.data();
  const double* const rmass = p.rmass.data();
  const int* const mask = p.mask.data();
  const int* const type = p.type.data();
  const int bit = groupbit;
  const contact::ModelSpec spec = spec_;
  const MaterialTable& materials = materials_;
  Vec3 total = Vec3::Zero();

  // candidate contacts of one particle (fixed storage: no allocation per step)
  Candidate cand[kMaxCandidates];
  int kept[kMaxCandidates];

  contact::dispatch_model(spec, [&](auto kernel) {
    using K = decltype(kernel);
    const int nh = K::history_size(spec);
    const int stride = kSlotHeader + nh;
    // The contacts go through the block machinery (contact/contact_block.h):
    // gathered, particle after particle, until a block is full, then
    // evaluated; the particles' slots are written back after the block.
    constexpr int kStage = kWallBlock + kMeshSlots;  // a block, plus the last particle's contacts
    WallContact blk[kStage + kWallPad];
    int nblk = 0;
    double
        fresh[kStage * (kSlotHeader + contact::kMaxHistory) + 1];  // the block's slots (key, point, history)
    struct Staged {
      int i, first, n;  // particle, its first contact in blk and fresh, number of contacts
    };
    Staged staged[kWallBlock];
    int nstaged = 0;
    double prev[kMeshSlots * (kSlotHeader + contact::kMaxHistory) +
                1];  // the slots of a particle with extra ones
    double zeros[contact::kMaxHistory] = {};
    // At run setup the forces leave the history as it was: the per-particle
    // slots are restored by Update, the extra ones are not written.
    const bool keep_extra = engine_.update->in_setup_forces;
    const double step_dt = engine_.update->dt;
    MultiContact* const mc = mc_;
    auto apply = [&](const WallContact& w, const Vec3& force, const Vec3& tq) {
      f[w.i] += force;
      torque[w.i] += tq;
      total -= force;
      if (mc)
        mc->record(p, w.i, w.key, MultiContact::offset(radius[w.i], w.overlap0, w.n), w.n, force.dot(w.n));
      FixMeshSurface& fm = *meshes_[w.mesh];
      fm.mesh.tri_force[w.tri] -= force;
      if (!fm.mesh.tri_moment.empty()) {  // at the contact point, on the triangle
        const Vec3 cp = x[w.i] - w.n * (radius[w.i] - w.overlap0);
        fm.mesh.tri_moment[w.tri] -= cp.cross(force);
      }
      if (fm.wear_finnie) add_finnie_wear(fm, w, force, type[w.i], step_dt);
    };
    // a particle's slots after its contacts were evaluated
    auto write_back = [&](const Staged& st) {
      const int i = st.i, nkept = st.n;
      const double* const slots = fresh + static_cast<std::size_t>(st.first) * stride;
      double* const h_inline = hist_base + static_cast<std::size_t>(i) * kInlineSlots * stride;
      const int ninline = std::min(nkept, kInlineSlots);
      for (int q = 0; q < ninline * stride; ++q)
        h_inline[q] = slots[q];
      for (int q = ninline * stride; q < kInlineSlots * stride; ++q)
        h_inline[q] = 0.0;
      if (!keep_extra) {
        if (nkept > kInlineSlots)
          extra_[p.id[i]].assign(slots + kInlineSlots * stride, slots + nkept * stride);
        else if (count[i] > kInlineSlots)
          extra_.erase(p.id[i]);
      }
      count[i] = nkept;
    };
    auto flush = [&]() {
      evaluate_wall_block<K, contact::lane::Wide>(spec, dt, blk, nblk, radius, omega, apply);
      for (int s = 0; s < nstaged; ++s)
        write_back(staged[s]);
      nblk = 0;
      nstaged = 0;
    };
    // the particles near the meshes when the list is current, else all of them
    const bool use_near = near_current();
    const int* const near_list = near_.data();
    const int nvisit = use_near ? static_cast<int>(near_.size()) : p.nlocal;
    for (int visit = 0; visit < nvisit; ++visit) {
      const int i = use_near ? near_list[visit] : visit;
      if (!(mask[i] & bit)) continue;
      const double r = radius[i];
      const Vec3 xi = x[i];
      // this particle's stored slots: the per-particle ones, followed by its
      // extra ones when it had more contacts than those hold
      double* const h_inline =
          nh > 0 ? hist_base + static_cast<std::size_t>(i) * kInlineSlots * stride : nullptr;
      const double* h = h_inline;
      int nold = nh > 0 ? static_cast<int>(count[i]) : 0;
      if (nold > kInlineSlots) {
        auto it = extra_.find(p.id[i]);
        const int nextra = it != extra_.end() ? static_cast<int>(it->second.size()) / stride : 0;
        nold = std::min(kInlineSlots + nextra, kMeshSlots);
        std::copy_n(h_inline, kInlineSlots * stride, prev);
        if (nextra > 0)
          std::copy_n(it->second.data(), (nold - kInlineSlots) * stride, prev + kInlineSlots * stride);
        h = prev;
      }
      const int nkept = mesh_contacts(xi, r, p.id[i], cand, kept);
      if (nkept == 0) {
        if (nh > 0) {
          if (count[i] != 0.0) {
            if (keep_extra) {
              for (int q = 0; q < kInlineSlots * stride; ++q)
                h_inline[q] = 0.0;
              count[i] = 0.0;
            } else {
              clear_slots(i, hist_base, count);
            }
          }
        }
        continue;
      }
      if (nkept > kMeshSlots) {
        throw RunError("fix " + id + " wall/gran: particle " + std::to_string(p.id[i]) + " has " +
                       std::to_string(nkept) + " mesh contacts at once, more than the " +
                       std::to_string(kMeshSlots) + " this fix keeps history for");
      }
      // match this step's contacts with the stored ones
      int source[kMeshSlots];
      bool used[kMeshSlots] = {};
      if (nh > 0) {
        for (int k = 0; k < nkept; ++k) {
          const Candidate& ck = cand[kept[k]];
          const double key = key_base_[ck.mesh] + ck.tri + 1;
          source[k] = -1;
          for (int s = 0; s < nold && h[s * stride] != 0.0; ++s)
            if (!used[s] && h[s * stride] == key) {
              source[k] = s;
              used[s] = true;
              break;
            }
        }
        for (int k = 0; k < nkept; ++k) {
          if (source[k] >= 0) continue;
          const Vec3& pk = cand[kept[k]].point;
          double best = 0.25 * r * r;
          for (int s = 0; s < nold && h[s * stride] != 0.0; ++s) {
            if (used[s]) continue;
            const double dd =
                (Vec3(h[s * stride + 1], h[s * stride + 2], h[s * stride + 3]) - pk).squaredNorm();
            if (dd < best) {
              best = dd;
              source[k] = s;
            }
          }
          if (source[k] >= 0) used[source[k]] = true;
        }
        staged[nstaged++] = Staged{i, nblk, nkept};
      }
      const double m_eff = body_mass && body_mass[i] > 0.0 ? body_mass[i] : rmass[i];
      for (int k = 0; k < nkept; ++k) {
        const Candidate& ck = cand[kept[k]];
        TriMesh& mesh = meshes_[ck.mesh]->mesh;
        double* hk = zeros;
        if (nh > 0) {
          double* slot = fresh + static_cast<std::size_t>(nblk) * stride;
          slot[0] = key_base_[ck.mesh] + ck.tri + 1;
          slot[1] = ck.point[0];
          slot[2] = ck.point[1];
          slot[3] = ck.point[2];
          hk = slot + kSlotHeader;
          const double* src = source[k] >= 0 ? h + source[k] * stride + kSlotHeader : nullptr;
          for (int q = 0; q < nh; ++q)
            hk[q] = src ? src[q] : 0.0;
        }
        WallContact& w = blk[nblk++];
        w.i = i;
        w.overlap = ck.overlap;
        w.overlap0 = ck.overlap;
        w.r = r;
        if (mc) {
          w.key =
              MultiContact::wall_key(mc_ordinal_, static_cast<long long>(key_base_[ck.mesh]) + ck.tri + 1);
          const double s = mc->shift(p, i, w.key, xi + MultiContact::offset(r, ck.overlap, ck.n), ck.n);
          w.r += s;
          w.overlap += s;
        }
        w.m_eff = m_eff;
        w.n = ck.n;
        w.v_rel = v[i] - mesh.velocity_at(ck.tri, ck.point);  // the wall material at the contact point
        w.mat = &materials(type[i], meshes_[ck.mesh]->wall_type);
        w.h = hk;
        w.mesh = ck.mesh;
        w.tri = ck.tri;
      }
      if (nblk >= kWallBlock) flush();
    }
    if (nblk > 0) flush();
  });
  for (int d = 0; d < 3; ++d)
    force_[d] = total[d];
}

void FixWallGran::local_contacts(int bits, const std::string& who, std::vector<LocalContact>& out) const {
  if (spec_.surface == contact::SurfaceModel::Multicontact)
    throw InputError(who + " recomputes the contact forces of fix " + id +
                     " from the positions, which 'surface multicontact' would give without its radius "
                     "changes (those come from the previous step's contacts): not supported with fix "
                     "multicontact/halfspace");
  if (!initialized_)
    throw InputError(who + " reports the contacts of fix " + id +
                     " wall/gran as a run finds them: use it during a run, or after `run 0`");
  const Particles& p = *engine_.particles;
  const double* body_mass = body_mass_.data(p);
  const int nh = nhist_;
  const double* hist = nh > 0 ? p.extras[field_].data.data() : nullptr;
  const double* count = mesh_ && nh > 0 ? p.extras[count_field_].data.data() : nullptr;
  const int stride = kSlotHeader + nh;
  Candidate cand[kMaxCandidates];
  int kept[kMaxCandidates];
  contact::ContactState c;
  c.dt = 0.0;  // the history as stored, not advanced
  c.r_j = 0.0;
  c.omega_j.setZero();
  auto evaluate = [&](LocalContact& lc, int wall_type) {
    const int i = lc.i;
    c.n = lc.n;
    c.overlap = lc.overlap;
    c.r_i = p.radius[i];
    c.r_eff = p.radius[i];
    c.m_eff = body_mass && body_mass[i] > 0.0 ? body_mass[i] : p.rmass[i];
    c.i_roll = contact::rolling_inertia(c.m_eff, c.r_i, 0.0, 0.0);
    c.v_rel = p.v[i] - lc.wall_v;
    c.omega_i = p.omega[i];
    lc.res = contact::ContactResult();
    std::vector<double> h = lc.history;  // evaluate may rescale it
    h.resize(std::max(nh, 1), 0.0);
    contact::evaluate(spec_, c, materials_(p.type[i], wall_type), h.data(), lc.res);
    out.push_back(lc);
  };
  for (int i = 0; i < p.nlocal; ++i) {
    if (!(p.mask[i] & groupbit) || !(p.mask[i] & bits)) continue;
    const double r = p.radius[i];
    const Vec3& xi = p.x[i];
    LocalContact lc;
    lc.i = i;
    if (!mesh_) {
      if (!contact(xi, r, lc.overlap, lc.n)) continue;
      lc.point = xi - (r - lc.overlap) * lc.n;
      lc.wall_v = Vec3::Zero();
      if (nh > 0)
        lc.history.assign(hist + static_cast<std::size_t>(i) * nh,
                          hist + static_cast<std::size_t>(i + 1) * nh);
      else
        lc.history.clear();
      evaluate(lc, wall_type_);
      continue;
    }
    const int nkept = mesh_contacts(xi, r, p.id[i], cand, kept);
    if (nkept == 0) continue;
    // the particle's stored slots: the per-particle ones, then the extra ones
    std::vector<double> slots;
    if (nh > 0) {
      const double* h = hist + static_cast<std::size_t>(i) * kInlineSlots * stride;
      slots.assign(h, h + kInlineSlots * stride);
      if (count[i] > kInlineSlots) {
        auto it = extra_.find(p.id[i]);
        if (it != extra_.end()) slots.insert(slots.end(), it->second.begin(), it->second.end());
      }
    }
    for (int k = 0; k < nkept; ++k) {
      const Candidate& ck = cand[kept[k]];
      const TriMesh& mesh = meshes_[ck.mesh]->mesh;
      lc.mesh = ck.mesh;
      lc.tri = ck.tri;
      lc.point = ck.point;
      lc.n = ck.n;
      lc.overlap = ck.overlap;
      lc.wall_v = mesh.velocity_at(ck.tri, ck.point);
      lc.history.assign(nh, 0.0);
      // the history of the slot of this triangle (none before the contact's first force evaluation)
      const double key = key_base_[ck.mesh] + ck.tri + 1;
      for (std::size_t at = 0; nh > 0 && at + stride <= slots.size(); at += stride)
        if (slots[at] == key) {
          std::copy_n(slots.begin() + at + kSlotHeader, nh, lc.history.begin());
          break;
        }
      evaluate(lc, meshes_[ck.mesh]->wall_type);
    }
  }
}

GRANARY_FIX_STYLE("wall/gran", FixWallGran);

}  // namespace granary
