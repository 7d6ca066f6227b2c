// The parameter list and parameter files (issue 35; docs/instrument-page.md, "Parameter list and
// parameter files"): every entry of the drive with its description and present value, a search
// (index or name) and a filter (all / writable / differs from default), a write per entry with the
// drive's refusal shown (the SDO abort code and its text), and the whole set saved to a file and
// loaded back with what was written, refused and skipped. Every value is the server's: the list is
// read again after each write.
import { api, el, page, send } from './page.js';

const state = { entries: [], loading: false };

function cell(row, text, cls) {
  const td = document.createElement('td');
  td.textContent = text === null || text === undefined ? '' : String(text);
  if (cls) td.className = cls;
  row.append(td);
  return td;
}

// The values a write may take: the choice where there is one (runs of consecutive values as
// "0 … 8"), else the range.
function limits(e) {
  if (Array.isArray(e.values) && e.values.length) {
    const runs = [];
    for (const v of e.values) {
      const last = runs[runs.length - 1];
      if (last && v === last[1] + 1) last[1] = v;
      else runs.push([v, v]);
    }
    return runs.map(([a, b]) => (a === b ? `${a}` : b === a + 1 ? `${a}, ${b}` : `${a} … ${b}`)).join(', ');
  }
  if (e.low === null && e.high === null) return '';
  return `${e.low ?? ''} … ${e.high ?? ''}`;
}

// Words as a commissioning engineer reads them: in hex, and the control and status word with the
// names of the bits set (the profile's names, from /api/info).
const HEX_WORDS = ['0x1001', '0x603F', '0x6040', '0x6041', '0x6502', '0x60FD'];
function valueText(e) {
  if (typeof e.value !== 'number' || e.sub !== 0 || !HEX_WORDS.includes(e.index)) return e.value;
  const digits = e.index === '0x6502' || e.index === '0x60FD' ? 8 : e.index === '0x1001' ? 2 : 4;
  const hex = `0x${(e.value >>> 0).toString(16).toUpperCase().padStart(digits, '0')}`;
  const names = { '0x6040': page.info && page.info.control_bits, '0x6041': page.info && page.info.status_bits }[e.index];
  if (!names) return hex;
  const set = names.filter((b) => (e.value >> b.bit) & 1).map((b) => b.name);
  return set.length ? `${hex}: ${set.join(', ')}` : hex;
}

function matches(e) {
  const q = el('param-search').value.trim().toLowerCase();
  const f = el('param-filter').value;
  if (f === 'writable' && !e.writable) return false;
  if (f === 'differs' && !e.differs) return false;
  if (!q) return true;
  return e.key.toLowerCase().includes(q) || e.index.toLowerCase().includes(q) || e.name.toLowerCase().includes(q);
}

function writeCell(row, e) {
  const td = document.createElement('td');
  if (e.writable) {
    const form = document.createElement('form');
    form.className = 'param-write';
    const input = document.createElement('input');
    input.className = 'control';
    input.size = 8;
    input.value = e.value ?? '';
    input.setAttribute('aria-label', `new value of ${e.key}`);
    const button = document.createElement('button');
    button.type = 'submit';
    button.className = 'control';
    button.textContent = 'Write';
    // Drawn after the page learnt whether it may control (stream.js setControl): off when not.
    input.disabled = button.disabled = document.body.classList.contains('view-only');
    form.append(input, button);
    form.addEventListener('submit', async (ev) => {
      ev.preventDefault();
      const text = input.value.trim();
      const number = /^-?\d+$/.test(text) ? Number(text) : null;
      const r = await send('/api/object', { index: e.key, value: number !== null && Number.isSafeInteger(number) ? number : text });
      showOutcome(r.ok ? `${e.key} = ${text}: written` : refusalText(e.key, r.reply), r.ok ? 'done' : 'refused');
      await readList();
    });
    td.append(form);
  }
  row.append(td);
}

// The abort once: the server's reason already names it ("WRITE ...: SDO abort 0x06090030 (...)"),
// and is given it alone where it does not.
function refusalText(key, reply) {
  const reason = reply.error || 'no reason given';
  const abort = reply.abort && !reason.includes(reply.abort) ? ` (SDO abort ${reply.abort}: ${reply.abort_text})` : '';
  return `${key}: refused: ${reason}${abort}`;
}

