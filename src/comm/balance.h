// Load balancing by moving the cut planes of the processor grid (LAMMPS'
// `balance ... shift` style), used by the `balance` command and `fix balance`.
//
// The grid keeps its topology (Px x Py x Pz ranks, same neighbours); only the
// fractions Comm::split[d] move. The load of a rank is the number of
// particles in its subdomain, and the imbalance factor is the largest load
// over the average load. For each dimension of the requested sequence, every
// interior cut is bisected independently towards the position below which
// k/P of the particles lie (k = 1..P-1). Each trial set of cuts is evaluated
// by one allreduce of the particle count of every grid cell, so every rank
// sees the same counts and computes the same cuts. The best set seen is kept
// (never worse than the cuts before), and trial cuts are kept ordered and at
// least the ghost cutoff apart, which keeps the single-hop ghost exchange of
// Comm valid.
//
// With `weight time FACTOR` each particle counts with a weight instead of 1:
// the measured pair and neighbour time of its rank per owned particle,
// relative to the average over all ranks, blended with 1 by FACTOR. All
// particles of a rank share its weight, since the cost is only known per rank.
// With `weight neigh FACTOR` every particle has its own weight: its number of
// neighbour-list entries relative to the mean over all particles, blended with
// 1 by FACTOR (a particle in a dense bed costs more than one falling freely).
//
// The rcb style (with `comm_style tiled`) does not keep a grid: it cuts the
// box in two where the weighted particle count splits in proportion to the
// ranks on each side (floor(P/2) below the cut), along the dimension in which
// the particles of that part spread furthest, and cuts each part again until
// every rank has a box of its own (Comm::set_rcb). Each cut is found by
// bisection over the fraction of the box, all parts of one level together,
// one allreduce per step; rank 0's cuts are broadcast so that every rank
// holds the same tree. The same weights apply.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/utils.h"

namespace granary {

class Engine;

/// Arguments of the shift style: `shift DIMSTR NITER STOPTHRESH`.
struct ShiftSettings {
  std::string dims;         // e.g. "z" or "xz", each letter at most once
  int niter = 0;            // bisection iterations per dimension
  double stopthresh = 1.0;  // stop once the imbalance factor is at or below this
};

/// Outcome of one balancing attempt.
struct BalanceResult {
  double imbalance_before = 1.0, imbalance_after = 1.0;
  double max_before = 0.0, max_after = 0.0;  // largest load (particle count, or weighted) of a rank
  int iterations = 0;
  bool balanced = false;  // false when the imbalance did not exceed the threshold
};

/// Parse `DIMSTR NITER STOPTHRESH` at args[first..first+2]; `what` names the
/// command in messages.
ShiftSettings parse_shift(const Args& args, std::size_t first, const std::string& what);
/// Optional weighting of the shift style.
struct WeightSettings {
  enum Kind { kNone, kTime, kNeigh } kind = kNone;
  double factor = 0.0;  // in (0, 1]
};
/// Parse the optional keywords after the shift arguments (from args[first]):
/// `weight time FACTOR` or `weight neigh FACTOR`.
WeightSettings parse_weight(const Args& args, std::size_t first, const std::string& what);

class Balancer {
 public:
  explicit Balancer(Engine& engine);

  /// Weigh this rank's particles by measured cost: `seconds` of pair and
  /// neighbour time spent on this rank's `nlocal` particles, blended with 1
  /// by `factor` (0 < factor <= 1). Without time on any rank the weights stay 1.
  /// Collective.
  void set_time_weight(double factor, double seconds);
  /// Weigh each owned particle by its neighbour-list entries (both ends of
  /// every listed pair), relative to the mean over all particles of all
  /// ranks, blended with 1 by `factor`. Uses the current neighbour list; a
  /// particle the list does not cover (added since the build) counts 1.
  /// Collective.
  void set_neigh_weight(double factor);
  double weight() const { return weight_; }

  /// Load (weighted particle count) of every grid cell (rank) for the given cuts; collective.
  std::vector<double> cell_loads(const std::array<std::vector<double>, 3>& cuts) const;
  /// Imbalance factor (largest load over average; 1 without particles) and the largest load.
  static double imbalance(const std::vector<double>& loads, double* maxload = nullptr);

  /// Shift style: move the cuts of Comm::split so that particle counts even
  /// out, if the current imbalance exceeds `thresh`. Slabs stay at least
  /// `minwidth` wide. Collective; only changes Comm::split.
  BalanceResult shift(double thresh, const ShiftSettings& settings, double minwidth);

  /// Rcb style: recursive coordinate bisection of the weighted particles,
  /// if the current imbalance exceeds `thresh` (needs comm_style tiled).
  /// Collective; only changes the boxes of Comm (set_rcb).
  BalanceResult rcb(double thresh);

  /// Weighted particle count of every rank's current subdomain (its own particles). Collective.
  std::vector<double> rank_loads() const;

  /// Smallest width a subdomain may have: the ghost cutoff of the next run
  /// (twice the largest radius plus the skin, or comm_modify cutoff). Collective.
  double min_width() const;

  /// After the cuts changed: update the subdomain bounds and send particles
  /// (with their contact history) to their new owners. Collective.
  void migrate();

  /// LAMMPS-style summary printed by the `balance` command.
  std::string summary(const BalanceResult& r) const;

 private:
  Engine& engine_;
  double weight_ = 1.0;          // weight of each particle owned by this rank
  std::vector<double> weights_;  // per owned particle (weight neigh); empty: weight_
};

}  // namespace granary
