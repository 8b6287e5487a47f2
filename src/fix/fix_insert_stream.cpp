// fix ID group insert/stream seed SEED distributiontemplate DIST
//     nparticles N|INF | mass M|INF  particlerate R | massrate MR
//     insertion_face MESH  extrude_length L | insert_every STEPS  [general keywords of insert/pack]
//
// A stream of particles entering through a planar face (LIGGGHTS syntax). The
// insertion volume is the face (a fix mesh/surface) extruded by L along its
// normal, on the side the particles come from (the normal is flipped to point
// against the normal component of the insertion velocity v). Every STEPS
// steps a batch of rate * STEPS * dt particles (fractions carried over, as in
// insert/rate/region) is placed in that volume. The two lengths are tied by
// the time a particle needs to cross the volume: STEPS = floor(L / (|v.n| dt))
// when extrude_length is given, L = STEPS |v.n| dt when insert_every is given,
// so consecutive batches fill the stream behind the face without gaps.
//
// The centre of a particle of radius r is placed at r + h above the face,
// h uniform in [0, L] (as LIGGGHTS does, observed: no particle of a fresh
// batch touches the face), so the spheres of a batch lie wholly behind it.
//
// Until a particle reaches the face it is "held": it moves straight towards
// the face with the normal component of its insertion velocity, unaffected by
// any force (pair forces, gravity, walls); when its centre reaches the face it
// gets its full insertion velocity, so that the particles leave the face
// exactly as specified (this is what LIGGGHTS does: its kinetic energy right
// after an insertion is that of the normal velocity only). Held particles are
// marked in a per-particle field that migrates with them; their forces are
// zeroed in post_force and their position x0 + v_n (t - t0) and velocity are
// imposed in end_of_step.
//
// Placement, overlap check, ids, restart state and rank independence are those
// of FixInsert (fix_insert.h); the amount and rate keywords those of
// FixInsertRateRegion. See doc/fixes/insert_stream.md.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "domain/region.h"
#include "fix/fix_insert_rate_region.h"
#include "fix/fix_mesh_surface.h"
#include "fix/fix_particledistribution_discrete.h"
#include "core/modify.h"
#include "particles/particles.h"

namespace granary {

namespace {

const char* kUsage =
    "fix ID group insert/stream seed SEED distributiontemplate DIST nparticles N|INF | mass M|INF "
    "particlerate R | massrate MR insertion_face MESH-ID extrude_length L | insert_every STEPS "
    "[maxattempt N] [start STEP] [overlapcheck yes|no] [all_in yes|no] "
    "[random_distribute exact|uncorrelated] [vel constant VX VY VZ] [omega constant WX WY WZ] "
    "[parallel yes|no]";

/// The planar insertion face extruded by `length` along the unit normal `n`.
class ExtrudedFace : public Region {
 public:
  ExtrudedFace(Engine& engine) : Region(engine, {"insert_stream", "insert/stream"}, 0) {}

  std::vector<std::array<Vec3, 3>> tri;  // face triangles (in the face plane)
  Vec3 origin = Vec3::Zero();            // a point of the face
  Vec3 n = Vec3::UnitZ();                // extrusion direction (upstream)
  double length = 0.0, area = 0.0;
  double rmax = 0.0;  // largest particle radius: centres lie up to length + rmax from the face

  bool inside(const Vec3& x) const override {
    const double h = (x - origin).dot(n);
    if (h < 0.0 || h > length) return false;
    const Vec3 q = x - h * n;  // projection onto the face plane
    for (const auto& t : tri) {
      // q inside triangle t: on the inner side of its three edges
      bool in = true;
      for (int k = 0; k < 3 && in; ++k)
        in = (t[(k + 1) % 3] - t[k]).cross(q - t[k]).dot(n) * side_ >= 0.0;
      if (in) return true;
    }
    return false;
  }
  bool bounds(Vec3& lo, Vec3& hi) const override {
    lo = Vec3::Constant(std::numeric_limits<double>::max());
    hi = -lo;
    for (const auto& t : tri)
      for (const Vec3& c : t)
        for (const Vec3& p : {c, Vec3(c + (length + rmax) * n)}) {
          lo = lo.cwiseMin(p);
          hi = hi.cwiseMax(p);
        }
    return true;
  }
  double volume() const override { return area * length; }

