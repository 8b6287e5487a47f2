// `dump ID group mesh/vtk N file.vtp|file.vtk [output face] [id] [vel] [area] [stress]
// [stresscomponents] [wear] [mesh-IDs ...]` (also named mesh/gran/VTK): the triangles of fix mesh/surface
// walls as VTK XML PolyData (or legacy VTK for a .vtk name). Meshes are replicated on every rank, so rank 0
// writes the whole frame; per-triangle forces are summed over the ranks first. Cell data: mesh (index of the
// mesh in the dump's list, from 0), normal, velocity, force (of the particles on the triangle on the last
// step), area, pressure and shear_stress (the normal and tangential force over the area), stress_components
// (the force over the area, a vector), wear (where a mesh has wear finnie: the accumulated Finnie wear,
// kg/m^2); velocity is that of the wall material at the triangle's centroid (rotation and surface_vel
// included); field data TimeValue and Step. A .pvd collection lists every frame with its simulated time. The
// group is ignored. `dump ID group mesh/vtm N file.vtm meshes all|IDs [mesh_properties ...]`: the same
// arrays as a VTK multiblock file with one block (a .vtp in the folder FILE/) per mesh, named by its ID, as
// LIGGGHTS writes it. See doc/commands/dump.md.
#include <mpi.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkTypeInt64Array.h>
#include <vtkXMLPolyDataWriter.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/engine.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/registry.h"
#include "output/vtk_module.h"
#include "core/update.h"
#include "fix/fix_mesh_surface.h"
#include "core/modify.h"
#include "output/dump.h"
#include "output/dump_frame_vtk.h"
#include "output/dump_custom.h"
#include "output/vtk_support.h"
#include "output/vtk_frame.h"

namespace granary {

namespace {

class DumpMeshVTK : public FrameDumpVTK {
 public:
  DumpMeshVTK(Engine& engine, const Args& args, const std::string& style = "mesh/vtk")
      : FrameDumpVTK(engine, args, style, style == "mesh/vtm" ? ".vtm" : ".vtp",
                     style == "mesh/vtm" ? "post/mesh*.vtm" : "post/mesh_*.vtp"),
        style_(style) {
    bool want_wear = false;
    const std::string where = "dump " + id + " " + style;
    multiblock_ = style == "mesh/vtm";
    if (multiblock_ && legacy_)
      throw InputError(where + ": writes VTK multiblock files; the name must end in .vtm, got '" + filename +
                       "'");
    if (multiblock_ && args.size() > 5 && args[5] != "meshes")
      throw InputError(where + ": expected 'meshes all' or 'meshes ID ...' after the file name, got '" +
                       args[5] + "'");
    bool listing_meshes = false;
    for (std::size_t k = 5; k < args.size(); ++k) {
      const std::string& w = args[k];
      if (multiblock_ && (w == "meshes" || w == "mesh_properties")) {
        listing_meshes = w == "meshes";  // mesh IDs follow `meshes`, identifiers `mesh_properties`
      } else if (multiblock_ && listing_meshes && w == "all") {
        // every fix mesh/surface: the default
      } else if (w == "output") {
        if (k + 1 >= args.size() || args[k + 1] != "face")
          throw InputError(where + ": only 'output face' is supported (values per triangle)");
        ++k;
      } else if (w == "id" || w == "vel" || w == "area" || w == "stress" || w == "stresscomponents") {
        // LIGGGHTS' dump identifiers: the mesh index, velocity, area, force and stresses are always written
      } else if (w == "wear") {
        want_wear = true;
      } else if (multiblock_ && !listing_meshes &&
                 (w == "owner" || w == "aedges" || w == "acorners" || w == "nneighs" || w == "nneigs")) {
        // LIGGGHTS' mesh topology identifiers: not written (see doc/commands/dump.md)
      } else if (engine.modify->find_fix(w) && (!multiblock_ || listing_meshes)) {
        FixMeshSurface::find(*engine.modify, w, where);
        mesh_ids_.push_back(w);
      } else {
        throw InputError(where + ": '" + w + "' is neither the ID of a fix mesh/surface" +
                         (multiblock_ ? " after 'meshes'" : "") +
                         " nor one of output, id, vel, area, stress, stresscomponents, wear");
      }
    }
    // the wear array: written when a mesh of the dump has wear finnie
    for (FixMeshSurface* m : meshes())
      if (m->wear_finnie) wear_ = true;
    if (want_wear && !wear_) {
      throw InputError(where +
                       ": 'wear' needs a fix mesh/surface/stress with 'wear finnie' among the meshes "
                       "written; add 'wear finnie' to the mesh fix or remove 'wear'");
    }
  }

