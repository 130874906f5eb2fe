// The browser test of `atelier view` (docs/viewer.md, "The browser test"), run by ../test.sh.
//
//   node browser.mjs --shots DIR [--chromium PATH] CASE=RUN_DIR ...
//
// CASE is `drape`, `garment`, `wet` (a run folder on which `atelier view` ran), `missing-glb` (one
// whose run.glb was deleted before `atelier view`) or `no-data` (one whose viewer-data.js was
// deleted after). Each page is opened from its file:// URL in headless Chromium (the system's,
// driven by playwright-core) and checked; each check prints one line; the last line counts them.
// Exit status 1 when a check failed.

import { mkdtempSync, readFileSync, rmSync, writeFileSync, mkdirSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { inflateSync } from 'node:zlib';
import { chromium } from 'playwright-core';

// ---------------------------------------------------------------------------------------------
// Arguments.
const args = process.argv.slice(2);
let shots = null;
let executablePath = '/usr/bin/chromium';
const cases = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--shots') shots = resolve(args[++i]);
  else if (args[i] === '--chromium') executablePath = args[++i];
  else {
    const [name, dir] = args[i].split('=');
    cases.push({ name, dir: resolve(dir) });
  }
}
if (!shots || !cases.length) {
  console.error('usage: node browser.mjs --shots DIR [--chromium PATH] CASE=RUN_DIR ...');
  process.exit(1);
}
mkdirSync(shots, { recursive: true });

// ---------------------------------------------------------------------------------------------
// Checks: one line each.
let passed = 0;
let failed = 0;
function check(name, ok, detail) {
  if (ok) passed++;
  else failed++;
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${name}: ${detail}`);
  return ok;
}

// ---------------------------------------------------------------------------------------------
// PNG decoding (8-bit RGB or RGBA, not interlaced: what Chromium's screenshots are), so that the
// pixel statistics need no package beyond node's zlib.
function decodePng(buf) {
  if (buf.readUInt32BE(0) !== 0x89504e47) throw new Error('not a PNG');
  let at = 8;
  let width, height, bitDepth, colourType, interlace;
  const idat = [];
  while (at < buf.length) {
    const len = buf.readUInt32BE(at);
    const type = buf.toString('latin1', at + 4, at + 8);
    const body = buf.subarray(at + 8, at + 8 + len);
    if (type === 'IHDR') {
      width = body.readUInt32BE(0);
      height = body.readUInt32BE(4);
      bitDepth = body[8];
      colourType = body[9];
      interlace = body[12];
    } else if (type === 'IDAT') idat.push(body);
    else if (type === 'IEND') break;
    at += 12 + len;
  }
  if (bitDepth !== 8 || interlace !== 0 || (colourType !== 2 && colourType !== 6)) {
    throw new Error(`unsupported PNG (bit depth ${bitDepth}, colour type ${colourType}, interlace ${interlace})`);
  }
  const bpp = colourType === 6 ? 4 : 3;
  const raw = inflateSync(Buffer.concat(idat));
  const stride = width * bpp;
  const out = Buffer.alloc(width * height * 4);
  let prev = Buffer.alloc(stride);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    const line = Buffer.from(raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1)));
    for (let x = 0; x < stride; x++) {
      const a = x >= bpp ? line[x - bpp] : 0;
      const b = prev[x];
      const c = x >= bpp ? prev[x - bpp] : 0;
      let p;
      switch (filter) {
        case 0: p = 0; break;
        case 1: p = a; break;
        case 2: p = b; break;
        case 3: p = (a + b) >> 1; break;
        case 4: {
          const pa = Math.abs(b - c);
          const pb = Math.abs(a - c);
          const pc = Math.abs(a + b - 2 * c);
          p = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
          break;
        }
        default: throw new Error(`PNG filter ${filter}`);
      }
      line[x] = (line[x] + p) & 255;
    }
    for (let x = 0; x < width; x++) {
      out[4 * (y * width + x)] = line[x * bpp];
      out[4 * (y * width + x) + 1] = line[x * bpp + 1];
      out[4 * (y * width + x) + 2] = line[x * bpp + 2];
      out[4 * (y * width + x) + 3] = bpp === 4 ? line[x * bpp + 3] : 255;
    }
    prev = line;
  }
  return { width, height, data: out };
}

/** Pixel statistics of a screenshot: the background (most frequent colour), distinct colours,
 * the fraction of pixels that are not the background. */
function stats(png) {
  const { data, width, height } = decodePng(png);
  const counts = new Map();
  for (let i = 0; i < data.length; i += 4) {
    const key = (data[i] << 16) | (data[i + 1] << 8) | data[i + 2];
    counts.set(key, (counts.get(key) || 0) + 1);
  }
  let bg = 0;
  let bgCount = 0;
  for (const [k, c] of counts) if (c > bgCount) [bg, bgCount] = [k, c];
  const total = width * height;
  return {
    distinct: counts.size,
    foreground: 1 - bgCount / total,
    background: `#${bg.toString(16).padStart(6, '0')}`,
    width,
    height,
  };
}

