// "Did you mean ...?": the closest known name to a misspelt one.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace sylva {

// Levenshtein distance (insert, delete, substitute; bytes), stopping early
// once it exceeds `limit` (then returns limit + 1).
int EditDistance(std::string_view a, std::string_view b, int limit = 1 << 20);

// The known name closest to `name` within `maxDistance` edits (ties: the
// first), or an empty string.
std::string ClosestName(std::string_view name, const std::vector<std::string_view>& known,
                        int maxDistance = 2);

// " (did you mean 'x'?)" for the closest name, or "" when none is close.
std::string DidYouMean(std::string_view name, const std::vector<std::string_view>& known);

}  // namespace sylva
