// A DICOMweb archive in the page (?dicomweb=ROOT, PS3.18): a study/series
// browser (QIDO-RS: a search box over a table of series), and a series
// opened from it (WADO-RS): its metadata, then each instance's frame as the
// archive stores it (multipart/related, transfer-syntax=*, several requests
// at once), parsed here. Each instance becomes a Part-10 file again
// (explicit VR little endian from its DICOM JSON, the frame encapsulated in
// the syntax it came in); compressed frames are decoded as they arrive by
// dicom-codecs.js, the decoders of dropped files, and shown in a preview
// (the frame, and a reformat through the stack that fills in slice by
// slice). When the stack is complete the files go to the page's
// openEntries(), the path a dropped folder takes (the module's io readers:
// io/DicomBasicReader.h), so a series read here has the dropped folder's
// voxels and geometry. The 3D and slice views show a volume only once it is
// whole: the module builds it from the complete stack.
//
// Every failure is one line naming the URL at fault (HTTP status, an answer
// that is not JSON, a multipart body without its boundary, a frame of the
// wrong size, a server that stopped); the table and the previous volume
// stay usable. Loaded by app.js only with ?dicomweb=.

const ACCEPT_FRAMES = 'multipart/related; type="application/octet-stream"; transfer-syntax=*';
const ACCEPT_INSTANCE = 'multipart/related; type="application/dicom"; transfer-syntax=*';
const ACCEPT_JSON = 'application/dicom+json, application/json';
const CONNECTIONS = 6;  // a browser's HTTP/1.1 connections per origin
const FRAMES_PER_REQUEST = 64;  // of a multi-frame object (as the CLI asks)
const MOST_FRAMES = 1 << 16;  // io/DicomMultiFrame.cpp's bound
const MOST_PIXEL_BYTES = 1024 * 1048576;  // of one instance (dicom-codecs.js decodes no more)
const MAX_JSON = 256 * 1048576;
const UNCOMPRESSED = new Set(['1.2.840.10008.1.2', '1.2.840.10008.1.2.1', '1.2.840.10008.1.2.1.99']);
const BIG_ENDIAN = '1.2.840.10008.1.2.2';
const RLE = '1.2.840.10008.1.2.5';
// PS3.18 table 8.7.3-5: a part's media type's default transfer syntax.
const MEDIA_DEFAULT = {
  'application/octet-stream': '1.2.840.10008.1.2.1', 'image/jpeg': '1.2.840.10008.1.2.4.70',
  'image/jls': '1.2.840.10008.1.2.4.80', 'image/jp2': '1.2.840.10008.1.2.4.90',
  'image/jpx': '1.2.840.10008.1.2.4.92', 'image/jphc': '1.2.840.10008.1.2.4.201',
  'image/dicom-rle': RLE, 'image/x-dicom-rle': RLE,
};
const HTTP_HINT = {
  400: 'the archive refused the request', 401: 'the archive wants credentials',
  403: 'the archive refuses access', 404: 'no such study, series or instance, or not a DICOMweb service root',
  406: 'the archive cannot send this representation', 500: 'the archive failed',
  503: 'the archive is unavailable',
};

// ------------------------------------------------------------------ HTTP

// An error for the page: one line, naming the URL.
function failure(url, why) { return new Error(`${url}: ${why}`); }

// GET with `accept`; the response's bytes, counted in `stats`.
async function get(url, accept, stats, signal) {
  let r;
  try {
    r = await fetch(url, { headers: { Accept: accept }, signal, cache: 'no-store' });
  } catch (e) {
    if (signal && signal.aborted) throw e;
    throw failure(url, `no answer (${e.message}): is the archive running, and does it allow this origin (CORS)?`);
  }
  let bytes;
  try {
    bytes = new Uint8Array(await r.arrayBuffer());
  } catch (e) {
    if (signal && signal.aborted) throw e;
    throw failure(url, `the answer stopped after its headers (${e.message}): did the archive stop?`);
  }
  if (stats) { stats.requests++; stats.bytes += bytes.length; }
  if (!r.ok) {
    const hint = HTTP_HINT[r.status] || '';
    throw failure(url, `HTTP ${r.status} ${r.statusText || ''}`.trim() + (hint ? `: ${hint}` : ''));
  }
  return { bytes, type: r.headers.get('Content-Type') || '' };
}

function textStart(bytes, n = 40) {
  return new TextDecoder('latin1').decode(bytes.subarray(0, n)).replace(/[^\x20-\x7e]/g, '.');
}

