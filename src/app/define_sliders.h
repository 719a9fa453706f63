// The viewer's slider of each #define: its range is fixed by the value the
// grammar file gives (0 to twice it, twice it to 0 for a negative value,
// -1 to 1 for 0), never by a value the slider set, or dragging a slider to
// its end would move the end away with it. GL-free, so it is tested
// without a window.
#pragma once

#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace sylva::app {

using SliderRange = std::pair<float, float>;

// The range of a #define whose value in the file is `fileValue`.
SliderRange SliderRangeFor(double fileValue);

// After a plant is built: `constants` are its #defines (a value the viewer
// set for the names in `overridden`, else the file's). The range of a name
// the file sets is recomputed from its value (an edited file moves it);
// the range of a slider-set name is kept (or made from its value once,
// when it has none).
void UpdateSliderRanges(const std::vector<std::pair<std::string, double>>& constants,
                        const std::set<std::string>& overridden,
                        std::map<std::string, SliderRange>& ranges);

}  // namespace sylva::app
