#pragma once
// RAII owners of GL objects. Textures, buffers and renderbuffers record their
// bytes in a MemoryLedger for as long as they live. All must be destroyed
// while their context is current.
#include <cstdint>
#include <string>

#include <glm/vec3.hpp>

#include "tessera/gpu/MemoryLedger.h"
#include "tessera/gpu/TexelFormat.h"

namespace tessera::gpu {

using GLenumT = unsigned int;
using GLuintT = unsigned int;

class LedgerEntry {
 public:
  LedgerEntry() = default;
  LedgerEntry(MemoryLedger& ledger, GpuResource kind, std::uint64_t bytes,
              const std::string& label);
  LedgerEntry(LedgerEntry&& o) noexcept;
  LedgerEntry& operator=(LedgerEntry&& o) noexcept;
  ~LedgerEntry();
  std::uint64_t bytes() const { return bytes_; }

 private:
  MemoryLedger* ledger_ = nullptr;
  MemoryLedger::Id id_ = 0;
  std::uint64_t bytes_ = 0;
};

class Texture {
 public:
  Texture() = default;
  Texture(Texture&& o) noexcept;
  Texture& operator=(Texture&& o) noexcept;
  ~Texture();

  // Allocates (and optionally fills) a texture of `format` (TexelFormat.h):
  // `data`, when given, has uploadBytesPerTexel(format) bytes per texel, rows
  // tightly packed. Filtering: linear, wrap: clamp to edge.
  static Texture create2D(MemoryLedger& ledger, const std::string& label, TexelFormat format,
                          int width, int height, const void* data = nullptr);
  static Texture create3D(MemoryLedger& ledger, const std::string& label, TexelFormat format,
                          int width, int height, int depth, const void* data = nullptr);
  // Replaces all of level 0, or the box at `offset` of `size` (2D: z = 0,
  // size.z = 1), with data in the texture's format.
  void update(const void* data);
  void updateRegion(glm::ivec3 offset, glm::ivec3 size, const void* data);
  void setFilter(Filter filter);
  TexelFormat format() const { return format_; }

  GLuintT id() const { return id_; }
  int width() const { return width_; }
  int height() const { return height_; }
  int depth() const { return depth_; }
  std::uint64_t bytes() const { return entry_.bytes(); }
  void bind(int unit) const;

 private:
  friend class Framebuffer;  // sets format_ of its colour target
  // The GL-enum forms behind the typed ones (GlObjects.cpp).
  static Texture create2D(MemoryLedger& ledger, const std::string& label, GLenumT internalFormat,
                          int width, int height, GLenumT format, GLenumT type, const void* data,
                          std::uint64_t texelBytes);
  static Texture create3D(MemoryLedger& ledger, const std::string& label, GLenumT internalFormat,
                          int width, int height, int depth, GLenumT format, GLenumT type,
                          const void* data, std::uint64_t texelBytes);
  void setFilter(GLenumT minFilter, GLenumT magFilter);
  GLuintT id_ = 0;
  GLenumT target_ = 0;
  int width_ = 0, height_ = 0, depth_ = 0;
  TexelFormat format_ = TexelFormat::RGBA8;
  LedgerEntry entry_;
};

enum class BufferKind { Vertices, Indices16 };
enum class BufferUsage { Static, Dynamic };

class Buffer {
 public:
  Buffer() = default;
  Buffer(Buffer&& o) noexcept;
  Buffer& operator=(Buffer&& o) noexcept;
  ~Buffer();
  static Buffer create(MemoryLedger& ledger, const std::string& label, BufferKind kind,
                       std::uint64_t bytes, const void* data, BufferUsage usage);
  // Replaces `bytes` bytes from `offset`.
  void update(std::uint64_t offset, std::uint64_t bytes, const void* data);
  GLuintT id() const { return id_; }
  std::uint64_t bytes() const { return entry_.bytes(); }

 private:
  GLuintT id_ = 0;
  GLenumT target_ = 0;
  LedgerEntry entry_;
};

// Framebuffer with one colour texture attachment (RGBA8 by default).
class Framebuffer {
 public:
  Framebuffer() = default;
  Framebuffer(Framebuffer&& o) noexcept;
  Framebuffer& operator=(Framebuffer&& o) noexcept;
  ~Framebuffer();
  // A colour texture of `color` and, with `depth`, a 16-bit depth buffer.
  static Framebuffer create(MemoryLedger& ledger, const std::string& label, int width, int height,
                            TexelFormat color = TexelFormat::RGBA8, bool depth = false);
  void bind() const;  // also sets the viewport
  GLuintT id() const { return id_; }
  int width() const { return color_.width(); }
  int height() const { return color_.height(); }
  const Texture& color() const { return color_; }
  Texture& color() { return color_; }
  // Reads the colour attachment as RGBA8, bottom row first.
  void readRgba8(std::uint8_t* out) const;

 private:
  GLuintT id_ = 0;
  GLuintT depth_ = 0;  // renderbuffer, 0 when none
  LedgerEntry depthEntry_;
  Texture color_;
};

// One triangle covering the viewport, drawn with attribute 0 = a_position
// (render/fullscreen.vert.glsl): the proxy of every full-screen pass.
class FullscreenTriangle {
 public:
  FullscreenTriangle() = default;
  explicit FullscreenTriangle(MemoryLedger& ledger);
  void draw() const;

 private:
  Buffer vertices_;
};

}  // namespace tessera::gpu
