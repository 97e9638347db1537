// Side-by-side browser benchmark: Tessera's web page
// (build-web/site, WebGL 2 and WebGL 1), vtk.js 37.4 (vtkVolumeMapper,
// WebGL 2) and NiiVue 0.69 (WebGL 2) in ONE headless Chromium (Debian's,
// SwiftShader through ANGLE), each in its own tab, showing the same volume
// with the same transfer function, camera (orthographic: NiiVue's own
// projection) and 512x512 canvas, at the same ray step. Rounds alternate
// the viewers (the order rotates every round); a viewer's round is the
// median of a few frames, each timed up to a 1-pixel read-back (glFinish
// returns at once in Chrome). Reports medians over rounds, ratios, and the
// PSNR of each viewer's image against Tessera WebGL 2's, so that the
// viewers are seen to draw the same picture.
//
//   node bench.mjs [--rounds N] [--frames N] [--steps 0.5,1] [--out DIR]
//                  [--only tessera2,vtk,...] [--query EXTRA] [--baseline SITE]
//                  [--variants post,fixed,...]
//
// --baseline SITE adds another build of the page (e.g. the commit before a
// fix, built with scripts/web.sh and copied) as two more viewers in the
// same rounds, so that a fix's gain is measured alternating too.
// --variants adds Tessera WebGL 2 tabs with the page's sampling controls set
// otherwise than its default (adaptive steps, post-classified):
// `preint` (pre-integrated and adaptive: `tessera render`'s default), `fixed`
// (pre-integrated, every step), `plain` (post-classified samples at exactly
// the step).
//
// run.sh installs the pinned packages (npm ci), bundles the vtk.js page and
// builds the web page first. Environment: TESSERA_SITE (default
// build-web/site), CH2 (default /usr/share/mricron/templates/ch2.nii.gz),
// CHROMIUM (default /usr/bin/chromium).
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import http from 'node:http';
import zlib from 'node:zlib';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.resolve(here, '../..');
const site = process.env.TESSERA_SITE || path.join(root, 'build-web/site');
const volumeFile = process.env.CH2 || '/usr/share/mricron/templates/ch2.nii.gz';
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';
const SIZE = 512;

function arg(name, fallback) {
  const i = process.argv.indexOf(`--${name}`);
  return i >= 0 && i + 1 < process.argv.length ? process.argv[i + 1] : fallback;
}
const rounds = Math.max(1, parseInt(arg('rounds', '7'), 10));
const framesPerRound = Math.max(1, parseInt(arg('frames', '3'), 10));
const steps = arg('steps', '0.5,1').split(',').map(Number);
const outDir = path.resolve(arg('out', path.join(root, 'build-web/web-peers')));
const only = arg('only', '') ? arg('only', '').split(',') : null;
const extraQuery = arg('query', '');
const baselineSite = arg('baseline', '') ? path.resolve(arg('baseline', '')) : '';
const SAMPLING_VARIANTS = {
  preint: { preint: true, adaptive: true, label: 'pre-integrated, adaptive' },
  fixed: { preint: true, adaptive: false, label: 'pre-integrated, fixed step' },
  plain: { preint: false, adaptive: false, label: 'post-classified, fixed step' },
};
const variants = arg('variants', '') ? arg('variants', '').split(',') : [];
for (const v of variants) if (!SAMPLING_VARIANTS[v]) throw new Error(`--variants ${v}: one of ${Object.keys(SAMPLING_VARIANTS).join(', ')}`);

