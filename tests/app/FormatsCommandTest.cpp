// `tessera formats`: the table in docs/formats.md and the web page's file
// picker are the registry's (io/FormatRegistry.h), so neither drifts from
// what the readers read.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "support/CliRunner.h"
#include "tessera/io/FormatRegistry.h"

namespace fs = std::filesystem;
using tessera::test::runCli;

namespace {

// tests/data is two folders below the source root.
fs::path sourceRoot() {
  return fs::path(TESSERA_TEST_DATA_DIR).parent_path().parent_path();
}

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

// The text between the two marker comments of docs/formats.md.
std::string committedTable() {
  const std::string doc = readText(sourceRoot() / "docs" / "formats.md");
  const std::string begin = "<!-- begin: tessera formats --markdown -->\n";
  const std::string end = "<!-- end: tessera formats --markdown -->";
  const auto a = doc.find(begin);
  const auto b = doc.find(end);
  if (a == std::string::npos || b == std::string::npos || b < a) return "(markers missing)";
  return doc.substr(a + begin.size(), b - a - begin.size());
}

// The accept attribute of the page's "Open volume" picker (<input id="file">).
std::string pageAcceptList() {
  const std::string html = readText(sourceRoot() / "frontends" / "web" / "index.html");
  const auto input = html.find("id=\"file\"");
  if (input == std::string::npos) return "(no id=\"file\" input)";
  const auto a = html.find("accept=\"", input);
  if (a == std::string::npos) return "(no accept)";
  const auto b = html.find('"', a + 8);
  return html.substr(a + 8, b - a - 8);
}

}  // namespace

TEST(FormatsCommand, DocsTableIsTheCommandsOutput) {
  const auto r = runCli("formats --markdown");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out, tessera::formatsTable(true));
  EXPECT_EQ(committedTable(), r.out)
      << "docs/formats.md is out of date: replace its table with `tessera formats --markdown`";
  // One row per format, after the header and the separator.
  std::size_t lines = 0;
  for (char c : r.out) lines += c == '\n';
  EXPECT_EQ(lines, tessera::volumeFormats().size() + 2);
}

TEST(FormatsCommand, WebPickerAcceptsExactlyTheBrowserReadableFiles) {
  const auto r = runCli("formats --web-accept");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out, tessera::browserAcceptList() + "\n");
  EXPECT_EQ(pageAcceptList(), tessera::browserAcceptList())
      << "frontends/web/index.html's accept list differs: set it to `tessera formats --web-accept`";
}

TEST(FormatsCommand, TextTableNamesEveryFormatAndTheDicomDecoders) {
  const auto r = runCli("formats");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const tessera::VolumeFormat& f : tessera::volumeFormats()) {
    EXPECT_NE(r.out.find(f.name + "\n"), std::string::npos) << f.name;
  }
  EXPECT_NE(r.out.find("DCMTK"), std::string::npos);
  EXPECT_NE(r.out.find("basic"), std::string::npos);
  EXPECT_EQ(r.out.find('`'), std::string::npos) << "Markdown only with --markdown";
}

TEST(FormatsCommand, HelpListsTheRegistrysExtensions) {
  const auto convert = runCli("convert --help");
  ASSERT_EQ(convert.exitCode, 0);
  EXPECT_NE(convert.out.find(tessera::writeExtensionsText()), std::string::npos) << convert.out;
  const auto info = runCli("info --help");
  ASSERT_EQ(info.exitCode, 0);
  EXPECT_NE(info.out.find(".nii.gz"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find(".pvm"), std::string::npos) << info.out;
}
