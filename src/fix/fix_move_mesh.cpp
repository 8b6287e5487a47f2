// fix ID group move/mesh mesh M linear VX VY VZ
// fix ID group move/mesh mesh M rotate origin PX PY PZ axis AX AY AZ period T
// (LIGGGHTS syntax): moves the nodes of fix mesh/surface M rigidly, at
// constant velocity V (linear) or at angular velocity omega = 2 pi / T about
// the axis through P (rotate, right-hand rule), and sets the velocity field
// the wall contacts see (V, or omega x (x - P) at each contact point). The
// position is computed from the positions when the fix was defined,
// X(t) = X0 + V (t - t0) or X(t) = P + R(omega (t - t0)) (X0 - P), every step
// in the initial_integrate stage (when the particles drift), so it does not
// accumulate round-off. X0, t0 and the motion parameters go into restart
// files: the same fix defined again after read_restart with the same
// parameters continues the same motion bit for bit. The group is ignored.
// See doc/fixes/move_mesh.md.
#include <Eigen/Geometry>
#include <cmath>
#include <cstring>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "fix/fix_mesh_surface.h"
#include "core/modify.h"

namespace granary {

namespace {

class FixMoveMesh : public Fix {
 public:
  FixMoveMesh(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage =
        "fix ID group move/mesh mesh MESH-ID linear VX VY VZ | rotate origin PX PY PZ axis AX AY AZ period T";
    const std::string where = "fix " + id + " move/mesh";
    if (args.size() < 5 || args[3] != "mesh")
      throw InputError(where + ": expected 'mesh MESH-ID' first; usage: " + usage);
    mesh_id_ = args[4];
    FixMeshSurface& m = FixMeshSurface::find(*engine.modify, mesh_id_, where);
    if (m.servo_wall)
      throw InputError(where + ": mesh " + mesh_id_ +
                       " is a servo wall (mesh/surface/stress/servo), moved by its controller only");
    if (args.size() < 6) throw InputError(where + ": missing the motion style; usage: " + usage);
    if (args[5] == "linear") {
      require_args(args, 9, 9, usage);
      for (int d = 0; d < 3; ++d)
        velocity_[d] = parse_double(args[6 + d], where + " velocity");
      params_ = {velocity_[0], velocity_[1], velocity_[2]};
    } else if (args[5] == "rotate") {
      require_args(args, 16, 16, usage);
      if (args[6] != "origin" || args[10] != "axis" || args[14] != "period")
        throw InputError(where +
                         ": expected 'rotate origin PX PY PZ axis AX AY AZ period T'; usage: " + usage);
      Vec3 axis;
      for (int d = 0; d < 3; ++d) {
        origin_[d] = parse_double(args[7 + d], where + " rotate origin");
        axis[d] = parse_double(args[11 + d], where + " rotate axis");
      }
      if (!(axis.norm() > 0.0)) throw InputError(where + ": the rotation axis must not be zero");
      const double period = parse_double(args[15], where + " rotate period");
      if (!(period != 0.0) || !std::isfinite(period))
        throw InputError(where + ": the period must be a non-zero number of seconds");
      rotate_ = true;
      axis_ = axis.normalized();
      omega_ = 2.0 * M_PI / period;
      params_ = {origin_[0], origin_[1], origin_[2], axis_[0], axis_[1], axis_[2], period};
    } else {
      throw InputError(where + ": motion style '" + args[5] +
                       "' is not supported; Granary has 'linear' and 'rotate'");
    }
    for (const auto& other : engine.modify->fixes) {
      auto* mover = dynamic_cast<FixMoveMesh*>(other.get());
      if (mover && mover->id != id && mover->mesh_id_ == mesh_id_) {
        throw InputError(where + ": mesh " + mesh_id_ + " is already moved by fix " + mover->id +
                         "; unfix that one first");
      }
    }
    reference_.resize(m.mesh.nnodes());
    for (int k = 0; k < m.mesh.nnodes(); ++k)
      reference_[k] = m.mesh.node(k);
    t0_ = engine.update->time();
    restart_global = true;
  }

