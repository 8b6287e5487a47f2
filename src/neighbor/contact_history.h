// Contact history (e.g. the tangential spring) of particle pairs.
//
// During a run the values live in an array aligned with the neighbour list, so
// the pair loop reads them by position. Before a rebuild they are saved into a
// store with one row per particle, listing the contacts it takes part in as
// (partner id, values seen from this particle); rows travel with migrating
// particles, and after the rebuild each list entry finds its values in the row
// of its first particle (a handful of partners to search). Values seen from the
// other particle get the swap signs applied. Saving and restoring are linear
// passes over the list; restoring looks up only the pairs of spheres that
// overlap (the granular pair loop clears the history of the others before
// reading it).
#pragma once

#include <cstdint>
#include <functional>
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

  /// At run setup the forces are computed once without advancing the history:
  /// hold() sets the flags and the values of the touched entries aside,
  /// put_back() makes them current again. (An entry not touched holds zeros:
  /// the pair loop clears a contact's values when it ends, and restore()
  /// starts every entry at zero; so the touched ones are all there is to keep.)
  void hold();
  void put_back();

  /// Save touched entries of the current list into the keyed store.
  void save(const Neighbor& list, const Particles& particles);
  /// Size the aligned arrays to the new list and fill them from the store.
  void restore(const Neighbor& list, const Particles& particles);

  // migration of store entries with particle `tag`
  void pack_particle(tagint tag, std::vector<double>& buf) const;
  int unpack_particle(tagint tag, const double* buf);
  /// Drop every entry of a particle that was deleted or lost.
  void forget_particle(tagint tag);
  /// Between runs, after particles were deleted: keep only entries whose two
  /// ids are in `sorted_ids` (ascending); with renumber, id sorted_ids[k]
  /// becomes k + 1 (delete_atoms ... compress yes).
  void retain(const std::vector<long long>& sorted_ids, bool renumber);

  // restart: every stored entry
  void pack_all(std::vector<double>& buf) const;
  void unpack_all(const std::vector<double>& buf, const std::function<bool(tagint)>& keep = {});
  /// Take over the rows of `pending` (a store configured with unit swap
  /// signs, whose values are seen from the smaller id of each pair): a row's
  /// values seen from its larger id get this history's swap signs.
  void adopt(const ContactHistory& pending);
  /// Number of stored (row, partner) entries; a contact between two owned particles counts twice.
  std::size_t stored() const { return partner_.size(); }

 private:
  struct Row {
    tagint tag;
    int start, count;  // entries [start, start + count) of partner_ / vals_
  };
  /// Append a row (entries copied) and index it by its particle id.
  void add_row(tagint tag, int count, const tagint* partners, const double* vals);
  const Row* find_row(tagint tag) const;
  void clear_store();

  int nvalues_ = 0;
  std::vector<double> held_values_;  // hold() .. put_back(): the touched entries' values, in list order
  std::vector<std::uint8_t> held_touch_;
  std::vector<double> swap_signs_;
  std::vector<Row> rows_;
  std::vector<tagint> partner_;
  std::vector<double> vals_;  // nvalues_ per entry
  std::unordered_map<tagint, int> row_of_;
};

}  // namespace granary
