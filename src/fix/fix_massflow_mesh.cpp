// fix ID group massflow/mesh mesh MESH-ID [vec_side VX VY VZ]
//     [point_at_outlet PX PY PZ [inside_out]] [count once|multiple]
//     [file F | append F] [writeTime] [screen yes|no] [delete_atoms yes|no]
// (LIGGGHTS syntax): mass and number of the group's particles whose centre
// passes through the triangles of a fix mesh/surface from its inner to its
// outer side. The outer side is the side vec_side points to (a planar mesh),
// or the side of each triangle that faces point_at_outlet (any mesh; the other
// side with inside_out).
//
// Every step, after the particles moved (post_integrate, as LIGGGHTS), each
// owned particle's centre has moved along the segment from where it was at
// the previous step (kept in unwrapped
// coordinates in a per-particle field that migrates with it, so periodic
// wrapping is no crossing) to where it is; a crossing is a segment that goes
// from the inner to the outer side of a triangle through the triangle (edges
// included; once per step however many triangles). The sums are kept per
// rank and added over the ranks when f_ID is read (collective, at most once
// per step: the rates are over the interval since the previous read).
// Particles counted with delete_atoms yes are deleted in pre_exchange of the
// next reneighbouring step. See doc/fixes/massflow_mesh.md.
//
// fix ID group massflow/mesh/sieve ... sieveSize S sieveSpacing A
//     sieveStiffness K [sieveDamping C] [sieveMultiSphereCanPass] [seed N]
// is the same counter on a mesh that is a sieve: a particle of the group that
// touches the mesh (its centre within its radius of the nearest point of the
// mesh) passes, at the first step of the contact, with the open-area
// probability of its diameter d, pi (S - d)^2 / (4 A^2) (0 for d >= S), drawn
// from a hash of the seed, the particle id and the step (the same on any
// number of ranks); otherwise, until the contact ends, the mesh pushes it
// back with the normal force max(0, K delta - C v_n) (post_force). See
// doc/fixes/massflow_mesh_sieve.md.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "comm/collectives.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/logger.h"
#include "core/modify.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/domain.h"
#include "fix/fix.h"
#include "fix/fix_mesh_surface.h"
#include "particles/clumps.h"
#include "neighbor/neighbor.h"
#include "particles/particles.h"

