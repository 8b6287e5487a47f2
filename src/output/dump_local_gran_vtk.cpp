// `dump ID group local/gran/vtk N file compute-ID`: the contacts of a compute
// pair/gran/local as VTK line cells (the contact network, force chains), one
// line from the first particle's centre to the second's per contact, with the
// compute's other values as cell data; or those of a compute wall/gran/local,
// one line from the contact point on the wall to the particle's centre. The extension picks the format: .vtp
// (XML PolyData), .vtu (XML UnstructuredGrid) and .vtk (legacy PolyData) are
// gathered to rank 0 and written there; .pvtp and .pvtu give one piece per
// rank and an index written by rank 0. XML frames are listed in a .pvd
// collection with their simulated time. See doc/commands/dump.md.
#include <mpi.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataWriter.h>
#include <vtkSmartPointer.h>
#include <vtkTypeInt64Array.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <type_traits>
#include <vector>

#include "compute/compute_gran_local.h"
#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/modify.h"
#include "core/registry.h"
#include "output/vtk_module.h"
#include "core/update.h"
#include "output/dump.h"
#include "output/dump_custom.h"
#include "output/vtk_frame.h"
#include "output/vtk_support.h"
#include "particles/particles.h"

namespace granary {

namespace {

/// One cell-data array: consecutive columns of a compute row.
struct CellArray {
  std::string name;
  int first = 0, ncomp = 1;
  int type = 0;  // 0 Float64, 1 Int32, 2 Int64
};

class DumpLocalGranVTK : public Dump {
 public:
  DumpLocalGranVTK(Engine& engine, const Args& args) : Dump(engine, args) {
    const std::string where = "dump " + id + " local/gran/vtk";
    if (args.size() != 6) {
      throw InputError(where + ": expected `dump " + id + " " + args[1] + " local/gran/vtk " + args[3] + " " +
                       filename + " compute-ID` (the ID of a compute pair/gran/local)");
    }
    compute_id_ = args[5];
    const std::string ext = vtkio::extension(filename);
    if (ext == ".vtp" || ext == ".pvtp")
      kind_ = Kind::kPolyData;
    else if (ext == ".vtu" || ext == ".pvtu")
      kind_ = Kind::kUnstructured;
    else if (ext == ".vtk")
      kind_ = Kind::kLegacy;
    else
      throw InputError(where + ": needs a file name ending in .vtp, .vtu, .pvtp, .pvtu or .vtk, got '" +
                       filename + "'; e.g. post/forcechain*.vtp");
    parallel_ = ext == ".pvtp" || ext == ".pvtu";
    if (filename.find('%') != std::string::npos)
      throw InputError(where + ": '%' is not allowed in '" + filename +
                       "'; .pvtp and .pvtu names give one piece per rank");
    find_compute();
    dumpio::check_directory(engine.world, filename, "dump " + id);
    if (kind_ != Kind::kLegacy) pvd_.path = vtkio::pvd_name(filename, id);
  }

  void single_file() override {
    pvd_.path.clear();
    pvd_.clear();
  }

  int modify_param(const Args& args, std::size_t k) override {
    const std::string& key = args[k];
    const std::string where = "dump_modify " + id + " " + key;
    if (const int used = options_.parse(args, k, where)) return used;
    if (const int used =
            dumpio::parse_pvd(engine_.world, args, k, where, kind_ == Kind::kLegacy, pvd_.path)) {
      pvd_.clear();
      return used;
    }
    return 0;
  }

  void init() override { find_compute(); }

  void write() override {
    ComputeGranLocal& c = find_compute();
    if (c.invoked_local != engine_.update->ntimestep) {
      c.compute_local();
      c.invoked_local = engine_.update->ntimestep;
    }
    const ComputeGranLocal::Layout L = c.layout();
    const std::vector<CellArray> arrays = cell_arrays(L);
    // the contacts whose particles are in the dump's group
    const Particles& p = *engine_.particles;
    std::vector<double> local;
    local.reserve(c.array_local.size());
    for (int r = 0; r < c.size_local_rows; ++r) {
      if (!(p.mask[c.row_i[r]] & groupbit) || (c.row_j[r] >= 0 && !(p.mask[c.row_j[r]] & groupbit))) continue;
      local.insert(local.end(), c.array_local.begin() + static_cast<std::size_t>(r) * L.ncols,
                   c.array_local.begin() + static_cast<std::size_t>(r + 1) * L.ncols);
    }
    const std::string frame = dumpio::expand(filename, engine_.update->ntimestep, options_.pad);
    const std::string listed =
        parallel_ ? vtkio::strip_extension(frame) + (kind_ == Kind::kPolyData ? ".pvtp" : ".pvtu") : frame;
    std::string err;
    if (parallel_) {
      err = write_file(piece_name(frame, engine_.rank), local, L, arrays);
    } else {
      std::vector<double> all;
      dumpio::gather_rows(engine_.world, local, L.ncols, all);
      if (engine_.rank == 0) err = write_file(frame, all, L, arrays);
    }
    err = dumpio::first_error(engine_.world, err);
    if (err.empty() && engine_.rank == 0) {
      if (parallel_) err = write_index(frame, listed, arrays);
      if (err.empty() && !pvd_.path.empty()) err = pvd_.add(listed, engine_.update->time());
    }
    err = dumpio::first_error(engine_.world, err);
    if (!err.empty()) throw RunError("dump " + id + ": " + err);
  }

