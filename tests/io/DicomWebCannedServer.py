#!/usr/bin/python3
"""A DICOMweb server with canned answers, for the bad-input cases of
tests/io/DicomWebBadInputTest.cpp that a real archive never gives (bodies
with wrong boundaries, answers that are not JSON, 403 and 500).

usage: DicomWebCannedServer.py SPEC.json
SPEC: {"routes": {"/path": [status, "content type", "body as hex"]},
       "die_after": N}   (optional: exit after answering N requests)
A path is matched without its query string. Unknown paths answer 404.
Prints the port it listens on (127.0.0.1), then serves until killed.
"""
import http.server
import json
import os
import socketserver
import sys
import threading

spec = json.load(open(sys.argv[1]))
routes = spec["routes"]
die_after = spec.get("die_after")
served = [0]
lock = threading.Lock()


class Handler(http.server.BaseHTTPRequestHandler):
    protocol_version = "HTTP/1.1"

    def log_message(self, *args):
        pass

    def do_GET(self):
        with lock:
            served[0] += 1
            n = served[0]
        if die_after is not None and n > die_after:
            os._exit(0)  # the archive stops: connections are refused from now on
        status, ctype, body = routes.get(self.path.split("?")[0], [404, "text/plain", ""])
        data = bytes.fromhex(body)
        self.send_response(status)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)


class Server(socketserver.ThreadingMixIn, http.server.HTTPServer):
    daemon_threads = True


server = Server(("127.0.0.1", 0), Handler)
print(server.server_address[1], flush=True)
server.serve_forever()