namespace granary {

namespace {

// per-particle state (component 0 of the field)
enum Track : int {
  kNew = 0,      // not seen by the fix yet: no previous position
  kFar = 1,      // tracked, never within reach of the mesh (marker -1)
  kNear = 2,     // has come within its radius plus the skin of the mesh (marker 0)
  kCounted = 3,  // counted at least once (marker 1)
};
constexpr int kComps = 4;  // state, previous unwrapped position (3)

// the sieve's per-particle state of the current contact with the mesh
enum SieveState : int {
  kNoContact = 0,
  kPasses = 1,        // passes through the mesh: no force until the contact ends
  kBlockedInner = 2,  // repelled, came from the inner side
  kBlockedOuter = 3,  // repelled, came from the outer side
};

constexpr double kPi = 3.14159265358979323846;

/// splitmix64's finaliser: a bijective mix of 64 bits.
std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class FixMassflowMesh : public Fix {
 public:
  FixMassflowMesh(Engine& engine, const Args& args, bool sieve = false) : Fix(engine, args), sieve_(sieve) {
    const std::string what = where();
    std::size_t k = 3;
    if (k + 1 >= args.size() || args[k] != "mesh")
      throw InputError(what + ": expected 'mesh MESH-ID' after the style, e.g. fix " + id + " " + args[1] +
                       " " + style + " mesh outlet vec_side 0 0 -1");
    mesh_id_ = args[k + 1];
    FixMeshSurface::find(*engine.modify, mesh_id_, what);
    k += 2;
    bool have_side = false;
    auto vec3 = [&](std::size_t at, const char* key) {
      if (at + 3 > args.size()) throw InputError(what + ": " + key + " needs three numbers");
      return Vec3(parse_double(args[at], what + " " + key), parse_double(args[at + 1], what + " " + key),
                  parse_double(args[at + 2], what + " " + key));
    };
    for (; k < args.size(); ++k) {
      const std::string& w = args[k];
      const bool has1 = k + 1 < args.size();
      if (w == "vec_side") {
        vec_side_ = vec3(k + 1, "vec_side");
        have_side = true;
        k += 3;
      } else if (w == "point_at_outlet") {
        point_ = vec3(k + 1, "point_at_outlet");
        use_point_ = true;
        k += 3;
      } else if (w == "inside_out") {
        inside_out_ = true;
      } else if (w == "count" && has1) {
        if (args[k + 1] != "once" && args[k + 1] != "multiple")
          throw InputError(what + ": count takes once or multiple, got '" + args[k + 1] + "'");
        once_ = args[k + 1] == "once";
        ++k;
      } else if ((w == "file" || w == "append") && has1) {
        file_ = args[k + 1];
        append_ = w == "append";
        ++k;
      } else if (w == "writeTime") {
        write_time_ = true;
      } else if (w == "screen" && has1) {
        screen_ = parse_bool(args[k + 1], what + " screen");
        ++k;
      } else if (w == "delete_atoms" && has1) {
        delete_ = parse_bool(args[k + 1], what + " delete_atoms");
        ++k;
      } else if (w == "mesh") {
        throw InputError(what + ": one mesh per fix; define another fix " + style + " for mesh '" +
                         (has1 ? args[k + 1] : std::string("?")) + "'");
      } else if (sieve_ && parse_sieve(args, k)) {
        // a sieve keyword (k is at its last word)
      } else {
        throw InputError(what + ": unknown keyword or missing value '" + w +
                         "'; expected vec_side, point_at_outlet, inside_out, count, file, append, writeTime, "
                         "screen or delete_atoms" +
                         (sieve_ ? std::string(", or sieveSize, sieveSpacing, sieveStiffness, sieveDamping, "
                                               "sieveMultiSphereCanPass, seed")
                                 : std::string()));
      }
    }
    if (sieve_) check_sieve();
    // LIGGGHTS 3.8's rules
    if (!have_side && !use_point_)
      throw InputError(what +
                       ": give the outer side of the mesh with vec_side VX VY VZ (a planar mesh) or "
                       "point_at_outlet PX PY PZ");
    if (inside_out_ && !use_point_)
      throw InputError(what +
                       ": inside_out flips the side given by point_at_outlet; without point_at_outlet "
                       "reverse vec_side instead");
    if (use_point_ && !once_)
      throw InputError(what + ": point_at_outlet requires count once (as in LIGGGHTS)");
    if (delete_ && !once_) throw InputError(what + ": delete_atoms yes requires count once (as in LIGGGHTS)");
    if (!use_point_) check_vec_side();

    size_vector = sieve_ ? 9 : 6;
    peratom_flag = true;
    restart_global = true;
    aliases.push_back("massflow_" + id);  // LIGGGHTS' name of the per-atom marker
    field_ = engine.particles->add_field(field_name(), kComps, false, true);
    if (sieve_) sieve_field_ = engine.particles->add_field(sieve_field_name(), 1, false, true);

    if (!file_.empty()) {
      // rank 0 writes; every rank learns whether it could open the file
      int ok = 1;
      if (engine.rank == 0) {
        fp_ = std::fopen(file_.c_str(), append_ ? "a" : "w");
        ok = fp_ ? 1 : 0;
        if (fp_) {
          std::fprintf(fp_, write_time_ ? "# ID time  diameter x y z u v w  (ex ey ez, color)\n"
                                        : "# ID diameter x y z u v w  (ex ey ez, color)\n");
          std::fflush(fp_);
        }
      }
      MPI_Bcast(&ok, 1, MPI_INT, 0, engine.world);
      if (!ok)
        throw InputError(what + ": cannot open '" + file_ +
                         "' for writing (does its directory exist and is it writable?)");
    }
  }

  ~FixMassflowMesh() override {
    if (fp_) std::fclose(fp_);
  }

  unsigned hooks() const override {
    return POST_INTEGRATE | (delete_ ? PRE_EXCHANGE : 0u) | (sieve_ ? POST_FORCE : 0u);
  }

  void unfixed() override {
    engine_.particles->release_field(field_name());
    if (sieve_) engine_.particles->release_field(sieve_field_name());
  }

  void init() override {
    mesh_ = &FixMeshSurface::find(*engine_.modify, mesh_id_, where());
    if (!use_point_) check_vec_side();
    field_ = engine_.particles->add_field(field_name(), kComps, false, true);
    if (sieve_) sieve_field_ = engine_.particles->add_field(sieve_field_name(), 1, false, true);
    if (delete_ && engine_.clumps)
      throw InputError(
          where() +
          ": delete_atoms yes deletes single spheres, which would break clumps of fix multisphere; "
          "use delete_atoms no (or fix clog-detect with remove yes, which removes whole clumps)");
    body_mass_ = FieldRef(*engine_.particles, kBodyMassField);
  }

  void setup() override {
    // positions of the previous step restart with the run (nothing moves between runs)
    Particles& p = *engine_.particles;
    double* f = field();
    for (int i = 0; i < p.nlocal; ++i) {
      double* s = f + static_cast<std::size_t>(i) * kComps;
      if (s[0] == kNew) s[0] = kFar;
      store_position(i, s);
    }
    if (last_step_ < 0) {
      last_step_ = engine_.update->ntimestep;
      last_time_ = engine_.update->time();
    }
  }

  void post_integrate() override {
    Particles& p = *engine_.particles;
    TriMesh& mesh = mesh_->mesh;
    const double skin = engine_.neighbor->skin;
    double* f = field();
    const double* body_mass = body_mass_.data(p);
    records_.clear();
    for (int i = 0; i < p.nlocal; ++i) {
      double* s = f + static_cast<std::size_t>(i) * kComps;
      if (s[0] == kNew) {  // inserted during the run: tracked from now on
        s[0] = kFar;
        store_position(i, s);
        continue;
      }
      if (!(p.mask[i] & groupbit)) {
        store_position(i, s);
        continue;
      }
      // the segment of this step, in the frame of the current position
      const Vec3 b = p.x[i];
      const Vec3 a = b - (unwrapped(i) - Vec3(s[1], s[2], s[3]));
      store_position(i, s);
      const double reach = p.radius[i] + skin;
      const double move = (b - a).norm();
      mesh.ensure_margin(std::max(reach, move));
      int n = 0;
      const int* cand = mesh.near(b, n);
      bool crossed = false;
      for (int c = 0; c < n; ++c) {
        const int t = cand[c];
        TriMesh::Feature feature;
        if (s[0] == kFar && (mesh.closest_point(t, b, feature) - b).norm() < reach) s[0] = kNear;
        if (crossed || (once_ && s[0] == kCounted)) continue;
        crossed = crosses(mesh, t, a, b);
      }
      if (!crossed) continue;
      s[0] = kCounted;
      const double share = body_mass && body_mass[i] > 0.0 ? p.rmass[i] / body_mass[i] : 1.0;
      mass_ += p.rmass[i];
      number_ += share;
      if (!file_.empty() || screen_) {
        const double rec[kRecord] = {static_cast<double>(p.id[i]),
                                     2.0 * p.radius[i],
                                     b[0],
                                     b[1],
                                     b[2],
                                     p.v[i][0],
                                     p.v[i][1],
                                     p.v[i][2]};
        records_.insert(records_.end(), rec, rec + kRecord);
      }
    }
    if (!file_.empty() || screen_) write_records();
  }

  // The sieve: every particle of the group touching the mesh either passes or
  // is pushed back, decided at the first step of each contact.
  void post_force() override {
    if (!sieve_) return;
    Particles& p = *engine_.particles;
    TriMesh& mesh = mesh_->mesh;
    double* state = engine_.particles->extras[sieve_field_].data.data();
    const double* body_mass = body_mass_.data(p);
    const std::int64_t step = engine_.update->ntimestep;
    Vec3 total = Vec3::Zero();
    for (int i = 0; i < p.nlocal; ++i) {
      if (!(p.mask[i] & groupbit)) {
        state[i] = kNoContact;
        continue;
      }
      const double r = p.radius[i];
      const Vec3 x = p.x[i];
      // the nearest point of the mesh
      mesh.ensure_margin(r);
      int n = 0;
      const int* cand = mesh.near(x, n);
      int tri = -1;
      Vec3 cp = Vec3::Zero();
      double best = r * r;
      for (int c = 0; c < n; ++c) {
        const int t = cand[c];
        const double dn = (x - mesh.corner(t, 0)).dot(mesh.normal(t));
        if (dn >= r || dn <= -r) continue;
        TriMesh::Feature feature;
        const Vec3 q = mesh.closest_point(t, x, feature);
        const double d2 = (x - q).squaredNorm();
        if (d2 < best) {
          best = d2;
          tri = t;
          cp = q;
        }
      }
      if (tri < 0) {
        state[i] = kNoContact;
        continue;
      }
      // the triangle's normal towards the outer side, and the signed
      // distance of the centre from its plane along it
      Vec3 m = mesh.normal(tri);
      if (m.dot(outer(mesh, tri)) < 0.0) m = -m;
      const double dn = (x - mesh.corner(tri, 0)).dot(m);
      if (state[i] == kNoContact) {
        bool inner = dn < 0.0;
        if (dn == 0.0) inner = p.v[i].dot(m) >= 0.0;  // centre on the mesh: from where it moves
        state[i] = passes(p, i, body_mass, step) ? kPasses : inner ? kBlockedInner : kBlockedOuter;
      }
      if (state[i] == kPasses) continue;
      // pushed back to the side it came from: across the mesh's faces along
      // the normal (also once its centre got past the mesh's plane), at the
      // mesh's edges away from the nearest point
      Vec3 normal;
      double overlap;
      const Vec3 off = x - cp;
      const Vec3 in_plane = off - off.dot(m) * m;
      if (in_plane.squaredNorm() <= 1e-18 * r * r) {
        const double side = state[i] == kBlockedInner ? -1.0 : 1.0;
        normal = side * m;
        overlap = r - side * dn;
      } else {
        const double dist = std::sqrt(best);
        normal = off / dist;
        overlap = r - dist;
      }
      const double vn = (p.v[i] - mesh.velocity_at(tri, cp)).dot(normal);
      const double fn = sieve_stiffness_ * overlap - sieve_damping_ * vn;
      if (!(fn > 0.0)) continue;  // the sieve pushes, never pulls
      const Vec3 f = fn * normal;
      p.f[i] += f;
      total += f;
      if (!mesh.tri_force.empty()) mesh.tri_force[tri] -= f;
      if (!mesh.tri_moment.empty()) mesh.tri_moment[tri] -= cp.cross(f);
    }
    sieve_force_ = -total;
  }

  void pre_exchange() override {
    if (!delete_) return;
    Particles& p = *engine_.particles;
    const double* f = field();
    std::vector<char> doomed(p.nlocal, 0);
    bool any = false;
    for (int i = 0; i < p.nlocal; ++i) {
      if (f[static_cast<std::size_t>(i) * kComps] == kCounted && (p.mask[i] & groupbit)) {
        doomed[i] = 1;
        any = true;
        deleted_mass_ += p.rmass[i];
        deleted_number_ += 1.0;
      }
    }
    if (any) engine_.delete_particles(doomed);
    long long mine = any ? static_cast<long long>(std::count(doomed.begin(), doomed.end(), 1)) : 0, total = 0;
    MPI_Allreduce(&mine, &total, 1, MPI_LONG_LONG, MPI_SUM, engine_.world);
    p.natoms -= total;
  }

  double compute_vector(int i) override {
    if (i < 0 || i >= size_vector) return 0.0;
    const std::int64_t step = engine_.update->ntimestep;
    if (step != summed_step_) {
      const double local[7] = {mass_,           number_,         deleted_mass_,  deleted_number_,
                               sieve_force_[0], sieve_force_[1], sieve_force_[2]};
      double total[7];
      MPI_Allreduce(local, total, 7, MPI_DOUBLE, MPI_SUM, engine_.world);
      const double now = engine_.update->time();
      if (last_step_ < 0) {
        last_step_ = step;
        last_time_ = now;
      }
      const double dt = now - last_time_;
      values_[0] = total[0];
      values_[1] = total[1];
      values_[2] = dt > 0.0 ? (total[0] - last_mass_) / dt : 0.0;
      values_[3] = dt > 0.0 ? (total[1] - last_number_) / dt : 0.0;
      values_[4] = total[2];
      values_[5] = total[3];
      for (int d = 0; d < 3; ++d)
        values_[6 + d] = total[4 + d];
      // the rates of the next read are over the time from this one
      last_mass_ = total[0];
      last_number_ = total[1];
      last_time_ = now;
      last_step_ = step;
      summed_step_ = step;
    }
    return values_[i];
  }

  void peratom(int col, std::vector<double>& out) override {
    const Particles& p = *engine_.particles;
    const double* f = field();
    out.assign(p.nlocal, -1.0);
    if (col != 0) return;
    for (int i = 0; i < p.nlocal; ++i) {
      const double s = f[static_cast<std::size_t>(i) * kComps];
      out[i] = s == kCounted ? 1.0 : s == kNear ? 0.0 : -1.0;
    }
  }

  void prepare_restart() override {
    const double local[4] = {mass_, number_, deleted_mass_, deleted_number_};
    MPI_Allreduce(local, restart_totals_, 4, MPI_DOUBLE, MPI_SUM, engine_.world);
  }

  void pack_restart(std::string& out) const override {
    std::ostringstream os;
    os.precision(17);
    os << "massflow/mesh 1";
    for (double v : restart_totals_)
      os << ' ' << v;
    os << ' ' << last_mass_ << ' ' << last_number_ << ' ' << last_time_ << ' ' << last_step_;
    out = os.str();
  }

  void unpack_restart(const std::string& in) override {
    std::istringstream is(in);
    std::string tag;
    int version = 0;
    double t[4];
    is >> tag >> version >> t[0] >> t[1] >> t[2] >> t[3] >> last_mass_ >> last_number_ >> last_time_ >>
        last_step_;
    if (!is || tag != "massflow/mesh" || version != 1)
      throw InputError(where() + ": the restart file's state of this fix is not readable");
    // the totals so far count on rank 0 only
    const bool mine = engine_.rank == 0;
    mass_ = mine ? t[0] : 0.0;
    number_ = mine ? t[1] : 0.0;
    deleted_mass_ = mine ? t[2] : 0.0;
    deleted_number_ = mine ? t[3] : 0.0;
    summed_step_ = -1;
  }

 private:
  static constexpr int kRecord = 8;  // id, diameter, x(3), v(3)

  std::string where() const { return "fix " + id + " " + style; }
  std::string field_name() const { return "massflow/" + id; }
  std::string sieve_field_name() const { return "massflow_sieve/" + id; }

  /// Parse the sieve keyword at args[k] (advancing k to its last word);
  /// false if args[k] is none.
  bool parse_sieve(const Args& args, std::size_t& k) {
    const std::string what = where();
    const std::string& w = args[k];
    auto number = [&](double& to) {
      if (k + 1 >= args.size()) throw InputError(what + ": " + w + " needs a value");
      to = parse_double(args[k + 1], what + " " + w);
      ++k;
    };
    if (w == "sieveSize") {
      number(sieve_size_);
    } else if (w == "sieveSpacing") {
      number(sieve_spacing_);
    } else if (w == "sieveStiffness") {
      number(sieve_stiffness_);
    } else if (w == "sieveDamping") {
      number(sieve_damping_);
    } else if (w == "sieveMultiSphereCanPass") {
      ms_can_pass_ = true;
    } else if (w == "seed") {
      if (k + 1 >= args.size()) throw InputError(what + ": seed needs a value");
      const long long v = parse_int(args[k + 1], what + " seed");
      if (v <= 0) throw InputError(what + ": seed must be a positive integer, got " + args[k + 1]);
      seed_ = static_cast<std::uint64_t>(v);
      ++k;
    } else {
      return false;
    }
    return true;
  }

  void check_sieve() const {
    const std::string what = where();
    if (sieve_size_ < 0.0 || sieve_spacing_ < 0.0 || sieve_stiffness_ < 0.0)
      throw InputError(what + ": sieveSize, sieveSpacing and sieveStiffness must be given, e.g. sieveSize " +
                       "2e-3 sieveSpacing 2.5e-3 sieveStiffness 1e5 (sieveDamping is 0 by default)");
    if (!(sieve_size_ > 0.0)) throw InputError(what + ": sieveSize (the hole diameter) must be positive");
    if (!(sieve_stiffness_ > 0.0)) throw InputError(what + ": sieveStiffness must be positive");
    if (sieve_damping_ < 0.0) throw InputError(what + ": sieveDamping must not be negative");
    if (sieve_spacing_ < sieve_size_)
      throw InputError(what + ": sieveSpacing (" + args_to_string(sieve_spacing_) +
                       ", the distance between the centres of neighbouring holes) must be at least " +
                       "sieveSize (" + args_to_string(sieve_size_) + "): holes would overlap");
  }

  static std::string args_to_string(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
  }

  /// Probability that a sphere of diameter d passes the sieve.
  double pass_probability(double d) const {
    if (d >= sieve_size_) return 0.0;
    const double open = sieve_size_ - d;
    return kPi * open * open / (4.0 * sieve_spacing_ * sieve_spacing_);
  }

  /// Whether particle i, at the first step of a contact, passes.
  bool passes(const Particles& p, int i, const double* body_mass, std::int64_t step) const {
    if (body_mass && body_mass[i] > 0.0 && !ms_can_pass_) return false;
    const double prob = pass_probability(2.0 * p.radius[i]);
    if (prob <= 0.0) return false;
    const std::uint64_t h =
        mix64(mix64(mix64(seed_) ^ static_cast<std::uint64_t>(p.id[i])) ^ static_cast<std::uint64_t>(step));
    const double u = static_cast<double>(h >> 11) * 0x1.0p-53;  // uniform in [0, 1)
    return u < prob;
  }
  double* field() const { return engine_.particles->extras[field_].data.data(); }

  Vec3 unwrapped(int i) const {
    const Particles& p = *engine_.particles;
    int ix, iy, iz;
    Particles::image_unpack(p.image[i], ix, iy, iz);
    const Vec3& prd = engine_.domain->prd;
    return p.x[i] + Vec3(ix * prd[0], iy * prd[1], iz * prd[2]);
  }
  void store_position(int i, double* s) const {
    const Vec3 u = unwrapped(i);
    s[1] = u[0];
    s[2] = u[1];
    s[3] = u[2];
  }

  /// The outer normal of triangle t.
  Vec3 outer(const TriMesh& mesh, int t) const {
    if (!use_point_) return vec_side_;
    const Vec3& n = mesh.normal(t);
    const Vec3 c = (mesh.corner(t, 0) + mesh.corner(t, 1) + mesh.corner(t, 2)) / 3.0;
    Vec3 m = (point_ - c).dot(n) >= 0.0 ? n : Vec3(-n);
    return inside_out_ ? Vec3(-m) : m;
  }

  /// Whether the segment a -> b goes from the inner to the outer side of
  /// triangle t through the triangle.
  bool crosses(const TriMesh& mesh, int t, const Vec3& a, const Vec3& b) const {
    const Vec3 m = outer(mesh, t);
    const Vec3& p0 = mesh.corner(t, 0);
    const double sa = (a - p0).dot(m), sb = (b - p0).dot(m);
    if (!(sa < 0.0 && sb >= 0.0)) return false;
    const Vec3 q = a + (sa / (sa - sb)) * (b - a);
    TriMesh::Feature feature;
    const Vec3 on = mesh.closest_point(t, q, feature);
    // on the triangle, edges included (to round-off of its size)
    const double size = (mesh.corner(t, 1) - p0).norm() + (mesh.corner(t, 2) - p0).norm();
    return (on - q).norm() <= 1e-12 * size;
  }

  void check_vec_side() {
    const FixMeshSurface& m = FixMeshSurface::find(*engine_.modify, mesh_id_, where());
    const TriMesh& mesh = m.mesh;
    const std::string what = where();
    if (vec_side_.norm() == 0.0) throw InputError(what + ": vec_side must not be the zero vector");
    if (mesh.ntri() == 0) throw InputError(what + ": mesh " + mesh_id_ + " has no triangles");
    const Vec3 n0 = mesh.normal(0);
    for (int t = 1; t < mesh.ntri(); ++t)
      if (std::abs(std::abs(mesh.normal(t).dot(n0)) - 1.0) > 1e-6)
        throw InputError(
            what + ": vec_side needs a planar mesh, and mesh " + mesh_id_ + " is not (triangle " +
            std::to_string(t + 1) +
            " is not parallel to the first); use point_at_outlet with a point on the outlet side");
    if (std::abs(vec_side_.normalized().dot(n0)) < 1e-6)
      throw InputError(what + ": vec_side lies in the plane of mesh " + mesh_id_ +
                       "; give a vector pointing to the outer side of the mesh");
  }

  /// Gather this step's crossings to rank 0 and write them (sorted by id).
  void write_records() {
    long long mine = static_cast<long long>(records_.size()), total = 0;
    MPI_Allreduce(&mine, &total, 1, MPI_LONG_LONG, MPI_SUM, engine_.world);
    if (total == 0) return;
    const std::vector<double> all = gather_to_root(engine_.world, records_);
    if (engine_.rank != 0) return;
    std::vector<std::size_t> order(all.size() / kRecord);
    for (std::size_t k = 0; k < order.size(); ++k)
      order[k] = k;
    std::sort(order.begin(), order.end(),
              [&](std::size_t u, std::size_t v) { return all[u * kRecord] < all[v * kRecord]; });
    std::string text;
    char line[400];
    for (std::size_t k : order) {
      const double* r = &all[k * kRecord];
      if (write_time_)
        std::snprintf(line, sizeof line, "%lld %.10g %.10g %.10g %.10g %.10g %.10g %.10g %.10g\n",
                      static_cast<long long>(r[0]), engine_.update->time(), r[1], r[2], r[3], r[4], r[5],
                      r[6], r[7]);
      else
        std::snprintf(line, sizeof line, "%lld %.10g %.10g %.10g %.10g %.10g %.10g %.10g\n",
                      static_cast<long long>(r[0]), r[1], r[2], r[3], r[4], r[5], r[6], r[7]);
      text += line;
    }
    if (fp_) {
      std::fputs(text.c_str(), fp_);
      std::fflush(fp_);
    }
    if (screen_) engine_.logger->print(text);
  }

  // the sieve (massflow/mesh/sieve)
  bool sieve_ = false;
  double sieve_size_ = -1.0, sieve_spacing_ = -1.0, sieve_stiffness_ = -1.0, sieve_damping_ = 0.0;
  bool ms_can_pass_ = false;
  std::uint64_t seed_ = 5489;
  int sieve_field_ = -1;
  Vec3 sieve_force_ = Vec3::Zero();  // of the particles on the sieve, this rank, last step

  std::string mesh_id_;
  FixMeshSurface* mesh_ = nullptr;
  Vec3 vec_side_ = Vec3::Zero(), point_ = Vec3::Zero();
  bool use_point_ = false, inside_out_ = false, once_ = false;
  std::string file_;
  bool append_ = false, write_time_ = false, screen_ = false, delete_ = false;
  std::FILE* fp_ = nullptr;
  int field_ = -1;
  FieldRef body_mass_;

  // this rank's sums
  double mass_ = 0.0, number_ = 0.0, deleted_mass_ = 0.0, deleted_number_ = 0.0;
  // the last read of f_ID (the rates are over the time since)
  double last_mass_ = 0.0, last_number_ = 0.0, last_time_ = 0.0;
  std::int64_t last_step_ = -1, summed_step_ = -1;
  double values_[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  double restart_totals_[4] = {0, 0, 0, 0};
  std::vector<double> records_;
};

class FixMassflowMeshSieve : public FixMassflowMesh {
 public:
  FixMassflowMeshSieve(Engine& engine, const Args& args) : FixMassflowMesh(engine, args, true) {}
};

}  // namespace

GRANARY_FIX_STYLE("massflow/mesh", FixMassflowMesh);
GRANARY_FIX_STYLE("massflow/mesh/sieve", FixMassflowMeshSieve);

}  // namespace granary