async function getJson(url, stats, signal) {
  const { bytes, type } = await get(url, ACCEPT_JSON, stats, signal);
  if (bytes.length === 0) return [];  // QIDO-RS: 204 or an empty body is no match
  if (bytes.length > MAX_JSON) throw failure(url, `a JSON answer of ${bytes.length} bytes, more than ${MAX_JSON}`);
  let j;
  try {
    j = JSON.parse(new TextDecoder().decode(bytes));
  } catch (e) {
    throw failure(url, `the answer is not JSON (Content-Type '${type}', starts '${textStart(bytes)}'): not a DICOMweb service root?`);
  }
  if (!Array.isArray(j)) throw failure(url, `the answer is JSON but not an array of DICOM data sets (starts '${textStart(bytes)}')`);
  return j;
}

// A media type's parameter (quoted or not), '' when absent.
function parameter(contentType, name) {
  const re = new RegExp(`(?:^|;)\\s*${name}\\s*=\\s*("([^"]*)"|[^;\\s]*)`, 'i');
  const m = contentType.match(re);
  return m ? (m[2] !== undefined ? m[2] : m[1]) : '';
}

function indexOf(hay, needle, from) {
  const first = needle[0], last = hay.length - needle.length;
  for (let i = hay.indexOf(first, from); i !== -1 && i <= last; i = hay.indexOf(first, i + 1)) {
    let k = 1;
    while (k < needle.length && hay[i + k] === needle[k]) k++;
    if (k === needle.length) return i;
  }
  return -1;
}

// The parts of a multipart/related body (RFC 2046 5.1.1): [{type, data}].
export function multipartParts(url, contentType, body) {
  const fail = (why) => failure(url, `multipart body: ${why}`);
  if (!/^multipart\/related/i.test(contentType.trim())) {
    throw fail(`the answer is '${contentType || 'untyped'}', not multipart/related (starts '${textStart(body)}')`);
  }
  // The boundary: after `type="…; …"`, whose quoted value has semicolons.
  const outer = contentType.replace(/"[^"]*"/g, (q) => q.replace(/;/g, ','));
  const boundary = parameter(outer, 'boundary');
  if (!boundary) throw fail(`its Content-Type '${contentType}' names no boundary`);
  const enc = new TextEncoder();
  const dash = enc.encode(`--${boundary}`);
  const delimiter = enc.encode(`\r\n--${boundary}`);
  let at = indexOf(body, dash, 0);
  if (at === -1) throw fail(`the boundary '${boundary}' of its Content-Type never occurs (body starts '${textStart(body)}')`);
  const parts = [];
  for (;;) {
    at += dash.length;
    if (body[at] === 0x2d && body[at + 1] === 0x2d) break;  // the close delimiter
    const headersEnd = indexOf(body, enc.encode('\r\n\r\n'), at);
    if (headersEnd === -1) throw fail(`part ${parts.length + 1} has no end of its headers (truncated?)`);
    const headers = new TextDecoder('latin1').decode(body.subarray(at, headersEnd));
    const type = (headers.match(/^content-type:\s*(.*)$/im) || [])[1] || '';
    const start = headersEnd + 4;
    const next = indexOf(body, delimiter, start);
    if (next === -1) throw fail(`part ${parts.length + 1} never ends: no boundary after it (truncated?)`);
    parts.push({ type: type.trim(), data: body.subarray(start, next) });
    at = next + 2;
  }
  if (parts.length === 0) throw fail('no part');
  return parts;
}

function partSyntax(type) {
  const ts = parameter(type, 'transfer-syntax');
  if (ts) return ts;
  return MEDIA_DEFAULT[type.split(';')[0].trim().toLowerCase()] || '';
}

// ------------------------------------------------------------------ DICOM JSON

const value = (ds, tag) => (ds && ds[tag] && ds[tag].Value ? ds[tag].Value : []);
const first = (ds, tag, dflt = '') => { const v = value(ds, tag); return v.length ? v[0] : dflt; };
function personName(ds, tag) {
  const v = first(ds, tag, null);
  return v && typeof v === 'object' ? (v.Alphabetic || v.Ideographic || '') : (v || '');
}

const TEXT_VRS = new Set(['AE', 'AS', 'CS', 'DA', 'DS', 'DT', 'IS', 'LO', 'LT', 'PN', 'SH', 'ST', 'TM', 'UC', 'UI', 'UR', 'UT']);
const LONG_VRS = new Set(['OB', 'OD', 'OF', 'OL', 'OV', 'OW', 'SQ', 'UC', 'UN', 'UR', 'UT', 'SV', 'UV']);
const BINARY = { US: [2, 'setUint16'], SS: [2, 'setInt16'], UL: [4, 'setUint32'], SL: [4, 'setInt32'],
  FL: [4, 'setFloat32'], FD: [8, 'setFloat64'] };

