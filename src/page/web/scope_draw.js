// Drawing the scope: the analog signals on a scale per unit (the first unit's ticks on the left,
// the second's on the right), the state as labelled bands, one lane per word bit, the transitions
// as numbered lines, the trigger, the two cursors, and the spans where snapshots were missed.
// Meaning never rests on colour alone: every trace is named in the legend with its line style,
// set-points are dashed.
import { fitCanvas, niceStep, stateLabel } from './page.js';
import { DRAWN_CYCLES, publishMs, series, store, transitions } from './scope_data.js';

export const COLOURS = ['#111111', '#b3261e', '#1f5fbf', '#2e7d32', '#8e24aa', '#ef6c00', '#00838f'];
export const DASHES = [[], [], [2, 2], [8, 3], [1, 3], [10, 3, 2, 3], [4, 4]];
const LEFT = 64, RIGHT = 64, TOP = 14, ANALOG_H = 190, STATE_H = 20, LANE_H = 13, AXIS_H = 22;

/** A duration as the time base reads it: ms, s or min. */
export function formatSpan(ms) {
  const a = Math.abs(ms);
  if (a < 1000) return `${+ms.toFixed(a < 10 ? 2 : 1)} ms`;
  if (a < 60000) return `${+(ms / 1000).toFixed(3)} s`;
  return `${+(ms / 60000).toFixed(3)} min`;
}

/** The canvas height the shown signals need, in CSS pixels. */
export function heightFor(shown) {
  const analog = shown.some((s) => s.kind === 'analog' || s.kind === 'step');
  const states = shown.some((s) => s.kind === 'state');
  const bits = shown.filter((s) => s.kind === 'bit').length;
  return TOP + (analog ? ANALOG_H : 0) + (states ? STATE_H + 4 : 0) + bits * (LANE_H + 1) + AXIS_H + 4;
}

// The scales: one per unit, over what the window shows.
function scales(analog, t0, t1) {
  const byUnit = new Map();
  for (const sig of analog) {
    const pts = series(sig, t0, t1, DRAWN_CYCLES);
    if (!pts.length) continue;  // a set-point of a mode not run in the window takes no scale
    const s = byUnit.get(sig.unit) || { unit: sig.unit, lo: Infinity, hi: -Infinity };
    for (const p of pts) { s.lo = Math.min(s.lo, p.v); s.hi = Math.max(s.hi, p.v); }
    byUnit.set(sig.unit, s);
  }
  for (const s of byUnit.values()) {
    if (!Number.isFinite(s.lo)) { s.lo = 0; s.hi = 1; }
    if (s.hi - s.lo < 1e-9) { s.lo -= 1; s.hi += 1; }
    s.step = niceStep((s.hi - s.lo) / 4);
    s.lo = Math.floor(s.lo / s.step) * s.step;
    s.hi = Math.max(Math.ceil(s.hi / s.step) * s.step, s.lo + s.step);
  }
  return [...byUnit.values()];
}

/**
 * Draws what `view` asks for: {t0, t1, now, shown: [signal], colours: Map(key -> index), cursors:
 * {a, b}, trigger: t | null, reference: t (time 0 of the axis)}. Returns the time <-> x mapping.
 */
export function drawScope(canvas, view) {
  canvas.style.height = `${heightFor(view.shown)}px`;
  const { g, w, h } = fitCanvas(canvas);
  const css = getComputedStyle(canvas);
  const ink = css.color, grid = css.getPropertyValue('--grid').trim() || '#ddd';
  const { t0, t1 } = view;
  const pw = w - LEFT - RIGHT;
  const x = (t) => LEFT + ((t - t0) / (t1 - t0)) * pw;
  const analog = view.shown.filter((s) => s.kind === 'analog' || s.kind === 'step');
  const stateSig = view.shown.find((s) => s.kind === 'state');
  const bits = view.shown.filter((s) => s.kind === 'bit');
  g.font = '11px system-ui, sans-serif';
  g.lineWidth = 1;

  // The grid: ten divisions.
  const bottom = h - AXIS_H;
  g.strokeStyle = grid;
  g.fillStyle = ink;
  g.textAlign = 'center';
  for (let d = 0; d <= 10; d++) {
    const xd = LEFT + (d / 10) * pw;
    g.beginPath();
    g.moveTo(Math.round(xd) + 0.5, TOP);
    g.lineTo(Math.round(xd) + 0.5, bottom);
    g.stroke();
    if (d % 2 === 0) g.fillText(formatSpan(t0 + (d / 10) * (t1 - t0) - view.reference), xd, h - 7);
  }

  const clip = (top, height, draw) => {
    g.save();
    g.beginPath();
    g.rect(LEFT, top, pw, height);
    g.clip();
    draw();
    g.restore();
  };

  const c = { g, ink, grid, t0, t1, pw, x, view, bottom, clip };
  let top = TOP;
  if (analog.length) top = drawAnalog(c, analog, top);
  if (stateSig) top = drawStateLane(c, stateSig, top);
  for (const sig of bits) top = drawBitLane(c, sig, top);
  drawMarks(c);
  return { left: LEFT, width: pw, x, t: (px) => t0 + ((px - LEFT) / pw) * (t1 - t0) };
}

