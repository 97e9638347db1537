// A DICOM file with sequences nested thousands of levels deep, as a user
// meets it: `tessera info`, `render` and `convert` refuse it in one line
// naming it (they used to die of a stack overflow inside DCMTK), and a
// folder holding it beside a valid series still gives that series.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/CliRunner.h"
#include "support/NestedDicom.h"
#include "support/TestSupport.h"
#include "tessera/io/VolumeReader.h"

namespace fs = std::filesystem;
using tessera::test::runCli;

namespace {

void writeBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::string refusalLine(const fs::path& file) {
  return "tessera: error: " + file.string() + ": sequences nested deeper than 64 levels; refused\n";
}

}  // namespace

TEST(DicomNestingCommand, InfoRenderAndConvertRefuseTheFileInOneLine) {
  const tessera::test::TempDir tmp;
  for (const int depth : {1000, 6000, 100000}) {
    const fs::path deep = tmp / ("deep-" + std::to_string(depth));
    fs::create_directory(deep);
    const fs::path file = deep / "deep.dcm";
    writeBytes(file, tessera::test::nestedDicomFile({.depth = depth}));
    for (const std::string& command :
         {"info " + file.string(), "render " + file.string() + " --out " + (tmp / "x.png").string(),
          "convert " + file.string() + " " + (tmp / "x.nii").string() + " --quiet"}) {
      const auto r = runCli(command);
      // Exit 1 is a refused input; a crash reads as -1 (killed by a signal).
      EXPECT_EQ(r.exitCode, 1) << command;
      EXPECT_EQ(r.err, refusalLine(file)) << command;
      EXPECT_LT(r.seconds, 10.0) << command;
    }
    EXPECT_FALSE(fs::exists(tmp / "x.png"));
    EXPECT_FALSE(fs::exists(tmp / "x.nii"));
  }
}

TEST(DicomNestingCommand, FolderWithAValidSeriesReadsTheSeriesAndNotesTheFile) {
  const tessera::test::TempDir tmp;
  const fs::path folder = tmp / "study";
  ASSERT_EQ(runCli("convert gen:sphere:24 " + folder.string() + "/ --quiet").exitCode, 0);
  const auto alone = runCli("info " + folder.string() + " --json");
  ASSERT_EQ(alone.exitCode, 0) << alone.err;
  const fs::path file = folder / "deep.dcm";
  writeBytes(file, tessera::test::nestedDicomFile({.depth = 6000}));

  const auto info = runCli("info " + folder.string() + " --json");
  ASSERT_EQ(info.exitCode, 0) << info.err;
  const auto j = nlohmann::json::parse(info.out);
  const auto e = nlohmann::json::parse(alone.out);
  EXPECT_EQ(j["dims"], nlohmann::json::array({24, 24, 24}));
  EXPECT_EQ(j["value_min"], e["value_min"]);
  EXPECT_EQ(j["value_max"], e["value_max"]);
  const std::string note = "skipped 1 unreadable DICOM file(s) of other or unknown series, e.g. " +
                           file.string() + ": sequences nested deeper than 64 levels; refused";
  EXPECT_NE(j["description"].get<std::string>().find(note), std::string::npos) << j["description"];

  const auto render =
      runCli("render " + folder.string() + " --size 64x64 --out " + (tmp / "study.png").string());
  EXPECT_EQ(render.exitCode, 0) << render.err;
  EXPECT_TRUE(fs::exists(tmp / "study.png"));

  // The same voxels as without the file: the centre of the sphere and a corner.
  const tessera::Volume withFile = tessera::readVolume(folder.string());
  fs::remove(file);
  const tessera::Volume without = tessera::readVolume(folder.string());
  ASSERT_EQ(withFile.dims(), without.dims());
  EXPECT_EQ(withFile.valueAt(12, 12, 12), without.valueAt(12, 12, 12));
  EXPECT_EQ(withFile.valueAt(0, 0, 0), without.valueAt(0, 0, 0));
  EXPECT_GT(withFile.valueAt(12, 12, 12), withFile.valueAt(0, 0, 0));
}
