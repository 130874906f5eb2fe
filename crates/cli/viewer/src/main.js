// The page of `atelier view` (docs/viewer.md): window.ATELIER_RUN (viewer-data.js) shown as a
// 3-D view with a time line and a side panel from the report. Built into one classic script
// (viewer.js) by build.sh, so that the page works from file:// without a server.

import { lineChart, SERIES_COLOURS } from './charts.js';
import { formatNumber, metricLabel } from './format.js';
import { h, renderReport, runStatus, section } from './report.js';
import { decodeBase64, rampCss, Viewer } from './scene.js';
import { drapeFromMesh, topView } from './topview.js';

const $ = (id) => document.getElementById(id);

// The test hook (docs/viewer.md, "The browser test"): state, time and colour mode from outside.
const api = {
  state: 'starting', // then 'ready', 'no-glb', 'no-webgl' or 'error'
  ready: false,
  problems: [],
  times: [],
  time: null,
};
window.atelierViewer = api;

const problems = [];
function showProblems() {
  const box = $('problems');
  api.problems = problems.slice();
  if (!problems.length) {
    box.replaceChildren();
    return;
  }
  box.replaceChildren(
    h('h2', { text: problems.length === 1 ? 'A problem with this run folder' : `${problems.length} problems with this run folder` }),
    h('ul', {}, problems.map((p) => h('li', { text: p }))),
  );
}
function addProblem(text) {
  if (!problems.includes(text)) problems.push(text);
  showProblems();
}

function finish(state) {
  api.state = state;
  api.ready = true;
  document.body.dataset.viewer = state;
}

// Anything unexpected still ends up on the page, never in a silent blank one.
window.addEventListener('error', (e) => addProblem(`The page hit an error: ${e.message}`));
window.addEventListener('unhandledrejection', (e) => addProblem(`The page hit an error: ${e.reason?.message || e.reason}`));

/** series.csv → { columns, bySolver: Map(solver → rows of numbers by column) }. */
function parseSeries(text) {
  const lines = text.split(/\r?\n/).filter((l) => l.trim());
  if (lines.length < 2) return null;
  const columns = lines[0].split(',').map((c) => c.trim());
  const bySolver = new Map();
  for (const line of lines.slice(1)) {
    const cells = line.split(',');
    const solver = columns[0] === 'solver' ? cells[0] : 'run';
    const row = {};
    columns.forEach((c, i) => {
      const v = cells[i] === undefined || cells[i].trim() === '' ? NaN : Number(cells[i]);
      row[c] = v;
    });
    if (!bySolver.has(solver)) bySolver.set(solver, []);
    bySolver.get(solver).push(row);
  }
  return { columns, bySolver };
}

const SERIES_CHARTS = ['tent_height_mm', 'pressure_difference_pa', 'lifted_area_cm2', 'volume_cm3'];

function seriesSection(text) {
  const parsed = parseSeries(text);
  if (!parsed) return { el: section('series', 'Series', [h('p', { text: 'series.csv holds no rows.' })]), charts: [] };
  const charts = [];
  const els = [];
  for (const column of SERIES_CHARTS.filter((c) => parsed.columns.includes(c))) {
    let { label, unit } = metricLabel(column);
    let scale = 1;
    const values = [...parsed.bySolver.values()].flat().map((r) => r[column]).filter(Number.isFinite);
    if (!values.length) continue;
    if (unit === 'Pa' && Math.max(...values.map(Math.abs)) >= 1e4) {
      scale = 1e-3;
      unit = 'kPa';
    }
    if (column === 'pressure_difference_pa') label = 'P_b − P_a';
    const series = [...parsed.bySolver.entries()].map(([solver, rows]) => ({
      name: solver,
      points: rows.map((r) => [r.time_s, r[column] * scale]),
    }));
    const chart = lineChart(series, { title: `${label} (${unit})` });
    charts.push(chart);
    els.push(chart.el);
  }
  const solvers = [...parsed.bySolver.keys()];
  const note = h('p', { class: 'note' }, [
    `From series.csv, one row every sample of each run (${solvers.map((s, i) => `${s}: ${parsed.bySolver.get(s).length} rows`).join(', ')}); `,
    'the dashed line is the time shown in the 3-D view (the main run: ',
    h('span', { style: `color:${SERIES_COLOURS[0]}`, text: solvers[0] }),
    ').',
  ]);
  return { el: section('series', 'Series', [...els, note]), charts };
}