// The analog signals, a scale per unit; returns the top of what comes below.
function drawAnalog(c, analog, top) {
  const { g, ink, grid, t0, t1, pw, x, view, clip } = c;
  const sc = scales(analog, t0, t1);
  const y = (s, v) => top + 3 + (1 - (v - s.lo) / (s.hi - s.lo)) * (ANALOG_H - 6);
  sc.slice(0, 2).forEach((s, i) => {
    g.textAlign = i === 0 ? 'right' : 'left';
    for (let v = s.lo; v <= s.hi + s.step * 1e-6; v += s.step) {
      if (i === 0) {
        g.strokeStyle = grid;
        g.beginPath();
        g.moveTo(LEFT, Math.round(y(s, v)) + 0.5);
        g.lineTo(LEFT + pw, Math.round(y(s, v)) + 0.5);
        g.stroke();
      }
      g.fillStyle = ink;
      g.fillText(String(+v.toPrecision(6)), i === 0 ? LEFT - 4 : LEFT + pw + 4, y(s, v) + 4);
    }
    g.fillText(s.unit, i === 0 ? LEFT - 4 : LEFT + pw + 4, TOP - 2);
  });
  const period = publishMs();
  clip(top, ANALOG_H, () => {
    for (const sig of analog) {
      const s = sc.find((u) => u.unit === sig.unit);
      const pts = series(sig, t0, t1, DRAWN_CYCLES);
      if (!pts.length || !s) continue;
      const k = view.colours.get(sig.key) || 0;
      g.strokeStyle = COLOURS[k % COLOURS.length];
      g.setLineDash(sig.dash ? [7, 4] : DASHES[k % DASHES.length]);
      g.lineWidth = k === 0 ? 2.5 : 1.8;
      g.beginPath();
      pts.forEach((p, i) => {
        if (i === 0) { g.moveTo(x(p.t), y(s, p.v)); return; }
        const q = pts[i - 1];
        // Held: a step signal always; an analog one across a gap between snapshots (they come
        // only on change), up to one period before the next.
        if (sig.kind === 'step') g.lineTo(x(p.t), y(s, q.v));
        else if (p.src === 'snap' && p.t - q.t > 1.5 * period) g.lineTo(x(p.t - period), y(s, q.v));
        g.lineTo(x(p.t), y(s, p.v));
      });
      const last = pts[pts.length - 1];
      g.lineTo(x(Math.min(t1, view.now)), y(s, last.v));
      g.stroke();
    }
  });
  g.setLineDash([]);
  g.lineWidth = 1;
  g.strokeStyle = grid;
  g.strokeRect(LEFT + 0.5, top + 0.5, pw, ANALOG_H);
  top += ANALOG_H + 4;
  return top;
}

// The state as bands, one per state, named where there is room.
function drawStateLane(c, stateSig, top) {
  const { g, ink, t0, t1, x, view, clip } = c;
  // One band per state: the recording repeats the state in every row it keeps.
  const pts = series(stateSig, t0, t1).filter((p, i, all) => i === 0 || p.v !== all[i - 1].v);
  g.fillStyle = ink;
  g.textAlign = 'right';
  g.fillText('state', LEFT - 4, top + STATE_H / 2 + 4);
  clip(top, STATE_H, () => {
    pts.forEach((p, i) => {
      const xa = Math.max(LEFT, x(p.t));
      const xb = x(i + 1 < pts.length ? pts[i + 1].t : Math.min(t1, view.now));
      g.fillStyle = i % 2 ? '#d9d9d9' : '#bdbdbd';
      g.fillRect(xa, top, Math.max(1, xb - xa - 1), STATE_H);
      if (xb - xa > 50) {
        g.fillStyle = '#111';
        g.textAlign = 'left';
        g.fillText(stateLabel(p.v), xa + 3, top + STATE_H / 2 + 4);
      }
    });
  });
  top += STATE_H + 4;
  return top;
}

