// The recorder: the server keeps every transition and each cycle where something changed
// (/api/recording); the page asks for what it has not seen twice a second, lists the transitions
// newest first and draws the last 30 s as a timeline. The exports are the server's whole recording.
import { api, el, fitCanvas, page, serverNow, stateLabel } from './page.js';

// Who else takes the rows as they come (the scope): a function of (rows, poll) where poll says
// {asked_at, lost, dropped, restarted}.
const listeners = [];
export function onRecording(listener) { listeners.push(listener); }

const recorder = { rowsSeen: 0, transitionsSeen: 0, rows: [], transitions: 0, dropped: 0 };
const TIMELINE_MS = 30000;

// One request at a time: under load a poll can outlast the 500 ms interval, and two polls asking
// from the same counts would both append what is new (the history listed transitions twice).
let recordingInFlight = false;

export async function pollRecording() {
  if (recordingInFlight) return;
  recordingInFlight = true;
  try {
    const askedRows = recorder.rowsSeen;
    const askedTransitions = recorder.transitionsSeen;
    // The drive's time when asking: the answer holds every row up to it at least. An idle drive
    // sends no snapshots, so its time is the newest snapshot's carried on by the page's clock, less
    // a margin for a drive running behind the wall clock (a loaded machine skips cycles).
    const askedAt = page.snapshot ? Math.max(page.snapshot.time_ms, serverNow() - 250) : null;
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
      for (const listener of listeners) listener([], { restarted: true });
      return;
    }
    recorder.rowsSeen = r.rows_seen;
    recorder.transitionsSeen = r.transitions_seen;
    recorder.dropped = r.dropped_rows;
    const rows = r.rows.map((row) => ({ t: row[0], cw: row[1], sw: row[2], state: row[3],
      transition: row[4], v: row[5], pos: row[6], tq: row[7] }));
    for (const row of rows) recorder.rows.push(row);
    // Rows the server had counted but no longer held when asked (its bound): lost to the page.
    const lost = Math.max(0, r.rows_seen - askedRows - r.rows.length);
    for (const listener of listeners) listener(rows, { askedAt, lost, dropped: r.dropped_rows });
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
export function drawTimeline() {
  const canvas = el('timeline');
  if (!page.info || !canvas.clientWidth) return;
  const { g, w, h } = fitCanvas(canvas);
  const ink = getComputedStyle(canvas).color;
  const left = 170, right = 8;
  const pw = w - left - right;
  const now = serverNow();
  const t0 = now - TIMELINE_MS;
  const x = (t) => left + Math.max(0, Math.min(1, (t - t0) / TIMELINE_MS)) * pw;
  const rows = recorder.rows;
  g.font = '11px system-ui, sans-serif';
  g.textBaseline = 'middle';

  const cwBits = page.info.control_bits.filter((b) => b.owned || b.bit === 8);
  const swBits = page.info.status_bits.filter((b) => b.bit <= 6 || b.bit === 10 || b.bit === 11);
  const stateTop = 4, stateH = 20, velTop = 30, velH = 54, laneH = 11;
  const bitsTop = velTop + velH + 8;

  // Segments: [t_start, t_end, row] for each kept row.
  const segments = rows.map((r, i) => [r.t, i + 1 < rows.length ? rows[i + 1].t : now, r]);
  const visible = segments.filter(([a, b]) => b >= t0);
  // One value of the rows at height y(row): samples are points of a ramp, so straight lines between
  // them, held after the last.
  const strokeRamp = (y) => {
    g.beginPath();
    visible.forEach(([a, b, r], i) => {
      if (i === 0) g.moveTo(x(a), y(r)); else g.lineTo(x(a), y(r));
      if (i === visible.length - 1) g.lineTo(x(b), y(r));
    });
    g.stroke();
  };

  g.fillStyle = ink;
  g.textAlign = 'right';
  g.fillText('state', left - 6, stateTop + stateH / 2);
  for (const [a, b, r] of visible) {
    const xa = x(a), xb = x(b);
    const present = r.state === (page.snapshot && page.snapshot.state) && b >= now - 1;
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
  strokeRamp((r) => vy(r.v));

  // The position 0x6064, dashed on a scale of its own, where it moved in the window.
  const positions = visible.map(([, , r]) => r.pos).filter((p) => p !== undefined && p !== null);
  if (positions.length) {
    let plo = Math.min(...positions), phi = Math.max(...positions);
    if (phi > plo) {
      const py = (p) => velTop + 3 + (1 - (p - plo) / (phi - plo)) * (velH - 6);
      g.save();
      g.setLineDash([5, 3]);
      g.lineWidth = 1.5;
      strokeRamp((r) => py(r.pos));
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

