#pragma once
// One rendering session: the device and its profile, the volume source (a
// file, folder, store, URL or generated volume, or an array handed over
// without a copy), the settings (session/Settings.h, validated once), and the
// frames rendered from them through the layout and technique registries,
// with a streamed source refined by the one refinement loop
// (session/BrickRefinement.h). The CLI, the benchmarks, embedders
// (examples/embed) and the Python module drive it; none re-implements it.
// The interactive front ends (the desktop viewer, the web page) hold one
// too, on their window's or canvas's context: its view() is what they draw,
// its exploration() what the slice views, regions and grid show, and its
// state() what they save and restore.
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
#include "tessera/render/TechniqueRegistry.h"
#include "tessera/session/ChannelView.h"
#include "tessera/session/Exploration.h"
#include "tessera/session/Fusion.h"
#include "tessera/session/RenderRun.h"
#include "tessera/session/Settings.h"
#include "tessera/session/StreamedFrames.h"
#include "tessera/session/StreamedSeries.h"
#include "tessera/session/TimeSeries.h"
#include "tessera/session/VolumePyramid.h"
#include "tessera/viewer/Viewer.h"

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

// A session state file (what Session::saveState, `tessera render
// --save-state` and the viewers' Save state write), read and checked as far
// as the file goes: InputError "PATH: ..." when it is a folder, cannot be
// read, is not JSON, is not a state or is of another version. Its settings
// are checked by Settings::fromJson, its exploration by Exploration::restore.
nlohmann::json readStateFile(const std::string& path);

class Session {
 public:
  // A headless device (EGL) obeying `profile` (a built-in name or a JSON
  // file; gpu::openDevice), with the host budget of this process.
  explicit Session(const std::string& profile = "native");
  // A device opened by the caller (gpu::borrowDevice: a window's context,
  // the page's WebGL), current while the session is used.
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

  // Opens `spec` as a pyramid to explore it in the view (a store or
  // head:WxHxD read box by box, a file read in core and downsampled): the
  // view shows its overview, the finest level within the profile's overview
  // budget, and exploration() works on the whole pyramid. On error the
  // previous volume stays. A time series plays: in core when its level 0
  // fits a quarter of the host budget, else (or with the settings' layout
  // bricks, for a store) over bricks (openStreamedSeries): the view then
  // holds the time point's coarsest level (its histogram, window, camera and
  // overview) and the front end draws streamedFrames().
  void openInView(const std::string& spec, const OpenOptions& options = {});

