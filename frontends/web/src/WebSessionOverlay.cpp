#include "WebOverlay.h"

#include <algorithm>
#include <memory>
#include <span>

#include <glm/common.hpp>

#include "tessera/core/Error.h"
#include "tessera/io/ByteSource.h"
#include "tessera/io/VolumeReader.h"
#include "tessera/reference/FusedVolume.h"

namespace tessera::web {

void openPickedOverlay(WebSession& s, const session::OverlayOptions& options) {
  std::vector<PickedFile> picked = s.takeFiles();
  MemoryFiles files;
  for (const PickedFile& f : picked) {
    files.add(f.name, std::span<const std::byte>(reinterpret_cast<const std::byte*>(f.bytes.get()),
                                                 f.size));
  }
  const std::string name = volumeFileAmong(files.names());
  auto volume = std::make_shared<Volume>(readVolume(*files.open(name), files));
  s.rendering().addOverlay(std::move(volume), name, options);
  s.zoomStop();  // the zoom swap's levels carry no overlay
}

void restyleOverlay(WebSession& s, const session::OverlayOptions& options) {
  s.rendering().restyleOpenOverlay(options);
}

nlohmann::json overlayJson(WebSession& s) {
  const session::Overlay* o = s.rendering().overlay();
  if (!o) return {{"open", false}};
  nlohmann::json j = session::overlayState(o);
  j["open"] = true;
  j["note"] = o->note;
  j["fusion_note"] = s.rendering().hasView() ? s.viewer().fusionNote() : "";
  const glm::ivec3 d = o->fused->volume->dims();
  j["dims"] = {d.x, d.y, d.z};
  j["labels_table"] = nlohmann::json::array();
  for (const auto& [value, label] : o->labels.labels) {
    j["labels_table"].push_back({{"value", value},
                                 {"name", label.name},
                                 {"color", {label.color.r, label.color.g, label.color.b}}});
  }
  return j;
}

nlohmann::json probeAtVoxel(WebSession& s, const glm::ivec3& voxel) {
  const glm::dvec3 world = s.sliceShape().worldOf(glm::dvec3(voxel));
  return session::probeJson(s.rendering().probe(world));
}

glm::ivec3 voxelAtWorld(WebSession& s, const glm::dvec3& worldMm) {
  const Volume& v = s.sliceShape();
  const glm::dvec3 i = glm::floor(indexOfWorld(v, worldMm) + 0.5);
  return glm::clamp(glm::ivec3(i), glm::ivec3(0), v.dims() - 1);
}

}  // namespace tessera::web

namespace tessera::session {

// The page reads no named files (SessionOpen.cpp is not in the web build):
// a state naming an overlay other than the open one (Session::restore)
// says how to open it.
void Session::openOverlay(const std::string& spec, const OverlayOptions&) {
  throw InputError("the overlay " + spec +
                   " is not open in the page: add it with \"Add overlay…\" first");
}

}  // namespace tessera::session