// An element's value bytes from its DICOM JSON (PS3.18 F.2), or null when
// it cannot be written (bulk data by reference).
function valueBytes(vr, el, writeItems) {
  if (vr === 'SQ') return writeItems(el.Value || []);
  if (TEXT_VRS.has(vr)) {
    const parts = (el.Value || []).map((v) => {
      if (v === null || v === undefined) return '';
      if (vr === 'PN') return typeof v === 'object' ? [v.Alphabetic, v.Ideographic, v.Phonetic].filter((x) => x !== undefined).join('=') : String(v);
      // Decimal strings sent as JSON numbers: the shortest form that reads
      // back to the same double (what the native client writes too).
      if (vr === 'IS' && typeof v === 'number') return String(Math.trunc(v));
      return String(v);
    });
    let b = new TextEncoder().encode(parts.join('\\'));
    if (b.length & 1) {
      const p = new Uint8Array(b.length + 1);
      p.set(b);
      p[b.length] = vr === 'UI' ? 0 : 0x20;
      b = p;
    }
    return b;
  }
  if (BINARY[vr]) {
    const [size, set] = BINARY[vr];
    const vals = el.Value || [];
    const b = new Uint8Array(size * vals.length);
    const dv = new DataView(b.buffer);
    vals.forEach((v, i) => dv[set](i * size, Number(v), true));
    return b;
  }
  if (vr === 'AT') {
    const vals = el.Value || [];
    const b = new Uint8Array(4 * vals.length);
    const dv = new DataView(b.buffer);
    vals.forEach((v, i) => { const n = parseInt(v, 16); dv.setUint16(4 * i, n >>> 16, true); dv.setUint16(4 * i + 2, n & 0xffff, true); });
    return b;
  }
  if (el.InlineBinary !== undefined) {
    const s = atob(el.InlineBinary);
    const b = new Uint8Array(s.length + (s.length & 1));
    for (let i = 0; i < s.length; i++) b[i] = s.charCodeAt(i);
    return b;
  }
  if (el.BulkDataURI === undefined && !el.Value) return new Uint8Array(0);
  return null;
}

function header(group, element, vr, length) {
  const long = LONG_VRS.has(vr);
  const b = new Uint8Array(long ? 12 : 8);
  const dv = new DataView(b.buffer);
  dv.setUint16(0, group, true);
  dv.setUint16(2, element, true);
  b[4] = vr.charCodeAt(0);
  b[5] = vr.charCodeAt(1);
  if (long) dv.setUint32(8, length, true); else dv.setUint16(6, length, true);
  return b;
}

// A data set's elements (sorted by tag) as explicit VR little endian.
function dataSetBytes(ds, skip) {
  const out = [];
  const writeItems = (items) => {
    const chunks = [];
    for (const item of items) {
      const body = dataSetBytes(item || {}, () => false);
      const h = new Uint8Array(8);
      new DataView(h.buffer).setUint32(0, 0xe000fffe, true);
      new DataView(h.buffer).setUint32(4, body.length, true);
      chunks.push(h, body);
    }
    return concat(chunks);
  };
  for (const key of Object.keys(ds).sort()) {
    const tag = parseInt(key, 16);
    if (!/^[0-9A-Fa-f]{8}$/.test(key) || skip(tag)) continue;
    const el = ds[key];
    const vr = (el && el.vr) || 'UN';
    const v = valueBytes(vr, el, writeItems);
    if (v === null) continue;
    const shortVr = !LONG_VRS.has(vr);
    if (shortVr && v.length > 0xffff) continue;  // not representable; no reader needs it
    out.push(header(tag >>> 16, tag & 0xffff, vr, v.length), v);
  }
  return concat(out);
}

function concat(chunks) {
  const out = new Uint8Array(chunks.reduce((n, c) => n + c.length, 0));
  let o = 0;
  for (const c of chunks) { out.set(c, o); o += c.length; }
  return out;
}

