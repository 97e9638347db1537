// Zarr v3 / OME-NGFF 0.5 interoperability with another implementation,
// npm's zarrita (pinned in package.json): Tessera reads what zarrita
// writes (several data types and codec chains; sharded stores, which
// zarrita cannot write, are built here byte by byte from the sharding
// spec and checked with zarrita's own reader first), and zarrita reads
// what `tessera convert --zarr-format 3 [--shard N]` writes, voxel for
// voxel. Tessera's side is the CLI: `convert STORE out.raw` gives the
// voxels it reads (x fastest, little-endian, its own type).
//
//   TESSERA=build/tessera node --test tests/interop/   (tests/interop/run.sh)
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { test } from "node:test";
import zlib from "node:zlib";

import FileSystemStore from "@zarrita/storage/fs";
import * as zarr from "zarrita";
import { crc32c } from "../support/crc32c.mjs";

const tessera = process.env.TESSERA ?? path.resolve("../../build/tessera");
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "tessera-zarrita-"));
process.on("exit", () => fs.rmSync(tmp, { recursive: true, force: true }));

const SHAPE = [12, 10, 14]; // z, y, x: edge chunks on every axis
const N = SHAPE[0] * SHAPE[1] * SHAPE[2];

const arrays = {
  uint8: Uint8Array,
  int8: Int8Array,
  uint16: Uint16Array,
  int16: Int16Array,
  int32: Int32Array,
  uint32: Uint32Array,
  float32: Float32Array,
  float64: Float64Array,
};

// Deterministic values spanning the type (negative where signed).
function values(dtype) {
  const out = new arrays[dtype](N);
  for (let i = 0; i < N; i++) {
    const v = (i * 2654435761) % 65521;
    switch (dtype) {
      case "uint8": out[i] = v & 0xff; break;
      case "int8": out[i] = (v & 0xff) - 128; break;
      case "uint16": out[i] = v; break;
      case "int16": out[i] = v - 32760; break;
      case "int32": out[i] = (v - 30000) * 17; break;
      case "uint32": out[i] = v * 3; break;
      default: out[i] = (v - 30000) / 7; break;
    }
  }
  return out;
}

// What Tessera holds a dtype as: u8, u16, i16, f32 themselves; the rest f32.
function asTessera(dtype, data) {
  if (dtype === "uint8" || dtype === "uint16" || dtype === "int16" || dtype === "float32") {
    return data;
  }
  return Float32Array.from(data, Number);
}

// The voxels Tessera reads from `store` (level 0), via `convert` to raw.
function tesseraRead(store, type) {
  const out = path.join(tmp, `read-${path.basename(store)}.raw`);
  execFileSync(tessera, ["convert", store, out, "--quiet"], { stdio: ["ignore", "ignore", "pipe"] });
  const bytes = fs.readFileSync(out);
  return new type(bytes.buffer, bytes.byteOffset, bytes.byteLength / type.BYTES_PER_ELEMENT);
}

function ngffGroup(version = "0.5") {
  const axes = ["z", "y", "x"].map((name) => ({ name, type: "space", unit: "millimeter" }));
  return {
    ome: {
      version,
      multiscales: [{
        name: "interop",
        axes,
        datasets: [{ path: "0", coordinateTransformations: [{ type: "scale", scale: [1, 1, 1] }] }],
      }],
    },
  };
}

const codecChains = {
  bytes: [{ name: "bytes", configuration: { endian: "little" } }],
  "bytes-big": [{ name: "bytes", configuration: { endian: "big" } }],
  gzip: [{ name: "bytes", configuration: { endian: "little" } }, { name: "gzip", configuration: { level: 5 } }],
  zstd: [{ name: "bytes", configuration: { endian: "little" } }, { name: "zstd", configuration: { level: 3, checksum: false } }],
  blosc: [
    { name: "bytes", configuration: { endian: "little" } },
    { name: "blosc", configuration: { cname: "lz4", clevel: 5, shuffle: "shuffle", typesize: 2, blocksize: 0 } },
  ],
  transpose: [
    { name: "transpose", configuration: { order: [2, 1, 0] } },
    { name: "bytes", configuration: { endian: "little" } },
  ],
  "transpose+blosc": [
    { name: "transpose", configuration: { order: [1, 2, 0] } },
    { name: "bytes", configuration: { endian: "big" } },
    { name: "blosc", configuration: { cname: "zstd", clevel: 3, shuffle: "bitshuffle", typesize: 2, blocksize: 0 } },
  ],
};
// zarrita 0.7.5 encodes neither gzip nor crc32c (decode only): those codecs
// are in the spec-built sharded stores below instead.

