// fix ID group move/mesh mesh M linear VX VY VZ (LIGGGHTS syntax): moves the
// nodes of fix mesh/surface M rigidly at constant velocity V and sets the
// mesh velocity that the wall contacts see. The position is computed from the
// positions when the fix was defined, X(t) = X0 + V (t - t0), every step in
// the initial_integrate stage (when the particles drift), so it does not
// accumulate round-off. X0, t0 and V go into restart files: the same fix
// defined again after read_restart with the same V continues the same motion
// bit for bit. The group is ignored. See doc/fixes/move_mesh.md.
#include <cstring>

#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix.h"
#include "fix/fix_mesh_surface.h"
#include "fix/modify.h"

namespace granary {

namespace {

class FixMoveMesh : public Fix {
 public:
  FixMoveMesh(Engine& engine, const Args& args) : Fix(engine, args) {
    const std::string usage = "fix ID group move/mesh mesh MESH-ID linear VX VY VZ";
    const std::string where = "fix " + id + " move/mesh";
    if (args.size() < 5 || args[3] != "mesh")
      throw InputError(where + ": expected 'mesh MESH-ID' first; usage: " + usage);
    mesh_id_ = args[4];
    FixMeshSurface& m = FixMeshSurface::find(*engine.modify, mesh_id_, where);
    if (args.size() < 6) throw InputError(where + ": missing the motion style; usage: " + usage);
    if (args[5] != "linear") {
      throw InputError(where + ": motion style '" + args[5] +
                       "' is not supported; Granary has 'linear' only");
    }
    require_args(args, 9, 9, usage);
    for (int d = 0; d < 3; ++d)
      velocity_[d] = parse_double(args[6 + d], where + " velocity");
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
    std::vector<double> v = {t0_, velocity_[0], velocity_[1], velocity_[2],
                             static_cast<double>(reference_.size())};
    for (const Vec3& r : reference_)
      v.insert(v.end(), r.data(), r.data() + 3);
    out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double));
  }

  void unpack_restart(const std::string& in) override {
    // continue the stored motion when it is the same (same velocity, same node count)
    std::vector<double> v(in.size() / sizeof(double));
    std::memcpy(static_cast<void*>(v.data()), in.data(), v.size() * sizeof(double));
    if (v.size() < 5 || v[1] != velocity_[0] || v[2] != velocity_[1] || v[3] != velocity_[2]) return;
    const std::size_t n = static_cast<std::size_t>(v[4]);
    if (n != reference_.size() || v.size() != 5 + 3 * n) return;
    t0_ = v[0];
    for (std::size_t k = 0; k < n; ++k)
      reference_[k] = Vec3(v[5 + 3 * k], v[6 + 3 * k], v[7 + 3 * k]);
  }

  unsigned hooks() const override { return INITIAL_INTEGRATE; }

  void init() override {
    FixMeshSurface& m = mesh();
    mesh_ = &m;
    if (m.mesh.nnodes() != static_cast<int>(reference_.size())) {
      throw InputError("fix " + id + " move/mesh: mesh " + mesh_id_ +
                       " was redefined with another node count; define fix move/mesh again");
    }
    m.mesh.velocity = velocity_;
  }

  void initial_integrate() override {
    TriMesh& m = mesh_->mesh;
    m.place(reference_, velocity_ * (engine_.update->time() - t0_));
    m.velocity = velocity_;
  }

 private:
  FixMeshSurface& mesh() const {
    return FixMeshSurface::find(*engine_.modify, mesh_id_, "fix " + id + " move/mesh");
  }

  std::string mesh_id_;
  FixMeshSurface* mesh_ = nullptr;  // resolved by init for the run
  Vec3 velocity_ = Vec3::Zero();
  std::vector<Vec3> reference_;  // node positions at t0
  double t0_ = 0.0;
};

}  // namespace

GRANARY_FIX_STYLE("move/mesh", FixMoveMesh);

}  // namespace granary
