// Folders dropped or picked in the page (a DICOM series is a folder): walks
// dropped directories (DataTransferItem.webkitGetAsEntry) and a
// webkitdirectory picker's files, and reads them as {name, bytes} entries
// for app.js, which hands them to the module's io readers
// (io/DicomBasicReader.h reads the series). Compressed DICOM files are
// decoded first by dicom-codecs.js, loaded only when one is among them.
// Exposed as window.TesseraFolders.
'use strict';

window.TesseraFolders = (function () {
  // Entries must be taken while the drop event is dispatched; the walk
  // itself is asynchronous. Null when nothing dropped is a folder.
  function droppedFolderEntries(dataTransfer) {
    const items = Array.from((dataTransfer && dataTransfer.items) || []);
    const entries = items
      .filter((i) => i.kind === 'file' && typeof i.webkitGetAsEntry === 'function')
      .map((i) => i.webkitGetAsEntry())
      .filter((e) => e);
    return entries.some((e) => e.isDirectory) ? entries : null;
  }

  function readAllEntries(reader) {
    // readEntries returns at most ~100 entries a call: call it until empty.
    return new Promise((resolve, reject) => {
      const all = [];
      const next = () => reader.readEntries((batch) => {
        if (batch.length === 0) { resolve(all); return; }
        all.push(...batch);
        next();
      }, reject);
      next();
    });
  }

  function fileOf(entry) {
    return new Promise((resolve, reject) => entry.file(resolve, reject));
  }

  // [{name: 'folder/sub/file', file: File}] under the dropped entries,
  // sorted by name. Hidden files (.DS_Store) are left out.
  async function walk(entries) {
    const out = [];
    const visit = async (entry, prefix) => {
      if (entry.name.startsWith('.')) return;
      const name = prefix ? `${prefix}/${entry.name}` : entry.name;
      if (entry.isFile) {
        out.push({ name, file: await fileOf(entry) });
      } else if (entry.isDirectory) {
        for (const child of await readAllEntries(entry.createReader())) await visit(child, name);
      }
    };
    for (const e of entries) await visit(e, '');
    return out.sort((a, b) => (a.name < b.name ? -1 : a.name > b.name ? 1 : 0));
  }

  // A webkitdirectory picker's files, named by their path in the folder.
  function pickedFiles(fileList) {
    return Array.from(fileList)
      .filter((f) => !f.name.startsWith('.'))
      .map((f) => ({ name: f.webkitRelativePath || f.name, file: f }))
      .sort((a, b) => (a.name < b.name ? -1 : a.name > b.name ? 1 : 0));
  }

  // Reads every file; onProgress(filesRead, total, bytesRead).
  async function readAll(named, onProgress) {
    const out = [];
    let bytes = 0;
    for (const { name, file } of named) {
      let data;
      try {
        data = new Uint8Array(await file.arrayBuffer());
      } catch (e) {
        throw new Error(`${name}: cannot read it (${e.message})`);
      }
      bytes += data.length;
      out.push({ name, bytes: data });
      onProgress(out.length, named.length, bytes);
    }
    return out;
  }

  // What to hand to the readers. With DICOM files in the folder: those only
  // (a header-like .json or a .raw beside them would otherwise be picked as
  // the volume), an image first (the readers read the first file's series; a
  // DICOMDIR index has the Part-10 marker but no image). Otherwise all.
  function forReading(entries) {
    const part10 = (e) => e.bytes.length > 132 && e.bytes[128] === 0x44 &&
      e.bytes[129] === 0x49 && e.bytes[130] === 0x43 && e.bytes[131] === 0x4d;
    const dicom = entries.filter(part10);
    if (dicom.length === 0) return entries;
    const i = dicom.findIndex((e) => !/(^|\/)DICOMDIR$/i.test(e.name));
    if (i > 0) dicom.unshift(dicom.splice(i, 1)[0]);
    return dicom;
  }

  // The transfer syntax of a Part-10 file's meta group (PS3.10 7.1: explicit
  // VR little endian), '' when it has none.
  function transferSyntax(bytes) {
    const v = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    if (bytes.length < 144 || v.getUint32(128) !== 0x4449434d) return '';
    for (let at = 132; at + 8 <= bytes.length && v.getUint16(at, true) === 0x0002;) {
      const vr = String.fromCharCode(bytes[at + 4], bytes[at + 5]);
      const long = ['OB', 'OW', 'UN', 'UT', 'SQ', 'UC', 'UR'].includes(vr);
      const length = long ? v.getUint32(at + 8, true) : v.getUint16(at + 6, true);
      const value = at + (long ? 12 : 8);
      if (v.getUint16(at + 2, true) === 0x0010) {
        return String.fromCharCode(...bytes.subarray(value, Math.min(value + length, bytes.length))).replace(/[\0 ]+$/, '');
      }
      at = value + length;
    }
    return '';
  }
  const COMPRESSED = /^1\.2\.840\.10008\.1\.2\.4\.(50|51|57|70|80|81|90|91|201|202|203)$/;

  // Entries with their compressed DICOM files decoded (dicom-codecs.js and
  // the decoders it needs are loaded only then); onProgress(done, total).
  async function decodeCompressed(entries, onProgress = () => {}) {
    if (!entries.some((e) => COMPRESSED.test(transferSyntax(e.bytes)))) return entries;
    const codecs = await import('./dicom-codecs.js');
    return codecs.decodeEntries(entries, onProgress);
  }

  return { droppedFolderEntries, walk, pickedFiles, readAll, forReading, decodeCompressed };
})();
