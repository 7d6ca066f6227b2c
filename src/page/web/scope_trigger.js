// The scope's trigger: where in the samples a condition first holds, and the acquisition around
// it (single shot: one capture, then the scope stops; normal: each trigger after the last capture
// ended gives the next one). Bit edges, states and transitions are found in the recording, exact to
// the cycle (0x60FD's inputs, the index pulse among them, in the drive's cycles); a level crossing in the signal's samples (the drive's cycles, else the recording where
// it carries the signal, never the snapshots of its live edge).
import { lowerBound, series, settledUntil, store } from './scope_data.js';

const edgeMatches = (edge, before, after) =>
  (edge !== 'falling' && !before && after) || (edge !== 'rising' && before && !after);

/**
 * The first time in (after, until] at which `cond` fires, or null. cond is one of
 * {type: 'transition', number}, {type: 'state', state}, {type: 'bit', word: 'cw'|'sw', bit, edge},
 * {type: 'level', signal, level, edge}; edge 'rising', 'falling' or 'either'.
 */
export function findTrigger(cond, after, until) {
  if (cond.type === 'level') {
    // Not from the snapshots of the live edge where the drive's cycles or the recording have it.
    const points = series(cond.signal, after, until).filter((p) => !cond.signal.rec || p.src !== 'snap');
    for (let i = 1; i < points.length; i++) {
      const p = points[i - 1], q = points[i];
      if (q.t <= after) continue;
      if (edgeMatches(cond.edge, p.v >= cond.level, q.v >= cond.level)) return q.t;
    }
    return null;
  }
  if (cond.type === 'bit' && cond.word === 'di') return inputEdge(cond, after, until);
  // From the row before `after` (it holds the words and the state an edge is seen against).
  const rec = store.rec;
  let prev = null;
  for (let i = Math.max(0, lowerBound(rec, after) - 1); i < rec.length; i++) {
    const r = rec[i];
    if (r.t > until || r.t > store.recUntil) break;
    if (r.t > after) {
      if (cond.type === 'transition' && r.transition === cond.number) return r.t;
      if (cond.type === 'state' && r.state === cond.state && (!prev || prev.state !== cond.state)) {
        return r.t;
      }
      if (cond.type === 'bit' && prev) {
        const b = (w) => ((w >> cond.bit) & 1) === 1;
        if (edgeMatches(cond.edge, b(prev[cond.word]), b(r[cond.word]))) return r.t;
      }
    }
    prev = r;
  }
  return null;
}

// 0x60FD's inputs (the index pulse) are in the drive's cycles only: an edge there, exact to the cycle.
function inputEdge(cond, after, until) {
  const cyc = store.cyc;
  const on = (r) => r.di !== null && r.di !== undefined && ((r.di >> cond.bit) & 1) === 1;
  for (let i = Math.max(1, lowerBound(cyc, after)); i < cyc.length && cyc[i].t <= until; i++) {
    if (cyc[i].t > after && edgeMatches(cond.edge, on(cyc[i - 1]), on(cyc[i]))) return cyc[i].t;
  }
  return null;
}

/** How far the samples a condition is looked for in are complete. */
// A signal the recording carries triggers from the recording alone, exact to the cycle, not from
// the snapshots of the live edge.
export function triggerSettled(cond) {
  const lastCycle = store.cyc.length ? store.cyc[store.cyc.length - 1].t : -Infinity;
  if (cond.type === 'bit' && cond.word === 'di') return lastCycle;
  if (cond.type !== 'level') return store.recUntil;
  if (!cond.signal.rec) return settledUntil(cond.signal);
  return Math.max(store.recUntil, cond.signal.cyc ? lastCycle : -Infinity);
}

/**
 * The acquisition: mode 'roll' (no trigger: the newest span, live), 'normal' or 'single'. `step`
 * looks for the trigger in what came since and returns what the scope shows:
 * {status, capture: {t, t0, t1, complete} | null}.
 */
export class acquisition {
  constructor() {
    this.mode = 'roll';
    this.cond = null;
    this.pre = 0.25;
    this.armedAfter = null;  // triggers after this time count
    this.capture = null;     // the one shown
    this.pending = null;     // normal mode: a newer one filling
    this.stopped = false;    // single shot after its capture
  }

  arm(mode, cond, pre, now) {
    this.mode = mode;
    this.cond = cond;
    this.pre = pre;
    this.capture = null;
    this.pending = null;
    this.stopped = false;
    this.armedAfter = now;
  }

  step(span) {
    if (this.mode === 'roll' || !this.cond || this.stopped) return;
    const until = triggerSettled(this.cond);
    const filling = this.pending || (this.mode === 'single' ? this.capture : null);
    if (!filling) {
      const t = findTrigger(this.cond, this.armedAfter, until);
      if (t === null) return;
      const c = { t, t0: t - this.pre * span, t1: t + (1 - this.pre) * span, complete: false };
      if (this.mode === 'single') this.capture = c;
      else this.pending = c;
    }
    const c = this.pending || this.capture;
    // Complete when every source holds samples past its end.
    if (Math.min(until, settledUntil(null)) >= c.t1) {
      c.complete = true;
      this.armedAfter = c.t1;
      if (this.mode === 'single') {
        this.stopped = true;
      } else {
        this.capture = c;
        this.pending = null;
      }
    } else if (this.mode === 'normal' && !this.capture) {
      this.capture = c;  // the first one is shown while it fills
    }
  }

  status() {
    if (this.mode === 'roll') return 'no trigger: the newest samples, live';
    if (this.stopped) return 'single shot: captured, stopped (Arm for another)';
    if (this.mode === 'single') return this.capture ? 'triggered, filling…' : 'armed, waiting for the trigger';
    if (this.pending) return 'triggered again, filling…';
    return this.capture ? 'normal: showing the last capture, armed' : 'normal: armed, waiting for the trigger';
  }
}
