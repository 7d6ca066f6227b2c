// The state machine diagram (CiA 402-2 figure 6.1): 8 states at fixed places as in the standard's figure, arrows drawn
// from the profile's rows.

import { el, page, stateLabel } from './page.js';

const SVG = 'http://www.w3.org/2000/svg';
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

export function drawDiagram() {
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
  for (const row of page.info.rows) {
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

  for (const name of page.info.states) {
    const [cx, cy] = POS[name];
    const g = svg('g', { id: `state.${name}`, class: 'state other' }, nodes);
    g.dataset.state = name;
    const meaning = page.info.state_meanings && page.info.state_meanings[name];
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
  const t = page.info.transition_texts && page.info.transition_texts[String(n)];
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

export function updateDiagram(s) {
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

