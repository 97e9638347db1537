#pragma once
// Drawing and pipeline state for the code above `gpu`, without GL enums:
// blending as the compositing rules this project uses, clears, viewports,
// draws from vertex buffers, read-backs and error checks. Everything here
// acts on the current context (GlContext, AdoptedGlContext).
#include <cstdint>
#include <initializer_list>
#include <string>

#include <glm/vec4.hpp>

#include "tessera/gpu/GlObjects.h"

namespace tessera::gpu {

// How a fragment combines with the target.
enum class Blend {
  Off,
  // Premultiplied source over the target: c = s + (1 - s.a) d.
  Over,
  // Front-to-back accumulation of premultiplied slices, the target in front:
  // c = (1 - d.a) s + d (Moser & Weiskopf 2008; Noguera et al. 2012).
  FrontToBack,
  // Straight (non-premultiplied) alpha: c = s.a s + (1 - s.a) d.
  StraightAlpha,
  // Per-channel maximum (MIP): ES 3, or ES 2 with EXT_blend_minmax.
  Max,
};

// The state a pass needs; apply() sets all of it, so a pass never inherits
// another's leftovers.
struct DrawState {
  Blend blend = Blend::Off;
  bool depthTest = false;  // GL_LESS, writing depth
  bool scissor = false;
  glm::ivec4 scissorBox{0};  // x, y, width, height (pixels from the bottom left)
  float lineWidth = 1.0f;
};
void apply(const DrawState& state);

void setViewport(glm::ivec4 box);  // x, y, width, height

// While one lives, every draw and clear is confined to a sub-rectangle of
// the viewport of the moment, given as fractions (x0, y0, x1, y1 in [0, 1],
// from the bottom left; pixel edges at round(fraction x size), so adjacent
// regions tile a target exactly): a technique renders one tile of its frame
// without knowing it (viewer::Viewer's progressive frames). It follows
// every viewport change, so each target of a multi-pass technique gets the
// same part of itself; a pass's own scissor box is intersected with it.
// Regions do not nest.
class RegionScope {
 public:
  explicit RegionScope(glm::vec4 fraction);
  ~RegionScope();
  RegionScope(const RegionScope&) = delete;
  RegionScope& operator=(const RegionScope&) = delete;
};
void clearColor(glm::vec4 rgba);
void clearColorAndDepth(glm::vec4 rgba, float depth = 1.0f);

// The framebuffer a front end gave us by its GL name (0: the window or
// canvas), with `viewport` set.
void bindFramebuffer(unsigned name, glm::ivec4 viewport);
// Copies a region of the framebuffer `from` to `to` (ES 3 only).
void blitFramebuffer(unsigned from, glm::ivec4 source, unsigned to, glm::ivec4 destination);
// RGBA8 pixels of the bound framebuffer's region, bottom row first.
void readPixelsRgba8(glm::ivec4 region, std::uint8_t* out);
// The same as floats, from an RGBA32F target (ES 3 + EXT_color_buffer_float).
void readPixelsRgba32F(glm::ivec4 region, float* out);

// Waits for the GPU (where the driver honours it; browsers do not).
void finish();
// GpuError naming `what` if GL has recorded an error (and the work left
// unasked before it, if any: leaveErrorsUnasked).
void checkErrors(const std::string& what);
// Forgets recorded errors (front ends such as ImGui's GL backend may leave
// some that a later check would blame on the engine). Errors of work left
// unasked are not forgotten: GpuError naming that work. Every new texture
// or buffer does this before its own allocation check.
void clearErrors();
// GL work named `what` has not asked for its errors: in a browser each
// glGetError is a round trip that waits for the GPU process, which a call
// answering input leaves to the next check that waits anyway (a read-back's,
// an upload's). That check, or a clear before it, reports them under this
// name as well as its own, so that no error is lost or blamed on the wrong
// work alone. The earliest unasked work keeps the name until asked.
void leaveErrorsUnasked(const std::string& what);
// GL error queries made so far (each glGetError: in a browser a round trip
// that waits for the GPU process), for records of what a call waited for.
std::uint64_t errorQueries();
// While one is alive, checkErrors() does not ask GL: in a browser each
// glGetError is a round trip to the GPU process that waits for every
// command before it, and a frame of several passes waited once per pass.
// check() asks once for all of them (GL keeps the errors until asked); the
// scope's work is left unasked (leaveErrorsUnasked) under `what` until
// then. A scope ends with a check, or leaves its work unasked on purpose
// (work after its last check is not named). Scopes do not nest.
class DeferredErrorChecks {
 public:
  explicit DeferredErrorChecks(std::string what);
  ~DeferredErrorChecks();
  DeferredErrorChecks(const DeferredErrorChecks&) = delete;
  DeferredErrorChecks& operator=(const DeferredErrorChecks&) = delete;
  // GpuError naming `what` if GL recorded an error since the scope began.
  void check(const std::string& what);

 private:
  bool checkedLast_ = false;
};

enum class Primitive { Triangles, Lines, Points };

// One float attribute of interleaved vertices: its location in the program
// (Program::attributeLocation; -1 is skipped), size and offset in floats.
struct Attribute {
  int location;
  int components;
  int offsetFloats = 0;
};

void drawArrays(Primitive primitive, const Buffer& vertices,
                std::initializer_list<Attribute> attributes, int strideFloats, int first,
                int count);
// Draws `count` indices of a 16-bit index buffer from index `firstIndex`.
void drawIndexed16(Primitive primitive, const Buffer& vertices, const Buffer& indices,
                   std::initializer_list<Attribute> attributes, int strideFloats, int count,
                   int firstIndex);

}  // namespace tessera::gpu
