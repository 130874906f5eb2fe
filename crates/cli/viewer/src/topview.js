// The drape test seen from above: the shadow, its outline, the nodes, the support and the
// specimen's circle, in the horizontal (x, z) plane of the y-up frame (x right, z down).

import { svg } from './charts.js';
import { formatNumber } from './format.js';

/**
 * The drape geometry from the cloth's positions (when the report has no `drape` object):
 * outline = the outer boundary loop of the cloth's triangles (the rim) projected on x–z; nodes =
 * the rim's radial maxima (as many as the report's `node_count` when given); specimen radius = the
 * largest radius of the first frame (the flat specimen); support radius = the largest horizontal
 * radius of the support's vertices.
 */
export function drapeFromMesh({ base, final, index, support, nodeCount }) {
  const n = final.length / 3;
  // Centre: the support's (else the flat specimen's) horizontal centre.
  const centreOf = (p) => {
    let x0 = Infinity, x1 = -Infinity, z0 = Infinity, z1 = -Infinity;
    for (let i = 0; i < p.length; i += 3) {
      x0 = Math.min(x0, p[i]); x1 = Math.max(x1, p[i]);
      z0 = Math.min(z0, p[i + 2]); z1 = Math.max(z1, p[i + 2]);
    }
    return [(x0 + x1) / 2, (z0 + z1) / 2];
  };
  const [cx, cz] = centreOf(support && support.length ? support : base);
  const radius = (p, i) => Math.hypot(p[3 * i] - cx, p[3 * i + 2] - cz);
  let specimen = 0;
  for (let i = 0; i < n; i++) specimen = Math.max(specimen, radius(base, i));
  let supportR = null;
  if (support && support.length) {
    supportR = 0;
    for (let i = 0; i < support.length / 3; i++) supportR = Math.max(supportR, radius(support, i));
  }
  // Boundary edges (used by one triangle), chained into loops.
  const uses = new Map();
  const key = (a, b) => (a < b ? a * n + b : b * n + a);
  for (let t = 0; t < index.length; t += 3) {
    for (const [a, b] of [[index[t], index[t + 1]], [index[t + 1], index[t + 2]], [index[t + 2], index[t]]]) {
      const k = key(a, b);
      uses.set(k, (uses.get(k) || 0) + 1);
    }
  }
  const next = new Map();
  for (const [k, c] of uses) {
    if (c !== 1) continue;
    const a = Math.floor(k / n);
    const b = k % n;
    if (!next.has(a)) next.set(a, []);
    if (!next.has(b)) next.set(b, []);
    next.get(a).push(b);
    next.get(b).push(a);
  }
  const seen = new Set();
  let best = null;
  for (const start of next.keys()) {
    if (seen.has(start)) continue;
    const loop = [start];
    seen.add(start);
    let prev = -1;
    let cur = start;
    for (;;) {
      const cand = (next.get(cur) || []).find((v) => v !== prev && !seen.has(v));
      if (cand === undefined) break;
      loop.push(cand);
      seen.add(cand);
      prev = cur;
      cur = cand;
    }
    const mean = loop.reduce((s, i) => s + radius(base, i), 0) / loop.length;
    if (loop.length >= 3 && (!best || mean > best.mean)) best = { loop, mean };
  }
  const loop = best ? best.loop : [];
  const outline = loop.map((i) => [final[3 * i] - cx, final[3 * i + 2] - cz]);
  // Nodes: local maxima of the (lightly smoothed) rim radius, most prominent first.
  const m = outline.length;
  const r = outline.map(([x, z]) => Math.hypot(x, z));
  const rs = r.map((_, i) => (r[(i - 1 + m) % m] + 2 * r[i] + r[(i + 1) % m]) / 4);
  const w = Math.max(2, Math.round(m / 36));
  const reach = Math.max(w, Math.round(m / 8));
  const peaks = [];
  for (let i = 0; i < m; i++) {
    let top = true;
    for (let d = 1; d <= w && top; d++) top = rs[i] >= rs[(i + d) % m] && rs[i] > rs[(i - d + m) % m];
    if (!top) continue;
    let low = rs[i];
    for (let d = 1; d <= reach; d++) low = Math.min(low, rs[(i + d) % m], rs[(i - d + m) % m]);
    peaks.push({ i, prominence: rs[i] - low });
  }
  peaks.sort((a, b) => b.prominence - a.prominence);
  const wanted = Number.isInteger(nodeCount) && nodeCount > 0 ? nodeCount : peaks.filter((p) => p.prominence > 0.02 * specimen).length;
  // Numbered round the rim from +x towards +z (clockwise as seen from above).
  const angle = ([x, z]) => (Math.atan2(z, x) + 2 * Math.PI) % (2 * Math.PI);
  const nodes = peaks.slice(0, wanted).map((p) => outline[p.i]).sort((a, b) => angle(a) - angle(b));
  return {
    outline,
    nodes,
    support: supportR,
    specimen,
    centre: [cx, cz],
  };
}

