// The scope's samples and signals. Two sources the page receives anyway:
//  - the recording (/api/recording, polled twice a second): every cycle in which a word, the state
//    or a transition changed, and the velocity, position and torque at most every 20 ms while they
//    move. Exact to the cycle, complete, but up to half a second late.
//  - the event stream: a snapshot at most every publish_ms, only when something changed, the newest
//    when the server writes (a version that skips is a snapshot the page never saw). It carries
//    what the recording does not: the set-points, the following error, the position demand, the
//    mode, the objects.
// A signal the recording carries is drawn from it up to the time the recording is known complete,
// and from the snapshots after that (the live edge); the other signals from the snapshots alone.
// Above both, the drive's own cycles (event `samples`, scope_samples.js): every cycle, every signal
// they carry, numbered; where they are, a signal is drawn from them (the recording before the
// first, the snapshots after the newest).
import { hexBits, page } from './page.js';
import { decodeBatch, skippedBefore } from './scope_samples.js';

const KEEP_MS = 15 * 60 * 1000;  // the longest time base is 10 minutes; a little more is kept
// The drive's cycles are kept for a minute (60,000 rows at 1 kHz); older spans come from the
// recording and the snapshots, as before the page had cycles.
const CYCLES_KEEP_MS = 60 * 1000;
/** At most this many cycle samples a signal is drawn with; a longer window keeps each bucket's extremes. */
export const DRAWN_CYCLES = 4000;

export const store = {
  rec: [],          // recording rows {t, cw, sw, state, transition, v, pos, tq}
  snaps: [],        // flattened snapshots, see flatten()
  recUntil: -Infinity,  // every recording row up to this drive time is here
  gaps: [],         // [t_from, t_to, missed]: snapshots that never arrived
  missed: 0,        // snapshots missed in all
  lostRows: 0,      // recording rows gone from the server's bound before the page asked
  dropped: 0,       // the server's own count of rows dropped from its recording
  cyc: [],          // the drive's cycles {n, t, sw, cw, state, transition, v, pos, tq, fe, sp, pd, di, mode, err}
  cycNext: null,    // the number the next cycle sample should have
  skipped: 0,       // cycle samples the page never got (it fell behind the server's ring)
  cycGaps: [],      // [t_from, t_to, skipped]
  polled: [],       // the columns that are the last polled value, not the bus's cycle
};

// A snapshot as the scope keeps it: the numbers only.
function flatten(s) {
  const o = s.objects || {};
  return {
    t: s.time_ms, version: s.version, cycle: s.cycle, mode: s.mode,
    v: s.velocity, pos: s.position, tq: s.torque_actual,
    cw: hexBits(s.control_word), sw: hexBits(s.status_word), state: s.state,
    fe: s.following_error, pd: s.position_demand, di: s.digital_inputs,
    target_velocity: s.target_velocity, effective: s.effective_target,
    objects: o,
  };
}

function trim(list, newest, keep = KEEP_MS) {
  // By bisection: the cycles are many.
  const cut = Math.max(0, lowerBound(list, newest - keep) - 1);
  if (cut) list.splice(0, cut);
}

export function addSnapshot(s, missed) {
  if (s.time_ms === undefined || s.time_ms === null) return;
  const f = flatten(s);
  const prev = store.snaps[store.snaps.length - 1];
  if (prev && f.t < prev.t) clear();  // the drive started again (a new profile)
  if (missed > 0 && prev) {
    store.gaps.push([prev.t, f.t, missed]);
    store.missed += missed;
  }
  store.snaps.push(f);
  trim(store.snaps, f.t);
  while (store.gaps.length && store.gaps[0][1] < f.t - KEEP_MS) store.gaps.shift();
}

export function addRows(rows, poll) {
  if (poll.restarted) {
    store.rec = [];
    store.recUntil = -Infinity;
    return;
  }
  for (const r of rows) store.rec.push(r);
  const last = store.rec[store.rec.length - 1];
  const until = Math.max(poll.askedAt ?? -Infinity, last ? last.t : -Infinity);
  if (until > store.recUntil) store.recUntil = until;
  store.lostRows += poll.lost || 0;
  store.dropped = poll.dropped || 0;
  if (last) trim(store.rec, last.t);
}

