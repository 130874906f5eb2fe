// The side panel: report.json (docs/report.md) as tables, lists and a cost chart.

import { barChart } from './charts.js';
import { formatMetric, formatNumber, formatSeconds, metricLabel } from './format.js';

/** An HTML element with attributes and children (strings become text). */
export function h(tag, attrs = {}, children = []) {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === null || v === false) continue;
    if (k === 'class') el.className = v;
    else if (k === 'text') el.textContent = v;
    else el.setAttribute(k, v === true ? '' : String(v));
  }
  for (const c of [].concat(children)) {
    if (c === null || c === undefined || c === false) continue;
    el.append(typeof c === 'string' ? document.createTextNode(c) : c);
  }
  return el;
}

export function section(id, title, children) {
  return h('section', { id }, [h('h2', { text: title }), ...children]);
}

function kv(rows) {
  return h(
    'table',
    { class: 'kv' },
    rows
      .filter(([, v]) => v !== undefined && v !== null && v !== '')
      .map(([k, v]) => h('tr', {}, [h('td', { text: k }), h('td', {}, [v])])),
  );
}

/** The run's overall state: { text, cls } for the badge in the top bar. */
export function runStatus(report) {
  if (!report) return { text: 'no report', cls: 'warn' };
  if (report.failure) return { text: 'failed', cls: 'bad' };
  if (report.expectations_met === false) return { text: 'expectation not met', cls: 'bad' };
  const c = report.convergence;
  if (c && c.unconverged_steps > 0) return { text: 'not converged', cls: 'warn' };
  return { text: 'passed', cls: 'ok' };
}

function bounds(e) {
  const { unit } = metricLabel(e.metric);
  const u = unit ? (unit === '°' ? '°' : ` ${unit}`) : '';
  if (e.min !== null && e.min !== undefined && e.max !== null && e.max !== undefined) {
    return `${formatNumber(e.min)} … ${formatNumber(e.max)}${u}`;
  }
  if (e.min !== null && e.min !== undefined) return `≥ ${formatNumber(e.min)}${u}`;
  if (e.max !== null && e.max !== undefined) return `≤ ${formatNumber(e.max)}${u}`;
  return 'any';
}

function convergenceRows(c) {
  const worst = c.worst;
  return [
    ['solver', c.solver],
    ['steps', formatNumber(c.steps)],
    ['unconverged steps', c.unconverged_steps === null ? 'not counted' : formatNumber(c.unconverged_steps)],
    ['shape stage unconverged', c.shape_unconverged_steps === null ? null : formatNumber(c.shape_unconverged_steps)],
    ['largest violation', c.max_violation === null ? null : formatNumber(c.max_violation)],
    ['tolerance', c.tolerance === null ? null : formatNumber(c.tolerance)],
    [
      'worst',
      worst
        ? [
            `${worst.constraint} ${worst.index}`,
            worst.direction ? ` (${worst.direction})` : '',
            ` at ${formatSeconds(worst.time_s)}`,
            worst.phase ? `, ${worst.phase}` : '',
          ].join('')
        : null,
    ],
  ];
}

/**
 * Fill the panel from the report. `extra` = { topView: element|null, series: element|null },
 * placed after the summary. Returns nothing.
 */