// ---- The volume: NIfTI-1 header parsed here for vtk.js's raw voxels.
function readNifti(file) {
  if (!fs.existsSync(file)) throw new Error(`${file}: not found (Debian package mricron-data, or set CH2)`);
  let bytes = fs.readFileSync(file);
  if (bytes[0] === 0x1f && bytes[1] === 0x8b) bytes = zlib.gunzipSync(bytes);
  if (bytes.length < 352 || bytes.readInt32LE(0) !== 348) throw new Error(`${file}: not a little-endian NIfTI-1 file`);
  const dims = [1, 2, 3].map((i) => bytes.readInt16LE(40 + 2 * i));
  const datatype = bytes.readInt16LE(70);
  if (datatype !== 2) throw new Error(`${file}: datatype ${datatype}; the bench reads uint8 volumes (2) only`);
  const spacing = [1, 2, 3].map((i) => Math.abs(bytes.readFloatLE(76 + 4 * i)));
  const voxOffset = Math.round(bytes.readFloatLE(108));
  const srow = [0, 1, 2].map((r) => [0, 1, 2, 3].map((c) => bytes.readFloatLE(280 + 16 * r + 4 * c)));
  const diagonal = srow.every((row, r) => row.every((v, c) => c === 3 || c === r ? true : Math.abs(v) < 1e-6)) &&
    [0, 1, 2].every((r) => srow[r][r] > 0);
  if (bytes.readInt16LE(254) <= 0 || !diagonal) throw new Error(`${file}: the bench needs an sform without rotation or flips (RAS storage)`);
  const n = dims[0] * dims[1] * dims[2];
  const voxels = bytes.subarray(voxOffset, voxOffset + n);
  if (voxels.length !== n) throw new Error(`${file}: ${voxels.length} voxel bytes, expected ${n}`);
  return { dims, spacing, origin: srow.map((row) => row[3]), voxels };
}

// ---- PNG writer (RGB, top row first) for the images the bench saves.
const CRC = (() => {
  const t = new Uint32Array(256);
  for (let n = 0; n < 256; n++) { let c = n; for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1; t[n] = c >>> 0; }
  return t;
})();
function crc32(buf) { let c = 0xffffffff; for (const b of buf) c = CRC[(c ^ b) & 0xff] ^ (c >>> 8); return (c ^ 0xffffffff) >>> 0; }
function chunk(type, data) {
  const len = Buffer.alloc(4); len.writeUInt32BE(data.length);
  const td = Buffer.concat([Buffer.from(type, 'latin1'), data]);
  const crc = Buffer.alloc(4); crc.writeUInt32BE(crc32(td));
  return Buffer.concat([len, td, crc]);
}
function writePng(file, width, height, rgba) {
  const raw = Buffer.alloc((width * 3 + 1) * height);
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      for (let k = 0; k < 3; k++) raw[y * (width * 3 + 1) + 1 + x * 3 + k] = rgba[(y * width + x) * 4 + k];
    }
  }
  const ihdr = Buffer.alloc(13);
  ihdr.writeUInt32BE(width, 0); ihdr.writeUInt32BE(height, 4); ihdr[8] = 8; ihdr[9] = 2;
  fs.writeFileSync(file, Buffer.concat([Buffer.from([137, 80, 78, 71, 13, 10, 26, 10]), chunk('IHDR', ihdr),
    chunk('IDAT', zlib.deflateSync(raw, { level: 9 })), chunk('IEND', Buffer.alloc(0))]));
}

// PSNR (dB) over R, G, B.
function psnr(a, b) {
  if (a.length !== b.length) return NaN;
  let sum = 0;
  for (let i = 0; i < a.length; i += 4) for (let k = 0; k < 3; k++) sum += (a[i + k] - b[i + k]) ** 2;
  const mse = sum / (a.length / 4 * 3);
  return mse === 0 ? Infinity : 10 * Math.log10(255 * 255 / mse);
}

