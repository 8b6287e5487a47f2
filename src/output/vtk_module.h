// The VTK dump styles live in a module, granary_vtk.so, beside the granary
// executable, loaded the first time a script creates one of them. A run that
// writes no VTK output never loads the VTK libraries (about 18 MiB of
// resident memory per rank, and their start-up time).
//
// The module's styles register with GRANARY_VTK_DUMP_STYLE (below) into
// vtk_module_dumps(); the main registry holds, under the same names, factories
// that load the module and hand over to the module's factory. The list of
// those names (vtk_module_dump_styles()) is what `list-styles` and the
// documentation checks see.
#pragma once

#include <string>
#include <vector>

#include "core/registry.h"

namespace granary {

/// The names of the dump styles the VTK module provides.
const std::vector<std::string>& vtk_module_dump_styles();

/// The registry the module's styles add themselves to when it is loaded.
DumpRegistry& vtk_module_dumps();

/// Load the VTK module once (thread-unsafe, as the input is). Looks in this
/// order: the file named by the environment variable GRANARY_VTK_MODULE, then
/// granary_vtk.so in the folder of the running executable. Throws InputError
/// naming where it looked when the module is missing, cannot be loaded or
/// belongs to another build. `style` names the dump that needed it.
void load_vtk_module(const std::string& style);

/// Where the module was loaded from ("" while it is not loaded).
const std::string& vtk_module_path();

}  // namespace granary

#define GRANARY_VTK_DUMP_STYLE(name, Class)                                                           \
  static const bool GRANARY_UNIQUE(granary_vtk_dump_registered_) = ::granary::vtk_module_dumps().add( \
      name, [](::granary::Engine& e, const ::granary::Args& a) -> std::unique_ptr<::granary::Dump> {  \
        return std::make_unique<Class>(e, a);                                                         \
      })
