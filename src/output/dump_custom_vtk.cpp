#include "output/dump_custom_vtk.h"
#include "output/vtk_support.h"

#include <vtkCellArray.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkTypeInt64Array.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <type_traits>

#include "core/atomic_file.h"
#include "core/engine.h"
#include "core/error.h"
#include "core/registry.h"
#include "output/vtk_module.h"
#include "core/update.h"
#include "domain/domain.h"
#include "domain/region.h"
#include "output/vtk_frame.h"

namespace granary {

using vtkio::byte_order;
using vtkio::extension;
using vtkio::strip_extension;
using vtkio::xml_escape;

namespace {

namespace fs = std::filesystem;

// Components that form one 3-vector array when all three are requested.
struct Triple {
  const char* a;
  const char* b;
  const char* c;
  const char* name;
};
const Triple kTriples[] = {
    {"vx", "vy", "vz", "v"},        {"fx", "fy", "fz", "f"},     {"omegax", "omegay", "omegaz", "omega"},
    {"tqx", "tqy", "tqz", "tq"},    {"ix", "iy", "iz", "image"}, {"xu", "yu", "zu", "x_unwrapped"},
    {"xs", "ys", "zs", "x_scaled"},
};

}  // namespace

namespace {

// atom/vtk: its fixed fields, and LIGGGHTS' names of the arrays they make
const char* const kAtomVtkFields[] = {"radius", "id",     "type",   "proc",   "mass", "vx", "vy",
                                      "vz",     "omegax", "omegay", "omegaz", "fx",   "fy", "fz"};
const std::pair<const char*, const char*> kAtomVtkNames[] = {
    {"radius", "radii"}, {"v", "velocity_lin"}, {"omega", "velocity_ang"}, {"f", "force"}};

}  // namespace

DumpCustomVTK::DumpCustomVTK(Engine& engine, const Args& args)
    : Dump(engine, args),
      fields_(
          engine,
          [&] {
            // positions come first (they become the points), then the other fields
            Args words{"x", "y", "z"};
            if (args.size() > 2 && args[2] == "atom/vtk") {
              if (args.size() > 5) {
                throw InputError("dump " + args[0] + " atom/vtk takes no fields after the file name (got '" +
                                 args[5] + "'); use dump custom/vtk to choose them");
              }
              for (const char* w : kAtomVtkFields)
                words.push_back(w);
              return words;
            }
            for (std::size_t k = 5; k < args.size(); ++k)
              if (args[k] != "x" && args[k] != "y" && args[k] != "z") words.push_back(args[k]);
            return words;
          }(),
          "dump " + args[0]) {
  const std::string ext = extension(filename);
  const std::string style_name = args[2];
  if (ext == ".vtp" || ext == ".pvtp")
    kind_ = Kind::kPolyData;
  else if (ext == ".vtu" || ext == ".pvtu")
    kind_ = Kind::kUnstructured;
  else if (ext == ".vtk")
    kind_ = Kind::kLegacy;
  else {
    throw InputError("dump " + id + ": " + style_name +
                     " needs a file name ending in .vtp, .vtu, .pvtp, .pvtu or .vtk, got '" + filename + "'");
  }
  parallel_ext_ = ext == ".pvtp" || ext == ".pvtu";
  if (filename.find('%') != std::string::npos) {
    throw InputError("dump " + id + ": '%' is not needed in " + style_name +
                     " file names: on several ranks every rank "
                     "writes its own piece and rank 0 the ." +
                     std::string(kind_ == Kind::kUnstructured ? "pvtu" : "pvtp") + " index");
  }
  dumpio::check_directory(engine.world, filename, "dump " + id);

  // the .pvd collection next to the files: the pattern without '*', extension .pvd.
  // ParaView's .pvd reader opens XML files only: no collection for legacy files
  if (kind_ != Kind::kLegacy) pvd_.path = vtkio::pvd_name(filename, id);

  // point-data arrays; x y z are the points (fields 0..2)
  std::vector<bool> used(fields_.ncols(), false);
  used[0] = used[1] = used[2] = true;
  std::vector<std::string> names;
  for (int c = 3; c < fields_.ncols(); ++c) {
    if (used[c]) continue;
    const DumpField& f = fields_.fields[c];
    Array a;
    a.name = f.name;
    a.cols = {c};
    for (const auto& t : kTriples) {
      if (f.name != t.a && f.name != t.b && f.name != t.c) continue;
      const int ia = fields_.find(t.a), ib = fields_.find(t.b), ic = fields_.find(t.c);
      if (ia >= 0 && ib >= 0 && ic >= 0) {
        a.name = t.name;
        a.cols = {ia, ib, ic};
      }
    }
    for (int col : a.cols)
      used[col] = true;
    if (std::find(names.begin(), names.end(), a.name) != names.end()) continue;  // e.g. "type type"
    names.push_back(a.name);
    if (f.integer)
      a.type = (f.name == "id" || f.name == "body" || f.name == "mol" || f.name == "id_multisphere") ? 2 : 1;
    if (style_name == "atom/vtk")
      for (const auto& [from, to] : kAtomVtkNames)
        if (a.name == from) a.name = to;
    arrays_.push_back(a);
  }
}

DumpCustomVTK::~DumpCustomVTK() = default;

int DumpCustomVTK::modify_param(const Args& args, std::size_t k) {
  const std::string& key = args[k];
  const bool has1 = k + 1 < args.size();
  const std::string where = "dump_modify " + id + " " + key;
  if (const int used = options_.parse(args, k, where)) return used;
  if (const int used = parse_region(args, k, where)) return used;
  if (key == "pvd" && has1) {
    const std::string& v = args[k + 1];
    if (v == "no" || v == "off" || v == "none") {
      pvd_.path.clear();
      pvd_.clear();
      return 2;
    }
    if (kind_ == Kind::kLegacy) {
      throw InputError(where +
                       ": legacy .vtk files cannot be listed in a .pvd (ParaView reads XML files from "
                       "it); use a .vtp file name, or open the numbered .vtk files as a series");
    }
    if (extension(v) != ".pvd")
      throw InputError(where + ": the collection file name must end in .pvd, got '" + v + "'");
    dumpio::check_directory(engine_.world, v, where);
    pvd_.path = v;
    pvd_.clear();
    return 2;
  }
  if (key == "sort" && has1) {
    if (args[k + 1] != "off" && args[k + 1] != "id") throw InputError(where + ": expected id or off");
    return 2;  // accepted for compatibility: the order of points does not matter to VTK readers
  }
  return 0;
}

void DumpCustomVTK::init() {
  fields_.init();
}

namespace {

// Build the data set of `nrows` packed rows (stride ncols, positions in 0..2).
template <class DataSet>
vtkSmartPointer<DataSet> build_dataset(const std::vector<double>& rows, std::int64_t nrows, int ncols,
                                       const std::vector<DumpCustomVTK::Array>& arrays, double time,
                                       std::int64_t step) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(nrows);
  for (std::int64_t k = 0; k < nrows; ++k) {
    const double* r = rows.data() + k * ncols;
    points->SetPoint(k, r[0], r[1], r[2]);
  }
  auto conn = vtkSmartPointer<vtkIdTypeArray>::New();
  conn->SetNumberOfValues(nrows);
  for (std::int64_t k = 0; k < nrows; ++k)
    conn->SetValue(k, k);
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  cells->SetData(1, conn);

