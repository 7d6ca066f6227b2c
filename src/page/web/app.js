// The instrument control page. It shows what the server sends and sends commands; every decision
// of the state machine is the server's (the core's): nothing here knows which transition a command
// leads to.
'use strict';

const SVG = 'http://www.w3.org/2000/svg';
const params = new URLSearchParams(location.search);
// The token printed by `cia402 serve` arrives in the URL once; it is kept for this tab only
// (sessionStorage) and taken out of the address bar and the history at once.
const token = (() => {
  const given = params.get('token');
  if (given) {
    try { sessionStorage.setItem('cia402-token', given); } catch (e) { /* storage off: URL only */ }
    params.delete('token');
    const rest = params.toString();
    history.replaceState(null, '', `${location.pathname}${rest ? `?${rest}` : ''}${location.hash}`);
    return given;
  }
  try { return sessionStorage.getItem('cia402-token') || ''; } catch (e) { return ''; }
})();
// Which of the server's drives this page shows (?axis=K; the first without it).
const axisParam = params.get('axis') || '';

// An API path for this page's axis.
function api(path) {
  if (!axisParam) return path;
  return `${path}${path.includes('?') ? '&' : '?'}axis=${encodeURIComponent(axisParam)}`;
}
const el = (id) => document.getElementById(id);

let info = null;       // /api/info
let snapshot = null;   // the newest snapshot
let received = 0;      // performance.now() when it came
const samples = [];    // {t, v, target} for the plot, server time in ms

// ---------------------------------------------------------------------------------------------
// Requests

async function post(path, body) {
  const headers = { 'Content-Type': 'application/json' };
  if (token) headers['X-Cia402-Token'] = token;
  let reply;
  try {
    const res = await fetch(api(path), { method: 'POST', headers, body: JSON.stringify(body) });
    reply = await res.json().catch(() => ({}));
    if (!res.ok) {
      showResult('refused', reply.error || `HTTP ${res.status}`);
      return null;
    }
  } catch (e) {
    showResult('refused', `no connection to the server (${e.message})`);
    return null;
  }
  return reply;
}

function showResult(outcome, text) {
  const r = el('result');
  r.textContent = text;
  r.dataset.outcome = outcome;
}

// ---------------------------------------------------------------------------------------------
// The state machine diagram: 8 states at fixed places as in the standard's figure, arrows drawn
// from the profile's rows.

const W = 180, H = 44;
const POS = {
  START: [185, 20],
  NOT_READY_TO_SWITCH_ON: [185, 78],
  SWITCH_ON_DISABLED: [185, 165],
  READY_TO_SWITCH_ON: [185, 255],
  SWITCHED_ON: [185, 345],
  OPERATION_ENABLED: [185, 435],
  FAULT_REACTION_ACTIVE: [460, 78],
  FAULT: [460, 165],
  QUICK_STOP_ACTIVE: [460, 435],
};
const RIGHT_COLUMN = new Set(['FAULT_REACTION_ACTIVE', 'FAULT', 'QUICK_STOP_ACTIVE']);

// Routes of the standard's arrows: a polyline and where its number goes.
const ROUTES = {
  'START>NOT_READY_TO_SWITCH_ON': { pts: [[185, 28], [185, 56]], label: [200, 43] },
  'NOT_READY_TO_SWITCH_ON>SWITCH_ON_DISABLED': { pts: [[185, 100], [185, 143]], label: [200, 122] },
  'SWITCH_ON_DISABLED>READY_TO_SWITCH_ON': { pts: [[165, 187], [165, 233]], label: [148, 210] },
  'READY_TO_SWITCH_ON>SWITCH_ON_DISABLED': { pts: [[205, 233], [205, 187]], label: [222, 210] },
  'READY_TO_SWITCH_ON>SWITCHED_ON': { pts: [[165, 277], [165, 323]], label: [148, 300] },
  'SWITCHED_ON>READY_TO_SWITCH_ON': { pts: [[205, 323], [205, 277]], label: [222, 300] },
  'SWITCHED_ON>OPERATION_ENABLED': { pts: [[165, 367], [165, 413]], label: [148, 390] },
  'OPERATION_ENABLED>SWITCHED_ON': { pts: [[205, 413], [205, 367]], label: [222, 390] },
  'OPERATION_ENABLED>READY_TO_SWITCH_ON': {
    pts: [[95, 440], [70, 440], [70, 260], [95, 260]], label: [70, 345], vertical: true },
  'OPERATION_ENABLED>SWITCH_ON_DISABLED': {
    pts: [[95, 452], [42, 452], [42, 160], [95, 160]], label: [42, 300], vertical: true },
  'SWITCHED_ON>SWITCH_ON_DISABLED': {
    pts: [[275, 345], [302, 345], [302, 179], [275, 179]], label: [302, 262], vertical: true },
  'QUICK_STOP_ACTIVE>SWITCH_ON_DISABLED': {
    pts: [[400, 413], [400, 395], [334, 395], [334, 167], [275, 167]], label: [334, 300],
    vertical: true },
  // Numbers clear of the arrowheads even when accented (larger, boxed).
  'OPERATION_ENABLED>QUICK_STOP_ACTIVE': { pts: [[275, 427], [375, 427]], label: [318, 414] },
  'QUICK_STOP_ACTIVE>OPERATION_ENABLED': { pts: [[375, 447], [275, 447]], label: [332, 464] },
  'FAULT_REACTION_ACTIVE>FAULT': { pts: [[460, 100], [460, 143]], label: [482, 118] },
  'FAULT>SWITCH_ON_DISABLED': { pts: [[375, 155], [275, 155]], label: [355, 146] },
};

function svg(tag, attrs, parent) {
  const n = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs || {})) n.setAttribute(k, v);
  if (parent) parent.appendChild(n);
  return n;
}

function label(name) {
  return name.replace(/_/g, ' ');
}

// A state as the profile's documents name it (info.state_names), else the CiA 402 name.
function stateLabel(name) {
  return (info && info.state_names && info.state_names[name]) || label(name);
}

// Long names on two lines, split at the space nearest the middle.
function lines(text) {
  if (text.length <= 17) return [text];
  const mid = text.length / 2;
  let best = -1;
  for (let i = 0; i < text.length; i++) {
    if (text[i] === ' ' && (best < 0 || Math.abs(i - mid) < Math.abs(best - mid))) best = i;
  }
  return best < 0 ? [text] : [text.slice(0, best), text.slice(best + 1)];
}

function box(name, pad) {
  const [cx, cy] = POS[name];
  return { x: cx - W / 2 - pad, y: cy - H / 2 - pad, w: W + 2 * pad, h: H + 2 * pad };
}

