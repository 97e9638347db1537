// tessera probe: what the crosshair reads at a world position (mm, RAS+):
// the anatomy's value, a fused overlay's value and its label's name
// (session::Session::probe, docs/fusion.md).
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "cli/FusionOptions.h"
#include "tessera/core/Error.h"
#include "tessera/session/Session.h"

namespace tessera::app {

namespace {

struct ProbeOptions {
  std::string file;
  std::string series;
  std::string at;
  bool json = false;
  FusionOptions fusion;
};

std::string vec3Text(glm::dvec3 v, const char* format) {
  char buf[128];
  std::snprintf(buf, sizeof buf, format, v.x, v.y, v.z);
  return buf;
}

std::string numberText(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

void printProbeText(const session::ProbeResult& r) {
  std::printf("position %s mm (RAS+: +x right, +y anterior, +z superior)\n",
              vec3Text(r.worldMm, "%.2f, %.2f, %.2f").c_str());
  std::printf("anatomy  voxel %s: %s\n", vec3Text(r.anatomyIndex, "(%.2f, %.2f, %.2f)").c_str(),
              r.inAnatomy ? ("value " + numberText(r.anatomyValue)).c_str() : "outside");
  if (!r.hasOverlay) return;
  const std::string value =
      r.inOverlay ? "value " + session::probeOverlayText(r) : std::string("outside");
  std::printf("overlay  voxel %s: %s\n", vec3Text(r.overlayIndex, "(%.2f, %.2f, %.2f)").c_str(),
              value.c_str());
}

void runProbe(const ProbeOptions& o) {
  const glm::dvec3 at = session::parseWorldPosition(o.at, "--at");
  session::Session session("native");
  session::OpenOptions open;
  open.series = o.series;
  open.hostVoxels = true;
  session.open(o.file, open);
  openFusion(session, o.fusion);
  const session::ProbeResult r = session.probe(at);
  if (o.json) {
    std::printf("%s\n", session::probeJson(r).dump(2).c_str());
  } else {
    printProbeText(r);
  }
}

}  // namespace

void addProbeCommand(CLI::App& app) {
  auto o = std::make_shared<ProbeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "probe",
      "What the crosshair reads at a world position: the volume's value there and, with "
      "--overlay, the overlay's value and label name");
  addVolumeOptions(cmd, o->file, o->series);
  cmd->add_option("--at", o->at,
                  "World position X,Y,Z in millimetres, RAS+ (+x towards the patient's right, "
                  "+y anterior, +z superior), as `tessera info` reports positions")
      ->required();
  cmd->add_flag("--json", o->json, "Print one JSON object instead of text");
  addFusionOptions(cmd, o->fusion);
  cmd->callback([o] { runProbe(*o); });
}

}  // namespace tessera::app
