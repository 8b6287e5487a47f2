// fix ID group ave/euler nevery N cell_size_relative c parallel yes|no
//
// Cell-based (Eulerian) averages of the particles of the group on a regular
// grid, computed on the steps that are multiples of N and at the start of a
// run (LIGGGHTS 3.8 syntax and semantics, measured on its output):
//   - the cells: along each axis n = max(1, floor(L / (c * 2 * rmax))) equal
//     cells over L, the box (parallel no) or this rank's subdomain (parallel
//     yes: every rank its own grid), rmax the largest particle radius (the
//     largest pair cutoff is 2 rmax); a particle belongs to the cell that
//     holds its centre;
//   - v_avg: the mass-weighted (Favre) mean velocity of a cell's particles;
//   - volumefraction: the volume of the particles whose centres lie in the
//     cell over the cell's volume;
//   - radius: the arithmetic mean radius;
//   - pressure: -1/3 of the trace of the cell's stress, the per-particle
//     stress of compute stress/atom (pair part) plus the kinetic part
//     m (v - v_avg)(v - v_avg) with the cell's mean velocity, summed over the
//     cell and divided by its volume;
//   - empty cells: 0 for every value.
// dump euler/vtk writes the cells (one point per cell centre).
// See doc/fixes/ave_euler.md.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/utils.h"
#include "core/vec3.h"
#include "fix/fix.h"

namespace granary {

class Compute;

class FixAveEuler : public Fix {
 public:
  FixAveEuler(Engine& engine, const Args& args);

  unsigned hooks() const override { return END_OF_STEP; }
  void init() override;
  void setup() override;
  void end_of_step() override;
  void unfixed() override;

  /// The grid of this rank: the cells of the whole box (parallel no; the
  /// same on every rank) or of this rank's subdomain (parallel yes).
  struct Grid {
    Vec3 lo{0, 0, 0};
    std::array<double, 3> dx{{0, 0, 0}};
    std::array<int, 3> n{{0, 0, 0}};
    int cells() const { return n[0] * n[1] * n[2]; }
    /// Centre of cell k (x fastest, then y, then z).
    Vec3 centre(int k) const;
  };
  const Grid& grid() const { return grid_; }
  bool parallel() const { return parallel_; }
  /// The step of the last evaluation (-1: none yet).
  std::int64_t computed_step() const { return computed_step_; }
  // per cell of grid(): v_avg (3 per cell), volume fraction, mean radius, pressure
  std::vector<double> v_avg, volumefraction, radius, pressure;

 private:
  void evaluate();
  void make_grid();

  double cell_size_relative_ = 3.0;
  bool parallel_ = false;
  std::string stress_id_;
  Compute* stress_ = nullptr;
  Grid grid_;
  std::int64_t computed_step_ = -1;
};

}  // namespace granary
