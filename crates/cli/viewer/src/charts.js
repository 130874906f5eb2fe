// Small SVG charts drawn by hand (no chart library): the per-stage cost and the wet series.

import { formatNumber } from './format.js';

const NS = 'http://www.w3.org/2000/svg';

/** An SVG element with attributes and children (strings become text nodes). */
export function svg(tag, attrs = {}, children = []) {
  const el = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v !== undefined && v !== null) el.setAttribute(k, String(v));
  }
  for (const c of children) el.append(typeof c === 'string' ? document.createTextNode(c) : c);
  return el;
}

/** Round tick positions covering [lo, hi], about `count` of them. */
export function niceTicks(lo, hi, count = 5) {
  if (!(hi > lo)) {
    const pad = lo === 0 ? 1 : Math.abs(lo) * 0.1;
    lo -= pad;
    hi += pad;
  }
  const raw = (hi - lo) / count;
  const mag = 10 ** Math.floor(Math.log10(raw));
  const norm = raw / mag;
  const step = (norm < 1.5 ? 1 : norm < 3 ? 2 : norm < 7 ? 5 : 10) * mag;
  const start = Math.floor(lo / step + 1e-9) * step;
  const end = Math.ceil(hi / step - 1e-9) * step;
  const ticks = [];
  for (let v = start; v <= end + step * 1e-6; v += step) ticks.push(Math.abs(v) < step * 1e-9 ? 0 : v);
  return { ticks, lo: start, hi: end, step };
}

function tickLabel(v, step) {
  // As many decimals as the step needs, so that ticks read 0.5, 1, 1.5 rather than 0.5000001.
  const decimals = Math.max(0, Math.min(6, -Math.floor(Math.log10(step) + 1e-9)));
  const text = Math.abs(v) >= 1e5 || (v !== 0 && Math.abs(v) < 1e-4) ? formatNumber(v) : v.toFixed(decimals);
  return text.replace('-', '−');
}

/**
 * Horizontal bars: `entries` is [[label, value]], `total` the 100 % of the percentages.
 * Returns an <svg>.
 */
export function barChart(entries, { total, unit = 's', width = 380 } = {}) {
  const rowH = 19;
  const labelW = 92;
  const valueW = 112;
  const barW = width - labelW - valueW - 8;
  const max = Math.max(...entries.map(([, v]) => v), 1e-300);
  const height = entries.length * rowH + 6;
  const root = svg('svg', { viewBox: `0 0 ${width} ${height}`, role: 'img', class: 'bar-chart' });
  entries.forEach(([label, value], i) => {
    const y = 3 + i * rowH;
    const w = Math.max(value > 0 ? 1 : 0, (barW * value) / max);
    const pct = total > 0 ? ` (${formatNumber(Number(((100 * value) / total).toFixed(1)))} %)` : '';
    root.append(
      svg('text', { x: labelW - 6, y: y + 13, 'text-anchor': 'end', 'font-size': 12, fill: '#1d2330' }, [label]),
      svg('rect', { x: labelW, y: y + 3, width: barW, height: rowH - 6, fill: '#eef0f3' }),
      svg('rect', { x: labelW, y: y + 3, width: w, height: rowH - 6, fill: '#2f5fb3' }, [
        svg('title', {}, [`${label}: ${value} ${unit}`]),
      ]),
      svg('text', { x: labelW + barW + 6, y: y + 13, 'font-size': 11.5, fill: '#5b6476' }, [
        `${formatNumber(Number(value.toPrecision(3)))} ${unit}${pct}`,
      ]),
    );
  });
  return root;
}

export const SERIES_COLOURS = ['#2f5fb3', '#d4582b', '#2e8b57', '#8e44ad'];

/**
 * A line chart of one or more series sharing x. `series`: [{ name, points: [[x, y]] }]
 * (non-finite y values break the line). Returns { el, setCursor(x) }.
 */
