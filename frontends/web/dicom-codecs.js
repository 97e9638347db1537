// Compressed DICOM in the page: the frames of encapsulated pixel data (PS3.5
// A.4) decoded by npm's WebAssembly decoders and the file handed on to the
// module's io readers as explicit VR little endian, which they read like any
// uncompressed file. Loaded by dicom-drop.js only when a dropped or picked
// file needs it; each decoder is loaded (from the site's codecs/, copied from
// frontends/web/node_modules by cmake/Web.cmake) only when a frame needs it.
//
//   JPEG baseline (8-bit; .50, and .51 with 8-bit samples)  @cornerstonejs/codec-libjpeg-turbo-8bit
//   JPEG lossless, processes 14 and 14 SV1 (.57, .70)      jpeg-lossless-decoder-js
//   JPEG-LS lossless and near-lossless (.80, .81)          @cornerstonejs/codec-charls
//   JPEG 2000 (.90, .91)                                    @cornerstonejs/codec-openjpeg
//   HTJ2K (.201, .202, .203)                                @cornerstonejs/codec-openjph
//   JPEG extended, 12-bit samples (.51)                     @cornerstonejs/dicom-image-loader's
//                                                           JavaScript JPEG decoder (codecs/jpeg.js)
//
// libjpeg-turbo's WebAssembly build is 8-bit and jpeg-lossless-decoder-js
// decodes only lossless, so 12-bit lossy frames go to the JavaScript decoder
// cornerstone's image loader uses for them (decodeJPEGBaseline12Bit-js); only
// its one file is copied to the site. Every frame's own header is checked against the
// file's Rows, Columns, Samples per Pixel and Bits Allocated before it is
// decoded, and the decoded size again after; a corrupt codestream is an error
// naming the file and the frame.

const SYNTAXES = {
  '1.2.840.10008.1.2.4.50': { name: 'JPEG Baseline', codec: 'jpeg' },
  '1.2.840.10008.1.2.4.51': { name: 'JPEG Extended', codec: 'jpeg' },
  '1.2.840.10008.1.2.4.57': { name: 'JPEG Lossless, Non-hierarchical', codec: 'jpeg' },
  '1.2.840.10008.1.2.4.70': { name: 'JPEG Lossless, Non-hierarchical, First-Order Prediction', codec: 'jpeg' },
  '1.2.840.10008.1.2.4.80': { name: 'JPEG-LS Lossless', codec: 'jpeg' },
  '1.2.840.10008.1.2.4.81': { name: 'JPEG-LS Lossy (Near-lossless)', codec: 'jpeg' },
  '1.2.840.10008.1.2.4.90': { name: 'JPEG 2000 (Lossless only)', codec: 'j2k' },
  '1.2.840.10008.1.2.4.91': { name: 'JPEG 2000', codec: 'j2k' },
  '1.2.840.10008.1.2.4.201': { name: 'HTJ2K (Lossless only)', codec: 'htj2k' },
  '1.2.840.10008.1.2.4.202': { name: 'HTJ2K with RPCL Options (Lossless only)', codec: 'htj2k' },
  '1.2.840.10008.1.2.4.203': { name: 'HTJ2K', codec: 'htj2k' },
};
const EXPLICIT_LE = '1.2.840.10008.1.2.1';
const MAX_DEPTH = 64;                 // sequences nested deeper are refused
const MAX_DECODED = 1024 * 1048576;   // bytes of decoded pixels one file may declare
const LONG_VRS = new Set(['OB', 'OD', 'OF', 'OL', 'OV', 'OW', 'SQ', 'UC', 'UN', 'UR', 'UT', 'SV', 'UV']);

// ------------------------------------------------------------- decoders

const CODEC_DIR = new URL('./codecs/', import.meta.url).href;
const loaded = new Map();  // decoder file -> Promise of its module instance
let lastDecoderMessage = '';

