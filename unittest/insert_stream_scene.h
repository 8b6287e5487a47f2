// The box, materials and insertion face shared by the insert/stream tests:
// spheres of 2500 kg/m^3 streamed through a mesh face (fix `face`).
#pragma once

#include <string>
#include <vector>

#include "script_engine.h"

namespace insert_stream_scene {

/// Box, materials, pair style, timestep and the insertion face read from `face_stl`.
inline std::vector<std::string> box(const std::string& face_stl) {
  return {
      "units si",
      "atom_style granular",
      "boundary f f f",
      "newton off",
      "communicate single vel yes",
      "region box block -0.05 0.15 -0.05 0.15 -0.2 0.15 units box",
      "create_box 1 box",
      "neighbor 0.001 bin",
      "neigh_modify delay 0",
      granary::test::materials(1, 5.e6, 0.45, 0.5, 0.5),
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 1e-5",
      "fix face all mesh/surface file " + face_stl + " type 1",
  };
}

}  // namespace insert_stream_scene
