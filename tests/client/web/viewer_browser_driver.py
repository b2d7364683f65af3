#!/usr/bin/env python3
"""Drives headless Chromium through the live viewer for viewer_browser_test.cc.

Starts Chromium (software WebGL) with the DevTools protocol on, opens URL, and reads the
viewer's #status element every 50 ms until the page says the session's stream has ended (or
--timeout passes). Writes "ready" to --ready_file once the page is watching, then one line per
mesh the page showed ("mesh SEQUENCE KIND VERTICES FACES SERVER_VERTICES SERVER_FACES FRAMES
DRACO_BYTES DELAY_MS", the delay from the server's snapshot to the bytes' arrival)
and a last line "end ENDED WEBGL MESHES ERROR" to stdout. Exits 0 when it got that far, 1 when
Chromium could not be driven, 2 on a timeout.

At the end it takes a screenshot and prints "coverage F": the share of the canvas's pixels
that show the mesh (the surface's blue or its edges; the background is grey), and with
--screenshot=PATH saves the PNG; then it follows the page's save link and prints "download
HREF STATUS BYTES MAGIC" (its first four bytes). With --stop_when_watching it prints "watching SESSION" once
the page follows a session, and stops there.

Usage: viewer_browser_driver.py --url=URL --ready_file=PATH [--timeout=60] [--screenshot=PATH]
                                [--stop_when_watching] [--trust_certificate=PEM]
"""
import argparse
import base64
import hashlib
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request
import zlib

import websocket  # Debian's python3-websocket.


def spki_hash(certificate):
    """The base64 SHA-256 of a PEM certificate's public key, as Chromium names a key it trusts."""
    key = subprocess.run(["openssl", "x509", "-in", certificate, "-pubkey", "-noout"],
                         check=True, capture_output=True).stdout
    der = subprocess.run(["openssl", "pkey", "-pubin", "-outform", "der"], input=key,
                         check=True, capture_output=True).stdout
    return base64.b64encode(hashlib.sha256(der).digest()).decode()


def start_chromium(profile, trusted_certificate=None):
    binary = shutil.which("chromium") or shutil.which("chromium-browser")
    if binary is None:
        sys.exit("chromium is not installed (scripts/install-deps.sh installs it)")
    command = [binary, "--headless", "--no-sandbox", "--no-proxy-server", "--disable-gpu-sandbox",
               "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-first-run",
               "--disable-dev-shm-usage",
               "--remote-debugging-port=0", "--user-data-dir=" + profile, "about:blank"]
    if trusted_certificate:
        # That certificate's key only: any other certificate error still stops the page.
        command.insert(1, "--ignore-certificate-errors-spki-list=" + spki_hash(trusted_certificate))
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                               text=True)
    deadline = time.time() + 30
    for line in process.stderr:
        match = re.search(r"DevTools listening on (ws://\S+)", line)
        if match:
            return process, match.group(1)
        if time.time() > deadline:
            break
    process.kill()
    sys.exit("chromium did not open its DevTools port")


def page_socket(browser_url):
    port = re.search(r"ws://[^:/]+:(\d+)/", browser_url).group(1)
    opener = urllib.request.build_opener(urllib.request.ProxyHandler({}))
    for _ in range(100):
        targets = json.load(opener.open("http://127.0.0.1:%s/json/list" % port, timeout=5))
        pages = [t for t in targets if t.get("type") == "page"]
        if pages:
            return websocket.create_connection(pages[0]["webSocketDebuggerUrl"], timeout=30,
                                               suppress_origin=True)
        time.sleep(0.1)
    sys.exit("chromium has no page target")


def decode_png(data):
    """Width, height and rows of RGB(A) bytes of an 8-bit, non-interlaced PNG."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    position, idat = 8, b""
    while position < len(data):
        length, kind = struct.unpack(">I4s", data[position:position + 8])
        chunk = data[position + 8:position + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", chunk)
            assert depth == 8 and color in (2, 6) and interlace == 0, "unexpected PNG format"
            channels = 3 if color == 2 else 4
        elif kind == b"IDAT":
            idat += chunk
        position += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        row = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            left = row[x - channels] if x >= channels else 0
            up = previous[x]
            up_left = previous[x - channels] if x >= channels else 0
            if kind == 1:
                row[x] = (row[x] + left) & 255
            elif kind == 2:
                row[x] = (row[x] + up) & 255
            elif kind == 3:
                row[x] = (row[x] + (left + up) // 2) & 255
            elif kind == 4:
                p = left + up - up_left
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - up_left)
                predictor = left if pa <= pb and pa <= pc else (up if pb <= pc else up_left)
                row[x] = (row[x] + predictor) & 255
        rows.append(row)
        previous = row
    return width, height, channels, rows


# The page's background (viewer.js: scene.background).
BACKGROUND = (0xf4, 0xf5, 0xf7)


def mesh_coverage(png, rect):
    """Share of the pixels inside rect (left, top, right, bottom) that are not the background:
    the mesh, in its one colour or in its vertices' colours."""
    width, height, channels, rows = decode_png(png)
    left, top = max(0, int(rect[0])), max(0, int(rect[1]))
    right, bottom = min(width, int(rect[2])), min(height, int(rect[3]))
    drawn = total = 0
    for y in range(top, bottom, 2):
        row = rows[y]
        for x in range(left, right, 2):
            pixel = row[x * channels:x * channels + 3]
            total += 1
            drawn += max(abs(p - b) for p, b in zip(pixel, BACKGROUND)) > 16
    return drawn / max(total, 1)


