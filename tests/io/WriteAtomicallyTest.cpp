// writeAtomically: a finished file renamed into place, a failed one leaving
// nothing; a device or FIFO written directly, never replaced by the file.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "support/ReadableFifo.h"
#include "support/TestSupport.h"
#include "tessera/core/Error.h"
#include "tessera/io/VolumeWriter.h"

namespace tessera {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::string readAll(const fs::path& from) {
  std::ifstream in(from, std::ios::binary);
  std::string text;
  char buffer[4096];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) text.append(buffer, in.gcount());
  return text;
}

std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

void writeText(const fs::path& to, const std::string& text) {
  std::ofstream out(to, std::ios::binary);
  out << text;
  if (!out) throw Error(to.string() + ": cannot write");
}

TEST(WriteAtomically, RenamesAFinishedFileIntoPlaceAndLeavesNothingOnFailure) {
  TempDir dir;
  const fs::path path = dir.file("volume.nii");
  writeAtomically(path, [&](const fs::path& temp) {
    EXPECT_EQ(temp.parent_path(), path.parent_path());
    EXPECT_NE(temp.filename(), "volume.nii");
    writeText(temp, "first");
  });
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"volume.nii"});
  // A failure keeps the previous file and names the final path.
  try {
    writeAtomically(path, [](const fs::path& temp) {
      writeText(temp, "half");
      throw InputError(temp.string() + ": out of voxels");
    });
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"volume.nii"});
  EXPECT_EQ(readAll(path), "first");
}

// A FIFO gets the bytes and stays a FIFO; /dev/null stays the device (a
// rename over it, as root, replaced it with the file).
TEST(WriteAtomically, WritesAFifoOrDeviceDirectlyWithoutReplacingIt) {
  TempDir dir;
  test::ReadableFifo out(dir.file("volume.nii"));
  const fs::path& fifo = out.path();
  writeAtomically(fifo, [&](const fs::path& to) {
    EXPECT_EQ(to, fifo);
    writeText(to, "the voxels");
  });
  const std::string received = out.drain();
  EXPECT_EQ(received, "the voxels");
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"volume.nii"});
  // (/dev/null tried only once the FIFO was kept, so that a regression
  // cannot replace it.)
  if (fs::is_fifo(fifo) && fs::is_character_file("/dev/null")) {
    writeAtomically("/dev/null", [](const fs::path& to) { writeText(to, "discarded"); });
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
  }
}

}  // namespace
}  // namespace tessera
