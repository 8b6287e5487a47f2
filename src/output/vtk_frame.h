// Writing one frame of a VTK XML dump: the simulated time and step as field
// data (ParaView reads TimeValue), and a serial PolyData frame written with
// the dump's options and listed in its .pvd collection.
#pragma once

#include <vtkDataObject.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkPolyData.h>
#include <vtkPolyDataWriter.h>
#include <vtkSmartPointer.h>
#include <vtkTypeInt64Array.h>
#include <vtkXMLPolyDataWriter.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "output/dump_custom.h"
#include "output/vtk_support.h"

namespace granary {
namespace vtkio {

/// A VTK data array named `name` with `ncomp` components and `n` tuples.
template <class Array>
vtkSmartPointer<Array> named_array(const char* name, int ncomp, vtkIdType n) {
  auto a = vtkSmartPointer<Array>::New();
  a->SetName(name);
  a->SetNumberOfComponents(ncomp);
  a->SetNumberOfTuples(n);
  return a;
}

/// Attach the simulated time (TimeValue) and the step (Step) as field data.
inline void add_time_step(vtkDataObject* ds, double time, std::int64_t step) {
  auto tv = vtkSmartPointer<vtkDoubleArray>::New();
  tv->SetName("TimeValue");
  tv->InsertNextValue(time);
  auto cycle = vtkSmartPointer<vtkTypeInt64Array>::New();
  cycle->SetName("Step");
  cycle->InsertNextValue(step);
  ds->GetFieldData()->AddArray(tv);
  ds->GetFieldData()->AddArray(cycle);
}

/// Write `ds` to `frame` as legacy VTK PolyData, file version 4.2 (binary,
/// big-endian, or ASCII), under a temporary name renamed when complete.
/// Returns "" or an error message naming the file.
inline std::string write_legacy_polydata(vtkPolyData* ds, const std::string& frame, const std::string& header,
                                         bool binary) {
  return replace_file_by_name(frame, [&](const std::string& temp) -> std::string {
    auto w = vtkSmartPointer<vtkPolyDataWriter>::New();
    w->SetFileVersion(vtkPolyDataWriter::VTK_LEGACY_READER_VERSION_4_2);
    if (binary)
      w->SetFileTypeToBinary();
    else
      w->SetFileTypeToASCII();
    w->SetHeader(header.c_str());
    w->SetInputData(ds);
    w->SetFileName(temp.c_str());
    return w->Write() ? "" : "VTK could not write '" + frame + "'";
  });
}

/// Write `ds` to `frame` with its time and step: VTK XML PolyData (.vtp),
/// then listed in `pvd` (when that has a path), or legacy VTK PolyData
/// (write_legacy_polydata) when `frame` ends in .vtk (never listed:
/// ParaView's .pvd reader reads XML files only). Returns "" or an error
/// message naming the file.
inline std::string write_polydata_frame(vtkPolyData* ds, const std::string& frame, double time,
                                        std::int64_t step, const WriteOptions& options, PvdCollection& pvd) {
  add_time_step(ds, time, step);
  if (extension(frame) == ".vtk")
    return write_legacy_polydata(ds, frame, "Granary, step " + std::to_string(step), options.binary);
  // written under a temporary name, then renamed: a frame is complete or absent
  const std::string err = replace_file_by_name(frame, [&](const std::string& temp) -> std::string {
    auto w = vtkSmartPointer<vtkXMLPolyDataWriter>::New();
    configure_writer(w.Get(), options.binary, options.compressor);
    w->SetInputData(ds);
    w->SetFileName(temp.c_str());
    return w->Write() ? "" : "VTK could not write '" + frame + "'";
  });
  if (!err.empty()) return err;
  if (!pvd.path.empty()) return pvd.add(frame, time);
  return "";
}

}  // namespace vtkio
}  // namespace granary
