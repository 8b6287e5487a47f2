// `dump ID group custom/vtk N file fields...`: VTK files for ParaView.
//
// The file name's extension picks the format:
//   .vtp   XML PolyData (one vertex cell per particle, point-data arrays)
//   .vtu   XML UnstructuredGrid (VTK_VERTEX cells)
//   .pvtp  .pvtu  the parallel XML formats even on one rank
//   .vtk   legacy VTK PolyData, gathered to rank 0
// With XML formats on several ranks every rank writes its own piece
// <stem>_<rank>.vtp with the serial VTK writer, and rank 0 then writes the
// .pvtp/.pvtu index naming every piece. (VTK's parallel writers list only the
// pieces their own process wrote unless VTK has an MPI controller, so the
// index is written here; this works with any VTK build.) Rank 0 keeps a .pvd
// collection listing every frame with its simulated time; it is rewritten
// (temporary file + rename) after each frame.
//
// `dump ID group atom/vtk N file` (LIGGGHTS) is the same writer with a fixed
// list of arrays under LIGGGHTS' names: radii, id, type, proc, mass,
// velocity_lin, velocity_ang and force.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "output/dump.h"
#include "output/vtk_support.h"
#include "output/dump_custom.h"

namespace granary {

class DumpCustomVTK : public Dump {
 public:
  DumpCustomVTK(Engine& engine, const Args& args);
  ~DumpCustomVTK() override;

  void init() override;
  void write() override;
  int modify_param(const Args& args, std::size_t k) override;
  void single_file() override {
    pvd_.path.clear();
    pvd_.clear();
  }

  /// One VTK point-data array: 1 or 3 columns of the packed rows.
  struct Array {
    std::string name;
    std::vector<int> cols;
    int type = 0;  // 0 Float64, 1 Int32, 2 Int64
  };

 private:
  enum class Kind { kPolyData, kUnstructured, kLegacy };

  /// Write this rank's data; returns an error message or "".
  std::string write_xml(const std::string& frame, const std::vector<double>& rows, std::int64_t nrows);
  std::string write_legacy(const std::string& frame, const std::vector<double>& rows, std::int64_t nrows);
  std::string write_index(const std::string& frame, const std::string& index);

  DumpFields fields_;
  std::vector<Array> arrays_;
  Kind kind_ = Kind::kPolyData;
  bool parallel_ext_ = false;  // .pvtp/.pvtu given
  vtkio::WriteOptions options_;
  vtkio::PvdCollection pvd_;
};

}  // namespace granary
