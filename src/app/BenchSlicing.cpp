#include "app/BenchSlicing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <glm/geometric.hpp>

#include "app/Commands.h"
#include "gpu/gl.h"
#include "tessera/core/Error.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/layout/Texture3DLayout.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Raycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"

namespace tessera::app {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// Trilinear resampling to new dims over the same world box (how the
// 128x128x186 "cthuman"-sized volume of GRAPP 2012 is made from ch2).
Volume resample(const Volume& v, glm::ivec3 dims) {
  Volume out = Volume::allocate(dims, ScalarType::U8, "resampled");
  out.setSpacing(v.extent() / glm::dvec3(dims));
  out.setDirection(v.direction());
  const ValueRange r = v.valueRange();
  const double scale = r.max > r.min ? 255.0 / (r.max - r.min) : 0.0;
  std::uint8_t* dst = out.dataAs<std::uint8_t>();
  for (int z = 0; z < dims.z; ++z) {
    for (int y = 0; y < dims.y; ++y) {
      for (int x = 0; x < dims.x; ++x) {
        const glm::dvec3 p = (glm::dvec3(x, y, z) + 0.5) / glm::dvec3(dims);
        const double s = (sampleTrilinear(v, p) - r.min) * scale;
        dst[out.index(x, y, z)] = static_cast<std::uint8_t>(std::lround(std::clamp(s, 0.0, 255.0)));
      }
    }
  }
  out.invalidateRange();
  out.setDescription(v.description() + " resampled");
  return out;
}

// Waits for queued uploads, so that an update's time includes them.
void glFinishForBench() {
  glFinish();
}

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// One technique at one count on one volume, behind one interface.
struct Technique {
  std::string name;
  std::function<void(const Camera&, int, int)> frame;
  std::function<Image()> read;
};

struct Scene {
  std::string name;
  Volume volume;
  std::unique_ptr<layout::Layout> layout;
};

Camera benchCamera(const Volume& v) {
  Camera cam;
  cam.azimuthDeg = 30;
  cam.elevationDeg = 20;
  cam.frame(v);
  return cam;
}

// Settings that make the ray caster take `steps` samples over the
// diagonal, as GRAPP 2012 divides each ray into a number of steps; slicing
// gets the same distance between its slices.
RenderSettings settingsForCount(const Volume& v, int count) {
  RenderSettings s;
  const glm::dvec3 sp = v.spacing();
  s.stepVoxels = glm::length(v.extent()) / count / std::min({sp.x, sp.y, sp.z});
  s.maxSteps = count;
  return s;
}

struct SpeedRow {
  std::string volume, technique;
  int width, height, count;
  double ms;
};

struct QualityRow {
  std::string technique;
  int count;
  double psnrDb, ssimValue;
};

struct TfRow {
  glm::ivec3 dims;
  std::string path;
  double frameMs, updateMs;
};

// A tiny line chart: one polyline per series over shared axes.
std::string svgChart(const std::string& title, const std::string& xLabel, const std::string& yLabel,
                     const std::vector<double>& xs,
                     const std::vector<std::pair<std::string, std::vector<double>>>& series,
                     bool logY) {
  const double W = 720, H = 420, L = 70, R = 230, T = 40, B = 50;
  double ymin = 1e300, ymax = -1e300;
  for (const auto& s : series) {
    for (double y : s.second) {
      if (y > 0) ymin = std::min(ymin, y);
      ymax = std::max(ymax, y);
    }
  }
  if (logY) {
    ymin = std::pow(10.0, std::floor(std::log10(ymin)));
    ymax = std::pow(10.0, std::ceil(std::log10(ymax)));
  } else {
    ymin = 0;
    ymax *= 1.1;
  }
  auto fy = [&](double y) {
    const double t = logY ? (std::log10(std::max(y, ymin)) - std::log10(ymin)) /
                                (std::log10(ymax) - std::log10(ymin))
                          : (y - ymin) / (ymax - ymin);
    return T + (H - T - B) * (1.0 - t);
  };
  auto fx = [&](std::size_t i) {
    return L + (W - L - R) * (xs.size() > 1 ? static_cast<double>(i) / (xs.size() - 1) : 0.5);
  };
  static const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                  "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" "
       "fill=\"white\"/>\n<text x=\""
    << L << "\" y=\"22\" font-size=\"14\">" << title << "</text>\n";
  o << "<line x1=\"" << L << "\" y1=\"" << H - B << "\" x2=\"" << W - R << "\" y2=\"" << H - B
    << "\" stroke=\"black\"/><line x1=\"" << L << "\" y1=\"" << T << "\" x2=\"" << L << "\" y2=\""
    << H - B << "\" stroke=\"black\"/>\n";
  for (std::size_t i = 0; i < xs.size(); ++i) {
    o << "<text x=\"" << fx(i) << "\" y=\"" << H - B + 16 << "\" text-anchor=\"middle\">" << xs[i]
      << "</text>\n";
  }
  std::vector<double> ticks;
  if (logY) {
    for (double t = ymin; t <= ymax * 1.0001; t *= 10) ticks.push_back(t);
  } else {
    for (int i = 0; i <= 5; ++i) ticks.push_back(ymin + (ymax - ymin) * i / 5);
  }
  for (double t : ticks) {
    o << "<line x1=\"" << L - 4 << "\" y1=\"" << fy(t) << "\" x2=\"" << W - R << "\" y2=\"" << fy(t)
      << "\" stroke=\"#ddd\"/><text x=\"" << L - 6 << "\" y=\"" << fy(t) + 4
      << "\" text-anchor=\"end\">" << fmt(t < 10 ? "%.3g" : "%.0f", t) << "</text>\n";
  }
  o << "<text x=\"" << (L + W - R) / 2 << "\" y=\"" << H - 12 << "\" text-anchor=\"middle\">"
    << xLabel << "</text>\n<text x=\"16\" y=\"" << (T + H - B) / 2
    << "\" transform=\"rotate(-90 16 " << (T + H - B) / 2 << ")\" text-anchor=\"middle\">" << yLabel
    << "</text>\n";
  for (std::size_t s = 0; s < series.size(); ++s) {
    const char* c = colours[s % 10];
    o << "<polyline fill=\"none\" stroke=\"" << c << "\" stroke-width=\"2\" points=\"";
    for (std::size_t i = 0; i < series[s].second.size(); ++i) {
      o << fx(i) << "," << fy(series[s].second[i]) << " ";
    }
    o << "\"/>\n";
    for (std::size_t i = 0; i < series[s].second.size(); ++i) {
      o << "<circle cx=\"" << fx(i) << "\" cy=\"" << fy(series[s].second[i]) << "\" r=\"3\" fill=\""
        << c << "\"/>\n";
    }
    o << "<line x1=\"" << W - R + 12 << "\" y1=\"" << T + 10 + 18 * s << "\" x2=\"" << W - R + 32
      << "\" y2=\"" << T + 10 + 18 * s << "\" stroke=\"" << c << "\" stroke-width=\"2\"/><text x=\""
      << W - R + 38 << "\" y=\"" << T + 14 + 18 * s << "\">" << series[s].first << "</text>\n";
  }
  o << "</svg>\n";
  return o.str();
}

}  // namespace

