#!/usr/bin/env bash
# Side-by-side browser benchmark of the web page against NiiVue and vtk.js
# (bench/web-peers/bench.mjs). Installs the pinned npm packages
# (package-lock.json: @niivue/niivue, @kitware/vtk.js, esbuild,
# playwright-core) with `npm ci` when missing, bundles the vtk.js page with
# esbuild, builds the web page (scripts/web.sh), then runs the bench in
# Debian's headless Chromium. Arguments go to bench.mjs, e.g.
#   bench/web-peers/run.sh --rounds 7 --frames 3 --steps 0.5,1
# Writes images, table.md and results.json to build-web/web-peers/ (--out).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
if [ ! -d "$here/node_modules/@kitware/vtk.js" ] || [ ! -d "$here/node_modules/@niivue/niivue" ] ||
   [ ! -d "$here/node_modules/esbuild" ] || [ ! -d "$here/node_modules/playwright-core" ]; then
  (cd "$here" && npm ci --no-audit --no-fund --loglevel=error)
fi
if [ ! -f "$here/dist/vtk-peer.js" ] || [ "$here/pages/vtk-entry.js" -nt "$here/dist/vtk-peer.js" ]; then
  (cd "$here" && node_modules/.bin/esbuild pages/vtk-entry.js --bundle --format=iife --minify \
     --outfile=dist/vtk-peer.js --log-level=warning)
fi
if [ -z "${TESSERA_SITE:-}" ]; then
  (cd "$here/../.." && scripts/web.sh)
fi
exec node "$here/bench.mjs" "$@"
