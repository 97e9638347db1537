#!/usr/bin/python3
"""A fault-injecting HTTP proxy for tests/io/ZarrHttpTest.cpp, in front of
the nginx the test started. Metadata (.zarray, .zattrs, .zgroup) passes
through; chunk requests are damaged by their path:

  flaky  (every chunk eventually right): by a hash of the path, two chunks
         in ten answer 500 the first time, two send half their body under
         the full Content-Length and close, two send their bytes with every
         byte flipped under the right length (only decoding can tell), one
         waits DELAY seconds before the first answer; the second request of
         each path is served intact.
  broken (one chunk keeps failing): the chunk whose path ends with BROKEN
         answers 500 every time; the others pass through.
  hang   the same, but that chunk's request is read and never answered.
  stall  the same, but that chunk sends its headers (the full
         Content-Length) and half its body, then nothing more.

usage: fault_proxy.py UPSTREAM_PORT MODE [DELAY] [BROKEN]
Prints the port it listens on (127.0.0.1), then serves until killed.
"""
import hashlib
import http.server
import sys
import threading
import time
import urllib.error
import urllib.request

UPSTREAM = int(sys.argv[1])
MODE = sys.argv[2]
DELAY = float(sys.argv[3]) if len(sys.argv) > 3 else 3.0
BROKEN = sys.argv[4] if len(sys.argv) > 4 else ""
seen = {}
lock = threading.Lock()


class Handler(http.server.BaseHTTPRequestHandler):
    protocol_version = "HTTP/1.1"

    def log_message(self, *args):
        pass

    def do_GET(self):
        with lock:
            count = seen.get(self.path, 0)
            seen[self.path] = count + 1
        try:
            with urllib.request.urlopen("http://127.0.0.1:%d%s" % (UPSTREAM, self.path)) as r:
                status, body = r.status, r.read()
        except urllib.error.HTTPError as e:
            status, body = e.code, e.read()
        name = self.path.rsplit("/", 1)[-1]
        chunk = status == 200 and not name.startswith(".")
        fault = None
        if chunk and MODE == "flaky" and count == 0:
            fault = ["500", "500", "truncate", "truncate", "garble", "garble", "delay", None,
                     None, None][hashlib.md5(self.path.encode()).digest()[0] % 10]
        if chunk and MODE in ("broken", "hang", "stall") and self.path.endswith(BROKEN):
            fault = {"broken": "500", "hang": "hang", "stall": "stall"}[MODE]
        if fault == "hang":
            time.sleep(3600)  # the client's stall timeout ends it
            return
        if fault == "500":
            self.send_response(500)
            self.send_header("Content-Length", "0")
            self.end_headers()
            return
        if fault == "delay":
            time.sleep(DELAY)
        try:
            self.answer(status, body, fault)
        except (BrokenPipeError, ConnectionResetError):
            pass  # the client gave up waiting (a stall it timed out)

    def answer(self, status, body, fault):
        self.send_response(status)
        self.send_header("Content-Length", str(len(body)))
        if fault == "truncate":
            self.send_header("Connection", "close")
        self.end_headers()
        if fault == "truncate":
            self.wfile.write(body[: len(body) // 2])
            self.wfile.flush()
            self.close_connection = True
            return
        if fault == "stall":
            self.wfile.write(body[: len(body) // 2])
            self.wfile.flush()
            time.sleep(3600)
            return
        if fault == "garble":
            body = bytes(b ^ 0xFF for b in body)
        self.wfile.write(body)


server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
server.daemon_threads = True
print(server.server_address[1], flush=True)
server.serve_forever()
