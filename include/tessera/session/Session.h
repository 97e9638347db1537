#pragma once
// One rendering session: the device and its profile, the volume source (a
// file, folder, store, URL or generated volume, or an array handed over
// without a copy), the settings (session/Settings.h, validated once), and the
// frames rendered from them through the layout and technique registries,
// with a streamed source refined by the one refinement loop
// (session/BrickRefinement.h). The CLI, the benchmarks, embedders
// (examples/embed) and the Python module drive it; none re-implements it.
//
//   tessera::session::Session s("webgl1");
//   s.open("/usr/share/mricron/templates/ch2.nii.gz");
//   s.settings().camera.azimuthDeg = 90;
//   s.render(512, 512).writePng("out/head.png");
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "tessera/core/Image.h"
#include "tessera/core/Volume.h"
#include "tessera/gpu/DeviceSession.h"
#include "tessera/lod/InCoreVolumeSource.h"
#include "tessera/lod/MultiresSource.h"
#include "tessera/session/Exploration.h"
#include "tessera/session/RenderRun.h"
#include "tessera/session/Settings.h"
#include "tessera/session/VolumePyramid.h"

namespace tessera::session {

struct OpenOptions {
  std::string series;  // DICOM Series Instance UID (a folder of several series)
  int time = 0;        // OME-Zarr time point and channel
  int channel = 0;
  // Render only this box (x0:x1,y0:y1,z0:z1, end exclusive) of `level`
  // (native = 0, the finest), read as one box: a store reads only the
  // chunks it touches. Ends past the level are clamped (with a note).
  std::string region;
  std::string level = "native";
  // The caller needs the voxels in host memory (the CPU reference, the
  // hybrid compositor, the FCC resampling): a store is then read in core.
  bool hostVoxels = false;
};

class Session {
 public:
  // A headless device (EGL) obeying `profile` (a built-in name or a JSON
  // file; gpu::openDevice), with the host budget of this process.
  explicit Session(const std::string& profile = "native");
  // A device opened by the caller (a window's context, the page's WebGL).
  explicit Session(gpu::DeviceSession device);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  gpu::DeviceSession& device() { return device_; }

  // A file, DICOM folder, OME-Zarr store (folder or URL) or generated
  // volume ("gen:sphere:64", "head:1024x1024x512"). A store the device
  // cannot hold in core, or one asked to stream (layout bricks), is read
  // brick by brick as views need it; anything else is read in core. The
  // settings must be set first (the layout wish and technique decide).
  void open(const std::string& spec, const OpenOptions& options = {});
  // A volume in memory, moved in or shared (never copied).
  void setVolume(Volume volume, const std::string& name = "array");
  void setVolume(std::shared_ptr<Volume> volume, const std::string& name = "array");

  bool hasVolume() const { return inCore_ != nullptr || streamed_ != nullptr; }
  bool streamed() const { return streamed_ != nullptr; }
  const std::string& name() const { return name_; }
  // The volume's shape and geometry (its voxels when in core).
  const Volume& shape() const;
  // In core only: the volume itself (InputError when streamed).
  const Volume& volume() const;
  // What --region read, level and chunks (null without a region).
  const nlohmann::json& regionReport() const;
  // A streamed store's pyramid (null otherwise), e.g. for its fetch counts.
  const lod::MultiresSource* pyramid() const { return streamed_.get(); }
  const lod::VolumeSource& source() const;

  Settings& settings() { return settings_; }
  const Settings& settings() const { return settings_; }
  // Validated first; the session keeps its old settings on error.
  void setSettings(Settings settings);

  // A frame of width x height at the current settings, refined to the end
  // when streamed.
  Image render(int width, int height);
  // A run (frames, rotation, reference): what `tessera render` reports.
  RenderResult run(const RenderRequest& request);
  // The CPU reference of the current settings' view (in core only).
  Image renderReference(int width, int height);

  // Exploring the volume at native resolution (session/Exploration.h):
  // made on first use for the volume open now (an in-core volume is its own
  // overview, shared; a streamed store's overview is the finest level the
  // profile's overview budget allows), forgotten when another one opens.
  Exploration& exploration();

  // The session's state as JSON: {"version", "volume": {...}, "settings",
  // "exploration" (null until exploration() was used)}.
  nlohmann::json state() const;
  // Restores the settings of a state and, where the state has one, the
  // exploration of the volume open now (the volume is the caller's to open).
  void restore(const nlohmann::json& state);

 private:
  void applyVolumeSettings();
  RenderRequest request(int width, int height) const;

  gpu::DeviceSession device_;
  Settings settings_;
  std::string name_;
  std::shared_ptr<lod::InCoreVolumeSource> inCore_;
  std::shared_ptr<const lod::MultiresSource> streamed_;
  std::unique_ptr<lod::VolumeSource> streamedView_;
  std::unique_ptr<nlohmann::json> region_;
  std::unique_ptr<Exploration> exploration_;
};

}  // namespace tessera::session