  // A time series (a 4-D NIfTI): time point `options.time` is read now and
  // shown in core as open() would; the time points after it are read ahead
  // on the series' thread, as many as a quarter of the host budget holds
  // (at least the next one). Every time point is shown with the first one's
  // window (or the settings' window) so that values keep their colour over
  // time. InputError when `spec` holds one time point.
  void openSeries(const std::string& spec, const OpenOptions& options = {});
  // The same for `count` time points that `read` reads (files in memory,
  // the browser's dropped 4-D NIfTI), shown under `name`, from time point
  // `time`; read ahead as `reading` says (stepPlayback pumps an OnPump
  // series: one time point per call).
  void openSeries(int count, TimeSeries::Reader read, const std::string& name, int time = 0,
                  TimeSeries::Reading reading = TimeSeries::defaultReading());
  // openSeries of a store without a view and with a layout that streams
  // bricks (settings' layout bricks): the store's t axis plays streamed
  // (session/StreamedSeries.h), each time point drawn by run() and render()
  // through a bricks layout over that time point's pyramid alone, the next
  // ones opened and warmed ahead within the host budget
  // (SessionStreamedSeries.cpp). With a view, openInView opens it and
  // streamedFrames() draws it.
  void openStreamedSeries(const std::string& spec, const OpenOptions& options = {});
  // The store played over bricks (openStreamedSeries) with channels
  // `indices` (empty: every one) streamed together: per time point every
  // chosen channel's pyramid, read ahead together, drawn by
  // streamedFrames() as the bricks layout's channels (ChannelView::open
  // calls this). Their set (shapes, no voxels; omero colours, windows,
  // visibility); with fewer than 2 channels the set and nothing changed.
  // InputError when no store plays over bricks, or as readZarrChannels.
  ChannelSet streamChannels(const std::vector<int>& indices);
  // The shown time point's pyramids of the channels streamed (empty
  // unless streamChannels did).
  const StreamedSeries::Pyramids& streamedChannels() const;
  // A store's t axis over bricks that a front end draws itself (the page's
  // store over fetch(), whose reads never wait): time point t's pyramid is
  // opened by `at` and read ahead as StreamedSeries reads (its levels that
  // fit `warmBytes`, with the series' arrival when the front end fetches:
  // TimeSeries::setArrival on series()), as many held as `heldBytes` holds
  // at `warmBytes` each (at least 2). The session's own volume stays; the
  // shown time point's pyramid is drawnPyramid() (what an overlay aligns
  // with and probe() reads). A time point, a jump too, is shown only once
  // read: showTimePoint returns false until then. drawPyramid() ends it.
  // InputError for fewer than 2 time points or `time` out of range.
  void drawStreamedSeries(int count, StreamedSeries::SourceAt at, std::uint64_t warmBytes,
                          std::uint64_t heldBytes, const std::string& name, int time = 0,
                          TimeSeries::Reading reading = TimeSeries::defaultReading());
  // The open series (null when the volume is not one): the channel view's
  // when it plays one (ChannelView::series), a streamed one's read-ahead of
  // pyramids.
  TimeSeries* series();
  const TimeSeries* series() const { return const_cast<Session*>(this)->series(); }
  const StreamedSeries* streamedSeries() const { return streamedSeries_.get(); }
  int timePoint() const;  // the channel view's when it plays a series
  // Shows time point `t` when it has been read, keeping the view's camera,
  // window and look, and returns true; otherwise asks for it and returns
  // false (the time point shown stays). The exploration is of the time
  // point shown: its crosshair, region side and picked box carry over, and
  // a region or grid block in the 3D view is shown again from time point t
  // (of a series the front end draws, whose reads never wait: t is shown
  // once that box's level-0 chunks of t have arrived, asked for until then).
  // InputError without a series or for t out of range.
  bool showTimePoint(int t);
  // As showTimePoint, waiting for the read (headless runs, benchmarks).
  void waitTimePoint(int t);
  // Playback of the series (session/TimeSeries.h): called once per drawn
  // frame, it shows the next time point when it is due, read, and the
  // view has finished the frame of the one shown (not refining; over
  // bricks, once streamedFrames() drew it complete); the number of the
  // time point shown. `shownComplete`: whether a front end that draws the
  // frames itself (drawStreamedSeries) has drawn the shown time point whole
  // (all its bricks); until it has, the next one waits, a late frame once
  // it is due.
  Playback& playback() { return playback_; }
  int stepPlayback(double nowMs, bool shownComplete = true);

  bool hasVolume() const { return inCore_ != nullptr || streamed_ != nullptr; }
  // Read from a pyramid level by level and box by box, not held whole.
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
  std::shared_ptr<const lod::MultiresSource> sharedPyramid() const { return streamed_; }
  // The 3D view's frames of the streamed volume in an interactive front end
  // (session/StreamedFrames.h: a time series played over bricks), made on
  // first use.
  StreamedFrames& streamedFrames();
  bool hasStreamedFrames() const { return streamedFrames_ != nullptr; }
  const lod::VolumeSource& source() const;

  // Channels of an OME-Zarr store rendered together with
  // settings().channels over its omero defaults (docs/channels.md), on
  // the session's device; with `reference` the CPU reference's frame and
  // the PSNR between them. Independent of the volume opened.
  ChannelFrame renderChannels(const std::string& spec, int width, int height, bool reference,
                              int time = 0);

  // Channels shown together in the interactive front ends' channel lists
  // (session/ChannelView.h; docs/channels.md): read, edited and drawn here,
  // their state in settings().channels.
  ChannelView& channelView();
  bool hasChannelView() const { return channelView_ != nullptr; }

