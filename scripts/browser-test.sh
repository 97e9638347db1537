#!/usr/bin/env bash
# Browser test of the web viewer: builds it (scripts/web.sh), installs
# playwright-core from tests/browser/package-lock.json when missing, and runs
# tests/browser/viewer.test.mjs in Debian's headless Chromium. Needs the
# native CLI for the reference image: TESSERA_CLI (default build/tessera).
# Extra arguments go to the test (--bench: ch2 frame times at 512x512).
set -euo pipefail
cd "$(dirname "$0")/.."
export TESSERA_CLI=${TESSERA_CLI:-$PWD/build/tessera}
scripts/web.sh
if [ ! -d tests/browser/node_modules/playwright-core ]; then
  (cd tests/browser && npm ci --no-audit --no-fund)
fi
node tests/browser/viewer.test.mjs "$@"
