#include "tessera/core/Image.h"

#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <limits>
#include <string>
#include <system_error>

#include "tessera/core/Error.h"
#include "tessera/core/HostBudget.h"
#include "tessera/core/OutputPath.h"

namespace tessera {

namespace {

// libpng's simplified API (png_image_*) is used instead of png_create_*:
// it reports errors through image.message instead of longjmp, which would
// skip C++ destructors.

// Frees libpng's read state on every exit path.
struct PngImageGuard {
  png_image* image;
  ~PngImageGuard() { png_image_free(image); }
};

std::filesystem::path temporarySibling(const std::filesystem::path& path) {
  // Unique per process and call, in the target's directory so that the final
  // rename stays within one file system and is atomic.
  static std::atomic<unsigned> counter{0};
  std::filesystem::path tmp = path;
  tmp += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  return tmp;
}

}  // namespace

Image::Image(int width, int height) : width_(width), height_(height) {
  if (width < 0 || height < 0) {
    throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is negative");
  }
  const std::uint64_t bytes =
      static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) * 4;
  HostBudget::global().check(
      bytes, "image " + std::to_string(width) + "x" + std::to_string(height) + " RGBA8");
  rgba_.assign(static_cast<std::size_t>(bytes), 0);
}

void Image::flipVertically() {
  const std::size_t stride = static_cast<std::size_t>(width_) * 4;
  for (int top = 0, bottom = height_ - 1; top < bottom; ++top, --bottom) {
    std::swap_ranges(rgba_.begin() + static_cast<std::ptrdiff_t>(top * stride),
                     rgba_.begin() + static_cast<std::ptrdiff_t>((top + 1) * stride),
                     rgba_.begin() + static_cast<std::ptrdiff_t>(bottom * stride));
  }
}

void Image::writePng(const std::filesystem::path& path) const {
  const std::string name = path.string();
  if (width_ <= 0 || height_ <= 0) {
    throw Error(name + ": cannot write an empty " + std::to_string(width_) + "x" +
                std::to_string(height_) + " image as PNG");
  }
  const std::size_t expected = static_cast<std::size_t>(width_) * height_ * 4;
  if (rgba_.size() != expected) {
    throw Error(name + ": image buffer holds " + std::to_string(rgba_.size()) + " bytes, " +
                std::to_string(width_) + "x" + std::to_string(height_) + " RGBA8 needs " +
                std::to_string(expected));
  }

  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width_);
  image.height = static_cast<png_uint_32>(height_);
  image.format = PNG_FORMAT_RGBA;

  // A device or FIFO (/dev/null, /dev/stdout) is written directly.
  if (writesInPlace(path)) {
    if (png_image_write_to_file(&image, path.c_str(), 0, rgba_.data(), 0, nullptr) == 0) {
      throw Error(name + ": cannot write PNG: " + image.message);
    }
    return;
  }
  // Write a sibling and rename it over the target: a reader never sees a
  // half-written PNG, and a failed write leaves any previous file intact.
  const std::filesystem::path tmp = temporarySibling(path);
  // png_image_write_to_file removes its file itself when it fails.
  if (png_image_write_to_file(&image, tmp.c_str(), 0, rgba_.data(), 0, nullptr) == 0) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw Error(name + ": cannot write PNG: " + image.message);
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw Error(name + ": cannot write PNG: renaming the temporary file failed: " + ec.message());
  }
}

Image Image::readPng(const std::filesystem::path& path) {
  const std::string name = path.string();
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&image, path.c_str()) == 0) {
    throw InputError(name + ": cannot read PNG: " + image.message);
  }
  PngImageGuard guard{&image};
  // Any PNG (grey, palette, 16-bit, with or without alpha) comes out as RGBA8.
  image.format = PNG_FORMAT_RGBA;
  if (image.width > static_cast<png_uint_32>(std::numeric_limits<int>::max() / 4) ||
      image.height > static_cast<png_uint_32>(std::numeric_limits<int>::max())) {
    throw InputError(name + ": PNG size " + std::to_string(image.width) + "x" +
                     std::to_string(image.height) + " is too large");
  }
  // A header may claim up to 10^6 x 10^6 pixels: check before allocating.
  HostBudget::global().check(
      static_cast<std::uint64_t>(image.width) * image.height * 4,
      name + " (" + std::to_string(image.width) + "x" + std::to_string(image.height) + " RGBA8)");
  Image out(static_cast<int>(image.width), static_cast<int>(image.height));
  if (png_image_finish_read(&image, nullptr, out.rgba_.data(), 0, nullptr) == 0) {
    throw InputError(name + ": cannot read PNG: " + image.message);
  }
  return out;
}

}  // namespace tessera
