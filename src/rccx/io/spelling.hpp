// The nearest known word to a misspelt one, for messages that say "did you mean ...?" (unknown
// keys of robot and cell files). Header-only, so that the header-only JSON reader can use it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace rccx::io {

/// Levenshtein distance (insert, delete, substitute one character), with a swap of two
/// neighbours counted as one edit (a common typo: "robts" / "rbots").
inline std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

/// The candidate nearest `word`, when it is near enough to be the word meant (at most a third
/// of the longer word's letters differ, at least one allowed); empty otherwise.
template <class Words>
std::string nearest_word(std::string_view word, const Words& candidates) {
  std::string best;
  std::size_t best_d = 0;
  for (const auto& c : candidates) {
    const std::string_view cv(c);
    const std::size_t d = edit_distance(word, cv);
    const std::size_t allowed = std::max<std::size_t>(1, std::max(word.size(), cv.size()) / 3);
    if (d > 0 && d <= allowed && (best.empty() || d < best_d)) {
      best = std::string(cv);
      best_d = d;
    }
  }
  return best;
}

}  // namespace rccx::io
