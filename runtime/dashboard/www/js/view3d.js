// The figure in 3-D: the bodies of the model posed as the server measures
// them, the commanded pose as a translucent ghost over it, a ground grid.
// World frame as in MuJoCo: z up, quaternions [w, x, y, z].

import * as THREE from '/lib/three.module.js';

const GHOST = { color: 0x7fc8ff, opacity: 0.28 };

// Software GL (SwiftShader, llvmpipe) draws on the CPUs that run the loop
// and the simulated devices; multisampling there costs several times the
// frame itself (with it, a page open on a 2-core machine made the simulated
// servos miss their watchdog), so it is off.
function softwareGL() {
  try {
    const gl = document.createElement('canvas').getContext('webgl');
    if (!gl) return false;
    const debug = gl.getExtension('WEBGL_debug_renderer_info');
    const name = String(gl.getParameter(debug ? debug.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
    const lose = gl.getExtension('WEBGL_lose_context');
    if (lose) lose.loseContext();
    return /swiftshader|llvmpipe|softpipe|software/i.test(name);
  } catch {
    return false;
  }
}

function webglContext(canvas, antialias) {
  const opts = { antialias, alpha: false };
  try {
    return canvas.getContext('webgl', opts) || canvas.getContext('experimental-webgl', opts);
  } catch {
    return null;
  }
}

function rgbaColor(rgba) {
  if (Array.isArray(rgba) && rgba.length >= 3) {
    return new THREE.Color(rgba[0], rgba[1], rgba[2]);
  }
  return new THREE.Color(0.75, 0.62, 0.45);
}

// MuJoCo geom sizes: box half-sizes; sphere [r]; capsule and cylinder
// [r, half-length] along the geom's z axis; ellipsoid radii.
function geomMesh(geom, material) {
  const s = Array.isArray(geom.size) ? geom.size : [];
  const n = (i, d) => (typeof s[i] === 'number' && s[i] > 0 ? s[i] : d);
  const type = geom.type || 'box';
  let object;
  if (type === 'box') {
    object = new THREE.Mesh(new THREE.BoxBufferGeometry(2 * n(0, 0.01), 2 * n(1, 0.01), 2 * n(2, 0.01)), material);
  } else if (type === 'sphere') {
    object = new THREE.Mesh(new THREE.SphereBufferGeometry(n(0, 0.01), 20, 14), material);
  } else if (type === 'ellipsoid') {
    object = new THREE.Mesh(new THREE.SphereBufferGeometry(1, 20, 14), material);
    object.scale.set(n(0, 0.01), n(1, 0.01), n(2, 0.01));
  } else if (type === 'cylinder' || type === 'capsule') {
    const r = n(0, 0.01);
    const half = n(1, 0.01);
    const cylinder = new THREE.CylinderBufferGeometry(r, r, 2 * half, 20, 1, type === 'capsule');
    cylinder.rotateX(Math.PI / 2); // three's cylinders stand along y, MuJoCo's along z
    object = new THREE.Group();
    object.add(new THREE.Mesh(cylinder, material));
    if (type === 'capsule') {
      for (const z of [-half, half]) {
        const cap = new THREE.Mesh(new THREE.SphereBufferGeometry(r, 16, 10), material);
        cap.position.z = z;
        object.add(cap);
      }
    }
  } else {
    return null; // planes (the grid stands in for the floor), meshes, height fields
  }
  if (Array.isArray(geom.pos) && geom.pos.length === 3) object.position.set(...geom.pos);
  if (Array.isArray(geom.quat) && geom.quat.length === 4) {
    const [w, x, y, z] = geom.quat;
    object.quaternion.set(x, y, z, w).normalize();
  }
  return object;
}

function buildFigure(model, ghost) {
  const bodies = [];
  const root = new THREE.Group();
  for (const body of model.bodies || []) {
    const group = new THREE.Group();
    group.visible = false; // until the server sends its pose
    for (const geom of body.geoms || []) {
      const material = ghost
        ? new THREE.MeshBasicMaterial({ color: GHOST.color, transparent: true, opacity: GHOST.opacity, depthWrite: false })
        : new THREE.MeshLambertMaterial({ color: rgbaColor(geom.rgba) });
      const mesh = geomMesh(geom, material);
      if (mesh) group.add(mesh);
    }
    root.add(group);
    bodies.push(group);
  }
  return { root, bodies };
}

function applyPoses(figure, poses) {
  if (!Array.isArray(poses)) return;
  figure.bodies.forEach((group, i) => {
    const p = poses[i];
    if (!p || !Array.isArray(p.pos) || !Array.isArray(p.quat)) return;
    group.position.set(p.pos[0], p.pos[1], p.pos[2]);
    const [w, x, y, z] = p.quat;
    group.quaternion.set(x, y, z, w).normalize();
    group.visible = true;
  });
}

const GRID = { size: 6, cell: 0.25 };

// The floor: a grid in the x-y plane. Every cell edge is its own segment,
// so lines that pass behind the camera are clipped piecewise (software GL
// drops long clipped lines).
function floorGrid() {
  const n = Math.round(GRID.size / GRID.cell);
  const half = GRID.size / 2;
  const points = [];
  const colors = [];
  const minor = new THREE.Color(0x3a4656);
  const major = new THREE.Color(0x6a7a90);
  for (let i = 0; i <= n; i++) {
    const a = -half + i * GRID.cell;
    const c = i === n / 2 ? major : minor;
    for (let j = 0; j < n; j++) {
      const b0 = -half + j * GRID.cell;
      const b1 = b0 + GRID.cell;
      points.push(a, b0, 0, a, b1, 0, b0, a, 0, b1, a, 0);
      for (let k = 0; k < 4; k++) colors.push(c.r, c.g, c.b);
    }
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(points, 3));
  geometry.setAttribute('color', new THREE.Float32BufferAttribute(colors, 3));
  return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ vertexColors: THREE.VertexColors }));
}

