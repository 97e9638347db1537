// A store's t axis played over bricks in the 3D view: the session's
// streamed frames (session::StreamedFrames) of the time point shown, refined
// a step per window frame; the session moves playback on once the frame of
// the one shown is complete (Session::stepPlayback). Here the frame is only
// placed in the view, recorded for --play-record and reported.
#include <sys/resource.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "DesktopApp.h"
#include "tessera/core/HostBudget.h"

namespace tessera::desktop {

namespace {

double playSeconds(const DesktopApp& ds) {
  return ds.playStartMs < 0.0 ? 0.0 : (steadyNowMs() - ds.playStartMs) / 1000.0;
}

// Once per time point shown: its complete frame written (--play-record)
// and a line saying when.
void recordComplete(DesktopApp& ds) {
  session::Session& s = *ds.session;
  const int t = s.timePoint();
  if (ds.completeShows >= ds.timePointsShown || !s.streamedFrames().shownComplete(t)) return;
  ds.completeShows = ds.timePointsShown;
  if (ds.options.playRecord.empty()) return;
  char name[64];
  std::snprintf(name, sizeof name, "%04d-t%d.png", ds.timePointsShown, t);
  const std::filesystem::path dir(ds.options.playRecord);
  std::filesystem::create_directories(dir);
  s.streamedFrames().readImage().writePng((dir / name).string());
  std::printf("shown %d: time point %d complete at %.2f s, frame %d\n", ds.timePointsShown, t,
              playSeconds(ds), ds.frame);
}

std::uint64_t peakRssBytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;  // KiB on Linux
}

}  // namespace

bool drawStreamedFrames(DesktopApp& ds, const Rect& rect, int viewW, int viewH) {
  session::Session& s = *ds.session;
  if (!s.streamedSeries() || !s.streamed()) return false;
  if (ds.exploring() && ds.exploration().mode() != session::ExploreMode::Overview) return false;
  session::StreamedFrames& frames = s.streamedFrames();
  try {
    const gpu::Texture& frame = frames.render(viewW, viewH);
    // Row 0 of the frame is its bottom row: ImGui's v runs down.
    ImGui::GetBackgroundDrawList()->AddImage(
        reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(frame.id())), rect.p0, rect.p1,
        ImVec2(0.0f, 1.0f), ImVec2(1.0f, 0.0f));
    recordComplete(ds);
  } catch (const Error& e) {
    ds.error = e.what();
    return false;
  }
  const layout::BricksFrame& b = frames.lastBricks();
  char line[200];
  const int channels = s.streamedChannels().size();
  std::snprintf(line, sizeof line, "time point %d over bricks%s: %s, %d of %d bricks missing (%s)",
                s.timePoint(),
                channels > 1 ? (", " + std::to_string(channels) + " channels").c_str() : "",
                frames.complete() ? "complete" : "refining", b.missing, b.wanted,
                ds.context().caps().renderer.c_str());
  ds.status = line;
  return true;
}

bool playbackDone(const DesktopApp& ds) {
  if (ds.options.playTimePoints <= 0) return true;
  if (ds.timePointsShown < ds.options.playTimePoints) return false;
  return !ds.session->streamedSeries() || ds.completeShows >= ds.timePointsShown;
}

void printPlayback(const DesktopApp& ds) {
  const double seconds = playSeconds(ds);
  const session::Playback& play = ds.session->playback();
  // What the playback reached: frames drawn and time points shown per
  // second, and the frames where a due time point was not read yet.
  std::printf(
      "playback: %d frames, %d time points shown in %.2f s (%.1f frames/s, %.2f "
      "time points/s, asked %.1f), %llu late frames, %llu time points late, %d read ahead\n",
      ds.frame, ds.timePointsShown, seconds, ds.frame / seconds, ds.timePointsShown / seconds,
      play.fps(), static_cast<unsigned long long>(play.lateFrames()),
      static_cast<unsigned long long>(play.lateTimePoints()), ds.session->series()->keep() - 1);
  const gpu::MemoryLedger& ledger = const_cast<DesktopApp&>(ds).context().ledger();
  const std::uint64_t host = HostBudget::global().limitBytes();
  std::printf("budgets: textures peak %s of %s, host peak RSS %s of %s%s\n",
              formatBytes(ledger.peakBytes()).c_str(),
              ledger.budget() ? formatBytes(ledger.budget()).c_str() : "no limit",
              formatBytes(peakRssBytes()).c_str(), formatBytes(host).c_str(),
              ds.session->hasStreamedFrames()
                  ? (", over bricks: " +
                     std::to_string(ds.session->streamedFrames().layoutsMade()) + " layouts made")
                        .c_str()
                  : "");
}

}  // namespace tessera::desktop
