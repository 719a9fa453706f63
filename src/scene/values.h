// Attribute values of scene files (docs/scene.md, "Values"): decimal
// numbers, whole counts (`1e6` is fine, `1.5` is not), vectors "x y z",
// colours "#rrggbb" (sRGB) or "r g b" (linear 0..1), booleans, enumerations
// and id lists. Each parser returns the value or a message and the byte in
// the text where the problem is, so the reader can point at it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/math.h"

namespace sylva::scene {

struct ValueError {
  std::string message;
  size_t at = 0;  // byte in the value text
  int length = 1;
};

template <typename T>
struct Parsed {
  std::optional<T> value;
  ValueError error;
  bool ok() const { return value.has_value(); }
};

// A finite decimal number (no hex, inf or nan), the whole text.
Parsed<double> ParseNumber(std::string_view text);
// `n` numbers separated by white space.
Parsed<std::vector<double>> ParseNumbers(std::string_view text, size_t n);
// A whole number in [0, max], written as an integer or in exponent form.
Parsed<uint64_t> ParseCount(std::string_view text, uint64_t max);
Parsed<Vec3> ParseVec3(std::string_view text);
// "#rrggbb" (sRGB, converted to linear) or "r g b" (linear, each 0..1).
Parsed<Vec3> ParseColor(std::string_view text);
// "true" / "false".
Parsed<bool> ParseBool(std::string_view text);
// Space-separated names (ids), at least one.
Parsed<std::vector<std::string>> ParseNames(std::string_view text);

}  // namespace sylva::scene
