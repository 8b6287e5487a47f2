#include "neighbor/contact_history.h"

#include <functional>

#include <algorithm>
#include <map>

#include "core/growth.h"
#include "neighbor/neighbor.h"

namespace granary {

namespace {
/// Whether spheres i and j overlap now: the pair loop's test, whose history
/// survives a rebuild (the pair loop clears the others' before reading any).
inline bool overlapping(const Vec3* x, const double* radius, int i, int j) {
  const double rsum = radius[i] + radius[j];
  const double r2 = (x[i] - x[j]).squaredNorm();
  return (r2 < rsum * rsum) & (r2 != 0.0);
}
}  // namespace

void ContactHistory::configure(int nvalues, const std::vector<double>& swap_signs) {
  nvalues_ = nvalues;
  swap_signs_ = swap_signs;
  swap_signs_.resize(nvalues, -1.0);
}

void ContactHistory::reset(std::size_t n) {
  assign_fresh(slot_, n, kNone);
  pool_.clear();
  entry_.clear();
  free_.clear();
}

void ContactHistory::clear_store() const {
  rows_.clear();
  partner_.clear();
  vals_.clear();
  row_of_.clear();
  in_place_ = false;
}

void ContactHistory::add_row(tagint tag, int count, const tagint* partners, const double* vals) const {
  const int start = static_cast<int>(partner_.size());
  partner_.insert(partner_.end(), partners, partners + count);
  vals_.insert(vals_.end(), vals, vals + static_cast<std::size_t>(count) * nvalues_);
  row_of_[tag] = static_cast<int>(rows_.size());
  rows_.push_back({tag, start, count});
}

const ContactHistory::Row* ContactHistory::find_row(tagint tag) const {
  make_store();
  auto it = row_of_.find(tag);
  return it == row_of_.end() ? nullptr : &rows_[it->second];
}

void ContactHistory::save(const Neighbor& list, const Particles& p, bool in_place) {
  clear_store();
  if (nvalues_ == 0 || list.offset.empty()) return;
  if (in_place && in_place_allowed && p.size() == p.nlocal &&
      list.offset.size() == static_cast<std::size_t>(p.nlocal) + 1) {
    // set the list-aligned state aside (the pool as it is, free slots included)
    saved_offset_.assign(list.offset.begin(), list.offset.end());
    saved_neigh_.assign(list.neigh.begin(), list.neigh.end());
    saved_id_.assign(p.id.begin(), p.id.begin() + p.nlocal);
    saved_slot_.swap(slot_);
    saved_pool_.swap(pool_);
    saved_entry_.swap(entry_);
    slot_.clear();
    pool_.clear();
    entry_.clear();
    free_.clear();
    in_place_ = true;
    return;
  }
  const std::size_t nlist = std::min(slot_.size(), list.neigh.size());
  build_store(p.nlocal, list.offset.data(), list.neigh.data(), p.id.data(), slot_.data(), nlist, pool_.data(),
              entry_);
}

void ContactHistory::make_store() const {
  if (!in_place_) return;
  in_place_ = false;
  const int nlocal = static_cast<int>(saved_id_.size());
  const std::size_t nslot = std::min(saved_slot_.size(), saved_neigh_.size());
  build_store(nlocal, saved_offset_.data(), saved_neigh_.data(), saved_id_.data(), saved_slot_.data(), nslot,
              saved_pool_.data(), saved_entry_);
}

// Two passes over the touched entries in list order, found from the pool's
// slots (a few per particle, against a dozen list entries): count each owned
// particle's contacts (as first particle, and as second when that one is
// owned too), then write them; the same rows, in the same order, as two
// passes over the whole list.
void ContactHistory::build_store(int nlocal, const int* offset, const int* neigh, const tagint* id,
                                 const std::int32_t* slot, std::size_t nslot, const double* pool,
                                 const std::vector<std::int32_t>& entry) const {
  auto values_of = [&](int k) { return pool + static_cast<std::size_t>(slot[k]) * nvalues_; };
  std::vector<int> touched;
  touched.reserve(entry.size());
  for (const std::int32_t k : entry)
    if (k >= 0 && static_cast<std::size_t>(k) < nslot && slot[k] != kNone) touched.push_back(k);
  std::sort(touched.begin(), touched.end());
  std::vector<int> count(nlocal, 0);
  int i = 0;
  for (const int k : touched) {
    while (offset[i + 1] <= k)
      ++i;
    ++count[i];
    const int j = neigh[k];
    if (j < nlocal) ++count[j];
  }
  std::vector<int> start(nlocal + 1, 0);
  for (int q = 0; q < nlocal; ++q)
    start[q + 1] = start[q] + count[q];
  partner_.resize(start[nlocal]);
  vals_.resize(static_cast<std::size_t>(start[nlocal]) * nvalues_);
  rows_.reserve(nlocal);
  row_of_.reserve(nlocal);
  std::vector<int> fill(start.begin(), start.end() - 1);
  i = 0;
  for (const int k : touched) {
    while (offset[i + 1] <= k)
      ++i;
    const int j = neigh[k];
    const double* h = values_of(k);
    int e = fill[i]++;
    partner_[e] = id[j];
    std::copy_n(h, nvalues_, &vals_[static_cast<std::size_t>(e) * nvalues_]);
    if (j < nlocal) {
      e = fill[j]++;
      partner_[e] = id[i];
      double* out = &vals_[static_cast<std::size_t>(e) * nvalues_];
      for (int c = 0; c < nvalues_; ++c)
        out[c] = swap_signs_[c] * h[c];
    }
  }
  for (int q = 0; q < nlocal; ++q) {
    if (count[q] == 0) continue;
    row_of_[id[q]] = static_cast<int>(rows_.size());
    rows_.push_back({id[q], start[q], count[q]});
  }
}

// The particles kept their indices since an in-place save and there are no
// ghosts: a pair (i, j), i < j, is in i's row of both lists, and both rows
// are in (id, index) order, so one walk along the two rows pairs each entry
// of the new list with its entry of the old one. As restore() does, only
// pairs that overlap now get their values (the same values, given slots in
// the same list order).
void ContactHistory::hand_over(const Neighbor& list, const Particles& p) {
  reset(list.neigh.size());
  ++hand_overs_;
  const Vec3* const x = p.x.data();
  const double* const radius = p.radius.data();
  const tagint* const id = p.id.data();
  const int* const oneigh = saved_neigh_.data();
  const std::size_t nslot = std::min(saved_slot_.size(), saved_neigh_.size());
  for (int i = 0; i < p.nlocal; ++i) {
    int ko = saved_offset_[i];
    const int ke = saved_offset_[i + 1];
    for (int k = list.offset[i]; k < list.offset[i + 1]; ++k) {
      const int j = list.neigh[k];
      if (!overlapping(x, radius, i, j)) continue;
      const tagint idj = id[j];
      while (ko < ke && (id[oneigh[ko]] < idj || (id[oneigh[ko]] == idj && oneigh[ko] < j)))
        ++ko;
      if (ko == ke) break;
      if (oneigh[ko] != j || static_cast<std::size_t>(ko) >= nslot || saved_slot_[ko] == kNone) continue;
      std::copy_n(&saved_pool_[static_cast<std::size_t>(saved_slot_[ko]) * nvalues_], nvalues_, values(k));
    }
  }
}

// A contact is looked up in the row of the list's first particle, then (for
// contacts stored only with the other one, e.g. with newton on after a
// migration) in the second particle's row with the swap signs.
void ContactHistory::restore(const Neighbor& list, const Particles& p) {
  if (in_place_ && p.size() == p.nlocal && saved_id_.size() == static_cast<std::size_t>(p.nlocal) &&
      std::equal(saved_id_.begin(), saved_id_.end(), p.id.begin())) {
    hand_over(list, p);
    clear_store();  // (the set-aside state is spent)
    return;
  }
  make_store();
  reset(list.neigh.size());
  auto lookup = [&](const Row* row, tagint partner) -> const double* {
    if (!row) return nullptr;
    for (int e = 0; e < row->count; ++e)
      if (partner_[row->start + e] == partner)
        return &vals_[static_cast<std::size_t>(row->start + e) * nvalues_];
    return nullptr;
  };
  // Only spheres that overlap now can keep their history: the pair loop
  // clears the history of every listed pair that does not touch before it
  // reads any (the same test as there), so the others are not looked up.
  if (nvalues_ > 0 && !rows_.empty()) {
    const Vec3* const x = p.x.data();
    const double* const radius = p.radius.data();
    for (int i = 0; i < p.nlocal; ++i) {
      const tagint idi = p.id[i];
      const Row* row = find_row(idi);
      for (int k = list.offset[i]; k < list.offset[i + 1]; ++k) {
        const int j = list.neigh[k];
        if (!overlapping(x, radius, i, j)) continue;
        const tagint idj = p.id[j];
        if (const double* v = lookup(row, idj)) {
          std::copy_n(v, nvalues_, values(k));
        } else if (const double* w = lookup(find_row(idj), idi)) {
          double* out = values(k);
          for (int c = 0; c < nvalues_; ++c)
            out[c] = swap_signs_[c] * w[c];
        }
      }
    }
  }
  clear_store();
}

// Buffer: count, then per contact the partner id and the values seen from `tag`.
void ContactHistory::pack_particle(tagint tag, std::vector<double>& buf) const {
  const Row* row = find_row(tag);
  const int count = row ? row->count : 0;
  buf.push_back(count);
  for (int e = 0; e < count; ++e) {
    buf.push_back(static_cast<double>(partner_[row->start + e]));
    const double* v = &vals_[static_cast<std::size_t>(row->start + e) * nvalues_];
    buf.insert(buf.end(), v, v + nvalues_);
  }
}

int ContactHistory::unpack_particle(tagint tag, const double* buf) {
  make_store();
  const int count = static_cast<int>(buf[0]);
  int m = 1;
  if (count > 0) {
    std::vector<tagint> partners(count);
    std::vector<double> vals(static_cast<std::size_t>(count) * nvalues_);
    for (int e = 0; e < count; ++e) {
      partners[e] = static_cast<tagint>(buf[m++]);
      std::copy_n(buf + m, nvalues_, &vals[static_cast<std::size_t>(e) * nvalues_]);
      m += nvalues_;
    }
    add_row(tag, count, partners.data(), vals.data());
  }
  return m;
}

void ContactHistory::hold() {
  held_entry_.clear();
  held_values_.clear();
  held_entry_.reserve(contacts());
  held_values_.reserve(contacts() * nvalues_);
  for (std::size_t k = 0; k < slot_.size(); ++k)
    if (const double* v = find(k)) {
      held_entry_.push_back(k);
      held_values_.insert(held_values_.end(), v, v + nvalues_);
    }
}

void ContactHistory::put_back() {
  // the contacts of the set-aside state, in list order; the setup's own go
  reset(slot_.size());
  for (std::size_t h = 0; h < held_entry_.size(); ++h)
    if (held_entry_[h] < slot_.size())
      std::copy_n(&held_values_[h * nvalues_], nvalues_, values(held_entry_[h]));
  // free the set-aside copy (clear() would keep its memory for the whole run)
  std::vector<double>().swap(held_values_);
  std::vector<std::size_t>().swap(held_entry_);
}

void ContactHistory::forget_particle(tagint tag) {
  make_store();
  row_of_.erase(tag);
}

void ContactHistory::retain(const std::vector<long long>& sorted_ids, bool renumber) {
  make_store();
  auto index = [&](tagint id) -> long long {
    auto it = std::lower_bound(sorted_ids.begin(), sorted_ids.end(), static_cast<long long>(id));
    return (it != sorted_ids.end() && *it == id) ? it - sorted_ids.begin() : -1;
  };
  std::vector<Row> rows;
  rows.swap(rows_);
  std::vector<tagint> partners;
  partners.swap(partner_);
  std::vector<double> vals;
  vals.swap(vals_);
  std::unordered_map<tagint, int> live;
  live.swap(row_of_);
  std::vector<tagint> keep_p;
  std::vector<double> keep_v;
  for (const auto& kv : live) {
    const Row& row = rows[kv.second];
    const long long ti = index(row.tag);
    if (ti < 0) continue;
    keep_p.clear();
    keep_v.clear();
    for (int e = 0; e < row.count; ++e) {
      const long long ui = index(partners[row.start + e]);
      if (ui < 0) continue;
      keep_p.push_back(renumber ? ui + 1 : partners[row.start + e]);
      const double* v = &vals[static_cast<std::size_t>(row.start + e) * nvalues_];
      keep_v.insert(keep_v.end(), v, v + nvalues_);
    }
    if (!keep_p.empty()) {
      add_row(renumber ? ti + 1 : row.tag, static_cast<int>(keep_p.size()), keep_p.data(), keep_v.data());
    }
  }
}

// Restart layout: count, nvalues, then per contact (smaller id, larger id,
// values seen from the smaller id). A contact stored in both of its rows is
// written twice; the reader keeps one.
void ContactHistory::pack_all(std::vector<double>& buf) const {
  make_store();
  std::size_t count = 0;
  for (const auto& kv : row_of_)
    count += rows_[kv.second].count;
  buf.push_back(static_cast<double>(count));
  buf.push_back(nvalues_);
  for (const auto& kv : row_of_) {
    const Row& row = rows_[kv.second];
    for (int e = 0; e < row.count; ++e) {
      const tagint u = partner_[row.start + e];
      const double* v = &vals_[static_cast<std::size_t>(row.start + e) * nvalues_];
      const bool own = row.tag < u;
      buf.push_back(static_cast<double>(own ? row.tag : u));
      buf.push_back(static_cast<double>(own ? u : row.tag));
      for (int c = 0; c < nvalues_; ++c)
        buf.push_back(own ? v[c] : swap_signs_[c] * v[c]);
    }
  }
}

void ContactHistory::adopt(const ContactHistory& pending) {
  make_store();
  pending.make_store();
  std::vector<double> vals;
  for (const Row& row : pending.rows_) {
    vals.assign(pending.vals_.begin() + static_cast<std::ptrdiff_t>(row.start) * nvalues_,
                pending.vals_.begin() + static_cast<std::ptrdiff_t>(row.start + row.count) * nvalues_);
    for (int e = 0; e < row.count; ++e)
      if (row.tag > pending.partner_[row.start + e])
        for (int c = 0; c < nvalues_; ++c)
          vals[static_cast<std::size_t>(e) * nvalues_ + c] *= swap_signs_[c];
    add_row(row.tag, row.count, &pending.partner_[row.start], vals.data());
  }
}

void ContactHistory::unpack_all(const std::vector<double>& buf, const std::function<bool(tagint)>& keep) {
  make_store();
  if (buf.size() < 2) return;
  const auto count = static_cast<std::size_t>(buf[0]);
  const int nv = static_cast<int>(buf[1]);
  if (nv != nvalues_) return;
  // gather both directions of every contact by particle, then make rows
  std::map<tagint, std::vector<std::pair<tagint, std::size_t>>> by_tag;
  std::map<std::pair<tagint, tagint>, std::size_t> seen;
  std::size_t m = 2;
  for (std::size_t c = 0; c < count && m + 2 + nv <= buf.size(); ++c, m += 2 + nv) {
    const auto a = static_cast<tagint>(buf[m]), b = static_cast<tagint>(buf[m + 1]);
    const bool keep_a = !keep || keep(a), keep_b = !keep || keep(b);
    if (!keep_a && !keep_b) continue;
    if (!seen.emplace(std::make_pair(a, b), m).second) continue;
    if (keep_a) by_tag[a].push_back({b, m + 2});
    if (keep_b) by_tag[b].push_back({a, m + 2});
  }
  std::vector<tagint> partners;
  std::vector<double> vals;
  for (const auto& kv : by_tag) {
    partners.clear();
    vals.clear();
    for (const auto& entry : kv.second) {
      partners.push_back(entry.first);
      const double* v = &buf[entry.second];
      const bool smaller = kv.first < entry.first;  // stored as seen from the smaller id
      for (int c = 0; c < nv; ++c)
        vals.push_back(smaller ? v[c] : swap_signs_[c] * v[c]);
    }
    add_row(kv.first, static_cast<int>(partners.size()), partners.data(), vals.data());
  }
}

}  // namespace granary