function start() {
  const data = window.ATELIER_RUN;
  if (data === undefined) {
    addProblem(
      'viewer-data.js did not load, so this page has no run to show: it is written by `atelier view DIR` beside index.html (run that command on the run folder again).',
    );
  } else if (!data || typeof data !== 'object') {
    addProblem('viewer-data.js does not hold a run (window.ATELIER_RUN is not an object).');
  }
  const run = data && typeof data === 'object' ? data : {};
  for (const p of Array.isArray(run.problems) ? run.problems : []) addProblem(String(p));
  showProblems();

  const report = run.report && typeof run.report === 'object' ? run.report : null;
  const kind = report?.scenario?.kind;
  const name = report?.scenario?.name;
  document.title = name ? `${name} · atelier` : 'atelier run';
  $('run-title').textContent = name || 'atelier run';
  $('run-subtitle').textContent = [kind, report?.fabric].filter(Boolean).join(' · ');
  const status = runStatus(report);
  $('run-status').textContent = report ? status.text : '';
  $('run-status').className = `status ${status.cls}`;

  // Panel: the report, with the top view (drape) and the series (wet) filled in as they come.
  const dc = report?.metrics?.drape_coefficient_percent;
  const isDrape = kind === 'Drape' || !!report?.drape;
  const topSection = isDrape
    ? section('top-view', 'Top view', [h('p', { class: 'note', text: 'Waiting for run.glb…' })])
    : null;
  let series = null;
  if (typeof run.series === 'string' && (kind === 'Wet' || !report)) series = seriesSection(run.series);
  renderReport($('panel'), report, { topView: topSection, series: series?.el });

  const drawTop = (viewer) => {
    if (!topSection) return;
    const d = report?.drape;
    let drape = null;
    let shadow = null;
    let source;
    const cloth = viewer?.cloth;
    if (viewer) {
      viewer.setTime(viewer.t1);
      const support = viewer.parts.find((p) => !p.cloth);
      const mesh = drapeFromMesh({
        base: cloth.base,
        final: viewer.clothPositions(),
        index: cloth.geometry.index.array,
        support: support ? support.geometry.attributes.position.array : null,
        nodeCount: Number.isInteger(report?.metrics?.node_count) ? report.metrics.node_count : null,
      });
      drape = mesh;
      shadow = { positions: viewer.clothPositions(), index: cloth.geometry.index.array, centre: mesh.centre };
      source = 'outline and nodes from the last frame';
    }
    if (d && Array.isArray(d.outline_m)) {
      drape = {
        outline: d.outline_m,
        nodes: Array.isArray(d.node_points_m) ? d.node_points_m : [],
        support: d.support_radius_m ?? drape?.support ?? null,
        specimen: d.specimen_radius_m ?? drape?.specimen ?? null,
      };
      if (shadow) shadow.centre = [0, 0];
      source = 'outline and nodes from the report';
    }
    if (!drape) {
      topSection.replaceChildren(h('h2', { text: 'Top view' }), h('p', { text: 'No top view: the report has no drape outline and run.glb could not be shown.' }));
      return;
    }
    topSection.replaceChildren(
      h('h2', { text: 'Top view' }),
      topView(drape, { shadow, dc, source }),
      h('p', { class: 'note', text: 'The final shadow (filled), its outline, the nodes (numbered), the support (grey disc) and the flat specimen (dashed).' }),
    );
  };

  // The 3-D view.
  const message = (html) => {
    const el = $('view-message');
    el.replaceChildren(...html);
    el.hidden = false;
  };
  // Without a 3-D view: say why, and show the run's own picture (final.png) when it has one.
  const noView = (why) => {
    const picture = (report?.outputs || []).includes('final.png')
      ? h('img', { src: 'final.png', alt: 'final.png: the final state from the front and the side' })
      : null;
    if (picture) picture.addEventListener('error', () => picture.remove());
    message([
      h('div', {}, [
        h('strong', { text: 'No 3-D view' }),
        h('br'),
        why,
        picture ? h('br') : null,
        picture ? h('span', { class: 'note', text: 'Below: final.png, the picture the run wrote.' }) : null,
        picture,
      ]),
    ]);
  };
  if (typeof run.glb !== 'string' || !run.glb) {
    noView(
      data === undefined
        ? 'This page has no run: viewer-data.js did not load (see the problem above).'
        : 'This page was given no run.glb (see the problems above); the report is in the panel.',
    );
    drawTop(null);
    finish('no-glb');
    return;
  }
  let viewer;
  try {
    viewer = new Viewer($('canvas'), { onRender: () => series?.charts.forEach((c) => c.setCursor(viewer.time)) });
  } catch (e) {
    addProblem(`WebGL is not available in this browser, so there is no 3-D view: ${e.message || e}`);
    noView('WebGL is not available in this browser.');
    drawTop(null);
    finish('no-webgl');
    return;
  }
  const view = $('view');
  viewer.resize(view.clientWidth, view.clientHeight);
  new ResizeObserver(() => viewer.resize(view.clientWidth, view.clientHeight)).observe(view);
  message([h('div', { text: 'Loading run.glb…' })]);

  let buffer;
  try {
    buffer = decodeBase64(run.glb);
  } catch (e) {
    buffer = null;
    addProblem(`run.glb could not be shown: its base64 text in viewer-data.js does not decode (${e.message || e})`);
  }
  const loading = buffer ? viewer.load(buffer, { kind }) : Promise.reject(null);
  loading.then(
    () => {
      $('view-message').hidden = true;
      setUpControls(viewer);
      drawTop(viewer);
      viewer.setTime(viewer.t1);
      api.viewer = viewer;
      requestAnimationFrame(() => requestAnimationFrame(() => finish('ready')));
    },
    (e) => {
      if (e) addProblem(`run.glb could not be shown: ${e.message || e}`);
      noView('run.glb could not be read (see the problems above).');
      drawTop(null);
      finish('error');
    },
  );
}

