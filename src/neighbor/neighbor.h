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
  /// True when the list must be rebuilt this step (collective). With `carry`,
  /// this rank's *carry (>= 0) travels with the decision's reduction over the
  /// ranks and holds the largest value of any rank on return, or -1 when the
  /// decision made no reduction: the step alone decides (a forced or sorting
  /// rebuild, `delay`, `every`, `check no`).
  bool decide(int* carry = nullptr);
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
  /// The largest squared distance of the n points x from x0 (a NaN counts as 0).
  static double max_displacement2(const Vec3* x, const Vec3* x0, int n);
  /// Whether a[i] == b[i] for all n values (in blocks, as moved_beyond).
  static bool same_values(const double* a, const double* b, int n);

  /// A displacement watch for a list kept between builds (the granular pair
  /// style's near list). Once set (limit2 > 0) and from the next build on,
  /// decide() finds in its own pass over the owned particles, and in its one
  /// reduction, whether any particle on any rank moved by more than
  /// sqrt(limit2) since the watch's reference positions were taken; if so
  /// every rank takes them anew and watch_epoch() changes, as it does at
  /// every build. Its largest displacement also bounds the one since the
  /// build, which then needs no pass of its own while the bound is below
  /// half the skin. watch_checked(): decide() did this in the current step
  /// (not with neigh_modify delay/every/check settings that skip it); a
  /// client then keeps its list while the epoch is the one it was made in.
  void watch(double limit2) { watch_limit2_ = limit2; }
  std::int64_t watch_epoch() const { return watch_epoch_; }
  bool watch_checked() const { return watch_checked_; }
  /// Whether the last build left out the neighbouring bins beyond each
  /// particle's reach (done where the build before found the bins crowded).
  bool pruned_bins() const { return pruned_bins_; }
  /// Called after a step's forces: until the next decide(), nothing vouches
  /// for the positions (forces computed outside a step check for themselves).
  void watch_step_done() { watch_checked_ = false; }
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
  double watch_limit2_ = 0.0;
  bool watch_ready_ = false;    // reference positions taken at the last build
  bool watch_checked_ = false;  // decide() checked the watch in this step
  std::int64_t watch_epoch_ = 0;
  std::vector<Vec3> watch_x_;  // owned particles' positions when the epoch began
  double watch_hold_ = 0.0;    // largest |watch_x_ - xhold_| (0 after a build)
  // bins: the particles of bin b are binpart_[binstart_[b] .. binstart_[b+1])
  // in ascending index order, with their coordinates and radii in the same
  // order (binx_[0], binx_[1], binx_[2], binr_) so that scanning a bin reads
  // contiguous memory, a lane's worth of candidates per load; each array has
  // lanes - 1 entries of padding after the last particle, read by a scan's
  // last group and masked out;
  // with clumps also a key per particle that is equal for sub-spheres of one
  // body and unique otherwise (binkey_), so that pairs within a body are
  // left out as they are found
  std::vector<int> binstart_, binpart_, bin_of_, bincursor_;
  // Whether the next build leaves out neighbouring bins beyond a particle's
  // reach: set when the last build's occupied bins held more than
  // kCrowdedBin particles each (the lists are the same either way).
  bool prune_bins_ = false, pruned_bins_ = false;
  static constexpr double kCrowdedBin = 4.0;
  std::vector<double> binx_[3];
  std::vector<double> binr_;
  std::vector<std::int64_t> binkey_;  // (tagint)
};

}  // namespace granary