/** Fraction of pixels whose colour differs by more than `tol` (any channel) between two shots. */
function difference(a, b, tol = 8) {
  const A = decodePng(a);
  const B = decodePng(b);
  if (A.width !== B.width || A.height !== B.height) return 1;
  let n = 0;
  for (let i = 0; i < A.data.length; i += 4) {
    if (
      Math.abs(A.data[i] - B.data[i]) > tol ||
      Math.abs(A.data[i + 1] - B.data[i + 1]) > tol ||
      Math.abs(A.data[i + 2] - B.data[i + 2]) > tol
    ) n++;
  }
  return n / (A.width * A.height);
}

const pct = (x) => `${(100 * x).toFixed(2)} %`;

// ---------------------------------------------------------------------------------------------
// The page's number format (crates/cli/viewer/src/format.js, formatNumber), for the values the
// test looks for: 0.001 ≤ |v| < 1000 and not whole: four significant digits, trailing zeros
// dropped. Written out again here so that a change of the page's format is caught.
function pageNumber(v) {
  if (Number.isInteger(v)) return String(v);
  if (Math.abs(v) < 1e-3 || Math.abs(v) >= 1e3) throw new Error(`the test formats 0.001 ≤ |v| < 1000 only, not ${v}`);
  const s = Math.abs(v).toPrecision(4);
  return (v < 0 ? '−' : '') + (s.includes('.') ? s.replace(/0+$/, '').replace(/\.$/, '') : s);
}

/** The JSON chunk of a glTF binary. */
function glbJson(path) {
  const b = readFileSync(path);
  const len = b.readUInt32LE(12);
  return JSON.parse(b.toString('utf8', 20, 20 + len));
}

// The vertices of one part (`o NAME`) of an OBJ file as atelier's exporter writes it, flat
// [x, y, z, …]; null when the file or the part is missing.
function objPart(path, name) {
  let text;
  try {
    text = readFileSync(path, 'utf8');
  } catch {
    return null;
  }
  const out = [];
  let inside = false;
  for (const line of text.split('\n')) {
    if (line.startsWith('o ')) {
      if (inside) break;
      inside = line.slice(2).trim() === name;
    } else if (inside && line.startsWith('v ')) {
      const [, x, y, z] = line.trim().split(/\s+/);
      out.push(Number(x), Number(y), Number(z));
    }
  }
  return out.length ? out : null;
}

// The largest distance between corresponding points of two flat [x, y, z, …] arrays.
function largestDistance(a, b) {
  let worst = 0;
  for (let k = 0; k + 2 < Math.min(a.length, b.length); k += 3) {
    worst = Math.max(worst, Math.hypot(a[k] - b[k], a[k + 1] - b[k + 1], a[k + 2] - b[k + 2]));
  }
  return worst;
}

// ---------------------------------------------------------------------------------------------
const userDataDir = mkdtempSync(join(tmpdir(), 'atelier-viewer-test-'));
const context = await chromium.launchPersistentContext(userDataDir, {
  executablePath,
  headless: true,
  viewport: { width: 1280, height: 800 },
  args: [
    '--headless',
    '--no-sandbox',
    '--disable-gpu',
    '--disable-quic',
    '--no-first-run',
    '--disable-background-networking',
    '--disable-component-update',
    '--disable-sync',
    // WebGL without a GPU: ANGLE on SwiftShader (software).
    '--use-angle=swiftshader',
    '--enable-unsafe-swiftshader',
  ],
});

async function open(c) {
  const page = await context.newPage();
  const errors = [];
  // viewer-data.js is absent on purpose in the no-data case: Chromium logs its failed load.
  const expected = (url) => c.name === 'no-data' && url.endsWith('/viewer-data.js');
  page.on('console', (m) => {
    if (m.type() === 'error' && !expected(m.location().url)) errors.push(`console: ${m.text()} (${m.location().url})`);
  });
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  page.on('requestfailed', (r) => {
    if (!expected(r.url())) errors.push(`request failed: ${r.url()}`);
  });
  await page.goto(pathToFileURL(join(c.dir, 'index.html')).href);
  await page.waitForSelector('body[data-viewer]', { timeout: 90_000 });
  const state = await page.evaluate(() => document.body.dataset.viewer);
  return { page, errors, state };
}

const canvasShot = (page) => page.locator('#canvas').screenshot();
const frames = (page) => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));

