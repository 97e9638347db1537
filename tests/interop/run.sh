#!/bin/sh
# Zarr v3 interoperability with npm's zarrita (tests/interop/zarrita.test.mjs).
# usage: tests/interop/run.sh [path/to/tessera]   (default build/tessera)
set -e
here=$(cd "$(dirname "$0")" && pwd)
cli=$(cd "$(dirname "${1:-$here/../../build/tessera}")" && pwd)/$(basename "${1:-tessera}")
cd "$here"
[ -d node_modules/zarrita ] || npm ci --no-audit --no-fund
TESSERA="$cli" exec node --test --test-reporter=spec zarrita.test.mjs