// A Part-10 file from an instance's metadata and its frames (an array, in
// frame order): stored uncompressed (defined length, the frames one after
// another) or encapsulated in `syntax`, one fragment per frame and an
// empty Basic Offset Table (PS3.5 A.4). A multi-frame object keeps its
// Number of Frames and functional groups (DICOM JSON sequences), which the
// module's reader places its frames by (io/DicomMultiFrame.cpp).
function part10(ds, syntax, frames, encapsulated) {
  const ui = (s) => { const b = new TextEncoder().encode(s); return b.length & 1 ? concat([b, new Uint8Array(1)]) : b; };
  const metaElements = concat([
    header(0x0002, 0x0001, 'OB', 2), new Uint8Array([0, 1]),
    header(0x0002, 0x0002, 'UI', ui(first(ds, '00080016')).length), ui(first(ds, '00080016')),
    header(0x0002, 0x0003, 'UI', ui(first(ds, '00080018')).length), ui(first(ds, '00080018')),
    header(0x0002, 0x0010, 'UI', ui(syntax).length), ui(syntax),
  ]);
  const groupLength = concat([header(0x0002, 0x0000, 'UL', 4), new Uint8Array(new Uint32Array([metaElements.length]).buffer)]);
  // Text is written as UTF-8 (DICOM JSON is), so the character set says so.
  const withCharset = { ...ds, '00080005': { vr: 'CS', Value: ['ISO_IR 192'] } };
  const body = dataSetBytes(withCharset, (tag) => (tag >>> 16) === 0x0002 || tag >= 0x7fe00000);
  const ob = first(ds, '00280100', 16) === 8 || encapsulated ? 'OB' : 'OW';
  let pixels;
  const even = (b) => (b.length & 1 ? concat([b, new Uint8Array(1)]) : b);
  if (encapsulated) {
    const item = (n) => { const h = new Uint8Array(8); const v = new DataView(h.buffer); v.setUint32(0, 0xe000fffe, true); v.setUint32(4, n, true); return h; };
    const end = new Uint8Array(8);
    new DataView(end.buffer).setUint32(0, 0xe0ddfffe, true);
    const fragments = frames.flatMap((f) => { const p = even(f); return [item(p.length), p]; });
    pixels = concat([header(0x7fe0, 0x0010, 'OB', 0xffffffff), item(0), ...fragments, end]);
  } else {
    const padded = even(frames.length === 1 ? frames[0] : concat(frames));
    pixels = concat([header(0x7fe0, 0x0010, ob, padded.length), padded]);
  }
  const preamble = new Uint8Array(132);
  preamble.set([0x44, 0x49, 0x43, 0x4d], 128);
  return concat([preamble, groupLength, metaElements, body, pixels]);
}

// An instance's frames (WADO-RS frames/1,2,…, as stored, FRAMES_PER_REQUEST
// to a request): {url, syntax, entry (a Part-10 file), pixels (uncompressed
// frames one after another, else null), compressed}.
async function framesOf(inst, signal, stats) {
  const frames = [];
  let syntax = '';
  let url = '';
  for (let from = 1; from <= inst.frames; from += FRAMES_PER_REQUEST) {
    const n = Math.min(FRAMES_PER_REQUEST, inst.frames - from + 1);
    const list = Array.from({ length: n }, (_, k) => from + k).join(',');
    url = `${inst.url}/frames/${list}`;
    const { bytes, type } = await get(url, ACCEPT_FRAMES, stats, signal);
    if (bytes.length > n * (2 * inst.frameBytes + 65536)) {
      throw failure(url, `an answer of ${bytes.length} bytes for ${n} frame(s) of ${inst.frameBytes} bytes (at most twice that, plus 64 KiB, each)`);
    }
    const parts = multipartParts(url, type, bytes);
    if (parts.length !== n) throw failure(url, `${parts.length} parts for ${n} frame(s)`);
    for (const part of parts) {
      const ts = partSyntax(part.type);
      if (!ts) throw failure(url, `the part's Content-Type '${part.type}' names no transfer syntax`);
      if (syntax && ts !== syntax) throw failure(url, `frames in transfer syntaxes ${syntax} and ${ts}: one instance has one`);
      syntax = ts;
      frames.push(part.data);
    }
  }
  let pixels = null;
  if (UNCOMPRESSED.has(syntax) || syntax === BIG_ENDIAN) {
    const ds = inst.ds;
    for (let k = 0; k < frames.length; k++) {
      let data = frames[k];
      if (data.length !== inst.frameBytes && data.length !== inst.frameBytes + 1) {
        throw failure(url, `${frames.length > 1 ? `frame ${k + 1}` : 'the frame'} holds ${data.length} bytes, but its ${first(ds, '00280011')}x${first(ds, '00280010')} pixels x ${first(ds, '00280100') / 8} bytes = ${inst.frameBytes} bytes`);
      }
      data = data.slice(0, inst.frameBytes);
      if (syntax === BIG_ENDIAN && first(ds, '00280100') === 16) {
        for (let i = 0; i + 1 < data.length; i += 2) { const t = data[i]; data[i] = data[i + 1]; data[i + 1] = t; }
      }
      frames[k] = data;
    }
    syntax = '1.2.840.10008.1.2.1';
    pixels = frames.length === 1 ? frames[0] : concat(frames);
  }
  const encapsulated = syntax !== '1.2.840.10008.1.2.1';
  return { url, syntax, pixels, compressed: encapsulated && syntax !== RLE,
    entry: { name: inst.url, bytes: part10(inst.ds, syntax, frames, encapsulated) } };
}