// A straight arrow between two boxes, for pairs the standard figure does not have.
function straightRoute(from, to) {
  const [x1, y1] = POS[from], [x2, y2] = POS[to];
  const clip = (cx, cy, dx, dy) => {
    const sx = dx === 0 ? Infinity : (W / 2) / Math.abs(dx);
    const sy = dy === 0 ? Infinity : (H / 2) / Math.abs(dy);
    const s = Math.min(sx, sy);
    return [cx + dx * s, cy + dy * s];
  };
  const a = clip(x1, y1, x2 - x1, y2 - y1), b = clip(x2, y2, x1 - x2, y1 - y2);
  return { pts: [a, b], label: [(a[0] + b[0]) / 2 + 10, (a[1] + b[1]) / 2 - 6] };
}

// The frame around the states a row leaves from (T13 leaves six): one rectangle for the left
// column and one strip out to each right-column state, drawn as their union's outline.
function frameRects(states) {
  const left = states.filter((s) => !RIGHT_COLUMN.has(s) && s !== 'START');
  const right = states.filter((s) => RIGHT_COLUMN.has(s));
  const rects = [];
  let edge = 275;
  if (left.length) {
    const bs = left.map((s) => box(s, 8));
    const y0 = Math.min(...bs.map((b) => b.y)), y1 = Math.max(...bs.map((b) => b.y + b.h));
    rects.push({ x: bs[0].x, y: y0, w: bs[0].w, h: y1 - y0 });
    edge = bs[0].x + bs[0].w;
  }
  for (const s of right) {
    const b = box(s, 8);
    const x0 = left.length ? edge - 14 : b.x;
    rects.push({ x: x0, y: b.y, w: b.x + b.w - x0, h: b.h });
  }
  return rects;
}

function drawDiagram() {
  const root = el('diagram');
  root.textContent = '';
  const defs = svg('defs', {}, root);
  const marker = svg('marker', {
    id: 'arrow', viewBox: '0 0 10 10', refX: '9', refY: '5', markerWidth: '7', markerHeight: '7',
    orient: 'auto-start-reverse',
  }, defs);
  svg('path', { d: 'M0,0 L10,5 L0,10 z', class: 'arrowhead' }, marker);

  const frames = svg('g', { class: 'frames' }, root);
  const arrows = svg('g', { class: 'arrows' }, root);
  const nodes = svg('g', { class: 'states' }, root);
  const labels = svg('g', { class: 'labels' }, root);

  // Group rows by route, so two numbers on one route (T9 and T17) sit side by side.
  const onRoute = new Map();
  for (const row of info.rows) {
    if (row.from.length >= 3) {
      drawGroupRow(row, frames, arrows, labels);
      continue;
    }
    for (const from of row.from) {
      const key = `${from}>${row.to}`;
      if (!onRoute.has(key)) onRoute.set(key, []);
      onRoute.get(key).push(row.number);
    }
  }
  for (const [key, numbers] of onRoute) {
    const [from, to] = key.split('>');
    const route = ROUTES[key] || straightRoute(from, to);
    numbers.forEach((n, i) => {
      const g = svg('g', { id: `t${n}.${from}.${to}`, class: `transition t${n}` }, arrows);
      g.dataset.number = n;
      svg('polyline', { points: route.pts.map((p) => p.join(',')).join(' '),
        'marker-end': 'url(#arrow)' }, g);
      const [lx, ly] = route.label;
      const offset = route.vertical ? [0, i * 24] : [i * 24, 0];
      drawNumber(labels, n, `${from}.${to}`, lx + offset[0], ly + offset[1]);
    });
  }

  for (const name of info.states) {
    const [cx, cy] = POS[name];
    const g = svg('g', { id: `state.${name}`, class: 'state other' }, nodes);
    g.dataset.state = name;
    const meaning = info.state_meanings && info.state_meanings[name];
    svg('title', {}, g).textContent = meaning ? `${stateLabel(name)}: ${meaning}` : stateLabel(name);
    if (name === 'START') {
      svg('circle', { cx, cy, r: 8 }, g);
      const t = svg('text', { x: cx + 14, y: cy + 4, class: 'start-label' }, g);
      t.textContent = 'power on';
      continue;
    }
    svg('rect', { x: cx - W / 2, y: cy - H / 2, width: W, height: H, rx: 6 }, g);
    const ls = lines(stateLabel(name).toUpperCase());
    ls.forEach((line, i) => {
      const t = svg('text', { x: cx, y: cy + 4.5 + (i - (ls.length - 1) / 2) * 15 }, g);
      t.textContent = line;
    });
  }
}

function drawGroupRow(row, frames, arrows, labels) {
  const rects = frameRects(row.from);
  const g = svg('g', { class: `frame t${row.number}` }, frames);
  for (const r of rects) svg('rect', { x: r.x, y: r.y, width: r.w, height: r.h, class: 'outline' }, g);
  for (const r of rects) {
    svg('rect', { x: r.x + 1.5, y: r.y + 1.5, width: r.w - 3, height: r.h - 3, class: 'fill' }, g);
  }
  const t = box(row.to, 0);
  const first = rects[0];
  const startX = first.x + first.w;
  const ty = POS[row.to][1];
  let pts;
  if (ty > first.y && ty < first.y + first.h && t.x > startX) {
    pts = [[startX, ty], [t.x, ty]];
  } else {
    pts = [[startX, first.y + 10], [t.x, ty]];
  }
  const a = svg('g', { id: `t${row.number}.ANY.${row.to}`, class: `transition t${row.number}` }, arrows);
  a.dataset.number = row.number;
  svg('polyline', { points: pts.map((p) => p.join(',')).join(' '), 'marker-end': 'url(#arrow)' }, a);
  const lx = (pts[0][0] + pts[1][0]) / 2, ly = (pts[0][1] + pts[1][1]) / 2 - 9;
  drawNumber(labels, row.number, `ANY.${row.to}`, lx, ly);
  const note = document.createElement('span');
  note.textContent = ` The dashed frame holds the states transition ${row.number} leaves.`;
  el('legend').appendChild(note);
}

// The transition's event and action, as the profile's document words them.
function transitionText(n) {
  const t = info.transition_texts && info.transition_texts[String(n)];
  if (!t) return `transition ${n}`;
  return `${n}. Event: ${t.event}${t.action ? `\nAction: ${t.action}` : ''}`;
}

