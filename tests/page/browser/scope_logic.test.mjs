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
globalThis.EventSource = class {
  constructor(url) { this.url = url; this.listeners = {}; sources.push(this); }
  addEventListener(type, fn) { this.listeners[type] = fn; }
};

const load = (name) => import(pathToFileURL(path.join(web, name)).href);
const { page } = await load('page.js');
const { connect } = await load('stream.js');
const data = await load('scope_data.js');
const { acquisition, findTrigger } = await load('scope_trigger.js');
const { decodeBatch } = await load('scope_samples.js');

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
  publish_ms: 40, cycle_us: 1000, states: ['START', 'NOT_READY_TO_SWITCH_ON', 'SWITCH_ON_DISABLED',
    'READY_TO_SWITCH_ON', 'SWITCHED_ON', 'OPERATION_ENABLED', 'QUICK_STOP_ACTIVE', 'FAULT_REACTION_ACTIVE', 'FAULT'],
  objects: [{ index: '0x607A', name: 'target position' }],
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
  // A batch of the drive's cycles as sample_ring.cpp writes it: 6 cycles of 1 ms from 2.000 s,
  // T4 in the fourth, an index pulse in the fifth, the torque never given.
  const batch = (from, t0Us, extra = {}) => ({
    from, n: 6, t0: t0Us, dt: [1000, 5], polled: ['torque'],
    columns: {
      status_word: [0x233, 3, 0x237, 3], control_word: [7, 2, 15, 4], state: [4, 3, 5, 3],
      transition: [null, 3, 4, 1, null, 2], velocity: [0, 3, 5, 1, 9, 2], position: [10, 1, 11, 1, 12, 4],
      torque: [null, 6], following_error: [0, 6], set_point: [100, 6], position_demand: [10, 6],
      digital_inputs: [4, 4, 65540, 1, 4, 1], mode: [3, 6], error_code: [0, 6],
    },
    ...extra,
  });

  check('a batch of the drive\'s cycles decodes to one row per cycle with its number, time and values', () => {
    const rows = decodeBatch(batch(40, 2000000), page.info.states);
    expect(rows.length === 6, `rows ${rows.length}`);
    expect(rows.map((r) => r.n).join(',') === '40,41,42,43,44,45', 'numbered');
    expect(rows.map((r) => r.t).join(',') === '2000,2001,2002,2003,2004,2005', `times ${rows.map((r) => r.t)}`);
    expect(rows.map((r) => r.v).join(',') === '0,0,0,5,9,9', `velocity ${rows.map((r) => r.v)}`);
    expect(rows[3].transition === 4 && rows[2].transition === null, 'T4 in the fourth only');
    expect(rows[3].state === 'OPERATION_ENABLED' && rows[2].state === 'SWITCHED_ON', 'state names');
    expect(rows[0].tq === null, 'a value not given is null');
    expect(rows.map((r) => (r.di >> 16) & 1).join('') === '000010', 'index pulse in the fifth');
  });

  check('batches in a row are all kept; a batch after a gap counts the samples skipped and marks the span', () => {
    data.clear();
    const source = sources[sources.length - 1];
    connect(() => {}, data.addSamples);
    const latest = sources[sources.length - 1];
    expect(latest !== source && latest.listeners.samples, 'the stream listens for samples');
    latest.listeners.samples({ data: JSON.stringify(batch(40, 2000000)) });
    latest.listeners.samples({ data: JSON.stringify(batch(46, 2006000)) });
    expect(data.store.cyc.length === 12 && data.store.skipped === 0, `kept ${data.store.cyc.length}, skipped ${data.store.skipped}`);
    latest.listeners.samples({ data: JSON.stringify(batch(100, 2060000)) });  // 52..99 never came
    expect(data.store.skipped === 48, `skipped ${data.store.skipped}`);
    expect(JSON.stringify(data.store.cycGaps) === '[[2011,2060,48]]', `gaps ${JSON.stringify(data.store.cycGaps)}`);
    expect(data.store.polled.join() === 'torque', 'the polled columns named');
  });

  check('where the drive\'s cycles are, a signal comes from them: the recording before, the snapshots after', () => {
    data.clear();
    data.addRows([row(1990, { v: 1 }), row(2002, { v: 777 })], { askedAt: 2010, lost: 0, dropped: 0 });
    data.addSamples(batch(200, 2000000));
    data.addSnapshot(snapshot(20, 2040, { velocity: 50 }), 0);
    const v = data.series(signal('v')).map((p) => `${p.t}:${p.v}:${p.src}`).join(' ');
    expect(v === '1990:1:rec 2000:0:cyc 2001:0:cyc 2002:0:cyc 2003:5:cyc 2004:9:cyc 2005:9:cyc 2040:50:snap', `velocity ${v}`);
    // The set-point of pv (mode 3) and the following error every cycle, where snapshots had none.
    expect(data.series(signal('sp_vel')).filter((p) => p.src === 'cyc').length === 6, 'pv set-point each cycle');
    expect(data.series(signal('fe')).filter((p) => p.src === 'cyc').length === 6, 'following error each cycle');
    const index = data.series(signal('di16')).map((p) => p.v).join('');
    expect(index === '000010', `index pulse ${index}`);
    expect(data.valueAt(signal('v'), 2003.5) === 7, `interpolated between cycles ${data.valueAt(signal('v'), 2003.5)}`);
  });

  check('a level trigger on a recorded signal fires on the cycle sample, not the later recorded row', () => {
    // The recording's row at 2002 says 777 (a row 20 ms apart would be later still); the cycles say 5 at 2003.
    const t = findTrigger({ type: 'level', signal: signal('v'), level: 5, edge: 'rising' }, 1995, 2010);
    expect(t === 2003, `fired at ${t}`);
    expect(findTrigger({ type: 'level', signal: signal('v'), level: 9, edge: 'rising' }, 1995, 2010) === 2004, 'over 9 at 2004');
  });

  check('a trigger on the index pulse (0x60FD bit 16) fires on its cycle, rising and falling', () => {
    expect(findTrigger({ type: 'bit', word: 'di', bit: 16, edge: 'rising' }, 1995, 2010) === 2004, 'rises at 2004');
    expect(findTrigger({ type: 'bit', word: 'di', bit: 16, edge: 'falling' }, 1995, 2010) === 2005, 'falls at 2005');
    expect(findTrigger({ type: 'bit', word: 'di', bit: 16, edge: 'rising' }, 2004, 2010) === null, 'not again');
    expect(findTrigger({ type: 'bit', word: 'di', bit: 2, edge: 'either' }, 1995, 2010) === null, 'the home switch stays on');
  });
  check('a long window is drawn from a bounded number of cycle samples, keeping a one-cycle pulse and a peak', () => {
    data.clear();
    const n = 20000;
    data.addSamples({ from: 100000, n, t0: 10000000, dt: [1000, n - 1], polled: [], columns: {
      digital_inputs: [4, 12345, 65540, 1, 4, n - 12346], velocity: [0, 10000, 900, 1, 0, n - 10001] } });
    const t0 = 10000, t1 = 10000 + n;
    const drawnV = data.series(signal('v'), t0, t1, data.DRAWN_CYCLES);
    const drawnPulse = data.series(signal('di16'), t0, t1, data.DRAWN_CYCLES);
    expect(drawnV.length <= data.DRAWN_CYCLES + 8 && drawnPulse.length <= data.DRAWN_CYCLES + 8,
      `${drawnV.length} and ${drawnPulse.length} points drawn`);
    expect(drawnV.some((p) => p.v === 900 && p.t === 20000), 'the velocity peak is drawn at its cycle');
    expect(drawnPulse.some((p) => p.v === 1 && p.t === 22345), 'the index pulse is drawn at its cycle');
    expect(drawnPulse.every((p, i) => i === 0 || p.t > drawnPulse[i - 1].t), 'in time order');
    expect(data.series(signal('v'), t0, t1).length === n, 'the export has every cycle');
  });
  check('the level trigger lists each object once', () => {
    const saved = page.info.objects;
    page.info.objects = [{ index: '0x607A', name: 'target position' }, { index: '0x6081', name: 'profile velocity' },
      { index: '0x6064', name: 'position actual value' }];
    const levels = data.levelSignals(data.catalogue());
    page.info.objects = saved;
    const objects = levels.map((s) => (s.label.match(/0x[0-9A-F]{4}/) || [null])[0]).filter((o) => o !== null);
    expect(objects.length === new Set(objects).size, `an object twice: ${objects.join(' ')}`);
    expect(levels.some((s) => s.key === 'tv') && !levels.some((s) => s.key === 'sp_vel'),
      '0x60FF as the object, not its set-point view');
    expect(levels.some((s) => s.key === 'pos') && !levels.some((s) => s.key === 'obj0x6064'), '0x6064 once');
    expect(levels.some((s) => s.key === 'obj0x6081') && levels.some((s) => s.key === 'sp_pos'),
      'the others kept');
    expect(!levels.some((s) => s.kind === 'bit' || s.kind === 'state'), 'levels only');
  });
  console.log(`# ${passed} scope logic checks passed`);
} catch (e) {
  console.error(`not ok ${passed + 1} - scope logic: ${e.message}`);
  process.exit(1);
}
