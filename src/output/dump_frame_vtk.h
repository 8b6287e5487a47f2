// Base of the dumps that write one VTK frame per output on rank 0 (mesh/vtk,
// decomposition/vtk, euler/vtk): legacy VTK for a .vtk name, VTK XML for
// the style's XML extension (listed with its time in a .pvd collection);
// dump_modify binary, compressor and pvd.
#pragma once

#include <string>

#include "output/dump.h"
#include "output/vtk_support.h"

namespace granary {

class FrameDumpVTK : public Dump {
 public:
  void single_file() override;
  int modify_param(const Args& args, std::size_t k) override;

 protected:
  /// Checks the file name (a .vtk or `xml_ext` ending, no '%': rank 0 writes
  /// whole frames) and its directory; `example` is shown in the error.
  FrameDumpVTK(Engine& engine, const Args& args, const std::string& style, const std::string& xml_ext,
               const std::string& example);

  bool legacy_ = false;  // .vtk: legacy VTK, never in a .pvd collection
  vtkio::WriteOptions options_;
  vtkio::PvdCollection pvd_;
};

}  // namespace granary
