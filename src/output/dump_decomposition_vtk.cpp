// `dump ID group decomposition/vtk N file.vtk|file.vtr`: the MPI processor
// grid as a VTK rectilinear grid whose coordinates along x, y, z are the cut
// planes of the subdomains (procgrid + 1 per dimension, moved by `balance`
// and `fix balance`): legacy VTK for a .vtk name (as LIGGGHTS 3.8 writes it),
// VTK XML for .vtr (listed with its time in a .pvd collection). Cell data:
// `rank` (the rank owning each subdomain) and `particles` (how many particles
// it owns at that step); field data TimeValue and Step. Rank 0 writes the
// frame. The group is ignored. With the rcb boxes of comm_style tiled, which
// are no grid, a .vtk frame is a legacy unstructured grid of one voxel per
// rank (cell data as above) and a .vtr name is refused. See
// doc/commands/dump.md.
#include <mpi.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkIntArray.h>
#include <vtkRectilinearGrid.h>
#include <vtkRectilinearGridWriter.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkUnstructuredGridWriter.h>
#include <vtkXMLRectilinearGridWriter.h>

#include <string>
#include <vector>

#include "comm/comm.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "output/vtk_module.h"
#include "core/update.h"
#include "output/dump.h"
#include "output/dump_frame_vtk.h"
#include "output/dump_custom.h"
#include "output/vtk_frame.h"
#include "output/vtk_support.h"
#include "particles/particles.h"

namespace granary {

namespace {

class DumpDecompositionVTK : public FrameDumpVTK {
 public:
  DumpDecompositionVTK(Engine& engine, const Args& args)
      : FrameDumpVTK(engine, args, "decomposition/vtk", ".vtr", "post/decomposition*.vtk") {
    if (args.size() > 5)
      throw InputError("dump " + id + " decomposition/vtk takes no further arguments, got '" + args[5] + "'");
  }

  void write() override {
    const Comm& c = *engine_.comm;
    const int nranks = engine_.nprocs;
    int mine = engine_.particles->nlocal;
    std::vector<int> counts(static_cast<std::size_t>(nranks), 0);
    MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, engine_.world);
    std::string err;
    const bool boxes = c.tiled() && !c.rcb_tree().empty();
    if (boxes && !legacy_) {
      throw RunError(
          "dump " + id + ": the rcb boxes of comm_style tiled are not a rectilinear grid (.vtr); " +
          "give the dump a .vtk file name (written as a legacy unstructured grid, a voxel per rank)");
    }
    if (engine_.rank == 0) {
      const std::string frame = dumpio::expand(filename, engine_.update->ntimestep, options_.pad);
      err = boxes ? write_boxes(frame, c, counts) : write_frame(frame, c, counts);
    }
    err = dumpio::first_error(engine_.world, err);
    if (!err.empty()) throw RunError("dump " + id + ": " + err);
  }

 private:
  // Every rank's box as a voxel of an unstructured grid (legacy VTK).
  std::string write_boxes(const std::string& frame, const Comm& c, const std::vector<int>& counts) {
    const int nranks = engine_.nprocs;
    auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
    auto points = vtkSmartPointer<vtkPoints>::New();
    points->SetDataTypeToDouble();
    auto rank = vtkio::named_array<vtkIntArray>("rank", 1, nranks);
    auto parts = vtkio::named_array<vtkIntArray>("particles", 1, nranks);
    grid->Allocate(nranks);
    for (int r = 0; r < nranks; ++r) {
      Vec3 lo, hi;
      c.rank_box(r, lo, hi);
      vtkIdType ids[8];
      for (int k = 0; k < 8; ++k)  // VTK_VOXEL order: x fastest, then y, then z
        ids[k] = points->InsertNextPoint(k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]);
      grid->InsertNextCell(VTK_VOXEL, 8, ids);
      rank->SetValue(r, r);
      parts->SetValue(r, counts[static_cast<std::size_t>(r)]);
    }
    grid->SetPoints(points);
    grid->GetCellData()->AddArray(rank);
    grid->GetCellData()->AddArray(parts);
    const std::int64_t step = engine_.update->ntimestep;
    vtkio::add_time_step(grid, engine_.update->time(), step);
    return replace_file_by_name(frame, [&](const std::string& temp) {
      return write_legacy<vtkUnstructuredGridWriter>(grid, temp, frame,
                                                     "Granary rcb boxes, step " + std::to_string(step));
    });
  }

