// quadlod report viewer (issue 22). Embedded into the CLI (cmake/report_assets.cmake) and inlined
// into every report page as a module script. It reads the mesh data block (#quadlod-data), imports
// three.js from the page's own text (#three-src) through a blob URL — no network — and draws one
// view per mesh into one canvas with one shared camera, so every view shows the same angle.
//
// For the headless test (tests/report/check_report_page.py) the page reports on itself in
// <body data-render-status="ok|error" data-errors="[…]" data-foreground="…">: console errors and
// uncaught exceptions are recorded, and after the first frame each view's pixels are read back
// and counted against the background colour.

const errors = [];
function recordError(message) {
  errors.push(String(message));
  document.body.dataset.errors = JSON.stringify(errors);
  document.body.dataset.renderStatus = 'error';
}
window.addEventListener('error', (e) => recordError(e.message || e));
window.addEventListener('unhandledrejection', (e) => recordError(e.reason && e.reason.stack || e.reason));
const consoleError = console.error.bind(console);
console.error = (...args) => { recordError(args.join(' ')); consoleError(...args); };
document.body.dataset.errors = '[]';

const threeUrl = URL.createObjectURL(new Blob([document.getElementById('three-src').textContent],
                                              { type: 'text/javascript' }));
const THREE = await import(threeUrl);
const data = JSON.parse(document.getElementById('quadlod-data').textContent);

function decode(text, Type) {
  const bytes = Uint8Array.from(atob(text), (c) => c.charCodeAt(0));
  return new Type(bytes.buffer, 0, bytes.byteLength / Type.BYTES_PER_ELEMENT);
}

const BACKGROUND_HEX = 0xf4f4f2;  // sRGB, as the page's pixels read back
const BACKGROUND = new THREE.Color(BACKGROUND_HEX);
const KIND_COLOURS = [new THREE.Color(0xe8743b), new THREE.Color(0x7fa7d6), new THREE.Color(0x9b6fc0)];
const KIND_NAMES = ['triangle', 'quad', 'n-gon'];

// Heat map: a perceptually ordered ramp (dark blue → teal → yellow → red), 0 … heat_max.
const RAMP = [[0.0, 0x2c3e8c], [0.33, 0x1fa187], [0.66, 0xf2c53d], [1.0, 0xd7301f]].map(
  ([t, c]) => [t, new THREE.Color(c)]);
function heatColour(value, out) {
  const t = Math.min(1, Math.max(0, value / data.heat_max));
  for (let i = 1; i < RAMP.length; ++i) {
    if (t <= RAMP[i][0]) {
      const [t0, c0] = RAMP[i - 1];
      const [t1, c1] = RAMP[i];
      return out.copy(c0).lerp(c1, (t - t0) / (t1 - t0));
    }
  }
  return out.copy(RAMP[RAMP.length - 1][1]);
}

function chordColour(index, out) {
  // Golden-angle hues: neighbouring chord numbers get distinct colours.
  return out.setHSL((index * 0.618033988749895) % 1, 0.85, 0.42);
}

