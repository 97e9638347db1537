#!/usr/bin/env bash
# Builds Tessera and its tests with AddressSanitizer + UndefinedBehaviorSanitizer
# (gcc, warnings as errors) into build-asan/ and runs the whole test suite.
# Extra arguments go to ctest (e.g. -R BadCorpus).
#
# Leak detection is off: Mesa's llvmpipe (the headless GL the GPU tests use)
# keeps allocations until exit by design. Any UBSan report fails the test
# that triggered it (halt_on_error).
set -euo pipefail
cd "$(dirname "$0")/.."
SANITIZE="-fsanitize=address,undefined -fno-omit-frame-pointer"
# GCC's -Wmaybe-uninitialized is unreliable with sanitizers (it fires inside
# libstdc++'s <regex> and <functional> here); every other warning stays an error.
QUIET="-Wno-maybe-uninitialized"
# -O1 -g1: readable reports with file:line, and the quickest sanitizer build.
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTESSERA_WERROR=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DCMAKE_CXX_FLAGS="$SANITIZE $QUIET" \
  -DCMAKE_EXE_LINKER_FLAGS="$SANITIZE" >/dev/null
cmake --build build-asan -j"$(nproc)"
cd build-asan
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
ctest --output-on-failure --timeout 900 -j"$(nproc)" "$@"