async function viewChecks(c, page) {
  // The canvas shows something: many colours, and a good part of it not background.
  const shot = await canvasShot(page);
  const s = stats(shot);
  check(
    `${c.name}: canvas not blank`,
    s.distinct > 200 && s.foreground > 0.03,
    `${s.distinct} distinct colours (> 200), ${pct(s.foreground)} of ${s.width}×${s.height} pixels not background ${s.background} (> 3 %)`,
  );
  // The cloth is drawn: hiding it (through its checkbox) changes the picture.
  await page.locator('input[data-part="cloth"]').click();
  await frames(page);
  const hidden = await canvasShot(page);
  await page.locator('input[data-part="cloth"]').click();
  await frames(page);
  const clothPixels = difference(shot, hidden);
  check(`${c.name}: cloth visible`, clothPixels > 0.01, `hiding the cloth changes ${pct(clothPixels)} of the pixels (> 1 %)`);
  // Time: Home and End on the focused slider (the keys a user would press) show the first and
  // the last frame; the garment's pixels differ.
  const slider = page.locator('#time');
  await slider.focus();
  await page.keyboard.press('Home');
  await frames(page);
  const first = await canvasShot(page);
  const firstLabel = await page.locator('#time-label').innerText();
  await page.keyboard.press('End');
  await frames(page);
  const last = await canvasShot(page);
  const lastLabel = await page.locator('#time-label').innerText();
  const moved = difference(first, last);
  // A garment or a drape moves a lot; the wet cloth only round its pinch (2 cm up in 30 cm).
  const least = c.name === 'wet' ? 0.0002 : 0.005;
  check(
    `${c.name}: time slider moves the garment`,
    moved > least && firstLabel !== lastLabel,
    `“${firstLabel}” → “${lastLabel}”: ${pct(moved)} of the pixels change (> ${pct(least)})`,
  );
  // The test hook gives the same frame as the keys.
  const times = await page.evaluate(() => window.atelierViewer.times);
  await page.evaluate((t) => window.atelierViewer.setTime(t), times[0]);
  const hooked = await canvasShot(page);
  const same = difference(first, hooked);
  check(`${c.name}: setTime hook`, same < 0.001, `window.atelierViewer.setTime(${times[0]}) differs from Home on ${pct(same)} of the pixels (< 0.1 %)`);
  // Geometry, not pixels: at the last key time the page's cloth is final.obj's (the exporter's
  // own file, not read from run.glb) to float precision, and over the time line it moves.
  const positions = (t) =>
    page.evaluate(async (t) => {
      await window.atelierViewer.setTime(t);
      return Array.from(window.atelierViewer.viewer.clothPositions());
    }, t);
  const start = await positions(times[0]);
  const end = await positions(times[times.length - 1]);
  const obj = objPart(join(c.dir, 'final.obj'), 'cloth');
  const off = obj ? largestDistance(end, obj) : Infinity;
  check(
    `${c.name}: last frame is final.obj`,
    !!obj && end.length === obj.length && off <= 1e-5,
    obj
      ? `${end.length / 3} cloth vertices on the page, ${obj.length / 3} in final.obj; largest distance ${(off * 1e6).toFixed(2)} µm (≤ 10 µm)`
      : 'final.obj has no cloth part',
  );
  const travel = largestDistance(start, end);
  check(`${c.name}: the cloth moves over the time line`, travel >= 0.005, `largest node travel from the first to the last frame ${(travel * 1000).toFixed(1)} mm (≥ 5 mm)`);
}

async function colourChecks(c, page) {
  const doc = glbJson(join(c.dir, 'run.glb'));
  const clothNode = doc.nodes.findIndex((n) => n.name === 'cloth');
  const mesh = doc.meshes[doc.nodes[clothNode].mesh];
  const hasStrain = !!mesh.extras?.strain_error;
  const hasPanels = mesh.primitives[0].attributes.COLOR_0 !== undefined;
  const initial = await page.locator('#colour').inputValue();
  await page.locator('#colour').selectOption('plain');
  await frames(page);
  const plain = await canvasShot(page);
  for (const [mode, has, what] of [['panel', hasPanels, 'COLOR_0'], ['strain', hasStrain, 'strain_error']]) {
    const disabled = await page.locator(`#colour option[value="${mode}"]`).evaluate((o) => o.disabled);
    if (!has) {
      const note = await page.locator('#colour-note').innerText();
      check(`${c.name}: colour ${mode}`, disabled && note.length > 0, `run.glb has no ${what}: option disabled (${disabled}), note “${note}”`);
      continue;
    }
    await page.locator('#colour').selectOption(mode);
    await frames(page);
    const coloured = await canvasShot(page);
    const legend = await page.locator('#legend').isVisible();
    const changed = difference(plain, coloured);
    check(`${c.name}: colour ${mode}`, !disabled && legend && changed > 0.01, `run.glb has ${what}: ${pct(changed)} of the pixels change (> 1 %), legend shown: ${legend}`);
    if (mode === 'strain') await page.screenshot({ path: join(shots, `${c.name}-strain.png`) });
    await page.locator('#colour').selectOption('plain');
    await frames(page);
  }
  await page.locator('#colour').selectOption(initial);
  await frames(page);
}