class Page:
    def __init__(self, socket):
        self.socket = socket
        self.next_id = 0

    def call(self, method, **params):
        self.next_id += 1
        self.socket.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            message = json.loads(self.socket.recv())
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise RuntimeError("%s: %s" % (method, message["error"]))
                return message["result"]

    def status(self):
        result = self.call("Runtime.evaluate", returnByValue=True, expression=(
            "(() => { const s = document.getElementById('status');"
            " return s === null ? null : Object.assign({}, s.dataset); })()"))
        return result["result"].get("value")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--url", required=True)
    parser.add_argument("--ready_file", required=True)
    parser.add_argument("--timeout", type=float, default=60)
    parser.add_argument("--screenshot")
    parser.add_argument("--stop_when_watching", action="store_true")
    parser.add_argument("--print_sessions", action="store_true",
                        help="with --stop_when_watching: print the session list's items too, "
                             "as 'listed ID TITLE'")
    parser.add_argument("--trust_certificate",
                        help="a PEM certificate whose key the browser trusts (an https:// URL "
                             "served with a test certificate)")
    args = parser.parse_args()

    profile = tempfile.mkdtemp(prefix="neuralmesh-chromium-")
    process, browser_url = start_chromium(profile, args.trust_certificate)
    try:
        page = Page(page_socket(browser_url))
        page.call("Emulation.setDeviceMetricsOverride", width=1000, height=700,
                  deviceScaleFactor=1, mobile=False)
        page.call("Page.navigate", url=args.url)
        deadline = time.time() + args.timeout
        ready = False
        shown = set()
        while time.time() < deadline:
            status = page.status()
            if status is not None and status.get("session"):
                if not ready:
                    with open(args.ready_file, "w") as ready_file:
                        ready_file.write("ready\n")
                    ready = True
                    if args.stop_when_watching:
                        print("watching %s" % status["session"], flush=True)
                        if args.print_sessions:
                            items = page.call("Runtime.evaluate", returnByValue=True, expression=(
                                "[...document.querySelectorAll('#sessions li')].map((li) =>"
                                " li.dataset.session + ' ' + li.firstChild.textContent)"
                            ))["result"]["value"]
                            for item in items:
                                print("listed %s" % item, flush=True)
                        return 0
                sequence = int(status.get("sequence", "0"))
                if sequence > 0 and sequence not in shown:
                    shown.add(sequence)
                    print("mesh %d %s %s %s %s %s %s %s %s %s" % (
                        sequence, status.get("kind"), status.get("vertices"), status.get("faces"),
                        status.get("serverVertices"), status.get("serverFaces"),
                        status.get("frames", "0"), status.get("bytes"), status.get("delayMs"),
                        status.get("colors")), flush=True)
                if status.get("ended"):
                    print("end %s %s %s %s" % (status["ended"], status.get("webgl"),
                                               status.get("meshes"),
                                               json.dumps(status.get("error", ""))), flush=True)
                    time.sleep(0.3)
                    png = base64.b64decode(
                        page.call("Page.captureScreenshot", format="png")["data"])
                    if args.screenshot:
                        with open(args.screenshot, "wb") as out:
                            out.write(png)
                    rect = page.call("Runtime.evaluate", returnByValue=True, expression=(
                        "(() => { const r = document.getElementById('canvas')"
                        ".getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; })()"
                    ))["result"]["value"]
                    print("coverage %.4f" % mesh_coverage(png, rect), flush=True)
                    # What the page's save link gives: its status, size and first bytes.
                    saved = page.call("Runtime.evaluate", returnByValue=True, awaitPromise=True,
                                      expression=(
                        "(async () => { const a = document.getElementById('download-link');"
                        " if (document.getElementById('download').hidden) return 'hidden';"
                        " const r = await fetch(a.href); const b = new Uint8Array("
                        "await r.arrayBuffer()); return r.status + ' ' + b.length + ' ' +"
                        " String.fromCharCode(...b.slice(0, 4)); })()"))["result"]["value"]
                    print("download %s %s" % (status.get("download"), saved), flush=True)
                    return 0
            time.sleep(0.05)
        print("timeout; last status: %s" % json.dumps(page.status()), flush=True)
        return 2
    finally:
        process.kill()
        process.wait()
        shutil.rmtree(profile, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
