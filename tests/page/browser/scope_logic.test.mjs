// The scope's logic without a browser (node, the page's own modules): the event stream counts the
// versions that never arrived and the scope marks the span they left; the recording and the
// snapshots merge at the time the recording is known complete; the trigger conditions fire on the
// exact row; an acquisition completes only once the recording holds its whole window.
//
//   node scope_logic.test.mjs
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const web = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../../../src/page/web');

// The little of a browser the modules touch when loaded and when a stream message comes.
function element() {
  return { dataset: {}, hidden: false, textContent: '', disabled: false,
    classList: { toggle() {}, contains: () => false } };
}
const elements = new Map();
globalThis.location = { search: '', pathname: '/', hash: '' };
globalThis.history = { replaceState() {} };
globalThis.sessionStorage = { getItem: () => null, setItem() {} };
globalThis.document = {
  body: element(),
  getElementById: (id) => { if (!elements.has(id)) elements.set(id, element()); return elements.get(id); },
  querySelectorAll: () => [],
};
const sources = [];
globalThis.EventSource = class { constructor(url) { this.url = url; sources.push(this); } };

const load = (name) => import(pathToFileURL(path.join(web, name)).href);
const { page } = await load('page.js');
const { connect } = await load('stream.js');
const data = await load('scope_data.js');
const { acquisition, findTrigger } = await load('scope_trigger.js');

let passed = 0;
function check(name, fn) {
  fn();
  passed += 1;
  console.log(`ok ${passed} - scope logic: ${name}`);
}
function expect(condition, message) {
  if (!condition) throw new Error(message);
}

page.info = {
  publish_ms: 40, cycle_us: 1000, objects: [{ index: '0x607A', name: 'target position' }],
  control_bits: [{ bit: 3, name: 'Enable operation' }], status_bits: [{ bit: 2, name: 'Operation enabled' }],
};
const snapshot = (version, t, extra = {}) => ({
  version, time_ms: t, cycle: t, mode: 3, velocity: 0, position: 0, torque_actual: 0,
  control_word: '0x0006', status_word: '0x0231', state: 'READY_TO_SWITCH_ON', following_error: 0,
  position_demand: 0, target_velocity: 0, effective_target: 0, objects: { '0x607A': 0 }, ...extra,
});
// A recording row as recorder.js hands it on.
const row = (t, extra = {}) => ({ t, cw: 6, sw: 0x231, state: 'READY_TO_SWITCH_ON', transition: null,
  v: 0, pos: 0, tq: 0, ...extra });
const signal = (key) => data.catalogue().find((s) => s.key === key);

try {
  check('a version that skips is counted as missed, and the span it left is marked', () => {
    const taken = [];
    connect((s, missed) => { taken.push(missed); data.addSnapshot(s, missed); });
    const source = sources[0];
    for (const [v, t] of [[7, 1000], [8, 1040], [11, 1200], [12, 1240]]) {
      source.onmessage({ data: JSON.stringify(snapshot(v, t)) });
    }
    expect(taken.join(',') === '0,0,2,0', `missed per message ${taken.join(',')}`);
    expect(data.store.missed === 2, `missed in all ${data.store.missed}`);
    expect(JSON.stringify(data.store.gaps) === '[[1040,1200,2]]', `gaps ${JSON.stringify(data.store.gaps)}`);
  });

  check('a signal the recording carries comes from it up to where it is complete, then from the snapshots', () => {
    data.clear();
    data.addRows([row(1000, { v: 10 }), row(1020, { v: 20 }), row(1040, { v: 30 })], { askedAt: 1050, lost: 0, dropped: 0 });
    data.addSnapshot(snapshot(1, 1040, { velocity: 999 }), 0);
    data.addSnapshot(snapshot(2, 1080, { velocity: 40 }), 0);
    const v = data.series(signal('v')).map((p) => `${p.t}:${p.v}:${p.src}`).join(' ');
    expect(v === '1000:10:rec 1020:20:rec 1040:30:rec 1080:40:snap', `velocity ${v}`);
    // The set-point 0x60FF of pv comes from the snapshots alone.
    expect(data.series(signal('sp_vel')).length === 2, 'set-point from both snapshots');
    expect(data.series(signal('sp_pos')).length === 0, 'no 0x607A set-point outside pp and csp');
  });

  check('cursor values: analog interpolated between recorded samples, a state held', () => {
    expect(data.valueAt(signal('v'), 1010) === 15, `v at 1010 ${data.valueAt(signal('v'), 1010)}`);
    expect(data.valueAt(signal('state'), 1030) === 'READY_TO_SWITCH_ON', 'state held');
    expect(data.valueAt(signal('v'), 999) === null, 'nothing before the first sample');
  });

  check('transition, state, bit and level triggers fire on their exact row, after the arming time only', () => {
    data.clear();
    data.addRows([row(100), row(120, { cw: 7, transition: 3, state: 'SWITCHED_ON', sw: 0x233 }),
      row(137, { cw: 15, transition: 4, state: 'OPERATION_ENABLED', sw: 0x237 }),
      row(160, { cw: 15, transition: null, state: 'OPERATION_ENABLED', sw: 0x237, v: 400 }),
      row(180, { cw: 15, state: 'OPERATION_ENABLED', sw: 0x237, v: 600 })], { askedAt: 200, lost: 0, dropped: 0 });
    expect(findTrigger({ type: 'transition', number: 4 }, 0, 200) === 137, 'T4 at 137');
    expect(findTrigger({ type: 'transition', number: 4 }, 137, 200) === null, 'not again after 137');
    expect(findTrigger({ type: 'state', state: 'OPERATION_ENABLED' }, 0, 200) === 137, 'entering OE at 137');
    expect(findTrigger({ type: 'bit', word: 'cw', bit: 3, edge: 'rising' }, 0, 200) === 137, 'CW bit 3 rises at 137');
    expect(findTrigger({ type: 'bit', word: 'cw', bit: 3, edge: 'falling' }, 0, 200) === null, 'CW bit 3 never falls');
    expect(findTrigger({ type: 'level', signal: signal('v'), level: 500, edge: 'rising' }, 0, 200) === 180,
      'velocity at or over 500 first at 180');
    expect(findTrigger({ type: 'transition', number: 4 }, 0, 130) === null, 'nothing past the time looked to');
  });

  check('a single shot completes once the recording holds its window, then stops', () => {
    const acq = new acquisition();
    acq.arm('single', { type: 'transition', number: 4 }, 0.25, 0);
    acq.step(100);  // window 112..212: the recording is complete to 200 only
    expect(acq.capture && acq.capture.t === 137 && acq.capture.t0 === 112 && !acq.capture.complete,
      `filling ${JSON.stringify(acq.capture)}`);
    expect(!acq.stopped, 'not stopped while filling');
    data.addRows([row(230, { cw: 15, state: 'OPERATION_ENABLED', sw: 0x237, v: 700 })], { askedAt: 240, lost: 0, dropped: 0 });
    acq.step(100);
    expect(acq.capture.complete && acq.stopped, `complete and stopped ${JSON.stringify(acq.capture)}`);
  });

  check('rows the server no longer held when asked are counted as lost', () => {
    data.addRows([], { askedAt: 300, lost: 5, dropped: 12 });
    expect(data.store.lostRows === 5 && data.store.dropped === 12, `lost ${data.store.lostRows}, dropped ${data.store.dropped}`);
  });
  console.log(`# ${passed} scope logic checks passed`);
} catch (e) {
  console.error(`not ok ${passed + 1} - scope logic: ${e.message}`);
  process.exit(1);
}
