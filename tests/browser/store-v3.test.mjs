// Browser test: OME-NGFF 0.5 stores on Zarr v3 over fetch() (issue 30).
// A sharded store is read as the native reader reads it: each shard's
// index once, with a Range request, then one Range request per inner chunk
// the bricks need, never a whole shard; a server that ignores Range (200
// with the whole body) still works, each shard then fetched whole once.
// Unsharded v3 stores and every compressor the page decodes (gzip with
// pako, zstd and blosc with numcodecs, a crc32c after them checked in the
// page) render as `tessera render` renders the same store.
import { test } from 'node:test';
import fs from 'node:fs';
import path from 'node:path';
import {
  SIZE, PAGE_SAMPLING, CH2, check, served, psnrAgainst, openPage, withoutOverlays, browserSuite,
  writeChannelStore,
} from './fixture.mjs';
import { crc32c } from '../support/crc32c.mjs';

const checks = browserSuite();

test('OME-Zarr v3 sharded: Range requests for indexes and inner chunks, renders as the CLI', checks(shardedRanges));
test('OME-Zarr v3 sharded from a server that ignores Range: whole shards once each, same image', checks(rangesIgnored));
test('OME-Zarr v3 sharded region: only the inner chunks overlapping the box are read', checks(shardedRegion));
test('OME-Zarr v3 sharded, three channels: listed and rendered as the CLI renders them, read by ranges', checks(shardedChannels));
test('OME-Zarr v3 unsharded and sharded, zstd, blosc and gzip: the page decodes them, same images', checks(v3Codecs));

// The store, its native render (the page's profile and sampling) and the
// page's refined view of it.
// `native: false`: no reference render (a store the CLI refuses).
async function openV3(context, url, tmp, run, name, args, { size = SIZE, untilComplete = false, native = true } = {}) {
  const store = path.join(tmp, name);
  if (!fs.existsSync(store)) run('convert', CH2, store, '--zarr-format', '3', ...args);
  const png = path.join(tmp, `native-${size}-${name}.png`);
  if (native && !fs.existsSync(png)) {
    run('render', store, '--layout', 'bricks', '--tf', 'mr-default', '--size', `${size}x${size}`,
        '--profile', 'webgl2', ...PAGE_SAMPLING, '--out', png);
  }
  const from = served.log.length;
  const { page, logs } = await openPage(context, url, `size=${size}&url=/data/${name}`);
  await page.waitForFunction((until) => (window.tessera.zarr() && window.tessera.zarr().completeMs !== null) ||
                             (!until && window.tessera.error() !== ''), untilComplete, { timeout: 90000 });
  await withoutOverlays(page);
  const z = await page.evaluate(() => window.tessera.zarr());
  const error = await page.evaluate(() => window.tessera.error());
  const m = native ? await psnrAgainst(page, png) : { psnr: 0, error: 'no reference' };
  const errors = logs.filter((l) => (l.startsWith('pageerror') || l.startsWith('error')) && !/status of 404/.test(l));
  return { store, page, z, error, psnr: m.psnr || 0, psnrError: m.error, log: served.log.slice(from), errors };
}