function showOutcome(text, outcome) {
  const o = el('param-outcome');
  o.textContent = text;
  o.dataset.outcome = outcome;
}

function draw() {
  const body = el('param-rows');
  body.replaceChildren();
  let shown = 0;
  for (const e of state.entries) {
    if (!matches(e)) continue;
    ++shown;
    const row = document.createElement('tr');
    row.dataset.key = e.key;
    if (e.differs) row.classList.add('differs');
    cell(row, e.key, 'mono');
    cell(row, e.name);
    cell(row, e.type);
    cell(row, e.unit);
    cell(row, e.access);
    cell(row, limits(e), 'mono');
    cell(row, e.default, 'mono');
    const v = cell(row, e.error ? e.error : valueText(e), 'mono param-value');
    if (e.error) v.classList.add('param-error');
    if (e.differs) v.title = `differs from the default ${e.default}`;
    writeCell(row, e);
    body.append(row);
  }
  el('param-count').textContent = `${shown} of ${state.entries.length} entries`;
}

export async function readList() {
  if (state.loading) return;
  state.loading = true;
  el('param-count').textContent = 'reading…';
  try {
    const res = await fetch(api('/api/parameters'));
    const reply = await res.json().catch(() => ({}));
    if (!res.ok) {
      el('param-count').textContent = `not read: ${reply.error || `HTTP ${res.status}`}`;
      // A drive not reachable yet (503): read again while the panel stays open.
      if (res.status === 503) setTimeout(() => { if (el('param-details').open) readList(); }, 1000);
      return;
    }
    state.entries = reply.entries || [];
    el('param-save').hidden = !reply.file;
    el('param-load-label').hidden = !reply.file;
    draw();
  } catch (e) {
    el('param-count').textContent = `not read: no connection to the server (${e.message})`;
  } finally {
    state.loading = false;
  }
}

function listResult(title, items, describe) {
  const li = document.createElement('li');
  li.textContent = `${title}: ${items.length}`;
  if (items.length) {
    const ul = document.createElement('ul');
    for (const item of items) {
      const i = document.createElement('li');
      i.textContent = describe(item);
      ul.append(i);
    }
    li.append(ul);
  }
  return li;
}

async function loadFile(file) {
  const text = await file.text();
  const r = await send('/api/parameters.dcf', { file: text });
  const out = el('param-load-result');
  out.replaceChildren();
  if (!r.ok) {
    showOutcome(`${file.name} not loaded, nothing changed: ${r.reply.error || `HTTP ${r.status}`}`, 'refused');
    return;
  }
  const { written = [], refused = [], skipped = [] } = r.reply;
  showOutcome(`${file.name}: ${written.length} written, ${refused.length} refused, ${skipped.length} skipped`,
    refused.length ? 'refused' : 'done');
  out.append(
    listResult('refused', refused, (x) => `${x.key} = ${x.value}: ${x.abort ? `${x.abort} ${x.abort_text}` : x.error}`),
    listResult('written', written, (x) => `${x.key} = ${x.value}`),
    listResult('skipped', skipped, (x) => `${x.key}: ${x.reason}`));
  await readList();
}

export function buildParameters() {
  el('param-search').addEventListener('input', draw);
  el('param-filter').addEventListener('change', draw);
  el('param-read').addEventListener('click', readList);
  // Read when first opened: the list is a read of every entry (an SDO each on a bus), not part of
  // the page's first load.
  const opened = () => {
    if (el('param-details').open && !state.entries.length) readList();
  };
  el('param-details').addEventListener('toggle', opened);
  opened();  // opened before the page had started
  el('param-save').addEventListener('click', () => {
    const a = document.createElement('a');
    a.href = api('/api/parameters.dcf');
    a.download = 'cia402-parameters.dcf';
    document.body.append(a);
    a.click();
    a.remove();
  });
  el('param-load').addEventListener('change', (ev) => {
    const f = ev.target.files && ev.target.files[0];
    if (f) loadFile(f).finally(() => { ev.target.value = ''; });
  });
}
