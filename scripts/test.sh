#!/usr/bin/env bash
# Sets up, builds everything (warnings as errors) and runs all tests; then
# the browser tests of the web viewer (scripts/browser-test.sh), the CPU
# layers' tests under ASan + UBSan (scripts/sanitize.sh; the GPU image tests
# run once, above) and a short fuzz run of every parser under ASan
# (scripts/fuzz.sh, FUZZ_SECONDS each, default 10).
set -euo pipefail
cd "$(dirname "$0")/.."
FUZZ_SECONDS=${FUZZ_SECONDS:-10}

timings=()
timed() {
  local name=$1 start=$SECONDS
  shift
  "$@"
  timings+=("$name $((SECONDS - start)) s")
}
ctest_build() { (cd build && ctest --output-on-failure --timeout 900 -j2); }

timed setup scripts/setup.sh
timed build scripts/build.sh
timed ctest ctest_build
timed python /usr/bin/python3 -m pytest -q -p no:cacheprovider python/tests  # import tessera (docs/python.md)
timed embed scripts/embed-test.sh  # examples/embed against an installed Tessera
timed readme scripts/readme-commands.sh  # every command the README shows
timed browser scripts/browser-test.sh  # web viewer in headless Chromium vs build/tessera
timed sanitize scripts/sanitize.sh
timed fuzz scripts/fuzz.sh "$FUZZ_SECONDS"
echo "test.sh timings: $(IFS=,; echo "${timings[*]}" | sed 's/,/, /g'); total ${SECONDS} s"
