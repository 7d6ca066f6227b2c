// The scope (docs/instrument-page.md, "Scope"): the signals chosen, on a time base from 1 ms to
// 1 min a division; zoom and pan; pause; a trigger in normal or single-shot mode with a pre-trigger
// fraction; two cursors and their difference; export of the view as CSV and PNG; and the spans the
// page missed, shown rather than hidden.
import { el, page, serverNow, stateLabel } from './page.js';
import { DRAWN_CYCLES, catalogue, edges, levelSignals, series, store, valueAt } from './scope_data.js';
import { COLOURS, DASHES, drawScope, formatSpan } from './scope_draw.js';
import { acquisition } from './scope_trigger.js';

// Time per division (ms); the view is ten divisions.
const DIVS = [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10000, 20000, 30000, 60000];
const DEFAULT_SHOWN = ['v', 'sp', 'tq', 'state'];

const scope = {
  signals: [],
  shown: new Set(DEFAULT_SHOWN),
  div: 1000,
  t0: null,          // the window's left edge when the user placed it (pan, zoom, pause); else null
  paused: false,
  showTransitions: true,
  cursors: { a: null, b: null },
  acq: new acquisition(),
  window: { t0: 0, t1: 0 },
  mapping: null,
};

const span = () => scope.div * 10;
const cycleMs = () => ((page.info && page.info.cycle_us) || 1000) / 1000;

function option(parent, value, text) {
  const o = document.createElement('option');
  o.value = String(value);
  o.textContent = text;
  parent.appendChild(o);
  return o;
}

// --- building ----------------------------------------------------------------------------------

export function buildScope() {
  scope.signals = catalogue();
  const div = el('scope-div');
  for (const d of DIVS) option(div, d, `${formatSpan(d)}/div`).selected = d === scope.div;
  div.addEventListener('change', () => zoomTo(Number(div.value)));
  buildSignalChoice();
  buildTrigger();
  el('scope-zoom-in').addEventListener('click', () => zoomStep(-1));
  el('scope-zoom-out').addEventListener('click', () => zoomStep(1));
  el('scope-left').addEventListener('click', () => pan(-0.5));
  el('scope-right').addEventListener('click', () => pan(0.5));
  el('scope-pause').addEventListener('click', () => setPaused(!scope.paused));
  el('scope-live').addEventListener('click', () => { scope.t0 = null; setPaused(false); });
  el('scope-csv').addEventListener('click', exportCsv);
  el('scope-png').addEventListener('click', exportPng);
  for (const [id, cursor, dir] of [['cur-a-prev', 'a', -1], ['cur-a-next', 'a', 1],
    ['cur-b-prev', 'b', -1], ['cur-b-next', 'b', 1]]) {
    el(id).addEventListener('click', () => jumpCursor(cursor, dir));
  }
  el('cur-clear').addEventListener('click', () => { scope.cursors = { a: null, b: null }; });
  buildPointer(el('plot'));
}

function buildSignalChoice() {
  const box = el('scope-signals');
  box.textContent = '';
  const groups = [
    ['Values', (s) => (s.kind === 'analog' || s.kind === 'setpoint' || s.key === 'mode') && !s.part],
    ['State', (s) => s.kind === 'state'],
    ['Objects', (s) => s.key.startsWith('obj')],
    [`${page.info.control_word_name} bits`, (s) => s.kind === 'bit' && s.key.startsWith('cw')],
    [`${page.info.status_word_name} bits`, (s) => s.kind === 'bit' && s.key.startsWith('sw')],
    ['Inputs 0x60FD', (s) => s.kind === 'bit' && s.key.startsWith('di')],
  ];
  for (const [title, pick] of groups) {
    const fs = document.createElement('fieldset');
    const legend = document.createElement('legend');
    legend.textContent = title;
    fs.appendChild(legend);
    for (const sig of scope.signals.filter(pick)) fs.appendChild(checkbox(sig.key, sig.label));
    if (title === 'State') {
      const t = checkbox('transitions', 'transitions (numbered lines)');
      t.querySelector('input').checked = scope.showTransitions;
      fs.appendChild(t);
    }
    box.appendChild(fs);
  }
  box.addEventListener('change', (e) => {
    const key = e.target.dataset.signal;
    if (!key) return;
    if (key === 'transitions') scope.showTransitions = e.target.checked;
    else if (e.target.checked) scope.shown.add(key);
    else scope.shown.delete(key);
  });
}

