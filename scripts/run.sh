#!/usr/bin/env bash
# The main job for a newcomer: set up, build, render the default volume
# (the ch2 MRI head) to out/head.png and print its path and the time taken.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh --target tessera_cli
mkdir -p out
build/tessera render --out out/head.png "$@"
echo "image: $(pwd)/out/head.png"
