#!/usr/bin/env bash
# Sets up, builds everything (warnings as errors) and runs all tests.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
cd build
ctest --output-on-failure --timeout 900 -j2
