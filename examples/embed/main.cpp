// Embeds Tessera: a Marschner-Lobb volume made in memory, rendered headless on
// the GPU (EGL) to a PNG and compared with the CPU reference of the same view.
// Usage: tessera_embed [OUT.png] (default embed.png). Exit 1 below 40 dB.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <numbers>

#include "tessera/reference/ImageMetrics.h"
#include "tessera/session/Session.h"

using namespace tessera;

// The Marschner-Lobb test field (f_M = 6, alpha = 0.25) on [-1,1]^3, as u8,
// with anisotropic voxels (1 x 1 x 1.25 mm).
static Volume marschnerLobb(int n) {
  Volume v = Volume::allocate({n, n, n}, ScalarType::U8, "Marschner-Lobb");
  v.setSpacing({1.0, 1.0, 1.25});
  const double pi = std::numbers::pi, alpha = 0.25;
  const auto c = [n](int i) { return 2.0 * (i + 0.5) / n - 1.0; };  // voxel centre in [-1,1]
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double r = std::hypot(c(x), c(y));
        const double rho = std::cos(2.0 * pi * 6.0 * std::cos(pi * r / 2.0));
        const double f =
            (1.0 - std::sin(pi * c(z) / 2.0) + alpha * (1.0 + rho)) / (2.0 * (1.0 + alpha));
        v.setValueAtIndex(v.index(x, y, z), std::round(255.0 * f));
      }
  return v;
}

struct Frames {
  Image gpu, reference;
};

// The one place that talks to the renderer: a session on a headless device,
// the array moved in (not copied), its settings, a frame and its reference.
static Frames renderBoth(Volume volume, const TransferFunction& tf, int width, int height) {
  session::Session s("native");
  s.setVolume(std::move(volume), "Marschner-Lobb");
  session::Settings& settings = s.settings();
  settings.tf = tf;
  settings.camera.azimuthDeg = 30.0;
  settings.camera.elevationDeg = 35.0;
  settings.gradient = "on-the-fly";    // the reference's central differences
  settings.render = RenderSettings();  // plain post-classified sampling, half-voxel steps
  settings.render.shading.enabled = true;
  return {s.render(width, height), s.renderReference(width, height)};
}

int main(int argc, char** argv) try {
  const char* out = argc > 1 ? argv[1] : "embed.png";
  const auto t0 = std::chrono::steady_clock::now();
  TransferFunction tf;
  tf.addColor(0.0, {0.1, 0.2, 0.8});
  tf.addColor(1.0, {1.0, 0.6, 0.1});
  tf.addOpacity(0.40, 0.0);  // a shell around the field's 0.5 level set
  tf.addOpacity(0.50, 0.9);
  tf.addOpacity(0.60, 0.0);
  const Frames f = renderBoth(marschnerLobb(64), tf, 256, 256);
  f.gpu.writePng(out);
  const double db = psnr(f.gpu, f.reference), s = ssim(f.gpu, f.reference);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("wrote %s (%dx%d); GPU vs CPU reference: PSNR %.2f dB, SSIM %.4f; %.0f ms\n", out,
              f.gpu.width(), f.gpu.height(), db, s, ms);
  return db >= 40.0 ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "tessera_embed: %s\n", e.what());
  return 2;
}