// An emscripten build (UMD: CommonJS when `module` is defined) instantiated
// with its .wasm from codecs/; no globals are left behind.
function loadEmscripten(file) {
  if (!loaded.has(file)) {
    const p = (async () => {
      const r = await fetch(CODEC_DIR + file);
      if (!r.ok) throw new Error(`cannot load the decoder ${file} (HTTP ${r.status})`);
      const text = await r.text();
      const module = { exports: {} };
      // eslint-disable-next-line no-new-func
      new Function('module', 'exports', text)(module, module.exports);
      // Their progress lines ([INFO] ...) go nowhere; the last error line is
      // kept for the message of a frame that fails.
      return module.exports({ locateFile: (p) => CODEC_DIR + p, print: () => {},
        printErr: (line) => { lastDecoderMessage = String(line).trim(); } });
    })();
    loaded.set(file, p);
    p.catch(() => loaded.delete(file));
  }
  return loaded.get(file);
}
// An ES module from codecs/, imported once.
function loadModule(file) {
  if (!loaded.has(file)) {
    const p = import(CODEC_DIR + file);
    loaded.set(file, p);
    p.catch(() => loaded.delete(file));
  }
  return loaded.get(file);
}
// A decoder that trapped may have left its memory inconsistent: the next
// frame gets a fresh instance.
function forget(file) { loaded.delete(file); }

const WASM = {
  jpeg: { file: 'libjpegturbowasm_decode.js', cls: 'JPEGDecoder', label: 'JPEG' },
  jpegls: { file: 'charlswasm_decode.js', cls: 'JpegLSDecoder', label: 'JPEG-LS' },
  j2k: { file: 'openjpegwasm_decode.js', cls: 'J2KDecoder', label: 'JPEG 2000' },
  htj2k: { file: 'openjphjs.js', cls: 'HTJ2KDecoder', label: 'HTJ2K' },
};

// What a JPEG-family stream's start-of-frame marker says (ITU T.81 B.2.2,
// T.87 for SOF55): the process, precision, size and components.
function jpegFrameHeader(b) {
  if (b.length < 4 || b[0] !== 0xff || b[1] !== 0xd8) throw new Error('not a JPEG stream (no SOI marker)');
  let i = 2;
  while (i + 4 <= b.length) {
    if (b[i] !== 0xff) throw new Error(`no marker at byte ${i}`);
    const m = b[i + 1];
    if (m === 0xff) { i += 1; continue; }
    const len = (b[i + 2] << 8) | b[i + 3];
    const sof = (m >= 0xc0 && m <= 0xcf && m !== 0xc4 && m !== 0xc8 && m !== 0xcc) || m === 0xf7;
    if (sof) {
      if (i + 10 > b.length) break;
      return { marker: m, precision: b[i + 4], rows: (b[i + 5] << 8) | b[i + 6],
        columns: (b[i + 7] << 8) | b[i + 8], components: b[i + 9] };
    }
    if (m === 0xda || len < 2) break;
    i += 2 + len;
  }
  throw new Error('no start-of-frame marker before the scan');
}

// The image size, components and precision of a JPEG 2000 codestream's SIZ
// marker (ITU T.800 A.5.1), read before any decoder sizes a buffer by it.
function j2kHeader(b) {
  let i = 0;
  if (b.length >= 12 && b[4] === 0x6a && b[5] === 0x50) {  // a JP2 file: find the jp2c box
    i = -1;
    for (let k = 0; k + 8 <= b.length; k++) {
      if (b[k] === 0x6a && b[k + 1] === 0x70 && b[k + 2] === 0x32 && b[k + 3] === 0x63) { i = k + 4; break; }
    }
    if (i < 0) throw new Error('a JP2 file without a codestream box');
  }
  if (b.length < i + 42 || b[i] !== 0xff || b[i + 1] !== 0x4f || b[i + 2] !== 0xff || b[i + 3] !== 0x51) {
    throw new Error('not a JPEG 2000 codestream (no SOC and SIZ markers)');
  }
  const u32 = (o) => ((b[o] << 24) | (b[o + 1] << 16) | (b[o + 2] << 8) | b[o + 3]) >>> 0;
  const s = i + 4;  // SIZ: Lsiz Rsiz Xsiz Ysiz XOsiz YOsiz ... Csiz Ssiz
  const components = (b[s + 36] << 8) | b[s + 37];
  return { columns: u32(s + 4) - u32(s + 12), rows: u32(s + 8) - u32(s + 16), components,
    precision: components > 0 && b.length > s + 38 ? (b[s + 38] & 0x7f) + 1 : 0 };
}

