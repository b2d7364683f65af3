#!/usr/bin/env python3
"""Reads glTF files with three.js's GLTFLoader (and its DRACOLoader) in headless Chromium, for
gltf_three_test.cc: an independent reader of what neuralmesh writes.

Serves FILES, three.js (--three, the folder of its npm package) and a page that loads them on
127.0.0.1, then asks the page to load each file and draw it. Prints one JSON array with an
object per file: {"meshes": [{"kind": "mesh"|"points", "positions": [x, y, z, ...] (in world
space), "index": [...] or null, "colors": [r, g, b, ...] (linear, as three.js holds them) or
null, "vertexColors", "metalness", "roughness", "doubleSided"}], "drawn": the share of a
200 x 200 picture of it that is not the background} or {"error": "..."}. Exits 0 when it got
that far, 1 when Chromium could not be driven.

Usage: gltf_three_reader.py --three=DIR [--timeout=60] FILE...
"""
import argparse
import http.server
import json
import os
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from viewer_browser_driver import Page, page_socket, start_chromium  # noqa: E402

PAGE = """<!doctype html><html><body>
<script type="importmap">
{"imports": {"three": "/three/build/three.module.js", "three/addons/": "/three/examples/jsm/"}}
</script>
<script type="module">
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { DRACOLoader } from 'three/addons/loaders/DRACOLoader.js';

const draco = new DRACOLoader();
draco.setDecoderPath('/three/examples/jsm/libs/draco/gltf/');
const loader = new GLTFLoader();
loader.setDRACOLoader(draco);
const renderer = new THREE.WebGLRenderer({ preserveDrawingBuffer: true });
renderer.setSize(200, 200);
renderer.setPixelRatio(1);

function describe(object) {
  const geometry = object.geometry;
  const position = geometry.attributes.position;
  const color = geometry.attributes.color;
  const world = new THREE.Vector3();
  const positions = [];
  for (let i = 0; i < position.count; ++i) {
    world.fromBufferAttribute(position, i).applyMatrix4(object.matrixWorld);
    positions.push(world.x, world.y, world.z);
  }
  let colors = null;
  if (color) {
    colors = [];
    for (let i = 0; i < color.count; ++i) colors.push(color.getX(i), color.getY(i), color.getZ(i));
  }
  return {
    kind: object.isMesh ? 'mesh' : 'points',
    positions,
    index: geometry.index ? Array.from(geometry.index.array) : null,
    colors,
    vertexColors: object.material.vertexColors,
    metalness: object.material.metalness,
    roughness: object.material.roughness,
    doubleSided: object.material.side === THREE.DoubleSide,
  };
}

// The share of the pixels of a picture of `scene` that are not the white background.
function drawnShare(scene) {
  const box = new THREE.Box3().setFromObject(scene);
  const centre = box.getCenter(new THREE.Vector3());
  const size = box.getSize(new THREE.Vector3()).length();
  const camera = new THREE.PerspectiveCamera(40, 1, size / 100, size * 10);
  camera.position.copy(centre).add(new THREE.Vector3(0, 0, size * 1.2));
  camera.lookAt(centre);
  const lit = new THREE.Scene();
  lit.background = new THREE.Color(0xffffff);
  lit.add(new THREE.HemisphereLight(0xffffff, 0x444444, 3));
  lit.add(scene);
  renderer.render(lit, camera);
  const gl = renderer.getContext();
  const pixels = new Uint8Array(200 * 200 * 4);
  gl.readPixels(0, 0, 200, 200, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
  let drawn = 0;
  for (let i = 0; i < pixels.length; i += 4) {
    if (pixels[i] < 240 || pixels[i + 1] < 240 || pixels[i + 2] < 240) ++drawn;
  }
  return drawn / (200 * 200);
}

window.readGltf = async (urls) => {
  const results = [];
  for (const url of urls) {
    try {
      const gltf = await loader.loadAsync(url);
      gltf.scene.updateMatrixWorld(true);
      const meshes = [];
      gltf.scene.traverse((object) => {
        if (object.isMesh || object.isPoints) meshes.push(describe(object));
      });
      results.push({ meshes, drawn: drawnShare(gltf.scene) });
    } catch (error) {
      results.push({ error: String(error && error.message ? error.message : error) });
    }
  }
  return JSON.stringify(results);
};
window.pageReady = true;
</script></body></html>
"""


def serve(three, files):
    """Starts an HTTP server on 127.0.0.1 for the page, three.js and the files; returns it."""
    by_name = {"/files/%d" % i + os.path.splitext(f)[1]: f for i, f in enumerate(files)}

    class Handler(http.server.BaseHTTPRequestHandler):
        def log_message(self, *args):
            pass

        def do_GET(self):
            path = self.path.split("?")[0]
            if path == "/":
                body, kind = PAGE.encode(), "text/html"
            elif path in by_name:
                with open(by_name[path], "rb") as f:
                    body, kind = f.read(), "application/octet-stream"
            elif path.startswith("/three/") and ".." not in path:
                name = os.path.join(three, path[len("/three/"):])
                if not os.path.isfile(name):
                    self.send_error(404)
                    return
                with open(name, "rb") as f:
                    body = f.read()
                kind = {".js": "text/javascript", ".wasm": "application/wasm"}.get(
                    os.path.splitext(name)[1], "application/octet-stream")
            else:
                self.send_error(404)
                return
            self.send_response(200)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, sorted(by_name, key=lambda name: int(name.split("/")[2].split(".")[0]))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--three", required=True)
    parser.add_argument("--timeout", type=float, default=60)
    parser.add_argument("files", nargs="+")
    args = parser.parse_args()

    server, urls = serve(os.path.abspath(args.three), args.files)
    profile = tempfile.mkdtemp(prefix="neuralmesh-chromium-")
    process, browser_url = start_chromium(profile)
    try:
        page = Page(page_socket(browser_url))
        page.call("Page.navigate", url="http://127.0.0.1:%d/" % server.server_address[1])
        deadline = time.time() + args.timeout
        while time.time() < deadline:
            ready = page.call("Runtime.evaluate", returnByValue=True,
                              expression="window.pageReady === true")
            if ready["result"].get("value"):
                break
            time.sleep(0.05)
        else:
            print("the page did not load three.js", file=sys.stderr)
            return 1
        result = page.call("Runtime.evaluate", returnByValue=True, awaitPromise=True,
                           expression="window.readGltf(%s)" % json.dumps(urls))
        if "exceptionDetails" in result:
            print("the page failed: %s" % result["exceptionDetails"], file=sys.stderr)
            return 1
        print(result["result"]["value"])
        return 0
    finally:
        process.kill()
        process.wait()
        server.shutdown()


if __name__ == "__main__":
    sys.exit(main())