  void init() override {
    if (meshes().empty())
      throw InputError("dump " + id + " " + style_ + ": there is no fix mesh/surface to write");
  }

  void write() override {
    std::vector<FixMeshSurface*> list = meshes();
    // per-triangle forces (3 per triangle) and, with wear, the accumulated
    // wear (1 per triangle; 0 on meshes without wear finnie) of all ranks,
    // summed on rank 0 in one reduction
    std::vector<double> local, all;
    for (FixMeshSurface* m : list)
      for (const Vec3& f : m->mesh.tri_force)
        local.insert(local.end(), f.data(), f.data() + 3);
    if (wear_) {
      for (FixMeshSurface* m : list) {
        if (m->wear_finnie && m->mesh.tri_wear.size() == static_cast<std::size_t>(m->mesh.ntri()))
          local.insert(local.end(), m->mesh.tri_wear.begin(), m->mesh.tri_wear.end());
        else
          local.insert(local.end(), m->mesh.ntri(), 0.0);
      }
    }
    all.resize(local.size());
    MPI_Reduce(local.data(), all.data(), static_cast<int>(local.size()), MPI_DOUBLE, MPI_SUM, 0,
               engine_.world);
    std::string err;
    if (engine_.rank == 0)
      err = write_frame(dumpio::expand(filename, engine_.update->ntimestep, options_.pad), list, all);
    err = dumpio::first_error(engine_.world, err);
    if (!err.empty()) throw RunError("dump " + id + ": " + err);
  }

 private:
  std::vector<FixMeshSurface*> meshes() const {
    return FixMeshSurface::select(*engine_.modify, mesh_ids_, "dump " + id + " " + style_);
  }

  std::string write_frame(const std::string& frame, const std::vector<FixMeshSurface*>& list,
                          const std::vector<double>& sums) {
    vtkIdType ncells = 0;
    for (const FixMeshSurface* m : list)
      ncells += m->mesh.ntri();
    if (!multiblock_) {
      auto ds = polydata(list, 0, list.size(), sums, ncells);
      return vtkio::write_polydata_frame(ds, frame, engine_.update->time(), engine_.update->ntimestep,
                                         options_, pvd_);
    }
    // mesh/vtm (as LIGGGHTS writes it): FRAME.vtm lists one .vtp per mesh,
    // FRAME/FRAME_<k>.vtp, each block named by its mesh ID; the pieces first,
    // each whole or absent, the index last
    const std::filesystem::path index(frame);
    const std::string stem = index.stem().string();
    const std::filesystem::path dir = index.parent_path() / stem;
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) return "cannot create the directory '" + dir.string() + "': " + ec.message();
    std::string xml =
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"vtkMultiBlockDataSet\" version=\"1.0\" "
        "byte_order=\"LittleEndian\" header_type=\"UInt32\">\n  <vtkMultiBlockDataSet>\n";
    for (std::size_t mi = 0; mi < list.size(); ++mi) {
      auto ds = polydata(list, mi, mi + 1, sums, ncells);
      const std::string piece = stem + "_" + std::to_string(mi) + ".vtp";
      vtkio::PvdCollection unlisted;  // the pieces are listed by the .vtm, not a .pvd
      const std::string err = vtkio::write_polydata_frame(ds, (dir / piece).string(), engine_.update->time(),
                                                          engine_.update->ntimestep, options_, unlisted);
      if (!err.empty()) return err;
      xml += "    <DataSet index=\"" + std::to_string(mi) + "\" name=\"" + list[mi]->id + "\" file=\"" +
             stem + "/" + piece + "\"/>\n";
    }
    xml += "  </vtkMultiBlockDataSet>\n</VTKFile>\n";
    const std::string err = replace_file(frame, xml);
    if (!err.empty()) return err;
    if (!pvd_.path.empty()) return pvd_.add(frame, engine_.update->time());
    return "";
  }

