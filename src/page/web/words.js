// The command buttons and their results, the control word (a button per bit) and the status word,
// and the operation modes: the mode-specific bits by the names CiA 402-2 gives them in each mode.
import { el, hexBits, label, make, page, post, showResult } from './page.js';

// The server says which bits the profile leaves to the mode and their names per mode (info.mode_bits); a
// DRIVECOM profile keeps the names it gives its bits.

export function modeTitle(mode) {
  const title = page.info.mode_names && page.info.mode_names[mode];
  const short = page.info.modes && page.info.modes[mode];
  return title ? `${title} (${short})` : String(mode);
}

export function modeLabel(mode) {
  if (mode === null || mode === undefined) return '–';
  return page.info.mode_names && page.info.mode_names[mode] ? `${mode} ${modeTitle(mode)}` : String(mode);
}

let namedForMode = null;
export function nameModeBits(mode) {
  if (mode === namedForMode) return;
  namedForMode = mode;
  const overlay = (page.info.mode_bits && page.info.mode_bits[mode]) || { control: {}, status: {} };
  const rename = (selector, bits, names) => {
    for (const b of bits) {
      const node = document.querySelector(`${selector}[data-bit="${b.bit}"] .name`);
      if (!node) continue;
      const name = names[b.bit] || b.name;
      node.textContent = name;
      node.parentElement.title = name === b.name ? '' : `${b.name}: in ${modeTitle(mode)}, ${name}`;
    }
  };
  rename('#control-bits button', page.info.control_bits, overlay.control);
  rename('#status-bits li', page.info.status_bits, overlay.status);
}

// The control and status words bit by bit, and the command buttons.

// A bit's number, value and name, filled in as each bit is built.
const BIT_CELLS = '<span class="n"></span><span class="v">0</span><span class="name"></span>';

export function buildBits() {
  el('h-control').textContent = page.info.control_word_name.replace(/^./, (c) => c.toUpperCase());
  el('h-status').textContent = page.info.status_word_name.replace(/^./, (c) => c.toUpperCase());
  const cw = el('control-bits');
  cw.textContent = '';
  for (const b of page.info.control_bits) {
    const btn = make('button', { type: 'button', className: 'bit control', innerHTML: BIT_CELLS });
    btn.setAttribute('role', 'switch');
    btn.setAttribute('aria-checked', 'false');
    btn.dataset.bit = b.bit;
    btn.querySelector('.n').textContent = b.bit;
    btn.querySelector('.name').textContent = b.name;
    if (b.owned) {
      btn.appendChild(make('span', { className: 'sm', title: "read by the profile's state machine", textContent: 'SM' }));
    }
    btn.addEventListener('click', () => post('/api/command', { command: 'toggle_bit', bit: b.bit }));
    cw.appendChild(make('li')).appendChild(btn);
  }
  const sw = el('status-bits');
  sw.textContent = '';
  for (const b of page.info.status_bits) {
    const li = make('li', { className: 'bit', innerHTML: BIT_CELLS });
    li.dataset.bit = b.bit;
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

export function buildCommands() {
  const box = el('commands');
  box.textContent = '';
  for (const c of page.info.commands) {
    // No Halt button where the profile has no halt: its bit 8 means something else there.
    if (c.key === 'halt' && !c.available) continue;
    const b = document.createElement('button');
    b.type = 'button';
    b.className = 'command control';
    b.dataset.command = c.key;
    b.textContent = (page.info.command_labels && page.info.command_labels[c.key]) || COMMAND_LABELS[c.key] ||
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
export function buildModes() {
  const sel = el('mode-select');
  sel.textContent = '';
  const entry = page.info.objects.find((o) => o.index === '0x6060');
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


let shownResult = '';  // the newest result shown: id, outcome and text
// The words and the results of the newest snapshot.
export function showWords(s) {
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
  nameModeBits(s.mode);

  const [latest, ...older] = s.results;
  // The newest result once it is new or changed: a refusal the server answered (post()) stays
  // shown until then, not overwritten by the next snapshot's older result.
  const key = latest ? `${latest.id} ${latest.outcome} ${latest.text}` : '';
  if (latest && key !== shownResult) showResult(latest.outcome, `${label(latest.action)}: ${latest.text}`);
  shownResult = key;
  const list = el('results');
  list.textContent = '';
  for (const r of older.slice(0, 3)) {
    const li = document.createElement('li');
    li.dataset.outcome = r.outcome;
    li.textContent = `${label(r.action)}: ${r.text}`;
    list.appendChild(li);
  }
}
