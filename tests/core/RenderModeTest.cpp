// The render modes' names exist once (renderModeNames): every mode has its
// own, and a name and its mode map to each other both ways.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "tessera/core/RenderSettings.h"

using namespace tessera;

namespace {

const RenderMode kEveryMode[] = {RenderMode::Composite, RenderMode::Mip, RenderMode::MinIp,
                                 RenderMode::Average};

}  // namespace

TEST(RenderMode, EveryModeRoundTripsThroughItsNameInTheList) {
  ASSERT_EQ(renderModeNames().size(), std::size(kEveryMode));
  for (const RenderMode mode : kEveryMode) {
    const std::string_view name = renderModeToName(mode);
    EXPECT_EQ(name, renderModeNames()[static_cast<std::size_t>(mode)]);
    ASSERT_TRUE(renderModeFromName(name).has_value()) << name;
    EXPECT_EQ(*renderModeFromName(name), mode) << name;
  }
}

TEST(RenderMode, EveryNameInTheListIsDistinctAndNamesItsMode) {
  std::set<std::string_view> seen;
  for (const std::string_view name : renderModeNames()) {
    EXPECT_TRUE(seen.insert(name).second) << name << " twice";
    ASSERT_TRUE(renderModeFromName(name).has_value()) << name;
    EXPECT_EQ(renderModeToName(*renderModeFromName(name)), name);
  }
  EXPECT_EQ(seen, (std::set<std::string_view>{"composite", "mip", "minip", "average"}));
}

TEST(RenderMode, WordsThatNameNoModeAreRejected) {
  for (const char* word : {"", "MIP", "max", "composite ", "minimum"}) {
    EXPECT_FALSE(renderModeFromName(word).has_value()) << "'" << word << "'";
  }
}

TEST(RenderMode, ChoicesListEveryNameInOrder) {
  EXPECT_EQ(renderModeChoices(), "composite, mip, minip or average");
}
