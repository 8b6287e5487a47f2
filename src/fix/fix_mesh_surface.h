// fix ID group mesh/surface file F.stl type T [scale S] [move dx dy dz]
//     [rotate axis ax ay az angle DEG] [curvature_tolerant yes|no] [surface_vel VX VY VZ] ...
// A triangle mesh read from an ASCII or binary STL file (with VTK's
// vtkSTLReader on rank 0, broadcast to every rank), transformed by scale, move
// and rotate in the order given, used as a granular wall by fix wall/gran
// (mesh form), moved by fix move/mesh and written by dump mesh/vtk.
// The current node positions go into restart files. See doc/fixes/mesh_surface.md.
#pragma once

#include <string>
#include <vector>

#include "fix/fix.h"
#include "geometry/tri_mesh.h"

namespace granary {

class Modify;

class FixMeshSurface : public Fix {
 public:
  FixMeshSurface(Engine& engine, const Args& args) : FixMeshSurface(engine, args, false) {}
  unsigned hooks() const override { return PRE_FORCE; }
  void init() override;
  /// Per-triangle forces are summed afresh every step.
  void pre_force() override;

  /// wear finnie: sums the ranks' wear on rank 0 for pack_restart.
  void prepare_restart() override;
  void pack_restart(std::string& out) const override;
  void unpack_restart(const std::string& in) override;

  TriMesh mesh;
  int wall_type = 1;  ///< atom type whose material the mesh has
  std::string file;   ///< the STL file it was read from
  /// mesh/surface/stress wear finnie: the wall contacts add Finnie's wear to
  /// mesh.tri_wear; k_finnie[t] is the constant for particle type t (1-based)
  /// against this wall's type (fix property/global k_finnie).
  bool wear_finnie = false;
  std::vector<double> k_finnie;
  /// mesh/surface/stress/servo: the mesh is moved by its own controller (fix
  /// move/mesh refuses it).
  bool servo_wall = false;

 protected:
  /// `stress`: also read the keywords of mesh/surface/stress (stress,
  /// wear, reference_point) into the members below.
  FixMeshSurface(Engine& engine, const Args& args, bool stress);

  Vec3 reference_point_ = Vec3::Zero();  ///< mesh/surface/stress: torque reference
  Vec3 surface_vel_ = Vec3::Zero();      ///< conveyor belt velocity (surface_vel)
  bool has_surface_vel_ = false;
  std::vector<double> wear_total_;  ///< wear of all ranks, on rank 0 at write_restart

 public:
  /// The mesh/surface fix with this ID, or an InputError saying what needs it.
  static FixMeshSurface& find(const Modify& modify, const std::string& id, const std::string& what);
  /// The mesh/surface fixes with these IDs, or every one defined when `ids` is empty.
  static std::vector<FixMeshSurface*> select(const Modify& modify, const std::vector<std::string>& ids,
                                             const std::string& what);
};

}  // namespace granary
