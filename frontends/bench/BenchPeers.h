#pragma once
// `tessera bench --peers` and `tessera bench --web-peers`: the side-by-side
// benchmarks against other renderers, which live in the source tree because
// they drive other programs: bench/peers/peers.py (VTK 9.1's GPU and CPU
// mappers under xvfb-run, alternating with `tessera render`) and
// bench/web-peers/run.sh (the web page beside NiiVue and vtk.js in headless
// Chromium). The CLI finds the tree it was built from (or --source-dir),
// checks what each needs, and runs it (peers.py with this binary as Tessera;
// the web page is built from the tree by run.sh).
#include <CLI/CLI.hpp>

namespace tessera::app {

// Adds --peers, --web-peers, --source-dir and --peers-args to `tessera bench`.
void addPeersBenchOptions(CLI::App* bench);
// Runs the asked benchmark and returns true; false when neither was asked.
// A missing script or tool is an InputError naming it.
bool runPeersBenchIfAsked();

}  // namespace tessera::app
