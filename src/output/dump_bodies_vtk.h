// `dump ID group bodies/vtk N file.vtp`: one VTK PolyData point per clump of
// fix multisphere, at its centre of mass, with the body state as point data
// (id, type, mass, quaternion, long_axis, velocity, angular_velocity,
// nspheres). Bodies are replicated on every rank, so rank 0 writes the whole
// frame (no pieces); it also keeps a .pvd collection of every frame with its
// simulated time. See doc/commands/dump.md.
#pragma once

#include <string>

#include "output/dump.h"
#include "output/vtk_support.h"

namespace granary {

class Clumps;

class DumpBodiesVTK : public Dump {
 public:
  DumpBodiesVTK(Engine& engine, const Args& args);

  void init() override;
  void write() override;
  int modify_param(const Args& args, std::size_t k) override;
  void single_file() override {
    pvd_.path.clear();
    pvd_.clear();
  }

 private:
  Clumps& multisphere() const;
  /// Rank 0: write the frame's .vtp; returns an error message or "".
  std::string write_frame(const std::string& frame, const std::vector<char>& selected);

  vtkio::WriteOptions options_;
  vtkio::PvdCollection pvd_;
};

}  // namespace granary
