#include "tessera/gpu/Draw.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gpu/ErrorQueries.h"
#include "gpu/gl.h"
#include "tessera/core/Error.h"

namespace tessera::gpu {

namespace {

// What RegionScope and the last apply() asked for, so that a viewport change
// can re-derive the scissor.
struct ScissorState {
  glm::ivec4 viewport{0};
  bool regionActive = false;
  glm::vec4 region{0.0f, 0.0f, 1.0f, 1.0f};
  bool passScissor = false;
  glm::ivec4 passBox{0};
};

ScissorState& scissorState() {
  static ScissorState s;
  return s;
}

int edge(int origin, int size, float fraction) {
  return origin + static_cast<int>(std::lround(std::clamp(fraction, 0.0f, 1.0f) * size));
}

void updateScissor() {
  const ScissorState& s = scissorState();
  glm::ivec4 box = s.passBox;
  bool enabled = s.passScissor;
  if (s.regionActive) {
    const glm::ivec4 v = s.viewport;
    int x0 = edge(v.x, v.z, s.region.x), y0 = edge(v.y, v.w, s.region.y);
    int x1 = edge(v.x, v.z, s.region.z), y1 = edge(v.y, v.w, s.region.w);
    if (enabled) {
      x0 = std::max(x0, box.x);
      y0 = std::max(y0, box.y);
      x1 = std::min(x1, box.x + box.z);
      y1 = std::min(y1, box.y + box.w);
    }
    box = glm::ivec4(x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0));
    enabled = true;
  }
  if (enabled) {
    glEnable(GL_SCISSOR_TEST);
    glScissor(box.x, box.y, box.z, box.w);
  } else {
    glDisable(GL_SCISSOR_TEST);
  }
}

}  // namespace

RegionScope::RegionScope(glm::vec4 fraction) {
  scissorState().regionActive = true;
  scissorState().region = fraction;
  updateScissor();
}

RegionScope::~RegionScope() {
  scissorState().regionActive = false;
  updateScissor();
}

void apply(const DrawState& s) {
  if (s.blend == Blend::Off) {
    glDisable(GL_BLEND);
  } else {
    glEnable(GL_BLEND);
  }
  // GL_MAX (ES 3) and GL_MAX_EXT (EXT_blend_minmax) are the same value.
  glBlendEquation(s.blend == Blend::Max ? GL_MAX : GL_FUNC_ADD);
  switch (s.blend) {
    case Blend::Off:
      break;
    case Blend::Over:
      glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
      break;
    case Blend::FrontToBack:
      glBlendFuncSeparate(GL_ONE_MINUS_DST_ALPHA, GL_ONE, GL_ONE_MINUS_DST_ALPHA, GL_ONE);
      break;
    case Blend::StraightAlpha:
      glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
      break;
    case Blend::Max:
      glBlendFunc(GL_ONE, GL_ONE);
      break;
  }
  if (s.depthTest) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
  } else {
    glDisable(GL_DEPTH_TEST);
  }
  glDisable(GL_CULL_FACE);
  scissorState().passScissor = s.scissor;
  scissorState().passBox = s.scissorBox;
  updateScissor();
  glLineWidth(s.lineWidth);
}

void setViewport(glm::ivec4 b) {
  glViewport(b.x, b.y, b.z, b.w);
  scissorState().viewport = b;
  if (scissorState().regionActive) updateScissor();
}

void clearColor(glm::vec4 c) {
  glClearColor(c.r, c.g, c.b, c.a);
  glClear(GL_COLOR_BUFFER_BIT);
}

void clearColorAndDepth(glm::vec4 c, float depth) {
  glClearColor(c.r, c.g, c.b, c.a);
  glClearDepthf(depth);
  glDepthMask(GL_TRUE);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

void bindFramebuffer(unsigned name, glm::ivec4 viewport) {
  glBindFramebuffer(GL_FRAMEBUFFER, name);
  setViewport(viewport);
}

void blitFramebuffer(unsigned from, glm::ivec4 s, unsigned to, glm::ivec4 d) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, from);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, to);
  glBlitFramebuffer(s.x, s.y, s.x + s.z, s.y + s.w, d.x, d.y, d.x + d.z, d.y + d.w,
                    GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, to);
}

void readPixelsRgba8(glm::ivec4 r, std::uint8_t* out) {
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(r.x, r.y, r.z, r.w, GL_RGBA, GL_UNSIGNED_BYTE, out);
  checkErrors("reading pixels");
}