  // One frame as legacy VTK with the writer class W (binary unless dump_modify binary no).
  template <class W, class Data>
  std::string write_legacy(Data& data, const std::string& temp, const std::string& frame,
                           const std::string& header) {
    auto w = vtkSmartPointer<W>::New();
    w->SetFileVersion(W::VTK_LEGACY_READER_VERSION_4_2);
    if (options_.binary)
      w->SetFileTypeToBinary();
    else
      w->SetFileTypeToASCII();
    w->SetHeader(header.c_str());
    w->SetInputData(data);
    w->SetFileName(temp.c_str());
    return w->Write() ? std::string() : "VTK could not write '" + frame + "'";
  }

  std::string write_frame(const std::string& frame, const Comm& c, const std::vector<int>& counts) {
    auto grid = vtkSmartPointer<vtkRectilinearGrid>::New();
    const int nx = c.procgrid[0] + 1, ny = c.procgrid[1] + 1, nz = c.procgrid[2] + 1;
    grid->SetDimensions(nx, ny, nz);
    vtkSmartPointer<vtkDoubleArray> coords[3];
    for (int d = 0; d < 3; ++d) {
      coords[d] = vtkSmartPointer<vtkDoubleArray>::New();
      coords[d]->SetNumberOfValues(c.procgrid[d] + 1);
      for (int k = 0; k <= c.procgrid[d]; ++k)
        coords[d]->SetValue(k, c.cut_coord(d, k));
    }
    grid->SetXCoordinates(coords[0]);
    grid->SetYCoordinates(coords[1]);
    grid->SetZCoordinates(coords[2]);
    const vtkIdType ncells = static_cast<vtkIdType>(c.procgrid[0]) * c.procgrid[1] * c.procgrid[2];
    auto rank = vtkio::named_array<vtkIntArray>("rank", 1, ncells);
    auto parts = vtkio::named_array<vtkIntArray>("particles", 1, ncells);
    // VTK orders the cells x fastest, then y, then z: the order of Comm::rank_at
    for (int iz = 0; iz < c.procgrid[2]; ++iz)
      for (int iy = 0; iy < c.procgrid[1]; ++iy)
        for (int ix = 0; ix < c.procgrid[0]; ++ix) {
          const vtkIdType cell = ix + static_cast<vtkIdType>(c.procgrid[0]) * (iy + c.procgrid[1] * iz);
          const int r = c.rank_at(ix, iy, iz);
          rank->SetValue(cell, r);
          parts->SetValue(cell, counts[static_cast<std::size_t>(r)]);
        }
    grid->GetCellData()->AddArray(rank);
    grid->GetCellData()->AddArray(parts);
    const double time = engine_.update->time();
    const std::int64_t step = engine_.update->ntimestep;
    vtkio::add_time_step(grid, time, step);
    const std::string err = replace_file_by_name(frame, [&](const std::string& temp) -> std::string {
      if (legacy_) {
        return write_legacy<vtkRectilinearGridWriter>(grid, temp, frame,
                                                      "Granary processor grid, step " + std::to_string(step));
      }
      auto w = vtkSmartPointer<vtkXMLRectilinearGridWriter>::New();
      vtkio::configure_writer(w.Get(), options_.binary, options_.compressor);
      w->SetInputData(grid);
      w->SetFileName(temp.c_str());
      return w->Write() ? "" : "VTK could not write '" + frame + "'";
    });
    if (!err.empty()) return err;
    if (!legacy_ && !pvd_.path.empty()) return pvd_.add(frame, time);
    return "";
  }
};

}  // namespace

GRANARY_VTK_DUMP_STYLE("decomposition/vtk", DumpDecompositionVTK);

}  // namespace granary
