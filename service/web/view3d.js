// The 3-D view: the body about its centre of mass, principal axes I1 I2 I3, the inertia ellipsoid,
// and with a trajectory the torque-free motion (M fixed in space, Ω, and for a symmetric top the cones).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

// metres per unit of the input (API.md: `units`); the service reports the unit it applied in source.units
const UNIT = { m: 1, cm: 0.01, mm: 0.001, um: 1e-6, in: 0.0254, ft: 0.3048, angstrom: 1e-10 };
const PART_COLORS = ['#5b8bd0', '#e07a5f', '#59a96a', '#d9a21b', '#9c6ade', '#2a9d8f', '#c2185b', '#6d4c41'];
const AXIS_COLORS = ['#d62828', '#2a9d45', '#1d4ed8'];
const BACKGROUND = '#eef2f7';

function webgl2Available() {
  try {
    return Boolean(document.createElement('canvas').getContext('webgl2'));
  } catch {
    return false;
  }
}

function label(text, color, size) {
  const canvas = document.createElement('canvas');
  canvas.width = 128; canvas.height = 64;
  const ctx = canvas.getContext('2d');
  ctx.font = 'bold 44px system-ui, sans-serif';
  ctx.textAlign = 'center'; ctx.textBaseline = 'middle';
  ctx.lineWidth = 8; ctx.strokeStyle = 'rgba(255,255,255,0.9)';
  ctx.strokeText(text, 64, 34);
  ctx.fillStyle = color; ctx.fillText(text, 64, 34);
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = THREE.SRGBColorSpace;
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({ map: texture, depthTest: false, transparent: true }));
  sprite.scale.set(size, size / 2, 1);
  sprite.renderOrder = 20;
  return sprite;
}

function arrow(dir, length, color, radius) {
  const group = new THREE.Group();
  const material = new THREE.MeshStandardMaterial({ color, roughness: 0.5 });
  const headLength = Math.min(0.18 * length, 6 * radius);
  const shaft = new THREE.Mesh(new THREE.CylinderGeometry(radius, radius, length - headLength, 12), material);
  shaft.position.y = (length - headLength) / 2;
  const head = new THREE.Mesh(new THREE.ConeGeometry(2.4 * radius, headLength, 16), material);
  head.position.y = length - headLength / 2;
  group.add(shaft, head);
  group.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), dir.clone().normalize());
  return group;
}

// a cone with its apex at the origin around `axis`, half-angle alpha, slant length L
function cone(axis, alpha, L, color) {
  const h = L * Math.cos(alpha);
  const r = L * Math.sin(alpha);
  const geometry = new THREE.ConeGeometry(r, h, 64, 1, true).rotateX(Math.PI).translate(0, h / 2, 0);
  const material = new THREE.MeshStandardMaterial({ color, transparent: true, opacity: 0.28, side: THREE.DoubleSide, depthWrite: false });
  const mesh = new THREE.Mesh(geometry, material);
  const rim = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(
    Array.from({ length: 64 }, (_, i) => new THREE.Vector3(r * Math.cos(2 * Math.PI * i / 64), h, r * Math.sin(2 * Math.PI * i / 64)))),
  new THREE.LineBasicMaterial({ color }));
  const group = new THREE.Group();
  group.add(mesh, rim);
  group.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), axis.clone().normalize());
  return group;
}

function dispose(group) {
  group.traverse((o) => {
    if (o.geometry) o.geometry.dispose();
    if (o.material) {
      if (o.material.map) o.material.map.dispose();
      o.material.dispose();
    }
  });
  group.clear();
}

// semi-axes of the uniform solid ellipsoid with the same principal moments: a_i² = 5/(2m) (I_j + I_k − I_i)
export function ellipsoidSemiAxes(moments, mass) {
  const [I1, I2, I3] = moments;
  return [I2 + I3 - I1, I1 + I3 - I2, I1 + I2 - I3].map((s) => Math.sqrt(Math.max(s, 0) * 5 / (2 * mass)));
}