// A word bit as a logic lane.
function drawBitLane(c, sig, top) {
  const { g, ink, t0, t1, x, view, clip } = c;
  const pts = series(sig, t0, t1, DRAWN_CYCLES);
  g.fillStyle = ink;
  g.textAlign = 'right';
  g.fillText(sig.label.length > 11 ? `${sig.label.slice(0, 10)}…` : sig.label, LEFT - 4, top + LANE_H - 2);
  clip(top, LANE_H, () => {
    g.strokeStyle = ink;
    g.lineWidth = 1.5;
    g.beginPath();
    const yb = (v) => top + (v ? 1.5 : LANE_H - 1.5);
    pts.forEach((p, i) => {
      if (i === 0) g.moveTo(x(p.t), yb(p.v));
      else { g.lineTo(x(p.t), yb(pts[i - 1].v)); g.lineTo(x(p.t), yb(p.v)); }
    });
    if (pts.length) g.lineTo(x(Math.min(t1, view.now)), yb(pts[pts.length - 1].v));
    g.stroke();
  });
  top += LANE_H + 1;
  return top;
}

// Over all lanes: the missed snapshots, the transitions, the trigger and the cursors.
function drawMarks(c) {
  const { g, t0, t1, pw, x, view, bottom } = c;
  // Missed snapshots and skipped cycle samples: hatched, with how many.
  const gaps = [...store.gaps.map(([a, b, n]) => [a, b, `${n} missed`]),
    ...store.cycGaps.map(([a, b, n]) => [a, b, `${n} samples skipped`])];
  for (const [a, b, text] of gaps) {
    if (b < t0 || a > t1) continue;
    const xa = Math.max(LEFT, x(a)), xb = Math.min(LEFT + pw, x(b));
    g.fillStyle = 'rgba(179, 38, 30, 0.12)';
    g.fillRect(xa, TOP, Math.max(2, xb - xa), bottom - TOP);
    g.fillStyle = '#b3261e';
    g.textAlign = 'left';
    g.fillText(text, xa + 2, bottom - 4);
  }

  const vline = (t, colour, width, text, dash) => {
    if (t === null || t === undefined || t < t0 || t > t1) return;
    const xt = Math.round(x(t)) + 0.5;
    g.save();
    g.strokeStyle = colour;
    g.lineWidth = width;
    g.setLineDash(dash || []);
    g.beginPath();
    g.moveTo(xt, TOP);
    g.lineTo(xt, bottom);
    g.stroke();
    g.fillStyle = colour;
    g.textAlign = 'center';
    if (text) g.fillText(text, xt, TOP - 2);
    g.restore();
  };
  if (view.showTransitions) {
    for (const tr of transitions(t0, t1)) vline(tr.t, 'rgba(179, 38, 30, 0.55)', 1, '', [3, 3]);
    g.textAlign = 'center';
    g.fillStyle = '#b3261e';
    for (const tr of transitions(t0, t1)) g.fillText(String(tr.number), x(tr.t), bottom - 4);
  }
  vline(view.trigger, '#b3261e', 2, '');
  if (view.trigger !== null && view.trigger >= t0 && view.trigger <= t1) {
    const xt = x(view.trigger);
    g.fillStyle = '#b3261e';
    g.beginPath();
    g.moveTo(xt - 6, 0);
    g.lineTo(xt + 6, 0);
    g.lineTo(xt, 8);
    g.fill();
  }
  vline(view.cursors.a, '#1f5fbf', 1.5, '', [6, 3]);
  vline(view.cursors.b, '#2e7d32', 1.5, '', [2, 3]);
  g.font = 'bold 12px system-ui, sans-serif';
  for (const [t, name, colour] of [[view.cursors.a, 'A', '#1f5fbf'], [view.cursors.b, 'B', '#2e7d32']]) {
    if (t === null || t < t0 || t > t1) continue;
    g.fillStyle = colour;
    g.textAlign = 'left';
    g.fillText(name, x(t) + 3, TOP + 10);
  }
}