  // The default the session chose for the volume open now because the
  // user named no TF (session/ModalityDefault.h): "CT: default transfer
  // function ct-soft-tissue (modality CT), ...; --tf to change"; empty when
  // the settings' TF stayed. For the front end to show.
  const std::string& defaultNote() const { return defaultNote_; }

  // A preset chosen from a front end's menu (desktop, page): the look of
  // `--tf NAME` (session/ModalityDefault.h): the TF into the settings and
  // the view's editor, and the window by the rules there (the user's, the
  // volume's own, a clinical preset's, the value range).
  void choosePreset(const std::string& name);

  Settings& settings() { return settings_; }
  const Settings& settings() const { return settings_; }
  // Validated first; the session keeps its old settings on error. With a
  // view, they are applied to it (technique, camera, TF, window, mode and
  // the rest of the render settings, labels).
  void setSettings(Settings settings);
  // The settings as they are now: with a view, what the user set there.
  Settings currentSettings() const;

  // The interactive view (viewer/Viewer.h) on the session's device: frames
  // while the user moves (adaptive quality, progressive refinement), the TF
  // editor, window/level, the bounding box and lines. Made on first use
  // with the session's settings; the session's in-core volume is shown in it
  // shared, not copied, and so is every volume opened later.
  viewer::Viewer& view();
  bool hasView() const { return view_ != nullptr; }

  // A frame of width x height at the current settings, refined to the end
  // when streamed. An in-core volume's technique is kept between calls (the
  // volume uploaded once): made again when the volume, the image size or a
  // setting other than the camera and the TF changes, so that a front end
  // drawing frame after frame (the Python module's widget) pays for the
  // frame only. The image is the one run() draws for the same settings.
  Image render(int width, int height);
  // A run (frames, rotation, reference): what `tessera render` reports.
  RenderResult run(const RenderRequest& request);
  // The CPU reference of the current settings' view (in core only).
  Image renderReference(int width, int height);

  // A second volume over this one (session/Fusion.h, docs/fusion.md), aligned
  // by world coordinates, mixed into the ray march of run(), render() and
  // renderReference(). openOverlay needs the anatomy open; its note (no
  // overlap in world space) is overlay()->note. clearOverlay() removes it.
  // openOverlay opens a named file (SessionOpen.cpp; in the web build the
  // page hands files over instead and it refuses, WebSessionOverlay.cpp).
  void openOverlay(const std::string& spec, const OverlayOptions& options = {});
  // A volume in memory as the overlay (a page's picked files), with the
  // same rules and messages as openOverlay (SessionOverlay.cpp).
  void addOverlay(std::shared_ptr<Volume> volume, const std::string& name,
                  const OverlayOptions& options = {});
  void setOverlay(Overlay overlay);
  // What an overlay goes over: the pyramid a front end draws itself
  // (drawPyramid), else the session's volume (its shape: dims and index ->
  // world). InputError "open a volume first: an overlay goes over one".
  const Volume& overlayAnatomy() const;
  // A pyramid a front end draws itself (the page's OME-Zarr store over
  // fetch, bricked): overlays align with its shape, probe() reads its
  // voxels; null: the session's own volume again.
  // A series drawn by the front end (drawStreamedSeries) ends here.
  void drawPyramid(std::shared_ptr<const lod::MultiresSource> pyramid);
  // The pyramid the front end draws: drawPyramid's, or the shown time point's.
  const std::shared_ptr<const lod::MultiresSource>& drawnPyramid() const { return drawn_; }
  // The open overlay with a new look (labels, colour map, alpha, window),
  // its volume kept; InputError when none is open.
  void restyleOpenOverlay(const OverlayOptions& options);
  void clearOverlay();
  const Overlay* overlay() const { return overlay_.get(); }
  // The crosshair's reading at a world position (RAS+ mm): the anatomy's
  // value, the overlay's and its label's name (in core, or the exploration's
  // overview when the volume is explored in the view).
  ProbeResult probe(glm::dvec3 worldMm) const;