  /// Set the triangles; their winding relative to n gives the edge-test sign.
  void set(std::vector<std::array<Vec3, 3>> t, const Vec3& normal) {
    tri = std::move(t);
    n = normal;
    area = 0.0;
    side_ = 0.0;
    for (auto& c : tri) {
      const Vec3 a = (c[1] - c[0]).cross(c[2] - c[0]);
      area += 0.5 * a.norm();
      // every triangle wound counter-clockwise about n
      if (a.dot(n) < 0.0) std::swap(c[1], c[2]);
    }
    side_ = 1.0;
    origin = tri.front()[0];
  }

 private:
  double side_ = 1.0;
};

class FixInsertStream : public FixInsertRateRegion {
 public:
  FixInsertStream(Engine& engine, const Args& args)
      : FixInsertRateRegion(engine, args,
                            {{"insertion_face", 1}, {"extrude_length", 1}, {"parallel", 1}, {"duration", 1}},
                            kUsage, true),
        face_(engine) {
    const std::string what = label();
    if (style_values_.count("duration"))
      throw InputError(what + ": the duration keyword (pulsed streams) is not supported");
    if (style_values_.count("parallel")) parse_bool(style_values_["parallel"][0], what + " parallel");
    if (!style_values_.count("insertion_face"))
      throw InputError(what + ": insertion_face MESH-ID is required; usage: " + kUsage);
    face_id_ = style_values_["insertion_face"][0];
    FixMeshSurface::find(*engine.modify, face_id_, what + " insertion_face");
    const bool has_length = style_values_.count("extrude_length") > 0;
    if (has_length == insert_every_given_) {
      throw InputError(what +
                       ": give exactly one of extrude_length and insert_every (the other follows from "
                       "the normal insertion velocity and the time step)");
    }
    if (has_length) {
      length_ = parse_double(style_values_["extrude_length"][0], what + " extrude_length");
      if (!(length_ > 0.0)) throw InputError(what + ": extrude_length must be positive");
    } else if (insert_every_ == 0) {
      throw InputError(what + ": insert_every must be a positive number of steps (not once)");
    }
    if (!(vel_.norm() > 0.0)) throw InputError(what + ": the insertion velocity (vel) must not be zero");
    held_field_ = engine.particles->add_field(field_name(), kHeldComps, false, true);
    region_id_ = "insertion face " + face_id_ + " extruded";
  }

  unsigned hooks() const override { return FixInsert::hooks() | POST_FORCE | END_OF_STEP; }

  void init() override {
    const std::string what = label();
    const FixParticleDistributionDiscrete& d = dist();
    if (d.any_multisphere())
      throw InputError(what + ": distribution " + dist_id_ +
                       " has a multisphere template; insert/stream inserts spheres");
    // the face: planar, its normal flipped against the normal velocity
    const TriMesh& m = FixMeshSurface::find(*engine_.modify, face_id_, what + " insertion_face").mesh;
    Vec3 n = m.normal(0);
    double extent = 0.0;
    for (int k = 0; k < m.nnodes(); ++k)
      extent = std::max(extent, (m.node(k) - m.node(0)).norm());
    for (int t = 0; t < m.ntri(); ++t) {
      const bool parallel = std::fabs(m.normal(t).dot(n)) > 1.0 - 1e-6;
      const bool in_plane = std::fabs((m.corner(t, 0) - m.corner(0, 0)).dot(n)) <= 1e-6 * extent;
      if (!parallel || !in_plane)
        throw InputError(what + ": the insertion face " + face_id_ + " is not planar (triangle " +
                         std::to_string(t + 1) + " leaves the plane of the first one)");
    }
    const double vn = vel_.dot(n);
    if (!(std::fabs(vn) > 1e-12 * vel_.norm()))
      throw InputError(what + ": the insertion velocity is parallel to the insertion face " + face_id_ +
                       "; it needs a component normal to the face");
    if (vn > 0.0) n = -n;  // extrude upstream: against the normal velocity
    const double dt = engine_.update->dt;
    if (style_values_.count("extrude_length")) {
      const double steps = length_ / (std::fabs(vn) * dt);
      insert_every_ = static_cast<int>(std::max(1.0, std::floor(steps * (1.0 + 1e-10))));
      face_.length = length_;
    } else {
      face_.length = insert_every_ * std::fabs(vn) * dt;
    }
    std::vector<std::array<Vec3, 3>> tri(m.ntri());
    for (int t = 0; t < m.ntri(); ++t)
      tri[t] = {m.corner(t, 0), m.corner(t, 1), m.corner(t, 2)};
    face_.set(std::move(tri), n);
    face_.rmax = d.max_bounding_radius();
    FixInsertRateRegion::init();
  }

