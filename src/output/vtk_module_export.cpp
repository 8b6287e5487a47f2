// Part of the VTK module (granary_vtk.so): the mark load_vtk_module() checks.
#include "output/vtk_module_interface.h"

extern "C" __attribute__((visibility("default"))) const char* granary_vtk_module_interface() {
  static const std::string mark = granary::vtk_module_interface_here();
  return mark.c_str();
}
