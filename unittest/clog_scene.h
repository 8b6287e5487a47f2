// A small silo bottom for the clog-detect tests, without mesh walls: a floor
// of fixed spheres (type 2, not integrated) on a square lattice, periodic in x
// and y, with a hole of 3 x 3 floor spheres (an opening 6 mm wide between
// the floor spheres, 2.2 grain diameters) that is plugged while frictional grains (type 1) are poured
// and settle, then opened. Bodies that fall through reach region `out` below
// the floor; region `arch` covers the opening from below the floor to two
// grain layers above it.
#pragma once

#include <string>
#include <vector>

#include "script_engine.h"

namespace clog_scene {

constexpr double kGrainDiameter = 0.0027;  // [m]; floor spheres: 0.002 m
constexpr double kDensity = 2500.0;        // [kg/m^3]
constexpr double kTimestep = 5.0e-5;       // [s]

/// The box (x, y in [0, 0.02] m, z from -0.02 m to zhi), two atom types.
inline std::vector<std::string> box(double zhi, bool walled = false) {
  return {"units si",
          "atom_style granular",
          "atom_modify map array",
          walled ? "boundary f f f" : "boundary p p f",
          "newton off",
          "processors * * 1",
          "region box block 0 0.02 0 0.02 -0.02 " + std::to_string(zhi) + " units box",
          "create_box 2 box"};
}

/// Neighbour settings, materials of the two types, pair style and timestep.
inline std::vector<std::string> materials() {
  return {
      "neighbor 0.0005 bin",
      "neigh_modify delay 0",
      granary::test::materials(2, 1.e6, 0.45, 0.3, 0.6),
      "pair_style gran model hertz tangential history",
      "pair_coeff * *",
      "timestep 5e-5",
  };
}

/// Lines appended to a script, in order.
inline void append(std::vector<std::string>& s, const std::vector<std::string>& more) {
  s.insert(s.end(), more.begin(), more.end());
}

/// A box of height zhi with the materials, a dumbbell clump template `dumb`
/// (two touching 2 mm spheres of type 1), fix multisphere and gravity.
inline std::vector<std::string> dumbbell_box(double zhi) {
  std::vector<std::string> s = box(zhi);
  append(s, materials());
  append(s, {
                "fix dumb all particletemplate/multisphere 15485867 atom_type 1 density constant 2500 "
                "nspheres 2 ntry 200000 spheres -0.001 0 0 0.001 0.001 0 0 0.001 type 1",
                "fix ms all multisphere",
                "fix g all gravity 9.81 vector 0 0 -1",
            });
  return s;
}

/// Pair style, materials, integration: what a script defines again after read_restart.
/// `walled`: the box is closed by four primitive walls instead of being periodic
/// in x and y (periodic images are remapped at different steps in a run and in a
/// restarted one, which changes the last bits of distances; walls do not).
inline std::vector<std::string> physics(bool walled = false) {
  std::vector<std::string> s = {"communicate single vel yes"};
  append(s, materials());
  if (walled) {
    for (const std::string w : {"xplane 0.0", "xplane 0.02", "yplane 0.0", "yplane 0.02"})
      s.push_back("fix wall_" + std::string(1, w[0]) + (w.back() == '0' ? "lo" : "hi") +
                  " all wall/gran model hertz tangential history primitive type 2 " + w);
  }
  return s;
}

/// Regions used by the fix (not stored in restart files).
inline std::vector<std::string> regions() {
  return {
      "region out block 0 0.02 0 0.02 -0.02 -0.0015 units box",
      "region arch cylinder z 0.01 0.01 0.006 -0.0015 0.005 units box",
      "region bed block 0 0.02 0 0.02 0.0005 0.04 units box",
  };
}

/// The whole scene: box, floor, `ngrains` grains poured on the plugged floor
/// and settled (0.125 s), then the plug removed. Groups: floor, grains.
inline std::vector<std::string> filled(int ngrains, bool walled = false) {
  std::vector<std::string> s = box(0.04, walled);
  for (const auto& l : physics(walled))
    s.push_back(l);
  for (const auto& l : std::vector<std::string>{
           "lattice sc 0.002",
           "region floor block 0 0.02 0 0.02 -0.0001 0.0001 units box",
           "create_atoms 2 region floor",
           "region hole cylinder z 0.01 0.01 0.0035 -0.001 0.001 units box",
           "group plug region hole",
           walled ? "region fill block 0.0014 0.0186 0.0014 0.0186 0.003 0.035 units box"
                  : "region fill block 0 0.02 0 0.02 0.003 0.035 units box",
           "create_atoms 1 random " + std::to_string(ngrains) + " 4242 fill overlap 0.0028 maxtry 200",
           "set type 1 diameter 0.0027 density 2500",
           "set type 2 diameter 0.002 density 2500",
           "group grains type 1",
           "fix grav grains gravity 9.81 vector 0 0 -1",
           "fix integr grains nve/sphere",
           "run 2500",
           "delete_atoms group plug",
       })
    s.push_back(l);
  for (const auto& l : regions())
    s.push_back(l);
  return s;
}

/// After read_restart of a filled scene: physics, gravity, integration, regions.
inline std::vector<std::string> restarted(const std::string& file, bool walled = false) {
  std::vector<std::string> s = {"atom_style granular", "atom_modify map array", "read_restart " + file};
  for (const auto& l : physics(walled))
    s.push_back(l);
  s.push_back("fix grav grains gravity 9.81 vector 0 0 -1");
  s.push_back("fix integr grains nve/sphere");
  for (const auto& l : regions())
    s.push_back(l);
  return s;
}

}  // namespace clog_scene
