#pragma once
// The page's second volume over the first (docs/fusion.md): the picked
// files opened as the session's overlay, its look changed, the crosshair's
// probe. The session (session/Fusion.h, Session::setOverlay / probe) holds
// the logic; these only hand the page's files and numbers to it.
#include <nlohmann/json.hpp>

#include "WebSession.h"
#include "tessera/session/Fusion.h"

namespace tessera::web {

// Reads the picked files (the one that names the others, as
// loadPickedFiles) as the overlay over the open volume; drops them all.
// InputError on WebGL 1 (Session::setOverlay: no 3D textures), without a
// volume, or naming the file or option that is wrong; the previous overlay
// then stays.
void openPickedOverlay(WebSession& s, const session::OverlayOptions& options);
// The open overlay with another look (labels, table, colour map, alpha, window).
void restyleOverlay(WebSession& s, const session::OverlayOptions& options);
// {open, file, note, fusion_note, labels: [{value, name, color}] (labels
// only), options as the session's state holds them (overlayState)}.
nlohmann::json overlayJson(WebSession& s);
// The probe at voxel (x, y, z) of the slice views (their voxel space:
// sliceShape()): session::probeJson at the voxel's centre.
nlohmann::json probeAtVoxel(WebSession& s, const glm::ivec3& voxel);
// The slice views' voxel nearest to a world position (RAS+ mm), clamped to
// the volume.
glm::ivec3 voxelAtWorld(WebSession& s, const glm::dvec3& worldMm);

}  // namespace tessera::web
