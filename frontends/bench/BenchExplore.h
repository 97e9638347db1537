#pragma once
// `tessera bench --explore`: the shape of Schultz 2016 Tables 1-4 on a
// generated volume (head:512x512x894 by default): the full volume (where
// the profile holds it), the downscaled overview (level 1), the grid view's
// 2x2x2 block of the paper's 4x4x4 split at native resolution, and a 256^3
// bread-slice region at native resolution; sagittal, frontal and spin views
// at zoom 1 and 1.5 (and min value 0 / 0.84 for the fixed views): ms per
// frame and texture bytes, as a Markdown table.
#include <CLI/CLI.hpp>

namespace tessera::app {

// Adds --explore and its options to `tessera bench`.
void addExploreBenchOptions(CLI::App* bench);
// Runs the benchmark if --explore was given; false otherwise.
bool runExploreBenchIfAsked();

}  // namespace tessera::app
