"use strict";
// The 3-D view of a measurement: its fused cloud coloured by height with the measured box drawn
// in it; drag to turn it. The canvas follows its box's size (a turned phone, a resized window).
// After each draw the canvas says what it shows and what reached the screen (data-id,
// data-points, data-lit-pixels).

// Reads the x, y, z floats of a binary little-endian PLY (what the daemon writes).
function parsePly(buffer) {
  const head = new TextDecoder().decode(new Uint8Array(buffer, 0, Math.min(buffer.byteLength, 2048)));
  const end = head.indexOf("end_header\n");
  const count = /element vertex (\d+)/.exec(head);
  if (end < 0 || !count || !head.includes("binary_little_endian")) throw new Error("not a binary PLY");
  const floats = (head.slice(0, end).match(/^property float/gm) || []).length;
  const n = Number(count[1]), view = new DataView(buffer, end + "end_header\n".length);
  const xyz = new Float32Array(n * 3);
  for (let i = 0; i < n; ++i) {
    for (let k = 0; k < 3; ++k) xyz[3 * i + k] = view.getFloat32((i * floats + k) * 4, true);
  }
  return xyz;
}

// Returns the scene: the points coloured by height, and the box of measurement `m` when it has one.
function buildScene(xyz, m) {
  const scene = new THREE.Scene();
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.BufferAttribute(xyz, 3));
  geometry.computeBoundingBox();
  const bounds = geometry.boundingBox, colors = new Float32Array(xyz.length), color = new THREE.Color();
  for (let i = 0; i < xyz.length; i += 3) {
    const t = (xyz[i + 2] - bounds.min.z) / Math.max(1e-6, bounds.max.z - bounds.min.z);
    color.setHSL(0.66 - 0.66 * t, 0.8, 0.55).toArray(colors, i);
  }
  geometry.setAttribute("color", new THREE.BufferAttribute(colors, 3));
  scene.add(new THREE.Points(geometry,
    new THREE.PointsMaterial({ size: 2, sizeAttenuation: false, vertexColors: true })));
  const centre = new THREE.Vector3();
  bounds.getCenter(centre);
  const d = m.dimensions;
  if (d && d.center_m && d.axes) {
    const box = new THREE.LineSegments(
      new THREE.EdgesGeometry(new THREE.BoxGeometry(d.length_m, d.width_m, d.height_m)),
      new THREE.LineBasicMaterial({ color: 0xffa000 }));
    const [a, b, c] = d.axes.map((v) => new THREE.Vector3(...v));
    box.setRotationFromMatrix(new THREE.Matrix4().makeBasis(a, b, c));
    box.position.set(...d.center_m);
    scene.add(box);
    centre.set(...d.center_m);
  }
  return { scene, centre, size: bounds.getSize(new THREE.Vector3()).length() || 1 };
}

// Counts the lit pixels of what was drawn, for whoever checks the page.
function countLit(renderer, canvas) {
  const gl = renderer.getContext(), pixels = new Uint8Array(canvas.width * canvas.height * 4);
  gl.readPixels(0, 0, canvas.width, canvas.height, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
  let lit = 0;
  for (let i = 0; i < pixels.length; i += 4) lit += pixels[i] + pixels[i + 1] + pixels[i + 2] > 200 ? 1 : 0;
  return lit;
}

let shown = null;  // {renderer, observer} of the view on screen

// Shows measurement `m`'s cloud (the PLY's bytes) in the element `view`, replacing what was there.
function showCloud(view, m, buffer) {
  if (shown) { shown.observer.disconnect(); shown.renderer.dispose(); shown = null; }
  const xyz = parsePly(buffer);
  const { scene, centre, size } = buildScene(xyz, m);
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setClearColor(0x20262c);
  const camera = new THREE.PerspectiveCamera(40, 1, size / 100, size * 20);
  camera.up.set(0, 0, 1);
  let azimuth = -0.8, elevation = 0.5;
  const canvas = renderer.domElement;
  const draw = () => {
    camera.position.set(centre.x + 1.6 * size * Math.cos(elevation) * Math.cos(azimuth),
                        centre.y + 1.6 * size * Math.cos(elevation) * Math.sin(azimuth),
                        centre.z + 1.6 * size * Math.sin(elevation));
    camera.lookAt(centre);
    renderer.render(scene, camera);
    canvas.dataset.id = m.id;
    canvas.dataset.points = String(xyz.length / 3);
    canvas.dataset.litPixels = String(countLit(renderer, canvas));
  };
  const fit = () => {
    const w = Math.max(1, view.clientWidth), h = Math.max(1, view.clientHeight);
    renderer.setSize(w, h);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
    draw();
  };
  canvas.addEventListener("pointermove", (e) => {
    if (!e.buttons) return;
    azimuth -= e.movementX * 0.01;
    elevation = Math.max(-1.4, Math.min(1.4, elevation + e.movementY * 0.01));
    draw();
  });
  view.replaceChildren(canvas);
  fit();
  const observer = new ResizeObserver(fit);
  observer.observe(view);
  shown = { renderer, observer };
}