void readPixelsRgba32F(glm::ivec4 r, float* out) {
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(r.x, r.y, r.z, r.w, GL_RGBA, GL_FLOAT, out);
  checkErrors("reading float pixels");
}

void finish() {
  glFinish();
}

namespace {

std::uint64_t errorQueryCount = 0;
bool errorChecksDeferred = false;
// The live DeferredErrorChecks scope's name ("" none): its work after any
// query is unasked again.
std::string deferredScope;
// The earliest GL work whose errors are not asked for yet ("" none).
std::string unasked;

// Asks GL once: GpuError naming `what` (and the unasked work before it).
void askErrors(const std::string& what) {
  const GLenum e = queryError();
  std::string earlier = deferredScope;
  earlier.swap(unasked);
  if (e == GL_NO_ERROR) return;
  if (earlier == what) earlier.clear();
  char code[16];
  std::snprintf(code, sizeof code, "0x%04X", e);
  throw GpuError(what + (earlier.empty() ? "" : " (or " + earlier + " before it)") + ": GL error " +
                 code + (e == GL_OUT_OF_MEMORY ? " (out of GPU memory)" : ""));
}

}  // namespace

GLenum queryError() {
  ++errorQueryCount;
  return glGetError();
}

std::uint64_t errorQueries() {
  return errorQueryCount;
}

void checkErrors(const std::string& what) {
  if (errorChecksDeferred) return;
  askErrors(what);
}

void clearErrors() {
  if (!unasked.empty()) {
    // One query: GpuError for any error, or none left to forget.
    askErrors(std::string(unasked));
    return;
  }
  for (int i = 0; i < 16 && queryError() != GL_NO_ERROR; ++i) {
  }
}

void leaveErrorsUnasked(const std::string& what) {
  if (unasked.empty()) unasked = what;
}

DeferredErrorChecks::DeferredErrorChecks(std::string what) {
  errorChecksDeferred = true;
  deferredScope = std::move(what);
  leaveErrorsUnasked(deferredScope);
}

DeferredErrorChecks::~DeferredErrorChecks() {
  errorChecksDeferred = false;
  // Ended by a check: nothing of it is unasked. Otherwise its work stays
  // unasked under its name (a preview answering input).
  if (checkedLast_ && unasked == deferredScope) unasked.clear();
  deferredScope.clear();
}

void DeferredErrorChecks::check(const std::string& what) {
  askErrors(what);
  checkedLast_ = true;
}

namespace {
GLenum glPrimitive(Primitive p) {
  switch (p) {
    case Primitive::Triangles:
      return GL_TRIANGLES;
    case Primitive::Lines:
      return GL_LINES;
    case Primitive::Points:
      return GL_POINTS;
  }
  return GL_TRIANGLES;
}

void enable(const Buffer& vertices, std::initializer_list<Attribute> attributes, int strideFloats) {
  glBindBuffer(GL_ARRAY_BUFFER, vertices.id());
  const GLsizei stride = static_cast<GLsizei>(strideFloats * sizeof(float));
  for (const Attribute& a : attributes) {
    if (a.location < 0) continue;
    glEnableVertexAttribArray(static_cast<GLuint>(a.location));
    glVertexAttribPointer(static_cast<GLuint>(a.location), a.components, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(a.offsetFloats * sizeof(float)));
  }
}

void disable(std::initializer_list<Attribute> attributes) {
  for (const Attribute& a : attributes) {
    if (a.location >= 0) glDisableVertexAttribArray(static_cast<GLuint>(a.location));
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}
}  // namespace

void drawArrays(Primitive primitive, const Buffer& vertices,
                std::initializer_list<Attribute> attributes, int strideFloats, int first,
                int count) {
  enable(vertices, attributes, strideFloats);
  glDrawArrays(glPrimitive(primitive), first, count);
  disable(attributes);
}

void drawIndexed16(Primitive primitive, const Buffer& vertices, const Buffer& indices,
                   std::initializer_list<Attribute> attributes, int strideFloats, int count,
                   int firstIndex) {
  enable(vertices, attributes, strideFloats);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, indices.id());
  glDrawElements(glPrimitive(primitive), count, GL_UNSIGNED_SHORT,
                 reinterpret_cast<const void*>(static_cast<std::uintptr_t>(firstIndex) * 2));
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
  disable(attributes);
}

}  // namespace tessera::gpu
