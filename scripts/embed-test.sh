#!/usr/bin/env bash
# Installs Tessera from build/ into a temporary prefix and builds
# examples/embed against that prefix alone, then runs it: the GPU frame must
# be written as a PNG and match the CPU reference (>= 40 dB, the example's
# exit code). Checks that neither the installed package nor the example's
# build refers to this source tree, so a consumer needs only the prefix.
# EMBED_KEEP=1 keeps the temporary directory.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
start=$SECONDS

# The existing build/ (scripts/build.sh configures it the same way); only
# what the install needs is built: the CLI, and through it every layer.
if [[ ! -f build/CMakeCache.txt ]]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DTESSERA_WERROR=ON >/dev/null
else
  cmake -S . -B build >/dev/null
fi
cmake --build build -j"$(nproc)" --target tessera_cli >/dev/null

TMP=$(mktemp -d "${TMPDIR:-/tmp}/tessera-embed.XXXXXX")
if [[ -z "${EMBED_KEEP:-}" ]]; then trap 'rm -rf "$TMP"' EXIT; fi
PREFIX=$TMP/prefix
cmake --install build --prefix "$PREFIX" >/dev/null

fail() { echo "embed-test: $*" >&2; exit 1; }
leaks=$(grep -rlF "$ROOT" "$PREFIX/lib/cmake" || true)
[[ -z "$leaks" ]] || fail "installed package files name the source/build tree $ROOT: $leaks"

# A copy of the example outside the tree: its quoted includes cannot reach
# include/ here, and the package registry is off, so only PREFIX can serve.
cp -r examples/embed "$TMP/src"
cmake -S "$TMP/src" -B "$TMP/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PREFIX" \
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DCMAKE_CXX_FLAGS="-Wall -Wextra -Werror" >/dev/null
grep -qxF "Tessera_DIR:PATH=$PREFIX/lib/cmake/Tessera" "$TMP/build/CMakeCache.txt" ||
  fail "find_package(Tessera) did not resolve to $PREFIX: $(grep '^Tessera_DIR' "$TMP/build/CMakeCache.txt")"
cmake --build "$TMP/build" -j"$(nproc)" >/dev/null
# The compiler's dependency files list every header the example used.
leaks=$(grep -rlF "$ROOT" "$TMP/build" || true)
[[ -z "$leaks" ]] || fail "the example's build used files of $ROOT: $leaks"

rc=0
"$TMP/build/tessera_embed" "$TMP/embed.png" || rc=$?
[[ -s "$TMP/embed.png" ]] || fail "no PNG written at $TMP/embed.png"
[[ "$(head -c 8 "$TMP/embed.png" | od -An -tx1 | tr -d ' \n')" == 89504e470d0a1a0a ]] ||
  fail "$TMP/embed.png is not a PNG"
[[ $rc -eq 0 ]] || fail "tessera_embed exited $rc (PSNR below 40 dB or an error above)"
echo "embed-test: OK, installed $(find "$PREFIX/lib" -name 'libtessera_*.a' | wc -l) layer libraries," \
  "example built against $PREFIX only; $((SECONDS - start)) s"
