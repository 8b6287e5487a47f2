#include "neighbor/contact_history.h"

#include <algorithm>

#include "neighbor/neighbor.h"

namespace granary {

void ContactHistory::configure(int nvalues, const std::vector<double>& swap_signs) {
  nvalues_ = nvalues;
  swap_signs_ = swap_signs;
  swap_signs_.resize(nvalues, -1.0);
}

void ContactHistory::save(const Neighbor& list, const Particles& p) {
  store_.clear();
  by_particle_.clear();
  if (nvalues_ == 0 || list.offset.empty()) return;
  std::vector<double> vals(nvalues_);
  for (int i = 0; i < p.nlocal; ++i) {
    for (int k = list.offset[i]; k < list.offset[i + 1]; ++k) {
      if (static_cast<std::size_t>(k) >= touch_.size() || !touch_[k]) continue;
      const int j = list.neigh[k];
      tagint a = p.id[i], b = p.id[j];
      const double* h = &values_[static_cast<std::size_t>(k) * nvalues_];
      if (a < b) {
        vals.assign(h, h + nvalues_);
      } else {
        std::swap(a, b);
        for (int c = 0; c < nvalues_; ++c)
          vals[c] = swap_signs_[c] * h[c];
      }
      const auto kk = key(a, b);
      if (store_.emplace(kk, vals).second) {
        by_particle_.emplace(a, kk);
        by_particle_.emplace(b, kk);
      }
    }
  }
}

void ContactHistory::restore(const Neighbor& list, const Particles& p) {
  const std::size_t npairs = list.neigh.size();
  touch_.assign(npairs, 0);
  values_.assign(npairs * nvalues_, 0.0);
  if (nvalues_ == 0 || store_.empty()) {
    store_.clear();
    by_particle_.clear();
    return;
  }
  for (int i = 0; i < p.nlocal; ++i) {
    for (int k = list.offset[i]; k < list.offset[i + 1]; ++k) {
      const int j = list.neigh[k];
      const tagint a = p.id[i], b = p.id[j];
      const bool swapped = a > b;
      auto it = store_.find(swapped ? key(b, a) : key(a, b));
      if (it == store_.end()) continue;
      double* h = &values_[static_cast<std::size_t>(k) * nvalues_];
      for (int c = 0; c < nvalues_; ++c)
        h[c] = swapped ? swap_signs_[c] * it->second[c] : it->second[c];
      touch_[k] = 1;
    }
  }
  store_.clear();
  by_particle_.clear();
}

void ContactHistory::pack_particle(tagint tag, std::vector<double>& buf) const {
  const std::size_t count_at = buf.size();
  buf.push_back(0.0);
  int count = 0;
  auto range = by_particle_.equal_range(tag);
  for (auto it = range.first; it != range.second; ++it) {
    auto entry = store_.find(it->second);
    if (entry == store_.end()) continue;
    buf.push_back(static_cast<double>(entry->first >> 32));
    buf.push_back(static_cast<double>(entry->first & 0xffffffffu));
    buf.insert(buf.end(), entry->second.begin(), entry->second.end());
    ++count;
  }
  buf[count_at] = count;
}

int ContactHistory::unpack_particle(const double* buf) {
  const int count = static_cast<int>(buf[0]);
  int m = 1;
  for (int c = 0; c < count; ++c) {
    const auto a = static_cast<tagint>(buf[m]), b = static_cast<tagint>(buf[m + 1]);
    m += 2;
    const auto kk = key(a, b);
    if (store_.emplace(kk, std::vector<double>(buf + m, buf + m + nvalues_)).second) {
      by_particle_.emplace(a, kk);
      by_particle_.emplace(b, kk);
    }
    m += nvalues_;
  }
  return m;
}

void ContactHistory::forget_particle(tagint tag) {
  auto range = by_particle_.equal_range(tag);
  for (auto it = range.first; it != range.second; ++it)
    store_.erase(it->second);
}

void ContactHistory::retain(const std::vector<long long>& sorted_ids, bool renumber) {
  auto index = [&](tagint id) -> long long {
    auto it = std::lower_bound(sorted_ids.begin(), sorted_ids.end(), static_cast<long long>(id));
    return (it != sorted_ids.end() && *it == id) ? it - sorted_ids.begin() : -1;
  };
  std::unordered_map<std::uint64_t, std::vector<double>> kept;
  by_particle_.clear();
  for (auto& kv : store_) {
    tagint a = static_cast<tagint>(kv.first >> 32), b = static_cast<tagint>(kv.first & 0xffffffffu);
    const long long ia = index(a), ib = index(b);
    if (ia < 0 || ib < 0) continue;
    if (renumber) {
      a = ia + 1;  // order is kept, so (a, b) stays (smaller, larger)
      b = ib + 1;
    }
    const auto k = key(a, b);
    kept[k] = std::move(kv.second);
    by_particle_.emplace(a, k);
    by_particle_.emplace(b, k);
  }
  store_.swap(kept);
}

void ContactHistory::pack_all(std::vector<double>& buf) const {
  buf.push_back(static_cast<double>(store_.size()));
  buf.push_back(nvalues_);
  for (const auto& kv : store_) {
    buf.push_back(static_cast<double>(kv.first >> 32));
    buf.push_back(static_cast<double>(kv.first & 0xffffffffu));
    buf.insert(buf.end(), kv.second.begin(), kv.second.end());
  }
}

void ContactHistory::unpack_all(const std::vector<double>& buf) {
  if (buf.size() < 2) return;
  const auto count = static_cast<std::size_t>(buf[0]);
  const int nv = static_cast<int>(buf[1]);
  std::size_t m = 2;
  for (std::size_t c = 0; c < count && m + 2 + nv <= buf.size(); ++c) {
    const auto a = static_cast<tagint>(buf[m]), b = static_cast<tagint>(buf[m + 1]);
    m += 2;
    const auto kk = key(a, b);
    store_[kk] = std::vector<double>(buf.begin() + m, buf.begin() + m + nv);
    by_particle_.emplace(a, kk);
    by_particle_.emplace(b, kk);
    m += nv;
  }
}

}  // namespace granary