// Checks what a frame's header says against what the file declares.
function checkShape(got, shape, label) {
  if (got.components !== shape.samples) {
    throw new Error(`a ${label} frame of ${got.components} components; only greyscale (one component) is read`);
  }
  if (got.columns !== shape.columns || got.rows !== shape.rows) {
    throw new Error(`the ${label} frame is ${got.columns}x${got.rows} pixels, but the file declares ` +
      `${shape.columns}x${shape.rows} (Columns x Rows)`);
  }
  if (!(got.precision >= 1 && got.precision <= shape.bitsAllocated)) {
    throw new Error(`the ${label} frame has ${got.precision}-bit samples, more than the ` +
      `${shape.bitsAllocated} bits allocated per pixel`);
  }
}

// One frame through a cornerstone decoder: header read and checked, then
// decoded; the samples as stored pixel data holds them (little endian).
async function wasmDecode(kind, frame, shape) {
  const w = WASM[kind];
  const m = await loadEmscripten(w.file);
  const d = new m[w.cls]();
  lastDecoderMessage = '';
  let fi, bytes;
  try {
    d.getEncodedBuffer(frame.length).set(frame);
    d.decode();
    fi = d.getFrameInfo();
    bytes = new Uint8Array(d.getDecodedBuffer());  // a copy out of the decoder's memory
  } catch (e) {
    if (!(e instanceof Error) || e instanceof WebAssembly.RuntimeError) forget(w.file);
    const why = e instanceof Error ? e.message : describeWasmError(m, e);
    throw new Error(`the ${w.label} decoder failed: ${why}${lastDecoderMessage ? ` (${lastDecoderMessage})` : ''}; corrupt or truncated?`);
  } finally {
    try { d.delete(); } catch { forget(w.file); }
  }
  if (!fi || !fi.width || !fi.height || !fi.componentCount) {
    throw new Error(`the ${w.label} decoder returned no image${lastDecoderMessage ? ` (${lastDecoderMessage})` : ''}; corrupt or truncated?`);
  }
  checkShape({ columns: fi.width, rows: fi.height, components: fi.componentCount, precision: fi.bitsPerSample }, shape, w.label);
  return { bytes, sampleBytes: fi.bitsPerSample > 8 ? 2 : 1 };
}

// These builds throw C++ exceptions as bare numbers (pointers, no message
// without exception support compiled in); say what we can.
function describeWasmError(m, e) {
  if (typeof e === 'number' && typeof m.getExceptionMessage === 'function') {
    try { return m.getExceptionMessage(e).join(': '); } catch { /* fall through */ }
  }
  return typeof e === 'number' ? 'it threw a C++ exception' : String(e);
}

// A 12-bit JPEG extended frame (DCT, Huffman; SOF1) through the JavaScript
// decoder, which throws strings; its 16-bit samples as stored pixel data
// holds them.
async function jpeg12Decode(frame, shape) {
  const JpegImage = (await loadModule('jpeg12.js')).default;
  const d = new JpegImage();
  let samples;
  try {
    d.parse(frame);
    d.colorTransform = false;
    checkShape({ columns: d.width, rows: d.height, components: d.components.length, precision: 12 }, shape, 'JPEG');
    samples = d.getData16(shape.columns, shape.rows);
  } catch (e) {
    if (e instanceof Error && /frame (is|has|of)/.test(e.message)) throw e;
    throw new Error(`the 12-bit JPEG decoder failed: ${e instanceof Error ? e.message : String(e)}; corrupt or truncated?`);
  }
  if (samples.length !== shape.columns * shape.rows) {
    throw new Error(`the 12-bit JPEG decoder returned ${samples.length} samples for a ${shape.columns}x${shape.rows} frame`);
  }
  return { bytes: new Uint8Array(samples.buffer, samples.byteOffset, samples.byteLength), sampleBytes: 2 };
}

async function losslessDecode(frame, shape) {
  const { Decoder } = await loadModule('lossless-min.js');
  const d = new Decoder();
  const out = d.decode(frame.buffer, frame.byteOffset, frame.length, shape.bitsAllocated / 8);
  checkShape({ columns: d.xDim, rows: d.yDim, components: d.numComp, precision: d.precision }, shape, 'JPEG lossless');
  return { bytes: new Uint8Array(out.buffer, out.byteOffset, out.byteLength), sampleBytes: shape.bitsAllocated / 8 };
}

