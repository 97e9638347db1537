#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "tessera/core/HostBudget.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/layout/ChannelLayouts.h"
#include "tessera/layout/LayoutRegistry.h"
#include "tessera/lod/ProceduralMultiresSource.h"
#include "tessera/render/Raycaster.h"
#include "tessera/session/RenderRun.h"

namespace tessera::app {

namespace {

struct PlanOptions {
  std::string file;
  std::string series;  // DICOM Series Instance UID
  std::string profile = "native";
  std::string layout = "auto";
  std::string size = "512x512";
  int skipBlock = 8;
  int channels = 0;  // > 0: also the bricks of that many channels
  bool json = false;
};

std::string dimsText(glm::ivec3 d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

nlohmann::json planJson(const layout::LayoutPlan& p) {
  nlohmann::json textures = nlohmann::json::array();
  for (const auto& t : p.textures) {
    textures.push_back({{"label", t.label},
                        {"size", {t.size.x, t.size.y, t.size.z}},
                        {"3d", t.is3D},
                        {"format", t.format},
                        {"bytes", t.bytes}});
  }
  return {{"layout", p.layout},
          {"fits", p.fits},
          {"textures", textures},
          {"total_bytes", p.totalBytes},
          {"reason", p.reason}};
}

void runPlan(const PlanOptions& o) {
  int width = 0, height = 0;
  parseSize(o.size, width, height);
  DeviceSession device = openDevice(o.profile);
  const std::string spec = o.file.empty() ? defaultVolumeSpec() : o.file;
  // A generated head:WxHxD is planned from its shape, as a streamed source.
  const bool streamed = lod::ProceduralMultiresSource::isSpec(spec);
  const Volume volume = streamed ? lod::ProceduralMultiresSource(spec).shape()
                                 : readVolume(spec, {.dicomSeries = o.series});
  // What the ray caster needs next to the volume, then the planner's choice.
  const render::TechniqueRequirements needs = render::Raycaster::requirements(
      device.limits, volume.dims(), {.imageSize = {width, height}, .skipBlock = o.skipBlock});
  const bool skipping = render::Raycaster::skipBlockFor(device.limits, o.skipBlock) > 0;
  layout::PlanRequest request;
  request.layout = o.layout;
  request.reservedUnits = needs.textureUnits;
  request.reservedBytes = needs.bytes;
  request.streamed = streamed;
  const layout::Plan plan = layout::planLayout(volume, device.limits, request);
  const gpu::DeviceLimits& l = device.limits;
  // With --shade: where the ray caster's gradient would come from (next to
  // the volume and the ray caster's own bytes; units as Raycaster::setGradient).
  const bool unitForGradient =
      static_cast<int>(plan.layout.textures.size()) + render::Raycaster::kOwnTextureUnits + 1 <=
      l.textureUnits;
  const layout::GradientPlan gradient =
      layout::planGradient(layout::GradientWish::Auto, plan.volumeDims, plan.layout.layout, l.api,
                           unitForGradient ? l.max3DTextureSize : 0, l.textureBudget,
                           plan.layout.totalBytes + needs.bytes);
  if (o.json) {
    nlohmann::json j;
    j["file"] = spec;
    j["dims"] = {volume.dims().x, volume.dims().y, volume.dims().z};
    j["type"] = std::string(scalarTypeName(volume.type()));
    j["profile"] = device.profile.name;
    j["limits"] = {{"api", l.api == gpu::ApiLevel::Gles2 ? "gles2" : "gles3"},
                   {"max_2d_texture_size", l.max2DTextureSize},
                   {"max_3d_texture_size", l.max3DTextureSize},
                   {"texture_units", l.textureUnits},
                   {"texture_budget", l.textureBudget},
                   {"host_budget", l.hostBudget}};
    j["plan"] = planJson(plan.layout);
    j["layout"] = plan.layout.layout;
    j["downsample"] = {plan.downsample.x, plan.downsample.y, plan.downsample.z};
    j["planned_dims"] = {plan.volumeDims.x, plan.volumeDims.y, plan.volumeDims.z};
    j["volume_texture_units"] = plan.volumeUnits;
    j["renderer_reserved_bytes"] = needs.bytes;
    j["empty_space_skipping"] = skipping;
    j["reason"] = plan.reason;
    j["shaded_gradient"] = {{"precomputed", gradient.precomputed},
                            {"bytes", gradient.precomputed ? gradient.texture.bytes : 0},
                            {"reason", gradient.reason}};
    if (!needs.note.empty()) j["note"] = needs.note;
    nlohmann::json rejected = nlohmann::json::array();
    for (const auto& r : plan.rejected) rejected.push_back(planJson(r));
    j["rejected"] = rejected;
    if (o.channels > 0) {
      j["channel_bricks"] = planJson(layout::channelBricksPlan(volume, l, o.channels));
    }
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  std::printf("volume   %s: %s %s (%s)\n", spec.c_str(), dimsText(volume.dims()).c_str(),
              std::string(scalarTypeName(volume.type())).c_str(),
              formatBytes(volume.byteSize()).c_str());
  std::printf("profile  %s: %s, 2D %d, 3D %d, %d units, textures %s, host %s\n",
              device.profile.name.c_str(), l.api == gpu::ApiLevel::Gles2 ? "gles2" : "gles3",
              l.max2DTextureSize, l.max3DTextureSize, l.textureUnits,
              l.textureBudget ? formatBytes(l.textureBudget).c_str() : "unlimited",
              l.hostBudget ? formatBytes(l.hostBudget).c_str() : "unlimited");
  std::printf("layout   %s\n", plan.layout.layout.c_str());
  for (const auto& t : plan.layout.textures) {
    std::printf(
        "texture  %-10s %s %s %s\n", t.label.c_str(),
        (t.is3D ? dimsText(t.size) : std::to_string(t.size.x) + "x" + std::to_string(t.size.y))
            .c_str(),
        t.format.c_str(), formatBytes(t.bytes).c_str());
  }
  std::printf("bytes    %s for the volume (%d of %d units), %s for the ray caster\n",
              formatBytes(plan.layout.totalBytes).c_str(),
              static_cast<int>(plan.layout.textures.size()), plan.volumeUnits,
              formatBytes(needs.bytes).c_str());
  if (plan.downsampled()) {
    std::printf("downsample %s -> %s\n", dimsText(plan.downsample).c_str(),
                dimsText(plan.volumeDims).c_str());
  }
  for (const auto& r : plan.rejected) {
    std::printf("not      %s: %s\n", r.layout.c_str(), r.reason.c_str());
  }
  if (!needs.note.empty()) std::printf("note     %s\n", needs.note.c_str());
  std::printf("reason   %s\n", plan.reason.c_str());
  std::printf("gradient with --shade: %s\n", gradient.reason.c_str());
  if (o.channels > 0) {
    std::printf("channels %s\n", layout::channelBricksPlan(volume, l, o.channels).reason.c_str());
  }
}

}  // namespace

void addPlanCommand(CLI::App& app) {
  auto o = std::make_shared<PlanOptions>();
  CLI::App* cmd = app.add_subcommand(
      "plan", "Show how a volume would be stored on a device: layout, textures, bytes and why");
  addVolumeOptions(cmd, o->file, o->series);
  addDefaultedOption(cmd, "--profile", o->profile,
                     "Device profile (tessera profiles) or FILE.json");
  addDefaultedOption(cmd, "--layout", o->layout, layout::LayoutRegistry::global().choices());
  addDefaultedOption(cmd, "--size", o->size,
                     "Image size the renderer must also fit (WIDTHxHEIGHT)");
  addDefaultedOption(cmd, "--skip-block", o->skipBlock, "Empty-space block size (0 = off)");
  addDefaultedOption(cmd, "--channels", o->channels,
                     "Also plan the bricks of this many channels of the volume's grid (0 = off)");
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->callback([o] { runPlan(*o); });
}

}  // namespace tessera::app