export function clear() {
  store.rec = [];
  store.snaps = [];
  store.gaps = [];
  store.recUntil = -Infinity;
  store.cyc = [];
  store.cycGaps = [];
}

/** A batch of the drive's cycles; a batch that starts after the number expected is a gap. */
export function addSamples(batch) {
  const rows = decodeBatch(batch, (page.info && page.info.states) || []);
  const skipped = skippedBefore(store.cycNext, batch);
  store.cycNext = batch.from + batch.n;
  store.polled = batch.polled || [];
  if (!rows.length) return;
  const prev = store.cyc[store.cyc.length - 1];
  if (prev && rows[0].t < prev.t) store.cyc = [];  // the drive started again (a new profile)
  else if (skipped > 0 && prev) {
    store.cycGaps.push([prev.t, rows[0].t, skipped]);
    store.skipped += skipped;
  }
  for (const r of rows) store.cyc.push(r);
  const newest = rows[rows.length - 1].t;
  trim(store.cyc, newest, CYCLES_KEEP_MS);
  while (store.cycGaps.length && store.cycGaps[0][1] < newest - KEEP_MS) store.cycGaps.shift();
}

// --- signals ---------------------------------------------------------------------------------
// kind: 'analog' (a line, interpolated), 'step' (held, e.g. the mode), 'bit' (a lane), 'state'.
// unit: analog signals of one unit share a scale. rec/snap: the value in a recording row or a
// flattened snapshot (undefined: that source does not carry it). dash: drawn dashed.

const bit = (word, n) => (w) => (w[word] === undefined || w[word] === null ? undefined : (w[word] >> n) & 1);
const inMode = (modes, get) => (s) => (modes.includes(s.mode) ? get(s) : null);

/** Every signal the scope can show, for the present profile (names from /api/info). */
export function catalogue() {
  const info = page.info;
  const list = [
    { key: 'v', label: 'velocity 0x606C', unit: 'rpm', kind: 'analog', rec: (r) => r.v, snap: (s) => s.v, cyc: (c) => c.v },
    { key: 'pos', label: 'position 0x6064', unit: 'inc', kind: 'analog', rec: (r) => r.pos, snap: (s) => s.pos, cyc: (c) => c.pos },
    { key: 'tq', label: 'torque 0x6077', unit: '‰', kind: 'analog', rec: (r) => r.tq, snap: (s) => s.tq, cyc: (c) => c.tq },
    // The set-point of the mode the drive runs (0x6061), on the scale of what it sets.
    { key: 'sp', label: 'set-point of the active mode', unit: null, kind: 'setpoint', dash: true },
    { key: 'sp_pos', label: 'set-point 0x607A', unit: 'inc', kind: 'analog', dash: true, part: 'sp',
      snap: inMode([1, 8], (s) => s.objects['0x607A']), cyc: inMode([1, 8], (c) => c.sp) },
    { key: 'sp_vel', label: 'set-point 0x60FF', unit: 'rpm', kind: 'analog', dash: true, part: 'sp',
      snap: inMode([3, 9], (s) => s.target_velocity), cyc: inMode([3, 9], (c) => c.sp) },
    { key: 'sp_tq', label: 'set-point 0x6071', unit: '‰', kind: 'analog', dash: true, part: 'sp',
      snap: inMode([4, 10], (s) => s.objects['0x6071']), cyc: inMode([4, 10], (c) => c.sp) },
    { key: 'fe', label: 'following error 0x60F4', unit: 'inc (error)', kind: 'analog', snap: (s) => s.fe,
      cyc: (c) => c.fe },
    { key: 'pd', label: 'position demand 0x6062', unit: 'inc', kind: 'analog', dash: true, snap: (s) => s.pd,
      cyc: (c) => c.pd },
    { key: 'tv', label: 'target velocity 0x60FF', unit: 'rpm', kind: 'analog', snap: (s) => s.target_velocity },
    { key: 'eff', label: 'velocity followed (set-points cleared)', unit: 'rpm', kind: 'analog', snap: (s) => s.effective },
    { key: 'mode', label: 'mode 0x6061', unit: 'mode', kind: 'step', snap: (s) => s.mode, cyc: (c) => c.mode },
    { key: 'state', label: 'state', kind: 'state', rec: (r) => r.state, snap: (s) => s.state, cyc: (c) => c.state },
  ];
  // 0x60FD's inputs: the limit and home switches (CiA 402-2) and the encoder's index pulse (bit 16,
  // manufacturer-specific), each cycle from the drive's cycles, else from the snapshots.
  for (const [n, name] of [[0, 'negative limit switch'], [1, 'positive limit switch'], [2, 'home switch'],
    [16, 'index pulse']]) {
    list.push({ key: `di${n}`, label: `${name} 0x60FD.${n}`, kind: 'bit', cyc: bit('di', n), snap: bit('di', n) });
  }
  for (const o of (info && info.objects) || []) {
    if (['0x607A', '0x6071', '0x6060'].includes(o.index)) continue;
    list.push({ key: `obj${o.index}`, label: `${o.index} ${o.name}`, unit: o.index, kind: 'step',
      snap: (s) => s.objects[o.index] });
  }
  for (const [word, names] of [['cw', info ? info.control_bits : []], ['sw', info ? info.status_bits : []]]) {
    for (const b of names) {
      const prefix = word === 'cw' ? 'CW' : 'SW';
      list.push({ key: `${word}${b.bit}`, label: `${prefix} ${b.bit} ${b.name}`, kind: 'bit',
        rec: bit(word, b.bit), snap: bit(word, b.bit), cyc: bit(word, b.bit) });
    }
  }
  return list;
}