// Every JPEG family stream ends with EOI, a JPEG 2000 codestream with EOC
// (both 0xffd9); a frame without one near its end (fragments are padded to
// even length) was cut short, which some decoders would fill in silently.
function checkEnd(frame) {
  for (let i = frame.length - 2; i >= Math.max(0, frame.length - 16); i--) {
    if (frame[i] === 0xff && frame[i + 1] === 0xd9) return;
  }
  throw new Error('the stream has no end marker (0xFFD9): truncated');
}

// Which decoder a frame needs, from its stream's own markers, once its
// header has been checked against the file's declarations.
function decoderFor(codec, frame, shape) {
  checkEnd(frame);
  if (codec === 'j2k' || codec === 'htj2k') {
    checkShape(j2kHeader(frame), shape, codec === 'j2k' ? 'JPEG 2000' : 'HTJ2K');
    // An HTJ2K syntax may carry a plain JPEG 2000 stream and the reverse:
    // OpenJPEG's build reads Part 1, OpenJPH's Part 15 (CAP marker, T.814).
    return hasCapMarker(frame) ? 'htj2k' : 'j2k';
  }
  const h = jpegFrameHeader(frame);
  checkShape(h, shape, 'JPEG');
  if (h.marker === 0xf7) return 'jpegls';
  if (h.marker === 0xc3) return 'lossless';
  if (h.marker === 0xc0 || h.marker === 0xc1) {
    if (h.precision === 12 && shape.bitsAllocated === 16) return 'jpeg12';
    if (h.precision !== 8) {
      throw new Error(`a ${h.precision}-bit JPEG frame in ${shape.bitsAllocated}-bit pixels: JPEG's DCT processes ` +
        'code 8 or 12 bits per sample');
    }
    return 'jpeg';
  }
  throw new Error(`a JPEG process (SOF marker 0x${h.marker.toString(16)}) the page does not decode`);
}

function decodeFrame(decoder, frame, shape) {
  if (decoder === 'lossless') return losslessDecode(frame, shape);
  if (decoder === 'jpeg12') return jpeg12Decode(frame, shape);
  return wasmDecode(decoder, frame, shape);
}

function hasCapMarker(b) {
  if (b[0] !== 0xff || b[1] !== 0x4f) return false;  // JP2-wrapped: OpenJPEG takes those
  // Main header markers after SIZ (its length counts its own two bytes), up
  // to the first tile (SOT 0xff90).
  let i = 4 + ((b[4] << 8) | b[5]);
  for (let n = 0; n < 64 && i + 4 <= b.length; n++) {
    if (b[i] !== 0xff) return false;
    if (b[i + 1] === 0x50) return true;
    if (b[i + 1] === 0x90) return false;
    i += 2 + ((b[i + 2] << 8) | b[i + 3]);
  }
  return false;
}

// ------------------------------------------------------------- Part 10

function reader(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  return {
    u16: (o) => view.getUint16(o, true),
    u32: (o) => view.getUint32(o, true),
    u64: (o) => Number(view.getBigUint64(o, true)),
    text: (o, n) => String.fromCharCode(...bytes.subarray(o, o + n)).replace(/[\0 ]+$/, ''),
  };
}

// The element at `at`: tag, VR, where its value starts, its length
// (0xffffffff = undefined).
function elementAt(r, bytes, at, explicit) {
  if (at + 8 > bytes.length) throw new Error(`an element header at byte ${at} runs past the end (truncated?)`);
  const group = r.u16(at), element = r.u16(at + 2);
  if (group === 0xfffe || !explicit) return { group, element, vr: '', value: at + 8, length: r.u32(at + 4) };
  const vr = String.fromCharCode(bytes[at + 4], bytes[at + 5]);
  if (LONG_VRS.has(vr)) {
    if (at + 12 > bytes.length) throw new Error(`an element header at byte ${at} runs past the end (truncated?)`);
    return { group, element, vr, value: at + 12, length: r.u32(at + 8) };
  }
  return { group, element, vr, value: at + 8, length: r.u16(at + 6) };
}

