// `dump ID group euler/vtk N file.vtk|file.vtp`: the cells of fix ave/euler
// (the first one defined) as VTK PolyData, one vertex per cell centre, with
// the point data v_avg (3 components), volumefraction, radius and pressure:
// legacy VTK for a .vtk name (as LIGGGHTS 3.8 writes it), VTK XML for .vtp
// (listed with its time in a .pvd collection). With `parallel yes` every
// rank's cells are gathered to rank 0, which writes the frame. The dump's
// steps must be steps on which the fix computed its cells (multiples of its
// nevery, or the start of a run). The group is ignored (the fix's counts).
// See doc/commands/dump.md.
#include <mpi.h>
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdTypeArray.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <string>
#include <vector>

#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "core/registry.h"
#include "output/vtk_module.h"
#include "core/update.h"
#include "fix/fix_ave_euler.h"
#include "output/dump.h"
#include "output/dump_frame_vtk.h"
#include "output/dump_custom.h"
#include "output/vtk_frame.h"
#include "output/vtk_support.h"

namespace granary {

namespace {

class DumpEulerVTK : public FrameDumpVTK {
 public:
  DumpEulerVTK(Engine& engine, const Args& args)
      : FrameDumpVTK(engine, args, "euler/vtk", ".vtp", "post/euler*.vtk") {
    if (args.size() > 5)
      throw InputError("dump " + id + " euler/vtk takes no further arguments, got '" + args[5] + "'");
  }

  void init() override { fix(); }

  void write() override {
    const FixAveEuler& f = fix();
    const std::int64_t step = engine_.update->ntimestep;
    if (f.computed_step() != step)
      throw RunError("dump " + id + " (euler/vtk): fix " + f.id + " (ave/euler) computes its cells every " +
                     std::to_string(f.nevery) + " steps, not at step " + std::to_string(step) +
                     "; write the dump every multiple of " + std::to_string(f.nevery) + " steps");
    // per cell: centre (3), v_avg (3), volume fraction, radius, pressure
    const int nv = 9;
    const FixAveEuler::Grid& g = f.grid();
    std::vector<double> mine;
    if (f.parallel() || engine_.rank == 0) {
      mine.reserve(static_cast<std::size_t>(nv) * g.cells());
      for (int c = 0; c < g.cells(); ++c) {
        const Vec3 x = g.centre(c);
        const std::size_t k = static_cast<std::size_t>(c);
        const double row[nv] = {x[0],
                                x[1],
                                x[2],
                                f.v_avg[3 * k],
                                f.v_avg[3 * k + 1],
                                f.v_avg[3 * k + 2],
                                f.volumefraction[k],
                                f.radius[k],
                                f.pressure[k]};
        mine.insert(mine.end(), row, row + nv);
      }
    }
    std::vector<double> all;
    dumpio::gather_rows(engine_.world, mine, nv, all);
    std::string err;
    if (engine_.rank == 0) err = write_frame(dumpio::expand(filename, step, options_.pad), all, nv);
    err = dumpio::first_error(engine_.world, err);
    if (!err.empty()) throw RunError("dump " + id + ": " + err);
  }

 private:
  const FixAveEuler& fix() const {
    for (const auto& f : engine_.modify->fixes)
      if (auto* e = dynamic_cast<const FixAveEuler*>(f.get())) return *e;
    throw InputError("dump " + id +
                     " (euler/vtk) writes the cells of fix ave/euler, but no fix ave/euler is "
                     "defined; add e.g. fix euler all ave/euler nevery 100 cell_size_relative 4 "
                     "parallel no");
  }

  std::string write_frame(const std::string& frame, const std::vector<double>& rows, int nv) {
    const vtkIdType n = static_cast<vtkIdType>(rows.size() / nv);
    auto points = vtkSmartPointer<vtkPoints>::New();
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(n);
    auto conn = vtkSmartPointer<vtkIdTypeArray>::New();
    conn->SetNumberOfValues(n);
    auto vel = vtkio::named_array<vtkDoubleArray>("v_avg", 3, n);
    auto phi = vtkio::named_array<vtkDoubleArray>("volumefraction", 1, n);
    auto rad = vtkio::named_array<vtkDoubleArray>("radius", 1, n);
    auto prs = vtkio::named_array<vtkDoubleArray>("pressure", 1, n);
    for (vtkIdType k = 0; k < n; ++k) {
      const double* r = &rows[static_cast<std::size_t>(k) * nv];
      points->SetPoint(k, r[0], r[1], r[2]);
      conn->SetValue(k, k);
      vel->SetTypedTuple(k, r + 3);
      phi->SetValue(k, r[6]);
      rad->SetValue(k, r[7]);
      prs->SetValue(k, r[8]);
    }
    auto cells = vtkSmartPointer<vtkCellArray>::New();
    cells->SetData(1, conn);
    auto ds = vtkSmartPointer<vtkPolyData>::New();
    ds->SetPoints(points);
    ds->SetVerts(cells);
    for (vtkDataArray* a : std::initializer_list<vtkDataArray*>{vel, phi, rad, prs})
      ds->GetPointData()->AddArray(a);
    return vtkio::write_polydata_frame(ds, frame, engine_.update->time(), engine_.update->ntimestep, options_,
                                       pvd_);
  }
};

}  // namespace

GRANARY_VTK_DUMP_STYLE("euler/vtk", DumpEulerVTK);

}  // namespace granary
