#pragma once
// `tessera bench --playback STORE`: a store's t axis played over bricks as
// the desktop viewer plays it (`view STORE --bricks --play`: the session's
// streamedFrames() a step per frame, Session::stepPlayback moving on once
// the time point shown is drawn complete), with each time point streamed
// into the one atlas kept on the GPU and, alternating in the same run, with
// a layout made for every time point (StreamedFrames::reuseLayout false,
// the way it was): time points per second of each, their ratio, the
// layouts made and the textures held.
#include <CLI/CLI.hpp>

namespace tessera::app {

// Adds --playback and its options to `tessera bench`.
void addPlaybackBenchOptions(CLI::App* bench);
// Runs the benchmark if --playback was given; false otherwise.
bool runPlaybackBenchIfAsked();

}  // namespace tessera::app