 private:
  enum class Kind { kPolyData, kUnstructured, kLegacy };

  ComputeGranLocal& find_compute() const {
    const std::string where = "dump " + id + " local/gran/vtk";
    Compute* c = engine_.modify->find_compute(compute_id_);
    if (!c)
      throw InputError(where + ": there is no compute '" + compute_id_ + "'; define it first, e.g. compute " +
                       compute_id_ + " all pair/gran/local pos vel force");
    auto* gl = dynamic_cast<ComputeGranLocal*>(c);
    if (!gl)
      throw InputError(where + ": compute " + compute_id_ + " is a " + c->style +
                       " compute; it must be a compute pair/gran/local or wall/gran/local");
    if (gl->layout().pos < 0)
      throw InputError(
          where + ": draws each contact as a line between " +
          (gl->layout().wall ? "the contact point and the particle centre" : "the two particle centres") +
          ", but compute " + compute_id_ + " does not give them; add the keyword pos to it");
    return *gl;
  }

  /// The cell-data arrays of a row layout, named as LIGGGHTS names them
  /// (periodic, history and contact_point, and the names of wall contacts'
  /// arrays are Granary's).
  static std::vector<CellArray> cell_arrays(const ComputeGranLocal::Layout& L) {
    std::vector<CellArray> out;
    auto add = [&out](const char* name, int first, int ncomp, int type = 0) {
      if (first >= 0 && ncomp > 0) out.push_back({name, first, ncomp, type});
    };
    if (L.wall) {
      add("wall_vel", L.vel, 3);
      add("vel", L.vel >= 0 ? L.vel + 3 : -1, 3);
      add("mesh_id", L.id, 1, 1);
      add("triangle_id", L.id >= 0 ? L.id + 1 : -1, 1, 1);
      add("id", L.id >= 0 ? L.id + 2 : -1, 1, 2);
    } else {
      add("vel1", L.vel, 3);
      add("vel2", L.vel >= 0 ? L.vel + 3 : -1, 3);
      add("id1", L.id, 1, 2);
      add("id2", L.id >= 0 ? L.id + 1 : -1, 1, 2);
      add("periodic", L.id >= 0 ? L.id + 2 : -1, 1, 1);
    }
    add("force", L.force, 3);
    add("force_normal", L.force_normal, 3);
    add("force_tangential", L.force_tangential, 3);
    add("torque", L.torque, 3);
    add("history", L.history, L.nhistory);
    add("contact_area", L.contact_area, 1);
    add("delta", L.delta, 1);
    add("contact_point", L.contact_point, 3);
    return out;
  }

  template <class DataSet>
  static vtkSmartPointer<DataSet> build(const std::vector<double>& rows, const ComputeGranLocal::Layout& L,
                                        const std::vector<CellArray>& arrays, double time,
                                        std::int64_t step) {
    const vtkIdType n = L.ncols > 0 ? static_cast<vtkIdType>(rows.size() / L.ncols) : 0;
    auto points = vtkSmartPointer<vtkPoints>::New();
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(2 * n);
    auto offsets = vtkSmartPointer<vtkIdTypeArray>::New();
    auto conn = vtkSmartPointer<vtkIdTypeArray>::New();
    offsets->SetNumberOfValues(n + 1);
    conn->SetNumberOfValues(2 * n);
    for (vtkIdType k = 0; k < n; ++k) {
      const double* r = rows.data() + k * L.ncols + L.pos;
      points->SetPoint(2 * k, r[0], r[1], r[2]);
      points->SetPoint(2 * k + 1, r[3], r[4], r[5]);
      offsets->SetValue(k, 2 * k);
      conn->SetValue(2 * k, 2 * k);
      conn->SetValue(2 * k + 1, 2 * k + 1);
    }
    offsets->SetValue(n, 2 * n);
    auto cells = vtkSmartPointer<vtkCellArray>::New();
    cells->SetData(offsets, conn);
    auto ds = vtkSmartPointer<DataSet>::New();
    ds->SetPoints(points);
    if constexpr (std::is_same_v<DataSet, vtkPolyData>)
      ds->SetLines(cells);
    else
      ds->SetCells(VTK_LINE, cells);
    for (const CellArray& a : arrays) {
      vtkSmartPointer<vtkDataArray> arr;
      if (a.type == 1)
        arr = vtkSmartPointer<vtkIntArray>::New();
      else if (a.type == 2)
        arr = vtkSmartPointer<vtkTypeInt64Array>::New();
      else
        arr = vtkSmartPointer<vtkDoubleArray>::New();
      arr->SetName(a.name.c_str());
      arr->SetNumberOfComponents(a.ncomp);
      arr->SetNumberOfTuples(n);
      for (vtkIdType k = 0; k < n; ++k)
        for (int q = 0; q < a.ncomp; ++q)
          arr->SetComponent(k, q, rows[k * L.ncols + a.first + q]);
      ds->GetCellData()->AddArray(arr);
    }
    vtkio::add_time_step(ds, time, step);
    return ds;
  }

