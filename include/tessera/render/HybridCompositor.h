#pragma once
// Hybrid low/high-resolution rendering (Moser & Weiskopf 2008, section 4):
// the volume is rendered into a small offscreen target and upscaled
// bilinearly to the screen, while overlay lines are drawn at the screen's
// full resolution. Lines behind or inside the volume are attenuated by an
// opacity image of the low-resolution volume, estimated by one of the
// paper's methods; lines in front of the volume (nearer than where the
// pixel's ray enters the volume's box) are drawn unattenuated:
//
//   out = C + (1 - alpha) * under,  under = the line's colour or the background,
//
// where C is the upscaled volume colour over black (premultiplied) and alpha
// the upscaled opacity estimate:
//   alpha    : the target's alpha channel (render over transparent black);
//   two-pass : renders over black and over white; since
//              C_white = C + 1 * (1 - a) and C_black = C + 0 * (1 - a),
//              a = 1 - (C_white - C_black) (mean of R, G, B);
//   luma-avg : a = (R + G + B) / 3 of C   (brighter means more opaque: a
//   luma-601 : a = 0.3 R + 0.59 G + 0.11 B  heuristic for one render).
#include <string>
#include <vector>

#include <glm/vec2.hpp>

#include "tessera/core/Camera.h"
#include "tessera/core/Image.h"
#include "tessera/core/RenderSettings.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/gpu/GlObjects.h"
#include "tessera/gpu/Program.h"
#include "tessera/render/Overlay.h"
#include "tessera/render/OverlayRenderer.h"
#include "tessera/render/Technique.h"

namespace tessera::render {

enum class OverlayOpacity { Alpha, TwoPass, LumaAverage, Luma601 };

// "alpha", "two-pass", "luma-avg", "luma-601".
std::string overlayOpacityName(OverlayOpacity method);
OverlayOpacity parseOverlayOpacity(const std::string& name);  // InputError lists the names
std::vector<OverlayOpacity> allOverlayOpacities();

// Size of the offscreen volume target: a fixed WxH, or a factor of the
// screen size (per axis, rounded, at least 1 pixel).
struct OffscreenSize {
  double factor = 1.0;
  glm::ivec2 fixed{0, 0};  // used when fixed.x > 0

  static OffscreenSize ofFactor(double f);
  static OffscreenSize ofSize(int width, int height);
  // "WxH" (e.g. 128x128, 256x512), a factor in (0,1] (e.g. 0.25), or "full".
  static OffscreenSize parse(const std::string& text);
  glm::ivec2 resolve(int screenWidth, int screenHeight) const;
  std::string describe() const;  // "128x128" or "factor 0.25"
};

struct HybridOptions {
  OffscreenSize offscreen;
  OverlayOpacity opacity = OverlayOpacity::Alpha;
};

struct HybridTimings {
  double volumeMs = 0.0;     // the technique's pass(es) and the low-resolution resolve
  double overlayMs = 0.0;    // line layer at full resolution
  double compositeMs = 0.0;  // upscale + blend at full resolution, until finished
  double totalMs = 0.0;
  int volumePasses = 0;        // 2 for two-pass, else 1
  glm::ivec2 offscreen{0, 0};  // the requested offscreen size
  glm::ivec2 rendered{0, 0};   // what the technique rendered (its texture's size)
};

class HybridCompositor {
 public:
  explicit HybridCompositor(gpu::GlContext& context);

  void setOverlayLines(std::vector<OverlayLine> lines) { lines_ = std::move(lines); }
  const std::vector<OverlayLine>& overlayLines() const { return lines_; }

  // Renders a width x height frame of the volume (whose world box is
  // `volumeExtent`, centred at the origin) through `technique`, with the
  // overlay lines, composited over settings.background; waits for it.
  void render(Technique& technique, const Camera& camera, const RenderSettings& settings,
              glm::dvec3 volumeExtent, int width, int height, const HybridOptions& options);
  Image readImage() const;  // the last frame, top row first
  // The viewers' path: a volume layer the caller rendered (premultiplied
  // colour over transparent black, its alpha the accumulated opacity; any
  // size, upscaled bilinearly) composed with the overlay lines by depth, as
  // render() composes them, over `background` into `framebuffer`'s
  // box (x, y, width, height); the lines are rasterised at the box's size.
  void composeInto(const gpu::Texture& volumeLayer, const Camera& camera, glm::vec4 background,
                   glm::dvec3 volumeExtent, unsigned framebuffer, glm::ivec4 box);
  // The last frame's upscaled volume layer: RGB = volume colour over black,
  // A = the opacity estimate, at the offscreen size (top row first).
  Image readOpacityLayer() const;
  const OverlayRenderer& overlays() const { return overlay_; }
  OverlayRenderer& overlays() { return overlay_; }  // (readDistance draws its pass)
  const HybridTimings& timings() const { return timings_; }

 private:
  const gpu::Program& resolveProgram(const std::string& method);
  // The full-resolution composite into the bound framebuffer, whose
  // viewport is width x height at `origin`.
  void drawComposite(const gpu::Texture& volumeLayer, glm::vec4 background, int width, int height,
                     glm::ivec2 origin);

  gpu::GlContext& context_;
  std::vector<OverlayLine> lines_;
  OverlayRenderer overlay_;
  gpu::FullscreenTriangle triangle_;
  gpu::Framebuffer white_;     // two-pass: the render over white, copied
  gpu::Framebuffer resolved_;  // (C over black, alpha estimate) at the offscreen size
  gpu::Framebuffer image_;     // the composed frame
  std::vector<std::pair<std::string, gpu::Program>> resolvePrograms_;
  gpu::Program composite_;
  HybridTimings timings_;
};

}  // namespace tessera::render