/**
 * The signals a level trigger offers: one entry per object. Where two signals show one object
 * (0x60FF as "target velocity" and as the set-point of the velocity modes), the object itself is
 * kept, not the view of it a mode gates.
 */
export function levelSignals(signals) {
  const objectOf = (s) => (s.label.match(/0x[0-9A-F]{4}/) || [null])[0];
  const analog = signals.filter((s) => s.kind === 'analog' || s.kind === 'step');
  const taken = new Set(analog.filter((s) => !s.part).map(objectOf).filter((o) => o !== null));
  const seen = new Set();
  return analog.filter((s) => {
    const o = objectOf(s);
    if (o === null) return true;
    if (s.part && taken.has(o)) return false;
    if (seen.has(o)) return false;
    seen.add(o);
    return true;
  });
}

const usable = (v) => v !== undefined && v !== null;

/**
 * The samples of a signal from t0 to t1, with the last one before t0 (so a line starts at the
 * left edge): [{t, v, src}] in time order; src 'cyc' (the drive's cycles), 'rec' or 'snap'.
 * `drawn`: at most that many cycle samples (the plot's): beyond it each bucket of the window gives
 * its first, lowest, highest and last value, so no peak (an index pulse of one cycle) is lost.
 */
export function series(sig, t0 = -Infinity, t1 = Infinity, drawn = Infinity) {
  const out = [];
  let before = null;
  const take = (t, v, src) => {
    if (!usable(v)) return;
    if (t < t0) before = { t, v, src };
    else if (t <= t1) out.push({ t, v, src });
  };
  // Where the drive's cycles are, they are the signal's; the other sources before and after.
  const cyc = sig.cyc && store.cyc.length ? store.cyc : null;
  const cycFrom = cyc ? cyc[0].t : Infinity;
  const cycUntil = cyc ? cyc[cyc.length - 1].t : -Infinity;
  let from = -Infinity;
  if (sig.rec) {
    const rec = store.rec;
    // From a little before the window (the value at its left edge), by bisection: the store is
    // long, the window often short.
    for (let i = Math.max(0, lowerBound(rec, t0) - 8); i < rec.length; i++) {
      const r = rec[i];
      if (r.t > store.recUntil || r.t > t1 || r.t >= cycFrom) break;
      take(r.t, sig.rec(r), 'rec');
    }
    from = store.recUntil;
  }
  const snaps = sig.snap ? store.snaps : [];
  const snapsBetween = (lo, hi) => {
    for (let i = Math.max(0, lowerBound(snaps, Math.max(t0, lo)) - 8); i < snaps.length; i++) {
      const s = snaps[i];
      if (s.t > t1 || s.t >= hi) break;
      if (s.t > lo) take(s.t, sig.snap(s), 'snap');
    }
  };
  snapsBetween(from, cycFrom);
  if (cyc) {
    const first = Math.max(0, lowerBound(cyc, t0) - 1);
    const end = Math.min(cyc.length, lowerBound(cyc, t1 + 1e-9));
    if (end - first <= drawn) {
      for (let i = first; i < end; i++) take(cyc[i].t, sig.cyc(cyc[i]), 'cyc');
    } else {
      takeExtremes(cyc, first, end, Math.ceil((end - first) / (drawn / 4)), sig.cyc, (t, v) => take(t, v, 'cyc'));
    }
    snapsBetween(Math.max(from, cycUntil), Infinity);
  }
  if (before) out.unshift(before);
  return out;
}

