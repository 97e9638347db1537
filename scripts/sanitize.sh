#!/usr/bin/env bash
# Builds Tessera's CPU layers and their tests with AddressSanitizer +
# UndefinedBehaviorSanitizer (clang-14, warnings as errors) into
# build-asan-clang/ (scripts/asan-build.sh, the build the fuzzers use too) and
# runs them: core, io (every reader and the bad-input corpus), lod and the CPU
# reference. The GPU image tests run once, in the plain build (test.sh);
# the parsers are fuzzed under ASan as well (scripts/fuzz.sh).
#   scripts/sanitize.sh            the CPU layers' tests
#   scripts/sanitize.sh --all      every test, the GPU ones too (slow)
# Further arguments go to ctest (e.g. -R BadCorpus).
#
# Leak detection is off: Mesa's llvmpipe (the headless GL the GPU tests use)
# keeps allocations until exit by design. Any UBSan report fails the test
# that triggered it (halt_on_error).
set -euo pipefail
cd "$(dirname "$0")/.."
targets=(test_core test_io test_lod test_reference)
skip=(-E _NOT_BUILT)  # ctest's stand-in for the test executables not built here
if [ "${1:-}" = "--all" ]; then
  targets=()
  skip=()
  shift
fi
scripts/asan-build.sh "${targets[@]}"  # shared with scripts/fuzz.sh
cd build-asan-clang
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
ctest --output-on-failure --timeout 900 -j"$(nproc)" "${skip[@]}" "$@"
