#include "bench/BenchPlayback.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "cli/Commands.h"
#include "tessera/core/Error.h"
#include "tessera/session/Session.h"

namespace tessera::app {

namespace {

struct PlaybackBenchOptions {
  std::string store;
  std::string profile = "gles3";
  std::string size = "512x512";
  int timePoints = 20;  // shown per run, after the first
  int rounds = 2;       // of each way, alternating
};

PlaybackBenchOptions& options() {
  static PlaybackBenchOptions o;
  return o;
}

// One way of playing, as the desktop viewer with --play-time-points.
struct PlayRun {
  int shown = 0;             // time points drawn complete after the first
  double seconds = 0;        // from the first's complete frame to the last's
  int layouts = 0;           // bricks layouts made
  int streamedIn = 0;        // time points streamed into a layout made before
  int draws = 0;             // frames drawn after the first time point's (refining ones too)
  double drawSeconds = 0.0;  // in render() for them (streaming, uploads, the ray march)
  std::uint64_t textureBytes = 0;
  std::size_t textures = 0;
  double rate() const { return seconds > 0.0 ? shown / seconds : 0.0; }
};

double nowMs() {
  using Clock = std::chrono::steady_clock;
  static const Clock::time_point start = Clock::now();
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

PlayRun play(const PlaybackBenchOptions& o, int width, int height, bool reuse) {
  session::Session s(o.profile);
  s.settings().layout = "bricks";
  s.openInView(o.store);
  if (!s.streamedSeries()) {
    throw InputError("--playback " + o.store + ": not a store with a t axis played over bricks");
  }
  s.view().camera().azimuthDeg = 30.0;
  s.view().camera().elevationDeg = 20.0;
  s.view().tfEditor().setTransferFunction(TransferFunction::preset("grey"));
  session::StreamedFrames& frames = s.streamedFrames();
  frames.reuseLayout = reuse;
  // As fast as the time points arrive and refine: the fastest rate asked.
  s.playback().setFps(120.0);
  s.playback().play(nowMs());
  PlayRun run;
  int shows = 0, recorded = -1;
  double first = 0.0;
  const double limitMs = nowMs() + 600000.0;
  while (run.shown < o.timePoints && nowMs() < limitMs) {
    const int before = s.timePoint();
    const int t = s.stepPlayback(nowMs());
    if (t != before) ++shows;
    // A frame is drawn unless the one shown is complete and unchanged.
    const bool draws = !(frames.complete() && frames.timePoint() == t);
    const double r0 = nowMs();
    frames.render(width, height);
    if (draws && shows > 0) {
      ++run.draws;
      run.drawSeconds += (nowMs() - r0) / 1000.0;
    }
    if (recorded == shows || !frames.shownComplete(t)) continue;
    recorded = shows;
    if (shows == 0) {
      first = nowMs();
    } else {
      run.shown = shows;
      run.seconds = (nowMs() - first) / 1000.0;
    }
  }
  run.layouts = frames.layoutsMade();
  run.streamedIn = frames.timePointsStreamedIn();
  run.textureBytes = s.device().context->ledger().totalBytes();
  run.textures = s.device().context->ledger().count();
  return run;
}

void runPlaybackBench(const PlaybackBenchOptions& o) {
  int width = 0, height = 0;
  parseSize(o.size, width, height);
  std::printf("store %s, %s, %dx%d, %d time points per run after the first, %d rounds\n",
              o.store.c_str(), o.profile.c_str(), width, height, o.timePoints, o.rounds);
  std::printf(
      "| round | way | time points | s | time points/s | frames drawn | s in them | layouts "
      "made | streamed in | textures | texture MiB |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<double> rates[2];
  for (int r = 0; r < o.rounds; ++r) {
    // Alternating, the first way first in even rounds: neither always
    // runs on a warmer page cache.
    for (int k = 0; k < 2; ++k) {
      const bool reuse = (k + r) % 2 == 1;
      const PlayRun run = play(o, width, height, reuse);
      rates[reuse ? 1 : 0].push_back(run.rate());
      std::printf("| %d | %s | %d | %.2f | %.2f | %d | %.2f | %d | %d | %zu | %.1f |\n", r + 1,
                  reuse ? "one atlas" : "a layout per time point", run.shown, run.seconds,
                  run.rate(), run.draws, run.drawSeconds, run.layouts, run.streamedIn, run.textures,
                  static_cast<double>(run.textureBytes) / (1 << 20));
      std::fflush(stdout);
    }
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2.0;
  };
  const double before = median(rates[0]), after = median(rates[1]);
  std::printf("median: a layout per time point %.2f time points/s, one atlas %.2f (x%.2f)\n",
              before, after, before > 0.0 ? after / before : 0.0);
}

}  // namespace

void addPlaybackBenchOptions(CLI::App* cmd) {
  PlaybackBenchOptions& o = options();
  cmd->add_option("--playback", o.store,
                  "A store with a t axis played over bricks as `view --bricks --play` plays it: "
                  "time points/s with one atlas for every time point and, alternating, with a "
                  "layout made for each");
  addDefaultedOption(cmd, "--playback-profile", o.profile, "With --playback: device profile");
  addDefaultedOption(cmd, "--playback-size", o.size, "With --playback: view size");
  addDefaultedOption(cmd, "--playback-time-points", o.timePoints,
                     "With --playback: time points shown per run after the first");
  addDefaultedOption(cmd, "--playback-rounds", o.rounds, "With --playback: rounds of each way");
}

bool runPlaybackBenchIfAsked() {
  const PlaybackBenchOptions& o = options();
  if (o.store.empty()) return false;
  if (o.timePoints < 1 || o.rounds < 1) {
    throw InputError("--playback-time-points and --playback-rounds must be >= 1");
  }
  runPlaybackBench(o);
  return true;
}

}  // namespace tessera::app