function setUpControls(viewer) {
  $('controls').hidden = false;
  $('view-buttons').hidden = false;
  const slider = $('time');
  const label = $('time-label');
  const playButton = $('play');
  const frames = viewer.frameTimes;
  const animated = frames.length > 1;
  slider.min = String(viewer.t0);
  slider.max = String(viewer.t1);
  slider.disabled = !animated;
  for (const id of ['play', 'prev', 'next', 'speed', 'loop']) $(id).disabled = !animated;
  api.times = frames.slice();

  const digits = viewer.t1 - viewer.t0 < 10 ? 3 : 2;
  let onTime = () => {};
  const update = () => {
    onTime();
    const t = viewer.time;
    api.time = t;
    slider.value = String(t);
    let where = '';
    if (animated) {
      const k = frames.findIndex((f) => Math.abs(f - t) <= 1e-6 * Math.max(1, Math.abs(f)));
      if (k >= 0) where = `frame ${k + 1} of ${frames.length}`;
      else {
        const next = frames.findIndex((f) => f > t);
        where = `frames ${next}–${next + 1} of ${frames.length}`;
      }
    }
    label.textContent = animated
      ? `t = ${t.toFixed(digits)} / ${viewer.t1.toFixed(digits)} s · ${where}`
      : 'a single frame (no motion in run.glb)';
  };

  // Playback.
  let playing = false;
  let last = null;
  const setPlaying = (on) => {
    playing = on && animated;
    playButton.innerHTML = playing ? '&#10074;&#10074;' : '&#9654;';
    playButton.setAttribute('aria-label', playing ? 'Pause' : 'Play');
    last = null;
    if (playing) requestAnimationFrame(tick);
  };
  const tick = (now) => {
    if (!playing) return;
    if (last !== null) {
      const speed = Number($('speed').value) || 1;
      let t = viewer.time + ((now - last) / 1000) * speed;
      if (t > viewer.t1) {
        if ($('loop').checked) t = viewer.t0 + ((t - viewer.t0) % (viewer.t1 - viewer.t0 || 1));
        else {
          t = viewer.t1;
          setPlaying(false);
        }
      }
      viewer.setTime(t);
      update();
    }
    last = now;
    if (playing) requestAnimationFrame(tick);
  };
  playButton.addEventListener('click', () => {
    if (!playing && viewer.time >= viewer.t1) viewer.setTime(viewer.t0);
    setPlaying(!playing);
  });
  const goto = (t) => {
    setPlaying(false);
    viewer.setTime(t);
    update();
  };
  const step = (dir) => {
    const t = viewer.time;
    const eps = 1e-9 * Math.max(1, Math.abs(t));
    const target = dir > 0 ? frames.find((f) => f > t + eps) : [...frames].reverse().find((f) => f < t - eps);
    goto(target ?? (dir > 0 ? viewer.t1 : viewer.t0));
  };
  slider.addEventListener('input', () => goto(Number(slider.value)));
  $('prev').addEventListener('click', () => step(-1));
  $('next').addEventListener('click', () => step(1));
  document.addEventListener('keydown', (e) => {
    const tag = e.target?.tagName;
    if (tag === 'SELECT' || (tag === 'INPUT' && e.target.type !== 'range')) return;
    if (e.key === ' ' && tag !== 'BUTTON') {
      e.preventDefault();
      playButton.click();
    } else if (e.key === 'ArrowRight' || e.key === 'ArrowLeft') {
      e.preventDefault();
      step(e.key === 'ArrowRight' ? 1 : -1);
    } else if ((e.key === 'Home' || e.key === 'End') && tag !== 'INPUT') {
      e.preventDefault();
      goto(e.key === 'Home' ? viewer.t0 : viewer.t1);
    }
  });

  // Parts.
  const toggles = $('part-toggles');
  toggles.replaceChildren(
    ...viewer.parts.map((part) => {
      const box = h('input', { type: 'checkbox', checked: true, 'data-part': part.name });
      box.addEventListener('change', () => viewer.setVisible(part, box.checked));
      return h('label', { title: part.cloth ? 'Show the cloth' : `Show the ${part.name}` }, [box, ` ${part.name}`]);
    }),
  );
  const grid = $('grid');
  grid.parentElement.lastChild.textContent = ` floor grid (${viewer.gridStep >= 1 ? `${viewer.gridStep} m` : `${formatNumber(viewer.gridStep * 100)} cm`})`;
  grid.addEventListener('change', () => viewer.setGrid(grid.checked));

  // Cloth colour.
  const select = $('colour');
  const note = $('colour-note');
  const available = viewer.colourAvailability();
  const notes = [];
  for (const option of select.options) {
    const why = available[option.value];
    option.disabled = !!why;
    if (why) {
      option.textContent = `${option.value === 'panel' ? 'by panel' : 'by strain error'} (not in this run)`;
      notes.push(why);
    }
  }
  const missing = ['panel', 'strain'].filter((m) => available[m]).map((m) => (m === 'panel' ? 'panel colours' : 'strain error'));
  note.textContent = missing.length ? `${missing.join(' and ')}: not in this run.glb` : '';
  note.title = notes.join('; ');
  const legend = $('legend');
  const pct = (v) => `${formatNumber(Number((100 * v).toPrecision(3)))} %`;
  const ticks = h('div', { class: 'ticks' });
  const updateTicks = () => {
    const top = viewer.strainTop;
    if (viewer.colourMode === 'strain' && top > 0) {
      ticks.replaceChildren(h('span', { text: '0' }), h('span', { text: pct(top / 2) }), h('span', { text: pct(top) }));
    }
  };
  const scaleSelect = h('select', { id: 'strain-scale', title: 'What the top of the ramp is' }, [
    h('option', { value: 'frame', text: 'this frame' }),
    h('option', { value: 'run', text: `the whole run (${viewer.cloth.strain ? pct(viewer.cloth.strain.max) : '—'})` }),
  ]);
  scaleSelect.addEventListener('change', () => {
    viewer.setStrainScale(scaleSelect.value);
    updateTicks();
  });
  onTime = updateTicks;
  const showLegend = () => {
    const mode = viewer.colourMode;
    if (mode === 'strain') {
      scaleSelect.value = viewer.strainScale;
      legend.replaceChildren(
        h('div', { text: 'Largest edge strain error at each vertex' }),
        h('div', { class: 'ramp', style: `background:${rampCss()}` }),
        ticks,
        h('label', { class: 'note' }, ['scale to the largest value of ', scaleSelect]),
      );
      updateTicks();
      legend.hidden = false;
    } else if (mode === 'panel') {
      legend.replaceChildren(
        h('div', { text: 'Panels' }),
        h('div', { class: 'swatches' }, viewer.panelLegend().map(({ name, colour }) =>
          h('span', {}, [colour ? h('span', { class: 'swatch', style: `background:${colour}` }) : null, name]))),
      );
      legend.hidden = false;
    } else legend.hidden = true;
  };
  const setMode = (mode) => {
    viewer.setColourMode(mode);
    select.value = viewer.colourMode;
    showLegend();
  };
  select.addEventListener('change', () => setMode(select.value));
  // Start with the most telling colours the run has: its panels when it has them, else plain.
  setMode(available.panel === null ? 'panel' : 'plain');

  for (const b of document.querySelectorAll('#view-buttons button')) {
    b.addEventListener('click', () => viewer.view(b.dataset.view));
  }

  Object.assign(api, {
    /** Show time t (s), paused; resolves once the frame is drawn. */
    setTime(t) {
      goto(t);
      return new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
    },
    getTime: () => viewer.time,
    play: () => setPlaying(true),
    pause: () => setPlaying(false),
    setColourMode: (mode) => setMode(mode),
    colourModes: () => ({ ...available }),
  });
  update();
}

start();