// CPU time (ms, user + system) of a process so far, from /proc: the GPU
// process runs SwiftShader, so its CPU time per frame is the frame's work,
// far less disturbed by other load on the machine than wall time.
function cpuMs(pid) {
  const stat = fs.readFileSync(`/proc/${pid}/stat`, 'latin1');
  const f = stat.slice(stat.lastIndexOf(')') + 2).split(' ');
  return (Number(f[11]) + Number(f[12])) * 10;  // utime, stime in 10 ms ticks (USER_HZ 100)
}
// The GPU process of the Chromium that uses `profile` as its user data dir
// (Chromium rewrites its children's command lines into one string).
function gpuProcessOf(profile) {
  const words = (pid) => { try { return fs.readFileSync(`/proc/${pid}/cmdline`, 'latin1').split(/[\0 ]/); } catch { return []; } };
  return fs.readdirSync('/proc').filter((d) => /^\d+$/.test(d)).find((p) => {
    const w = words(p);
    return w.includes('--type=gpu-process') && w.includes(`--user-data-dir=${profile}`);
  }) || null;
}

const median = (xs) => { const s = [...xs].sort((a, b) => a - b); const m = s.length >> 1; return s.length % 2 ? s[m] : 0.5 * (s[m - 1] + s[m]); };

// ---- Server: the bench's pages, the npm packages, our site, the volume.
const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.css': 'text/css',
  '.wasm': 'application/wasm', '.json': 'application/json', '.gz': 'application/gzip' };
function serve(routes) {
  const server = http.createServer((req, res) => {
    const p = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    let file = null;
    for (const [prefix, target] of routes) {
      if (p === prefix || (prefix.endsWith('/') && p.startsWith(prefix))) {
        file = prefix.endsWith('/') ? path.join(target, path.normalize('/' + p.slice(prefix.length))) : target;
        break;
      }
    }
    if (file && fs.existsSync(file) && fs.statSync(file).isDirectory()) file = path.join(file, 'index.html');
    if (!file || !fs.existsSync(file)) { res.writeHead(404); res.end('not found'); return; }
    const body = typeof file === 'string' ? fs.readFileSync(file) : file;
    res.writeHead(200, { 'Content-Type': TYPES[path.extname(file)] || 'application/octet-stream',
      'Content-Length': body.length, 'Cache-Control': 'no-store' });
    res.end(body);
  });
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve({ server, url: `http://127.0.0.1:${server.address().port}` })));
}

// ---- The viewers, each behind one interface: setup(step), frame() -> ms, pixels().
async function openTab(context, url, readyExpr) {
  const page = await context.newPage();
  const logs = [];
  page.on('console', (m) => { if (m.type() === 'error') logs.push(m.text()); });
  page.on('pageerror', (e) => logs.push(e.message));
  await page.goto(url);
  try {
    await page.evaluate(readyExpr);
  } catch (e) {
    throw new Error(`${url}: ${e.message}\n${logs.join('\n')}`);
  }
  return { page, logs };
}

