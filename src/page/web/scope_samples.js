// The drive's cycles as the event stream brings them (SSE event `samples`, src/page/sample_ring.hpp):
// one sample per cycle of the link, numbered without a gap, in batches of run-length coded columns.
// decodeBatch() turns a batch back into rows; a batch that starts after the number expected is the
// samples the page never got (the browser or the connection fell behind the server's ring).

// Column name -> the key a row has (the recording's keys where it has the same signal).
const KEYS = {
  status_word: 'sw', control_word: 'cw', state: 'stateNumber', transition: 'transition',
  velocity: 'v', position: 'pos', torque: 'tq', following_error: 'fe', set_point: 'sp',
  position_demand: 'pd', digital_inputs: 'di', mode: 'mode', error_code: 'err',
};

/** Expands run-length pairs [value, count, ...] into `n` values. */
export function expandRuns(runs, n) {
  const out = new Array(n);
  let at = 0;
  for (let k = 0; k + 1 < runs.length && at < n; k += 2) {
    for (let c = 0; c < runs[k + 1] && at < n; c++) out[at++] = runs[k];
  }
  while (at < n) out[at++] = null;
  return out;
}

/**
 * A batch as rows {n, t (ms, the drive's time), sw, cw, stateNumber, state, transition, v, pos, tq,
 * fe, sp, pd, di, mode, err}; `states` names the state numbers (/api/info's states).
 */
export function decodeBatch(batch, states = []) {
  const n = batch.n;
  const times = new Array(n);
  let t = batch.t0;
  let i = 0;
  if (n > 0) times[i++] = t;
  for (let k = 0; k + 1 < batch.dt.length; k += 2) {
    for (let c = 0; c < batch.dt[k + 1] && i < n; c++) {
      t += batch.dt[k];
      times[i++] = t;
    }
  }
  const rows = [];
  for (let q = 0; q < n; q++) rows.push({ n: batch.from + q, t: times[q] / 1000 });
  for (const [name, runs] of Object.entries(batch.columns || {})) {
    const key = KEYS[name];
    if (!key) continue;
    const values = expandRuns(runs, n);
    for (let q = 0; q < n; q++) rows[q][key] = values[q];
  }
  for (const r of rows) r.state = r.stateNumber === null || r.stateNumber === undefined ? null : (states[r.stateNumber] ?? null);
  return rows;
}

/**
 * The samples skipped before a batch: how many numbers lie between the one expected and the
 * batch's first (0 for the first batch, or when none were skipped).
 */
export function skippedBefore(expected, batch) {
  if (expected === null || expected === undefined) return 0;
  return batch.from > expected ? batch.from - expected : 0;
}
