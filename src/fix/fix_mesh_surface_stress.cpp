// fix ID group mesh/surface/stress file F.stl type T [mesh/surface keywords]
//     [stress on] [wear off|finnie] [reference_point RX RY RZ]
// (LIGGGHTS syntax): a fix mesh/surface whose forces are reported. The wall
// fixes sum the force of the particles on every triangle each step (for every
// mesh); this style adds the global outputs f_ID[1..9]: the total force on the
// mesh (3), the torque about the reference point (3, each triangle's force
// taken at its centroid) and the reference point itself (3, moved, scaled and
// rotated with the mesh). The per-triangle normal and shear stresses are
// written by dump mesh/vtk. `wear finnie` accumulates Finnie's erosive wear
// per triangle (fix wall/gran adds it, see add_finnie_wear; dump mesh/vtk
// writes it).
// See doc/fixes/mesh_surface_stress.md.
#include <mpi.h>

#include "core/engine.h"
#include "core/registry.h"
#include "core/update.h"
#include "fix/fix_mesh_surface.h"

namespace granary {

namespace {

class FixMeshSurfaceStress : public FixMeshSurface {
 public:
  FixMeshSurfaceStress(Engine& engine, const Args& args) : FixMeshSurface(engine, args, true) {
    size_vector = 9;
  }

  double compute_vector(int i) override {
    if (i < 0 || i >= 9) return 0.0;
    if (i >= 6) return reference_point_[i - 6];
    const std::int64_t step = engine_.update->ntimestep;
    if (step != summed_step_) {
      // sum over the triangles of this rank, then over the ranks
      double local[6] = {0, 0, 0, 0, 0, 0};
      for (int t = 0; t < mesh.ntri(); ++t) {
        const Vec3& f = mesh.tri_force[t];
        const Vec3 c = (mesh.corner(t, 0) + mesh.corner(t, 1) + mesh.corner(t, 2)) / 3.0;
        const Vec3 m = (c - reference_point_).cross(f);
        for (int d = 0; d < 3; ++d) {
          local[d] += f[d];
          local[3 + d] += m[d];
        }
      }
      MPI_Allreduce(local, sums_, 6, MPI_DOUBLE, MPI_SUM, engine_.world);
      summed_step_ = step;
    }
    return sums_[i];
  }

  void init() override {
    FixMeshSurface::init();
    summed_step_ = -1;
  }

 private:
  std::int64_t summed_step_ = -1;
  double sums_[6] = {0, 0, 0, 0, 0, 0};
};

}  // namespace

GRANARY_FIX_STYLE("mesh/surface/stress", FixMeshSurfaceStress);

}  // namespace granary