  static std::string piece_name(const std::string& frame, int rank) {
    return vtkio::strip_extension(frame) + "_" + std::to_string(rank) +
           (vtkio::extension(frame) == ".pvtp" ? ".vtp" : ".vtu");
  }

  /// Write one file (a whole frame, or this rank's piece); "" or an error message.
  std::string write_file(const std::string& file, const std::vector<double>& rows,
                         const ComputeGranLocal::Layout& L, const std::vector<CellArray>& arrays) const {
    const double time = engine_.update->time();
    const std::int64_t step = engine_.update->ntimestep;
    return replace_file_by_name(file, [&](const std::string& temp) -> std::string {
      int ok = 0;
      if (kind_ == Kind::kLegacy) {
        auto w = vtkSmartPointer<vtkPolyDataWriter>::New();
        w->SetFileVersion(vtkPolyDataWriter::VTK_LEGACY_READER_VERSION_4_2);
        if (options_.binary)
          w->SetFileTypeToBinary();
        else
          w->SetFileTypeToASCII();
        w->SetHeader(("Granary dump " + id + " (contacts), step " + std::to_string(step)).c_str());
        w->SetInputData(build<vtkPolyData>(rows, L, arrays, time, step));
        w->SetFileName(temp.c_str());
        ok = w->Write();
      } else if (kind_ == Kind::kPolyData) {
        auto w = vtkSmartPointer<vtkXMLPolyDataWriter>::New();
        vtkio::configure_writer(w.Get(), options_.binary, options_.compressor);
        w->SetInputData(build<vtkPolyData>(rows, L, arrays, time, step));
        w->SetFileName(temp.c_str());
        ok = w->Write();
      } else {
        auto w = vtkSmartPointer<vtkXMLUnstructuredGridWriter>::New();
        vtkio::configure_writer(w.Get(), options_.binary, options_.compressor);
        w->SetInputData(build<vtkUnstructuredGrid>(rows, L, arrays, time, step));
        w->SetFileName(temp.c_str());
        ok = w->Write();
      }
      return ok ? "" : "VTK could not write '" + file + "'";
    });
  }

  /// The .pvtp/.pvtu index naming every rank's piece (relative to the index).
  std::string write_index(const std::string& frame, const std::string& index,
                          const std::vector<CellArray>& arrays) const {
    const bool poly = kind_ == Kind::kPolyData;
    const std::string type = poly ? "PPolyData" : "PUnstructuredGrid";
    static const char* kTypeNames[] = {"Float64", "Int32", "Int64"};
    std::string text = "<?xml version=\"1.0\"?>\n<VTKFile type=\"" + type +
                       "\" version=\"1.0\" byte_order=\"" + vtkio::byte_order() +
                       "\" header_type=\"UInt64\">\n";
    text += "  <" + type + " GhostLevel=\"0\">\n    <PCellData>\n";
    for (const CellArray& a : arrays) {
      text += "      <PDataArray type=\"" + std::string(kTypeNames[a.type]) + "\" Name=\"" +
              vtkio::xml_escape(a.name) + "\"";
      if (a.ncomp > 1) text += " NumberOfComponents=\"" + std::to_string(a.ncomp) + "\"";
      text += "/>\n";
    }
    text += "    </PCellData>\n    <PPoints>\n";
    text += "      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n";
    text += "    </PPoints>\n";
    for (int r = 0; r < engine_.nprocs; ++r) {
      const std::string piece = std::filesystem::path(piece_name(frame, r)).filename().string();
      text += "    <Piece Source=\"" + vtkio::xml_escape(piece) + "\"/>\n";
    }
    text += "  </" + type + ">\n</VTKFile>\n";
    return replace_file(index, text);
  }

  std::string compute_id_;
  Kind kind_ = Kind::kPolyData;
  bool parallel_ = false;
  vtkio::WriteOptions options_;
  vtkio::PvdCollection pvd_;
};

}  // namespace

GRANARY_VTK_DUMP_STYLE("local/gran/vtk", DumpLocalGranVTK);

}  // namespace granary
