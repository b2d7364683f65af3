// The live viewer of `neuralmesh view` (client/web/viewer_service.h has the HTTP API it reads).
// Lists the server's sessions; for the chosen one, long-polls /api/sessions/ID/mesh?after=N,
// decodes each Draco mesh with three.js's Draco decoder and draws it, until the session's
// stream ends. #status carries the figures of the mesh on screen as data-* attributes, which
// the browser test reads.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { DRACOLoader } from 'three/addons/loaders/DRACOLoader.js';

const statusElement = document.getElementById('status');
const sessionList = document.getElementById('sessions');
const sessionsError = document.getElementById('sessions-error');
const canvas = document.getElementById('canvas');
const wireframeBox = document.getElementById('wireframe');
const flatBox = document.getElementById('flat');
const download = document.getElementById('download');
const downloadLink = document.getElementById('download-link');
const downloadFormat = document.getElementById('download-format');

const draco = new DRACOLoader();
draco.setDecoderPath('/vendor/three/examples/jsm/libs/draco/');
draco.setDecoderConfig({ type: 'wasm' });

// ---- Drawing -------------------------------------------------------------------------------

const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f5f7);
scene.add(new THREE.HemisphereLight(0xffffff, 0x556070, 2.0));
const light = new THREE.DirectionalLight(0xffffff, 1.5);
scene.add(light);
const camera = new THREE.PerspectiveCamera(40, 1, 0.001, 1000);
const material = new THREE.MeshStandardMaterial({
  color: 0x9fb8d8, roughness: 0.7, metalness: 0.0, side: THREE.DoubleSide,
  polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
});
const edgeMaterial = new THREE.LineBasicMaterial({ color: 0x33415c, transparent: true,
                                                   opacity: 0.35 });
let renderer = null;
let controls = null;
let surface = null;  // The mesh on screen.
let edges = null;    // Its edges.
let framed = false;  // The camera has been placed for the current session.

try {
  renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  controls = new OrbitControls(camera, canvas);
  controls.addEventListener('change', render);
  statusElement.dataset.webgl = 'true';
} catch (error) {
  statusElement.dataset.webgl = 'false';
  showStatus(`WebGL is not available (${error.message}); the figures still update.`);
}

function render() {
  if (renderer === null) return;
  const width = canvas.clientWidth;
  const height = canvas.clientHeight;
  if (canvas.width !== Math.floor(width * renderer.getPixelRatio()) ||
      canvas.height !== Math.floor(height * renderer.getPixelRatio())) {
    renderer.setSize(width, height, false);
    camera.aspect = width / Math.max(height, 1);
    camera.updateProjectionMatrix();
  }
  light.position.copy(camera.position);
  renderer.render(scene, camera);
  statusElement.dataset.frames = String(Number(statusElement.dataset.frames || 0) + 1);
}
window.addEventListener('resize', render);

function updateEdges() {
  if (edges !== null) {
    scene.remove(edges);
    edges.geometry.dispose();
    edges = null;
  }
  if (surface !== null && wireframeBox.checked) {
    edges = new THREE.LineSegments(new THREE.WireframeGeometry(surface.geometry), edgeMaterial);
    scene.add(edges);
  }
}
wireframeBox.addEventListener('change', () => { updateEdges(); render(); });
flatBox.addEventListener('change', () => {
  material.flatShading = flatBox.checked;
  material.needsUpdate = true;
  render();
});

function frameCamera(geometry) {
  geometry.computeBoundingSphere();
  const { center, radius } = geometry.boundingSphere;
  const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 1.25;
  camera.position.copy(center).add(new THREE.Vector3(0.6, 0.45, 1).normalize()
                                        .multiplyScalar(distance));
  camera.near = distance / 100;
  camera.far = distance * 10;
  camera.updateProjectionMatrix();
  if (controls !== null) {
    controls.target.copy(center);
    controls.update();
  }
}

// Meshes of sessions whose points carry colours have a colour per vertex (a Draco COLOR
// attribute); the others are drawn in one colour.
function useVertexColors(colored) {
  statusElement.dataset.colors = String(colored);
  if (material.vertexColors === colored) return;
  material.vertexColors = colored;
  material.color.set(colored ? 0xffffff : 0x9fb8d8);
  material.needsUpdate = true;
}

function showGeometry(geometry) {
  geometry.computeVertexNormals();
  useVertexColors(geometry.getAttribute('color') !== undefined);
  if (surface === null) {
    surface = new THREE.Mesh(geometry, material);
    scene.add(surface);
  } else {
    surface.geometry.dispose();
    surface.geometry = geometry;
  }
  if (!framed) {
    frameCamera(geometry);
    framed = true;
  }
  updateEdges();
  render();
}

function decodeDraco(buffer) {
  return new Promise((resolve, reject) => draco.parse(buffer, resolve, reject));
}

// ---- Status --------------------------------------------------------------------------------

function showStatus(text) {
  statusElement.textContent = text;
}

function describe(figures) {
  return `session ${figures.session}: ${figures.kind} mesh #${figures.sequence}\n` +
         `${figures.vertices} vertices, ${figures.faces} faces, genus ${figures.genus}, ` +
         `${figures.boundaries} boundaries\n` +
         `${figures.points} points received, ${figures.steps} basic steps, ${figures.state}\n` +
         `${(figures.bytes / 1024).toFixed(1)} KB of Draco, here ${figures.delayMs} ms after ` +
         'the server took it';
}

// ---- Following a session -------------------------------------------------------------------

let following = null;  // The id of the session being followed.
let generation = 0;    // Bumped by each follow(); an older loop sees it changed and stops.

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

async function errorText(response) {
  try {
    return (await response.json()).error;
  } catch {
    return `HTTP ${response.status}`;
  }
}

