#!/usr/bin/env bash
# Configures build-asan-clang/ (clang-14, AddressSanitizer +
# UndefinedBehaviorSanitizer, warnings as errors, the libFuzzer targets on) and
# builds the given targets in it. One build serves both the sanitized tests
# (scripts/sanitize.sh) and the fuzzers (scripts/fuzz.sh), so the libraries
# they share (core, io, gpu) compile once per CI run, not twice.
#   scripts/asan-build.sh TARGET...        e.g. test_io fuzz_targets
#   scripts/asan-build.sh                  every target
#
# -O1 -gline-tables-only: readable reports with file:line, and a quick build.
# clang-14 compiles these sanitized builds in about 55 % of gcc's CPU time at
# -O1 (src/io/ZarrStore.cpp 18.7 s vs 32.3 s); gcc's own warnings are the
# plain build's job. With TESSERA_FUZZ the layers also carry libFuzzer's
# coverage hooks (-fsanitize=fuzzer-no-link); in a test executable the
# sanitizer runtime's default hooks do nothing.
set -euo pipefail
cd "$(dirname "$0")/.."
SANITIZE="-fsanitize=address,undefined -fno-omit-frame-pointer"
CC=clang-14 CXX=clang++-14 cmake -S . -B build-asan-clang -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DTESSERA_WERROR=ON -DTESSERA_FUZZ=ON -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
  -DCMAKE_CXX_FLAGS="$SANITIZE" -DCMAKE_EXE_LINKER_FLAGS="$SANITIZE" >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build build-asan-clang -j"$(nproc)" "${targets[@]}"