function checkbox(key, text) {
  const l = document.createElement('label');
  l.className = 'scope-signal';
  const c = document.createElement('input');
  c.type = 'checkbox';
  c.dataset.signal = key;
  c.checked = scope.shown.has(key);
  l.append(c, document.createTextNode(` ${text}`));
  return l;
}

function buildTrigger() {
  const info = page.info;
  const numbers = [...new Set(info.rows.map((r) => r.number))].sort((a, b) => a - b);
  for (const n of numbers) option(el('trig-transition'), n, `transition ${n}`);
  for (const s of info.states.filter((x) => x !== 'START')) option(el('trig-state'), s, stateLabel(s));
  for (const sig of scope.signals.filter((s) => s.kind === 'bit')) option(el('trig-bit'), sig.key, sig.label);
  for (const sig of levelSignals(scope.signals)) option(el('trig-signal'), sig.key, sig.label);
  const showFields = () => {
    const type = el('trig-type').value;
    el('trig-transition').hidden = type !== 'transition';
    el('trig-state').hidden = type !== 'state';
    el('trig-bit').hidden = type !== 'bit';
    for (const id of ['trig-signal', 'trig-level-wrap']) el(id).hidden = type !== 'level';
    el('trig-edge').hidden = type !== 'bit' && type !== 'level';
  };
  el('trig-type').addEventListener('change', showFields);
  showFields();
  el('trig-arm').addEventListener('click', arm);
  el('trig-mode').addEventListener('change', arm);
}

// The trigger condition the inputs describe.
function condition() {
  const type = el('trig-type').value;
  const edge = el('trig-edge').value;
  if (type === 'transition') return { type, number: Number(el('trig-transition').value) };
  if (type === 'state') return { type, state: el('trig-state').value };
  if (type === 'bit') {
    const key = el('trig-bit').value;
    return { type, word: key.slice(0, 2), bit: Number(key.slice(2)), edge };
  }
  const signal = scope.signals.find((s) => s.key === el('trig-signal').value);
  return { type, signal, level: Number(el('trig-level').value), edge };
}

function arm() {
  const mode = el('trig-mode').value;
  const pre = Math.min(100, Math.max(0, Number(el('trig-pre').value) || 0)) / 100;
  // From the newest cycle the drive sent (exact, at most a batch old); the page's clock carried on
  // from a snapshot runs ahead of a drive that runs behind the wall clock.
  const newest = store.cyc.length ? store.cyc[store.cyc.length - 1].t : serverNow();
  scope.acq.arm(mode, mode === 'roll' ? null : condition(), pre, newest);
  scope.t0 = null;
  setPaused(false);
}

// --- the view ----------------------------------------------------------------------------------

function zoomTo(div, anchor) {
  const i = DIVS.indexOf(div);
  if (i < 0) return;
  if (scope.t0 !== null && anchor !== undefined) {
    // The time under the pointer stays where it is.
    const frac = (anchor - scope.t0) / span();
    scope.div = div;
    scope.t0 = anchor - frac * span();
  } else if (scope.t0 !== null) {
    const centre = scope.t0 + span() / 2;
    scope.div = div;
    scope.t0 = centre - span() / 2;
  } else {
    scope.div = div;
  }
  el('scope-div').value = String(div);
}

function zoomStep(dir, anchor) {
  const i = DIVS.indexOf(scope.div) + dir;
  if (i >= 0 && i < DIVS.length) zoomTo(DIVS[i], anchor);
}

// Panning stops the window following the samples, as Pause does (Run or Live: follow again).
function pan(fraction) {
  scope.t0 = scope.window.t0 + fraction * span();
  if (!scope.paused) setPaused(true);
}