// The instance as the archive stores it (WADO-RS, application/dicom,
// transfer-syntax=*): the same result as framesOf().
async function instanceOf(inst, signal, stats) {
  const url = inst.url;
  const { bytes, type } = await get(url, ACCEPT_INSTANCE, stats, signal);
  if (bytes.length > 2 * inst.frames * inst.frameBytes + 16 * 1048576) {
    throw failure(url, `an answer of ${bytes.length} bytes for ${inst.frames} frame(s) of ${inst.frameBytes} bytes`);
  }
  const parts = multipartParts(url, type, bytes);
  if (parts.length !== 1) throw failure(url, `${parts.length} parts for one instance`);
  const file = parts[0].data.slice();
  const syntax = part10Syntax(file);
  if (!syntax) throw failure(url, 'the part is not a DICOM Part-10 file');
  return { url, syntax, pixels: null, compressed: !UNCOMPRESSED.has(syntax) && syntax !== BIG_ENDIAN && syntax !== RLE,
    entry: { name: inst.url, bytes: file } };
}

// The pixel data of a file dicom-codecs.js decoded (explicit VR LE, OW or
// OB of the frame's size), found from the end; null when it is not there.
// (Its last() is shared by concurrent decodes, so it is not used here.)
function decodedPixels(b, frameBytes) {
  const padded = frameBytes + (frameBytes & 1);
  const v = new DataView(b.buffer, b.byteOffset, b.byteLength);
  for (let at = b.length - padded - 12; at >= 132; at--) {
    if (b[at] === 0xe0 && b[at + 1] === 0x7f && b[at + 2] === 0x10 && b[at + 3] === 0x00 && b[at + 4] === 0x4f &&
        (b[at + 5] === 0x57 || b[at + 5] === 0x42) && v.getUint32(at + 8, true) === padded) {
      return b.subarray(at + 12, at + 12 + frameBytes);
    }
  }
  return null;
}

// A Part-10 file's transfer syntax (its meta group, explicit VR LE), '' if none.
function part10Syntax(b) {
  if (b.length < 144 || b[128] !== 0x44 || b[129] !== 0x49 || b[130] !== 0x43 || b[131] !== 0x4d) return '';
  const v = new DataView(b.buffer, b.byteOffset, b.byteLength);
  for (let at = 132; at + 8 <= b.length && v.getUint16(at, true) === 0x0002;) {
    const vr = String.fromCharCode(b[at + 4], b[at + 5]);
    const long = LONG_VRS.has(vr);
    const length = long ? v.getUint32(at + 8, true) : v.getUint16(at + 6, true);
    const start = at + (long ? 12 : 8);
    if (v.getUint16(at + 2, true) === 0x0010) return new TextDecoder().decode(b.subarray(start, Math.min(start + length, b.length))).replace(/[\0 ]+$/, '');
    at = start + length;
  }
  return '';
}

// ------------------------------------------------------------------ the panel

