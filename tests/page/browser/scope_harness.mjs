// What the scope's browser tests share (scope.test.mjs on the local virtual drive,
// scope_can.test.mjs on a drive behind `cia402 serve --can`): the server's own recording and info
// as the page can fetch them, the plot's and the cursors' readings, arming a trigger, and the
// drive's cycles the page holds for a window, checked to fill it one sample per cycle.
import { expect, patience } from './page_harness.mjs';

/** The server's recording (GET /api/recording), as the page could fetch it. */
export function recording(page) {
  return page.evaluate(async () => (await fetch('/api/recording')).json());
}

/** The time of one cycle of the drive in ms (GET /api/info's cycle_us). */
export async function cycleMs(page) {
  return (await page.evaluate(async () => (await fetch('/api/info')).json())).cycle_us / 1000;
}

/** What the plot shows: its window, span, trigger and where it is drawn (#plot's data-*). */
export function dataset(page) {
  return page.evaluate(() => {
    const d = document.getElementById('plot').dataset;
    return { t0: Number(d.t0), t1: Number(d.t1), span: Number(d.span), samples: Number(d.samples),
      trigger: d.trigger === '' ? null : Number(d.trigger), left: Number(d.left), width: Number(d.width) };
  });
}

/** A cursor readout's time in ms (data-ms), null where it is not placed. */
export function cursorMs(page, id) {
  return page.evaluate((i) => {
    const v = document.getElementById(i).dataset.ms;
    return v === '' ? null : Number(v);
  }, id);
}

/** Sets the trigger controls as `settings` says and arms; returns once the scope says "armed". */
export async function arm(page, settings) {
  await page.selectOption('#trig-mode', settings.mode);
  await page.selectOption('#trig-type', settings.type);
  if (settings.transition !== undefined) await page.selectOption('#trig-transition', String(settings.transition));
  if (settings.signal) await page.selectOption('#trig-signal', settings.signal);
  if (settings.bit) await page.selectOption('#trig-bit', settings.bit);
  if (settings.level !== undefined) await page.fill('#trig-level', String(settings.level));
  if (settings.edge) await page.selectOption('#trig-edge', settings.edge);
  await page.fill('#trig-pre', String(settings.pre));
  await page.selectOption('#scope-div', String(settings.div));
  await page.click('#trig-arm');
  await page.waitForFunction(() => document.getElementById('scope-status').textContent.includes('armed'),
    null, { timeout: patience });
}

/**
 * Cursor A on the trigger's line (a click there), then B stepped back edge by edge with ◀ until it
 * is at or before `before`; returns the times A and B read.
 */
export async function cursorsFromTrigger(page, trigger, before) {
  const d = await dataset(page);
  const x = d.left + ((trigger - d.t0) / (d.t1 - d.t0)) * d.width;
  await page.click('#plot', { position: { x: Math.round(x), y: 60 } });
  await page.waitForFunction(() => document.getElementById('cursor-a-time').dataset.ms !== '', null, { timeout: patience });
  for (let i = 0; i < 40; i++) {
    const b = await cursorMs(page, 'cursor-b-time');
    if (b !== null && b <= before) break;
    await page.click('#cur-b-prev');
    await page.waitForFunction((old) => document.getElementById('cursor-b-time').dataset.ms !== String(old ?? ''),
      b, { timeout: patience });
  }
  return { a: await cursorMs(page, 'cursor-a-time'), b: await cursorMs(page, 'cursor-b-time') };
}

/**
 * The drive's cycles the page holds in [t0, t1] as [number, time, transition, state], after
 * checking that none were skipped and that they fill the window: numbered without a gap or a
 * repeat, one cycle (`cycle` ms) apart, the first and the last less than a cycle from its ends.
 */
export async function cyclesFilling(page, t0, t1, cycle) {
  const got = await page.evaluate(async ([from, to]) => {
    const { store } = await import('/scope_data.js');
    return { skipped: store.skipped,
      rows: store.cyc.filter((r) => r.t >= from && r.t <= to).map((r) => [r.n, r.t, r.transition, r.state]) };
  }, [t0, t1]);
  const rows = got.rows;
  expect(got.skipped === 0, `${got.skipped} samples skipped`);
  expect(rows.length > 1 && rows[0][1] - t0 < cycle && t1 - rows.at(-1)[1] < cycle,
    `${rows.length} cycle samples in ${t0}..${t1} (${rows.length && rows[0][1]}..${rows.length && rows.at(-1)[1]}), ` +
    `one per ${cycle} ms expected from end to end`);
  const broken = rows.findIndex((r, i) => i > 0 && (r[0] !== rows[i - 1][0] + 1 || r[1] !== rows[i - 1][1] + cycle));
  expect(broken < 0, `numbered and timed without a gap: ${JSON.stringify(rows.slice(Math.max(0, broken - 1), broken + 1))}`);
  return rows;
}
