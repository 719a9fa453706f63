#include "core/spelling.h"

#include <algorithm>
#include <cstdlib>

namespace sylva {

int EditDistance(std::string_view a, std::string_view b, int limit) {
  const int la = int(a.size()), lb = int(b.size());
  if (std::abs(la - lb) > limit) return limit + 1;
  std::vector<int> prev(size_t(lb) + 1), cur(size_t(lb) + 1);
  for (int j = 0; j <= lb; ++j) prev[size_t(j)] = j;
  for (int i = 1; i <= la; ++i) {
    cur[0] = i;
    int rowMin = cur[0];
    for (int j = 1; j <= lb; ++j) {
      const int sub = prev[size_t(j - 1)] + (a[size_t(i - 1)] == b[size_t(j - 1)] ? 0 : 1);
      cur[size_t(j)] = std::min({prev[size_t(j)] + 1, cur[size_t(j - 1)] + 1, sub});
      rowMin = std::min(rowMin, cur[size_t(j)]);
    }
    if (rowMin > limit) return limit + 1;
    std::swap(prev, cur);
  }
  return std::min(prev[size_t(lb)], limit + 1);
}

std::string ClosestName(std::string_view name, const std::vector<std::string_view>& known,
                        int maxDistance) {
  std::string_view best;
  int bestDistance = maxDistance + 1;
  for (std::string_view k : known) {
    const int d = EditDistance(name, k, maxDistance);
    // A one-letter name is "close" to every other one-letter name: suggest
    // only names that share more than they change.
    if (d < bestDistance && d < int(std::max(name.size(), k.size()))) {
      bestDistance = d;
      best = k;
    }
  }
  return std::string(best);
}

std::string DidYouMean(std::string_view name, const std::vector<std::string_view>& known) {
  const std::string best = ClosestName(name, known);
  return best.empty() ? std::string() : " (did you mean '" + best + "'?)";
}

}  // namespace sylva