// The end of an undefined-length sequence whose items start at `at`.
function skipSequence(r, bytes, at, explicit, depth) {
  if (depth > MAX_DEPTH) throw new Error(`sequences nested deeper than ${MAX_DEPTH}`);
  for (;;) {
    const e = elementAt(r, bytes, at, false);
    if (e.group === 0xfffe && e.element === 0xe0dd) return e.value;
    if (e.group !== 0xfffe || e.element !== 0xe000) throw new Error(`a sequence item expected at byte ${at}`);
    at = e.length === 0xffffffff ? skipItems(r, bytes, e.value, explicit, depth + 1) : e.value + e.length;
  }
}

// The end of an undefined-length item's data set starting at `at`.
function skipItems(r, bytes, at, explicit, depth) {
  for (;;) {
    const e = elementAt(r, bytes, at, explicit);
    if (e.group === 0xfffe && e.element === 0xe00d) return e.value;
    at = e.length === 0xffffffff ? skipSequence(r, bytes, e.value, explicit && e.vr !== 'UN', depth + 1)
      : e.value + e.length;
    if (at > bytes.length) throw new Error('an element runs past the end of the file (truncated?)');
  }
}

// Where the parts of a Part-10 file are, and what it declares about its
// pixels. Null when the file is not Part 10 or its syntax is not one here.
function parsePart10(bytes) {
  if (bytes.length < 140 || bytes[128] !== 0x44 || bytes[129] !== 0x49 || bytes[130] !== 0x43 || bytes[131] !== 0x4d) return null;
  const r = reader(bytes);
  let at = 132, syntax = '';
  const meta = [];
  while (at + 8 <= bytes.length && r.u16(at) === 0x0002) {
    const e = elementAt(r, bytes, at, true);
    const end = e.value + e.length;
    if (end > bytes.length) throw new Error('the file meta information runs past the end (truncated?)');
    if (e.element === 0x0010) syntax = r.text(e.value, e.length);
    if (e.element !== 0x0000 && e.element !== 0x0010) meta.push(bytes.subarray(at, end));
    at = end;
  }
  const ts = SYNTAXES[syntax];
  if (!ts) return null;
  const info = { syntax, ts, meta, datasetStart: at, numbers: {}, omit: [] };
  for (;;) {
    const e = elementAt(r, bytes, at, true);
    if (e.group === 0x7fe0 && e.element === 0x0010) {
      if (e.length !== 0xffffffff) throw new Error(`its ${ts.name} pixel data is not encapsulated (defined length)`);
      Object.assign(info, { pixelStart: at, pixelItems: e.value });
      return info;
    }
    const end = e.length === 0xffffffff ? skipSequence(r, bytes, e.value, e.vr !== 'UN', 1) : e.value + e.length;
    if (end > bytes.length) throw new Error(`element (${hex(e.group)},${hex(e.element)}) runs past the end of the file (truncated?)`);
    const key = (e.group << 16) | e.element;
    if (e.group === 0x0028 && e.vr === 'US' && e.length >= 2) info.numbers[key] = r.u16(e.value);
    if (key === 0x00280008) info.numbers[key] = parseInt(r.text(e.value, e.length), 10);
    if (key === 0x7fe00001 || key === 0x7fe00002) {
      info.numbers[key] = Array.from({ length: Math.floor(e.length / 8) }, (_, k) => r.u64(e.value + 8 * k));
      info.omit.push([at, end]);  // the extended offset table describes nothing once decoded
    }
    at = end;
    if (at >= bytes.length) throw new Error(`no pixel data in its ${ts.name} data set`);
  }
}

function hex(n) { return n.toString(16).padStart(4, '0').toUpperCase(); }

// The encapsulated pixel data's basic offset table, fragments and end.
function fragmentsOf(r, bytes, at) {
  const items = [];
  for (;;) {
    const e = elementAt(r, bytes, at, false);
    if (e.group === 0xfffe && e.element === 0xe0dd) return { items, end: e.value };
    if (e.group !== 0xfffe || e.element !== 0xe000) throw new Error(`a pixel data fragment expected at byte ${at}`);
    if (e.value + e.length > bytes.length) {
      throw new Error(`pixel data fragment ${items.length} says ${e.length} bytes, past the end of the file (truncated?)`);
    }
    items.push({ at, data: bytes.subarray(e.value, e.value + e.length) });
    at = e.value + e.length;
  }
}