export function lineChart(series, { title, xLabel = 't (s)', width = 380, height = 180 } = {}) {
  const m = { left: 56, right: 12, top: 26, bottom: 32 };
  const pw = width - m.left - m.right;
  const ph = height - m.top - m.bottom;
  const xs = [];
  const ys = [];
  for (const s of series) {
    for (const [x, y] of s.points) {
      if (Number.isFinite(x)) xs.push(x);
      if (Number.isFinite(y)) ys.push(y);
    }
  }
  const root = svg('svg', { viewBox: `0 0 ${width} ${height}`, role: 'img', class: 'line-chart' });
  root.append(svg('text', { x: m.left, y: 14, 'font-size': 12.5, 'font-weight': 600, fill: '#1d2330' }, [title]));
  if (!xs.length || !ys.length) {
    root.append(svg('text', { x: m.left, y: m.top + ph / 2, 'font-size': 12, fill: '#5b6476' }, ['no values']));
    return { el: root, setCursor() {} };
  }
  const xt = niceTicks(Math.min(...xs), Math.max(...xs), 5);
  const xlo = Math.min(...xs);
  const xhi = Math.max(...xs) > xlo ? Math.max(...xs) : xlo + 1;
  const yt = niceTicks(Math.min(...ys), Math.max(...ys), 4);
  const X = (x) => m.left + ((x - xlo) / (xhi - xlo)) * pw;
  const Y = (y) => m.top + ph - ((y - yt.lo) / (yt.hi - yt.lo)) * ph;
  const axes = svg('g', { 'font-size': 11, fill: '#5b6476' });
  for (const v of yt.ticks) {
    axes.append(
      svg('line', { x1: m.left, x2: m.left + pw, y1: Y(v), y2: Y(v), stroke: '#e3e6eb' }),
      svg('text', { x: m.left - 5, y: Y(v) + 4, 'text-anchor': 'end' }, [tickLabel(v, yt.step)]),
    );
  }
  for (const v of xt.ticks) {
    if (v < xlo - 1e-9 || v > xhi + 1e-9) continue;
    axes.append(
      svg('line', { x1: X(v), x2: X(v), y1: m.top + ph, y2: m.top + ph + 4, stroke: '#8a93a3' }),
      svg('text', { x: X(v), y: m.top + ph + 16, 'text-anchor': 'middle' }, [tickLabel(v, xt.step)]),
    );
  }
  axes.append(
    svg('line', { x1: m.left, x2: m.left + pw, y1: m.top + ph, y2: m.top + ph, stroke: '#8a93a3' }),
    svg('line', { x1: m.left, x2: m.left, y1: m.top, y2: m.top + ph, stroke: '#8a93a3' }),
    svg('text', { x: m.left + pw, y: height - 2, 'text-anchor': 'end' }, [xLabel]),
  );
  root.append(axes);
  series.forEach((s, i) => {
    const colour = SERIES_COLOURS[i % SERIES_COLOURS.length];
    let d = '';
    let pen = false;
    for (const [x, y] of s.points) {
      if (!Number.isFinite(x) || !Number.isFinite(y)) {
        pen = false;
        continue;
      }
      d += `${pen ? 'L' : 'M'}${X(x).toFixed(1)},${Y(y).toFixed(1)}`;
      pen = true;
    }
    root.append(svg('path', { d, fill: 'none', stroke: colour, 'stroke-width': 1.8, 'stroke-linejoin': 'round' }));
    if (series.length > 1 || s.name) {
      const lx = width - m.right - (series.length - i) * 70;
      root.append(
        svg('line', { x1: lx, x2: lx + 14, y1: 10, y2: 10, stroke: colour, 'stroke-width': 2 }),
        svg('text', { x: lx + 18, y: 14, 'font-size': 11.5, fill: '#1d2330' }, [s.name]),
      );
    }
  });
  const cursor = svg('line', {
    x1: m.left, x2: m.left, y1: m.top, y2: m.top + ph, stroke: '#b3261e', 'stroke-width': 1, 'stroke-dasharray': '3 2',
  });
  root.append(cursor);
  return {
    el: root,
    setCursor(x) {
      const inside = Number.isFinite(x) && x >= xlo && x <= xhi;
      cursor.setAttribute('visibility', inside ? 'visible' : 'hidden');
      if (inside) {
        cursor.setAttribute('x1', X(x));
        cursor.setAttribute('x2', X(x));
      }
    },
  };
}