export function renderReport(panel, report, extra = {}) {
  panel.replaceChildren();
  if (!report) {
    panel.append(
      section('report-missing', 'Report', [
        h('p', { text: 'No report: report.json is missing or does not read (see the problems above).' }),
      ]),
    );
    if (extra.topView) panel.append(extra.topView);
    if (extra.series) panel.append(extra.series);
    return;
  }
  const sc = report.scenario || {};
  // Summary.
  const status = runStatus(report);
  panel.append(
    section('summary', 'Run', [
      kv([
        ['scenario', h('strong', { text: sc.name || '—' })],
        ['kind', sc.kind],
        ['file', sc.file ? h('code', { text: sc.file }) : null],
        ['fabric', report.fabric],
        ['status', h('span', { class: `status ${status.cls}`, text: status.text })],
        ['simulated', formatSeconds(report.simulated_s)],
        ['steps', report.steps === undefined ? null : `${formatNumber(report.steps)}${report.dt_s ? ` × Δt ${formatSeconds(report.dt_s)}` : ''}`],
        ['wall time', report.wall_s === undefined ? null : `${formatSeconds(report.wall_s)} (setup ${formatSeconds(report.setup_s)}), ${report.threads} thread${report.threads === 1 ? '' : 's'}`],
        ['cloth', report.nodes === undefined ? null : `${formatNumber(report.nodes)} nodes, ${formatNumber(report.triangles)} triangles`],
        ['body', report.body_triangles ? `${formatNumber(report.body_triangles)} triangles` : null],
        ['atelier', report.atelier_version],
      ]),
      sc.reproduces
        ? h('details', { class: 'reproduces' }, [h('summary', { text: 'What it reproduces' }), h('p', { text: sc.reproduces })])
        : null,
    ]),
  );
  // Failure and warnings first: they say how far the numbers below can be trusted.
  if (report.failure) {
    panel.append(section('failure', 'Failure', [h('p', { class: 'failure', text: String(report.failure) })]));
  }
  const expectations = report.expectations || [];
  if (expectations.length) {
    panel.append(
      section('expectations', 'Expectations', [
        h('table', {}, [
          h('tr', {}, [h('th', { text: '' }), h('th', { text: 'metric' }), h('th', { text: 'bounds' }), h('th', { text: 'value' })]),
          ...expectations.map((e) =>
            h('tr', { class: e.met ? '' : 'highlight' }, [
              h('td', { class: e.met ? 'met' : 'unmet', text: e.met ? '✓ met' : '✗ not met' }),
              h('td', { title: e.metric, text: metricLabel(e.metric).label }),
              h('td', { class: 'num', text: bounds(e) }),
              h('td', { class: 'num', text: formatMetric(e.metric, e.value) }),
            ]),
          ),
        ]),
      ]),
    );
  }
  const warnings = report.warnings || [];
  if (warnings.length) {
    panel.append(section('warnings', `Warnings (${warnings.length})`, [h('ul', { class: 'warnings' }, warnings.map((w) => h('li', { text: String(w) })))]));
  }
  if (extra.topView) panel.append(extra.topView);
  if (extra.series) panel.append(extra.series);
  // Metrics.
  const metrics = Object.entries(report.metrics || {});
  if (metrics.length) {
    panel.append(
      section('metrics', 'Metrics', [
        h('table', {}, metrics.map(([name, value]) => {
          const { label } = metricLabel(name);
          return h('tr', { 'data-metric': name }, [
            h('td', { title: name, text: label }),
            h('td', { class: 'num', text: formatMetric(name, value) }),
          ]);
        })),
        h('p', { class: 'note', text: '“—”: not measured. Hover a name for the metric as report.json spells it.' }),
      ]),
    );
  }
  if (report.convergence) {
    panel.append(section('convergence', 'Convergence', [kv(convergenceRows(report.convergence))]));
  }
  const cmp = report.comparison;
  if (cmp) {
    panel.append(
      section('comparison', `Compared run (${cmp.solver})`, [
        kv([
          ['Δt', formatSeconds(cmp.dt_s)],
          ['steps', formatNumber(cmp.steps)],
          ['simulated', formatSeconds(cmp.simulated_s)],
          ['wall time', formatSeconds(cmp.wall_s)],
          ['failure', cmp.failure ? h('span', { class: 'unmet', text: String(cmp.failure) }) : 'none'],
        ]),
      ]),
    );
  }
  // Cost per stage.
  const stages = Object.entries(report.stage_s || {}).filter(([k, v]) => k !== 'total' && typeof v === 'number');
  if (stages.length) {
    const total = typeof report.stage_s.total === 'number' ? report.stage_s.total : stages.reduce((s, [, v]) => s + v, 0);
    panel.append(
      section('cost', 'Cost per stage', [
        barChart(stages, { total }),
        h('p', { class: 'note', text: `Total ${formatSeconds(total)} in the stages; wall time ${formatSeconds(report.wall_s)}.` }),
      ]),
    );
  }
  const outputs = report.outputs || [];
  if (outputs.length) {
    panel.append(
      section('files', 'Files', [
        h('p', { class: 'files' }, outputs.map((f) => h('a', { href: encodeURI(f), target: '_blank', text: f }))),
        h('p', {}, [h('a', { href: 'report.json', target: '_blank', text: 'report.json' })]),
      ]),
    );
  }
}
