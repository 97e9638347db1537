#pragma once
#include <cstdint>
#include <filesystem>
#include <vector>

namespace tessera {

// RGBA8 image, row 0 at the top (as in PNG), 4 bytes per pixel.
class Image {
 public:
  Image() = default;
  Image(int width, int height);  // zero-filled

  int width() const { return width_; }
  int height() const { return height_; }
  std::uint8_t* pixel(int x, int y) {
    return &rgba_[(static_cast<std::size_t>(y) * width_ + x) * 4];
  }
  const std::uint8_t* pixel(int x, int y) const {
    return &rgba_[(static_cast<std::size_t>(y) * width_ + x) * 4];
  }
  std::vector<std::uint8_t>& rgba() { return rgba_; }
  const std::vector<std::uint8_t>& rgba() const { return rgba_; }

  // Reverses the row order (GL read-back is bottom-up).
  void flipVertically();

  // Writes an 8-bit RGBA PNG via libpng; Error naming the path on failure.
  void writePng(const std::filesystem::path& path) const;
  static Image readPng(const std::filesystem::path& path);  // InputError naming the file

 private:
  int width_ = 0;
  int height_ = 0;
  std::vector<std::uint8_t> rgba_;
};

}  // namespace tessera
