#!/usr/bin/env python3
"""Serves DIR over HTTP on 127.0.0.1 for the viewer test, and stores what the
page POSTs (screenshots, PLYs, status lines) under POSTED/<path>; status
lines (POST /log) are appended to POSTED/log after the time they came. Prints the
port it listens on. Usage: serve.py DIR POSTED"""
import http.server
import os
import sys
import time

root, posted = sys.argv[1], sys.argv[2]


class Handler(http.server.SimpleHTTPRequestHandler):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, directory=root, **kwargs)

    def do_POST(self):
        body = self.rfile.read(int(self.headers.get("Content-Length", 0)))
        name = os.path.join(posted, self.path.strip("/").replace("/", "_"))
        if self.path == "/log":
            with open(name, "ab") as f:
                f.write(b"%.3f " % time.time() + body + b"\n")
        else:
            with open(name + ".part", "wb") as f:
                f.write(body)
            os.replace(name + ".part", name)
        self.send_response(204)
        self.end_headers()

    def log_message(self, *args):
        pass


server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
print(server.server_address[1], flush=True)
server.serve_forever()
