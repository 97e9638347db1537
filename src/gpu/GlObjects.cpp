#include "tessera/gpu/GlObjects.h"

#include <utility>

#include "gpu/ErrorQueries.h"
#include "gpu/GlFormats.h"
#include "gpu/gl.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/Draw.h"

namespace tessera::gpu {

LedgerEntry::LedgerEntry(MemoryLedger& ledger, GpuResource kind, std::uint64_t bytes,
                         const std::string& label)
    : ledger_(&ledger), id_(ledger.add(kind, bytes, label)), bytes_(bytes) {}

LedgerEntry::LedgerEntry(LedgerEntry&& o) noexcept
    : ledger_(std::exchange(o.ledger_, nullptr)), id_(o.id_), bytes_(std::exchange(o.bytes_, 0)) {}

LedgerEntry& LedgerEntry::operator=(LedgerEntry&& o) noexcept {
  if (this != &o) {
    if (ledger_) ledger_->remove(id_);
    ledger_ = std::exchange(o.ledger_, nullptr);
    id_ = o.id_;
    bytes_ = std::exchange(o.bytes_, 0);
  }
  return *this;
}

LedgerEntry::~LedgerEntry() {
  if (ledger_) ledger_->remove(id_);
}

// ---------------------------------------------------------------- Texture

Texture::Texture(Texture&& o) noexcept
    : id_(std::exchange(o.id_, 0)),
      target_(o.target_),
      width_(o.width_),
      height_(o.height_),
      depth_(o.depth_),
      format_(o.format_),
      entry_(std::move(o.entry_)) {}

Texture& Texture::operator=(Texture&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteTextures(1, &id_);
    id_ = std::exchange(o.id_, 0);
    target_ = o.target_;
    width_ = o.width_;
    height_ = o.height_;
    depth_ = o.depth_;
    format_ = o.format_;
    entry_ = std::move(o.entry_);
  }
  return *this;
}

Texture::~Texture() {
  if (id_) glDeleteTextures(1, &id_);
}

namespace {
void checkGl(const std::string& what) {
  const GLenum e = queryError();
  if (e == GL_OUT_OF_MEMORY) throw GpuError(what + ": GL_OUT_OF_MEMORY");
  if (e != GL_NO_ERROR)
    throw GpuError(what + ": GL error 0x" + [&] {
      char b[16];
      std::snprintf(b, sizeof b, "%04X", e);
      return std::string(b);
    }());
}
}  // namespace

Texture Texture::create2D(MemoryLedger& ledger, const std::string& label, GLenumT internalFormat,
                          int width, int height, GLenumT format, GLenumT type, const void* data,
                          std::uint64_t texelBytes) {
  const std::uint64_t bytes =
      static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) * texelBytes;
  Texture t;
  t.entry_ = LedgerEntry(ledger, GpuResource::Texture, bytes, label);  // budget check first
  clearErrors();  // earlier errors are not this allocation's (Draw.h: unasked work's are reported)
  glGenTextures(1, &t.id_);
  t.target_ = GL_TEXTURE_2D;
  t.width_ = width;
  t.height_ = height;
  t.depth_ = 1;
  glBindTexture(GL_TEXTURE_2D, t.id_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(internalFormat), width, height, 0, format, type,
               data);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  checkGl("texture '" + label + "' " + std::to_string(width) + "x" + std::to_string(height));
  return t;
}

Texture Texture::create3D(MemoryLedger& ledger, const std::string& label, GLenumT internalFormat,
                          int width, int height, int depth, GLenumT format, GLenumT type,
                          const void* data, std::uint64_t texelBytes) {
  const std::uint64_t bytes = static_cast<std::uint64_t>(width) *
                              static_cast<std::uint64_t>(height) *
                              static_cast<std::uint64_t>(depth) * texelBytes;
  Texture t;
  t.entry_ = LedgerEntry(ledger, GpuResource::Texture, bytes, label);
  clearErrors();  // earlier errors are not this allocation's (Draw.h: unasked work's are reported)
  glGenTextures(1, &t.id_);
  t.target_ = GL_TEXTURE_3D;
  t.width_ = width;
  t.height_ = height;
  t.depth_ = depth;
  glBindTexture(GL_TEXTURE_3D, t.id_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage3D(GL_TEXTURE_3D, 0, static_cast<GLint>(internalFormat), width, height, depth, 0,
               format, type, data);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  checkGl("3D texture '" + label + "' " + std::to_string(width) + "x" + std::to_string(height) +
          "x" + std::to_string(depth));
  return t;
}

Texture Texture::create2D(MemoryLedger& ledger, const std::string& label, TexelFormat format,
                          int width, int height, const void* data) {
  const GlFormat f = glFormat(format);
  Texture t = create2D(ledger, label, f.internalFormat, width, height, f.format, f.type, data,
                       f.texelBytes);
  t.format_ = format;
  return t;
}

Texture Texture::create3D(MemoryLedger& ledger, const std::string& label, TexelFormat format,
                          int width, int height, int depth, const void* data) {
  const GlFormat f = glFormat(format);
  Texture t = create3D(ledger, label, f.internalFormat, width, height, depth, f.format, f.type,
                       data, f.texelBytes);
  t.format_ = format;
  return t;
}

void Texture::update(const void* data) {
  updateRegion({0, 0, 0}, {width_, height_, depth_}, data);
}

void Texture::updateRegion(glm::ivec3 o, glm::ivec3 n, const void* data) {
  const GlFormat f = glFormat(format_);
  glBindTexture(target_, id_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (target_ == GL_TEXTURE_3D) {
    glTexSubImage3D(GL_TEXTURE_3D, 0, o.x, o.y, o.z, n.x, n.y, n.z, f.format, f.type, data);
  } else {
    glTexSubImage2D(GL_TEXTURE_2D, 0, o.x, o.y, n.x, n.y, f.format, f.type, data);
  }
}

void Texture::setFilter(Filter filter) {
  const GLenum f = filter == Filter::Nearest ? GL_NEAREST : GL_LINEAR;
  setFilter(f, f);
}

void Texture::setFilter(GLenumT minFilter, GLenumT magFilter) {
  glBindTexture(target_, id_);
  glTexParameteri(target_, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(minFilter));
  glTexParameteri(target_, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(magFilter));
}

void Texture::bind(int unit) const {
  glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
  glBindTexture(target_, id_);
}

// ---------------------------------------------------------------- Buffer

Buffer::Buffer(Buffer&& o) noexcept
    : id_(std::exchange(o.id_, 0)), target_(o.target_), entry_(std::move(o.entry_)) {}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteBuffers(1, &id_);
    id_ = std::exchange(o.id_, 0);
    target_ = o.target_;
    entry_ = std::move(o.entry_);
  }
  return *this;
}

