// A real PACS for the page's DICOMweb test and bench (as
// tests/support/OrthancServer.h for the native ones): Debian's Orthanc with
// only its DICOMweb plugin, on a free loopback port, a temporary storage
// folder and a generated config; instances stored through its REST API
// (POST /instances). And the page's origin: a server for the site that
// forwards /dicom-web/… to Orthanc (a same-origin proxy, as a hospital's
// web server in front of its archive would), counting what it forwards.
import { spawn, execFileSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import net from 'node:net';
import path from 'node:path';

export const ORTHANC = '/usr/sbin/Orthanc';
export const ORTHANC_DICOMWEB = '/usr/share/orthanc/plugins/libOrthancDicomWeb.so';

// Why Orthanc cannot run here ('' when it can).
export function orthancMissing() {
  if (!fs.existsSync(ORTHANC)) return `${ORTHANC} is not installed (orthanc)`;
  if (!fs.existsSync(ORTHANC_DICOMWEB)) return `${ORTHANC_DICOMWEB} is not installed (orthanc-dicomweb)`;
  return '';
}

function freePort() {
  return new Promise((resolve, reject) => {
    const s = net.createServer();
    s.once('error', reject);
    s.listen(0, '127.0.0.1', () => { const { port } = s.address(); s.close(() => resolve(port)); });
  });
}

export async function startOrthanc(folder) {
  fs.mkdirSync(path.join(folder, 'storage'), { recursive: true });
  const port = await freePort();
  const config = path.join(folder, 'orthanc.json');
  fs.writeFileSync(config, JSON.stringify({
    Name: 'tessera-browser-test', StorageDirectory: path.join(folder, 'storage'),
    IndexDirectory: path.join(folder, 'storage'), HttpPort: port, DicomServerEnabled: false,
    RemoteAccessAllowed: false, HttpCompressionEnabled: false, AuthenticationEnabled: false,
    Plugins: [ORTHANC_DICOMWEB], DicomWeb: { Enable: true, Root: '/dicom-web/' },
  }));
  const log = fs.openSync(path.join(folder, 'orthanc.log'), 'w');
  const child = spawn(ORTHANC, [config], { stdio: ['ignore', log, log] });
  const root = `http://127.0.0.1:${port}`;
  const t = Date.now();
  for (;;) {
    try {
      if ((await fetch(`${root}/system`)).ok) break;
    } catch { /* not yet */ }
    if (child.exitCode !== null || Date.now() - t > 20000) {
      child.kill('SIGKILL');
      throw new Error(`Orthanc did not start on port ${port} (see ${path.join(folder, 'orthanc.log')})`);
    }
    await new Promise((r) => setTimeout(r, 100));
  }
  return {
    root, port, dicomWeb: `${root}/dicom-web`,
    // Stores every file of `dir`; throws naming the file Orthanc refused.
    async upload(dir) {
      for (const f of fs.readdirSync(dir).sort()) {
        const r = await fetch(`${root}/instances`, { method: 'POST', body: fs.readFileSync(path.join(dir, f)) });
        if (!r.ok) throw new Error(`Orthanc refused ${path.join(dir, f)}: HTTP ${r.status}`);
      }
    },
    // The size Orthanc stores for the series (its files, as sent).
    async seriesBytes(seriesUid) {
      const ids = await (await fetch(`${root}/tools/lookup`, { method: 'POST', body: seriesUid })).json();
      const id = ids.find((x) => x.Type === 'Series');
      const s = await (await fetch(`${root}/series/${id.ID}/statistics`)).json();
      return Number(s.DiskSize);
    },
    stop() {
      if (child.exitCode !== null) return Promise.resolve();
      return new Promise((resolve) => {
        const timer = setTimeout(() => child.kill('SIGKILL'), 5000);
        child.once('exit', () => { clearTimeout(timer); resolve(); });
        child.kill('SIGTERM');
      });
    },
  };
}

const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript',
  '.css': 'text/css', '.wasm': 'application/wasm', '.png': 'image/png', '.json': 'application/json' };

// The site, and /dicom-web/… forwarded to `archive` (its DICOMweb root's
// origin). For the bad-input cases, `hooks.answer(path)` may answer in the
// archive's stead ({status, type, body}, or 'hang up': the connection
// closed unanswered) and `hooks.contentType(path, type)` change a forwarded
// answer's Content-Type; `counts` is what was forwarded.
export async function serveWithArchive(site, archive, hooks = {}) {
  const counts = { requests: 0, bytes: 0 };
  const server = http.createServer((req, res) => {
    const p = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    if (p.startsWith('/dicom-web/')) {
      const canned = hooks.answer ? hooks.answer(p) : null;
      if (canned === 'hang up') { req.socket.destroy(); return; }
      if (canned) {
        res.writeHead(canned.status, { 'Content-Type': canned.type });
        res.end(canned.body);
        return;
      }
      const up = http.request(`${archive()}${req.url}`, { method: req.method, headers: { accept: req.headers.accept || '*/*' } }, (ur) => {
        let type = ur.headers['content-type'] || '';
        if (hooks.contentType) type = hooks.contentType(p, type);
        const headers = { 'Cache-Control': 'no-store' };
        if (type) headers['Content-Type'] = type;
        if (ur.headers['content-length']) headers['Content-Length'] = ur.headers['content-length'];
        res.writeHead(ur.statusCode, ur.statusMessage, headers);
        ur.on('data', (d) => { counts.bytes += d.length; });
        ur.pipe(res);
        counts.requests++;
      });
      up.on('error', (e) => {
        res.writeHead(502, 'Bad Gateway', { 'Content-Type': 'text/plain' });
        res.end(`the archive did not answer: ${e.message}`);
      });
      req.pipe(up);
      return;
    }
    const file = path.join(site, path.normalize(p === '/' ? '/index.html' : p));
    fs.stat(file, (err, st) => {
      if (err || !st.isFile()) { res.writeHead(404, { 'Content-Type': 'text/plain' }); res.end('not found'); return; }
      res.writeHead(200, { 'Content-Type': TYPES[path.extname(file)] || 'application/octet-stream',
        'Content-Length': st.size, 'Cache-Control': 'no-store' });
      fs.createReadStream(file).pipe(res);
    });
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return { server, url: `http://127.0.0.1:${server.address().port}`, counts };
}

// tests/browser/dicomweb_series.py: the generated series and their manifest.
export function makeSeries(out, columns, rows, slices, kinds) {
  const script = path.join(path.dirname(new URL(import.meta.url).pathname), 'dicomweb_series.py');
  execFileSync('/usr/bin/python3', [script, out, String(columns), String(rows), String(slices), ...kinds],
    { stdio: ['ignore', 'pipe', 'inherit'] });
  return JSON.parse(fs.readFileSync(path.join(out, 'manifest.json'), 'utf8'));
}