// A small orbit around a target point: drag turns, wheel zooms.
class Orbit {
  constructor(camera, element, onChange) {
    this.camera = camera;
    this.target = new THREE.Vector3(0, 0, 0.2);
    this.azimuth = -Math.PI / 3;
    this.elevation = 0.6;
    this.distance = 1.6;
    this.onChange = onChange;
    let drag = null;
    element.addEventListener('pointerdown', (e) => {
      drag = { x: e.clientX, y: e.clientY };
      element.setPointerCapture(e.pointerId);
      element.style.cursor = 'grabbing';
    });
    element.addEventListener('pointermove', (e) => {
      if (!drag) return;
      this.azimuth -= (e.clientX - drag.x) * 0.008;
      this.elevation += (e.clientY - drag.y) * 0.008;
      this.elevation = Math.min(1.5, Math.max(-0.2, this.elevation));
      drag = { x: e.clientX, y: e.clientY };
      this.update();
    });
    const release = () => {
      drag = null;
      element.style.cursor = '';
    };
    element.addEventListener('pointerup', release);
    element.addEventListener('pointercancel', release);
    element.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.distance *= Math.exp(e.deltaY * 0.001);
      this.distance = Math.min(50, Math.max(0.1, this.distance));
      this.update();
    }, { passive: false });
    this.update();
  }

  update() {
    const c = Math.cos(this.elevation);
    this.camera.position.set(
      this.target.x + this.distance * c * Math.cos(this.azimuth),
      this.target.y + this.distance * c * Math.sin(this.azimuth),
      this.target.z + this.distance * Math.sin(this.elevation));
    this.camera.lookAt(this.target);
    this.onChange();
  }
}

export class FigureView {
  constructor(container, note) {
    this.container = container;
    this.note = note;
    this.ok = false;
    const canvas = document.createElement('canvas');
    const software = softwareGL();
    const gl = webglContext(canvas, !software);
    if (!gl) {
      container.dataset.webgl = '0';
      this.showNote('3-D view unavailable: this browser gives no WebGL context.');
      return;
    }
    container.prepend(canvas);
    this.renderer = new THREE.WebGLRenderer({ canvas, context: gl, antialias: !software });
    this.renderer.setPixelRatio(software ? 1 : window.devicePixelRatio || 1);
    container.dataset.gl = software ? 'software' : 'hardware';
    this.renderer.setClearColor(0x0d1014);

    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 200);
    this.camera.up.set(0, 0, 1);
    this.scene.add(new THREE.HemisphereLight(0xdde6f0, 0x30281e, 0.75));
    const sun = new THREE.DirectionalLight(0xffffff, 0.7);
    sun.position.set(2, -3, 5);
    this.scene.add(sun);
    this.grid = floorGrid();
    this.scene.add(this.grid);

    this.pending = false;
    this.orbit = new Orbit(this.camera, container, () => this.requestRender());
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
    this.ok = true;
    container.dataset.webgl = '1';
  }

  showNote(text) {
    this.note.textContent = text;
    this.note.hidden = false;
  }

  setModel(model) {
    if (!this.ok) return;
    if (!model || !Array.isArray(model.bodies) || model.bodies.length === 0) {
      this.showNote('No model: the robot file names no MJCF model, so there is no figure to draw.');
      this.requestRender();
      return;
    }
    this.measured = buildFigure(model, false);
    this.commanded = buildFigure(model, true);
    this.scene.add(this.measured.root);
    this.scene.add(this.commanded.root);
    this.container.dataset.model = String(model.bodies.length);
    this.framed = false;
    this.requestRender();
  }

  // Draws only a pose that differs from the one on screen, so the view is
  // drawn at most once per streamed state and not at all while the figure
  // stands still (with software GL each drawing costs the run's machine CPU).
  update(bodies) {
    if (!this.ok || !this.measured || !bodies) return;
    const pose = JSON.stringify([bodies.measured, bodies.commanded]);
    if (pose === this.shownPose) return;
    this.shownPose = pose;
    applyPoses(this.measured, bodies.measured);
    applyPoses(this.commanded, bodies.commanded);
    // A digest of the measured pose, for tests: it changes as the figure moves.
    if (Array.isArray(bodies.measured)) {
      let sum = 0;
      bodies.measured.forEach((p, i) => {
        if (p && Array.isArray(p.pos)) sum += (i + 1) * (p.pos[0] + 2 * p.pos[1] + 3 * p.pos[2]);
      });
      this.container.dataset.pose = sum.toFixed(6);
    }
    this.follow();
    this.requestRender();
  }

  // Keep the figure in view as it walks: the orbit's target follows the
  // measured figure's centre, the grid moves in whole cells under it.
  follow() {
    const box = new THREE.Box3().setFromObject(this.measured.root);
    if (box.isEmpty()) return;
    const centre = box.getCenter(new THREE.Vector3());
    if (!this.framed) {
      const size = box.getSize(new THREE.Vector3()).length();
      this.orbit.distance = Math.max(0.5, 2.2 * size);
      this.framed = true;
    }
    this.orbit.target.lerp(centre, 0.2);
    const cell = GRID.cell;
    this.grid.position.set(Math.round(centre.x / cell) * cell, Math.round(centre.y / cell) * cell, 0);
    this.orbit.update();
  }

  resize() {
    const w = this.container.clientWidth || 1;
    const h = this.container.clientHeight || 1;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  requestRender() {
    if (!this.ok || this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.renderer.render(this.scene, this.camera);
    });
  }
}
