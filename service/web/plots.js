// Two plots on 2-D canvases: Ω(t) in the body frame, and the polhode on the energy ellipsoid.
const COLORS = ['#d62828', '#2a9d45', '#1d4ed8'];
const INK = '#374151';

function prepare(canvas) {
  const ratio = Math.min(window.devicePixelRatio || 1, 2);
  const w = canvas.clientWidth || canvas.width;
  const h = Math.round(w * 0.54);
  if (canvas.width !== Math.round(w * ratio)) { canvas.width = Math.round(w * ratio); canvas.height = Math.round(h * ratio); }
  const ctx = canvas.getContext('2d');
  ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
  ctx.clearRect(0, 0, w, h);
  ctx.font = '12px system-ui, sans-serif';
  return { ctx, w, h };
}

const short = (x) => (x === 0 ? '0' : Math.abs(x) >= 1e4 || Math.abs(x) < 1e-2 ? x.toExponential(1) : Number(x.toPrecision(3)).toString());

export function drawOmega(canvas, traj, now) {
  const { ctx, w, h } = prepare(canvas);
  const pad = { l: 46, r: 10, t: 10, b: 24 };
  const t = traj.t, W = traj.omega_body;
  const T = t[t.length - 1] || 1;
  const ymax = Math.max(...W.flat().map(Math.abs)) * 1.08 || 1;
  const X = (s) => pad.l + (w - pad.l - pad.r) * s / T;
  const Y = (v) => pad.t + (h - pad.t - pad.b) * (1 - (v + ymax) / (2 * ymax));
  ctx.strokeStyle = '#d1d5db'; ctx.lineWidth = 1;
  ctx.beginPath(); ctx.moveTo(pad.l, Y(0)); ctx.lineTo(w - pad.r, Y(0)); ctx.stroke();
  ctx.strokeStyle = INK; ctx.strokeRect(pad.l, pad.t, w - pad.l - pad.r, h - pad.t - pad.b);
  ctx.fillStyle = INK; ctx.textAlign = 'right'; ctx.textBaseline = 'middle';
  for (const v of [ymax, 0, -ymax]) ctx.fillText(short(v / 1.08 * (v === 0 ? 0 : 1)), pad.l - 4, Y(v));
  ctx.textAlign = 'center'; ctx.textBaseline = 'top';
  ctx.fillText('0', X(0), h - pad.b + 4); ctx.fillText(`${short(T)} s`, X(T) - 12, h - pad.b + 4);
  for (let k = 0; k < 3; k += 1) {
    ctx.strokeStyle = COLORS[k]; ctx.lineWidth = 1.6;
    ctx.beginPath();
    W.forEach((wk, i) => (i ? ctx.lineTo(X(t[i]), Y(wk[k])) : ctx.moveTo(X(t[i]), Y(wk[k]))));
    ctx.stroke();
    ctx.fillStyle = COLORS[k]; ctx.textAlign = 'left';
    ctx.fillText(`Ω${k + 1}`, pad.l + 6 + 34 * k, pad.t + 4);
  }
  ctx.strokeStyle = '#111827'; ctx.lineWidth = 1; ctx.setLineDash([4, 3]);
  ctx.beginPath(); ctx.moveTo(X(now), pad.t); ctx.lineTo(X(now), h - pad.b); ctx.stroke();
  ctx.setLineDash([]);
}

// orthographic view of body-frame points: returns [screen x, screen y, depth] with depth > 0 behind
function projector(w, h, extent) {
  const az = -0.75, el = 0.45;
  const s = 0.4 * Math.min(w, h) / extent;
  return ([x, y, z]) => {
    const x1 = Math.cos(az) * x - Math.sin(az) * y;
    const y1 = Math.sin(az) * x + Math.cos(az) * y;
    const sy = z * Math.cos(el) - y1 * Math.sin(el);
    const depth = y1 * Math.cos(el) + z * Math.sin(el);
    return [w / 2 + s * x1, h / 2 - s * sy, depth];
  };
}