const cases = [
  ["uint8", "bytes"], ["int8", "zstd"], ["uint16", "blosc"], ["int16", "bytes-big"],
  ["int32", "zstd"], ["uint32", "transpose"], ["float32", "blosc"], ["float64", "bytes-big"],
  ["uint16", "transpose+blosc"], ["int16", "transpose"],
];

const table = [];

for (const [dtype, chain] of cases) {
  test(`Tessera reads zarrita's ${dtype} ${chain}`, async () => {
    const dir = path.join(tmp, `zarrita-${dtype}-${chain}.ome.zarr`);
    const store = new FileSystemStore(dir);
    const group = await zarr.create(zarr.root(store), { attributes: ngffGroup() });
    const codecs = structuredClone(codecChains[chain]);
    for (const c of codecs) if (c.name === "blosc") c.configuration.typesize = arrays[dtype].BYTES_PER_ELEMENT;
    const arr = await zarr.create(group.resolve("0"), {
      shape: SHAPE, chunkShape: [5, 4, 6], dtype, codecs, fillValue: 0,
    });
    const data = values(dtype);
    await zarr.set(arr, null, { data, shape: SHAPE, stride: [SHAPE[1] * SHAPE[2], SHAPE[2], 1] });
    const want = asTessera(dtype, data);
    const got = tesseraRead(dir, want.constructor);
    assert.equal(got.length, want.length);
    assert.deepEqual(Array.from(got), Array.from(want));
    table.push(`zarrita -> Tessera  ${dtype} ${chain}: ${N} voxels equal`);
  });
}

// --- sharded stores built from the spec ----------------------------------

function le32(v) {
  const b = Buffer.alloc(4);
  b.writeUInt32LE(v >>> 0);
  return b;
}

// A sharded uint16 array: shards of 8x8x8 holding 4x4x4 inner chunks,
// inner codecs bytes + gzip + crc32c, index (bytes + crc32c) at `location`.
function writeShardedStore(dir, data, location, skipInner) {
  const shard = [8, 8, 8], inner = [4, 4, 4];
  fs.mkdirSync(path.join(dir, "0"), { recursive: true });
  fs.writeFileSync(path.join(dir, "zarr.json"), JSON.stringify({
    zarr_format: 3, node_type: "group", attributes: ngffGroup(),
  }));
  fs.writeFileSync(path.join(dir, "0", "zarr.json"), JSON.stringify({
    zarr_format: 3, node_type: "array", shape: SHAPE, data_type: "uint16",
    chunk_grid: { name: "regular", configuration: { chunk_shape: shard } },
    chunk_key_encoding: { name: "default", configuration: { separator: "/" } },
    fill_value: 9,
    codecs: [{
      name: "sharding_indexed",
      configuration: {
        chunk_shape: inner,
        codecs: [{ name: "bytes", configuration: { endian: "little" } }, { name: "gzip", configuration: { level: 1 } }, { name: "crc32c" }],
        index_codecs: [{ name: "bytes", configuration: { endian: "little" } }, { name: "crc32c" }],
        index_location: location,
      },
    }],
    storage_transformers: [],
    dimension_names: ["z", "y", "x"],
    attributes: {},
  }));
  const per = shard.map((s, a) => s / inner[a]);
  const count = per[0] * per[1] * per[2];
  const indexBytes = count * 16 + 4;
  for (let sz = 0; sz * 8 < SHAPE[0]; sz++) for (let sy = 0; sy * 8 < SHAPE[1]; sy++) for (let sx = 0; sx * 8 < SHAPE[2]; sx++) {
    const chunks = [];
    const index = Buffer.alloc(count * 16);
    let offset = location === "start" ? indexBytes : 0;
    for (let n = 0; n < count; n++) {
      const iz = Math.floor(n / (per[1] * per[2])), iy = Math.floor(n / per[2]) % per[1], ix = n % per[2];
      if (skipInner(sz, sy, sx, n)) {
        index.writeBigUInt64LE(0xffffffffffffffffn, 16 * n);
        index.writeBigUInt64LE(0xffffffffffffffffn, 16 * n + 8);
        continue;
      }
      const raw = Buffer.alloc(64 * 2);
      for (let z = 0; z < 4; z++) for (let y = 0; y < 4; y++) for (let x = 0; x < 4; x++) {
        const gz = sz * 8 + iz * 4 + z, gy = sy * 8 + iy * 4 + y, gx = sx * 8 + ix * 4 + x;
        const v = gz < SHAPE[0] && gy < SHAPE[1] && gx < SHAPE[2] ? data[(gz * SHAPE[1] + gy) * SHAPE[2] + gx] : 9;
        raw.writeUInt16LE(v, 2 * ((z * 4 + y) * 4 + x));
      }
      const gz = zlib.gzipSync(raw);
      const c = Buffer.concat([gz, le32(crc32c(gz))]);
      index.writeBigUInt64LE(BigInt(offset), 16 * n);
      index.writeBigUInt64LE(BigInt(c.length), 16 * n + 8);
      chunks.push(c);
      offset += c.length;
    }
    const idx = Buffer.concat([index, le32(crc32c(index))]);
    const body = location === "start" ? Buffer.concat([idx, ...chunks]) : Buffer.concat([...chunks, idx]);
    const file = path.join(dir, "0", "c", String(sz), String(sy), String(sx));
    fs.mkdirSync(path.dirname(file), { recursive: true });
    fs.writeFileSync(file, body);
  }
}