  // Exploring the volume at native resolution (session/Exploration.h):
  // made on first use for the volume open now (an in-core volume is its own
  // overview, shared; a streamed store's overview is the finest level the
  // profile's overview budget allows), forgotten when another one opens.
  Exploration& exploration();
  bool exploring() const { return exploration_ != nullptr; }
  // Explores another pyramid than the session's volume, one a front end
  // draws itself (the page's OME-Zarr store over fetch): its overview level
  // is read only when `overviewVoxels` > 0. Replaces the exploration.
  Exploration& explore(std::shared_ptr<const lod::MultiresSource> source,
                       std::uint64_t overviewVoxels, const std::string& label);
  // Explores what a front end that draws its own pyramid shows
  // (drawPyramid) at the time point shown: the shown time point's pyramid
  // of a series it draws over bricks (drawStreamedSeries), the session's
  // volume (that time point's level 0) of a series read in core
  // (openSeries), the drawn pyramid otherwise; no overview level is read.
  // Replaces the exploration; it follows each time point shown from then
  // on (showTimePoint). InputError when nothing is drawn.
  Exploration& exploreDrawn(const std::string& label);
  // Forgets the exploration (the next exploration() starts anew).
  void endExploration() {
    exploration_.reset();
    again_.reset();
  }

  // The session's state as JSON: {"version", "volume": {...}, "settings"
  // (currentSettings()), "exploration" (null until exploration() was used)}.
  nlohmann::json state() const;
  // Restores the settings of a state and, where the state has one, the
  // exploration of the volume open now (the volume is the caller's to open);
  // with a view, the region or grid block the state showed is shown again
  // and the camera is the state's.
  void restore(const nlohmann::json& state);
  // state() as a JSON file (its folder made), and restore() from one;
  // InputError naming the file when it cannot be read or written, is not
  // JSON or is not a session state (with what is wrong in it).
  void saveState(const std::string& path) const;
  void loadState(const std::string& path);
  // The state's "overlay" alone (session/Fusion.h overlayState): the open
  // overlay's file is restyled, another file opened; null or absent: kept.
  // restore() does this too; `render --state` takes the settings merged with
  // its options and the overlay from here.
  void restoreOverlay(const nlohmann::json& state);

  // A lost GPU context (SessionContext.cpp): a phone's browser takes the
  // page's WebGL context away when the app goes to the background, and a GPU
  // reset takes any context, with every GL object made on it. loseContext()
  // lets go of the session's GPU side (the view's, the exploration's zoom
  // swap, the channels' textures, render()'s technique) and of its device,
  // and keeps in host memory what it showed: the volume, the settings as the
  // view had them, the view's camera and its own knobs (quality, box and
  // axes, budgets, the clip plane that follows the camera, a label table),
  // the exploration (crosshair, grid, the region or block shown), the
  // overlay and the channels shown together (their voxels). Nothing draws
  // (GpuError) until restoreContext(device), on a new context, makes the
  // GPU side again from that: the same frame, nothing read again.
  void loseContext();
  bool contextLost() const { return lost_.has_value(); }
  void restoreContext(gpu::DeviceSession device);
  // The region or grid block the view showed when the context was lost,
  // shown again with its window and camera (the overview's camera kept to
  // go back to) once its level-0 voxels are held: by restoreContext itself
  // for the session's own volume; for a pyramid a front end draws itself
  // (drawPyramid: the page's store over fetch(), whose chunk cache may have
  // let the block's chunks go) by the front end once it draws it again.
  // False while chunks are wanted (MultiresSource::prefetch asked for them:
  // the front end fetches them and calls again); true once shown or when
  // nothing is left to show.
  bool showRegionAgain();
  bool regionAgainPending() const { return again_.has_value(); }

