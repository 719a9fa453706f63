// The viewer's #define sliders: see define_sliders.h.
#include "app/define_sliders.h"

namespace sylva::app {

SliderRange SliderRangeFor(double v) {
  if (v > 0) return {0.0f, float(2 * v)};
  if (v < 0) return {float(2 * v), 0.0f};
  return {-1.0f, 1.0f};
}

void UpdateSliderRanges(const std::vector<std::pair<std::string, double>>& constants,
                        const std::set<std::string>& overridden,
                        std::map<std::string, SliderRange>& ranges) {
  for (const auto& [name, value] : constants)
    if (!overridden.count(name) || !ranges.count(name)) ranges[name] = SliderRangeFor(value);
}

}  // namespace sylva::app
