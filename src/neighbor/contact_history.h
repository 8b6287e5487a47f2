// Contact history (e.g. the tangential spring) of particle pairs.
//
// During a run the values live in an array aligned with the neighbour list, so
// the pair loop reads them by position. Before a rebuild they are saved into a
// store keyed by the pair of global ids; entries travel with migrating
// particles; after the rebuild they are put back at the new list positions.
// The store key is (smaller id, larger id) and values are stored as seen from
// the smaller id; a pair met in the other order gets the swap signs applied.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "particles/particles.h"

namespace granary {

class Neighbor;

class ContactHistory {
 public:
  /// nvalues per contact and their signs under i<->j swap.
  void configure(int nvalues, const std::vector<double>& swap_signs);
  int nvalues() const { return nvalues_; }

  /// Values of list entry p (nvalues doubles), and the "in contact" flag.
  double* at(std::size_t p) { return &values_[p * nvalues_]; }
  std::vector<double> values_;
  std::vector<std::uint8_t> touch_;

  /// Save touched entries of the current list into the keyed store.
  void save(const Neighbor& list, const Particles& particles);
  /// Size the aligned arrays to the new list and fill them from the store.
  void restore(const Neighbor& list, const Particles& particles);

  // migration of store entries with particle `tag`
  void pack_particle(tagint tag, std::vector<double>& buf) const;
  int unpack_particle(const double* buf);
  /// Drop every entry of a particle that was deleted or lost.
  void forget_particle(tagint tag);
  /// Between runs, after particles were deleted: keep only entries whose two
  /// ids are in `sorted_ids` (ascending); with renumber, id sorted_ids[k]
  /// becomes k + 1 (delete_atoms ... compress yes).
  void retain(const std::vector<long long>& sorted_ids, bool renumber);

  // restart: every stored entry
  void pack_all(std::vector<double>& buf) const;
  void unpack_all(const std::vector<double>& buf);
  std::size_t stored() const { return store_.size(); }

 private:
  static std::uint64_t key(tagint a, tagint b) {
    return (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint64_t>(b);
  }
  int nvalues_ = 0;
  std::vector<double> swap_signs_;
  std::unordered_map<std::uint64_t, std::vector<double>> store_;
  // index from particle id to the keys it takes part in (built by save)
  std::unordered_multimap<tagint, std::uint64_t> by_particle_;
};

}  // namespace granary