function curve(ctx, pts, project, front, back) {
  let prev = null;
  for (const p of pts) {
    const q = project(p);
    if (prev) {
      ctx.strokeStyle = (q[2] + prev[2]) / 2 > 0 ? back : front;
      ctx.beginPath(); ctx.moveTo(prev[0], prev[1]); ctx.lineTo(q[0], q[1]); ctx.stroke();
    }
    prev = q;
  }
}

const loop = (n, f) => Array.from({ length: n + 1 }, (_, i) => f(2 * Math.PI * i / n));

export function drawPolhode(canvas, moments, traj, now) {
  const { ctx, w, h } = prepare(canvas);
  const [I1, I2, I3] = moments;
  const W = traj.omega_body;
  const w0 = W[0];
  const twoE = I1 * w0[0] ** 2 + I2 * w0[1] ** 2 + I3 * w0[2] ** 2; // Landau & Lifshitz §37: Σ I_i Ω_i² = 2E
  if (!(twoE > 0) || !(I1 > 0)) { ctx.fillStyle = INK; ctx.fillText('no rotation to draw', 10, 20); return; }
  const e = [I1, I2, I3].map((I) => Math.sqrt(twoE / I)); // semi-axes of the energy ellipsoid
  const project = projector(w, h, Math.max(...e));
  ctx.lineWidth = 1;
  for (let j = 1; j < 6; j += 1) { // parallels and meridians
    const th = Math.PI * j / 6;
    curve(ctx, loop(72, (f) => [e[0] * Math.sin(th) * Math.cos(f), e[1] * Math.sin(th) * Math.sin(f), e[2] * Math.cos(th)]), project, '#cbd5e1', '#eef2f7');
    const ph = Math.PI * j / 6;
    curve(ctx, loop(72, (f) => [e[0] * Math.sin(f) * Math.cos(ph), e[1] * Math.sin(f) * Math.sin(ph), e[2] * Math.cos(f)]), project, '#cbd5e1', '#eef2f7');
  }
  const distinct = (I2 - I1) > 1e-9 * I3 && (I3 - I2) > 1e-9 * I3;
  if (distinct) {
    // separatrices (2E I2 = M²): the planes Ω3 = ±c Ω1 through the Ω2 axis, c² = I1 (I2 − I1) / (I3 (I3 − I2))
    const c = Math.sqrt(I1 * (I2 - I1) / (I3 * (I3 - I2)));
    const A = Math.sqrt(twoE / (I1 + I3 * c * c)), B = e[1];
    ctx.setLineDash([5, 4]); ctx.lineWidth = 1.3;
    for (const sign of [1, -1]) curve(ctx, loop(120, (f) => [A * Math.cos(f), B * Math.sin(f), sign * c * A * Math.cos(f)]), project, '#6b7280', '#d1d5db');
    ctx.setLineDash([]);
  }
  ctx.fillStyle = INK; ctx.textAlign = 'center'; ctx.textBaseline = 'middle';
  for (let k = 0; k < 3; k += 1) {
    const tip = [0, 0, 0]; tip[k] = e[k] * 1.18;
    const q = project(tip), o = project([0, 0, 0]);
    ctx.strokeStyle = COLORS[k]; ctx.beginPath(); ctx.moveTo(o[0], o[1]); ctx.lineTo(q[0], q[1]); ctx.stroke();
    ctx.fillStyle = COLORS[k]; ctx.fillText(`Ω${k + 1}`, q[0] + 10, q[1] - 6);
  }
  ctx.lineWidth = 2;
  curve(ctx, W, project, '#7c3aed', '#c4b5fd');
  const i = nearest(traj.t, now);
  const q = project(W[i]);
  ctx.fillStyle = '#111827'; ctx.beginPath(); ctx.arc(q[0], q[1], 4.5, 0, 2 * Math.PI); ctx.fill();
}

function nearest(ts, t) {
  let lo = 0, hi = ts.length - 1;
  while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (ts[mid] <= t) lo = mid; else hi = mid; }
  return t - ts[lo] < ts[hi] - t ? lo : hi;
}
