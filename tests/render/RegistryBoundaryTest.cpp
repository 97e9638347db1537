// Registries without leaks (STYLE.md "Ask the entry, not the name"): what a
// caller needs to know of a layout or technique is a property of its registry
// entry or interface (LayoutEntry::streamsBricks, Layout::streaming(),
// Layout::referenceField(), TechniqueEntry::honoursSampling,
// Technique::samplingTwin() ...). So outside the file that defines a layout or
// technique, no source compares a registry name ("== \"bricks\"") and none
// casts to its concrete class (dynamic_cast<BricksLayout*>). The names and
// classes come from the registries and headers themselves, so a new layout or
// technique is covered without editing this test. Tests of one concrete
// class (its address maths) are not scanned.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "support/SourceScan.h"

#include "tessera/layout/LayoutRegistry.h"
#include "tessera/render/TechniqueRegistry.h"

namespace fs = std::filesystem;

namespace {

const fs::path& kRoot = tessera::test::repoRoot();
using tessera::test::readText;

// The code with comments blanked (string literals kept: they are what a
// name compare compares with).
std::string withoutComments(const std::string& text) {
  return tessera::test::blankComments(text, true);
}

// Production sources: the layers, the front ends and the examples.
std::vector<fs::path> productionSources() {
  return tessera::test::cppSources({"src", "include", "frontends", "examples"});
}

std::string inRepo(const fs::path& p) {
  return fs::relative(p, kRoot).string();
}

std::string escapeRegex(const std::string& s);

// The name as a quoted string literal, escaped for a regex.
std::string quotedPattern(const std::string& name) {
  std::string q = "\"";
  q += escapeRegex(name);
  q += '"';
  return q;
}

std::string escapeRegex(const std::string& s) {
  return std::regex_replace(s, std::regex(R"([.^$|()\[\]{}*+?\\-])"), R"(\$&)");
}

std::vector<std::string> registryNames() {
  std::vector<std::string> names = tessera::layout::LayoutRegistry::global().names();
  for (const std::string& n : tessera::render::TechniqueRegistry::global().names())
    names.push_back(n);
  return names;
}

// The files that define an entry of that name (where its registration or
// name() spells it): the only places allowed to compare it.
bool definesName(const std::string& code, const std::string& name) {
  const std::string quoted = quotedPattern(name);
  std::string assigned = R"(\.name\s*=\s*)";
  assigned += quoted;
  std::string returned = R"(return\s+)";
  returned += quoted;
  return std::regex_search(code, std::regex(assigned)) ||
         std::regex_search(code, std::regex(returned));
}

// Concrete layouts and techniques: classes deriving from Layout or Technique
// in the public headers.
std::set<std::string> concreteClasses() {
  std::set<std::string> classes;
  const std::regex derived(
      R"(class\s+(\w+)\s+(?:final\s+)?:\s*public\s+(?:\w+::)?(Layout|Technique)\b)");
  for (const char* dir : {"include/tessera/layout", "include/tessera/render"}) {
    for (const auto& e : fs::directory_iterator(kRoot / dir)) {
      const std::string text = readText(e.path());
      for (std::sregex_iterator m(text.begin(), text.end(), derived), end; m != end; ++m) {
        classes.insert((*m)[1]);
      }
    }
  }
  return classes;
}

TEST(RegistryBoundary, NoSourceComparesARegistryNameOutsideItsDefinition) {
  const std::vector<std::string> names = registryNames();
  ASSERT_GE(names.size(), 9u);  // 6 layouts, 3 techniques at least
  std::vector<std::string> leaks;
  for (const fs::path& file : productionSources()) {
    const std::string code = withoutComments(readText(file));
    for (const std::string& name : names) {
      const std::string quoted = quotedPattern(name);
      std::string pattern = "(==|!=)\\s*";
      pattern += quoted;
      pattern += "|";
      pattern += quoted;
      pattern += "\\s*(==|!=)|compare\\(\\s*";
      pattern += quoted;
      const std::regex compare(pattern);
      if (std::regex_search(code, compare) && !definesName(code, name)) {
        std::string leak = inRepo(file);
        leak += " compares ";
        leak += name;
        leaks.push_back(leak);
      }
    }
  }
  EXPECT_TRUE(leaks.empty()) << "ask the registry entry instead:\n"
                             << ::testing::PrintToString(leaks);
}

TEST(RegistryBoundary, NoSourceCastsToAConcreteLayoutOrTechniqueOutsideItsFiles) {
  const std::set<std::string> classes = concreteClasses();
  ASSERT_TRUE(classes.count("BricksLayout") && classes.count("Raycaster"))
      << "the class scan found " << ::testing::PrintToString(classes);
  const std::regex cast(R"(dynamic_cast\s*<\s*(?:const\s+)?(?:\w+::)*(\w+)\s*[*&])");
  std::vector<std::string> leaks;
  for (const fs::path& file : productionSources()) {
    const std::string code = withoutComments(readText(file));
    const std::string stem = file.stem().string();
    for (std::sregex_iterator m(code.begin(), code.end(), cast), end; m != end; ++m) {
      const std::string target = (*m)[1];
      if (classes.count(target) && stem != target) {
        std::string leak = inRepo(file);
        leak += " casts to ";
        leak += target;
        leaks.push_back(leak);
      }
    }
  }
  EXPECT_TRUE(leaks.empty()) << "use the interface (Layout::streaming(), "
                                "Layout::referenceField(), Technique::samplingTwin()):\n"
                             << ::testing::PrintToString(leaks);
}

// The scanner itself: a planted compare and cast are found.
TEST(RegistryBoundary, TheScanFindsAPlantedCompareAndCast) {
  const std::string code = withoutComments(
      "// if (name == \"bricks\") is a comment\n"
      "if (plan.layout == \"bricks\") {}\n"
      "auto* b = dynamic_cast<layout::BricksLayout*>(l);\n");
  EXPECT_TRUE(std::regex_search(code, std::regex("==\\s*\"bricks\"")));
  EXPECT_EQ(code.find("if (name"), std::string::npos);
  EXPECT_TRUE(std::regex_search(
      code, std::regex(R"(dynamic_cast\s*<\s*(?:const\s+)?(?:\w+::)*(BricksLayout)\s*[*&])")));
}

}  // namespace