function drawNumber(parent, n, ends, x, y) {
  const g = svg('g', { id: `n${n}.${ends}`, class: `number t${n}` }, parent);
  g.dataset.number = n;
  svg('title', {}, g).textContent = transitionText(n);
  svg('rect', { x: x - 13, y: y - 11, width: 26, height: 22, rx: 3 }, g);
  const t = svg('text', { x, y: y + 5 }, g);
  t.textContent = String(n);
}

function updateDiagram(s) {
  for (const g of document.querySelectorAll('#diagram .state')) {
    const present = g.dataset.state === s.state;
    g.classList.toggle('present', present);
    g.classList.toggle('other', !present);
  }
  const last = s.last_transition;
  for (const g of document.querySelectorAll('#diagram .number, #diagram .transition')) {
    g.classList.remove('last');
  }
  if (!last) return;
  // The arrow of this row from that state; for a row drawn from a frame (T13), the frame's.
  const ends = [`${last.from}.${last.to}`, `ANY.${last.to}`];
  for (const e of ends) {
    const n = document.getElementById(`n${last.number}.${e}`);
    const t = document.getElementById(`t${last.number}.${e}`);
    if (n) {
      n.classList.add('last');
      if (t) t.classList.add('last');
      return;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Operation modes: the mode-specific bits by the names CiA 402-2 gives them in each mode. The server
// says which bits the profile leaves to the mode and their names per mode (info.mode_bits); a
// DRIVECOM profile keeps the names it gives its bits.

function modeTitle(mode) {
  const title = info.mode_names && info.mode_names[mode];
  const short = info.modes && info.modes[mode];
  return title ? `${title} (${short})` : String(mode);
}

function modeLabel(mode) {
  if (mode === null || mode === undefined) return '–';
  return info.mode_names && info.mode_names[mode] ? `${mode} ${modeTitle(mode)}` : String(mode);
}

let namedForMode = null;
function nameModeBits(mode) {
  if (mode === namedForMode) return;
  namedForMode = mode;
  const overlay = (info.mode_bits && info.mode_bits[mode]) || { control: {}, status: {} };
  const rename = (selector, bits, names) => {
    for (const b of bits) {
      const node = document.querySelector(`${selector}[data-bit="${b.bit}"] .name`);
      if (!node) continue;
      const name = names[b.bit] || b.name;
      node.textContent = name;
      node.parentElement.title = name === b.name ? '' : `${b.name}: in ${modeTitle(mode)}, ${name}`;
    }
  };
  rename('#control-bits button', info.control_bits, overlay.control);
  rename('#status-bits li', info.status_bits, overlay.status);
}

// The set-point inputs of the mode the drive runs: velocity 0x60FF (pv, csv; and when the mode is
// not known), position 0x607A (pp with the new set-point handshake, csp), torque 0x6071 (tq, cst),
// homing method 0x6098 and homing start (hm).
const SETPOINT_FORMS = {
  velocity: ['target-form'],
  position: ['position-form'],
  pp: ['position-form', 'pp-options'],
  torque: ['torque-form'],
  homing: ['homing-form'],
};
function setpointKind(mode) {
  switch (mode) {
    case 1: return 'pp';
    case 8: return 'position';
    case 4: case 10: return 'torque';
    case 6: return 'homing';
    default: return 'velocity';
  }
}

// A set-point checked against the object table's range before it is written, as the object form does.
function setpointValue(inputId, index) {
  const v = el(inputId).value.trim();
  const what = `WRITE ${index} = ${v}: refused`;
  if (!/^-?\d+$/.test(v)) {
    showResult('refused', `${what}: the value must be an integer`);
    return null;
  }
  const n = Number(v);
  const o = info.objects.find((x) => x.index === index);
  if (o && o.min !== undefined && (n < o.min || n > o.max)) {
    showResult('refused', `${what}: outside ${o.min}..${o.max}`);
    return null;
  }
  return n;
}

function controlBit(bit) {
  return snapshot ? ((hexBits(snapshot.control_word) >> bit) & 1) === 1 : false;
}

function buildSetpoints() {
  const handshake = info.new_setpoint === true;
  el('position-form').addEventListener('submit', async (e) => {
    e.preventDefault();
    const n = setpointValue('position-input', '0x607A');
    if (n === null) return;
    const written = await post('/api/object', { index: '0x607A', value: n });
    // Profile position takes the set-point with the handshake on bit 4; csp follows 0x607A as is.
    if (written && handshake && snapshot && snapshot.mode === 1) {
      post('/api/command', { command: 'new_setpoint' });
    }
  });
  for (const [id, bit] of [['pp-relative', 6], ['pp-immediate', 5]]) {
    el(id).addEventListener('change', (e) => {
      touched[id] = performance.now();
      if (e.target.checked !== controlBit(bit)) post('/api/command', { command: 'toggle_bit', bit });
    });
  }
  el('torque-form').addEventListener('submit', (e) => {
    e.preventDefault();
    const n = setpointValue('torque-input', '0x6071');
    if (n !== null) post('/api/object', { index: '0x6071', value: n });
  });
  const methods = el('homing-method');
  const entry = info.objects.find((o) => o.index === '0x6098');
  for (const m of entry ? entry.values : []) {
    const opt = document.createElement('option');
    opt.value = String(m);
    opt.textContent = String(m);
    methods.appendChild(opt);
  }
  methods.addEventListener('change', () => { touched['homing-method'] = performance.now(); });
  // Homing operation start is bit 4 held up (CiA 402-2); taking it down interrupts the run.
  el('homing-start').hidden = !handshake;
  el('homing-form').addEventListener('submit', async (e) => {
    e.preventDefault();
    if (controlBit(4)) {
      post('/api/command', { command: 'toggle_bit', bit: 4 });
      return;
    }
    const method = Number(methods.value);
    if (snapshot && snapshot.objects['0x6098'] !== method) {
      if (!(await post('/api/object', { index: '0x6098', value: method }))) return;
    }
    if (handshake) post('/api/command', { command: 'toggle_bit', bit: 4 });
  });
}

function showSetpoints(s) {
  const mode = s.mode !== null && s.mode !== undefined ? s.mode : s.requested_mode;
  const kind = setpointKind(mode);
  const shown = new Set(SETPOINT_FORMS[kind]);
  for (const ids of Object.values(SETPOINT_FORMS)) {
    for (const id of ids) el(id).hidden = !shown.has(id);
  }
  el('position-go').textContent = kind === 'pp' && info.new_setpoint ? 'Move' : 'Set';
  el('position-go').title = kind === 'pp' && info.new_setpoint
    ? 'writes 0x607A, then bit 4 (new set-point) up until the drive acknowledges with status bit 12'
    : 'writes 0x607A';
  const cw = hexBits(s.control_word);
  syncSwitch('pp-relative', ((cw >> 6) & 1) === 1);
  syncSwitch('pp-immediate', ((cw >> 5) & 1) === 1);
  const homing = el('homing-start');
  const running = mode === 6 && ((cw >> 4) & 1) === 1;
  homing.setAttribute('aria-pressed', running ? 'true' : 'false');
  homing.textContent = running ? 'Stop homing' : 'Start homing';
  const method = s.objects && s.objects['0x6098'];
  if (method !== undefined && document.activeElement !== el('homing-method') &&
      performance.now() - (touched['homing-method'] || 0) > 3000) {
    el('homing-method').value = String(method);
  }
}

// ---------------------------------------------------------------------------------------------
// Words, commands, plant

function buildBits() {
  el('h-control').textContent = info.control_word_name.replace(/^./, (c) => c.toUpperCase());
  el('h-status').textContent = info.status_word_name.replace(/^./, (c) => c.toUpperCase());
  const cw = el('control-bits');
  cw.textContent = '';
  for (const b of info.control_bits) {
    const li = document.createElement('li');
    const btn = document.createElement('button');
    btn.type = 'button';
    btn.className = 'bit control';
    btn.setAttribute('role', 'switch');
    btn.setAttribute('aria-checked', 'false');
    btn.dataset.bit = b.bit;
    btn.innerHTML = '<span class="n"></span><span class="v">0</span><span class="name"></span>';
    btn.querySelector('.n').textContent = b.bit;
    btn.querySelector('.name').textContent = b.name;
    if (b.owned) {
      const sm = document.createElement('span');
      sm.className = 'sm';
      sm.title = "read by the profile's state machine";
      sm.textContent = 'SM';
      btn.appendChild(sm);
    }
    btn.addEventListener('click', () => post('/api/command', { command: 'toggle_bit', bit: b.bit }));
    li.appendChild(btn);
    cw.appendChild(li);
  }
  const sw = el('status-bits');
  sw.textContent = '';
  for (const b of info.status_bits) {
    const li = document.createElement('li');
    li.className = 'bit';
    li.dataset.bit = b.bit;
    li.innerHTML = '<span class="n"></span><span class="v">0</span><span class="name"></span>';
    li.querySelector('.n').textContent = b.bit;
    li.querySelector('.name').textContent = b.name;
    sw.appendChild(li);
  }
}

const COMMAND_LABELS = {
  shutdown: 'Shutdown', switch_on: 'Switch on', enable_operation: 'Enable operation',
  disable_operation: 'Disable operation', disable_voltage: 'Disable voltage',
  quick_stop: 'Quick stop', fault_reset: 'Fault reset', halt: 'Halt',
};

function buildCommands() {
  const box = el('commands');
  box.textContent = '';
  for (const c of info.commands) {
    // No Halt button where the profile has no halt: its bit 8 means something else there.
    if (c.key === 'halt' && !c.available) continue;
    const b = document.createElement('button');
    b.type = 'button';
    b.className = 'command control';
    b.dataset.command = c.key;
    b.textContent = (info.command_labels && info.command_labels[c.key]) || COMMAND_LABELS[c.key] ||
      c.action;
    if (b.textContent !== COMMAND_LABELS[c.key]) b.title = `CiA 402: ${COMMAND_LABELS[c.key]}`;
    if (!c.available) {
      b.disabled = true;
      b.dataset.unavailable = 'true';
      b.title = 'this profile has no control word for it';
    }
    if (c.key === 'halt') {
      b.setAttribute('aria-pressed', 'false');
      b.title = 'toggles bit 8: stops on the 0x605D ramp while set';
    }
    b.addEventListener('click', () => post('/api/command', { command: c.key }));
    box.appendChild(b);
  }
}

// The mode select writes 0x6060; its choices are the modes 0x6502 announces.
function buildModes() {
  const sel = el('mode-select');
  sel.textContent = '';
  const entry = info.objects.find((o) => o.index === '0x6060');
  sel.hidden = !entry;
  if (!entry) return;
  for (const m of entry.values) {
    const opt = document.createElement('option');
    opt.value = String(m);
    opt.textContent = modeTitle(m);
    sel.appendChild(opt);
  }
  sel.addEventListener('change', () => post('/api/object', { index: '0x6060', value: Number(sel.value) }));
}

function buildObjects() {
  const sel = el('object-index');
  sel.textContent = '';
  for (const o of info.objects) {
    const opt = document.createElement('option');
    opt.value = o.index;
    opt.textContent = `${o.index} ${o.name}`;
    sel.appendChild(opt);
  }
  el('object-form').addEventListener('submit', (e) => {
    e.preventDefault();
    const v = el('object-value').value.trim();
    if (v === '' || !/^-?\d+$/.test(v)) {
      showResult('refused', 'the value must be an integer');
      return;
    }
    // What the profile or the object table cannot take is refused here, as the drive would
    // refuse it, without a request (and without a failed request in the browser's console).
    const o = info.objects.find((x) => x.index === sel.value);
    const n = Number(v);
    const what = `WRITE ${sel.value} = ${v}: refused`;
    if (o && o.values.length && !o.values.includes(n)) {
      showResult('refused', `${what}: profile ${info.profile.name} supports ${o.values.join(', ')}`);
      return;
    }
    if (o && o.min !== undefined && (n < o.min || n > o.max)) {
      showResult('refused', `${what}: outside ${o.min}..${o.max}`);
      return;
    }
    post('/api/object', { index: sel.value, value: n });
  });
  sel.addEventListener('change', () => fillObjectValue());
}

function fillObjectValue() {
  if (!snapshot) return;
  const v = snapshot.objects[el('object-index').value];
  if (v !== undefined) el('object-value').value = v;
}

function buildPlant() {
  el('fault-class-wrap').hidden = !info.error_classes;
  el('target-form').addEventListener('submit', (e) => {
    e.preventDefault();
    const v = el('target-input').value.trim();
    if (!/^-?\d+$/.test(v)) {
      showResult('refused', 'the target velocity must be an integer (rpm)');
      return;
    }
    post('/api/plant', { target_velocity: Number(v) });
  });
  el('fault-switch').addEventListener('change', (e) => {
    const on = e.target.checked;
    const body = { fault: on };
    if (on) {
      body.fault_code = el('fault-code').value.trim();
      if (info.error_classes) body.fault_class = Number(el('fault-class').value);
    }
    post('/api/plant', body).then((r) => { if (!r) e.target.checked = !on; });
  });
  el('dc-switch').addEventListener('change', (e) => post('/api/plant', { dc_link: !e.target.checked }));
  el('sto-switch').addEventListener('change', (e) => post('/api/plant', { sto: e.target.checked }));
}

// A switch the user just changed is not overwritten by a snapshot older than the change.
const touched = {};
function syncSwitch(id, value) {
  if (value === null || value === undefined) return;
  if (performance.now() - (touched[id] || 0) > 800) el(id).checked = value;
}

// The plant switches a backend cannot serve (DC link and STO on a remote drive; fault injection on
// any remote drive but a node of `cia402 bus`) are disabled, with the server's reason.
const SWITCHES = { fault: 'fault-switch', dc_link: 'dc-switch', sto: 'sto-switch' };
let capabilitiesShown = '';
function applyCapabilities(caps) {
  if (!caps) return;
  const key = JSON.stringify(caps);
  if (key === capabilitiesShown) return;
  capabilitiesShown = key;
  const notes = [];
  for (const [name, id] of Object.entries(SWITCHES)) {
    const available = caps[name] !== false;
    const reason = (caps.reasons && caps.reasons[name]) || '';
    const inputs = [el(id)];
    if (name === 'fault') inputs.push(el('fault-code'), el('fault-class'));
    for (const input of inputs) {
      input.dataset.unavailable = available ? 'false' : 'true';
      input.disabled = !available || !(info && info.control);
      input.title = available ? '' : reason;
    }
    el(id).closest('.row').dataset.unavailable = available ? 'false' : 'true';
    if (!available && reason) notes.push(`${el(id).nextElementSibling.textContent}: ${reason}`);
  }
  el('switches-note').textContent = notes.join('. ');
  el('switches-note').hidden = notes.length === 0;
}

function showRemote(s) {
  const r = s.remote;
  const banner = el('remote');
  if (!r) {
    banner.hidden = true;
    return;
  }
  banner.hidden = false;
  banner.dataset.status = r.status;
  // A drive on EtherCAT says where it is itself ("slave 1 on EtherCAT eth1") and its AL state.
  const where = r.where || `node ${r.node}${r.bus ? ` on ${r.bus}` : ''}`;
  let text = r.status === 'running'
    ? `Remote drive: ${where}${r.device_name ? ` (${r.device_name})` : ''}` +
      `${r.nmt ? `, NMT ${label(r.nmt)}` : ''}${r.al_state ? `, AL state ${r.al_state}` : ''}. ` +
      'Transition numbers are inferred from the observed states.'
    : `Remote drive: ${r.text || `${where}: ${r.status}`}`;
  banner.textContent = text;
}
for (const id of ['fault-switch', 'dc-switch', 'sto-switch']) {
  document.addEventListener('change', (e) => { if (e.target.id === id) touched[id] = performance.now(); },
    true);
}

// A lamp whose value is null is one a remote drive does not show over the bus.
function setLamp(id, on, text) {
  const l = el(id);
  const unknown = on === null || on === undefined;
  l.classList.toggle('on', !unknown && on);
  l.classList.toggle('unknown', unknown);
  l.querySelector('b').textContent = unknown ? 'unknown' : text || (on ? 'ON' : 'OFF');
}

function hexBits(hex) {
  return parseInt(hex, 16);
}

function update(s) {
  if (s.profile && info && s.profile !== info.profile.name) {
    // The drive runs under another profile now (chosen here or in another page): draw it anew.
    location.reload();
    return;
  }
  snapshot = s;
  received = performance.now();
  el('state-name').textContent = stateLabel(s.state);
  const last = s.last_transition;
  const number = last && last.number !== null ? last.number : '?';
  el('last-transition').textContent = last
    ? `${number} (${stateLabel(last.from)} → ${stateLabel(last.to)})${last.inferred ? ', inferred' : ''}`
    : 'none';
  updateDiagram(s);
  showRemote(s);
  applyCapabilities(s.capabilities);

  el('sw-hex').textContent = s.status_word;
  const sw = hexBits(s.status_word);
  for (const li of el('status-bits').children) {
    const on = ((sw >> Number(li.dataset.bit)) & 1) === 1;
    li.classList.toggle('on', on);
    li.querySelector('.v').textContent = on ? '1' : '0';
  }
  el('cw-hex').textContent = s.control_word;
  el('cw-decodes').textContent = label(s.decodes_to);
  const cw = hexBits(s.control_word);
  for (const btn of el('control-bits').querySelectorAll('button')) {
    const on = ((cw >> Number(btn.dataset.bit)) & 1) === 1;
    btn.classList.toggle('on', on);
    btn.setAttribute('aria-checked', on ? 'true' : 'false');
    btn.querySelector('.v').textContent = on ? '1' : '0';
  }
  const halt = document.querySelector('button[data-command="halt"]');
  if (halt) halt.setAttribute('aria-pressed', ((cw >> 8) & 1) ? 'true' : 'false');

  el('velocity').textContent = s.velocity === null ? '–' : s.velocity;
  el('mode').textContent = modeLabel(s.mode);
  el('position').textContent = s.position === null || s.position === undefined ? '–' : s.position;
  el('following-note').textContent = s.following_error ? `(following error ${s.following_error})` : '';
  el('torque-actual').textContent =
    s.torque_actual === null || s.torque_actual === undefined ? '–' : s.torque_actual;
  nameModeBits(s.mode);
  showSetpoints(s);
  const modeSelect = el('mode-select');
  const requested = s.requested_mode !== undefined && s.requested_mode !== null
    ? s.requested_mode : s.objects && s.objects['0x6060'];
  if (requested !== undefined && document.activeElement !== modeSelect) modeSelect.value = String(requested);
  el('target').textContent = s.target_velocity;
  el('setpoint-note').textContent = s.effective_target !== s.target_velocity
    ? `(set-points cleared: following ${s.effective_target})` : '';
  el('error-code').textContent = s.error_code;
  // The code's CiA 301 / CiA 402 text (emergency error codes), where the drive reports one.
  el('error-text').textContent = s.error_code !== '0x0000' && s.error_text ? s.error_text : '';
  el('error-register').textContent = s.error_register;
  setLamp('lamp-torque', s.torque);
  setLamp('lamp-brake', s.brake_engaged, s.brake_engaged ? 'ON (holding)' : 'OFF (released)');
  setLamp('lamp-dc', s.dc_link);
  setLamp('lamp-sto', s.sto);
  const cause = s.fault_cause === null ? null : s.fault_cause !== '0x0000';
  setLamp('lamp-fault', cause, cause ? `ON ${s.fault_cause}` : 'OFF');
  syncSwitch('fault-switch', cause);
  syncSwitch('dc-switch', !s.dc_link);
  syncSwitch('sto-switch', s.sto);

  const rows = el('object-values');
  rows.textContent = '';
  for (const o of info.objects) {
    const tr = document.createElement('tr');
    const a = document.createElement('th');
    a.scope = 'row';
    a.textContent = `${o.index} ${o.name}`;
    const b = document.createElement('td');
    b.textContent = s.objects[o.index] !== undefined ? s.objects[o.index] : '–';
    tr.append(a, b);
    rows.appendChild(tr);
  }
  if (document.activeElement !== el('object-value') && el('object-value').value === '') {
    fillObjectValue();
  }

  const [latest, ...older] = s.results;
  if (latest) showResult(latest.outcome, `${label(latest.action)}: ${latest.text}`);
  const list = el('results');
  list.textContent = '';
  for (const r of older.slice(0, 3)) {
    const li = document.createElement('li');
    li.dataset.outcome = r.outcome;
    li.textContent = `${label(r.action)}: ${r.text}`;
    list.appendChild(li);
  }

  if (s.velocity !== null) samples.push({ t: s.time_ms, v: s.velocity, target: s.effective_target });
  while (samples.length && samples[0].t < s.time_ms - 12000) samples.shift();
}

// ---------------------------------------------------------------------------------------------
// The velocity plot: the last 10 s, the newest value held up to now between updates (updates come
// only when something changed).

// A canvas sized to its CSS box at the screen's pixel ratio, cleared: its context and CSS size.
function fitCanvas(canvas) {
  const dpr = window.devicePixelRatio || 1;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
  }
  const g = canvas.getContext('2d');
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  g.clearRect(0, 0, w, h);
  return { g, w, h };
}

function drawPlot() {
  const canvas = el('plot');
  const { g, w, h } = fitCanvas(canvas);
  const css = getComputedStyle(canvas);
  const ink = css.color, grid = css.getPropertyValue('--grid').trim() || '#ccc';
  const left = 48, right = 8, top = 8, bottom = 20;
  const pw = w - left - right, ph = h - top - bottom;
  const now = snapshot ? snapshot.time_ms + (performance.now() - received) : 0;
  const t0 = now - 10000;
  let lo = 0, hi = 0;
  for (const p of samples) {
    lo = Math.min(lo, p.v, p.target);
    hi = Math.max(hi, p.v, p.target);
  }
  const span = Math.max(hi - lo, 100);
  const step = niceStep(span / 4);
  lo = Math.floor(lo / step) * step;
  hi = Math.max(Math.ceil(hi / step) * step, lo + step);
  const period = (info && info.publish_ms) || 40;
  const x = (t) => left + ((t - t0) / 10000) * pw;
  const y = (v) => top + (1 - (v - lo) / (hi - lo)) * ph;

  g.font = '11px system-ui, sans-serif';
  g.lineWidth = 1;
  g.strokeStyle = grid;
  g.fillStyle = ink;
  g.textAlign = 'right';
  for (let v = lo; v <= hi + 1e-9; v += step) {
    g.beginPath();
    g.moveTo(left, y(v) + 0.5);
    g.lineTo(left + pw, y(v) + 0.5);
    g.stroke();
    g.fillText(String(Math.round(v)), left - 4, y(v) + 4);
  }
  g.textAlign = 'center';
  for (let s = 0; s <= 10; s += 2) {
    const xs = left + (s / 10) * pw;
    g.fillText(s === 10 ? 'now' : `-${10 - s} s`, xs, h - 5);
  }
  g.strokeStyle = ink;
  g.beginPath();
  g.moveTo(left, y(0) + 0.5);
  g.lineTo(left + pw, y(0) + 0.5);
  g.stroke();

  const trace = (key, dashed, width) => {
    if (!samples.length) return;
    g.save();
    g.beginPath();
    g.rect(left, top - 2, pw, ph + 4);
    g.clip();
    g.setLineDash(dashed ? [6, 4] : []);
    g.lineWidth = width;
    g.strokeStyle = ink;
    g.beginPath();
    let prev = null;
    for (const p of samples) {
      const px = x(p.t), py = y(p[key]);
      if (prev === null) {
        g.moveTo(px, py);
      } else {
        // Snapshots come only on change, at most every `period` ms: the value before a gap held
        // until one period before the next sample.
        if (p.t - prev.t > 1.5 * period) g.lineTo(x(p.t - period), y(prev[key]));
        g.lineTo(px, py);
      }
      prev = p;
    }
    g.lineTo(x(now), y(prev[key]));
    g.stroke();
    g.restore();
  };
  trace('target', true, 1.5);
  trace('v', false, 2.5);
}

function niceStep(raw) {
  const p = Math.pow(10, Math.floor(Math.log10(raw)));
  for (const m of [1, 2, 5, 10]) if (raw <= m * p) return m * p;
  return 10 * p;
}

// ---------------------------------------------------------------------------------------------
// The profile (a virtual drive starts again under the one chosen) and the overview of several axes.

function buildProfileChoice() {
  const wrap = el('profile-choice');
  if (!info.profiles || info.profiles.length < 2) return;
  const sel = el('profile-select');
  for (const p of info.profiles) {
    const o = document.createElement('option');
    o.value = p.name;
    o.textContent = `${p.name}: ${p.title}`;
    o.selected = p.name === info.profile.name;
    sel.appendChild(o);
  }
  wrap.hidden = false;
  sel.classList.add('control');
  sel.addEventListener('change', async () => {
    const r = await post('/api/profile', { profile: sel.value });
    if (r) location.reload();
    else sel.value = info.profile.name;
  });
}

function axisHref(k) {
  const q = new URLSearchParams(location.search);
  q.set('axis', String(k));
  return `?${q.toString()}`;
}

function buildAxes() {
  if (!info.axes || info.axes < 2) return;
  el('axes').hidden = false;
  el('axis-name').textContent = `${info.axis_label}: `;
  const refresh = async () => {
    try {
      const res = await fetch('/api/axes');
      if (!res.ok) return;
      const list = await res.json();
      const nav = el('axes');
      nav.textContent = '';
      for (const a of list) {
        const link = document.createElement('a');
        link.className = 'axis-card';
        link.href = axisHref(a.axis);
        link.dataset.axis = a.axis;
        if (a.axis === info.axis) link.setAttribute('aria-current', 'page');
        const name = document.createElement('b');
        name.textContent = a.label;
        const state = document.createElement('span');
        state.className = 'axis-state';
        state.textContent = a.state ? label(a.state) : '–';
        const more = document.createElement('span');
        more.className = 'axis-more';
        more.textContent = `${a.status_word || ''} · ${a.velocity === null || a.velocity === undefined ? '–' : a.velocity} rpm` +
          (a.error_code && a.error_code !== '0x0000' ? ` · error ${a.error_code}${a.error_text ? ` (${a.error_text})` : ''}` : '');
        link.append(name, state, more);
        nav.appendChild(link);
      }
    } catch (e) {
      // The stale marking tells that the server is gone.
    }
  };
  refresh();
  setInterval(refresh, 1000);
}

// ---------------------------------------------------------------------------------------------
// The recorder: the server keeps every transition and each cycle where something changed
// (/api/recording); the page asks for what it has not seen twice a second, lists the transitions
// newest first and draws the last 30 s as a timeline. The exports are the server's whole recording.

const recorder = { rowsSeen: 0, transitionsSeen: 0, rows: [], transitions: 0, dropped: 0 };
const TIMELINE_MS = 30000;

// One request at a time: under load a poll can outlast the 500 ms interval, and two polls asking
// from the same counts would both append what is new (the history listed transitions twice).
let recordingInFlight = false;

async function pollRecording() {
  if (recordingInFlight) return;
  recordingInFlight = true;
  try {
    const askedRows = recorder.rowsSeen;
    const askedTransitions = recorder.transitionsSeen;
    const res = await fetch(api(
      `/api/recording?rows_seen=${askedRows}&transitions_seen=${askedTransitions}`));
    if (!res.ok) return;
    const r = await res.json();
    // An answer to counts that are no longer ours (the recording started over meanwhile) is dropped.
    if (recorder.rowsSeen !== askedRows || recorder.transitionsSeen !== askedTransitions) return;
    if (r.rows_seen < recorder.rowsSeen || r.transitions_seen < recorder.transitionsSeen) {
      // A new recording (the server restarted; a profile switch reloads the page): start over.
      recorder.rowsSeen = 0;
      recorder.transitionsSeen = 0;
      recorder.rows = [];
      recorder.transitions = 0;
      el('history').textContent = '';
      return;
    }
    recorder.rowsSeen = r.rows_seen;
    recorder.transitionsSeen = r.transitions_seen;
    recorder.dropped = r.dropped_rows;
    for (const row of r.rows) {
      recorder.rows.push({ t: row[0], cw: row[1], sw: row[2], state: row[3], transition: row[4],
        v: row[5], pos: row[6], tq: row[7] });
    }
    const newest = recorder.rows.length ? recorder.rows[recorder.rows.length - 1].t : 0;
    // Keep one row from before the window, so the lanes start at its left edge with a value.
    let cut = 0;
    while (cut + 1 < recorder.rows.length && recorder.rows[cut + 1].t < newest - TIMELINE_MS - 5000) {
      cut++;
    }
    if (cut) recorder.rows.splice(0, cut);
    addHistory(r.transitions);
  } catch (e) {
    // The event stream's stale marking says the server is gone; nothing to add here.
  } finally {
    recordingInFlight = false;
  }
}

function addHistory(list) {
  const body = el('history');
  for (const t of list) {
    recorder.transitions++;
    const tr = document.createElement('tr');
    tr.dataset.number = t.number === null ? '' : t.number;
    const cells = [
      [(t.time_ms / 1000).toFixed(3) + ' s', 'time'],
      [t.number === null ? '?' : (t.inferred ? `${t.number}*` : String(t.number)), 't'],
      [`${stateLabel(t.from)} → ${stateLabel(t.to)}`, 'states'],
      [t.control_word, 'words'],
      [t.status_word, 'words'],
    ];
    for (const [text, cls] of cells) {
      const td = document.createElement('td');
      td.className = cls;
      td.textContent = text;
      tr.appendChild(td);
    }
    if (t.inferred) tr.title = 'number inferred from the observed states';
    body.insertBefore(tr, body.firstChild);
  }
  // The page lists the newest 1000; the exports hold them all.
  while (body.children.length > 1000) body.removeChild(body.lastChild);
  const n = recorder.transitions;
  el('recorder-count').textContent = `${n} transition${n === 1 ? '' : 's'} recorded` +
    (recorder.dropped ? ` (the oldest ${recorder.dropped} cycles dropped from the recording)` : '') +
    (body.children.length < n ? `, the newest ${body.children.length} listed` : '');
}

// Lanes, top to bottom: the state as labelled bands, the velocity, then one lane per bit the
// state machine reads (control word) and the state bits of the status word.
function drawTimeline() {
  const canvas = el('timeline');
  if (!info || !canvas.clientWidth) return;
  const { g, w, h } = fitCanvas(canvas);
  const ink = getComputedStyle(canvas).color;
  const left = 170, right = 8;
  const pw = w - left - right;
  const now = snapshot ? snapshot.time_ms + (performance.now() - received) : 0;
  const t0 = now - TIMELINE_MS;
  const x = (t) => left + Math.max(0, Math.min(1, (t - t0) / TIMELINE_MS)) * pw;
  const rows = recorder.rows;
  g.font = '11px system-ui, sans-serif';
  g.textBaseline = 'middle';

  const cwBits = info.control_bits.filter((b) => b.owned || b.bit === 8);
  const swBits = info.status_bits.filter((b) => b.bit <= 6 || b.bit === 10 || b.bit === 11);
  const stateTop = 4, stateH = 20, velTop = 30, velH = 54, laneH = 11;
  const bitsTop = velTop + velH + 8;

  // Segments: [t_start, t_end, row] for each kept row.
  const segments = rows.map((r, i) => [r.t, i + 1 < rows.length ? rows[i + 1].t : now, r]);
  const visible = segments.filter(([a, b]) => b >= t0);

  g.fillStyle = ink;
  g.textAlign = 'right';
  g.fillText('state', left - 6, stateTop + stateH / 2);
  for (const [a, b, r] of visible) {
    const xa = x(a), xb = x(b);
    const present = r.state === (snapshot && snapshot.state) && b >= now - 1;
    g.fillStyle = present ? ink : '#d0d0d0';
    g.fillRect(xa, stateTop, Math.max(1, xb - xa - 1), stateH);
    if (xb - xa > 60) {
      g.save();
      g.beginPath();
      g.rect(xa, stateTop, xb - xa - 2, stateH);
      g.clip();
      g.fillStyle = present ? '#fff' : '#222';
      g.textAlign = 'left';
      g.fillText(stateLabel(r.state), xa + 4, stateTop + stateH / 2);
      g.restore();
    }
  }

  // Velocity, scaled to what the window holds.
  let lo = 0, hi = 0;
  for (const [, , r] of visible) { lo = Math.min(lo, r.v); hi = Math.max(hi, r.v); }
  if (hi - lo < 100) hi = lo + 100;
  const vy = (v) => velTop + (1 - (v - lo) / (hi - lo)) * velH;
  g.fillStyle = ink;
  g.textAlign = 'right';
  g.fillText(`velocity ${Math.round(hi)}`, left - 6, velTop + 5);
  g.fillText(`${Math.round(lo)} rpm`, left - 6, velTop + velH - 5);
  g.strokeStyle = '#dedede';
  g.lineWidth = 1;
  g.strokeRect(left, velTop, pw, velH);
  g.strokeStyle = ink;
  g.lineWidth = 2;
  g.beginPath();
  visible.forEach(([a, b, r], i) => {
    // Samples are points of a ramp: straight lines between them, held after the last.
    if (i === 0) g.moveTo(x(a), vy(r.v)); else g.lineTo(x(a), vy(r.v));
    if (i === visible.length - 1) g.lineTo(x(b), vy(r.v));
  });
  g.stroke();

  // The position 0x6064, dashed on a scale of its own, where it moved in the window.
  const positions = visible.map(([, , r]) => r.pos).filter((p) => p !== undefined && p !== null);
  if (positions.length) {
    let plo = Math.min(...positions), phi = Math.max(...positions);
    if (phi > plo) {
      const py = (p) => velTop + 3 + (1 - (p - plo) / (phi - plo)) * (velH - 6);
      g.save();
      g.setLineDash([5, 3]);
      g.lineWidth = 1.5;
      g.beginPath();
      visible.forEach(([a, b, r], i) => {
        if (i === 0) g.moveTo(x(a), py(r.pos)); else g.lineTo(x(a), py(r.pos));
        if (i === visible.length - 1) g.lineTo(x(b), py(r.pos));
      });
      g.stroke();
      g.restore();
      g.fillStyle = ink;
      g.textAlign = 'right';
      g.fillText(`- - pos ${plo}..${phi}`, left - 6, velTop + velH / 2);
    }
  }

  const lane = (label, top, word, bit) => {
    g.fillStyle = ink;
    g.textAlign = 'right';
    g.fillText(label, left - 6, top + laneH / 2);
    g.strokeStyle = '#e6e6e6';
    g.lineWidth = 1;
    g.beginPath();
    g.moveTo(left, top + laneH - 0.5);
    g.lineTo(left + pw, top + laneH - 0.5);
    g.stroke();
    g.fillStyle = ink;
    for (const [a, b, r] of visible) {
      if ((r[word] >> bit) & 1) g.fillRect(x(a), top + 1, Math.max(1, x(b) - x(a)), laneH - 3);
    }
  };
  let top = bitsTop;
  const short = (name) => (name.length > 18 ? name.slice(0, 17) + '…' : name);
  for (const b of cwBits) { lane(`CW ${b.bit} ${short(b.name)}`, top, 'cw', b.bit); top += laneH + 1; }
  for (const b of swBits) { lane(`SW ${b.bit} ${short(b.name)}`, top, 'sw', b.bit); top += laneH + 1; }

  // Transitions: a line through every lane with the number on top.
  g.textAlign = 'center';
  for (const [a, , r] of visible) {
    if (r.transition === null || a < t0) continue;
    g.strokeStyle = '#b3261e';
    g.lineWidth = 1;
    g.beginPath();
    g.moveTo(x(a) + 0.5, stateTop);
    g.lineTo(x(a) + 0.5, top);
    g.stroke();
  }
  g.fillStyle = ink;
  g.textAlign = 'left';
  g.fillText('−30 s', left, h - 6);
  g.textAlign = 'right';
  g.fillText('now', left + pw, h - 6);
  canvas.dataset.rows = String(visible.length);
}

function animate() {
  drawPlot();
  drawTimeline();
  setTimeout(() => requestAnimationFrame(animate), 50);
}

// ---------------------------------------------------------------------------------------------

function setControl(allowed) {
  document.body.classList.toggle('view-only', !allowed);
  el('view-only').hidden = allowed;
  for (const c of document.querySelectorAll('.control, .command, #target-input')) {
    c.disabled = !allowed || c.dataset.unavailable === 'true';
  }
}

function connect() {
  const source = new EventSource(api('/api/events'));
  // While the stream is down every value on the page is old: the whole instrument is marked stale
  // (grayed, controls off) until the next snapshot arrives.
  const stale = (on) => {
    document.body.classList.toggle('stale', on);
    el('stale').hidden = !on;
    for (const c of document.querySelectorAll('.control, .command, #target-input')) {
      if (on) {
        c.dataset.staleDisabled = c.disabled ? 'no' : 'yes';
        c.disabled = true;
      } else if (c.dataset.staleDisabled === 'yes') {
        c.disabled = false;
        delete c.dataset.staleDisabled;
      }
    }
  };
  source.onopen = () => {
    el('link').textContent = 'live';
    el('link').dataset.live = 'true';
  };
  source.onerror = () => {
    el('link').textContent = 'connection lost, retrying…';
    el('link').dataset.live = 'false';
    if (!document.body.classList.contains('stale')) stale(true);
  };
  source.onmessage = (e) => {
    try {
      if (document.body.classList.contains('stale')) stale(false);
      update(JSON.parse(e.data));
      document.body.dataset.version = snapshot.version;
    } catch (err) {
      console.error(err);
    }
  };
}

async function main() {
  const headers = token ? { 'X-Cia402-Token': token } : {};
  const res = await fetch(api('/api/info'), { headers });
  info = await res.json();
  const p = info.profile;
  el('profile').textContent = `${p.title} (profile ${p.name})`;
  if (p.seed) el('profile').title = `transition table from the drive manual ${p.seed}`;
  document.title = `${p.name}: instrument control`;
  for (const a of document.querySelectorAll('.exports a')) a.href = api(a.getAttribute('href'));
  buildProfileChoice();
  buildAxes();
  drawDiagram();
  buildBits();
  buildCommands();
  buildObjects();
  buildModes();
  buildSetpoints();
  buildPlant();
  setControl(info.control);
  applyCapabilities(info.capabilities);
  connect();
  animate();
  pollRecording();
  setInterval(pollRecording, 500);
}

main().catch((e) => {
  el('link').textContent = `cannot load the page's data: ${e.message}`;
});
