// The render modes are named once (core's renderModeNames): `tessera render
// --help` offers that list, and the session's settings parse and name every
// mode in it the same way.
#include <gtest/gtest.h>

#include <string>

#include "support/CliRunner.h"
#include "tessera/core/Error.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/session/Settings.h"

using namespace tessera;

TEST(RenderModeOption, HelpOffersTheListOfModes) {
  const test::CliRun help = test::runCli("render --help");
  ASSERT_EQ(help.exitCode, 0) << help.err;
  EXPECT_NE(help.out.find("--mode"), std::string::npos);
  // CLI11 wraps nothing: the list appears as one run of text.
  EXPECT_NE(help.out.find(renderModeChoices() + ":"), std::string::npos) << help.out;
}

TEST(RenderModeOption, TheSessionParsesAndNamesEveryModeOfTheList) {
  for (const std::string_view name : renderModeNames()) {
    const RenderMode mode = session::parseRenderMode(std::string(name));
    EXPECT_EQ(mode, renderModeFromName(name)) << name;
    EXPECT_EQ(session::renderModeName(mode), name);
  }
  EXPECT_THROW(session::parseRenderMode("xray"), InputError);
}
