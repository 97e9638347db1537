#!/usr/bin/env bash
# Builds the web viewer with Debian's emscripten into build-web/site/ and,
# with --serve [PORT], serves it on http://127.0.0.1:PORT/ (default 8080).
#   scripts/web.sh            build only
#   scripts/web.sh --serve    build, then serve until Ctrl-C
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${TESSERA_WEB_BUILD:-build-web}
export NODE_PATH=${NODE_PATH:-/usr/share/nodejs}  # Debian's emscripten needs acorn from here
command -v emcmake >/dev/null || { echo "web.sh: emscripten missing (scripts/setup.sh)" >&2; exit 1; }
# pako (the page's inflater for the io readers) and numcodecs (blosc and zstd
# for OME-Zarr stores), pinned by frontends/web/package-lock.json.
# The compressed-DICOM decoders (frontends/web/dicom-codecs.js) likewise.
if [ ! -f frontends/web/node_modules/pako/dist/pako_inflate.min.js ] || [ ! -f frontends/web/node_modules/numcodecs/dist/blosc.js ] ||
   [ ! -f frontends/web/node_modules/@cornerstonejs/codec-openjph/dist/openjphjs.wasm ] ||
   [ ! -f frontends/web/node_modules/@cornerstonejs/dicom-image-loader/dist/esm/codecs/jpeg.js ]; then
  (cd frontends/web && npm ci --no-audit --no-fund --loglevel=error)
fi
if [ ! -f "$BUILD/build.ninja" ] && [ ! -f "$BUILD/Makefile" ]; then
  gen=()
  command -v ninja >/dev/null && gen=(-G Ninja)
  emcmake cmake -S . -B "$BUILD" "${gen[@]}" -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build "$BUILD" -j"$(nproc)"
echo "web.sh: built $BUILD/site (index.html, tessera.js, tessera-core.js, tessera-core.wasm, examples/embed-web/)"
if [ "${1:-}" = "--serve" ]; then
  port=${2:-8080}
  echo "web.sh: serving http://127.0.0.1:$port/ (Ctrl-C stops)"
  exec python3 -m http.server "$port" --bind 127.0.0.1 --directory "$BUILD/site"
fi