for (const c of cases) {
  const t0 = Date.now();
  const { page, errors, state } = await open(c);
  const report = (() => {
    try {
      return JSON.parse(readFileSync(join(c.dir, 'report.json'), 'utf8'));
    } catch {
      return null;
    }
  })();
  if (c.name === 'missing-glb' || c.name === 'no-data') {
    const problems = await page.locator('#problems').innerText();
    const expected = c.name === 'missing-glb' ? 'run.glb is missing' : 'viewer-data.js did not load';
    const visible = await page.locator('#problems').isVisible();
    check(`${c.name}: problem shown`, visible && problems.includes(expected), `state ${state}; the problems box ${visible ? 'shows' : 'does not show'} “${expected}”: ${JSON.stringify(problems.slice(0, 160))}`);
    if (c.name === 'missing-glb') {
      const view = (() => {
        try {
          return readFileSync(`${c.dir}.view`, 'utf8');
        } catch {
          return null;
        }
      })();
      if (view !== null) {
        const [status, ...stderr] = view.split('\n');
        const said = stderr.join(' ').trim();
        check(`${c.name}: atelier view`, status === '2' && said.includes('run.glb is missing'), `exit status ${status} (want 2), stderr “${said}”`);
      }
      const panel = await page.locator('#panel').innerText();
      const name = report?.scenario?.name;
      check(`${c.name}: report still shown`, !!name && panel.includes(name) && /metrics/i.test(panel), `the panel names the scenario “${name}” and lists its metrics`);
    } else {
      const body = (await page.locator('body').innerText()).trim();
      check(`${c.name}: page not blank`, body.length > 100, `${body.length} characters of text`);
    }
    await page.screenshot({ path: join(shots, `${c.name}.png`) });
  } else {
    check(`${c.name}: page ready`, state === 'ready', `state “${state}” after ${((Date.now() - t0) / 1000).toFixed(1)} s`);
    if (state === 'ready') {
      await viewChecks(c, page);
      if (c.name.startsWith('garment')) await colourChecks(c, page);
    }
    if (c.name === 'drape') {
      const dc = report.metrics.drape_coefficient_percent;
      const text = `${pageNumber(dc)} %`;
      const metrics = await page.locator('#metrics').innerText();
      const top = await page.locator('#top-view').innerText();
      check(`${c.name}: drape coefficient`, metrics.includes(text) && top.includes(`DC ${text}`), `report.json's DC ${dc} shown as “${text}” in the metrics and “DC ${text}” in the top view`);
      const nodes = await page.locator('#top-view circle[fill="#d4582b"]').count();
      const want = report.drape?.node_points_m?.length ?? report.metrics.node_count;
      check(`${c.name}: drape nodes`, nodes === want, `${nodes} nodes marked in the top view (report: ${want})`);
      await page.locator('#top-view').scrollIntoViewIfNeeded();
    }
    if (c.name === 'wet') {
      const charts = await page.locator('#series svg.line-chart').count();
      check(`${c.name}: series charts`, charts >= 2, `${charts} charts from series.csv (≥ 2: tent height, pressure)`);
      await page.locator('#series').scrollIntoViewIfNeeded();
    }
    await page.screenshot({ path: join(shots, `${c.name}.png`) });
    if (c.name.startsWith('garment')) {
      // A narrower window: the panel goes below the view, nothing sticks out sideways.
      await page.setViewportSize({ width: 720, height: 1000 });
      await frames(page);
      const overflow = await page.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
      const box = await page.locator('#canvas').boundingBox();
      check(`${c.name}: narrow window`, overflow <= 0 && box.width > 600 && box.height > 300, `at 720×1000: ${overflow} px sideways overflow, view ${Math.round(box.width)}×${Math.round(box.height)}`);
      await page.screenshot({ path: join(shots, `${c.name}-narrow.png`) });
      await page.setViewportSize({ width: 1280, height: 800 });
    }
  }
  check(`${c.name}: no console or page errors`, errors.length === 0, errors.length ? errors.join(' | ') : 'none');
  await page.close();
}

await context.close();
rmSync(userDataDir, { recursive: true, force: true });
writeFileSync(join(shots, 'summary.txt'), `${passed} passed, ${failed} failed\n`);
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