function tesseraViewer(webgl, baseline = false, variant = null) {
  const sampling = variant ? SAMPLING_VARIANTS[variant] : null;  // null: the page's default
  return {
    key: `tessera${webgl}${baseline ? '-baseline' : ''}${variant ? `-${variant}` : ''}`,
    label: `Tessera WebGL ${webgl}${baseline ? ' (baseline build)' : ''}${variant ? ` (${sampling.label})` : ''}`,
    async open(context, base) {
      const q = `size=${SIZE}&url=/data/volume.nii.gz${webgl === 1 ? '&webgl=1' : ''}${extraQuery ? `&${extraQuery}` : ''}`;
      const dir = baseline ? 'tessera-baseline' : 'tessera';
      Object.assign(this, await openTab(context, `${base}/${dir}/index.html?${q}`, () => window.tessera.ready));
      const s = await this.page.evaluate(() => window.tessera.state());
      if (s.webgl !== webgl) throw new Error(`Tessera page: asked for WebGL ${webgl}, got ${s.webgl}`);
      this.detail = `${s.layout}; ${s.renderer}`;
      return { tf: await this.page.evaluate(() => window.tessera.tf()), window: s.window, dims: s.dims };
    },
    async setup({ step, camera }) {
      await this.page.evaluate(async ({ step, camera, sampling }) => {
        for (const id of ['box', 'axes']) document.getElementById(id).checked = false;
        document.getElementById('axes').dispatchEvent(new Event('change'));
        // The page's sampling controls (a baseline build may predate them).
        const preint = document.getElementById('preint');
        const adaptive = document.getElementById('adaptive');
        if (sampling && preint && adaptive) {
          preint.checked = sampling.preint;
          adaptive.checked = sampling.adaptive;
          adaptive.dispatchEvent(new Event('change'));
        }
        const s = document.getElementById('step');
        s.value = String(step);
        s.dispatchEvent(new Event('input'));
        await window.tessera.setProjection(true);
        await window.tessera.setCamera(camera.azimuth, camera.elevation, camera.zoom);
      }, { step, camera, sampling });
      const st = await this.page.evaluate(() => window.tessera.state());
      const stepNow = await this.page.evaluate(() => +document.getElementById('step').value);
      if (Math.abs(stepNow - step) > 1e-9) throw new Error(`Tessera page: step ${step} not accepted (${stepNow})`);
      const sm = st.sampling;
      if (sm && sampling && (sm.preintegrate !== sampling.preint || sm.adaptive !== sampling.adaptive)) {
        throw new Error(`Tessera page: sampling ${JSON.stringify(sm)}, asked for ${JSON.stringify(sampling)}`);
      }
      return `${st.render_size.join('x')} volume pixels` + (sm ? `, step ${sm.step}, ${sm.preintegrate ? 'pre-integrated' : 'post-classified'}` +
        (sm.adaptive ? `, adaptive up to ${sm.max_multiplier}x (tolerance ${sm.tolerance})` : ', fixed step') : '');
    },
    frames(n) { return this.page.evaluate((n) => window.tessera.timeFrames(n), n); },
    async pixels() {
      const b64 = await this.page.evaluate(() => {
        const p = window.tessera.pixels();
        let s = '';
        for (let i = 0; i < p.length; i += 32768) s += String.fromCharCode.apply(null, p.subarray(i, i + 32768));
        return btoa(s);
      });
      return Buffer.from(b64, 'base64');
    },
  };
}

function peerViewer(key, label, pageUrl) {
  return {
    key,
    label,
    async open(context, base) {
      Object.assign(this, await openTab(context, `${base}/${pageUrl}`, () => window.peer.ready));
      this.loaded = await this.page.evaluate(() => window.peer.ready);
      const info = await this.page.evaluate(() => window.peer.info());
      this.detail = `${info.version}; ${info.renderer}`;
      return this.loaded;
    },
    async setup(config) {
      return JSON.stringify(await this.page.evaluate((c) => window.peer.setup(c), config));
    },
    frames(n) { return this.page.evaluate((n) => Array.from({ length: n }, () => window.peer.frame()), n); },
    async pixels() {
      const b64 = await this.page.evaluate(() => {
        const { rgba } = window.peer.pixels();
        let s = '';
        for (let i = 0; i < rgba.length; i += 32768) s += String.fromCharCode.apply(null, rgba.subarray(i, i + 32768));
        return btoa(s);
      });
      return Buffer.from(b64, 'base64');
    },
  };
}