Buffer::~Buffer() {
  if (id_) glDeleteBuffers(1, &id_);
}

Buffer Buffer::create(MemoryLedger& ledger, const std::string& label, BufferKind kind,
                      std::uint64_t bytes, const void* data, BufferUsage usage) {
  const GLenum target = kind == BufferKind::Vertices ? GL_ARRAY_BUFFER : GL_ELEMENT_ARRAY_BUFFER;
  Buffer b;
  b.entry_ = LedgerEntry(ledger, GpuResource::Buffer, bytes, label);
  clearErrors();  // earlier errors are not this allocation's (Draw.h: unasked work's are reported)
  glGenBuffers(1, &b.id_);
  b.target_ = target;
  glBindBuffer(target, b.id_);
  glBufferData(target, static_cast<GLsizeiptr>(bytes), data,
               usage == BufferUsage::Static ? GL_STATIC_DRAW : GL_DYNAMIC_DRAW);
  checkGl("buffer '" + label + "'");
  return b;
}

void Buffer::update(std::uint64_t offset, std::uint64_t bytes, const void* data) {
  glBindBuffer(target_, id_);
  glBufferSubData(target_, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
  glBindBuffer(target_, 0);
}

// ---------------------------------------------------------------- Framebuffer

Framebuffer::Framebuffer(Framebuffer&& o) noexcept
    : id_(std::exchange(o.id_, 0)),
      depth_(std::exchange(o.depth_, 0)),
      depthEntry_(std::move(o.depthEntry_)),
      color_(std::move(o.color_)) {}

Framebuffer& Framebuffer::operator=(Framebuffer&& o) noexcept {
  if (this != &o) {
    if (id_) glDeleteFramebuffers(1, &id_);
    if (depth_) glDeleteRenderbuffers(1, &depth_);
    id_ = std::exchange(o.id_, 0);
    depth_ = std::exchange(o.depth_, 0);
    depthEntry_ = std::move(o.depthEntry_);
    color_ = std::move(o.color_);
  }
  return *this;
}

Framebuffer::~Framebuffer() {
  if (id_) glDeleteFramebuffers(1, &id_);
  if (depth_) glDeleteRenderbuffers(1, &depth_);
}

Framebuffer Framebuffer::create(MemoryLedger& ledger, const std::string& label, int width,
                                int height, TexelFormat color, bool depth) {
  const GlFormat c = glFormat(color);
  // Render targets are allocated without data: the upload type only has to
  // be one ES accepts with the internal format (half floats for RGBA16F).
  const GLenum type = color == TexelFormat::RGBA16F ? GL_HALF_FLOAT : c.type;
  Framebuffer f;
  f.color_ = Texture::create2D(ledger, label + " colour", c.internalFormat, width, height, c.format,
                               type, nullptr, c.texelBytes);
  f.color_.format_ = color;
  glGenFramebuffers(1, &f.id_);
  glBindFramebuffer(GL_FRAMEBUFFER, f.id_);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, f.color_.id(), 0);
  if (depth) {
    f.depthEntry_ = LedgerEntry(ledger, GpuResource::Renderbuffer,
                                static_cast<std::uint64_t>(width) * height * 2, label + " depth");
    glGenRenderbuffers(1, &f.depth_);
    glBindRenderbuffer(GL_RENDERBUFFER, f.depth_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT16, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, f.depth_);
  }
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    throw GpuError("framebuffer '" + label + "' " + std::to_string(width) + "x" +
                   std::to_string(height) + " " + texelFormatName(color) + " incomplete (status " +
                   std::to_string(status) + ")");
  }
  return f;
}

void Framebuffer::bind() const {
  glBindFramebuffer(GL_FRAMEBUFFER, id_);
  setViewport({0, 0, color_.width(), color_.height()});  // follows a RegionScope
}

void Framebuffer::readRgba8(std::uint8_t* out) const {
  glBindFramebuffer(GL_FRAMEBUFFER, id_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, color_.width(), color_.height(), GL_RGBA, GL_UNSIGNED_BYTE, out);
  checkGl("glReadPixels");
}

// ---------------------------------------------------------------- FullscreenTriangle

namespace {
constexpr float kTriangle[] = {-1.0f, -1.0f, 3.0f, -1.0f, -1.0f, 3.0f};
}

FullscreenTriangle::FullscreenTriangle(MemoryLedger& ledger)
    : vertices_(Buffer::create(ledger, "full-screen triangle", BufferKind::Vertices,
                               sizeof kTriangle, kTriangle, BufferUsage::Static)) {}

void FullscreenTriangle::draw() const {
  glBindBuffer(GL_ARRAY_BUFFER, vertices_.id());
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDisableVertexAttribArray(0);
}

}  // namespace tessera::gpu