for (const location of ["end", "start"]) {
  test(`Tessera and zarrita read a spec-built sharded store (index at the ${location})`, async () => {
    const dir = path.join(tmp, `sharded-${location}.ome.zarr`);
    const data = values("uint16");
    // Inner chunk 3 of shard (0,0,0) is absent: fill_value 9 in both reads.
    const skip = (sz, sy, sx, n) => sz === 0 && sy === 0 && sx === 0 && n === 3;
    writeShardedStore(dir, data, location, skip);
    const want = Uint16Array.from(data);
    for (let z = 0; z < 4; z++) for (let y = 4; y < 8; y++) for (let x = 4; x < 8; x++) want[(z * SHAPE[1] + y) * SHAPE[2] + x] = 9;
    // zarrita 0.7.5 ignores index_location (it reads the index from the
    // end), so the index-at-start store is checked by Tessera alone.
    let readers = "Tessera";
    if (location === "end") {
      const arr = await zarr.open.v3(zarr.root(new FileSystemStore(dir)).resolve("0"), { kind: "array" });
      const z = await zarr.get(arr);
      assert.deepEqual(Array.from(z.data), Array.from(want), "zarrita reads the hand-built shards");
      readers = "zarrita and Tessera";
    }
    const got = tesseraRead(dir, Uint16Array);
    assert.deepEqual(Array.from(got), Array.from(want));
    table.push(`spec-built sharded (index ${location}, gzip+crc32c, 1 missing inner chunk) -> ${readers}: equal`);
  });
}

// --- zarrita reads Tessera's stores --------------------------------------

for (const [compressor, shard] of [["zstd", 2], ["blosc", 2], ["zlib", 3], ["none", 0], ["zstd", 0]]) {
  test(`zarrita reads Tessera's v3 store (${compressor}, shard ${shard})`, async () => {
    const src = "gen:shepp-logan:40";
    const ref = path.join(tmp, "ref.raw");
    execFileSync(tessera, ["convert", src, ref, "--quiet"]);
    const refBytes = fs.readFileSync(ref);
    const refJson = JSON.parse(fs.readFileSync(ref + ".json", "utf8"));
    const dir = path.join(tmp, `tessera-${compressor}-${shard}.ome.zarr`);
    const args = ["convert", src, dir, "--zarr-format", "3", "--chunk", "8,8,8", "--compressor", compressor, "--quiet"];
    if (shard) args.push("--shard", String(shard));
    execFileSync(tessera, args);
    const root = zarr.root(new FileSystemStore(dir));
    const group = await zarr.open.v3(root, { kind: "group" });
    assert.equal(group.attrs.ome.version, "0.5");
    const datasets = group.attrs.ome.multiscales[0].datasets;
    assert.ok(datasets.length >= 3);
    const arr = await zarr.open.v3(root.resolve(datasets[0].path), { kind: "array" });
    const got = await zarr.get(arr);
    const type = got.data.constructor;
    const want = new type(refBytes.buffer, refBytes.byteOffset, refBytes.byteLength / type.BYTES_PER_ELEMENT);
    assert.deepEqual(got.shape, [40, 40, 40]);
    assert.ok(JSON.stringify(refJson).length > 0);
    assert.deepEqual(Array.from(got.data), Array.from(want));
    // Every level opens and reads, and its shape halves.
    for (let l = 1; l < datasets.length; l++) {
      const a = await zarr.open.v3(root.resolve(datasets[l].path), { kind: "array" });
      const lv = await zarr.get(a);
      assert.equal(lv.shape[2], Math.ceil(40 / 2 ** l));
    }
    table.push(`Tessera -> zarrita  ${type.name} ${compressor}${shard ? ` sharded ${shard}^3` : ""}: 64000 voxels equal, ${datasets.length} levels read`);
  });
}

test("interop table", () => {
  console.log(table.join("\n"));
  assert.ok(table.length >= cases.length + 2 + 5);
});
