// A fingerprint of the interface between granary and its VTK module: the
// version, the compiler, and the sizes of the engine's classes the module
// uses. Each side computes it with its own headers (internal linkage: the
// module never calls the executable's copy); the module exports its value and
// load_vtk_module() refuses a module of another build.
#pragma once

#include <string>

#include "core/engine.h"
#include "output/dump.h"
#include "output/dump_custom.h"
#include "particles/particles.h"

#ifndef GRANARY_VERSION
#define GRANARY_VERSION "0.1.0"
#endif

namespace granary {
namespace {

[[maybe_unused]] std::string vtk_module_interface_here() {
  return std::string("granary " GRANARY_VERSION ", ") + __VERSION__ + ", sizes " +
         std::to_string(sizeof(Engine)) + " " + std::to_string(sizeof(Particles)) + " " +
         std::to_string(sizeof(Dump)) + " " + std::to_string(sizeof(DumpCustom));
}

}  // namespace
}  // namespace granary