// The shard files of a store (under c/), by served path.
function shardFiles(store, name) {
  const out = new Map();
  for (const f of fs.readdirSync(store, { recursive: true })) {
    const full = path.join(store, f);
    if (fs.statSync(full).isFile() && /(^|\/)c\//.test(f)) out.set(`/data/${name}/${f}`, fs.statSync(full).size);
  }
  return out;
}

// A level's shards: inner chunk shape, shard shape, and the index's bytes.
function shardLayout(store, level) {
  const meta = JSON.parse(fs.readFileSync(path.join(store, String(level), 'zarr.json'), 'utf8'));
  const sharding = meta.codecs.find((c) => c.name === 'sharding_indexed').configuration;
  const outer = meta.chunk_grid.configuration.chunk_shape;
  const per = outer.map((c, i) => Math.ceil(c / sharding.chunk_shape[i]));
  const n = per.reduce((k, c) => k * c, 1);
  return { inner: sharding.chunk_shape, outer, per,
    indexBytes: n * 16 + (sharding.index_codecs.some((c) => c.name === 'crc32c') ? 4 : 0) };
}
// The Range header that reads a served shard's index.
function indexRange(store, name, servedPath) {
  const level = servedPath.slice(`/data/${name}/`.length).split('/')[0];
  return `bytes=-${shardLayout(store, level).indexBytes}`;
}
// The inner chunk (z, y, x of the level's chunk grid) a Range request of a
// level-0 shard reads, from the shard's own index.
function innerChunkOf(store, name, servedPath, range) {
  const { per, indexBytes } = shardLayout(store, 0);
  const file = fs.readFileSync(path.join(store, servedPath.slice(`/data/${name}/`.length)));
  const index = file.subarray(file.length - indexBytes);
  const [a, b] = range.slice('bytes='.length).split('-').map(Number);
  const shard = servedPath.split('/').slice(-3).map(Number);  // z, y, x
  for (let i = 0; i * 16 + 16 <= index.length; i++) {
    if (Number(index.readBigUInt64LE(i * 16)) === a && Number(index.readBigUInt64LE(i * 16 + 8)) === b - a + 1) {
      const local = [Math.floor(i / (per[1] * per[2])), Math.floor(i / per[2]) % per[1], i % per[2]];
      return local.map((l, k) => shard[k] * per[k] + l).join(',');
    }
  }
  return null;
}

async function shardedRanges(context, url, tmp, run) {
  if (!fs.existsSync(CH2)) { check(`OME-Zarr v3 test needs ${CH2} (mricron-data)`, false); return; }
  const name = 'ch2-v3-sharded.ome.zarr';
  served.ranges = true;
  const r = await openV3(context, url, tmp, run, name, ['--chunk', '32,32,32', '--shard', '4']);
  const shards = shardFiles(r.store, name);
  const shardLog = r.log.filter((e) => shards.has(e.path));
  const whole = shardLog.filter((e) => e.status === 200);
  const isIndex = (e) => e.range === indexRange(r.store, name, e.path);
  const indexReads = new Map();
  for (const e of shardLog.filter(isIndex)) indexReads.set(e.path, (indexReads.get(e.path) || 0) + 1);
  const inner = shardLog.filter((e) => !isIndex(e));
  const innerKeys = new Set(inner.map((e) => `${e.path} ${e.range}`));
  const shardsRead = new Set(shardLog.map((e) => e.path));
  const shardBytes = [...shardsRead].reduce((n, p) => n + shards.get(p), 0);
  const fetched = shardLog.reduce((n, e) => n + e.bytes, 0);
  check('v3 sharded: the page renders what `tessera render` renders of the store (PSNR >= 50 dB)',
        !r.error && r.z.last && r.z.last.complete && r.psnr >= 50,
        r.error || r.psnrError || `${r.psnr.toFixed(2)} dB, refined in ${r.z.completeMs.toFixed(0)} ms`);
  check('v3 sharded: no shard fetched whole; every read a 206 of a Range request',
        whole.length === 0 && shardLog.length > 0 && shardLog.every((e) => e.status === 206 && e.range),
        `${shardLog.length} shard requests, ${whole.length} whole`);
  check('v3 sharded: each shard index fetched once, then one request per inner chunk (none twice)',
        indexReads.size === shardsRead.size && [...indexReads.values()].every((n) => n === 1) &&
        innerKeys.size === inner.length && inner.length > 0,
        `${indexReads.size} indexes for ${shardsRead.size} shards read (${JSON.stringify([...indexReads.values()])}); ` +
        `${inner.length} inner chunk requests, ${innerKeys.size} distinct`);
  // At this size every brick refines to level 0: every inner chunk is
  // needed (the region test below reads fewer).
  check('v3 sharded: the bytes fetched are the indexes and inner chunks, none twice, no more than the shards hold',
        fetched <= shardBytes && r.z.rangeRequests === shardLog.length && r.z.wholeBodies === 0,
        `${fetched} bytes of ${shardBytes} in the ${shardsRead.size} shards read ` +
        `(page: ${r.z.rangeRequests} range requests, ${r.z.wholeBodies} whole bodies)`);
  check('no script errors on the v3 sharded page', r.errors.length === 0, r.errors.join(' | '));
  console.log(`zarr v3: ${name} ${SIZE}x${SIZE}: ${shardsRead.size} shards, ${indexReads.size} index reads, ` +
              `${inner.length} inner chunk reads, ${fetched} of ${shardBytes} shard bytes, refined ${r.z.completeMs.toFixed(0)} ms, ` +
              `${r.psnr.toFixed(2)} dB`);
  await r.page.close();
}

// Whether level-0 inner chunk z,y,x is stored (its shard exists and its
// index entry is not the absent marker).
function innerStored(store, chunk) {
  const { per, indexBytes } = shardLayout(store, 0);
  const shard = chunk.map((c, k) => Math.floor(c / per[k]));
  const file = path.join(store, '0', 'c', ...shard.map(String));
  if (!fs.existsSync(file)) return false;
  const bytes = fs.readFileSync(file);
  const index = bytes.subarray(bytes.length - indexBytes);
  const local = chunk.map((c, k) => c % per[k]);
  const i = (local[0] * per[1] + local[1]) * per[2] + local[2];
  return index.readBigUInt64LE(i * 16) !== 0xffffffffffffffffn;
}

// The bread-slice region of a sharded store: at 64 px the page refines only
// to coarser levels, so level 0 is read for the region (and the slice
// views' slabs before it): after the pick, only Range requests of the
// level-0 shards overlapping it — their indexes if not read before, then
// the inner chunks overlapping the box that were not fetched before, each
// once — fewer bytes than those shards hold; the render equals `tessera
// render STORE --region`.
async function shardedRegion(context, url, tmp, run) {
  const name = 'ch2-v3-sharded.ome.zarr';
  const store = path.join(tmp, name);
  if (!fs.existsSync(store)) return;  // shardedRanges said why
  const opened = served.log.length;
  const { page, logs } = await openPage(context, url, `size=64&url=/data/${name}`);
  await page.waitForFunction(() => window.tessera.zarr().completeMs !== null, null, { timeout: 60000 });
  await withoutOverlays(page);
  await page.waitForFunction(() => Object.values(window.tessera.slices.state().panels).every((p) => p.frame && !p.frame.pending),
                             null, { timeout: 30000 }).catch(() => {});
  const isLevel0 = (e) => e.path.startsWith(`/data/${name}/0/c/`);
  const isIndex = (e) => e.range === indexRange(store, name, e.path);
  const before = served.log.slice(opened).filter(isLevel0);
  const indexedBefore = new Set(before.filter(isIndex).map((e) => e.path));
  const innerBefore = new Set(before.filter((e) => !isIndex(e)).map((e) => innerChunkOf(store, name, e.path, e.range)));
  const from = served.log.length;
  const picked = await page.evaluate(() => window.tessera.slices.showRegion({ begin: [39, 98, 51], end: [99, 150, 79] }));
  const ex = await page.evaluate(() => window.tessera.slices.state().explore);
  if (!picked || !ex.region_level0) throw new Error(`picking a region of the store: ${await page.evaluate(() => window.tessera.error())}`);
  const { begin, end } = ex.region_level0;
  const { inner } = shardLayout(store, 0);  // z, y, x
  const overlapping = [];
  for (let z = Math.floor(begin[2] / inner[0]); z <= Math.floor((end[2] - 1) / inner[0]); z++) {
    for (let y = Math.floor(begin[1] / inner[1]); y <= Math.floor((end[1] - 1) / inner[1]); y++) {
      for (let x = Math.floor(begin[0] / inner[2]); x <= Math.floor((end[0] - 1) / inner[2]); x++) {
        if (innerStored(store, [z, y, x])) overlapping.push(`${z},${y},${x}`);
      }
    }
  }
  const after = served.log.slice(from).filter((e) => e.path.startsWith(`/data/${name}/`));
  const innerAfter = after.filter((e) => !isIndex(e)).map((e) => innerChunkOf(store, name, e.path, e.range));
  const indexesAfter = after.filter(isIndex).map((e) => e.path);
  const shardsTouched = new Set(after.map((e) => e.path));
  const shardBytes = [...shardsTouched].reduce((n, p) => n + fs.statSync(path.join(store, p.slice(`/data/${name}/`.length))).size, 0);
  const bytes = after.reduce((n, e) => n + e.bytes, 0);
  const wanted = overlapping.filter((c) => !innerBefore.has(c));
  const same = (a, b) => JSON.stringify([...a].sort()) === JSON.stringify([...b].sort());
  check('v3 sharded region: only Range reads of level-0 shards, no index read twice',
        after.length > 0 && after.every((e) => isLevel0(e) && e.status === 206) &&
        indexesAfter.every((p) => !indexedBefore.has(p)) && new Set(indexesAfter).size === indexesAfter.length,
        `${after.length} requests after the pick (${indexesAfter.length} indexes, ${indexedBefore.size} read before)`);
  check('v3 sharded region: exactly the stored inner chunks overlapping the box not fetched before, each once',
        same(innerAfter, wanted) && new Set(innerAfter).size === innerAfter.length,
        `${innerAfter.length} inner chunks read (${innerAfter.join(' ')}); the box ${JSON.stringify(ex.region_level0)} ` +
        `overlaps ${overlapping.length} stored, ${overlapping.length - wanted.length} fetched before for the slices`);
  check('v3 sharded region: fewer bytes than the shards it touches', bytes < shardBytes,
        `${bytes} bytes of the ${shardBytes} in ${shardsTouched.size} shards`);
  const spec = [0, 1, 2].map((a) => `${begin[a]}:${end[a]}`).join(',');
  const refPng = path.join(tmp, 'native-v3-region.png');
  await page.evaluate(() => window.tessera.setCamera(30, 20, 1));
  run('render', store, '--region', spec, '--tf', 'mr-default', '--size', '64x64', '--profile', 'webgl2',
      '--azimuth', '30', '--elevation', '20', ...PAGE_SAMPLING, '--out', refPng);
  const m = await psnrAgainst(page, refPng);
  check(`v3 sharded region: renders like \`tessera render STORE --region ${spec}\` (PSNR >= 45 dB)`, m.psnr >= 45,
        m.error || `${m.psnr.toFixed(2)} dB`);
  const errors = logs.filter((l) => (l.startsWith('pageerror') || l.startsWith('error')) && !/status of 404/.test(l));
  check('no script errors on the v3 region page', errors.length === 0, errors.join(' | '));
  console.log(`zarr v3 region ${spec}: ${innerAfter.length} inner chunks + ${indexesAfter.length} indexes, ` +
              `${bytes} of ${shardBytes} shard bytes, ${m.psnr.toFixed(2)} dB`);
  await page.close();
}

// The three-channel v2 store of the channels test as NGFF 0.5 on Zarr v3,
// built here from the spec: one shard per channel and level (its whole
// 1 x Z x Y x X chunk), 2 x 2 x 2 inner chunks of raw little-endian u16
// in it, the index (with its crc32c) at the start (Tessera writes it at
// the end: the other case of the page's index range).
function shardedChannelStore(v2, v3) {
  fs.rmSync(v3, { recursive: true, force: true });
  fs.mkdirSync(v3, { recursive: true });
  const attrs = JSON.parse(fs.readFileSync(path.join(v2, '.zattrs'), 'utf8'));
  const multiscales = attrs.multiscales.map(({ version, ...m }) => m);
  fs.writeFileSync(path.join(v3, 'zarr.json'), JSON.stringify({ zarr_format: 3, node_type: 'group',
    attributes: { ome: { version: '0.5', multiscales, omero: attrs.omero } } }));
  for (const level of ['0', '1']) {
    const a = JSON.parse(fs.readFileSync(path.join(v2, level, '.zarray'), 'utf8'));
    const [, lz, ly, lx] = a.shape;
    const inner = [1, lz / 2, ly / 2, lx / 2];
    fs.mkdirSync(path.join(v3, level), { recursive: true });
    fs.writeFileSync(path.join(v3, level, 'zarr.json'), JSON.stringify({
      zarr_format: 3, node_type: 'array', shape: a.shape, data_type: 'uint16',
      chunk_grid: { name: 'regular', configuration: { chunk_shape: [1, lz, ly, lx] } },
      chunk_key_encoding: { name: 'default', configuration: { separator: '/' } }, fill_value: 0,
      codecs: [{ name: 'sharding_indexed', configuration: { chunk_shape: inner,
        codecs: [{ name: 'bytes', configuration: { endian: 'little' } }],
        index_codecs: [{ name: 'bytes', configuration: { endian: 'little' } }, { name: 'crc32c' }],
        index_location: 'start' } }],
      dimension_names: ['c', 'z', 'y', 'x'] }));
    for (let c = 0; c < 3; c++) {
      const whole = fs.readFileSync(path.join(v2, level, String(c), '0', '0', '0'));
      const parts = [];
      const index = Buffer.alloc(8 * 16 + 4);
      let offset = index.length;
      for (let n = 0; n < 8; n++) {
        const [iz, iy, ix] = [n >> 2, (n >> 1) & 1, n & 1];  // C order of the 2 x 2 x 2 inner grid
        const part = Buffer.alloc(inner[1] * inner[2] * inner[3] * 2);
        let o = 0;
        for (let z = 0; z < inner[1]; z++) {
          for (let y = 0; y < inner[2]; y++) {
            const row = (((iz * inner[1] + z) * ly + iy * inner[2] + y) * lx + ix * inner[3]) * 2;
            whole.copy(part, o, row, row + inner[3] * 2);
            o += inner[3] * 2;
          }
        }
        index.writeBigUInt64LE(BigInt(offset), n * 16);
        index.writeBigUInt64LE(BigInt(part.length), n * 16 + 8);
        offset += part.length;
        parts.push(part);
      }
      index.writeUInt32LE(crc32c(index.subarray(0, 8 * 16)), 8 * 16);
      const dir = path.join(v3, level, 'c', String(c), '0', '0');
      fs.mkdirSync(dir, { recursive: true });
      fs.writeFileSync(path.join(dir, '0'), Buffer.concat([index, ...parts]));
    }
  }
}

// A sharded v3 store of three u16 channels in the page: the channel list
// from its omero metadata, the frame equal to `tessera render STORE
// --channels 0,1,2` of the same store, every shard read by Range requests.
async function shardedChannels(context, url, tmp, run) {
  const v2 = path.join(tmp, 'three.ome.zarr');
  writeChannelStore(v2, [48, 48, 24]);
  const name = 'three-v3.ome.zarr';
  const store = path.join(tmp, name);
  shardedChannelStore(v2, store);
  const from = served.log.length;
  const { page, logs } = await openPage(context, url, `size=${SIZE}&slices=0&url=/data/${name}`);
  await page.waitForFunction(() => window.tessera.channels() !== null || window.tessera.error() !== '', null,
                             { timeout: 30000 }).catch(() => {});
  const listed = await page.evaluate(() => window.tessera.channels());
  check('v3 sharded channels: the page lists the three channels with their omero labels',
        listed && listed.open && listed.channels.map((c) => c.label).join(',') === 'sphere,slab,rod',
        JSON.stringify(listed) + (await page.evaluate(() => window.tessera.error())));
  await page.evaluate(() => window.tessera.setCamera(30, 20, 1));
  const tfPath = path.join(tmp, 'page-tf-v3.json');
  fs.writeFileSync(tfPath, JSON.stringify(await page.evaluate(() => window.tessera.tf())));
  const png = path.join(tmp, 'v3-channels.png');
  run('render', store, '--channels', '0,1,2', '--tf', tfPath, '--azimuth', '30', '--elevation', '20',
      '--size', `${SIZE}x${SIZE}`, '--profile', 'webgl2', ...PAGE_SAMPLING, '--out', png);
  const m = await psnrAgainst(page, png);
  check('v3 sharded channels: the frame renders as `tessera render STORE --channels 0,1,2` (PSNR >= 40 dB)',
        m.psnr >= 40, m.error || `${m.psnr.toFixed(2)} dB`);
  const shards = served.log.slice(from).filter((e) => /\/c\/\d\/0\/0\/0$/.test(e.path));
  const indexReads = shards.filter((e) => e.range === `bytes=0-${8 * 16 + 4 - 1}`);
  check('v3 sharded channels: every shard read by Range requests, its index at the start once, none whole',
        shards.length > 0 && shards.every((e) => e.status === 206 && e.range) &&
        new Set(indexReads.map((e) => e.path)).size === indexReads.length &&
        indexReads.length === new Set(shards.map((e) => e.path)).size,
        `${shards.length} shard requests: ${shards.filter((e) => e.status === 206).length} x 206, ` +
        `${shards.filter((e) => e.status === 200).length} whole; ${indexReads.length} index reads for the ` +
        `${new Set(shards.map((e) => e.path)).size} shards read`);
  const errors = logs.filter((l) => l.startsWith('pageerror') || (l.startsWith('error') && !/status of 404/.test(l)));
  check('no script errors on the v3 channels page', errors.length === 0, errors.join(' | '));
  await page.close();
}

async function rangesIgnored(context, url, tmp, run) {
  if (!fs.existsSync(CH2)) { check(`OME-Zarr v3 test needs ${CH2} (mricron-data)`, false); return; }
  const name = 'ch2-v3-sharded.ome.zarr';
  served.ranges = false;
  let r;
  try {
    r = await openV3(context, url, tmp, run, name, ['--chunk', '32,32,32', '--shard', '4']);
  } finally {
    served.ranges = true;
  }
  const shards = shardFiles(r.store, name);
  const shardLog = r.log.filter((e) => shards.has(e.path));
  const perShard = new Map();
  for (const e of shardLog) perShard.set(e.path, (perShard.get(e.path) || 0) + 1);
  const CONNECTIONS = 6;  // zarr-url.js: requests in flight before the first 200 is known
  check('v3 sharded, Range ignored: the page renders the same (PSNR >= 50 dB)',
        !r.error && r.z.last && r.z.last.complete && r.psnr >= 50,
        r.error || r.psnrError || `${r.psnr.toFixed(2)} dB, refined in ${r.z.completeMs.toFixed(0)} ms`);
  check('v3 sharded, Range ignored: whole shards, each fetched about once',
        shardLog.every((e) => e.status === 200) && shardLog.length <= perShard.size + CONNECTIONS &&
        r.z.wholeBodies === shardLog.length,
        `${shardLog.length} requests for ${perShard.size} shards (page: ${r.z.wholeBodies} whole bodies)`);
  check('no script errors on the v3 page without ranges', r.errors.length === 0, r.errors.join(' | '));
  console.log(`zarr v3 without Range: ${shardLog.length} requests for ${perShard.size} shards, ` +
              `${shardLog.reduce((n, e) => n + e.bytes, 0)} bytes, refined ${r.z.completeMs.toFixed(0)} ms`);
  await r.page.close();
}

async function v3Codecs(context, url, tmp, run) {
  if (!fs.existsSync(CH2)) { check(`OME-Zarr v3 test needs ${CH2} (mricron-data)`, false); return; }
  const cases = [
    { name: 'ch2-v3-zstd.ome.zarr', args: ['--compressor', 'zstd'] },
    { name: 'ch2-v3-gzip-sharded.ome.zarr', args: ['--compressor', 'zlib', '--shard', '2'] },
    { name: 'ch2-v3-blosc-sharded.ome.zarr', args: ['--compressor', 'blosc', '--shard', '2'] },
  ];
  // The zstd store with a crc32c codec after zstd on every chunk (as
  // zarr-python writes with crc32c), one level-0 chunk's crc made wrong in
  // a copy.
  const zstd = path.join(tmp, cases[0].name);
  run('convert', CH2, zstd, '--zarr-format', '3', ...cases[0].args);
  const crcStore = path.join(tmp, 'ch2-v3-zstd-crc.ome.zarr');
  withCrc32c(zstd, crcStore);
  cases.push({ name: 'ch2-v3-zstd-crc.ome.zarr', args: [] });
  for (const c of cases) {
    const r = await openV3(context, url, tmp, run, c.name, c.args, { size: 128 });
    const meta = fs.readFileSync(path.join(r.store, '0', 'zarr.json'), 'utf8');
    check(`v3 ${c.name}: the page renders what \`tessera render\` renders (PSNR >= 50 dB)`,
          !r.error && r.z.last && r.z.last.complete && r.psnr >= 50 && r.errors.length === 0,
          r.error || r.psnrError || r.errors.join(' | ') ||
          `${r.psnr.toFixed(2)} dB, ${r.z.requests} requests, ${r.z.decodes.length} chunks decoded in the page`);
    check(`v3 ${c.name}: its chunks are decoded in the page`, r.z.decodes.length > 0,
          `${r.z.decodes.length} decodes; codecs ${JSON.stringify(JSON.parse(meta).codecs).slice(0, 200)}`);
    await r.page.close();
  }
  const bad = path.join(tmp, 'ch2-v3-zstd-badcrc.ome.zarr');
  fs.cpSync(crcStore, bad, { recursive: true });
  const victim = fs.readdirSync(path.join(bad, '0', 'c'), { recursive: true })
    .map((f) => path.join(bad, '0', 'c', f)).filter((f) => fs.statSync(f).isFile())
    .sort((a, b) => fs.statSync(b).size - fs.statSync(a).size)[0];
  const bytes = fs.readFileSync(victim);
  bytes[bytes.length - 1] ^= 0xff;
  fs.writeFileSync(victim, bytes);
  const r = await openV3(context, url, tmp, run, 'ch2-v3-zstd-badcrc.ome.zarr', [], { untilComplete: true, native: false });
  const key = path.relative(bad, victim);
  check('v3 chunk whose crc32c does not match: its bricks fail with a message naming the chunk, the rest renders',
        r.z.last && r.z.last.complete && r.z.last.failing > 0 && /crc32c mismatch/.test(r.z.last.last_error) &&
        r.z.last.last_error.includes(key),
        r.z.last ? `complete ${r.z.last.complete}, ${r.z.last.failing} bricks failing: "${r.z.last.last_error}" ` +
          `(corrupted ${key}); page error "${r.error}"` : r.error);
  await r.page.close();
}

// A copy of an unsharded v3 store with crc32c after each array's codecs
// and every chunk's checksum appended.
function withCrc32c(from, to) {
  fs.cpSync(from, to, { recursive: true });
  for (const f of fs.readdirSync(to, { recursive: true })) {
    const full = path.join(to, f);
    if (path.basename(f) !== 'zarr.json') continue;
    const meta = JSON.parse(fs.readFileSync(full, 'utf8'));
    if (meta.node_type !== 'array') continue;
    meta.codecs.push({ name: 'crc32c' });
    fs.writeFileSync(full, JSON.stringify(meta));
    const chunks = path.join(path.dirname(full), 'c');
    if (!fs.existsSync(chunks)) continue;
    for (const c of fs.readdirSync(chunks, { recursive: true })) {
      const file = path.join(chunks, c);
      if (!fs.statSync(file).isFile()) continue;
      const body = fs.readFileSync(file);
      const tail = Buffer.alloc(4);
      tail.writeUInt32LE(crc32c(body));
      fs.writeFileSync(file, Buffer.concat([body, tail]));
    }
  }
}