// Frames from fragments (PS3.5 A.4): one frame takes them all; otherwise the
// extended or basic offset table says where each frame starts, else one
// frame per fragment, else a new frame at each stream's start marker.
function framesOf(items, count, eot) {
  const bot = items[0].data, fragments = items.slice(1);
  if (fragments.length === 0) throw new Error('the encapsulated pixel data has no fragments');
  const joined = (list) => {
    if (list.length === 1) return list[0].data;
    const out = new Uint8Array(list.reduce((n, f) => n + f.data.length, 0));
    let o = 0;
    for (const f of list) { out.set(f.data, o); o += f.data.length; }
    return out;
  };
  if (count === 1) return [joined(fragments)];
  const first = fragments[0].at;
  let starts = null;
  if (eot && eot.length > 0) starts = eot;
  else if (bot.length > 0) {
    const r = reader(bot);
    starts = Array.from({ length: bot.length / 4 }, (_, k) => r.u32(4 * k));
  }
  if (starts) {
    if (starts.length !== count) throw new Error(`the offset table lists ${starts.length} frames, Number of Frames says ${count}`);
    const frames = [];
    for (let k = 0; k < count; k++) {
      const lo = first + starts[k], hi = k + 1 < count ? first + starts[k + 1] : Infinity;
      const list = fragments.filter((f) => f.at >= lo && f.at < hi);
      if (list.length === 0 || list[0].at !== lo) throw new Error(`the offset table's frame ${k + 1} does not start at a fragment`);
      frames.push(joined(list));
    }
    return frames;
  }
  if (fragments.length === count) return fragments.map((f) => f.data);
  const groups = [];
  for (const f of fragments) {
    const d = f.data;
    const starts = d.length >= 2 && d[0] === 0xff && (d[1] === 0xd8 || d[1] === 0x4f);
    if (starts || groups.length === 0) groups.push([f]); else groups[groups.length - 1].push(f);
  }
  if (groups.length !== count) throw new Error(`${fragments.length} fragments hold ${groups.length} frames, Number of Frames says ${count}`);
  return groups.map(joined);
}

// Part 10 again, explicit VR little endian, the pixel data decoded.
function rewritten(bytes, info, pixels, end) {
  const ts = new TextEncoder().encode(EXPLICIT_LE + '\0');  // even length
  const tsElement = new Uint8Array(8 + ts.length);
  tsElement.set([0x02, 0x00, 0x10, 0x00, 0x55, 0x49, ts.length, 0]);
  tsElement.set(ts, 8);
  const metaLength = info.meta.reduce((n, m) => n + m.length, 0) + tsElement.length;
  const ow = info.numbers[0x00280100] === 8 ? [0x4f, 0x42] : [0x4f, 0x57];
  const padded = pixels.length + (pixels.length & 1);
  const kept = [];  // the data set before the pixel data, less omitted elements
  let from = info.datasetStart;
  for (const [a, b] of info.omit) { kept.push(bytes.subarray(from, a)); from = b; }
  kept.push(bytes.subarray(from, info.pixelStart));
  const head = kept.reduce((n, k) => n + k.length, 0);
  const out = new Uint8Array(132 + 12 + metaLength + head + 12 + padded + (bytes.length - end));
  const v = new DataView(out.buffer);
  out.set(bytes.subarray(0, 132));
  let o = 132;
  out.set([0x02, 0x00, 0x00, 0x00, 0x55, 0x4c, 4, 0], o); v.setUint32(o + 8, metaLength, true); o += 12;
  for (const m of [...info.meta.filter((m) => m[2] < 0x10 && m[3] === 0), tsElement, ...info.meta.filter((m) => !(m[2] < 0x10 && m[3] === 0))]) {
    out.set(m, o); o += m.length;
  }
  for (const k of kept) { out.set(k, o); o += k.length; }
  out.set([0xe0, 0x7f, 0x10, 0x00, ow[0], ow[1], 0, 0], o); v.setUint32(o + 8, padded, true); o += 12;
  out.set(pixels, o); o += padded;
  out.set(bytes.subarray(end), o);
  return out;
}

