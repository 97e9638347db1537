#pragma once
// Reading the project's own sources for the boundary tests (GL only in the
// gpu layer, no registry names outside the registries): the repository root,
// its C++ files under some folders, and the code with comments (and, where
// asked, string and character literals) blanked, lines kept.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace tessera::test {

inline const std::filesystem::path& repoRoot() {
  static const std::filesystem::path root =
      std::filesystem::path(TESSERA_TEST_DATA_DIR).parent_path().parent_path();
  return root;
}

inline std::string readText(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The .cpp and .h files below each folder (relative to the root) that exists.
inline std::vector<std::filesystem::path> cppSources(const std::vector<std::string>& folders) {
  std::vector<std::filesystem::path> files;
  for (const std::string& folder : folders) {
    if (!std::filesystem::exists(repoRoot() / folder)) continue;
    for (auto it = std::filesystem::recursive_directory_iterator(repoRoot() / folder);
         it != std::filesystem::recursive_directory_iterator(); ++it) {
      const auto& e = *it;
      // The web front end's npm packages are not ours.
      if (e.is_directory() && e.path().filename() == "node_modules") {
        it.disable_recursion_pending();
        continue;
      }
      const std::string ext = e.path().extension().string();
      if (e.is_regular_file() && (ext == ".cpp" || ext == ".h")) files.push_back(e.path());
    }
  }
  return files;
}

// `text` with comments blanked, and string and character literals too unless
// `keepStrings` (a registry-name compare is a compare with a literal).
// Newlines stay, so that offsets keep their line numbers.
inline std::string blankComments(const std::string& text, bool keepStrings) {
  std::string out;
  out.reserve(text.size());
  enum { Code, Line, Block, String, Char } state = Code;
  const auto put = [&](char c, bool blank) { out += blank && c != '\n' ? ' ' : c; };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    const char next = i + 1 < text.size() ? text[i + 1] : '\0';
    switch (state) {
      case Code:
        if (c == '/' && (next == '/' || next == '*')) {
          state = next == '/' ? Line : Block;
        } else if (c == '"') {
          state = String;
        } else if (c == '\'') {
          state = Char;
        }
        put(c, state == Line || state == Block || (!keepStrings && state != Code));
        break;
      case Line:
        if (c == '\n') state = Code;
        put(c, true);
        break;
      case Block:
        put(c, true);
        if (c == '*' && next == '/') {
          put(next, true);
          ++i;
          state = Code;
        }
        break;
      case String:
      case Char: {
        const bool closes = (state == String && c == '"') || (state == Char && c == '\'');
        put(c, !keepStrings);
        if (c == '\\' && i + 1 < text.size()) {
          put(next, !keepStrings);
          ++i;
        } else if (closes) {
          state = Code;
        }
        break;
      }
    }
  }
  return out;
}

}  // namespace tessera::test
