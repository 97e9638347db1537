// GL lives in one place (STYLE.md, DESIGN.md): no source outside src/gpu
// (and the web platform's context file) calls GL or names a GL enum, and no
// public header can reach the GL headers. Comments and string literals are
// ignored (an extension name in a message is not a GL call).
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "support/SourceScan.h"

namespace fs = std::filesystem;

namespace {

const fs::path& kRoot = tessera::test::repoRoot();
using tessera::test::readText;

// The code with comments and string/char literals blanked (lines kept).
std::string codeOnly(const std::string& text) {
  return tessera::test::blankComments(text, false);
}

std::vector<fs::path> sources(const std::vector<std::string>& folders) {
  return tessera::test::cppSources(folders);
}

bool allowed(const fs::path& p) {
  const std::string rel = fs::relative(p, kRoot).generic_string();
  // The gpu layer, which also creates every context (EGL's in
  // GlContext.cpp, the browser's WebGL one in GlContextWebGL.cpp).
  return rel.rfind("src/gpu/", 0) == 0;
}

}  // namespace

TEST(GlBoundary, NoRawGlOutsideTheGpuLayer) {
  const std::regex call(R"(\bgl[A-Z]\w*\s*\()");
  const std::regex name(R"(\bGL_[A-Z0-9_]+\b)");
  const std::regex header(R"(#\s*include\s*[<"](GLES\d?/|gpu/gl\.h))");
  int checked = 0;
  std::vector<std::string> offenders;
  for (const fs::path& p : sources({"src", "include", "frontends"})) {
    if (allowed(p)) continue;
    ++checked;
    const std::string raw = readText(p);
    const std::string code = codeOnly(raw);
    std::smatch m;
    if (std::regex_search(code, m, call) || std::regex_search(code, m, name) ||
        std::regex_search(raw, m, header)) {
      offenders.push_back(fs::relative(p, kRoot).string() + ": " + m.str());
    }
  }
  EXPECT_GT(checked, 100);
  for (const auto& o : offenders) ADD_FAILURE() << o;
}

TEST(GlBoundary, PublicHeadersNeverReachTheGlHeaders) {
  const std::regex header(R"(#\s*include\s*[<"](GLES\d?/|EGL/|gpu/gl\.h))");
  int checked = 0;
  for (const fs::path& p : sources({"include"})) {
    ++checked;
    EXPECT_FALSE(std::regex_search(readText(p), header)) << p;
  }
  EXPECT_GT(checked, 50);
}

TEST(GlBoundary, TheCheckSeesACallAndIgnoresCommentsAndStrings) {
  const std::regex call(R"(\bgl[A-Z]\w*\s*\()");
  EXPECT_TRUE(std::regex_search(codeOnly("  glFinish();\n"), call));
  EXPECT_FALSE(std::regex_search(codeOnly("// glFinish();\n"), call));
  EXPECT_FALSE(std::regex_search(codeOnly("x = \"glFinish()\";\n"), call));
  EXPECT_FALSE(std::regex_search(codeOnly("/* glFinish(); */ y();\n"), call));
}

// Contexts are made in one place too: the front ends (frontends/,
// frontends/web/) adopt the context a gpu class made (GlContext, GlfwWindow) and never
// create one themselves.
TEST(GlBoundary, OnlyTheGpuLayerCreatesContexts) {
  const std::regex create(
      R"(\b(glfwCreateWindow|eglCreateContext|emscripten_webgl_create_context)\s*\()");
  int checked = 0;
  std::vector<std::string> offenders;
  for (const fs::path& p : sources({"src", "include", "frontends"})) {
    const std::string rel = fs::relative(p, kRoot).generic_string();
    if (rel.rfind("src/gpu/", 0) == 0) continue;
    ++checked;
    std::smatch m;
    const std::string code = codeOnly(readText(p));
    if (std::regex_search(code, m, create)) offenders.push_back(rel + ": " + m.str());
  }
  EXPECT_GT(checked, 100);
  for (const auto& o : offenders) ADD_FAILURE() << o;
  // The check sees a call in code, not one in a comment.
  EXPECT_TRUE(std::regex_search(codeOnly("w = glfwCreateWindow(1, 1, t, 0, 0);\n"), create));
  EXPECT_FALSE(std::regex_search(codeOnly("// eglCreateContext(d, c, 0, a)\n"), create));
}
