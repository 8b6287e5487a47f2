#include "core/error.h"

#include <algorithm>

namespace granary {

int edit_distance(const std::string& a, const std::string& b) {
  std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = static_cast<int>(j);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = static_cast<int>(i);
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const int sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string did_you_mean(const std::string& name, const std::vector<std::string>& known) {
  std::string best;
  int best_d = 1 << 30;
  for (const auto& k : known) {
    const int d = edit_distance(name, k);
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  // Accept a suggestion when at most a third of the word differs (and at least one letter).
  const int limit = std::max<int>(1, static_cast<int>(name.size()) / 3);
  if (best.empty() || best_d > limit) return "";
  return "did you mean '" + best + "'?";
}

}  // namespace granary