async function main() {
  if (!fs.existsSync(path.join(site, 'tessera-core.wasm'))) throw new Error(`no web build in ${site} (scripts/web.sh)`);
  const vtkBundle = path.join(here, 'dist/vtk-peer.js');
  if (!fs.existsSync(vtkBundle)) throw new Error(`${vtkBundle} missing: run bench/web-peers/run.sh (it bundles the vtk.js page)`);
  const vol = readNifti(volumeFile);
  fs.mkdirSync(outDir, { recursive: true });
  const meta = Buffer.from(JSON.stringify({ dims: vol.dims, spacing: vol.spacing, origin: vol.origin }));
  const metaFile = path.join(outDir, 'volume.json');
  const rawFile = path.join(outDir, 'volume.raw');
  fs.writeFileSync(metaFile, meta);
  fs.writeFileSync(rawFile, vol.voxels);
  const { server, url } = await serve([
    ['/tessera/', site], ['/tessera-baseline/', baselineSite || site], ['/npm/', path.join(here, 'node_modules')], ['/dist/', path.join(here, 'dist')],
    ['/data/volume.nii.gz', volumeFile], ['/data/volume.raw', rawFile], ['/data/volume.json', metaFile],
    ['/', path.join(here, 'pages')],
  ]);
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'tessera-web-peers-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: chromiumPath,
    headless: true,
    viewport: { width: 1280, height: 900 },
    args: ['--no-sandbox', '--no-first-run', '--disable-background-networking', '--disable-component-update',
      '--disable-sync', '--disable-quic', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  try {
    let viewers = [tesseraViewer(2), tesseraViewer(1),
      peerViewer('vtk', 'vtk.js 37.4 (WebGL 2)', 'vtk.html?raw=/data/volume.raw&meta=/data/volume.json'),
      peerViewer('niivue', 'NiiVue 0.69 (WebGL 2)', 'niivue.html?url=/data/volume.nii.gz')];
    if (baselineSite) {
      // Builds since the web adapter split write tessera-core.wasm; older ones tessera.wasm.
      const wasmNames = ['tessera-core.wasm', 'tessera.wasm'];
      if (!wasmNames.some((f) => fs.existsSync(path.join(baselineSite, f)))) {
        throw new Error(`--baseline ${baselineSite}: neither ${wasmNames.join(' nor ')} there (not a web build)`);
      }
      viewers.push(tesseraViewer(2, true), tesseraViewer(1, true));
    }
    for (const v of variants) viewers.push(tesseraViewer(2, false, v));
    if (only) viewers = viewers.filter((v) => v.key === 'tessera2' || only.includes(v.key));
    const opened = {};
    for (const v of viewers) opened[v.key] = await v.open(context, url);
    const gpuPid = gpuProcessOf(profile);
    if (!gpuPid) console.log(`web-peers: no GPU process with --user-data-dir=${profile} found: wall times only`);
    const ours = opened.tessera2;
    // One camera for all: looking at the face (anterior view, superior up,
    // the patient's right on the screen's left), orthographic with
    // NiiVue's framing (half height 0.8 x half the box diagonal).
    const extent = vol.dims.map((d, i) => d * vol.spacing[i]);
    const halfDiagonal = 0.5 * Math.hypot(...extent);
    const halfHeight = 0.8 * (opened.niivue ? opened.niivue.furthestFromPivot : halfDiagonal);
    const centre = vol.origin.map((o, i) => o + 0.5 * (vol.dims[i] - 1) * vol.spacing[i]);
    const camera = {
      azimuth: 0, elevation: 0, zoom: halfDiagonal / halfHeight,
      niivueAzimuth: 180, niivueElevation: 0,
      focalPoint: centre, position: [centre[0], centre[1] + 4 * halfDiagonal, centre[2]], viewUp: [0, 0, 1],
      parallelScale: halfHeight,
    };
    console.log(`web-peers: ${path.basename(volumeFile)} ${vol.dims.join('x')}, ${SIZE}x${SIZE}, orthographic, ` +
                `half height ${halfHeight.toFixed(2)} mm; ${rounds} rounds of ${framesPerRound} frames per viewer`);
    for (const v of viewers) console.log(`  ${v.label}: ${v.detail}`);

    const results = [];
    for (const step of steps) {
      // NiiVue's step is one voxel, fixed in its shader.
      const here = viewers.filter((v) => v.key !== 'niivue' || Math.abs(step - 1) < 1e-9);
      for (const v of here) {
        const note = await v.setup({ step, camera, tf: ours.tf, window: ours.window });
        await v.frames(2);  // warm-up: shaders, textures
        if (note) console.log(`  step ${step}: ${v.label} set up (${note})`);
      }
      const perRound = Object.fromEntries(here.map((v) => [v.key, []]));
      const cpuPerRound = Object.fromEntries(here.map((v) => [v.key, []]));
      for (let r = 0; r < rounds; r++) {
        const order = here.map((_, i) => here[(i + r) % here.length]);
        for (const v of order) {
          const c0 = gpuPid ? cpuMs(gpuPid) : 0;
          perRound[v.key].push(median(await v.frames(framesPerRound)));
          if (gpuPid) cpuPerRound[v.key].push((cpuMs(gpuPid) - c0) / framesPerRound);
        }
      }
      const images = {};
      for (const v of here) {
        images[v.key] = await v.pixels();
        writePng(path.join(outDir, `${v.key}-step${step}.png`), SIZE, SIZE, images[v.key]);
      }
      for (const v of here) {
        const ms = median(perRound[v.key]);
        results.push({ step, key: v.key, label: v.label, ms, rounds: perRound[v.key],
          cpuMs: gpuPid ? median(cpuPerRound[v.key]) : null, cpuRounds: cpuPerRound[v.key],
          psnr: v.key === 'tessera2' ? null : psnr(images[v.key], images.tessera2) });
      }
      console.log(`  step ${step}: ` + here.map((v) => `${v.key} ${median(perRound[v.key]).toFixed(1)} ms [${perRound[v.key].map((x) => x.toFixed(0)).join(' ')}]` +
        (gpuPid ? ` cpu [${cpuPerRound[v.key].map((x) => x.toFixed(0)).join(' ')}]` : '')).join('; '));
    }
    const table = formatTable(results);
    console.log('\n' + table);
    fs.writeFileSync(path.join(outDir, 'table.md'), table + '\n');
    fs.writeFileSync(path.join(outDir, 'results.json'), JSON.stringify({ date: new Date().toISOString(), rounds, framesPerRound,
      chromium: (await context.browser()?.version()) || 'chromium', viewers: viewers.map((v) => ({ key: v.key, label: v.label, detail: v.detail })),
      results }, null, 2));
    console.log(`web-peers: images and table in ${outDir}`);
    for (const v of viewers) if (v.logs.length) console.log(`  ${v.label} console errors: ${v.logs.slice(0, 3).join(' | ')}`);
  } finally {
    await context.close();
    server.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
}

// Markdown: per step, each viewer's median wall time per frame and its
// GPU-process CPU time per frame (SwiftShader's work, summed over its
// threads), each over Tessera WebGL 2's and WebGL 1's (>1: Tessera is
// faster by that factor), and the PSNR of its image against Tessera WebGL 2's.
function formatTable(results) {
  const lines = ['| step (voxels) | viewer | ms/frame (wall) | ms/frame (GPU-process CPU) | wall / Tessera WebGL 2 | CPU / Tessera WebGL 2 | wall / Tessera WebGL 1 | CPU / Tessera WebGL 1 | PSNR vs Tessera WebGL 2 |',
    '|---|---|---:|---:|---:|---:|---:|---:|---:|'];
  const ratio = (a, b) => (a !== null && b ? (a / b).toFixed(2) : '–');
  for (const step of [...new Set(results.map((r) => r.step))]) {
    const rs = results.filter((r) => r.step === step);
    const t2 = rs.find((r) => r.key === 'tessera2');
    const t1 = rs.find((r) => r.key === 'tessera1');
    for (const r of rs) {
      const p = r.psnr === null ? '–' : Number.isFinite(r.psnr) ? `${r.psnr.toFixed(1)} dB` : 'identical';
      lines.push(`| ${step} | ${r.label} | ${r.ms.toFixed(0)} | ${r.cpuMs === null ? '–' : r.cpuMs.toFixed(0)} | ` +
        `${ratio(r.ms, t2?.ms)} | ${ratio(r.cpuMs, t2?.cpuMs)} | ${ratio(r.ms, t1?.ms)} | ${ratio(r.cpuMs, t1?.cpuMs)} | ${p} |`);
    }
  }
  return lines.join('\n');
}

main().catch((e) => {
  console.error(`web-peers: error: ${e.stack || e}`);
  process.exit(1);
});
