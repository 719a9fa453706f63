// The viewer's #define sliders keep the range the file's value gives
// (app/define_sliders.h).
#include "app/define_sliders.h"

#include <gtest/gtest.h>

namespace sylva::app {
namespace {

TEST(DefineSliders, RangeComesFromTheFileValue) {
  EXPECT_EQ(SliderRangeFor(3), SliderRange(0.0f, 6.0f));
  EXPECT_EQ(SliderRangeFor(-2), SliderRange(-4.0f, 0.0f));
  EXPECT_EQ(SliderRangeFor(0), SliderRange(-1.0f, 1.0f));
}

TEST(DefineSliders, ASliderDraggedToItsEndKeepsItsRange) {
  std::map<std::string, SliderRange> ranges;
  UpdateSliderRanges({{"len", 3.0}, {"angle", 30.0}}, {}, ranges);
  ASSERT_EQ(ranges["len"], SliderRange(0.0f, 6.0f));
  // The slider set len to its end, 6, three times over: each build reports
  // len = 6 (a value the viewer set); the range stays 0..6 (it was 0..2x
  // the current value, recomputed after each change, and ran away).
  for (int i = 0; i < 3; ++i) {
    UpdateSliderRanges({{"len", 6.0}, {"angle", 30.0}}, {"len"}, ranges);
    EXPECT_EQ(ranges["len"].second, 6.0f) << "after " << i + 1 << " drags to the end";
  }
  EXPECT_EQ(ranges["angle"], SliderRange(0.0f, 60.0f));
  // "file values" drops the slider settings; an edited file moves the range.
  UpdateSliderRanges({{"len", 5.0}, {"angle", 30.0}}, {}, ranges);
  EXPECT_EQ(ranges["len"], SliderRange(0.0f, 10.0f));
  // A name first seen with a slider value (a -D on the command line) gets
  // a range from it once.
  UpdateSliderRanges({{"len", 5.0}, {"angle", 30.0}, {"new", 2.0}}, {"new"}, ranges);
  EXPECT_EQ(ranges["new"], SliderRange(0.0f, 4.0f));
}

}  // namespace
}  // namespace sylva::app
