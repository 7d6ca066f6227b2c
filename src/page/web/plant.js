// The plant panel: the set-point of the mode the drive runs, the plant's switches (fault, DC link,
// STO) as far as the backend serves them, the readouts and lamps, the object table and its form.
import { el, errorText, hexBits, label, make, page, post, showList, showResult } from './page.js';
import { homingBody, homingRunning } from './modes.js';
import { modeLabel } from './words.js';

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
  const o = page.info.objects.find((x) => x.index === index);
  if (o && o.min !== undefined && (n < o.min || n > o.max)) {
    showResult('refused', `${what}: outside ${o.min}..${o.max}`);
    return null;
  }
  return n;
}

function controlBit(bit) {
  return page.snapshot ? ((hexBits(page.snapshot.control_word) >> bit) & 1) === 1 : false;
}

export function buildSetpoints() {
  const handshake = page.info.new_setpoint === true;
  el('position-form').addEventListener('submit', async (e) => {
    e.preventDefault();
    const n = setpointValue('position-input', '0x607A');
    if (n === null) return;
    const written = await post('/api/object', { index: '0x607A', value: n });
    // Profile position takes the set-point with the handshake on bit 4; csp follows 0x607A as is.
    if (written && handshake && page.snapshot && page.snapshot.mode === 1) {
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
  const entry = page.info.objects.find((o) => o.index === '0x6098');
  for (const m of entry ? entry.values : []) {
    const opt = document.createElement('option');
    opt.value = String(m);
    opt.textContent = String(m);
    methods.appendChild(opt);
  }
  methods.addEventListener('change', () => { touched['homing-method'] = performance.now(); });
  // Homing operation start is bit 4 held up (CiA 402-2); taking it down interrupts the run.
  el('homing-start').hidden = !handshake;
  // POST /api/homing: the parameters, then the run (or its stop); modes.js fills the speeds.
  el('homing-form').addEventListener('submit', (e) => {
    e.preventDefault();
    post('/api/homing', homingBody(Number(methods.value), !homingRunning(page.snapshot)));
  });
}

function showSetpoints(s) {
  const mode = s.mode !== null && s.mode !== undefined ? s.mode : s.requested_mode;
  const kind = setpointKind(mode);
  const shown = new Set(SETPOINT_FORMS[kind]);
  for (const ids of Object.values(SETPOINT_FORMS)) {
    for (const id of ids) el(id).hidden = !shown.has(id);
  }
  el('position-go').textContent = kind === 'pp' && page.info.new_setpoint ? 'Move' : 'Set';
  el('position-go').title = kind === 'pp' && page.info.new_setpoint
    ? 'writes 0x607A, then bit 4 (new set-point) up until the drive acknowledges with status bit 12'
    : 'writes 0x607A';
  const cw = hexBits(s.control_word);
  syncSwitch('pp-relative', ((cw >> 6) & 1) === 1);
  syncSwitch('pp-immediate', ((cw >> 5) & 1) === 1);
  const homing = el('homing-start');
  const running = homingRunning(s);
  homing.setAttribute('aria-pressed', running ? 'true' : 'false');
  homing.textContent = running ? 'Stop homing' : 'Start homing';
  const method = s.objects && s.objects['0x6098'];
  if (method !== undefined && document.activeElement !== el('homing-method') &&
      (touched['homing-method'] === undefined || performance.now() - touched['homing-method'] > 3000)) {
    el('homing-method').value = String(method);
  }
}

export function buildObjects() {
  const sel = el('object-index');
  sel.textContent = '';
  for (const o of page.info.objects) {
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
    const o = page.info.objects.find((x) => x.index === sel.value);
    const n = Number(v);
    const what = `WRITE ${sel.value} = ${v}: refused`;
    if (o && o.values.length && !o.values.includes(n)) {
      showResult('refused', `${what}: profile ${page.info.profile.name} supports ${o.values.join(', ')}`);
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
  if (!page.snapshot) return;
  const v = page.snapshot.objects[el('object-index').value];
  if (v !== undefined) el('object-value').value = v;
}

export function buildPlant() {
  el('fault-class-wrap').hidden = !page.info.error_classes;
  el('error-history-export').addEventListener('click', exportErrorHistory);
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
      if (page.info.error_classes) body.fault_class = Number(el('fault-class').value);
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
  // Never touched is not "touched at time 0": the first 0.8 s after a load follow the drive too.
  if (touched[id] === undefined || performance.now() - touched[id] > 800) el(id).checked = value;
}

// The plant switches a backend cannot serve (DC link and STO on a remote drive; fault injection on
// any remote drive but a node of `cia402 bus`) are disabled, with the server's reason.
const SWITCHES = { fault: 'fault-switch', dc_link: 'dc-switch', sto: 'sto-switch' };
let capabilitiesShown = '';
export function applyCapabilities(caps) {
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
      input.disabled = !available || !(page.info && page.info.control);
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


// Each error code the drive showed in 0x603F, newest first, with the drive's time it came and the
// time of day (the snapshot's error_history); redrawn only when it changed. Export: the list as CSV.
const wallText = (e) => (e.unix_ms === null || e.unix_ms === undefined ? '' : new Date(e.unix_ms).toISOString());
let historyShown = [];
function showErrorHistory(history) {
  historyShown = history;
  showList('error-history', history, (li, e) => {
    const wall = wallText(e);
    li.textContent = `${wall ? `${wall}  ` : ''}${(e.time_ms / 1000).toFixed(3)} s  ${errorText(e)}`;
  });
  el('error-history-none').hidden = history.length > 0;
  el('error-history-export').disabled = history.length === 0;
}

export function errorHistoryCsv(history) {
  const quote = (s) => `"${String(s).replace(/"/g, '""')}"`;
  const lines = ['time of day (UTC),drive time (s),code,text'];
  for (const e of history) lines.push([wallText(e), (e.time_ms / 1000).toFixed(3), e.code, quote(e.text || '')].join(','));
  return `${lines.join('\n')}\n`;
}

function exportErrorHistory() {
  const a = document.createElement('a');
  a.href = URL.createObjectURL(new Blob([errorHistoryCsv(historyShown)], { type: 'text/csv' }));
  a.download = 'cia402-errors.csv';
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

// The readouts, lamps, switches, set-points and objects of the newest snapshot.
export function showPlant(s) {
  showRemote(s);
  applyCapabilities(s.capabilities);
  el('velocity').textContent = s.velocity === null ? '–' : s.velocity;
  el('mode').textContent = modeLabel(s.mode);
  el('position').textContent = s.position === null || s.position === undefined ? '–' : s.position;
  el('following-note').textContent = s.following_error ? `(following error ${s.following_error})` : '';
  el('torque-actual').textContent =
    s.torque_actual === null || s.torque_actual === undefined ? '–' : s.torque_actual;
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
  showErrorHistory(s.error_history || []);
  setLamp('lamp-torque', s.torque);
  setLamp('lamp-brake', s.brake_engaged, s.brake_engaged ? 'ON (holding)' : 'OFF (released)');
  setLamp('lamp-dc', s.dc_link);
  setLamp('lamp-sto', s.sto);
  const cause = s.fault_cause === null ? null : s.fault_cause !== '0x0000';
  setLamp('lamp-fault', cause, cause ? `ON ${s.fault_cause}` : 'OFF');
  // 0x60FD digital inputs (CiA 402): bit 0 negative limit, bit 1 positive limit, bit 2 home switch.
  const inputs = s.digital_inputs;
  const input = (bit) => (inputs === null || inputs === undefined ? null : (inputs & (1 << bit)) !== 0);
  setLamp('lamp-neg-limit', input(0));
  setLamp('lamp-pos-limit', input(1));
  setLamp('lamp-home', input(2));
  // "Why can't I enable?": what blocks the way to OPERATION ENABLED, as the server reads the drive.
  const blocker = el('enable-blocker');
  blocker.hidden = !s.enable_blocker;
  blocker.textContent = s.enable_blocker ? `Enable is blocked: ${s.enable_blocker}` : '';
  syncSwitch('fault-switch', cause);
  syncSwitch('dc-switch', !s.dc_link);
  syncSwitch('sto-switch', s.sto);

  const rows = el('object-values');
  rows.textContent = '';
  for (const o of page.info.objects) {
    const value = s.objects[o.index] !== undefined ? s.objects[o.index] : '–';
    rows.appendChild(make('tr')).append(make('th', { scope: 'row', textContent: `${o.index} ${o.name}` }),
      make('td', { textContent: value }));
  }
  if (document.activeElement !== el('object-value') && el('object-value').value === '') {
    fillObjectValue();
  }
}
