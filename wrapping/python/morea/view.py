# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The front navigator: a local web page to look through a run's front.

    python -m morea.view RUN_DIR [--port 8000] [--open]
    morea view RUN_DIR

serves, on this machine only (127.0.0.1 by default), a page that shows the
front of the run in RUN_DIR (a folder written by `morea register`, by the
C++ filter's users through itk::morea::WriteRegistrationOutputs, or by
Python's `result.save`) as a scatter plot and parallel coordinates. Selecting
a solution shows its slices (axial, coronal, sagittal; contours, checkerboard,
difference, Jacobian determinant, deformed grid) and its scores; "export"
writes its transforms and fields into RUN_DIR/solution_<id>/. Solutions are
rasterised on demand from the run's saved front. The page needs no internet:
its script and style ship with this package.
"""
import argparse
import json
import os
import sys
import threading
import webbrowser
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import parse_qs, urlparse

ASSETS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "view_assets")
CONTENT_TYPES = {".html": "text/html; charset=utf-8", ".js": "text/javascript; charset=utf-8",
                 ".css": "text/css; charset=utf-8"}
OBJECTIVES = ("magnitude", "intensity", "guidance")


class RunNotViewable(Exception):
    """The folder is not a complete run that can be looked at (the message says why)."""


def open_run(folder):
    """The run in `folder` read back (morea._morea.SavedRun); raises
    RunNotViewable saying why when it is not a complete run."""
    from . import _morea

    try:
        return _morea.SavedRun(os.fspath(folder))
    except ValueError as error:
        raise RunNotViewable(str(error)) from None


class Navigator:
    """The page's data: the run and the answers to the page's requests."""

    def __init__(self, run):
        self.run = run
        self.layout = run.layout()
        self.front = [{"index": i, "id": int(r[0]), "magnitude": r[1], "intensity": r[2], "guidance": r[3],
                       "constraint": r[4], "chosen": r[5]} for i, r in enumerate(run.front())]
        self._export_lock = threading.Lock()

    def describe(self):
        summary = json.loads(self.run.summary())
        return {"folder": os.path.abspath(self.run.folder), "objectives": list(OBJECTIVES), "front": self.front,
                "layout": self.layout,
                "run": {k: summary.get(k) for k in ("problem_id", "seed", "backend", "generations", "front_size")},
                "rigid_baseline": summary.get("rigid_baseline")}

    def solution_index(self, query):
        try:
            index = int(query.get("solution", ["-1"])[0])
        except ValueError:
            raise ValueError("solution must be an index into the front") from None
        if index < -1 or index >= len(self.front):
            raise ValueError(f"solution {index} is not in the front of {len(self.front)}")
        return index

    def slice_png(self, query):
        get = lambda key, default: query.get(key, [default])[0]  # noqa: E731
        axis = get("axis", "axial")
        slice_index = get("slice", "")
        slice_index = int(slice_index) if slice_index not in ("", "focus") else self.layout["focus_slices"][axis]
        return self.run.slice_png(self.solution_index(query), axis, slice_index, get("view", "overlay"),
                                  get("contours", "1") not in ("0", "false"), int(get("width", "512")))

    def scores(self, query):
        index = self.solution_index(query)
        if index < 0:
            raise ValueError("scores need a solution of the front")
        entry = dict(self.front[index])
        entry["scores"] = json.loads(self.run.scores(index))
        return entry

    def export(self, query):
        index = self.solution_index(query)
        if index < 0:
            raise ValueError("export needs a solution of the front")
        with self._export_lock:
            folder = self.run.export(index)
        return {"folder": folder, "files": sorted(os.listdir(folder))}


def make_handler(navigator, quiet=True):
    class Handler(BaseHTTPRequestHandler):
        server_version = "morea-view"

        def log_message(self, format, *args):  # noqa: A002
            if not quiet:
                super().log_message(format, *args)

        def _send(self, status, body, content_type):
            self.send_response(status)
            self.send_header("Content-Type", content_type)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)

        def _json(self, value, status=200):
            self._send(status, json.dumps(value).encode(), "application/json")

        def _answer(self, method):
            url = urlparse(self.path)
            query = parse_qs(url.query)
            try:
                if method == "GET" and url.path in ("/", "/index.html"):
                    return self._asset("index.html")
                if method == "GET" and url.path.startswith("/static/"):
                    return self._asset(url.path[len("/static/"):])
                if method == "GET" and url.path == "/api/run":
                    return self._json(navigator.describe())
                if method == "GET" and url.path == "/api/slice":
                    return self._send(200, navigator.slice_png(query), "image/png")
                if method == "GET" and url.path == "/api/scores":
                    return self._json(navigator.scores(query))
                if method == "POST" and url.path == "/api/export":
                    return self._json(navigator.export(query))
                return self._json({"error": f"no such page: {url.path}"}, 404)
            except (ValueError, RuntimeError) as error:
                return self._json({"error": str(error)}, 400)

        def _asset(self, name):
            if "/" in name or name.startswith(".") or os.path.splitext(name)[1] not in CONTENT_TYPES:
                return self._json({"error": f"no such file: {name}"}, 404)
            path = os.path.join(ASSETS, name)
            if not os.path.isfile(path):
                return self._json({"error": f"no such file: {name}"}, 404)
            with open(path, "rb") as f:
                self._send(200, f.read(), CONTENT_TYPES[os.path.splitext(name)[1]])

        def do_GET(self):  # noqa: N802
            self._answer("GET")

        def do_POST(self):  # noqa: N802
            length = int(self.headers.get("Content-Length") or 0)
            if length:
                self.rfile.read(length)
            self._answer("POST")

    return Handler


def serve(folder, host="127.0.0.1", port=0, quiet=True):
    """A ThreadingHTTPServer for the page of the run in `folder` (not yet
    serving: call serve_forever). Raises RunNotViewable."""
    navigator = Navigator(open_run(folder))
    server = ThreadingHTTPServer((host, port), make_handler(navigator, quiet))
    server.daemon_threads = True
    server.navigator = navigator
    return server


def main(argv=None):
    parser = argparse.ArgumentParser(prog="morea view", description="Look through a run's front in a web browser.")
    parser.add_argument("run", metavar="RUN_DIR", help="the output folder of a run")
    parser.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1: this machine)")
    parser.add_argument("--port", type=int, default=8000, help="port (0: any free one; default 8000)")
    parser.add_argument("--open", action="store_true", help="open the page in the default web browser")
    parser.add_argument("--verbose", action="store_true", help="log every request")
    args = parser.parse_args(argv)
    try:
        server = serve(args.run, args.host, args.port, quiet=not args.verbose)
    except RunNotViewable as error:
        print(f"morea view: error: {error}", file=sys.stderr)
        return 2
    except OSError as error:
        print(f"morea view: error: cannot listen on {args.host}:{args.port}: {error}", file=sys.stderr)
        return 2
    host, port = server.server_address[:2]
    url = f"http://{host}:{port}/"
    navigator = server.navigator
    print(f"morea view: the front of {len(navigator.front)} solutions in {os.path.abspath(args.run)}", flush=True)
    print(f"morea view: serving {url} (Ctrl-C to stop)", flush=True)
    if args.open:
        webbrowser.open(url)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
