#include "bench/BenchSlicing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include <glm/geometric.hpp>

#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/core/Timing.h"
#include "tessera/gpu/Draw.h"
#include "tessera/gpu/GlContext.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/layout/VolumeUpload.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/reference/ImageMetrics.h"
#include "tessera/reference/ReferenceRaycaster.h"
#include "tessera/render/Slice2DRenderer.h"
#include "tessera/render/Slice3DRenderer.h"
#include "tessera/render/TechniqueRegistry.h"

namespace tessera::app {

namespace {

using Clock = std::chrono::steady_clock;

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

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// A volume uploaded as texture3d, which every technique shares.
struct Scene {
  std::string name;
  layout::VolumeUpload upload;
  const Volume& volume() const { return *upload.volume; }
};

// A technique of the registry at one count, under its row name in the tables.
struct Contestant {
  std::string label;
  std::unique_ptr<render::Technique> technique;
};

// The counts (ray-casting steps, slices) and image sizes of the tables.
struct Grid {
  std::vector<int> counts;
  std::vector<std::pair<int, int>> sizes;
};

Camera benchCamera(const Volume& v) {
  return Camera::framing(v, 30, 20);
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

const char* const kRows[] = {"raycast", "raycast+skip", "slice3d", "slice2d post", "slice2d pre"};

std::unique_ptr<render::Technique> makeTechnique(gpu::GlContext& context,
                                                 const gpu::DeviceLimits& limits,
                                                 const std::string& name, const Volume& volume,
                                                 const layout::Layout* layout,
                                                 const render::TechniqueOptions& options,
                                                 const TransferFunction& tf) {
  std::unique_ptr<render::Technique> t =
      render::TechniqueRegistry::global().create(name, {.context = context,
                                                        .limits = limits,
                                                        .volume = volume,
                                                        .layout = layout,
                                                        .options = options});
  t->setTransferFunction(tf);
  return t;
}

// slice2d with its own interface (stack re-creation, upload timing), as the
// registry makes it.
std::unique_ptr<render::Slice2DRenderer> makeSlice2D(gpu::GlContext& context,
                                                     const gpu::DeviceLimits& limits,
                                                     const Volume& volume,
                                                     const render::TechniqueOptions& options,
                                                     const TransferFunction& tf) {
  auto t = render::Slice2DRenderer::create({.context = context,
                                            .limits = limits,
                                            .volume = volume,
                                            .layout = nullptr,
                                            .options = options});
  t->setTransferFunction(tf);
  return t;
}

// ch2 and its GRAPP 2012-sized resampling, each uploaded once.
std::vector<Scene> loadScenes(gpu::GlContext& context, const gpu::DeviceLimits& limits,
                              const std::string& spec) {
  Volume full = readVolume(spec);
  Volume small = resample(full, {128, 128, 186});
  std::vector<std::pair<std::string, Volume>> volumes;
  volumes.emplace_back("ch2 " + dimsText(full.dims()), std::move(full));
  volumes.emplace_back("ch2 resampled " + dimsText(small.dims()), std::move(small));
  std::vector<Scene> scenes;
  for (auto& [name, volume] : volumes) {
    const lod::InCoreVolumeSource source(std::move(volume));
    scenes.push_back({name, layout::uploadVolume(context, limits, source, {}, "texture3d")});
  }
  return scenes;
}

// The five rows of the tables at one count: the ray caster with early
// termination only (the paper's) and with skipping, slice3d, slice2d post-
// and pre-classified.
std::vector<Contestant> contestants(gpu::GlContext& context, const gpu::DeviceLimits& limits,
                                    const Scene& scene, const TransferFunction& tf, int count) {
  const std::pair<const char*, render::TechniqueOptions> rows[] = {
      {"raycast", {.skipBlock = 0}},
      {"raycast", {}},
      {"slice3d", {.slices = count}},
      {"slice2d", {.slices = count}},
      {"slice2d", {.slices = count, .classify = "pre"}}};
  std::vector<Contestant> list;
  for (std::size_t i = 0; i < std::size(rows); ++i) {
    list.push_back({kRows[i], makeTechnique(context, limits, rows[i].first, scene.volume(),
                                            scene.upload.layout.get(), rows[i].second, tf)});
  }
  return list;
}

// Warm-up (programs, tables, targets), then frames interleaved so that a
// shared machine's load falls on all alike; the median per technique.
void timeCell(std::vector<Contestant>& list, const Scene& scene, const RenderSettings& s, int count,
              int w, int h, int frames, std::vector<SpeedRow>& speed) {
  const Volume& v = scene.volume();
  for (Contestant& c : list) c.technique->render(benchCamera(v), s, w, h, 0.0);
  std::map<std::string, std::vector<double>> ms;
  for (int f = 0; f < frames; ++f) {
    Camera cam = benchCamera(v);
    cam.azimuthDeg += 10.0 * f;
    for (Contestant& c : list) {
      const auto t0 = Clock::now();
      c.technique->render(cam, s, w, h, 0.0);
      ms[c.label].push_back(msSince(t0));
    }
  }
  for (Contestant& c : list)
    speed.push_back({scene.name, c.label, w, h, count, median(ms[c.label])});
  std::fprintf(stderr, "\r%s %d %dx%d done   ", scene.name.c_str(), count, w, h);
}

// Quality against the reference at half-voxel steps without early termination.
void measureQuality(std::vector<Contestant>& list, const Volume& v, const TransferFunction& tf,
                    const RenderSettings& s, int count, std::pair<int, int> size,
                    std::optional<Image>& reference, std::vector<QualityRow>& quality) {
  const auto [w, h] = size;
  const Camera cam = benchCamera(v);
  RenderSettings refSettings;
  refSettings.ertThreshold = 1.0;
  if (!reference) reference = renderReference(v, tf, cam, refSettings, w, h);
  for (Contestant& c : list) {
    const Image img = c.technique->renderImage(cam, s, w, h);
    quality.push_back({c.label, count, psnr(img, *reference), ssim(img, *reference)});
  }
}

// GRAPP 2012 Tables 1-2: ms/frame per technique, count and resolution, and
// the quality on the smaller volume at the smaller size.
void measureTables(gpu::GlContext& context, const gpu::DeviceLimits& limits,
                   const std::vector<Scene>& scenes, const TransferFunction& tf, const Grid& grid,
                   int frames, std::vector<SpeedRow>& speed, std::vector<QualityRow>& quality) {
  for (const Scene& scene : scenes) {
    std::optional<Image> reference;
    for (int count : grid.counts) {
      const RenderSettings s = settingsForCount(scene.volume(), count);
      std::vector<Contestant> list = contestants(context, limits, scene, tf, count);
      for (auto [w, h] : grid.sizes) timeCell(list, scene, s, count, w, h, frames, speed);
      if (&scene == &scenes.back()) {
        measureQuality(list, scene.volume(), tf, s, count, grid.sizes.front(), reference, quality);
      }
    }
  }
  std::fprintf(stderr, "\r%60s\r", "");
}

// Moser & Weiskopf 2008, Figure 6: TF changed -> frame ready, per slice2d
// classification path and volume size.
std::vector<TfRow> measureTfUpdates(gpu::GlContext& context, const gpu::DeviceLimits& limits,
                                    const Volume& source, const TransferFunction& tf,
                                    const SlicingBenchOptions& o) {
  const std::vector<glm::ivec3> dimsList =
      o.quick ? std::vector<glm::ivec3>{{128, 128, 64}, {128, 128, 128}}
              : std::vector<glm::ivec3>{{128, 128, 32}, {128, 128, 64},  {128, 128, 128},
                                        {256, 256, 64}, {256, 256, 128}, {256, 256, 256}};
  TransferFunction tfB = tf;
  for (auto& p : tfB.opacities) p.alpha = std::min(1.0, p.alpha * 1.5);
  struct Path {
    const char* name;
    render::TechniqueOptions options;
    bool recreate;
  };
  const std::vector<Path> paths{
      {"pre-classified RGBA, 3 stacks re-created", {.classify = "pre"}, false},
      {"pre-classified RGBA, current stack only",
       {.classify = "pre", .currentStackOnly = true},
       false},
      {"index + palette, re-created (GL_PALETTE8 way)", {.classify = "palette"}, true},
      {"index + palette, palette upload only", {.classify = "palette"}, false},
      {"post-classification, LUT upload only", {}, false},
  };
  std::vector<TfRow> rows;
  for (const glm::ivec3 dims : dimsList) {
    const Volume v = resample(source, dims);
    const Camera cam = Camera::framing(v, 10, 10);  // the y stack
    const RenderSettings s;
    for (const Path& p : paths) {
      const auto t = makeSlice2D(context, limits, v, p.options, tf);
      render::Slice2DRenderer& r = *t;
      r.renderFrame(cam, s, 480, 320);
      // The update alone (classification + uploads, waited for), then the
      // frame it makes ready; summed, they are "TF changed -> frame ready".
      std::vector<double> frame, update;
      for (int i = 0; i < std::max(5, o.frames); ++i) {
        auto t0 = Clock::now();
        if (p.recreate) r.recreateStackTextures();
        r.setTransferFunction(i % 2 ? tf : tfB);
        r.prepare(cam, s);
        gpu::finish();  // an update's time includes its queued uploads
        update.push_back(msSince(t0));
        t0 = Clock::now();
        r.renderFrame(cam, s, 480, 320);
        frame.push_back(msSince(t0));
      }
      rows.push_back({dims, p.name, median(frame), median(update)});
    }
    std::fprintf(stderr, "\rTF updates %s done   ", dimsText(dims).c_str());
  }
  std::fprintf(stderr, "\r%60s\r", "");
  return rows;
}

// The hitch of the one-stack mode when the view changes stack (ms).
double measureStackHitch(gpu::GlContext& context, const gpu::DeviceLimits& limits,
                         const Scene& scene, const TransferFunction& tf) {
  const auto t = makeSlice2D(context, limits, scene.volume(), {.currentStackOnly = true}, tf);
  render::Slice2DRenderer& r = *t;
  Camera cam = benchCamera(scene.volume());
  cam.azimuthDeg = 10;
  r.renderFrame(cam, {}, 480, 320);
  cam.azimuthDeg = 80;  // the x stack
  r.renderFrame(cam, {}, 480, 320);
  return r.lastStackUploadMs();
}

// A "| technique | c1 | c2 |" table header over the counts.
void countsHeader(std::ostringstream& md, const char* first, const std::vector<int>& counts,
                  const char* second = nullptr) {
  md << "| " << first << " |" << (second ? std::string(" ") + second + " |" : "");
  for (int c : counts) md << " " << c << " |";
  md << "\n|---|" << (second ? "---|" : "");
  for (std::size_t i = 0; i < counts.size(); ++i) md << "---:|";
  md << "\n";
}

const SpeedRow* findSpeed(const std::vector<SpeedRow>& speed, const std::string& volume,
                          const std::string& technique, int width, int count) {
  for (const SpeedRow& r : speed) {
    if (r.volume == volume && r.technique == technique && r.width == width && r.count == count) {
      return &r;
    }
  }
  return nullptr;
}

void reportSpeed(std::ostringstream& md, const Scene& scene, const Grid& grid,
                 const std::vector<SpeedRow>& speed) {
  md << "### " << scene.name << ": ms/frame (fps)\n\n";
  countsHeader(md, "technique", grid.counts, "resolution");
  for (const char* t : kRows) {
    for (auto [w, h] : grid.sizes) {
      md << "| " << t << " | " << w << "x" << h << " |";
      for (int c : grid.counts) {
        if (const SpeedRow* r = findSpeed(speed, scene.name, t, w, c)) {
          md << " " << fmt("%.1f", r->ms) << " (" << fmt("%.1f", 1000.0 / r->ms) << ") |";
        }
      }
      md << "\n";
    }
  }
  md << "\nslice3d ÷ raycast (time ratio; < 1 means slicing is faster):\n\n";
  countsHeader(md, "resolution", grid.counts);
  for (auto [w, h] : grid.sizes) {
    md << "| " << w << "x" << h << " |";
    for (int c : grid.counts) {
      const SpeedRow* a = findSpeed(speed, scene.name, "slice3d", w, c);
      const SpeedRow* b = findSpeed(speed, scene.name, "raycast", w, c);
      md << " " << fmt("%.2f", (a ? a->ms : 0.0) / (b ? b->ms : 0.0)) << " |";
    }
    md << "\n";
  }
  md << "\n";
}

void reportQuality(std::ostringstream& md, const Scene& scene, const Grid& grid,
                   const std::vector<QualityRow>& quality) {
  md << "### Quality vs the CPU reference (" << scene.name << ", " << grid.sizes.front().first
     << "x" << grid.sizes.front().second << ", reference at 0.5-voxel steps): PSNR dB / SSIM\n\n";
  countsHeader(md, "technique", grid.counts);
  for (const char* t : kRows) {
    md << "| " << t << " |";
    for (int c : grid.counts) {
      for (const QualityRow& q : quality) {
        if (q.technique == t && q.count == c) {
          md << " " << fmt("%.2f", q.psnrDb) << " / " << fmt("%.4f", q.ssimValue) << " |";
        }
      }
    }
    md << "\n";
  }
}

void reportTfUpdates(std::ostringstream& md, const std::vector<TfRow>& tfRows,
                     const std::string& hitchVolume, double hitchMs) {
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
}

// bench-slicing.svg: ms/frame of three techniques per volume and size.
std::string speedChart(const std::vector<Scene>& scenes, const Grid& grid,
                       const std::vector<SpeedRow>& speed) {
  std::vector<double> xs(grid.counts.begin(), grid.counts.end());
  std::vector<std::pair<std::string, std::vector<double>>> series;
  for (const Scene& scene : scenes) {
    for (const char* t : {"raycast", "slice3d", "slice2d post"}) {
      for (auto [w, h] : grid.sizes) {
        std::vector<double> ys;
        for (int c : grid.counts) {
          if (const SpeedRow* r = findSpeed(speed, scene.name, t, w, c)) ys.push_back(r->ms);
        }
        series.push_back({std::string(t) + " " + std::to_string(w) + "x" + std::to_string(h) +
                              (&scene == &scenes.front() ? " ch2" : " 128²x186"),
                          ys});
      }
    }
  }
  return svgChart("ms/frame vs steps (raycast) or slices (slicing), llvmpipe", "steps / slices",
                  "ms per frame (log)", xs, series, true);
}

// bench-slicing-tf.svg: update time per path over the z resolution (128²).
std::string tfChart(const std::vector<TfRow>& tfRows) {
  std::vector<double> zs;
  for (const TfRow& r : tfRows) {
    if (r.dims.x != 128) continue;
    if (std::find(zs.begin(), zs.end(), r.dims.z) == zs.end()) zs.push_back(r.dims.z);
  }
  std::map<std::string, std::vector<double>> byPath;
  std::vector<std::string> order;
  for (const TfRow& r : tfRows) {
    if (r.dims.x != 128) continue;
    if (!byPath.count(r.path)) order.push_back(r.path);
    byPath[r.path].push_back(std::max(r.updateMs, 0.01));
  }
  std::vector<std::pair<std::string, std::vector<double>>> series;
  for (const auto& p : order) series.push_back({p.substr(0, 28) + " 128²", byPath[p]});
  return svgChart("TF update time vs z resolution (128x128xz), cf. Moser & Weiskopf Fig. 6",
                  "slices in z", "ms (log)", zs, series, true);
}

}  // namespace

void runSlicingBench(const SlicingBenchOptions& o) {
  if (o.frames < 1) throw InputError("--frames must be >= 1");
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  const TransferFunction tf = TransferFunction::fromPresetOrFile(o.tf);
  auto context = gpu::GlContext::createHeadless();
  const gpu::DeviceLimits limits = gpu::DeviceLimits::of(context->caps());
  const std::vector<Scene> scenes = loadScenes(*context, limits, spec);
  const Grid grid =
      o.quick ? Grid{{10, 40}, {{480, 320}}} : Grid{{10, 20, 40, 80}, {{480, 320}, {1024, 768}}};

  std::vector<SpeedRow> speed;
  std::vector<QualityRow> quality;
  measureTables(*context, limits, scenes, tf, grid, o.frames, speed, quality);
  const std::vector<TfRow> tfRows =
      measureTfUpdates(*context, limits, scenes.front().volume(), tf, o);
  const double hitchMs = measureStackHitch(*context, limits, scenes.front(), tf);

  std::ostringstream md;
  const render::TechniqueOptions defaults;
  const auto slice3d =
      render::Slice3DRenderer::create({.context = *context,
                                       .limits = limits,
                                       .volume = scenes.front().volume(),
                                       .layout = scenes.front().upload.layout.get(),
                                       .options = defaults});
  md << "GL: " << context->caps().renderer << " (" << context->caps().version << "); TF `" << o.tf
     << "`; camera azimuth 30, elevation 20; median of " << o.frames
     << " frames rotating 10 deg; texture3d layout; accumulation " << slice3d->accumulationFormat()
     << ".\n\n";
  for (const Scene& scene : scenes) reportSpeed(md, scene, grid, speed);
  reportQuality(md, scenes.back(), grid, quality);
  reportTfUpdates(md, tfRows, scenes.front().name, hitchMs);
  std::printf("%s", md.str().c_str());

  if (!o.outDir.empty()) {
    const std::filesystem::path dir(o.outDir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "bench-slicing.md")
        << "# Texture slicing benchmark\n\nGenerated by `tessera bench --slicing --slicing-out "
           "docs`.\n\n"
        << md.str();
    std::ofstream(dir / "bench-slicing.svg") << speedChart(scenes, grid, speed);
    std::ofstream(dir / "bench-slicing-tf.svg") << tfChart(tfRows);
    std::fprintf(stderr, "wrote %s/bench-slicing.md, bench-slicing.svg, bench-slicing-tf.svg\n",
                 o.outDir.c_str());
  }
}

}  // namespace tessera::app