/// One view: the flat-shaded mesh (face-kind colours or heat), its wireframe and its chords.
function buildView(column) {
  const positions = decode(column.positions, Float32Array);
  const tris = decode(column.triangle_vertices, Uint32Array);
  const kinds = decode(column.triangle_kind, Uint8Array);
  const heat = column.heat ? decode(column.heat, Float32Array) : null;
  // Non-indexed triangles: flat shading and one colour per face, whatever the vertex sharing.
  const corner = new Float32Array(tris.length * 3);
  const kindColour = new Float32Array(tris.length * 3);
  const heatColours = new Float32Array(tris.length * 3);
  const c = new THREE.Color();
  for (let i = 0; i < tris.length; ++i) {
    const v = tris[i];
    corner.set(positions.subarray(3 * v, 3 * v + 3), 3 * i);
    KIND_COLOURS[kinds[Math.floor(i / 3)]].toArray(kindColour, 3 * i);
    heatColour(heat ? heat[v] : 0, c).toArray(heatColours, 3 * i);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(corner, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(kindColour, 3));
  geometry.computeVertexNormals();
  geometry.computeBoundingSphere();
  const material = new THREE.MeshLambertMaterial({
    vertexColors: true, flatShading: true, side: THREE.DoubleSide,
    polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
  });
  const surface = new THREE.Mesh(geometry, material);

  const edges = decode(column.edges, Uint32Array);
  const wireGeometry = new THREE.BufferGeometry();
  wireGeometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  wireGeometry.setIndex(new THREE.BufferAttribute(edges, 1));
  const wire = new THREE.LineSegments(wireGeometry, new THREE.LineBasicMaterial({ color: 0x222222, transparent: true, opacity: 0.55 }));

  const segments = decode(column.chord_segments, Float32Array);
  const segmentChord = decode(column.chord_of_segment, Uint32Array);
  const chordColours = new Float32Array(segments.length);
  for (let s = 0; s < segmentChord.length; ++s) {
    chordColour(segmentChord[s], c);
    c.toArray(chordColours, 6 * s);
    c.toArray(chordColours, 6 * s + 3);
  }
  const chordGeometry = new THREE.BufferGeometry();
  chordGeometry.setAttribute('position', new THREE.BufferAttribute(segments, 3));
  chordGeometry.setAttribute('color', new THREE.BufferAttribute(chordColours, 3));
  const chords = new THREE.LineSegments(chordGeometry, new THREE.LineBasicMaterial({ vertexColors: true }));
  chords.visible = false;

  const scene = new THREE.Scene();
  scene.background = BACKGROUND;
  const model = new THREE.Group();  // rotated as a whole by the "Z up" switch
  model.add(surface, wire, chords);
  scene.add(model);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8a80, 1.6));
  const light = new THREE.DirectionalLight(0xffffff, 1.4);  // a headlight: follows the camera
  scene.add(light, light.target);
  return { column, scene, model, surface, wire, chords, light, kindColour, heatColours, hasHeat: !!heat };
}

const views = data.columns.map(buildView);

const canvas = document.getElementById('canvas');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setScissorTest(true);

// One camera for all views: an orbit around the origin (the input's bbox centre).
const camera = new THREE.PerspectiveCamera(35, 1, 0.01, 100);
const orbit = { theta: 0.6, phi: 1.15, radius: 2.4, target: new THREE.Vector3() };
function resetView() {
  Object.assign(orbit, { theta: 0.6, phi: 1.15, radius: 2.4 });
  orbit.target.set(0, 0, 0);
}
function placeCamera() {
  const { theta, phi, radius, target } = orbit;
  camera.position.set(target.x + radius * Math.sin(phi) * Math.sin(theta), target.y + radius * Math.cos(phi),
                      target.z + radius * Math.sin(phi) * Math.cos(theta));
  camera.lookAt(target);
}

const labels = document.getElementById('labels');
for (const v of views) {
  const div = document.createElement('div');
  div.className = 'view-label';
  const c = v.column;
  div.innerHTML = `<b></b><br>${c.faces} faces: <span class="q">${c.quads} quads</span>, ` +
                  `<span class="t">${c.triangles} tris</span>, <span class="n">${c.ngons} n-gons</span>` +
                  `<br>${c.tri_equivalent} triangle-equivalents · ${c.chords} poly-chords`;
  div.querySelector('b').textContent = c.role === 'input' ? `${c.label} (input)` : c.label;
  labels.appendChild(div);
  v.label = div;
}

const legend = document.getElementById('legend');
function drawLegend() {
  const heatOn = document.getElementById('show-heat').checked;
  if (!heatOn) {
    legend.innerHTML = KIND_NAMES.map((n, i) =>
      `<span class="swatch" style="background:#${KIND_COLOURS[i].getHexString()}"></span>${n}`).join(' ');
  } else {
    const stops = RAMP.map(([t, col]) => `#${col.getHexString()} ${100 * t}%`).join(',');
    legend.innerHTML = `distance to the input surface: 0 <span class="ramp" style="background:linear-gradient(90deg,${stops})"></span> ` +
                       `${data.heat_max.toExponential(2)} (largest ${data.heat_top.toExponential(2)}) — the input view keeps its face colours`;
  }
}