// One compressed file decoded; null when it is not a compressed syntax.
async function decodeFile(name, bytes, stats) {
  let info;
  try {
    info = parsePart10(bytes);
  } catch (e) {
    throw new Error(`${name}: ${e.message}`);
  }
  if (!info) return null;
  const n = info.numbers;
  const shape = { rows: n[0x00280010], columns: n[0x00280011], bitsAllocated: n[0x00280100],
    samples: n[0x00280002] ?? 1 };
  const count = Number.isFinite(n[0x00280008]) ? n[0x00280008] : 1;
  if (!shape.rows || !shape.columns) throw new Error(`${name}: no Rows or Columns for its ${info.ts.name} pixel data`);
  if (shape.bitsAllocated !== 8 && shape.bitsAllocated !== 16) {
    throw new Error(`${name}: Bits Allocated is ${shape.bitsAllocated}; compressed frames are read with 8 or 16`);
  }
  if (count < 1) throw new Error(`${name}: Number of Frames is ${n[0x00280008]}`);
  const frameBytes = shape.rows * shape.columns * shape.samples * (shape.bitsAllocated / 8);
  if (frameBytes * count > MAX_DECODED) {
    throw new Error(`${name}: ${count} frames of ${shape.columns}x${shape.rows} declare ${(frameBytes * count / 1048576).toFixed(0)} MiB of pixels, more than the page decodes (${MAX_DECODED / 1048576} MiB)`);
  }
  let frames, end;
  try {
    const r = reader(bytes);
    const f = fragmentsOf(r, bytes, info.pixelItems);
    if (f.items.length === 0) throw new Error('the encapsulated pixel data has no basic offset table item');
    end = f.end;
    frames = framesOf(f.items, count, n[0x7fe00001]);
  } catch (e) {
    throw new Error(`${name}: ${e.message}`);
  }
  const where = (k) => (count > 1 ? `frame ${k + 1} of ${count}` : 'its frame');
  const failed = (k, e) => new Error(`${name}: ${where(k)} (${info.ts.name}) cannot be decoded: ${e.message}`);
  // Every frame's header first, so that nothing is allocated for a file
  // whose frames do not hold what it declares.
  const decoders = frames.map((f, k) => {
    try { return decoderFor(info.ts.codec, f, shape); } catch (e) { throw failed(k, e); }
  });
  const pixels = new Uint8Array(frameBytes * count);
  for (let k = 0; k < count; k++) {
    let d;
    try {
      d = await decodeFrame(decoders[k], frames[k], shape);
    } catch (e) {
      throw failed(k, e);
    }
    const samples = shape.rows * shape.columns * shape.samples;
    if (d.bytes.length !== samples * d.sampleBytes) {
      throw new Error(`${name}: ${where(k)} decoded to ${d.bytes.length} bytes, not the ${samples * d.sampleBytes} its header declares`);
    }
    const target = pixels.subarray(k * frameBytes, (k + 1) * frameBytes);
    if (d.sampleBytes === shape.bitsAllocated / 8) target.set(d.bytes);
    else if (d.sampleBytes === 1) for (let i = 0; i < samples; i++) target[2 * i] = d.bytes[i];  // 8-bit samples, 16 allocated
    else throw new Error(`${name}: ${where(k)} decoded to 16-bit samples, but Bits Allocated is 8`);
    stats.frames++;
  }
  stats.syntaxes.add(info.ts.name);
  return { bytes: rewritten(bytes, info, pixels, end), pixels };
}

// Entries ({name, bytes}) with every compressed DICOM file decoded; the
// others unchanged. onProgress(filesDone, total).
export async function decodeEntries(entries, onProgress = () => {}) {
  const t0 = performance.now();
  const stats = { files: 0, frames: 0, syntaxes: new Set(), ms: 0 };
  const out = [], pixels = [];
  for (let i = 0; i < entries.length; i++) {
    const e = entries[i];
    const decoded = await decodeFile(e.name, e.bytes, stats);
    if (decoded) {
      stats.files++;
      pixels.push({ name: e.name, pixels: decoded.pixels });
    }
    out.push(decoded ? { name: e.name, bytes: decoded.bytes } : e);
    onProgress(i + 1, entries.length);
  }
  stats.ms = performance.now() - t0;
  lastStats = { ...stats, syntaxes: [...stats.syntaxes] };
  lastPixels = pixels;
  return out;
}

export function isCompressedSyntax(uid) { return Object.prototype.hasOwnProperty.call(SYNTAXES, uid); }

// For tests: what the last decode did, and each file's decoded pixels.
let lastStats = null, lastPixels = null;
export function last() { return { stats: lastStats, pixels: lastPixels }; }
