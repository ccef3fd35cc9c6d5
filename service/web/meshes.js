// Reading meshes in the browser, for drawing only (the numbers always come from the service),
// and decimating large ones by vertex clustering so that the view stays responsive.
import * as THREE from 'three';
import { STLLoader } from 'three/addons/loaders/STLLoader.js';
import { OBJLoader } from 'three/addons/loaders/OBJLoader.js';
import { PLYLoader } from 'three/addons/loaders/PLYLoader.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

export const BROWSER_FORMATS = ['stl', 'obj', 'ply', 'off', 'glb', 'gltf'];
export const MAX_TRIANGLES = 200000; // above this the view draws a decimated copy

function parseOFF(text) {
  const tokens = text.replace(/#[^\n]*/g, ' ').trim().split(/\s+/);
  let i = 0;
  if (/^[A-Z]*OFF$/.test(tokens[0])) i += 1;
  const [nv, nf] = [Number(tokens[i]), Number(tokens[i + 1])];
  i += 3;
  const v = new Float64Array(nv * 3);
  for (let k = 0; k < nv * 3; k += 1) v[k] = Number(tokens[i + k]);
  i += nv * 3;
  const out = [];
  for (let f = 0; f < nf; f += 1) {
    const n = Number(tokens[i]);
    const idx = tokens.slice(i + 1, i + 1 + n).map(Number);
    i += 1 + n;
    for (let k = 1; k + 1 < n; k += 1) {
      for (const j of [idx[0], idx[k], idx[k + 1]]) out.push(v[3 * j], v[3 * j + 1], v[3 * j + 2]);
    }
  }
  if (out.some((x) => !Number.isFinite(x))) throw new Error('malformed OFF');
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(out, 3));
  return g;
}

// every mesh of a three.js object tree, with its world transform applied: one part each
function partsOf(root) {
  root.updateMatrixWorld(true);
  const parts = [];
  root.traverse((o) => {
    if (o.isMesh && o.geometry && o.geometry.attributes.position) {
      const g = o.geometry.clone().applyMatrix4(o.matrixWorld);
      parts.push({ name: o.name || `part ${parts.length + 1}`, geometry: g });
    }
  });
  return parts;
}

function parseGLTF(buffer) {
  return new Promise((resolve, reject) => {
    new GLTFLoader().parse(buffer, '', (gltf) => resolve(partsOf(gltf.scene)), (e) => reject(new Error(e.message || String(e))));
  });
}

const triangles = (g) => (g.index ? g.index.count : g.attributes.position.count) / 3;

// vertex clustering on a grid: vertices in one cell merge at their mean, collapsed triangles drop
export function decimate(geometry, target) {
  const g = geometry.index ? geometry.toNonIndexed() : geometry;
  const pos = g.attributes.position.array;
  const box = new THREE.Box3().setFromBufferAttribute(g.attributes.position);
  const size = box.getSize(new THREE.Vector3());
  const extent = Math.max(size.x, size.y, size.z) || 1;
  let cells = Math.ceil(Math.sqrt(target / 2));
  for (;;) {
    const h = extent / cells;
    const ids = new Map();
    const sums = [];
    const cluster = new Int32Array(pos.length / 3);
    for (let v = 0; v < pos.length / 3; v += 1) {
      const ix = Math.floor((pos[3 * v] - box.min.x) / h);
      const iy = Math.floor((pos[3 * v + 1] - box.min.y) / h);
      const iz = Math.floor((pos[3 * v + 2] - box.min.z) / h);
      const key = (ix * (cells + 1) + iy) * (cells + 1) + iz;
      let id = ids.get(key);
      if (id === undefined) { id = sums.length / 4; ids.set(key, id); sums.push(0, 0, 0, 0); }
      sums[4 * id] += pos[3 * v]; sums[4 * id + 1] += pos[3 * v + 1]; sums[4 * id + 2] += pos[3 * v + 2]; sums[4 * id + 3] += 1;
      cluster[v] = id;
    }
    const out = [];
    for (let t = 0; t < cluster.length; t += 3) {
      const [a, b, c] = [cluster[t], cluster[t + 1], cluster[t + 2]];
      if (a === b || b === c || a === c) continue;
      for (const id of [a, b, c]) out.push(sums[4 * id] / sums[4 * id + 3], sums[4 * id + 1] / sums[4 * id + 3], sums[4 * id + 2] / sums[4 * id + 3]);
    }
    if (out.length / 9 <= target || cells < 4) {
      const d = new THREE.BufferGeometry();
      d.setAttribute('position', new THREE.Float32BufferAttribute(out, 3));
      return d;
    }
    cells = Math.floor(cells * 0.8);
  }
}

// file -> {parts: [{name, geometry}], triangles, originalTriangles, decimated}
export async function parseMesh(file, format) {
  const buffer = await file.arrayBuffer();
  let parts;
  if (format === 'stl') parts = [{ name: file.name, geometry: new STLLoader().parse(buffer) }];
  else if (format === 'ply') parts = [{ name: file.name, geometry: new PLYLoader().parse(buffer) }];
  else if (format === 'off') parts = [{ name: file.name, geometry: parseOFF(new TextDecoder().decode(buffer)) }];
  else if (format === 'obj') parts = partsOf(new OBJLoader().parse(new TextDecoder().decode(buffer)));
  else if (format === 'glb' || format === 'gltf') parts = await parseGLTF(buffer);
  else throw new Error(`no browser reader for ${format}`);
  parts = parts.filter((p) => triangles(p.geometry) > 0);
  if (parts.length === 0) throw new Error('no triangles found');
  const originalTriangles = parts.reduce((n, p) => n + triangles(p.geometry), 0);
  const decimated = originalTriangles > MAX_TRIANGLES;
  if (decimated) {
    for (const p of parts) p.geometry = decimate(p.geometry, Math.max(200, MAX_TRIANGLES * triangles(p.geometry) / originalTriangles));
  }
  const shown = parts.reduce((n, p) => n + triangles(p.geometry), 0);
  return { parts, triangles: shown, originalTriangles, decimated };
}

// an XYZ molecule for drawing: [{element, position}] in the file's units
export function parseXYZ(text) {
  const lines = text.split(/\r?\n/).slice(2);
  const atoms = [];
  for (const line of lines) {
    const [el, x, y, z] = line.trim().split(/\s+/);
    if (el && [x, y, z].every((c) => Number.isFinite(Number(c)))) atoms.push({ element: el, position: [Number(x), Number(y), Number(z)] });
  }
  return atoms;
}
