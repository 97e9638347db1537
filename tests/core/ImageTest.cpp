#include "support/ReadableFifo.h"
#include "support/TestSupport.h"
#include "tessera/core/Image.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tessera/core/Error.h"

namespace tessera {
namespace {

using test::BudgetOverride;
using test::TempDir;

namespace fs = std::filesystem;

std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

// Every byte differs from its neighbours, alpha covers 0..255, and some
// pixels are fully transparent with non-zero colour (which a premultiplying
// writer would lose).
Image pattern(int w, int h, int seed) {
  Image img(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = img.pixel(x, y);
      p[0] = static_cast<std::uint8_t>(x * 7 + y * 13 + seed);
      p[1] = static_cast<std::uint8_t>(x * 31 + y * 3 + 2 * seed);
      p[2] = static_cast<std::uint8_t>(x * y + seed);
      p[3] = static_cast<std::uint8_t>((x + y) % 5 == 0 ? 0 : x * 11 + y * 17);
    }
  }
  return img;
}

TEST(Image, ConstructsZeroFilledRgba) {
  const Image img(5, 3);
  EXPECT_EQ(img.width(), 5);
  EXPECT_EQ(img.height(), 3);
  ASSERT_EQ(img.rgba().size(), 5u * 3u * 4u);
  for (std::uint8_t b : img.rgba()) EXPECT_EQ(b, 0);
  // pixel() addresses row-major RGBA.
  EXPECT_EQ(img.pixel(2, 1) - img.rgba().data(), (1 * 5 + 2) * 4);
  EXPECT_THROW(Image(-1, 4), InputError);
}

TEST(Image, PngRoundTripIsExact) {
  TempDir dir;
  for (const auto& [w, h] : {std::pair{37, 23}, std::pair{1, 1}, std::pair{256, 3}}) {
    const Image original = pattern(w, h, w + h);
    const fs::path path = dir.file("round-trip.png");
    original.writePng(path);
    const Image back = Image::readPng(path);
    ASSERT_EQ(back.width(), w);
    ASSERT_EQ(back.height(), h);
    EXPECT_EQ(back.rgba(), original.rgba()) << w << "x" << h;
  }
  // The temporary file was renamed, not left behind.
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"round-trip.png"});
}

TEST(Image, WritePngReplacesAnExistingFile) {
  TempDir dir;
  const fs::path path = dir.file("out.png");
  pattern(8, 8, 1).writePng(path);
  const Image second = pattern(4, 6, 99);
  second.writePng(path);
  EXPECT_EQ(Image::readPng(path).rgba(), second.rgba());
}

TEST(Image, FlipVerticallyReversesRowOrder) {
  for (int h : {1, 2, 3, 4, 7}) {
    const Image original = pattern(5, h, 3);
    Image flipped = original;
    flipped.flipVertically();
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < 5; ++x) {
        for (int c = 0; c < 4; ++c) {
          ASSERT_EQ(flipped.pixel(x, y)[c], original.pixel(x, h - 1 - y)[c])
              << "h=" << h << " x=" << x << " y=" << y << " c=" << c;
        }
      }
    }
    flipped.flipVertically();
    EXPECT_EQ(flipped.rgba(), original.rgba()) << h;
  }
}

TEST(Image, WriteIntoAMissingDirectoryThrowsNamingThePath) {
  TempDir dir;
  const fs::path path = dir.file("no-such-dir") / "out.png";
  try {
    pattern(4, 4, 0).writePng(path);
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.file("no-such-dir")));
  EXPECT_TRUE(entries(dir.path()).empty());
}

TEST(Image, FailedRenameLeavesNoTemporaryFile) {
  // The PNG itself is written fine, but a directory sits where it should go.
  TempDir dir;
  const fs::path path = dir.file("taken");
  fs::create_directory(path);
  fs::create_directory(path / "child");  // a non-empty directory cannot be replaced
  EXPECT_THROW(pattern(4, 4, 0).writePng(path), Error);
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"taken"});
  EXPECT_TRUE(fs::is_directory(path));
}

// A FIFO (as /dev/stdout may be) gets the PNG itself and stays a FIFO:
// renaming a temporary file over it would replace it, as it would replace
// /dev/null (which `render --out /dev/null` did when run as root).
TEST(Image, WritesAFifoOrDeviceInPlaceWithoutReplacingIt) {
  TempDir dir;
  test::ReadableFifo out(dir.file("out.png"));
  const fs::path& fifo = out.path();
  const Image original = pattern(9, 7, 3);
  original.writePng(fifo);
  const std::string received = out.drain();
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_EQ(entries(dir.path()), std::vector<std::string>{"out.png"});  // no temporary left
  // What came through the FIFO is the image.
  const fs::path copy = dir.file("copy.png");
  std::ofstream(copy, std::ios::binary) << received;
  const Image back = Image::readPng(copy);
  EXPECT_EQ(back.width(), 9);
  EXPECT_EQ(back.height(), 7);
  EXPECT_EQ(back.rgba(), original.rgba());
  // /dev/null, where it is the device: still the device afterwards (tried
  // only once the FIFO was kept, so that a regression cannot replace it).
  if (fs::is_fifo(fifo) && fs::is_character_file("/dev/null")) {
    pattern(4, 4, 0).writePng("/dev/null");
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
  }
}

TEST(Image, WritingAnEmptyImageThrows) {
  TempDir dir;
  const fs::path path = dir.file("empty.png");
  EXPECT_THROW(Image().writePng(path), Error);
  EXPECT_FALSE(fs::exists(path));
}

TEST(Image, ReadPngNamesTheFileOnFailure) {
  TempDir dir;
  const fs::path missing = dir.file("missing.png");
  try {
    Image::readPng(missing);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
  }

  const fs::path garbage = dir.file("garbage.png");
  std::ofstream(garbage, std::ios::binary) << "this is not a PNG file at all";
  try {
    Image::readPng(garbage);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(garbage.string()), std::string::npos) << e.what();
  }

  // A valid PNG cut short: the header parses, the pixel data does not.
  const fs::path whole = dir.file("whole.png");
  pattern(64, 64, 5).writePng(whole);
  const auto size = fs::file_size(whole);
  const fs::path truncated = dir.file("truncated.png");
  fs::copy_file(whole, truncated);
  fs::resize_file(truncated, size / 2);
  try {
    Image::readPng(truncated);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(truncated.string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tessera