/**
 * The top view as an <svg>: `drape` = { outline, nodes, support, specimen } (metres, centred),
 * `shadow` = optional { positions, index, centre } to fill the projected cloth, `dc` = the drape
 * coefficient (%) or null.
 */
export function topView(drape, { shadow, dc, source } = {}) {
  const size = 380;
  const R = Math.max(
    drape.specimen || 0,
    ...drape.outline.map(([x, z]) => Math.hypot(x, z)),
    drape.support || 0,
    1e-3,
  ) * 1.06;
  const s = (size / 2 - 6) / R;
  const X = (x) => size / 2 + x * s;
  const Z = (z) => size / 2 + z * s;
  const root = svg('svg', { viewBox: `0 0 ${size} ${size + 24}`, role: 'img', class: 'top-view', 'aria-label': 'drape seen from above' });
  root.append(svg('rect', { x: 0, y: 0, width: size, height: size, fill: '#f7f8fa', stroke: '#d8dce3' }));
  if (drape.specimen) {
    root.append(svg('circle', { cx: X(0), cy: Z(0), r: drape.specimen * s, fill: 'none', stroke: '#8a93a3', 'stroke-dasharray': '5 4' }));
  }
  if (shadow) {
    const g = svg('g', { opacity: 0.32, fill: '#2f5fb3' });
    const p = shadow.positions;
    const [cx, cz] = shadow.centre;
    let d = '';
    for (let t = 0; t < shadow.index.length; t += 3) {
      const [a, b, c] = [shadow.index[t], shadow.index[t + 1], shadow.index[t + 2]];
      d += `M${X(p[3 * a] - cx).toFixed(1)},${Z(p[3 * a + 2] - cz).toFixed(1)}L${X(p[3 * b] - cx).toFixed(1)},${Z(p[3 * b + 2] - cz).toFixed(1)}L${X(p[3 * c] - cx).toFixed(1)},${Z(p[3 * c + 2] - cz).toFixed(1)}Z`;
    }
    g.append(svg('path', { d, stroke: '#2f5fb3', 'stroke-width': 0.6, 'stroke-linejoin': 'round' }));
    root.append(g);
  }
  if (drape.outline.length) {
    const d = drape.outline.map(([x, z], i) => `${i ? 'L' : 'M'}${X(x).toFixed(1)},${Z(z).toFixed(1)}`).join('') + 'Z';
    root.append(svg('path', { d, fill: shadow ? 'none' : 'rgba(47,95,179,0.3)', stroke: '#1f3f7a', 'stroke-width': 1.6 }));
  }
  if (drape.support) {
    root.append(svg('circle', { cx: X(0), cy: Z(0), r: drape.support * s, fill: '#9aa3b2', stroke: '#5b6476' }));
  }
  drape.nodes.forEach(([x, z], i) => {
    const r = Math.hypot(x, z) || 1;
    root.append(
      svg('circle', { cx: X(x), cy: Z(z), r: 5, fill: '#d4582b', stroke: '#fff', 'stroke-width': 1.5 }),
      svg('text', {
        x: X(x + (x / r) * 14 / s), y: Z(z + (z / r) * 14 / s) + 4, 'text-anchor': 'middle', 'font-size': 11, fill: '#8f3416',
      }, [String(i + 1)]),
    );
  });
  // Scale bar and axes.
  const bar = 10 ** Math.floor(Math.log10(R));
  const barPx = bar * s;
  root.append(
    svg('line', { x1: 10, x2: 10 + barPx, y1: size - 12, y2: size - 12, stroke: '#1d2330', 'stroke-width': 2 }),
    svg('text', { x: 10, y: size - 17, 'font-size': 11, fill: '#1d2330' }, [bar >= 1 ? `${bar} m` : `${formatNumber(bar * 100)} cm`]),
    svg('text', { x: size - 8, y: size - 8, 'text-anchor': 'end', 'font-size': 11, fill: '#5b6476' }, ['x →   z ↓   (from above)']),
  );
  const caption = [
    dc === null || dc === undefined ? null : `DC ${formatNumber(dc)} %`,
    `${drape.nodes.length} node${drape.nodes.length === 1 ? '' : 's'}`,
    source,
  ].filter(Boolean).join(' · ');
  root.append(svg('text', { x: 2, y: size + 17, 'font-size': 12, fill: '#1d2330' }, [caption]));
  return root;
}