async function follow(sessionId) {
  following = sessionId;
  updateDownload();
  const mine = ++generation;
  const current = () => generation === mine;
  framed = false;
  Object.assign(statusElement.dataset, {
    session: sessionId, sequence: '0', meshes: '0', ended: '', error: '',
  });
  showStatus(`session ${sessionId}: waiting for its first mesh...`);
  let sequence = 0;
  while (current()) {
    let response;
    try {
      response = await fetch(`/api/sessions/${encodeURIComponent(sessionId)}/mesh?after=${sequence}`);
    } catch (error) {
      showStatus(`session ${sessionId}: the viewer is unreachable (${error.message}); retrying`);
      await sleep(2000);
      continue;
    }
    if (!current()) return;
    if (response.status === 204) continue;  // No newer mesh yet: ask again.
    if (response.status === 200) {
      const buffer = await response.arrayBuffer();
      const arrived = Date.now();
      const bytes = buffer.byteLength;  // The decoder takes the buffer over (it is detached).
      const header = (name) => response.headers.get(`X-Neuralmesh-${name}`);
      let geometry;
      try {
        geometry = await decodeDraco(buffer);
      } catch (error) {
        statusElement.dataset.error = `decoding failed: ${error.message || error}`;
        showStatus(`session ${sessionId}: mesh #${header('Sequence')} could not be decoded`);
        return;
      }
      if (!current()) return;
      sequence = Number(header('Sequence'));
      const figures = {
        session: sessionId, sequence, kind: header('Kind'),
        vertices: geometry.attributes.position.count,
        faces: geometry.index === null ? 0 : geometry.index.count / 3,
        genus: header('Genus'), boundaries: header('Boundaries'), state: header('State'),
        points: header('Points-Received'), steps: header('Basic-Steps'),
        // From the server's snapshot to the bytes here (clocks of one machine, or in sync).
        delayMs: Math.max(0, Math.round(arrived - Number(header('Snapshot-Time-Us')) / 1000)),
        bytes,
      };
      showGeometry(geometry);
      Object.assign(statusElement.dataset, {
        sequence: String(sequence), kind: figures.kind, vertices: String(figures.vertices),
        faces: String(figures.faces), serverVertices: header('Vertices'),
        serverFaces: header('Faces'), delayMs: String(figures.delayMs),
        bytes: String(figures.bytes),
        meshes: String(Number(statusElement.dataset.meshes) + 1),
      });
      showStatus(describe(figures));
      continue;
    }
    const message = await errorText(response);
    if (response.status === 410 || response.status === 404 || response.status === 400) {
      statusElement.dataset.ended = response.status === 410 ? 'gone' : 'error';
      if (response.status !== 410) statusElement.dataset.error = message;
      showStatus(`${statusElement.textContent}\n${message}`);
      return;
    }
    showStatus(`session ${sessionId}: ${message}; retrying`);
    await sleep(2000);
  }
}

// The link that saves the followed session's latest mesh (/api/sessions/ID/download) in the
// chosen format; #status's data-download carries it for the browser test.
function updateDownload() {
  download.hidden = following === null;
  if (following === null) return;
  downloadLink.href = `/api/sessions/${encodeURIComponent(following)}/download?format=` +
                      downloadFormat.value;
  statusElement.dataset.download = downloadLink.getAttribute('href');
}
downloadFormat.addEventListener('change', updateDownload);

function choose(sessionId) {
  const url = new URL(window.location.href);
  url.searchParams.set('session', sessionId);
  window.history.pushState({}, '', url);
  follow(sessionId);
  markCurrent();
}

// ---- Session list --------------------------------------------------------------------------

function markCurrent() {
  for (const item of sessionList.children) {
    item.classList.toggle('current', item.dataset.session === following);
  }
}

let autoPicked = false;  // The first list has been looked at for a session to follow.

async function refreshSessions() {
  let sessions;
  try {
    const response = await fetch('/api/sessions');
    if (!response.ok) throw new Error(await errorText(response));
    sessions = await response.json();
    sessionsError.hidden = true;
  } catch (error) {
    sessionsError.textContent = `Cannot list the sessions: ${error.message}`;
    sessionsError.hidden = false;
    return;
  }
  if (!autoPicked) {
    // Opened without ?session=: follow the newest session that is still learning, if any.
    autoPicked = true;
    const live = sessions.filter((s) => ['collecting', 'learning', 'finishing'].includes(s.state));
    if (following === null && live.length > 0) choose(live[live.length - 1].session_id);
  }
  sessionList.replaceChildren(...sessions.map((s) => {
    const item = document.createElement('li');
    item.dataset.session = s.session_id;
    const title = document.createElement('div');
    const state = s.stalled ? `${s.state}, stalled: waiting for points` : s.state;
    title.textContent = `${s.name || s.session_id} (${state})`;
    const figures = document.createElement('div');
    figures.className = 'figures';
    figures.textContent = `${s.points_received} points, ${s.vertices}/${s.target_vertices} ` +
                          `vertices, ${s.latest_sequence} meshes`;
    item.append(title, figures);
    item.addEventListener('click', () => choose(s.session_id));
    return item;
  }));
  markCurrent();
}

window.addEventListener('popstate', () => {
  const sessionId = new URLSearchParams(window.location.search).get('session');
  if (sessionId !== null && sessionId !== following) follow(sessionId);
  markCurrent();
});

// ---- Start ---------------------------------------------------------------------------------

const requested = new URLSearchParams(window.location.search).get('session');
if (requested !== null) {
  autoPicked = true;
  follow(requested);
}
refreshSessions();
// The list refreshes every 3 s while the page is visible.
setInterval(() => { if (!document.hidden) refreshSessions(); }, 3000);