function setPaused(on) {
  scope.paused = on;
  if (on && scope.t0 === null) scope.t0 = scope.window.t0;
  if (!on) scope.t0 = null;
  el('scope-pause').setAttribute('aria-pressed', on ? 'true' : 'false');
  el('scope-pause').textContent = on ? 'Run' : 'Pause';
}

// Where the window is now: where the user put it, else around the capture, else the newest span.
function placeWindow(now) {
  const c = scope.acq.capture;
  let t0;
  if (scope.t0 !== null) t0 = scope.t0;
  else if (scope.acq.mode !== 'roll' && c) t0 = c.t - scope.acq.pre * span();
  else t0 = now - span();
  scope.window = { t0, t1: t0 + span() };
}

function shownSignals() {
  const out = [];
  for (const sig of scope.signals) {
    if (sig.kind === 'setpoint') continue;
    if (scope.shown.has(sig.key) || (sig.part && scope.shown.has(sig.part))) out.push(sig);
  }
  return out;
}

// A colour per analog trace; a set-point takes the colour of the actual value it sets.
function colours(shown) {
  const map = new Map();
  let k = 0;
  const actualOf = { inc: 'pos', rpm: 'v', '‰': 'tq' };
  for (const sig of shown) if (sig.kind !== 'bit' && sig.kind !== 'state' && !sig.part) map.set(sig.key, k++);
  for (const sig of shown.filter((s) => s.part)) {
    const actual = actualOf[sig.unit];
    map.set(sig.key, map.has(actual) ? map.get(actual) : k++);
  }
  return map;
}

export function drawScopeFrame() {
  const canvas = el('plot');
  if (!page.info || !canvas.clientWidth) return;
  scope.acq.step(span());
  const now = serverNow();
  placeWindow(now);
  const shown = shownSignals();
  const map = colours(shown);
  const { t0, t1 } = scope.window;
  const c = scope.acq.capture;
  const reference = scope.acq.mode !== 'roll' && c ? c.t : (scope.t0 === null ? t1 : t0);
  scope.mapping = drawScope(canvas, {
    t0, t1, now, shown, colours: map, cursors: scope.cursors, showTransitions: scope.showTransitions,
    trigger: scope.acq.mode !== 'roll' && c ? c.t : null, reference,
  });
  const rows = viewRows(shown, false);  // the times only: the values are for the export
  Object.assign(canvas.dataset, { left: String(scope.mapping.left), width: String(scope.mapping.width),
    t0: String(t0), t1: String(t1), span: String(t1 - t0),
    samples: String(rows.length), trigger: c && scope.acq.mode !== 'roll' ? String(c.t) : '' });
  el('scope-status').textContent = `${scope.paused ? 'paused · ' : ''}${scope.acq.status()} · ` +
    `${formatSpan(t1 - t0)} shown, ${rows.length} samples` +
    (scope.acq.mode !== 'roll' ? ' · time 0 is the trigger' : (scope.t0 === null ? ' · time 0 is now' : ''));
  el('scope-status').dataset.state = scope.acq.stopped ? 'stopped' : (c ? 'triggered' : scope.acq.mode);
  showHealth();
  showLegend(shown, map);
  showCursors(shown, reference, c);
}

// What the page could not keep up with, said plainly.
function showHealth() {
  const parts = [];
  if (store.skipped) parts.push(`browser fell behind: ${store.skipped} samples of the drive's cycles skipped (hatched in the scope)`);
  if (store.missed) parts.push(`${store.missed} snapshots missed from the event stream (the browser or the link could not keep up; hatched in the scope)`);
  if (store.lostRows) parts.push(`${store.lostRows} recording rows lost before the page asked for them`);
  if (store.dropped) parts.push(`the server dropped the oldest ${store.dropped} rows of its recording`);
  const h = el('scope-health');
  h.textContent = parts.length ? `⚠ ${parts.join('; ')}.` : '';
  h.hidden = parts.length === 0;
  h.dataset.missed = String(store.missed);
  h.dataset.skipped = String(store.skipped);
}