  void pack_restart(std::string& out) const override {
    std::vector<double> v = {t0_, static_cast<double>(params_.size())};
    v.insert(v.end(), params_.begin(), params_.end());
    v.push_back(static_cast<double>(reference_.size()));
    for (const Vec3& r : reference_)
      v.insert(v.end(), r.data(), r.data() + 3);
    out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double));
  }

  void unpack_restart(const std::string& in) override {
    // continue the stored motion when it is the same (same style and
    // parameters, same node count)
    std::vector<double> v(in.size() / sizeof(double));
    std::memcpy(static_cast<void*>(v.data()), in.data(), v.size() * sizeof(double));
    const std::size_t np = params_.size();
    if (v.size() < 3 + np || v[1] != static_cast<double>(np)) return;
    for (std::size_t k = 0; k < np; ++k)
      if (v[2 + k] != params_[k]) return;
    const std::size_t head = 3 + np;
    const std::size_t n = static_cast<std::size_t>(v[head - 1]);
    if (n != reference_.size() || v.size() != head + 3 * n) return;
    t0_ = v[0];
    for (std::size_t k = 0; k < n; ++k)
      reference_[k] = Vec3(v[head + 3 * k], v[head + 1 + 3 * k], v[head + 2 + 3 * k]);
  }

  unsigned hooks() const override { return INITIAL_INTEGRATE; }

  void init() override {
    FixMeshSurface& m = mesh();
    mesh_ = &m;
    if (m.mesh.nnodes() != static_cast<int>(reference_.size())) {
      throw InputError("fix " + id + " move/mesh: mesh " + mesh_id_ +
                       " was redefined with another node count; define fix move/mesh again");
    }
    set_velocity(m.mesh);
  }

  void initial_integrate() override {
    TriMesh& m = mesh_->mesh;
    const double t = engine_.update->time() - t0_;
    if (rotate_) {
      const Eigen::Matrix3d r = Eigen::AngleAxisd(omega_ * t, axis_).toRotationMatrix();
      std::vector<Vec3> nodes(reference_.size());
      for (std::size_t k = 0; k < nodes.size(); ++k)
        nodes[k] = origin_ + r * (reference_[k] - origin_);
      m.set_nodes(nodes);  // normals and bins follow the rotation
    } else {
      m.place(reference_, velocity_ * t);
    }
    set_velocity(m);
  }

  void unfixed() override {
    // the mesh stands still from now on
    if (Fix* f = engine_.modify->find_fix(mesh_id_)) {
      if (auto* m = dynamic_cast<FixMeshSurface*>(f)) {
        m->mesh.velocity.setZero();
        m->mesh.omega.setZero();
      }
    }
  }

 private:
  FixMeshSurface& mesh() const {
    return FixMeshSurface::find(*engine_.modify, mesh_id_, "fix " + id + " move/mesh");
  }

  std::string mesh_id_;
  FixMeshSurface* mesh_ = nullptr;  // resolved by init for the run
  void set_velocity(TriMesh& m) const {
    m.velocity = velocity_;
    m.omega = rotate_ ? Vec3(omega_ * axis_) : Vec3::Zero();
    m.origin = origin_;
  }

  Vec3 velocity_ = Vec3::Zero();  // linear
  bool rotate_ = false;           // rotate: about axis_ through origin_ at omega_ rad/s
  Vec3 origin_ = Vec3::Zero(), axis_ = Vec3::UnitZ();
  double omega_ = 0.0;
  std::vector<double> params_;   // the motion's parameters, as given (restart check)
  std::vector<Vec3> reference_;  // node positions at t0
  double t0_ = 0.0;
};

}  // namespace

GRANARY_FIX_STYLE("move/mesh", FixMoveMesh);

}  // namespace granary
