#include <gtest/gtest.h>

#include <cmath>

#include "tessera/core/Error.h"
#include "tessera/core/Histogram.h"
#include "tessera/core/TransferFunction.h"
#include "tessera/viewer/TransferFunctionEditor.h"

namespace tessera::viewer {
namespace {

const glm::dvec2 kRadius{0.03, 0.05};

TEST(TransferFunctionEditor, TapOnEmptySpaceAddsAnOpacityPointThatDragMoves) {
  TransferFunctionEditor ed;
  ed.loadPreset("grey");  // opacity points at 0 and 1
  const std::uint64_t r0 = ed.revision();
  ed.pointerDown(TfChannel::Opacity, {0.5, 0.4}, kRadius);
  ASSERT_EQ(ed.transferFunction().opacities.size(), 3u);
  EXPECT_EQ(ed.selection().index, 1);
  ed.pointerMove({0.6, 0.7});
  ed.pointerUp({0.6, 0.7});
  EXPECT_DOUBLE_EQ(ed.transferFunction().opacities[1].x, 0.6);
  EXPECT_DOUBLE_EQ(ed.transferFunction().opacities[1].alpha, 0.7);
  EXPECT_GT(ed.revision(), r0);
  EXPECT_DOUBLE_EQ(ed.transferFunction().opacity(0.6), 0.7);
}

TEST(TransferFunctionEditor, PressNearAPointSelectsItInsteadOfAdding) {
  TransferFunctionEditor ed;
  ed.loadPreset("grey");
  ed.pointerDown(TfChannel::Opacity, {0.99, 0.04}, kRadius);  // grey: (1, 0.05)
  EXPECT_EQ(ed.transferFunction().opacities.size(), 2u);
  EXPECT_EQ(ed.selection().index, 1);
}

TEST(TransferFunctionEditor, DraggedPointStaysBetweenItsNeighbours) {
  TransferFunctionEditor ed;
  ed.loadPreset("grey");
  const int i = ed.addOpacityPoint(0.5, 0.2);
  ed.moveOpacityPoint(i, 1.5, 2.0);
  EXPECT_DOUBLE_EQ(ed.transferFunction().opacities[static_cast<std::size_t>(i)].x, 1.0);
  EXPECT_DOUBLE_EQ(ed.transferFunction().opacities[static_cast<std::size_t>(i)].alpha, 1.0);
  EXPECT_EQ(i, 1);
}

TEST(TransferFunctionEditor, DraggingAnOpacityPointBelowTheAreaRemovesIt) {
  TransferFunctionEditor ed;
  ed.loadPreset("grey");
  ed.pointerDown(TfChannel::Opacity, {0.5, 0.4}, kRadius);
  ed.pointerMove({0.5, -0.5});
  ed.pointerUp({0.5, -0.5});
  EXPECT_EQ(ed.transferFunction().opacities.size(), 2u);
  EXPECT_EQ(ed.selection().index, -1);
}

TEST(TransferFunctionEditor, TheLastPointOfAChannelCannotBeRemoved) {
  TransferFunctionEditor ed;
  ed.loadPreset("grey");
  EXPECT_TRUE(ed.removePoint(TfChannel::Color, 0));
  EXPECT_FALSE(ed.removePoint(TfChannel::Color, 0));
  EXPECT_EQ(ed.transferFunction().colors.size(), 1u);
}

TEST(TransferFunctionEditor, NewColourPointTakesTheColourAtItsPosition) {
  TransferFunctionEditor ed;
  ed.loadPreset("grey");  // black at 0 to white at 1
  ed.pointerDown(TfChannel::Color, {0.25, 0.0}, kRadius);
  const auto& c = ed.transferFunction().colors;
  ASSERT_EQ(c.size(), 3u);
  EXPECT_NEAR(c[1].rgb.r, 0.25, 1e-12);
  ed.setSelectedColor({1.0, 0.0, 0.0});
  EXPECT_DOUBLE_EQ(ed.transferFunction().color(0.25).r, 1.0);
  EXPECT_DOUBLE_EQ(ed.transferFunction().color(0.25).g, 0.0);
}

TEST(TransferFunctionEditor, JsonIsTheCliFormat) {
  TransferFunctionEditor ed;
  ed.loadPreset("ct-bone");
  ed.addOpacityPoint(0.3, 0.25);
  const TransferFunction back = TransferFunction::fromJson(ed.json());
  EXPECT_EQ(back.toJson(), ed.transferFunction().toJson());
  EXPECT_THROW(ed.loadJson("{\"color\": 3}"), InputError);
  EXPECT_EQ(ed.transferFunction().toJson(), back.toJson());  // kept on error
}

TEST(TransferFunctionEditor, HistogramHeightsLinearAndLog) {
  Volume v = Volume::allocate({4, 1, 1}, ScalarType::U8);
  v.setValueAtIndex(0, 0);
  v.setValueAtIndex(1, 0);
  v.setValueAtIndex(2, 0);
  v.setValueAtIndex(3, 255);
  v.invalidateRange();
  TransferFunctionEditor ed;
  ed.setHistogram(Histogram::compute(v, 2));
  const auto lin = ed.histogramHeights(false), lg = ed.histogramHeights(true);
  ASSERT_EQ(lin.size(), 2u);
  EXPECT_DOUBLE_EQ(lin[0], 1.0);
  EXPECT_NEAR(lin[1], 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(lg[1], std::log1p(1.0) / std::log1p(3.0), 1e-12);
}

}  // namespace
}  // namespace tessera::viewer
