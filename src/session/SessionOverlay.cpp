// The session's rules for a second volume over the first (docs/fusion.md),
// the same for every front end: what it goes over (the session's volume, or
// the pyramid a front end draws itself, such as the page's OME-Zarr store),
// the message without one, and a volume handed over in memory. The CLI and
// the desktop viewer open a named file (SessionOpen.cpp), the page hands its
// picked files over (addOverlay); none of them checks anything itself.
#include "tessera/core/Error.h"
#include "tessera/session/Session.h"

namespace tessera::session {

const Volume& Session::overlayAnatomy() const {
  if (drawn_) return drawn_->shape();
  if (!hasVolume()) throw InputError("open a volume first: an overlay goes over one");
  return shape();
}

void Session::addOverlay(std::shared_ptr<Volume> volume, const std::string& name,
                         const OverlayOptions& options) {
  const Volume& anatomy = overlayAnatomy();
  if (!volume) throw InputError("overlay " + name + ": no volume");
  setOverlay(makeOverlay(std::move(volume), name, options, anatomy));
}

}  // namespace tessera::session
