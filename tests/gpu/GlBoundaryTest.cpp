// GL lives in one place (STYLE.md, DESIGN.md): no source outside src/gpu
// (and the web platform's context file) calls GL or names a GL enum, and no
// public header can reach the GL headers. Comments and string literals are
// ignored (an extension name in a message is not a GL call).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const fs::path kRoot = fs::path(TESSERA_TEST_DATA_DIR).parent_path().parent_path();

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The code with comments and string/char literals blanked (lines kept).
std::string codeOnly(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  enum { Code, Line, Block, String, Char } state = Code;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const char next = i + 1 < text.size() ? text[i + 1] : '\0';
    switch (state) {
      case Code:
        if (c == '/' && next == '/')
          state = Line;
        else if (c == '/' && next == '*')
          state = Block;
        else if (c == '"')
          state = String;
        else if (c == '\'')
          state = Char;
        out += state == Code ? c : ' ';
        break;
      case Line:
        if (c == '\n') state = Code;
        out += c == '\n' ? '\n' : ' ';
        break;
      case Block:
        if (c == '*' && next == '/') {
          state = Code;
          ++i;
        }
        out += c == '\n' ? '\n' : ' ';
        break;
      case String:
      case Char:
        if (c == '\\') {
          ++i;
        } else if ((state == String && c == '"') || (state == Char && c == '\'')) {
          state = Code;
        }
        out += c == '\n' ? '\n' : ' ';
        break;
    }
  }
  return out;
}

std::vector<fs::path> sources(const std::vector<std::string>& folders) {
  std::vector<fs::path> files;
  for (const std::string& folder : folders) {
    for (const auto& e : fs::recursive_directory_iterator(kRoot / folder)) {
      const std::string ext = e.path().extension().string();
      if (e.is_regular_file() && (ext == ".cpp" || ext == ".h")) files.push_back(e.path());
    }
  }
  return files;
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
  for (const fs::path& p : sources({"src", "include", "frontends", "web/src"})) {
    if (allowed(p)) continue;
    ++checked;
    const std::string raw = readFile(p);
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
    EXPECT_FALSE(std::regex_search(readFile(p), header)) << p;
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
// web/) adopt the context a gpu class made (GlContext, GlfwWindow) and never
// create one themselves.
TEST(GlBoundary, OnlyTheGpuLayerCreatesContexts) {
  const std::regex create(
      R"(\b(glfwCreateWindow|eglCreateContext|emscripten_webgl_create_context)\s*\()");
  int checked = 0;
  std::vector<std::string> offenders;
  for (const fs::path& p : sources({"src", "include", "frontends", "web/src"})) {
    const std::string rel = fs::relative(p, kRoot).generic_string();
    if (rel.rfind("src/gpu/", 0) == 0) continue;
    ++checked;
    std::smatch m;
    const std::string code = codeOnly(readFile(p));
    if (std::regex_search(code, m, create)) offenders.push_back(rel + ": " + m.str());
  }
  EXPECT_GT(checked, 100);
  for (const auto& o : offenders) ADD_FAILURE() << o;
  // The check sees a call in code, not one in a comment.
  EXPECT_TRUE(std::regex_search(codeOnly("w = glfwCreateWindow(1, 1, t, 0, 0);\n"), create));
  EXPECT_FALSE(std::regex_search(codeOnly("// eglCreateContext(d, c, 0, a)\n"), create));
}
