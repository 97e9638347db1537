#!/usr/bin/env bash
# Configures and builds Tessera into build/ (Release, warnings as errors).
# Extra arguments are passed to `cmake --build` (e.g. --target tessera_cli).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DTESSERA_WERROR=ON >/dev/null
args=("$@")
# The Python module (build/python/tessera, docs/python.md) comes with the CLI,
# so that the README's Python commands work after scripts/run.sh.
if [[ " $* " == *" tessera_cli "* ]] && grep -q '^TESSERA_PYTHON:BOOL=ON' build/CMakeCache.txt; then
  args+=(--target tessera_python)
fi
cmake --build build -j"$(nproc)" "${args[@]}"
