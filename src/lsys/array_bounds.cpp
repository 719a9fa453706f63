// cpfg arrays read or written past their ends (see array_bounds.h).
#include "lsys/array_bounds.h"

#include <cstdio>
#include <unordered_set>

namespace sylva::lsys {

uint32_t ArrayBounds::AddSite(SourceLoc loc, std::string sourceLine, std::string array,
                              int dimension, uint32_t size) {
  Site& s = sites_.emplace_back();
  s.loc = std::move(loc);
  s.sourceLine = std::move(sourceLine);
  s.array = std::move(array);
  s.dimension = dimension;
  s.size = size;
  multiDimensional_ = multiDimensional_ || dimension > 1;
  return uint32_t(sites_.size());
}

void ArrayBounds::Note(uint32_t site, double index) {
  Site& s = sites_[site - 1];
  double lo = s.lowest.load(std::memory_order_relaxed);
  while (index < lo && !s.lowest.compare_exchange_weak(lo, index, std::memory_order_relaxed)) {
  }
  double hi = s.highest.load(std::memory_order_relaxed);
  while (index > hi && !s.highest.compare_exchange_weak(hi, index, std::memory_order_relaxed)) {
  }
}

std::vector<Diagnostic> ArrayBounds::Warnings() const {
  std::vector<Diagnostic> out;
  std::unordered_set<std::string> reported;
  for (const Site& s : sites_) {
    const double lo = s.lowest.load(), hi = s.highest.load();
    if (lo > hi || !reported.insert(s.array).second) continue;  // not out of bounds
    char what[160];
    if (lo == hi)
      std::snprintf(what, sizeof what, "index %.6g", lo);
    else
      std::snprintf(what, sizeof what, "indices from %.6g to %.6g", lo, hi);
    std::string used;
    if (lo < 0) used = "element 0";
    if (hi >= double(s.size))
      used += (used.empty() ? "element " : " or ") + std::to_string(s.size - 1);
    const std::string which = multiDimensional_ && s.dimension > 1
                                  ? " (its index " + std::to_string(s.dimension) + ")"
                                  : "";
    Diagnostic d =
        MakeError(s.loc,
                  std::string(what) + " of array '" + s.array + "'" + which + " is outside 0 to " +
                      std::to_string(s.size - 1) + ": Sylva uses " + used +
                      " instead, as cpfg does (cpfg says 'Subscript out of range')",
                  int(s.array.size()), s.sourceLine);
    d.severity = Severity::kWarning;
    out.push_back(std::move(d));
  }
  return out;
}

}  // namespace sylva::lsys