function showLegend(shown, map) {
  const box = el('scope-legend');
  // A set-point is named only where its mode ran in the window.
  const { t0, t1 } = scope.window;
  const named = shown.filter((s) => (s.kind === 'analog' || s.kind === 'step') &&
    (!s.part || series(s, t0, t1).length));
  const key = named.map((s) => s.key).join(',');
  if (box.dataset.key === key) return;
  box.dataset.key = key;
  box.textContent = '';
  for (const sig of named) {
    const item = document.createElement('span');
    const swatch = document.createElement('span');
    const k = map.get(sig.key) || 0;
    swatch.className = 'key';
    const dash = sig.dash ? [7, 4] : DASHES[k % DASHES.length];
    swatch.style.borderTop = `${k === 0 ? 3 : 2}px ${dash.length ? (dash[0] <= 2 ? 'dotted' : 'dashed') : 'solid'} ${COLOURS[k % COLOURS.length]}`;
    item.append(swatch, document.createTextNode(`${sig.label}${sig.unit && !sig.key.startsWith('obj') ? ` (${sig.unit})` : ''}`));
    box.appendChild(item);
  }
}

// --- cursors -----------------------------------------------------------------------------------

// The times a cursor snaps to: the recording's edges and the samples of the shown signals.
function snapTimes(shown) {
  const { t0, t1 } = scope.window;
  const times = new Set(edges(t0, t1));
  for (const sig of shown) for (const p of series(sig, t0, t1)) if (p.t >= t0) times.add(p.t);
  return [...times].sort((a, b) => a - b);
}

function snap(t, px) {
  const m = scope.mapping;
  let best = null;
  for (const s of snapTimes(shownSignals())) {
    if (Math.abs(m.x(s) - px) <= 6 && (best === null || Math.abs(s - t) < Math.abs(best - t))) best = s;
  }
  return best !== null ? best : Math.round(t / cycleMs()) * cycleMs();
}

function jumpCursor(name, dir) {
  const { t0, t1 } = scope.window;
  const from = scope.cursors[name] ?? (dir > 0 ? t0 : t1);
  const list = edges(-Infinity, Infinity);
  const next = dir > 0 ? list.find((t) => t > from) : [...list].reverse().find((t) => t < from);
  if (next === undefined) return;
  scope.cursors[name] = next;
  // Keep the cursor in view: the window follows it.
  if (next < t0 || next > t1) {
    scope.t0 = next - span() / 2;
    if (!scope.paused) setPaused(true);
  }
}

function placeCursor(px) {
  const t = snap(scope.mapping.t(px), px);
  const { a, b } = scope.cursors;
  const m = scope.mapping;
  let which = a === null ? 'a' : b === null ? 'b' : null;
  if (!which) which = Math.abs(m.x(a) - px) <= Math.abs(m.x(b) - px) ? 'a' : 'b';
  scope.cursors[which] = t;
}

function buildPointer(canvas) {
  let drag = null;
  canvas.addEventListener('pointerdown', (e) => {
    drag = { x: e.offsetX, t0: scope.window.t0, moved: false };
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag || !scope.mapping) return;
    const dx = e.offsetX - drag.x;
    if (Math.abs(dx) > 4) drag.moved = true;
    if (drag.moved) scope.t0 = drag.t0 - (dx / scope.mapping.width) * span();
  });
  canvas.addEventListener('pointerup', (e) => {
    if (drag && !drag.moved && scope.mapping) placeCursor(e.offsetX);
    else if (drag && drag.moved) setPaused(true);
    drag = null;
  });
  canvas.addEventListener('wheel', (e) => {
    if (!scope.mapping) return;
    e.preventDefault();
    zoomStep(e.deltaY > 0 ? 1 : -1, scope.mapping.t(e.offsetX));
  }, { passive: false });
}

const fmt = (v) => (v === null || v === undefined ? '–' : typeof v === 'number' ? String(+v.toFixed(3)) : stateLabel(v));