export function attach(opts) {
  const { root: rootParam, openEntries, showError, clearError, status, progress } = opts;
  const root = new URL(rootParam, location.href).href.replace(/\/+$/, '');
  let rows = [];          // series of the table
  let last = null;        // what the last open did (for tests and the bench)
  let busy = null;        // AbortController of the open in progress
  let codecs = null;

  const panel = document.createElement('section');
  panel.id = 'dicomweb';
  panel.setAttribute('aria-label', 'DICOMweb studies and series');
  panel.innerHTML = `
    <div class="row"><strong>DICOMweb</strong> <span class="note dw-root"></span>
      <input type="search" class="dw-search" placeholder="search patient, ID, description, modality, date" aria-label="Search the series">
      <button class="dw-reload">Reload</button> <span class="note dw-count" role="status" aria-live="polite"></span></div>
    <div class="dw-table-box"><table class="dw-table"><thead><tr><th>Patient</th><th>ID</th><th>Date</th>
      <th>Study</th><th>Modality</th><th>Series</th><th>#</th><th>Images</th><th></th></tr></thead><tbody></tbody></table></div>
    <div class="dw-preview" hidden><canvas class="dw-frame" aria-label="The last frame received"></canvas>
      <canvas class="dw-stack" aria-label="A reformat through the stack, filled in as frames arrive"></canvas>
      <span class="note dw-preview-note">Frames as they arrive (left: the last one; right: a cut through the stack filling in).
      The 3D and slice views show the series once the stack is complete.</span></div>`;
  const errorBox = document.getElementById('error');
  errorBox.parentNode.insertBefore(panel, errorBox.nextSibling);
  const q = (sel) => panel.querySelector(sel);
  q('.dw-root').textContent = root;
  q('.dw-search').addEventListener('input', draw);
  q('.dw-reload').addEventListener('click', () => list().catch(() => {}));  // shown

  function draw() {
    const words = q('.dw-search').value.toLowerCase().split(/\s+/).filter((w) => w);
    const shown = rows.filter((r) => words.every((w) => r.text.includes(w)));
    const tbody = q('tbody');
    tbody.replaceChildren(...shown.map((r) => {
      const tr = document.createElement('tr');
      tr.dataset.series = r.series;
      for (const v of [r.patient, r.patientId, r.date, r.study_description, r.modality, r.description, r.number, r.instances]) {
        const td = document.createElement('td');
        td.textContent = v;
        tr.appendChild(td);
      }
      const td = document.createElement('td');
      const b = document.createElement('button');
      b.textContent = 'Open';
      b.className = 'dw-open';
      b.addEventListener('click', () => open(r.study, r.series).catch(() => {}));
      td.appendChild(b);
      tr.appendChild(td);
      return tr;
    }));
    q('.dw-count').textContent = `${shown.length} of ${rows.length} series`;
  }

  // QIDO-RS: the studies, then each study's series. Resolves to the rows.
  async function list() {
    const stats = { requests: 0, bytes: 0 };
    q('.dw-count').textContent = 'searching…';
    try {
      const studies = await getJson(`${root}/studies?includefield=00081030&includefield=00080061&includefield=00201206&includefield=00201208`, stats);
      const out = [];
      for (const s of studies) {
        const study = first(s, '0020000D');
        if (!study) continue;
        const series = await getJson(`${root}/studies/${study}/series?includefield=0008103E&includefield=00201209&includefield=00200011`, stats);
        for (const r of series) {
          const row = {
            study, series: first(r, '0020000E'), patient: personName(s, '00100010'), patientId: String(first(s, '00100020')),
            date: String(first(s, '00080020')), study_description: String(first(s, '00081030')),
            modality: String(first(r, '00080060')), description: String(first(r, '0008103E')),
            number: String(first(r, '00200011')), instances: Number(first(r, '00201209', 0)),
          };
          row.text = [row.patient, row.patientId, row.date, row.study_description, row.modality, row.description].join(' ').toLowerCase();
          if (row.series) out.push(row);
        }
      }
      rows = out;
      clearError();
    } catch (e) {
      showError(e.message);
      q('.dw-count').textContent = 'search failed';
      throw e;
    }
    draw();
    return rows.map(({ text, ...r }) => r);
  }

  // The preview: the last frame, and a cut through the stack (the middle
  // row of each frame, one line per slice in position order).
  // Rows of the cut: one per frame (a multi-frame object's in frame order).
  function preview(instances, total) {
    const box = q('.dw-preview');
    box.hidden = false;
    const ds = instances[0].ds;
    const cols = first(ds, '00280011'), rowsN = first(ds, '00280010');
    const frame = q('.dw-frame'), stack = q('.dw-stack');
    frame.width = cols; frame.height = rowsN;
    stack.width = cols; stack.height = total;
    // Shown in millimetres: the pixel spacing across, the slice spacing down.
    const dx = Number(value(ds, '00280030')[1] || 1);
    const dz = instances.length > 1 ? Math.abs(instances[instances.length - 1].along - instances[0].along) / (instances.length - 1) : dx;
    stack.style.aspectRatio = `${cols * dx} / ${total * (dz || dx)}`;
    frame.style.aspectRatio = `${cols * dx} / ${rowsN * Number(value(ds, '00280030')[0] || dx)}`;
    const fctx = frame.getContext('2d'), sctx = stack.getContext('2d');
    sctx.fillStyle = '#223'; sctx.fillRect(0, 0, stack.width, stack.height);
    const slope = Number(first(ds, '00281053', 1)), intercept = Number(first(ds, '00281052', 0));
    let c = Number(first(ds, '00281050', NaN)), w = Number(first(ds, '00281051', NaN));
    const signed = first(ds, '00280103', 0) === 1, bytes = first(ds, '00280100', 16) / 8;
    const sample = (pixels, i) => {
      const v = bytes === 1 ? pixels[i] : (pixels[2 * i] | (pixels[2 * i + 1] << 8));
      return (signed && bytes === 2 && v >= 32768 ? v - 65536 : v) * slope + intercept;
    };
    const grey = (v) => Math.max(0, Math.min(255, Math.round(255 * ((v - (c - w / 2)) / w))));
    return (k, pixels) => {
      if (!pixels) return;
      if (!(w > 0)) {  // no window in the series: the first frame's range
        let lo = Infinity, hi = -Infinity;
        for (let i = 0; i < cols * rowsN; i++) { const v = sample(pixels, i); lo = Math.min(lo, v); hi = Math.max(hi, v); }
        c = (lo + hi) / 2; w = Math.max(hi - lo, 1);
      }
      const img = fctx.createImageData(cols, rowsN);
      for (let i = 0; i < cols * rowsN; i++) {
        const g = grey(sample(pixels, i));
        img.data.set([g, g, g, 255], 4 * i);
      }
      fctx.putImageData(img, 0, 0);
      const line = sctx.createImageData(cols, 1);
      const r0 = Math.floor(rowsN / 2) * cols;
      for (let x = 0; x < cols; x++) { const g = grey(sample(pixels, r0 + x)); line.data.set([g, g, g, 255], 4 * x); }
      sctx.putImageData(line, 0, total - 1 - k);  // superior at the top
    };
  }

  // WADO-RS: the series' metadata, then every instance's frame; the
  // volume shown once all are in. Resolves to the stats of the open;
  // rejects (after showing the error) when it fails.
  async function open(study, series) {
    if (busy) busy.abort();
    const controller = new AbortController();
    busy = controller;
    const signal = controller.signal;
    const seriesUrl = `${root}/studies/${study}/series/${series}`;
    const t0 = performance.now();
    const stats = { url: seriesUrl, fallbacks: 0, requests: 0, bytes: 0, instances: 0, frames: 0, syntaxes: [], metadataMs: 0,
      framesMs: 0, openMs: 0, ms: 0, firstFrameMs: 0, shown: [] };
    last = stats;
    const syntaxes = new Set();
    progress(0, 1);
    status(`reading ${seriesUrl}/metadata…`);
    try {
      const meta = await getJson(`${seriesUrl}/metadata`, stats, signal);
      stats.metadataMs = performance.now() - t0;
      if (meta.length === 0) throw failure(`${seriesUrl}/metadata`, 'the series has no instances');
      const instances = meta.map((ds) => {
        const sop = first(ds, '00080018');
        const url = `${seriesUrl}/instances/${sop}`;
        if (!sop) throw failure(`${seriesUrl}/metadata`, 'an instance without SOP Instance UID');
        // A multi-frame object (Enhanced CT/MR, legacy converted enhanced,
        // classic) is read whole: its frames are placed by the module's
        // reader from the functional groups its metadata holds.
        const frames = Number(first(ds, '00280008', 1));
        const rowsN = first(ds, '00280010'), cols = first(ds, '00280011'), bits = first(ds, '00280100');
        if (!(rowsN > 0 && cols > 0) || (bits !== 8 && bits !== 16)) throw failure(url, `Rows ${rowsN}, Columns ${cols}, Bits Allocated ${bits}: not an image the page reads`);
        const spp = first(ds, '00280002', 1);
        const frameBytes = rowsN * cols * spp * bits / 8;
        if (!(Number.isInteger(frames) && frames >= 1 && frames <= MOST_FRAMES)) throw failure(url, `Number of Frames (0028,0008) is ${first(ds, '00280008')}: expected 1 to ${MOST_FRAMES}`);
        if (frames * frameBytes > MOST_PIXEL_BYTES) throw failure(url, `${frames} frames of ${cols}x${rowsN} are ${(frames * frameBytes / 1048576).toFixed(0)} MiB of pixels, more than the page reads (${MOST_PIXEL_BYTES / 1048576} MiB)`);
        // Its plane for the preview's order: the first frame's, for an
        // enhanced object from its functional groups.
        const perFrame = first(ds, '52009230', null), shared = first(ds, '52009229', null);
        const macro = (tag) => first(perFrame, tag, null) || first(shared, tag, null);
        const ipp = (value(ds, '00200032').length ? value(ds, '00200032') : value(macro('00209113'), '00200032')).map(Number);
        const iop = (value(ds, '00200037').length ? value(ds, '00200037') : value(macro('00209116'), '00200037')).map(Number);
        const n = iop.length === 6 ? [iop[1] * iop[5] - iop[2] * iop[4], iop[2] * iop[3] - iop[0] * iop[5], iop[0] * iop[4] - iop[1] * iop[3]] : [0, 0, 1];
        const along = ipp.length === 3 ? ipp[0] * n[0] + ipp[1] * n[1] + ipp[2] * n[2] : Number(first(ds, '00200013', 0));
        return { ds, sop, url, along, frames, frameBytes, row: 0, entry: null };
      });
      instances.sort((a, b) => a.along - b.along);
      let rowsSoFar = 0;
      for (const inst of instances) { inst.row = rowsSoFar; rowsSoFar += inst.frames; }
      const totalFrames = rowsSoFar;
      stats.instances = instances.length;
      stats.multiFrame = instances.filter((i) => i.frames > 1).length;
      const show = preview(instances, totalFrames);
      progress(0, totalFrames);
      let done = 0;
      let wholeInstances = false;
      const fetchOne = async (k) => {
        const inst = instances[k];
        let got;
        const whole = wholeInstances;
        try {
          got = whole ? await instanceOf(inst, signal, stats) : await framesOf(inst, signal, stats);
        } catch (e) {
          // Some archives cannot send a frame of some syntaxes on its own
          // (Orthanc 1.10 answers HTTP 500 "Not implemented yet" for HTJ2K
          // frames): the instance as it is stored, a Part-10 file, instead.
          if (whole || !/: HTTP (500|501|406|400)\b/.test(e.message) || signal.aborted) throw e;
          try {
            got = await instanceOf(inst, signal, stats);
          } catch (e2) {
            throw new Error(`${e.message}; and the instance itself: ${e2.message}`);
          }
          stats.fallbacks++;
          wholeInstances = true;  // the rest of the series likewise
        }
        syntaxes.add(got.syntax);
        let { entry, pixels } = got;
        if (got.compressed) {
          if (!codecs) codecs = await import('./dicom-codecs.js');
          if (!codecs.isCompressedSyntax(got.syntax)) throw failure(got.url, `transfer syntax ${got.syntax}: the page has no decoder for it`);
          try {
            [entry] = await codecs.decodeEntries([entry]);
          } catch (e) {
            throw failure(got.url, e.message.startsWith(entry.name) ? e.message.slice(entry.name.length + 2) : e.message);
          }
          pixels = decodedPixels(entry.bytes, inst.frames * inst.frameBytes);
        }
        if (signal.aborted) return;
        inst.entry = entry;
        if (done === 0) stats.firstFrameMs = performance.now() - t0;
        done += inst.frames;
        stats.frames = done;
        for (let f = 0; f < inst.frames && pixels; f++) {
          show(inst.row + f, pixels.subarray(f * inst.frameBytes, (f + 1) * inst.frameBytes));
        }
        stats.shown.push(k);
        progress(done, totalFrames);
        status(`${done} of ${totalFrames} frames from ${seriesUrl} (${(stats.bytes / 1048576).toFixed(1)} MB)`);
      };
      // CONNECTIONS requests at a time, in slice order.
      let next = 0;
      const worker = async () => { while (next < instances.length && !signal.aborted) await fetchOne(next++); };
      const workers = Array.from({ length: Math.min(CONNECTIONS, instances.length) }, worker);
      try {
        await Promise.all(workers);
      } catch (e) {
        controller.abort();  // the other requests stop
        throw e;
      }
      stats.framesMs = performance.now() - t0 - stats.metadataMs;
      stats.syntaxes = [...syntaxes];
      status(`opening ${instances.length} images from ${seriesUrl}…`);
      const t1 = performance.now();
      const ok = await openEntries(instances.map((i) => i.entry), (message) => message);
      stats.openMs = performance.now() - t1;
      stats.ms = performance.now() - t0;
      progress(0, 0);
      if (!ok) throw new Error(document.getElementById('error').textContent);
      return stats;
    } catch (e) {
      stats.error = e.message;
      stats.ms = performance.now() - t0;
      if (signal.aborted && busy !== controller) throw new Error('superseded by another series');
      progress(0, 0);
      if (e.name !== 'AbortError') showError(e.message + opts.keeps());
      status(`${seriesUrl} did not open`);
      throw e;
    } finally {
      if (busy === controller) busy = null;
    }
  }

  return {
    list,
    open,
    // For tests and the bench: what the last open did; the table's rows as shown.
    last: () => last,
    shownRows: () => Array.from(panel.querySelectorAll('tbody tr')).map((tr) => ({ series: tr.dataset.series,
      cells: Array.from(tr.children).slice(0, -1).map((td) => td.textContent) })),
    search: (text) => { q('.dw-search').value = text; draw(); },
    root,
  };
}
