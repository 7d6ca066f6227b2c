// What every part of the instrument page shares: the token and the axis from the URL, requests to
// the server, the newest /api/info and snapshot, and a few helpers. The page shows what the server
// sends and sends commands; every decision of the state machine is the server's (the core's):
// nothing here knows which transition a command leads to.

const params = new URLSearchParams(location.search);
// The token printed by `cia402 serve` arrives in the URL once; it is kept for this tab only
// (sessionStorage) and taken out of the address bar and the history at once.
export const token = (() => {
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
// This tab's name for the server (docs/instrument-page.md, "Control model"): kept for the tab
// (sessionStorage), so showing another axis is the same page, which holds the axes it commanded.
export const clientId = (() => {
  const bytes = new Uint8Array(12);
  const fresh = () => {
    if (globalThis.crypto && crypto.getRandomValues) crypto.getRandomValues(bytes);
    else for (let i = 0; i < bytes.length; ++i) bytes[i] = Math.floor(Math.random() * 256);
    return Array.from(bytes, (b) => b.toString(16).padStart(2, '0')).join('');
  };
  try {
    let id = sessionStorage.getItem('cia402-client');
    if (!id) {
      id = fresh();
      sessionStorage.setItem('cia402-client', id);
    }
    return id;
  } catch (e) {
    return fresh();
  }
})();
// The headers of every request: the token where there is one, and this page's client id.
export function headers(more = {}) {
  const h = { 'X-Cia402-Client': clientId, ...more };
  if (token) h['X-Cia402-Token'] = token;
  return h;
}
// Which of the server's drives this page shows (?axis=K; the first without it).
const axisParam = params.get('axis') || '';

/** The page's shared state: /api/info, the newest snapshot and when it came (performance.now()). */
export const page = { info: null, snapshot: null, received: 0 };

// An API path for this page's axis.
export function api(path) {
  if (!axisParam) return path;
  return `${path}${path.includes('?') ? '&' : '?'}axis=${encodeURIComponent(axisParam)}`;
}
export const el = (id) => document.getElementById(id);
// A new element with its properties set (textContent, className, title, type, ...).
export const make = (tag, props = {}) => Object.assign(document.createElement(tag), props);

// The drive's time now in ms: the newest snapshot's, carried on by the time since it came.
export function serverNow() {
  return page.snapshot ? page.snapshot.time_ms + (performance.now() - page.received) : 0;
}

// A POST with the token: `{ ok, status, reply }` (the reply's JSON, `{ error }` without a connection).
export async function send(path, body) {
  try {
    const res = await fetch(api(path), { method: 'POST', headers: headers({ 'Content-Type': 'application/json' }),
      body: JSON.stringify(body) });
    return { ok: res.ok, status: res.status, reply: await res.json().catch(() => ({})) };
  } catch (e) {
    return { ok: false, status: 0, reply: { error: `no connection to the server (${e.message})` } };
  }
}

// A POST whose refusal is shown as the page's result: the reply, or null when refused.
export async function post(path, body) {
  const { ok, status, reply } = await send(path, body);
  if (ok) return reply;
  showResult('refused', reply.error || `HTTP ${status}`);
  return null;
}

export function showResult(outcome, text) {
  const r = el('result');
  r.textContent = text;
  r.dataset.outcome = outcome;
}

export function label(name) {
  return name.replace(/_/g, ' ');
}

// A state as the profile's documents name it (info.state_names), else the CiA 402 name.
export function stateLabel(name) {
  const info = page.info;
  return (info && info.state_names && info.state_names[name]) || label(name);
}

// Fills the list `id` with one <li> an entry, each written by fill(li, entry), only when the entries
// changed since the list was last filled: one redrawn with every snapshot would lose a hover.
const listsShown = new Map();
export function showList(id, entries, fill) {
  const key = JSON.stringify(entries);
  if (listsShown.get(id) === key) return;
  listsShown.set(id, key);
  const list = el(id);
  list.textContent = '';
  for (const e of entries) {
    const li = document.createElement('li');
    fill(li, e);
    list.append(li);
  }
}

// An error code as the server sends it, then its text where the server knows one.
export function errorText(e) {
  return `${e.code}${e.text ? ` ${e.text}` : ''}`;
}

export function hexBits(hex) {
  return parseInt(hex, 16);
}

// A canvas sized to its CSS box at the screen's pixel ratio, cleared: its context and CSS size.
export function fitCanvas(canvas) {
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

// A step of 1, 2 or 5 times a power of ten at least `raw`.
export function niceStep(raw) {
  const p = Math.pow(10, Math.floor(Math.log10(raw)));
  for (const m of [1, 2, 5, 10]) if (raw <= m * p) return m * p;
  return 10 * p;
}
