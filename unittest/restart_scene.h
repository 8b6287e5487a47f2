// A small poured bed used by the restart tests: spheres on a lattice fall into
// a box with five walls; contacts with tangential history everywhere.
#pragma once

#include <string>
#include <vector>

#include "script_engine.h"

namespace restart_scene {

// Settings, materials, walls and integrator: what a restart script re-defines.
inline std::vector<std::string> physics(const std::string& newton = "off") {
  return {
      "neighbor 0.0005 bin",
      "neigh_modify delay 0",
      "newton " + newton,
      granary::test::materials(1, 5.e6, 0.45, 0.9, 0.5),
      "fix m5 all property/global coefficientRollingFriction peratomtypepair 1 0.1",
      "pair_style gran model hertz tangential history rolling_friction cdt",
      "pair_coeff * *",
      "timestep 0.00001",
      "fix gravi all gravity 9.81 vector 0.0 0.0 -1.0",
      "fix xw1 all wall/gran model hertz tangential history rolling_friction cdt primitive type 1 xplane "
      "-0.008",
      "fix xw2 all wall/gran model hertz tangential history rolling_friction cdt primitive type 1 xplane "
      "0.008",
      "fix yw1 all wall/gran model hertz tangential history rolling_friction cdt primitive type 1 yplane "
      "-0.008",
      "fix yw2 all wall/gran model hertz tangential history rolling_friction cdt primitive type 1 yplane "
      "0.008",
      "fix floor all wall/gran model hertz tangential history rolling_friction cdt primitive type 1 zplane "
      "0.0",
      "fix integr all nve/sphere",
  };
}

// The whole scene from scratch (box, particles, physics).
inline std::vector<std::string> fresh(const std::string& newton = "off") {
  std::vector<std::string> s = {
      "atom_style granular", "atom_modify map array",
      "boundary m m m",      "units si",
      "processors * * 1",    "region domain block -0.008 0.008 -0.008 0.008 0.0 0.03 units box",
      "create_box 1 domain",
  };
  for (const auto& l : physics(newton))
    s.push_back(l);
  for (const auto& l : std::vector<std::string>{
           "lattice bcc 0.0025",
           "region fill block -0.0068 0.0068 -0.0068 0.0068 0.0021 0.0251 units box",
           "create_atoms 1 region fill",
           "set group all diameter 0.002 density 2500",
           "velocity all set 0.3 -0.2 -0.5 units box",
       }) {
    s.push_back(l);
  }
  return s;
}

// What a restart script says: read the file, then define the physics again.
inline std::vector<std::string> restarted(const std::string& file, const std::string& newton = "off") {
  std::vector<std::string> s = {"atom_style granular", "atom_modify map array", "read_restart " + file};
  for (const auto& l : physics(newton))
    s.push_back(l);
  return s;
}

}  // namespace restart_scene
