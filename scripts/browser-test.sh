#!/usr/bin/env bash
# Browser tests of the web viewer: builds it (scripts/web.sh), installs
# playwright-core from tests/browser/package-lock.json when missing, and runs
# every tests/browser/*.test.mjs with node's test runner in Debian's
# headless Chromium, one file at a time (each launches its own Chromium;
# tests/browser/fixture.mjs). Needs the native CLI for the reference images:
# TESSERA_CLI (default build/tessera).
#   scripts/browser-test.sh                 all of them
#   scripts/browser-test.sh store explore   only store.test.mjs and explore.test.mjs
#   scripts/browser-test.sh --bench         also ch2 frame times at 512x512 (render.test.mjs)
set -euo pipefail
cd "$(dirname "$0")/.."
export TESSERA_CLI=${TESSERA_CLI:-$PWD/build/tessera}
files=()
for a in "$@"; do
  case "$a" in
    --bench) export TESSERA_BENCH=1 ;;
    *) files+=("tests/browser/$a.test.mjs") ;;
  esac
done
[ ${#files[@]} -gt 0 ] || files=(tests/browser/*.test.mjs)
scripts/web.sh
if [ ! -d tests/browser/node_modules/playwright-core ]; then
  (cd tests/browser && npm ci --no-audit --no-fund)
fi
# One file at a time: two Chromiums rendering with SwiftShader on the same
# cores would make the timing checks (input during slow frames) flaky.
start=$(date +%s)
status=0
node --test --test-concurrency=1 --test-reporter=spec "${files[@]}" || status=$?
echo "browser-test: $(( $(date +%s) - start )) s, exit $status"
exit $status