  auto ds = vtkSmartPointer<DataSet>::New();
  ds->SetPoints(points);
  if constexpr (std::is_same_v<DataSet, vtkPolyData>)
    ds->SetVerts(cells);
  else
    ds->SetCells(VTK_VERTEX, cells);

  for (const auto& a : arrays) {
    vtkSmartPointer<vtkDataArray> arr;
    if (a.type == 1)
      arr = vtkSmartPointer<vtkIntArray>::New();
    else if (a.type == 2)
      arr = vtkSmartPointer<vtkTypeInt64Array>::New();
    else
      arr = vtkSmartPointer<vtkDoubleArray>::New();
    const int nc = static_cast<int>(a.cols.size());
    arr->SetName(a.name.c_str());
    arr->SetNumberOfComponents(nc);
    arr->SetNumberOfTuples(nrows);
    for (std::int64_t k = 0; k < nrows; ++k)
      for (int c = 0; c < nc; ++c)
        arr->SetComponent(k, c, rows[k * ncols + a.cols[c]]);
    ds->GetPointData()->AddArray(arr);
  }
  vtkio::add_time_step(ds, time, step);
  return ds;
}

}  // namespace

std::string DumpCustomVTK::write_xml(const std::string& frame, const std::vector<double>& rows,
                                     std::int64_t nrows) {
  const double time = engine_.update->time();
  const std::int64_t step = engine_.update->ntimestep;
  const int ncols = fields_.ncols();
  const bool parallel = parallel_ext_ || engine_.nprocs > 1;
  const bool poly = kind_ == Kind::kPolyData;

  // In the parallel format every rank writes its piece <stem>_<rank>.vtp (.vtu)
  // with the serial writer; rank 0 writes the index afterwards (write_index).
  const std::string file =
      parallel ? strip_extension(frame) + "_" + std::to_string(engine_.rank) + (poly ? ".vtp" : ".vtu")
               : frame;
  // written under a temporary name, then renamed: a frame is complete or absent
  return replace_file_by_name(file, [&](const std::string& temp) -> std::string {
    int ok = 0;
    if (poly) {
      auto w = vtkSmartPointer<vtkXMLPolyDataWriter>::New();
      vtkio::configure_writer(w.Get(), options_.binary, options_.compressor);
      w->SetInputData(build_dataset<vtkPolyData>(rows, nrows, ncols, arrays_, time, step));
      w->SetFileName(temp.c_str());
      ok = w->Write();
    } else {
      auto w = vtkSmartPointer<vtkXMLUnstructuredGridWriter>::New();
      vtkio::configure_writer(w.Get(), options_.binary, options_.compressor);
      w->SetInputData(build_dataset<vtkUnstructuredGrid>(rows, nrows, ncols, arrays_, time, step));
      w->SetFileName(temp.c_str());
      ok = w->Write();
    }
    return ok ? "" : "VTK could not write '" + file + "'";
  });
}

