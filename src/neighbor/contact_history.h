// Contact history (e.g. the tangential spring) of particle pairs.
//
// During a run every neighbour-list entry has a slot number (4 bytes): none
// while its two particles do not touch, else the place of its values in a
// compact pool that holds the contacts only (a few percent of the entries in a
// dense bed). The pair loop takes a slot when a pair begins to touch and
// returns it when the contact ends. Before a rebuild the values are saved into a
// store with one row per particle, listing the contacts it takes part in as
// (partner id, values seen from this particle); rows travel with migrating
// particles, and after the rebuild each list entry finds its values in the row
// of its first particle (a handful of partners to search). Values seen from the
// other particle get the swap signs applied. Saving and restoring are linear
// passes over the list; restoring looks up only the pairs of spheres that
// overlap (the granular pair loop clears the history of the others before
// reading it). On one rank without ghosts the list-aligned state is only set
// aside at a rebuild, and when no particle changed its index (no spatial sort,
// insertion or deletion since) each contact goes straight to its entry of the
// new list: the two lists' rows are walked side by side. The store is made
// from the set-aside state whenever it is needed.
#pragma once

#include <algorithm>
#include <cstddef>
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

  /// Slot number of a list entry without a contact.
  static constexpr std::int32_t kNone = -1;

  /// Number of list entries the slots are sized for.
  std::size_t entries() const { return slot_.size(); }
  /// Whether list entry k touched at the last evaluation (holds a contact).
  bool touched(std::size_t k) const { return slot_[k] != kNone; }
  /// The values of list entry k (nvalues doubles), or nullptr without a contact.
  const double* find(std::size_t k) const {
    return slot_[k] == kNone ? nullptr : &pool_[static_cast<std::size_t>(slot_[k]) * nvalues_];
  }
  /// The values of list entry k; a contact without one gets a slot of zeros.
  double* values(std::size_t k) {
    if (slot_[k] == kNone) take(k);
    return &pool_[static_cast<std::size_t>(slot_[k]) * nvalues_];
  }
  /// Number of list entries that hold a contact.
  std::size_t contacts() const { return pool_.size() / std::max(nvalues_, 1) - free_.size(); }
  /// Size the slots to a list of n entries, none holding a contact.
  void reset(std::size_t n);
  /// Give list entry k (without a contact) a slot of zeros.
  void take(std::size_t k) {
    std::int32_t s;
    if (!free_.empty()) {
      s = free_.back();
      free_.pop_back();
      std::fill_n(&pool_[static_cast<std::size_t>(s) * nvalues_], nvalues_, 0.0);
    } else {
      s = static_cast<std::int32_t>(pool_.size() / nvalues_);
      pool_.resize(pool_.size() + nvalues_, 0.0);
      entry_.push_back(-1);
    }
    slot_[k] = s;
    entry_[s] = static_cast<std::int32_t>(k);
  }
  /// The contact of list entry k ended: its slot is returned.
  void forget(std::size_t k) {
    free_.push_back(slot_[k]);
    entry_[slot_[k]] = -1;
    slot_[k] = kNone;
  }
  /// For the pair loop: the slots (one per entry) and the pool's first value
  /// (valid until the next take()).
  std::int32_t* slots() { return slot_.data(); }
  double* pool() { return pool_.data(); }

  /// At run setup the forces are computed once without advancing the history:
  /// hold() sets the contacts (list entries and values) aside, put_back()
  /// makes them current again.
  void hold();
  void put_back();

  /// Save touched entries of the current list into the keyed store. With
  /// `in_place` (one rank, so that no particle migrates) and no ghosts, the
  /// list-aligned state is only set aside: if the particles keep their
  /// indices until restore() (no sort, insertion or deletion in between), each
  /// contact is handed to its entry of the new list directly, row against row;
  /// otherwise, and whenever the store is read before, the store is made from
  /// it as without `in_place`.
  void save(const Neighbor& list, const Particles& particles, bool in_place = false);
  /// Whether save() may set the state aside in place (tests compare both ways).
  bool in_place_allowed = true;
  /// restore() calls that handed the contacts over in place.
  std::int64_t hand_overs() const { return hand_overs_; }
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
  std::size_t stored() const {
    make_store();
    return partner_.size();
  }

 private:
  struct Row {
    tagint tag;
    int start, count;  // entries [start, start + count) of partner_ / vals_
  };
  /// Append a row (entries copied) and index it by its particle id.
  void add_row(tagint tag, int count, const tagint* partners, const double* vals) const;
  const Row* find_row(tagint tag) const;
  void clear_store() const;
  /// The keyed store from a list's touched entries: nlocal owned particles
  /// (ids id[0 .. ), ghosts after them), entries offset[i] .. offset[i+1] with
  /// partners neigh[k], slots slot[k] (nslot of them) into pool, and per
  /// slot of the pool its entry (entry_ of that state: -1 when free).
  void build_store(int nlocal, const int* offset, const int* neigh, const tagint* id,
                   const std::int32_t* slot, std::size_t nslot, const double* pool,
                   const std::vector<std::int32_t>& entry) const;
  /// An in-place save made into the keyed store (nothing when there is none).
  void make_store() const;
  /// restore() when the particles kept their indices since an in-place save.
  void hand_over(const Neighbor& list, const Particles& particles);

  int nvalues_ = 0;
  std::vector<std::int32_t> slot_;       // per list entry: kNone or the slot of its values in pool_
  std::vector<double> pool_;             // nvalues_ per slot
  std::vector<std::int32_t> entry_;      // per slot: the list entry holding it, or -1 when free
  std::vector<std::int32_t> free_;       // slots of ended contacts, taken again first
  std::vector<std::size_t> held_entry_;  // hold() .. put_back(): the contacts' list entries, in list order
  std::vector<double> held_values_;      // and their values
  std::vector<double> swap_signs_;
  // the keyed store; made on demand from an in-place save, hence mutable
  mutable std::vector<Row> rows_;
  mutable std::vector<tagint> partner_;
  mutable std::vector<double> vals_;  // nvalues_ per entry
  mutable std::unordered_map<tagint, int> row_of_;
  // an in-place save: the list, the owned particles' ids, the slots and the pool
  mutable bool in_place_ = false;
  mutable std::vector<int> saved_offset_, saved_neigh_;
  mutable std::vector<tagint> saved_id_;
  mutable std::vector<std::int32_t> saved_slot_;
  mutable std::vector<double> saved_pool_;
  mutable std::vector<std::int32_t> saved_entry_;
  std::int64_t hand_overs_ = 0;
};

}  // namespace granary
