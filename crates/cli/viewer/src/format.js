// Numbers and metric names as the page shows them (docs/viewer.md, "Numbers").

const SUPERSCRIPT = { '-': '⁻', 0: '⁰', 1: '¹', 2: '²', 3: '³', 4: '⁴', 5: '⁵', 6: '⁶', 7: '⁷', 8: '⁸', 9: '⁹' };
const MINUS = '−';

function stripZeros(s) {
  return s.includes('.') ? s.replace(/0+$/, '').replace(/\.$/, '') : s;
}

function group(digits) {
  // Thousands separated by a narrow no-break space from 10 000 on.
  return digits.length > 4 ? digits.replace(/\B(?=(\d{3})+(?!\d))/g, '\u202f') : digits;
}

/**
 * A number as the page writes it:
 * - null or undefined: "—" (not measured);
 * - integers below 10⁹: every digit ("18 000");
 * - 0.001 ≤ |v| < 1000: four significant digits, trailing zeros dropped ("10.27", "0.04389");
 * - 1000 ≤ |v| < 10⁶: rounded to a whole number ("101 325");
 * - otherwise: four significant digits times a power of ten ("9.983 × 10⁻⁵").
 * Negative numbers take a true minus sign (U+2212).
 */
export function formatNumber(v) {
  if (v === null || v === undefined) return '—';
  if (typeof v !== 'number') return String(v);
  if (!Number.isFinite(v)) return Number.isNaN(v) ? 'NaN' : (v > 0 ? '∞' : MINUS + '∞');
  const sign = v < 0 ? MINUS : '';
  const a = Math.abs(v);
  if (Number.isInteger(a) && a < 1e9) return sign + group(String(a));
  if (a >= 1e-3 && a < 1e3) return sign + stripZeros(a.toPrecision(4));
  if (a >= 1e3 && a < 1e6) return sign + group(String(Math.round(a)));
  const [m, e] = a.toExponential(3).split('e');
  const exp = String(Number(e)).split('').map((c) => SUPERSCRIPT[c]).join('');
  return `${sign}${stripZeros(m)} × 10${exp}`;
}

// Unit suffixes of metric names, longest first: suffix → unit as written.
const UNITS = [
  ['_gf_cm2_cm', 'gf·cm²/cm'],
  ['_gf_cm_cm2', 'gf·cm/cm²'],
  ['_gf_cm_cm', 'gf·cm/cm'],
  ['_percent_span', '% of span'],
  ['_m_s', 'm/s'],
  ['_cm2', 'cm²'],
  ['_cm3', 'cm³'],
  ['_m2', 'm²'],
  ['_m3', 'm³'],
  ['_mm', 'mm'],
  ['_cm', 'cm'],
  ['_px', 'px'],
  ['_percent', '%'],
  ['_deg', '°'],
  ['_pa', 'Pa'],
  ['_j', 'J'],
  ['_m', 'm'],
  ['_s', 's'],
];

const WORDS = { emt: 'EMT', lt: 'LT', rt: 'RT', wt: 'WT', rms: 'RMS', b: 'B', dc: 'DC', kes: 'KES' };

/** A metric's readable label and unit, from its name: `drape_coefficient_percent` → "drape coefficient", "%". */
export function metricLabel(name) {
  let base = name;
  let unit = '';
  for (const [suffix, u] of UNITS) {
    if (name.endsWith(suffix) && name.length > suffix.length) {
      base = name.slice(0, -suffix.length);
      unit = u;
      break;
    }
  }
  const label = base
    .replace(/(^|_)two_hb(?=_|$)/, '$12HB')
    .split('_')
    .map((w) => WORDS[w] || w)
    .join(' ');
  return { label, unit };
}

/** A metric's value with its unit: "10.27 %", "0.2506 m", "—" when not measured. */
export function formatMetric(name, value) {
  const { unit } = metricLabel(name);
  const text = formatNumber(value);
  if (value === null || value === undefined || !unit) return text;
  return unit === '°' ? text + unit : `${text} ${unit}`;
}

/** Seconds: "2.458 s". */
export function formatSeconds(s) {
  return s === null || s === undefined ? '—' : `${formatNumber(s)} s`;
}