 private:
  // What the view holds beyond the settings, kept over a lost context.
  struct ViewKnobs {
    viewer::Quality quality = viewer::Quality::Adaptive;
    int maxVolumePixels = 0;
    bool showBoundingBox = true, showAxes = true;
    bool progressive = false;
    double frameBudgetMs = 12.0;
    bool clipPlaneFollowsCamera = false;
    double followingPlaneDistance = 0.0;
    std::optional<render::LabelTable> labels;
    render::QualityController::Options adaptive;  // its frame-time goal
    static ViewKnobs of(viewer::Viewer& view);
    void applyTo(viewer::Viewer& view) const;
  };
  struct Lost {
    bool hadView = false;
    ViewKnobs knobs;
    Camera camera;
    std::optional<ChannelView::Shown> channels;
  };
  // A region or grid block to show again (showRegionAgain).
  struct RegionAgain {
    ExploreStep step;
    Camera camera;
    ValueRange window;
  };
  std::optional<Lost> lost_;
  std::optional<RegionAgain> again_;

  // Several sessions on one thread each draw on their own context: every
  // entry point that touches GL makes it current first (a no-op when it is).
  void makeCurrent();
  void applyVolumeSettings();
  // A new time point's exploration given the last one's state (crosshair,
  // region side, picked box, grid): a region or block is read again from it.
  void showExplorationAgain(const nlohmann::json& state);
  void closeChannelView();
  bool applyModalityDefault(const Volume& v);  // true when it changed the TF
  void showDefaultInView(bool tfChanged);
  void applyToView();
  void applyCameraToView();
  void showInView();
  RenderRequest request(int width, int height) const;

  gpu::DeviceSession device_;
  Settings settings_;
  std::string name_;
  std::shared_ptr<lod::InCoreVolumeSource> inCore_;
  std::shared_ptr<const lod::MultiresSource> streamed_;
  std::unique_ptr<lod::VolumeSource> streamedView_;
  std::unique_ptr<nlohmann::json> region_;
  std::unique_ptr<TimeSeries> series_;
  std::unique_ptr<StreamedSeries> streamedSeries_;
  StreamedSeries::Pyramids streamedChannels_;  // streamChannels' of the time point shown
  bool showStreamedTimePoint(int t);
  bool showDrawnTimePoint(int t);
  // The region or grid block of the exploration that the view shows (null:
  // none, or the overview), drawn by the view rather than streamed frames.
  std::optional<lod::VoxelBox> boxInView() const;
  // That box when the exploration is of the drawn pyramid, which a series
  // the front end draws over bricks reads again from each time point.
  std::optional<lod::VoxelBox> drawnBoxInView() const;
  // Whether time point t's drawn pyramid holds drawnBoxInView()'s level-0
  // chunks (asked for otherwise); true when no box is in the view.
  bool drawnBoxArrived(int t) const;
  bool seriesDrawn_ = false;  // streamedSeries_ is drawn by the front end
  void openStreamedSeriesInView(const std::string& spec, const OpenOptions& options);
  // The voxels of the overview an exploration of the volume reads.
  std::uint64_t explorationOverviewVoxels() const;
  std::optional<ValueRange> seriesWindow_;
  // The modality default (session/ModalityDefault.h): whether the volume
  // came with its own window, what was chosen, the TF it replaced.
  bool ownWindow_ = false;
  std::string defaultNote_;
  std::optional<TransferFunction> tfBeforeDefault_;
  int timePoint_ = 0;
  Playback playback_;
  std::unique_ptr<Overlay> overlay_;
  std::shared_ptr<const lod::MultiresSource> drawn_;  // drawPyramid
  // Both go before device_ (declared first), while its context lives: the
  // view's GL objects and the exploration's zoom swap.
  std::unique_ptr<viewer::Viewer> view_;
  std::unique_ptr<Exploration> exploration_;
  std::unique_ptr<ChannelView> channelView_;  // its layout's textures too
  std::unique_ptr<StreamedFrames> streamedFrames_;
  // render()'s technique on the in-core volume (before device_ goes).
  struct Resident {
    std::shared_ptr<lod::InCoreVolumeSource> source;
    std::string key;
    render::TechniqueOnVolume technique;
  };
  std::unique_ptr<Resident> resident_;
};

}  // namespace tessera::session