export class Viewer {
  static create(container) {
    return webgl2Available() ? new Viewer(container) : null;
  }

  static partColor(i) {
    return PART_COLORS[i % PART_COLORS.length];
  }

  constructor(container) {
    this.container = container;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.setClearColor(BACKGROUND);
    container.querySelector('.placeholder')?.remove();
    container.append(this.renderer.domElement);
    this.renderer.domElement.setAttribute('aria-hidden', 'true');
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(2, -3, 1.5);
    this.scene.add(new THREE.HemisphereLight('#ffffff', '#8090a0', 1.6));
    this.light = new THREE.DirectionalLight('#ffffff', 1.8);
    this.camera.add(this.light);
    this.light.position.set(1, 2, 1);
    this.scene.add(this.camera);
    this.pivot = new THREE.Group(); // the body frame: rotated by the attitude q(t)
    this.fixed = new THREE.Group(); // the fixed (input) frame
    this.scene.add(this.pivot, this.fixed);
    this.layers = { body: new THREE.Group(), axes: new THREE.Group(), ellipsoid: new THREE.Group(), cones: new THREE.Group() };
    this.pivot.add(this.layers.body, this.layers.axes, this.layers.ellipsoid);
    this.spaceCone = new THREE.Group();
    this.bodyCone = new THREE.Group();
    this.pivot.add(this.bodyCone);
    this.fixed.add(this.spaceCone);
    this.motion = null;
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = false;
    this.controls.addEventListener('change', () => this.render());
    this.controls.listenToKeyEvents(container); // arrows pan, Shift+arrows rotate
    container.addEventListener('keydown', (e) => {
      const factor = { '+': 0.85, '=': 0.85, '-': 1 / 0.85, '−': 1 / 0.85 }[e.key];
      if (!factor) return;
      e.preventDefault();
      this.camera.position.sub(this.controls.target).multiplyScalar(factor).add(this.controls.target);
      this.controls.update();
    });
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  resize() {
    const w = this.container.clientWidth || 1;
    const h = this.container.clientHeight || 1;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() {
    this.renderer.render(this.scene, this.camera);
  }

  setVisible(name, visible) {
    if (name === 'cones') { this.spaceCone.visible = visible; this.bodyCone.visible = visible; } else this.layers[name].visible = visible;
    this.render();
  }

  // draw a result: `shape` is {parts: [{name, geometry}]} (file units), {points: [{position, mass?}]}, or null
  show(result, shape) {
    for (const g of [...Object.values(this.layers), this.spaceCone, this.bodyCone, this.fixed]) {
      if (g !== this.spaceCone) dispose(g);
    }
    this.fixed.add(this.spaceCone);
    this.pivot.quaternion.identity();
    this.motion = null;
    const scale = UNIT[result.source && result.source.units] ?? 1;
    const com = new THREE.Vector3(...result.center_of_mass);
    let bodyRadius = 0;
    if (shape && shape.parts) bodyRadius = this.drawParts(shape.parts, scale, com);
    else if (shape && shape.points) bodyRadius = this.drawPoints(shape.points, scale, com);
    const semi = ellipsoidSemiAxes(result.principal.moments, result.mass);
    const R = Math.max(bodyRadius, ...semi) || 1;
    this.radius = R;
    this.drawEllipsoid(result.principal.axes, semi, R);
    this.drawAxes(result.principal.axes, R);
    if (result.parts) this.drawPartCentres(result.parts, com, R);
    this.frame(R);
  }

  drawParts(parts, scale, com) {
    let radius = 0;
    parts.forEach((part, i) => {
      const g = part.geometry.clone().scale(scale, scale, scale).translate(-com.x, -com.y, -com.z);
      g.deleteAttribute('normal');
      g.computeVertexNormals();
      g.computeBoundingSphere();
      radius = Math.max(radius, g.boundingSphere.center.length() + g.boundingSphere.radius);
      const color = parts.length > 1 ? Viewer.partColor(i) : '#7d9cc4';
      const material = new THREE.MeshStandardMaterial({ color, roughness: 0.65, metalness: 0.05, flatShading: true,
        transparent: true, opacity: 0.82, side: THREE.DoubleSide });
      const mesh = new THREE.Mesh(g, material);
      mesh.name = part.name;
      this.layers.body.add(mesh);
    });
    return radius;
  }

  drawPoints(points, scale, com) {
    const positions = points.map((p) => new THREE.Vector3(...p.position).multiplyScalar(scale).sub(com));
    const extent = Math.max(...positions.map((v) => v.length()), 1e-30);
    const mmax = Math.max(...points.map((p) => p.mass ?? 1));
    const geometry = new THREE.SphereGeometry(1, 24, 16);
    points.forEach((p, i) => {
      const r = 0.09 * extent * Math.cbrt((p.mass ?? 1) / mmax);
      const mesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({ color: Viewer.partColor(i % 3 === 0 ? 0 : i), roughness: 0.4 }));
      mesh.position.copy(positions[i]);
      mesh.scale.setScalar(Math.max(r, 0.03 * extent));
      this.layers.body.add(mesh);
    });
    return extent * 1.1;
  }

  drawEllipsoid(axes, semi, R) {
    const basis = new THREE.Matrix4().makeBasis(...axes.map((a) => new THREE.Vector3(...a)));
    const s = semi.map((a) => Math.max(a, 0.004 * R)); // a zero semi-axis (rotator) is drawn as a thin sheet
    const shell = new THREE.Mesh(new THREE.SphereGeometry(1, 48, 24), new THREE.MeshStandardMaterial({
      color: '#f59e0b', transparent: true, opacity: 0.16, depthWrite: false, side: THREE.DoubleSide }));
    shell.scale.set(...s);
    const group = new THREE.Group();
    group.add(shell);
    for (let k = 0; k < 3; k += 1) { // the three principal sections
      const pts = Array.from({ length: 97 }, (_, i) => {
        const c = Math.cos(2 * Math.PI * i / 96), d = Math.sin(2 * Math.PI * i / 96);
        const v = [0, 0, 0]; v[(k + 1) % 3] = c * s[(k + 1) % 3]; v[(k + 2) % 3] = d * s[(k + 2) % 3];
        return new THREE.Vector3(...v);
      });
      group.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: '#b45309' })));
    }
    group.quaternion.setFromRotationMatrix(basis);
    this.layers.ellipsoid.add(group);
  }

  drawAxes(axes, R) {
    const L = 1.3 * R;
    axes.forEach((a, i) => {
      const dir = new THREE.Vector3(...a).normalize();
      this.layers.axes.add(arrow(dir, L, AXIS_COLORS[i], 0.008 * R));
      const back = new THREE.Line(new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), dir.clone().multiplyScalar(-L)]),
        new THREE.LineDashedMaterial({ color: AXIS_COLORS[i], dashSize: 0.04 * R, gapSize: 0.03 * R }));
      back.computeLineDistances();
      this.layers.axes.add(back);
      const tag = label(`I${i + 1}`, AXIS_COLORS[i], 0.3 * R);
      tag.position.copy(dir.clone().multiplyScalar(L * 1.1));
      this.layers.axes.add(tag);
    });
    const com = new THREE.Mesh(new THREE.SphereGeometry(0.03 * R, 20, 12), new THREE.MeshBasicMaterial({ color: '#111827', depthTest: false }));
    com.renderOrder = 10;
    this.layers.axes.add(com);
  }

  drawPartCentres(parts, com, R) {
    parts.forEach((p, i) => {
      const dot = new THREE.Mesh(new THREE.SphereGeometry(0.025 * R, 16, 10), new THREE.MeshBasicMaterial({ color: Viewer.partColor(i), depthTest: false }));
      dot.position.set(...p.center_of_mass).sub(com);
      dot.renderOrder = 9;
      this.layers.body.add(dot);
    });
  }

  frame(R, across) {
    const dir = new THREE.Vector3(1.1, -1.6, 0.95).normalize();
    if (across && across.lengthSq() > 0) { // look across this direction (M), not along it
      const a = across.clone().normalize();
      dir.addScaledVector(a, -dir.dot(a)).normalize().addScaledVector(a, 0.35).normalize();
    }
    this.camera.position.copy(dir.multiplyScalar(4.3 * R));
    this.camera.near = R / 200;
    this.camera.far = R * 200;
    this.camera.updateProjectionMatrix();
    this.controls.target.set(0, 0, 0);
    this.controls.minDistance = 0.2 * R;
    this.controls.maxDistance = 40 * R;
    this.controls.update();
    this.render();
  }

  // a trajectory (API.md: quaternion carries the body from t = 0 to t; omega in the fixed frame)
  setMotion(result, traj) {
    dispose(this.spaceCone); dispose(this.bodyCone);
    for (const o of [...this.fixed.children]) if (o !== this.spaceCone) { dispose(o); this.fixed.remove(o); }
    this.pivot.quaternion.identity();
    this.motion = null;
    if (!result || !traj) { this.render(); return; }
    const R = this.radius;
    const p = result.precession;
    const M = new THREE.Vector3(...p.angular_momentum);
    const omegaMax = Math.max(...traj.omega.map((w) => Math.hypot(...w)), 1e-300);
    if (M.length() > 0) {
      this.fixed.add(arrow(M, 1.5 * R, '#c2410c', 0.012 * R));
      const tag = label('M', '#c2410c', 0.3 * R);
      tag.position.copy(M.clone().normalize().multiplyScalar(1.62 * R));
      this.fixed.add(tag);
    }
    // herpolhode: the tip of Ω traced in space
    const tips = traj.omega.map((w) => new THREE.Vector3(...w).multiplyScalar(1.15 * R / omegaMax));
    this.fixed.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(tips), new THREE.LineBasicMaterial({ color: '#7c3aed' })));
    this.omegaArrow = new THREE.Group();
    this.omegaTag = label('Ω', '#7c3aed', 0.28 * R);
    this.fixed.add(this.omegaArrow, this.omegaTag);
    const w0 = new THREE.Vector3(...traj.omega[0]);
    if (p.regime === 'regular_precession' && result.classification.symmetry_axis && M.length() > 0 && w0.length() > 0) {
      const axis = new THREE.Vector3(...result.classification.symmetry_axis);
      if (axis.dot(w0) < 0) axis.negate();
      this.bodyCone.add(cone(axis, axis.angleTo(w0), 1.15 * R, '#0e7490'));
      this.spaceCone.add(cone(M, M.angleTo(w0), 1.15 * R, '#be185d'));
    }
    this.motion = { traj, omegaMax, R, q0: new THREE.Quaternion(), q1: new THREE.Quaternion() };
    this.frame(R, M);
    this.setTime(0);
  }

  setTime(t) {
    const m = this.motion;
    if (!m) return;
    const ts = m.traj.t;
    let lo = 0, hi = ts.length - 1;
    while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (ts[mid] <= t) lo = mid; else hi = mid; }
    const f = ts[hi] > ts[lo] ? Math.min(Math.max((t - ts[lo]) / (ts[hi] - ts[lo]), 0), 1) : 0;
    const [a, b] = [m.traj.quaternion[lo], m.traj.quaternion[hi]];
    m.q0.set(a[1], a[2], a[3], a[0]);
    m.q1.set(b[1], b[2], b[3], b[0]);
    this.pivot.quaternion.slerpQuaternions(m.q0, m.q1, f);
    const w = m.traj.omega[lo].map((x, k) => x + f * (m.traj.omega[hi][k] - x));
    const wv = new THREE.Vector3(...w);
    dispose(this.omegaArrow);
    if (wv.length() > 0) {
      const length = 1.15 * m.R * wv.length() / m.omegaMax;
      const shaft = arrow(wv, length, '#7c3aed', 0.01 * m.R);
      this.omegaArrow.add(shaft);
      this.omegaTag.position.copy(wv.clone().normalize().multiplyScalar(length + 0.1 * m.R));
    }
    this.render();
  }
}
