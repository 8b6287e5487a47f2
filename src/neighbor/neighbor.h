// Binned half neighbour lists with a skin, and the decision when to rebuild.
//
// List rules (see doc/architecture.md):
// - owned-owned pairs appear once;
// - owned-ghost pairs: with `newton off` every one appears (each rank computes
//   the force on its own particle; no reverse communication); with `newton on`
//   only those where the owned particle has the smaller id (the force on the
//   ghost is sent back by reverse communication).
// Pairs excluded by neigh_modify exclude, and sub-spheres of one clump, never appear.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/utils.h"
#include "core/vec3.h"

namespace granary {

class Engine;

class Neighbor {
 public:
  explicit Neighbor(Engine& engine);

  double skin = 0.001;  // [m], `neighbor SKIN bin`
  /// Pairs are listed while their distance is below range_factor (r_i + r_j)
  /// + skin: 1 for contact forces; a pair style whose forces reach beyond
  /// contact (liquid bridges: maxSeparationDistanceRatio) sets it at init.
  double range_factor = 1.0;
  /// The cutoff of the largest pair for particles up to radius rmax: 2 rmax range_factor + skin.
  double cutoff_for(double rmax_) const { return 2.0 * rmax_ * range_factor + skin; }
  int every = 1, delay = 0;
  bool check = true;
  bool once = false;
  int sort_every = 1000;  // atom_modify sort N binsize (0 = off)
  double sort_binsize = 0.0;

  void neighbor_command(const Args& args);
  void modify_command(const Args& args);

  /// Set cutoffs before a run from the largest particle radius (collective).
  void init();
  /// True when the list must be rebuilt this step (collective).
  bool decide();
  /// Set on every rank by a fix that adds particles during a run (insertion):
  /// the next decide() returns true and clears it, so that step reneighbours.
  bool force_rebuild = false;
  /// Build the half list from owned and ghost particles.
  void build();
  double cutneighmax = 0.0;  // largest pair cutoff plus skin: cutoff_for(rmax)
  double rmax = 0.0;

  // CSR half list: neighbours of owned particle i are
  // neigh[offset[i] .. offset[i+1]).
  std::vector<int> offset;
  std::vector<int> neigh;
  std::int64_t ago = 0;  // steps since the last build
  std::int64_t nbuilds = 0;
  std::int64_t last_build_step = -1;

  bool excluded(int i, int j) const;
  /// Whether any of the n points x moved from x0 by more than sqrt(limit2)
  /// (in blocks without an early exit, so that the compiler can vectorise them).
  static bool moved_beyond(const Vec3* x, const Vec3* x0, int n, double limit2);
  /// Reorder owned particles along bins for memory locality (atom_modify sort)
  /// at steps that are multiples of sort_every (decide() forces a rebuild
  /// there); called after migration, before ghosts are built.
  void sort_particles(std::int64_t step);

 private:
  Engine& engine_;
  std::vector<Vec3> xhold_;
  std::vector<std::pair<int, int>> exclude_types_;
  std::vector<std::pair<int, int>> exclude_groups_;
  bool exclude_body_ = true;  // sub-spheres of one clump never interact
  // bins: the particles of bin b are binpart_[binstart_[b] .. binstart_[b+1])
  // in ascending index order, with their positions and radii in the same
  // order (binx_, binr_) so that scanning a bin reads contiguous memory
  std::vector<int> binstart_, binpart_, bin_of_, bincursor_;
  std::vector<Vec3> binx_;
  std::vector<double> binr_;
};

}  // namespace granary