  /// The triangles of meshes list[first, last) as PolyData; `sums` holds the
  /// forces of every triangle of `list` (3 each), then, with wear, the wear
  /// of each (ncells in all).
  vtkSmartPointer<vtkPolyData> polydata(const std::vector<FixMeshSurface*>& list, std::size_t first,
                                        std::size_t last, const std::vector<double>& sums, vtkIdType nall) {
    vtkIdType npts = 0, ncells = 0, cell0 = 0;
    for (std::size_t mi = 0; mi < list.size(); ++mi) {
      if (mi < first) cell0 += list[mi]->mesh.ntri();
      if (mi < first || mi >= last) continue;
      npts += list[mi]->mesh.nnodes();
      ncells += list[mi]->mesh.ntri();
    }
    auto points = vtkSmartPointer<vtkPoints>::New();
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(npts);
    auto offsets = vtkSmartPointer<vtkIdTypeArray>::New();
    auto conn = vtkSmartPointer<vtkIdTypeArray>::New();
    offsets->SetNumberOfValues(ncells + 1);
    conn->SetNumberOfValues(3 * ncells);
    auto index = vtkio::named_array<vtkIntArray>("mesh", 1, ncells);
    auto normal = vtkio::named_array<vtkDoubleArray>("normal", 3, ncells);
    auto vel = vtkio::named_array<vtkDoubleArray>("velocity", 3, ncells);
    auto fa = vtkio::named_array<vtkDoubleArray>("force", 3, ncells);
    auto area = vtkio::named_array<vtkDoubleArray>("area", 1, ncells);
    auto pressure = vtkio::named_array<vtkDoubleArray>("pressure", 1, ncells);
    auto shear = vtkio::named_array<vtkDoubleArray>("shear_stress", 1, ncells);
    auto traction = vtkio::named_array<vtkDoubleArray>("stress_components", 3, ncells);
    auto wear_arr = vtkio::named_array<vtkDoubleArray>("wear", 1, wear_ ? ncells : 0);
    vtkIdType p0 = 0, cell = 0;
    for (std::size_t mi = first; mi < last; ++mi) {
      const TriMesh& mesh = list[mi]->mesh;
      for (int k = 0; k < mesh.nnodes(); ++k)
        points->SetPoint(p0 + k, mesh.node(k).data());
      for (int t = 0; t < mesh.ntri(); ++t, ++cell) {
        offsets->SetValue(cell, 3 * cell);
        for (int c = 0; c < 3; ++c)
          conn->SetValue(3 * cell + c, p0 + mesh.tri(t)[c]);
        index->SetValue(cell, static_cast<int>(mi));
        normal->SetTypedTuple(cell, mesh.normal(t).data());
        {
          // the wall velocity at the triangle's centroid
          const Vec3 centroid = (mesh.corner(t, 0) + mesh.corner(t, 1) + mesh.corner(t, 2)) / 3.0;
          const Vec3 vc = mesh.velocity_at(t, centroid);
          vel->SetTypedTuple(cell, vc.data());
        }
        const vtkIdType g = cell0 + cell;  // the triangle's place in `sums`
        fa->SetTypedTuple(cell, sums.data() + 3 * g);
        const double a = mesh.area(t);
        area->SetValue(cell, a);
        // mean stresses of the particles on the triangle: normal (pressure,
        // positive when the particles push against the normal) and shear
        const Vec3 f(sums[3 * g], sums[3 * g + 1], sums[3 * g + 2]);
        const double fn = f.dot(mesh.normal(t));
        pressure->SetValue(cell, -fn / a);
        shear->SetValue(cell, (f - fn * mesh.normal(t)).norm() / a);
        const Vec3 tr = f / a;
        traction->SetTypedTuple(cell, tr.data());
        if (wear_) wear_arr->SetValue(cell, sums[3 * nall + g]);
      }
      p0 += mesh.nnodes();
    }
    offsets->SetValue(ncells, 3 * ncells);
    auto cells = vtkSmartPointer<vtkCellArray>::New();
    cells->SetData(offsets, conn);
    auto ds = vtkSmartPointer<vtkPolyData>::New();
    ds->SetPoints(points);
    ds->SetPolys(cells);
    for (vtkDataArray* a :
         std::initializer_list<vtkDataArray*>{index, normal, vel, fa, area, pressure, shear, traction})
      ds->GetCellData()->AddArray(a);
    if (wear_) ds->GetCellData()->AddArray(wear_arr);
    return ds;
  }

  std::string style_;
  bool multiblock_ = false;  ///< mesh/vtm: one block per mesh
  std::vector<std::string> mesh_ids_;
  bool wear_ = false;  ///< a mesh of the dump has wear finnie: the "wear" array is written
};

}  // namespace

GRANARY_VTK_DUMP_STYLE("mesh/vtk", DumpMeshVTK);
// LIGGGHTS' older name of the same dump
GRANARY_VTK_DUMP_STYLE("mesh/gran/VTK", DumpMeshVTK);

namespace {
class DumpMeshVTM : public DumpMeshVTK {
 public:
  DumpMeshVTM(Engine& engine, const Args& args) : DumpMeshVTK(engine, args, "mesh/vtm") {}
};
}  // namespace

GRANARY_VTK_DUMP_STYLE("mesh/vtm", DumpMeshVTM);

}  // namespace granary
