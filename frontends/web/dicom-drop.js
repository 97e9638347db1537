// Folders dropped or picked in the page (a DICOM series is a folder): walks
// dropped directories (DataTransferItem.webkitGetAsEntry) and a
// webkitdirectory picker's files, and reads them as {name, bytes} entries
// for app.js, which hands them to the module's io readers
// (io/DicomBasicReader.h reads the series). Exposed as window.TesseraFolders.
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

  return { droppedFolderEntries, walk, pickedFiles, readAll, forReading };
})();
