#include "core/error.h"

#include <algorithm>

namespace granary {

// Optimal string alignment distance: insertions, deletions, substitutions and
// swaps of two neighbouring letters each count as one edit.
int edit_distance(const std::string& a, const std::string& b) {
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::vector<int>> d(n + 1, std::vector<int>(m + 1, 0));
  for (std::size_t i = 0; i <= n; ++i)
    d[i][0] = static_cast<int>(i);
  for (std::size_t j = 0; j <= m; ++j)
    d[0][j] = static_cast<int>(j);
  for (std::size_t i = 1; i <= n; ++i) {
    for (std::size_t j = 1; j <= m; ++j) {
      const int cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[n][m];
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
  // Accept a suggestion when at most a third of the word differs: one edit for
  // words of up to five letters, two from six letters on.
  const int limit = std::max<int>(name.size() <= 5 ? 1 : 2, static_cast<int>(name.size()) / 3);
  if (best.empty() || best_d > limit) return "";
  return "did you mean '" + best + "'?";
}

}  // namespace granary