void runSlicingBench(const SlicingBenchOptions& o) {
  if (o.frames < 1) throw InputError("--frames must be >= 1");
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  auto context = gpu::GlContext::createHeadless();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(context->caps());
  std::vector<Scene> scenes;
  {
    Volume full = readVolume(spec);
    Volume small = resample(full, {128, 128, 186});
    scenes.push_back({"ch2 " + dimsText(full.dims()), std::move(full), nullptr});
    scenes.push_back({"ch2 resampled " + dimsText(small.dims()), std::move(small), nullptr});
  }
  for (Scene& s : scenes) {
    s.layout = layout::Texture3DLayout::create(s.volume, limits, context->ledger());
  }
  const std::vector<int> counts =
      o.quick ? std::vector<int>{10, 40} : std::vector<int>{10, 20, 40, 80};
  const std::vector<std::pair<int, int>> sizes =
      o.quick ? std::vector<std::pair<int, int>>{{480, 320}}
              : std::vector<std::pair<int, int>>{{480, 320}, {1024, 768}};

  // ---- Tables 1-2: ms/frame per technique, count and resolution.
  std::vector<SpeedRow> speed;
  std::vector<QualityRow> quality;
  for (Scene& scene : scenes) {
    const Volume& v = scene.volume;
    render::Raycaster caster(*context, v, *scene.layout);
    caster.setSkipBlockSize(0);  // the paper's ray caster: early termination only
    caster.setTransferFunction(tf);
    render::Raycaster skipping(*context, v, *scene.layout);
    skipping.setTransferFunction(tf);
    render::Slice3DRenderer slice3d(*context, v, *scene.layout);
    slice3d.setTransferFunction(tf);
    render::Slice2DRenderer slice2d(*context, v, {});
    slice2d.setTransferFunction(tf);
    render::Slice2DRenderer slice2dPre(*context, v,
                                       {.classification = render::SliceClassification::Pre});
    slice2dPre.setTransferFunction(tf);
    std::optional<Image> reference;
    for (int count : counts) {
      RenderSettings s = settingsForCount(v, count);
      slice3d.setSliceCount(count);
      slice2d.setSliceCount(count);
      slice2dPre.setSliceCount(count);
      std::vector<Technique> techniques{
          {"raycast", [&](const Camera& c, int w, int h) { caster.renderFrame(c, s, w, h); },
           [&] { return caster.readImage(); }},
          {"raycast+skip", [&](const Camera& c, int w, int h) { skipping.renderFrame(c, s, w, h); },
           [&] { return skipping.readImage(); }},
          {"slice3d", [&](const Camera& c, int w, int h) { slice3d.renderFrame(c, s, w, h); },
           [&] { return slice3d.readImage(); }},
          {"slice2d post", [&](const Camera& c, int w, int h) { slice2d.renderFrame(c, s, w, h); },
           [&] { return slice2d.readImage(); }},
          {"slice2d pre",
           [&](const Camera& c, int w, int h) { slice2dPre.renderFrame(c, s, w, h); },
           [&] { return slice2dPre.readImage(); }},
      };
      for (auto [w, h] : sizes) {
        // Warm-up (programs, tables, targets), then interleaved frames.
        for (Technique& t : techniques) t.frame(benchCamera(v), w, h);
        std::map<std::string, std::vector<double>> ms;
        for (int f = 0; f < o.frames; ++f) {
          Camera cam = benchCamera(v);
          cam.azimuthDeg += 10.0 * f;
          for (Technique& t : techniques) {
            const auto t0 = Clock::now();
            t.frame(cam, w, h);
            ms[t.name].push_back(msSince(t0));
          }
        }
        for (Technique& t : techniques) {
          speed.push_back({scene.name, t.name, w, h, count, median(ms[t.name])});
        }
        std::fprintf(stderr, "\r%s %d %dx%d done   ", scene.name.c_str(), count, w, h);
      }
      // Quality on the smaller volume at the smaller size, against the
      // reference at half-voxel steps without early termination.
      if (&scene == &scenes.back()) {
        const auto [w, h] = sizes.front();
        const Camera cam = benchCamera(v);
        RenderSettings refSettings;
        refSettings.ertThreshold = 1.0;
        if (!reference) reference = renderReference(v, tf, cam, refSettings, w, h);
        for (Technique& t : techniques) {
          t.frame(cam, w, h);
          const Image img = t.read();
          quality.push_back({t.name, count, psnr(img, *reference), ssim(img, *reference)});
        }
      }
    }
  }
  std::fprintf(stderr, "\r%60s\r", "");

  // ---- TF updates (Moser & Weiskopf 2008, Figure 6): TF changed -> frame ready.
  std::vector<TfRow> tfRows;
  {
    const Volume& source = scenes.front().volume;
    const std::vector<glm::ivec3> dimsList =
        o.quick ? std::vector<glm::ivec3>{{128, 128, 64}, {128, 128, 128}}
                : std::vector<glm::ivec3>{{128, 128, 32}, {128, 128, 64},  {128, 128, 128},
                                          {256, 256, 64}, {256, 256, 128}, {256, 256, 256}};
    TransferFunction tfB = tf;
    for (auto& p : tfB.opacities) p.alpha = std::min(1.0, p.alpha * 1.5);
    for (const glm::ivec3 dims : dimsList) {
      const Volume v = resample(source, dims);
      Camera cam = benchCamera(v);
      cam.azimuthDeg = 10;  // the y stack
      cam.elevationDeg = 10;
      RenderSettings s;
      struct Path {
        const char* name;
        render::Slice2DOptions options;
        bool recreate;
      };
      const std::vector<Path> paths{
          {"pre-classified RGBA, 3 stacks re-created",
           {.classification = render::SliceClassification::Pre},
           false},
          {"pre-classified RGBA, current stack only",
           {.classification = render::SliceClassification::Pre, .currentStackOnly = true},
           false},
          {"index + palette, re-created (GL_PALETTE8 way)",
           {.classification = render::SliceClassification::Palette},
           true},
          {"index + palette, palette upload only",
           {.classification = render::SliceClassification::Palette},
           false},
          {"post-classification, LUT upload only", {}, false},
      };
      for (const Path& p : paths) {
        render::Slice2DRenderer r(*context, v, p.options);
        r.setTransferFunction(tf);
        r.renderFrame(cam, s, 480, 320);
        // The update alone (classification + uploads, waited for), then the
        // frame it makes ready; summed, they are "TF changed -> frame ready".
        std::vector<double> frame, update;
        for (int i = 0; i < std::max(5, o.frames); ++i) {
          auto t0 = Clock::now();
          if (p.recreate) r.recreateStackTextures();
          r.setTransferFunction(i % 2 ? tf : tfB);
          r.prepare(cam, s);
          glFinishForBench();
          update.push_back(msSince(t0));
          t0 = Clock::now();
          r.renderFrame(cam, s, 480, 320);
          frame.push_back(msSince(t0));
        }
        tfRows.push_back({dims, p.name, median(frame), median(update)});
      }
      std::fprintf(stderr, "\rTF updates %s done   ", dimsText(dims).c_str());
    }
    std::fprintf(stderr, "\r%60s\r", "");
  }
  // The hitch of the one-stack mode when the view changes stack.
  double hitchMs = 0.0;
  std::string hitchVolume;
  {
    const Scene& scene = scenes.front();
    render::Slice2DRenderer r(*context, scene.volume, {.currentStackOnly = true});
    r.setTransferFunction(tf);
    Camera cam = benchCamera(scene.volume);
    cam.azimuthDeg = 10;
    r.renderFrame(cam, {}, 480, 320);
    cam.azimuthDeg = 80;  // the x stack
    r.renderFrame(cam, {}, 480, 320);
    hitchMs = r.lastStackUploadMs();
    hitchVolume = scene.name;
  }

  // ---- Report.
  std::ostringstream md;
  md << "GL: " << context->caps().renderer << " (" << context->caps().version << "); TF `" << o.tf
     << "`; camera azimuth 30, elevation 20; median of " << o.frames
     << " frames rotating 10 deg; texture3d layout; accumulation "
     << render::Slice3DRenderer(*context, scenes.front().volume, *scenes.front().layout)
            .accumulationFormat()
     << ".\n\n";
  for (const Scene& scene : scenes) {
    md << "### " << scene.name << ": ms/frame (fps)\n\n| technique | resolution |";
    for (int c : counts) md << " " << c << " |";
    md << "\n|---|---|";
    for (std::size_t i = 0; i < counts.size(); ++i) md << "---:|";
    md << "\n";
    for (const char* t : {"raycast", "raycast+skip", "slice3d", "slice2d post", "slice2d pre"}) {
      for (auto [w, h] : sizes) {
        md << "| " << t << " | " << w << "x" << h << " |";
        for (int c : counts) {
          for (const SpeedRow& r : speed) {
            if (r.volume == scene.name && r.technique == t && r.width == w && r.count == c) {
              md << " " << fmt("%.1f", r.ms) << " (" << fmt("%.1f", 1000.0 / r.ms) << ") |";
            }
          }
        }
        md << "\n";
      }
    }
    md << "\nslice3d ÷ raycast (time ratio; < 1 means slicing is faster):\n\n| resolution |";
    for (int c : counts) md << " " << c << " |";
    md << "\n|---|";
    for (std::size_t i = 0; i < counts.size(); ++i) md << "---:|";
    md << "\n";
    for (auto [w, h] : sizes) {
      md << "| " << w << "x" << h << " |";
      for (int c : counts) {
        double a = 0, b = 0;
        for (const SpeedRow& r : speed) {
          if (r.volume != scene.name || r.width != w || r.count != c) continue;
          if (r.technique == "slice3d") a = r.ms;
          if (r.technique == "raycast") b = r.ms;
        }
        md << " " << fmt("%.2f", a / b) << " |";
      }
      md << "\n";
    }
    md << "\n";
  }
  md << "### Quality vs the CPU reference (" << scenes.back().name << ", " << sizes.front().first
     << "x" << sizes.front().second << ", reference at 0.5-voxel steps): PSNR dB / SSIM\n\n"
     << "| technique |";
  for (int c : counts) md << " " << c << " |";
  md << "\n|---|";
  for (std::size_t i = 0; i < counts.size(); ++i) md << "---:|";
  md << "\n";
  for (const char* t : {"raycast", "raycast+skip", "slice3d", "slice2d post", "slice2d pre"}) {
    md << "| " << t << " |";
    for (int c : counts) {
      for (const QualityRow& q : quality) {
        if (q.technique == t && q.count == c) {
          md << " " << fmt("%.2f", q.psnrDb) << " / " << fmt("%.4f", q.ssimValue) << " |";
        }
      }
    }
    md << "\n";
  }
  md << "\n### TF update (slice2d, 480x320): host classification + uploads until the GPU has them, "
        "then the frame\n\n"
     << "| volume | path | update ms | frame ms | TF changed -> frame ready, ms |\n"
     << "|---|---|---:|---:|---:|\n";
  for (const TfRow& r : tfRows) {
    md << "| " << dimsText(r.dims) << " | " << r.path << " | " << fmt("%.1f", r.updateMs) << " | "
       << fmt("%.1f", r.frameMs) << " | " << fmt("%.1f", r.updateMs + r.frameMs) << " |\n";
  }
  md << "\nOne-stack mode (" << hitchVolume << "): changing from the y to the x stack re-creates "
     << "the x stack in " << fmt("%.1f", hitchMs) << " ms (the hitch).\n";
  std::printf("%s", md.str().c_str());

  if (!o.outDir.empty()) {
    const std::filesystem::path dir(o.outDir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "bench-slicing.md")
        << "# Texture slicing benchmark\n\nGenerated by `tessera bench --slicing --slicing-out "
           "docs`.\n\n"
        << md.str();
    std::vector<double> xs(counts.begin(), counts.end());
    std::vector<std::pair<std::string, std::vector<double>>> series;
    for (const Scene& scene : scenes) {
      for (const char* t : {"raycast", "slice3d", "slice2d post"}) {
        for (auto [w, h] : sizes) {
          std::vector<double> ys;
          for (int c : counts) {
            for (const SpeedRow& r : speed) {
              if (r.volume == scene.name && r.technique == t && r.width == w && r.count == c) {
                ys.push_back(r.ms);
              }
            }
          }
          series.push_back({std::string(t) + " " + std::to_string(w) + "x" + std::to_string(h) +
                                (&scene == &scenes.front() ? " ch2" : " 128²x186"),
                            ys});
        }
      }
    }
    std::ofstream(dir / "bench-slicing.svg")
        << svgChart("ms/frame vs steps (raycast) or slices (slicing), llvmpipe", "steps / slices",
                    "ms per frame (log)", xs, series, true);
    std::vector<double> zs;
    std::vector<std::pair<std::string, std::vector<double>>> tfSeries;
    for (const TfRow& r : tfRows) {
      if (r.dims.x != 128) continue;
      if (std::find(zs.begin(), zs.end(), r.dims.z) == zs.end()) zs.push_back(r.dims.z);
    }
    for (int xy : {128, 256}) {
      std::map<std::string, std::vector<double>> byPath;
      std::vector<std::string> order;
      for (const TfRow& r : tfRows) {
        if (r.dims.x != xy) continue;
        if (!byPath.count(r.path)) order.push_back(r.path);
        byPath[r.path].push_back(std::max(r.updateMs, 0.01));
      }
      for (const auto& p : order) {
        if (xy == 128) tfSeries.push_back({p.substr(0, 28) + " 128²", byPath[p]});
      }
    }
    std::ofstream(dir / "bench-slicing-tf.svg")
        << svgChart("TF update time vs z resolution (128x128xz), cf. Moser & Weiskopf Fig. 6",
                    "slices in z", "ms (log)", zs, tfSeries, true);
    std::fprintf(stderr, "wrote %s/bench-slicing.md, bench-slicing.svg, bench-slicing-tf.svg\n",
                 o.outDir.c_str());
  }
}

}  // namespace tessera::app
