#!/usr/bin/env bash
# Configures and builds Tessera into build/ (Release, warnings as errors).
# Extra arguments are passed to `cmake --build` (e.g. --target tessera_cli).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DTESSERA_WERROR=ON >/dev/null
cmake --build build -j"$(nproc)" "$@"
