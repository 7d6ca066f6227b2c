// The active mode's panel: what the drive does now (the snapshot's doing_now, inferred by the
// server from what any drive shows), the mode's set-point (snapshot.set_point), its handshake bits
// by the names the mode gives them (info.mode_bits), the homing parameters and phase
// (snapshot.homing, POST /api/homing), and the drive's own error list 0x1003 (snapshot.drive_errors,
// POST /api/errors/read and /clear).
import { el, errorText, hexBits, page, post, showList } from './page.js';
import { modeTitle } from './words.js';

// Control bits 4, 5, 6, 8 (halt), 9 and status bits 10, 11, 12, 13: the ones a mode's handshake uses.
const CONTROL_BITS = [4, 5, 6, 8, 9];
const STATUS_BITS = [10, 11, 12, 13];
const HOMING_INPUTS = [['fast', 'homing-fast'], ['slow', 'homing-slow'],
  ['acceleration', 'homing-acc'], ['offset', 'homing-offset']];

function shownMode(s) {
  return s.mode !== null && s.mode !== undefined ? s.mode : s.requested_mode;
}

// A homing run the page started, or control bit 4 up in homing mode.
export function homingRunning(s) {
  if (!s) return false;
  if (s.homing && s.homing.running) return true;
  return shownMode(s) === 6 && ((hexBits(s.control_word) >> 4) & 1) === 1;
}

// The body of POST /api/homing: start or stop, with the method and each parameter that differs from
// what the drive holds (a value written elsewhere meanwhile is not overwritten with an old one).
export function homingBody(method, start) {
  if (!start) return { start: false };
  const held = (page.snapshot && page.snapshot.homing) || {};
  const body = { start: true };
  if (method !== held.method) body.method = method;
  for (const [key, id] of HOMING_INPUTS) {
    const v = el(id).value.trim();
    if (/^-?\d+$/.test(v) && Number(v) !== held[key]) body[key] = Number(v);
  }
  return body;
}

const touched = {};
export function buildModePanel() {
  for (const [, id] of HOMING_INPUTS) {
    el(id).addEventListener('input', () => { touched[id] = performance.now(); });
  }
  el('drive-errors-read').addEventListener('click', () => post('/api/errors/read', {}));
  el('drive-errors-clear').addEventListener('click', () => post('/api/errors/clear', {}));
}

function bitName(list, overlay, bit) {
  if (overlay && overlay[bit]) return overlay[bit];
  const entry = list && list.find((b) => b.bit === bit);
  return entry ? entry.name : `bit ${bit}`;
}

let bitsShown = '';
function showModeBits(s, mode) {
  const overlay = (page.info.mode_bits && page.info.mode_bits[mode]) || { control: {}, status: {} };
  const cw = hexBits(s.control_word);
  const sw = hexBits(s.status_word);
  const items = [];
  for (const b of CONTROL_BITS) {
    const name = bitName(page.info.control_bits, overlay.control, b);
    if (!name.startsWith('Reserved')) items.push([`control ${b}`, name, (cw >> b) & 1]);
  }
  for (const b of STATUS_BITS) {
    const name = bitName(page.info.status_bits, overlay.status, b);
    if (!name.startsWith('Reserved')) items.push([`status ${b}`, name, (sw >> b) & 1]);
  }
  const key = JSON.stringify([mode, items]);
  if (key === bitsShown) return;
  bitsShown = key;
  const list = el('mode-bits');
  list.textContent = '';
  for (const [where, name, value] of items) {
    const li = document.createElement('li');
    li.dataset.bit = where;
    li.classList.toggle('on', value === 1);
    li.textContent = `${where} ${name}: ${value}`;
    list.append(li);
  }
}

function showHoming(s) {
  const h = s.homing;
  el('homing-phase').textContent = h && h.phase ? `phase: ${h.phase}` : '';
  if (!h) return;
  for (const [key, id] of HOMING_INPUTS) {
    const input = el(id);
    if (h[key] === null || h[key] === undefined || document.activeElement === input) continue;
    if (touched[id] !== undefined && performance.now() - touched[id] < 5000) continue;
    input.value = String(h[key]);
  }
}

function showDriveErrors(d) {
  showList('drive-errors', d ? d.entries : [], (li, e) => {
    li.textContent = `sub ${e.sub}: ${errorText(e)}`;
    li.title = `0x1003 sub ${e.sub} = ${e.value}`;
  });
  let note = 'not read';
  if (d && d.error) note = `not read: ${d.error}`;
  else if (d && d.count === 0) note = 'empty';
  else if (d && d.count) note = `${d.count} error${d.count === 1 ? '' : 's'}, newest first`;
  if (d && d.reading) note += ' (reading)';
  el('drive-errors-note').textContent = note;
}

// The set-point of the mode the drive shows (snapshot.set_point): a stream's value as it goes out.
function showSetpoint(sp) {
  const p = el('mode-setpoint');
  p.hidden = !sp;
  if (!sp) {
    p.textContent = '';
    return;
  }
  const value = sp.value === null ? 'not read' : `${sp.value}${sp.unit ? ` ${sp.unit}` : ''}`;
  p.textContent = `Set-point ${sp.index} ${sp.name}: ${value}${sp.cyclic ? ' (sent every cycle)' : ''}`;
}

export function showModePanel(s) {
  const mode = shownMode(s);
  el('doing-now').textContent = s.doing_now ? `Now: ${s.doing_now}` : '';
  el('doing-now').title = mode !== null && mode !== undefined ? `in ${modeTitle(mode)}` : '';
  showSetpoint(s.set_point);
  if (mode !== null && mode !== undefined) showModeBits(s, mode);
  showHoming(s);
  showDriveErrors(s.drive_errors);
}