std::string DumpCustomVTK::write_index(const std::string& frame, const std::string& index) {
  // The .pvtp/.pvtu index: array declarations (as the pieces store them) and
  // one Piece per rank, named relative to the index.
  const bool poly = kind_ == Kind::kPolyData;
  const std::string type = poly ? "PPolyData" : "PUnstructuredGrid";
  const std::string piece_stem = fs::path(strip_extension(frame)).filename().string();
  static const char* kTypeNames[] = {"Float64", "Int32", "Int64"};
  std::string text = "<?xml version=\"1.0\"?>\n<VTKFile type=\"" + type + "\" version=\"1.0\" byte_order=\"" +
                     byte_order() + "\" header_type=\"UInt64\">\n";
  text += "  <" + type + " GhostLevel=\"0\">\n    <PPointData>\n";
  for (const auto& a : arrays_) {
    text += "      <PDataArray type=\"" + std::string(kTypeNames[a.type]) + "\" Name=\"" +
            xml_escape(a.name) + "\"";
    if (a.cols.size() > 1) text += " NumberOfComponents=\"" + std::to_string(a.cols.size()) + "\"";
    text += "/>\n";
  }
  text += "    </PPointData>\n    <PPoints>\n";
  text += "      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n";
  text += "    </PPoints>\n";
  for (int r = 0; r < engine_.nprocs; ++r) {
    text += "    <Piece Source=\"" +
            xml_escape(piece_stem + "_" + std::to_string(r) + (poly ? ".vtp" : ".vtu")) + "\"/>\n";
  }
  text += "  </" + type + ">\n</VTKFile>\n";
  return replace_file(index, text);
}

std::string DumpCustomVTK::write_legacy(const std::string& frame, const std::vector<double>& rows,
                                        std::int64_t nrows) {
  return vtkio::write_legacy_polydata(
      build_dataset<vtkPolyData>(rows, nrows, fields_.ncols(), arrays_, engine_.update->time(),
                                 engine_.update->ntimestep),
      frame, "Granary dump " + id + ", step " + std::to_string(engine_.update->ntimestep), options_.binary);
}

void DumpCustomVTK::write() {
  std::vector<int> sel;
  fields_.select(groupbit, region_, sel);
  std::vector<double> local;
  fields_.pack(sel, false, local);
  const std::string frame = dumpio::expand(filename, engine_.update->ntimestep, options_.pad);

  std::string err;
  const bool parallel = kind_ != Kind::kLegacy && (parallel_ext_ || engine_.nprocs > 1);
  const std::string listed =
      parallel ? strip_extension(frame) + (kind_ == Kind::kPolyData ? ".pvtp" : ".pvtu") : frame;
  if (kind_ == Kind::kLegacy) {
    std::vector<double> all;
    const std::int64_t nrows = dumpio::gather_rows(engine_.world, local, fields_.ncols(), all);
    if (engine_.rank == 0) err = write_legacy(frame, all, nrows);
  } else {
    err = write_xml(frame, local, static_cast<std::int64_t>(sel.size()));
  }
  err = dumpio::first_error(engine_.world, err);
  if (err.empty() && (parallel || !pvd_.path.empty())) {
    if (engine_.rank == 0 && parallel) err = write_index(frame, listed);
    if (engine_.rank == 0 && err.empty() && !pvd_.path.empty())
      err = pvd_.add(listed, engine_.update->time());
    err = dumpio::first_error(engine_.world, err);
  }
  if (!err.empty()) throw RunError("dump " + id + ": " + err);
}

GRANARY_VTK_DUMP_STYLE("custom/vtk", DumpCustomVTK);
GRANARY_VTK_DUMP_STYLE("atom/vtk", DumpCustomVTK);

}  // namespace granary