  Vec3 candidate_shift(double r) const override { return r * face_.n; }

  void pre_exchange() override {
    Particles& p = *engine_.particles;
    const int nold = p.nlocal;
    FixInsert::pre_exchange();
    // the particles just added are held until they reach the face
    const double t0 = engine_.update->time();
    double* h = p.extras[held_field_].data.data();
    for (int i = nold; i < p.nlocal; ++i) {
      double* hi = h + static_cast<std::size_t>(i) * kHeldComps;
      hi[0] = 1.0;
      for (int d = 0; d < 3; ++d) {
        hi[1 + d] = p.x[i][d];
        hi[4 + d] = p.v[i][d];
      }
      hi[7] = t0;
    }
  }

  void post_force() override {
    Particles& p = *engine_.particles;
    const double* h = p.extras[held_field_].data.data();
    for (int i = 0; i < p.nlocal; ++i) {
      if (h[static_cast<std::size_t>(i) * kHeldComps] == 0.0) continue;
      p.f[i].setZero();
      p.torque[i].setZero();
    }
  }

  void end_of_step() override {
    Particles& p = *engine_.particles;
    double* h = p.extras[held_field_].data.data();
    const double t = engine_.update->time();
    for (int i = 0; i < p.nlocal; ++i) {
      double* hi = h + static_cast<std::size_t>(i) * kHeldComps;
      if (hi[0] == 0.0) continue;
      const Vec3 v(hi[4], hi[5], hi[6]);
      const Vec3 vn = v.dot(face_.n) * face_.n;  // towards the face
      p.x[i] = Vec3(hi[1], hi[2], hi[3]) + (t - hi[7]) * vn;
      p.v[i] = vn;
      p.omega[i] = omega_;
      // released with the full velocity once the centre has reached the face plane
      if ((p.x[i] - face_.origin).dot(face_.n) <= 0.0) {
        p.v[i] = v;
        hi[0] = 0.0;
      }
    }
  }

  void unfixed() override { engine_.particles->release_field(field_name()); }

  /// Number of particles still held (this rank).
  int held_local() const {
    const Particles& p = *engine_.particles;
    const double* h = p.extras[held_field_].data.data();
    int n = 0;
    for (int i = 0; i < p.nlocal; ++i)
      n += h[static_cast<std::size_t>(i) * kHeldComps] != 0.0;
    return n;
  }

 protected:
  Region& region() const override { return const_cast<ExtrudedFace&>(face_); }

 private:
  // held flag, insertion position (3), velocity (3), time
  static constexpr int kHeldComps = 8;
  std::string field_name() const { return "insert/stream/" + id + "/held"; }

  std::string face_id_;
  double length_ = 0.0;
  ExtrudedFace face_;
  int held_field_ = -1;
};

}  // namespace

GRANARY_FIX_STYLE("insert/stream", FixInsertStream);

}  // namespace granary
