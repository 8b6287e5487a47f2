// `compute ID group wall/gran/local [pos] [vel] [id] [force] [force_normal]
// [force_tangential] [torque] [history] [contactArea] [delta] [contactPoint]`:
// one row per contact of a particle of the group with a wall of a fix
// wall/gran (mesh and primitive walls, every such fix in the order they were
// defined), with the requested values in LIGGGHTS' column order. The forces
// are those of the fix's contact model for the current positions, velocities
// and stored contact history (not advanced). Each contact is listed by the
// rank owning the particle. See doc/computes/wall_gran_local.md.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "compute/compute_gran_local.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "core/registry.h"
#include "fix/fix_wall_gran.h"
#include "particles/particles.h"

namespace granary {

namespace {

constexpr double kPi = 3.14159265358979323846;

class ComputeWallGranLocal : public ComputeGranLocal {
 public:
  ComputeWallGranLocal(Engine& engine, const Args& args) : ComputeGranLocal(engine, args) {
    size_local_cols = local_cols(layout());
  }

  void init() override {
    walls();
    size_local_cols = local_cols(layout());
  }

  void compute_local() override {
    const std::string where = "compute " + id + " (" + style + ")";
    const std::vector<FixWallGran*> fixes = walls();
    const Layout L = layout();
    size_local_cols = local_cols(L);
    const Particles& p = *engine_.particles;
    array_local.clear();
    row_i.clear();
    row_j.clear();
    std::vector<double> row(L.ncols);
    std::vector<FixWallGran::LocalContact> contacts;
    // mesh ids count the meshes of all mesh walls in order; primitive walls
    // are -1, -2, ... in order
    int mesh_base = 0, primitive = 0;
    for (FixWallGran* w : fixes) {
      contacts.clear();
      w->local_contacts(groupbit, where, contacts);
      for (const FixWallGran::LocalContact& lc : contacts) {
        const int i = lc.i;
        auto put3 = [&row](int at, const Vec3& v) {
          for (int q = 0; q < 3; ++q)
            row[at + q] = v[q];
        };
        if (L.pos >= 0) {
          put3(L.pos, lc.point);
          put3(L.pos + 3, p.x[i]);
        }
        if (L.vel >= 0) {
          put3(L.vel, lc.wall_v);
          put3(L.vel + 3, p.v[i]);
        }
        if (L.id >= 0) {
          row[L.id] = w->mesh_form() ? mesh_base + lc.mesh : -1 - primitive;
          row[L.id + 1] = w->mesh_form() ? lc.tri : -1;
          row[L.id + 2] = static_cast<double>(p.id[i]);
        }
        const Vec3& f = lc.res.force;
        const Vec3 fn = f.dot(lc.n) * lc.n;
        if (L.force >= 0) put3(L.force, f);
        if (L.force_normal >= 0) put3(L.force_normal, fn);
        if (L.force_tangential >= 0) put3(L.force_tangential, f - fn);
        if (L.torque >= 0) put3(L.torque, lc.res.torque_i);
        for (int q = 0; q < L.nhistory && L.history >= 0; ++q)
          row[L.history + q] = q < static_cast<int>(lc.history.size()) ? lc.history[q] : 0.0;
        if (L.contact_area >= 0) {
          // the circle where the wall's plane cuts the sphere
          const double r = p.radius[i], d = r - lc.overlap;
          row[L.contact_area] = kPi * std::max(0.0, r * r - d * d);
        }
        if (L.delta >= 0) row[L.delta] = lc.overlap;
        if (L.contact_point >= 0) put3(L.contact_point, lc.point);
        array_local.insert(array_local.end(), row.begin(), row.end());
        row_i.push_back(i);
        row_j.push_back(-1);
      }
      if (w->mesh_form())
        mesh_base += w->nmeshes();
      else
        ++primitive;
    }
    size_local_rows = static_cast<int>(row_i.size());
  }

 protected:
  int history_size() const override {
    int n = 0;
    for (const auto& f : engine_.modify->fixes)
      if (const auto* w = dynamic_cast<const FixWallGran*>(f.get())) n = std::max(n, w->history_size());
    return n;
  }
  bool wall() const override { return true; }

 private:
  /// The fix wall/gran walls, in the order they were defined, or an InputError.
  std::vector<FixWallGran*> walls() const {
    std::vector<FixWallGran*> out;
    for (const auto& f : engine_.modify->fixes)
      if (auto* w = dynamic_cast<FixWallGran*>(f.get())) out.push_back(w);
    if (out.empty())
      throw InputError("compute " + id + " " + style +
                       " reports the particle-wall contacts of fix wall/gran, and there is none; define "
                       "e.g. fix walls all wall/gran model hertz tangential history mesh n_meshes 1 meshes "
                       "MESH-ID");
    return out;
  }
};

}  // namespace

GRANARY_COMPUTE_STYLE("wall/gran/local", ComputeWallGranLocal);

}  // namespace granary