// Rows first..end in buckets of `size`: each bucket's first, lowest, highest and last value, in time order.
function takeExtremes(rows, first, end, size, get, take) {
  for (let b = first; b < end; b += size) {
    const picks = new Set([b, Math.min(end, b + size) - 1]);
    let lo = null, hi = null;
    for (let i = b; i < Math.min(end, b + size); i++) {
      const v = get(rows[i]);
      if (!usable(v)) continue;
      if (lo === null || v < get(rows[lo])) lo = i;
      if (hi === null || v > get(rows[hi])) hi = i;
    }
    if (lo !== null) picks.add(lo);
    if (hi !== null) picks.add(hi);
    for (const i of [...picks].sort((x, y) => x - y)) take(rows[i].t, get(rows[i]));
  }
}

/** The first index in a list sorted by time whose time is at least t. */
export function lowerBound(list, t) {
  let lo = 0, hi = list.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (list[mid].t < t) lo = mid + 1; else hi = mid;
  }
  return lo;
}

/** The value a signal had at time t as drawn: analog interpolated between samples, others held. */
export function valueAt(sig, t, points = series(sig)) {
  // The last sample at or before t, by bisection (the export asks for every sample time).
  let lo = 0, hi = points.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (points[mid].t <= t) lo = mid + 1; else hi = mid;
  }
  const i = lo - 1;
  if (i < 0) return null;
  const p = points[i], q = points[i + 1];
  if (sig.kind !== 'analog' || !q || p.t === t) return p.v;
  // A gap between snapshots is a value held (they come only on change).
  if (q.src === 'snap' && q.t - p.t > 1.5 * publishMs()) {
    const heldUntil = q.t - publishMs();
    if (t <= heldUntil) return p.v;
    return p.v + ((q.v - p.v) * (t - heldUntil)) / (q.t - heldUntil);
  }
  return p.v + ((q.v - p.v) * (t - p.t)) / (q.t - p.t);
}

export function publishMs() {
  return (page.info && page.info.publish_ms) || 40;
}

/** The newest drive time up to which a signal's samples are all in. */
export function settledUntil(sig) {
  const lastSnap = store.snaps.length ? store.snaps[store.snaps.length - 1].t : -Infinity;
  const lastCyc = store.cyc.length ? store.cyc[store.cyc.length - 1].t : -Infinity;
  if (sig && sig.rec && !sig.snap) return Math.max(store.recUntil, sig.cyc ? lastCyc : -Infinity);
  return Math.max(store.recUntil, lastSnap, lastCyc);
}

/** Times of the recording's edges: a transition or a change of a word or the state. */
export function edges(t0 = -Infinity, t1 = Infinity) {
  const out = [];
  const rec = store.rec;
  const first = Math.max(0, lowerBound(rec, t0) - 1);
  let prev = null;
  for (let i = first; i < rec.length; i++) {
    const r = rec[i];
    if (r.t > store.recUntil || r.t > t1) break;
    const changed = !prev || r.transition !== null || r.cw !== prev.cw || r.sw !== prev.sw ||
      r.state !== prev.state;
    if (changed && prev && r.t >= t0 && r.t <= t1) out.push(r.t);
    prev = r;
  }
  return out;
}

/** The transitions in the recording from t0 to t1: [{t, number}]. */
export function transitions(t0 = -Infinity, t1 = Infinity) {
  const out = [];
  const rec = store.rec;
  for (let i = lowerBound(rec, t0); i < rec.length; i++) {
    const r = rec[i];
    if (r.t > store.recUntil || r.t > t1) break;
    if (r.transition !== null && r.t >= t0 && r.t <= t1) out.push({ t: r.t, number: r.transition });
  }
  return out;
}