// The cursors' times read as the time axis does, from its time 0 (`reference`: the trigger of the
// capture shown, else now); their values are read again for each new capture.
function showCursors(shown, reference, capture) {
  const { a, b } = scope.cursors;
  const cyc = cycleMs();
  const ta = el('cursor-a-time'), tb = el('cursor-b-time'), dt = el('cursor-dt');
  const relative = (t) => { const s = (t - reference) / 1000; return `${s > 0 ? '+' : ''}${s.toFixed(3)} s`; };
  ta.textContent = a === null ? '–' : relative(a);
  tb.textContent = b === null ? '–' : relative(b);
  ta.dataset.ms = a === null ? '' : String(a);
  tb.dataset.ms = b === null ? '' : String(b);
  ta.dataset.relative = a === null ? '' : String(a - reference);
  if (a !== null && b !== null) {
    const d = b - a;
    dt.textContent = `${formatSpan(d)} = ${+(d / cyc).toFixed(3)} cycles` +
      (d !== 0 ? ` (1/Δt ${+(1000 / Math.abs(d)).toPrecision(4)} Hz)` : '');
    dt.dataset.ms = String(d);
  } else {
    dt.textContent = '–';
    dt.dataset.ms = '';
  }
  const body = el('cursor-values');
  const newestCycle = store.cyc.length ? store.cyc[store.cyc.length - 1].n : '';
  const key = `${a}|${b}|${shown.map((s) => s.key).join(',')}|${store.snaps.length}|${store.rec.length}|${newestCycle}|` +
    `${capture ? capture.t : ''}`;
  if (body.dataset.key === key) return;
  body.dataset.key = key;
  body.textContent = '';
  if (a === null && b === null) return;
  // Around the cursors only (a second either side holds the samples they fall between).
  const ends = [a, b].filter((t) => t !== null);
  for (const sig of shown) {
    const pts = series(sig, Math.min(...ends) - 1000, Math.max(...ends) + 1000);
    const va = a === null ? null : valueAt(sig, a, pts);
    const vb = b === null ? null : valueAt(sig, b, pts);
    if (sig.part && va === null && vb === null) continue;  // a set-point of a mode not run there
    const tr = document.createElement('tr');
    const diff = typeof va === 'number' && typeof vb === 'number' ? fmt(vb - va) : '';
    for (const text of [sig.label, fmt(va), fmt(vb), diff]) {
      const td = document.createElement('td');
      td.textContent = text;
      tr.appendChild(td);
    }
    body.appendChild(tr);
  }
}

// --- export ------------------------------------------------------------------------------------

// The view as rows: one per sample time of a shown signal in the window, each signal's value at
// that time as drawn (analog interpolated between samples, the others held).
function viewRows(shown, withValues = true) {
  const { t0, t1 } = scope.window;
  const times = new Set();
  // The count shown with the plot is of the samples drawn; the export has every one.
  const all = shown.map((sig) => {
    const pts = series(sig, t0, t1, withValues ? Infinity : DRAWN_CYCLES);
    for (const p of pts) if (p.t >= t0) times.add(p.t);
    return pts;
  });
  const sorted = [...times].sort((x, y) => x - y);
  if (!withValues) return sorted;
  return sorted.map((t) => [t, ...shown.map((sig, i) => valueAt(sig, t, all[i]))]);
}

function download(blob, name) {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

function exportCsv() {
  const shown = shownSignals();
  const quote = (s) => (/[",\n]/.test(s) ? `"${s.replace(/"/g, '""')}"` : s);
  const lines = [['time_ms', ...shown.map((s) => s.label)].map(quote).join(',')];
  for (const row of viewRows(shown)) {
    lines.push(row.map((v) => (v === null || v === undefined ? '' : typeof v === 'number' ? String(+v.toFixed(3)) : quote(v))).join(','));
  }
  download(new Blob([`${lines.join('\n')}\n`], { type: 'text/csv' }), 'cia402-scope.csv');
}

function exportPng() {
  el('plot').toBlob((blob) => { if (blob) download(blob, 'cia402-scope.png'); }, 'image/png');
}