function applyToggles() {
  const wire = document.getElementById('show-wire').checked;
  const chords = document.getElementById('show-chords').checked;
  const heat = document.getElementById('show-heat').checked;
  const zUp = document.getElementById('z-up').checked;
  for (const v of views) {
    v.model.rotation.x = zUp ? -Math.PI / 2 : 0;  // Z-up files (CAD, Blender's own axes) stand upright
    v.wire.visible = wire;
    v.chords.visible = chords;
    const colours = heat && v.hasHeat ? v.heatColours : v.kindColour;
    const attribute = v.surface.geometry.getAttribute('color');
    attribute.array.set(colours);
    attribute.needsUpdate = true;
  }
  drawLegend();
  requestRender();
}
for (const id of ['show-wire', 'show-chords', 'show-heat', 'z-up']) document.getElementById(id).addEventListener('change', applyToggles);
document.getElementById('reset-view').addEventListener('click', () => { resetView(); requestRender(); });

function layout() {
  const width = canvas.clientWidth, height = canvas.clientHeight;
  renderer.setSize(width, height, false);
  const w = width / views.length;
  views.forEach((v, i) => {
    v.rect = { x: Math.round(i * w), y: 0, w: Math.round((i + 1) * w) - Math.round(i * w), h: height };
    v.label.style.left = `${v.rect.x}px`;
    v.label.style.width = `${v.rect.w}px`;
  });
}

let pending = false;
function requestRender() {
  if (!pending) {
    pending = true;
    requestAnimationFrame(render);
  }
}
let firstFrame = true;
function render() {
  pending = false;
  placeCamera();
  const height = renderer.domElement.height / renderer.getPixelRatio();
  for (const v of views) {
    const { x, w, h } = v.rect;
    renderer.setViewport(x, height - h, w, h);
    renderer.setScissor(x, height - h, w, h);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
    v.light.position.copy(camera.position);
    v.light.target.position.copy(orbit.target);
    renderer.render(v.scene, camera);
  }
  if (firstFrame) {
    firstFrame = false;
    selfCheck();
  }
}

/// Counts, per view, the pixels that differ from the background: a blank view has none.
function selfCheck() {
  const gl = renderer.getContext();
  const ratio = renderer.getPixelRatio();
  const counts = views.map((v) => {
    const w = Math.floor(v.rect.w * ratio), h = Math.floor(v.rect.h * ratio);
    const pixels = new Uint8Array(w * h * 4);
    gl.readPixels(Math.floor(v.rect.x * ratio), 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    const [r0, g0, b0] = [BACKGROUND_HEX >> 16, (BACKGROUND_HEX >> 8) & 255, BACKGROUND_HEX & 255];
    let differ = 0;
    for (let i = 0; i < pixels.length; i += 4) {
      if (Math.abs(pixels[i] - r0) + Math.abs(pixels[i + 1] - g0) + Math.abs(pixels[i + 2] - b0) > 24) ++differ;
    }
    return differ / (w * h);
  });
  document.body.dataset.foreground = JSON.stringify(counts);
  if (!errors.length) document.body.dataset.renderStatus = counts.every((f) => f > 0.01) ? 'ok' : 'blank';
}

// --- synchronised orbit: one camera, so every view follows ---------------------------------------
let drag = null;
canvas.addEventListener('pointerdown', (e) => {
  drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
  canvas.setPointerCapture(e.pointerId);
});
canvas.addEventListener('pointermove', (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX;
  drag.y = e.clientY;
  if (drag.pan) {
    const scale = orbit.radius / canvas.clientHeight;
    const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
    const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
    orbit.target.addScaledVector(right, -dx * scale).addScaledVector(up, dy * scale);
  } else {
    orbit.theta -= dx * 0.01;
    orbit.phi = Math.min(Math.PI - 0.01, Math.max(0.01, orbit.phi - dy * 0.01));
  }
  requestRender();
});
canvas.addEventListener('pointerup', () => { drag = null; });
canvas.addEventListener('contextmenu', (e) => e.preventDefault());
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  orbit.radius = Math.min(50, Math.max(0.05, orbit.radius * Math.exp(e.deltaY * 0.001)));
  requestRender();
}, { passive: false });
window.addEventListener('resize', () => { layout(); requestRender(); });

// report.html#heat,chords,nowire,zup opens with those switches set (links, screenshots).
const flags = new Set(location.hash.slice(1).split(','));
if (flags.has('heat')) document.getElementById('show-heat').checked = true;
if (flags.has('chords')) document.getElementById('show-chords').checked = true;
if (flags.has('nowire')) document.getElementById('show-wire').checked = false;
if (flags.has('zup')) document.getElementById('z-up').checked = true;
layout();
applyToggles();
