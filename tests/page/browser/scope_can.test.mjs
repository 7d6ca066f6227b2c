// The instrument page's scope in a real browser (Debian's chromium, headless, playwright-core) on a
// drive behind `cia402 serve --can` (node 1 of a `cia402 bus` over socketcand), issue 35: the
// page's cycle is the SYNC period, one sample of the drive's cycles each SYNC; a single-shot trigger
// on transition 4 captures around the T4 the server inferred from the status word, at the
// pre-trigger fraction; the cursors snap to the recording's T4 and T3 and read their difference in
// ms and in SYNC cycles; the captured window holds one sample per SYNC, every cycle once, T4 in the
// sample of the SYNC that followed the status word it was inferred from. The expected times come
// from the server's own recording (/api/recording), info (/api/info) and cycle samples as the event
// stream brought them; no wait asserts a duration.
//
//   node scope_can.test.mjs CIA402_BINARY OUTPUT_DIR
// Environment: CIA402_NODE_MODULES (where npm ci put playwright-core), CIA402_CHROMIUM.
import {
  patience, startRun, expect, check, runInBrowser, startCanServer,
  stopServer, waitPresent, stopCleanly, pageProblems, enableByClicks, newTab,
} from './page_harness.mjs';
import { arm, cursorMs, cursorsFromTrigger, cycleMs, cyclesFilling, dataset, recording } from './scope_harness.mjs';

startRun('scope_can.test.mjs', ['CIA402_BINARY', 'OUTPUT_DIR']);

// The capture: single shot on transition 4, a quarter of the window before it, 50 ms a division.
const capture = { mode: 'single', type: 'transition', transition: 4, pre: 25, div: 50 };
const span = 10 * capture.div;
const before = (span * capture.pre) / 100;

// The times (ms) of the drive's cycles the page holds, newest last.
const cycleTimes = (page) => page.evaluate(async () => (await import('/scope_data.js')).store.cyc.map((r) => r.t));

runInBrowser(async (context) => {
  const { bus, server } = await startCanServer();
  const page = await newTab(context);
  const problems = pageProblems(page);
  await page.goto(server.url);
  await page.waitForSelector('#remote[data-status="running"]', { timeout: patience });
  await waitPresent(page, 'SWITCH_ON_DISABLED');

  let cycle = null;
  await check('--can: the page\'s cycle (/api/info cycle_us) is the SYNC period the drive\'s cycles come at', async () => {
    const info = await page.evaluate(async () => (await fetch('/api/info')).json());
    expect(info.backend === 'remote' && info.transitions_inferred === true, `info: ${JSON.stringify(info.remote)}`);
    cycle = await cycleMs(page);
    await page.waitForFunction(async () => (await import('/scope_data.js')).store.cyc.length >= 10, null,
      { timeout: patience, polling: 100 });
    const times = (await cycleTimes(page)).slice(-10);
    const steps = new Set(times.slice(1).map((t, i) => t - times[i]));
    expect(steps.size === 1 && steps.has(cycle), `cycle_us says ${cycle} ms; the samples came ${[...steps]} ms apart`);
  });

  let t4 = null;
  let t3 = null;
  await check('--can: single shot on transition 4 captures around the inferred T4, the trigger at the pre-trigger fraction', async () => {
    await arm(page, capture);
    await enableByClicks(page);
    await page.waitForSelector('#scope-status[data-state="stopped"]', { timeout: patience });
    const rec = await recording(page);
    const fired = rec.transitions.filter((t) => t.number === 4);
    expect(fired.length === 1 && fired[0].inferred === true,
      `one T4 in the recording, inferred from the status word: ${JSON.stringify(rec.transitions)}`);
    t4 = fired[0].time_ms;
    t3 = rec.transitions.find((t) => t.number === 3).time_ms;
    const d = await dataset(page);
    expect(d.trigger === t4, `trigger at ${d.trigger}, the recording's T4 at ${t4}`);
    expect(d.span === span, `${capture.div} ms/div is a span of ${span} ms, not ${d.span}`);
    expect(d.t0 === t4 - before && d.t1 === t4 + span - before,
      `window ${d.t0}..${d.t1}: ${capture.pre} % of it before ${t4}`);
    expect(d.samples > 0, `${d.samples} samples shown`);
  });

  await check('--can: cursors snap to T4 and T3 and read their difference in ms and in SYNC cycles', async () => {
    const at = await cursorsFromTrigger(page, t4, t3);
    expect(at.a === t4, `cursor A at ${at.a}, T4 at ${t4}`);
    expect(at.b === t3, `cursor B at ${at.b}, T3 at ${t3}`);
    const dt = await cursorMs(page, 'cursor-dt');
    expect(dt === t3 - t4, `Δt ${dt}, the recording says ${t3 - t4}`);
    // In cycles of the SYNC period, as the readout rounds them (three decimals).
    const text = await page.textContent('#cursor-dt');
    expect(text.includes(`= ${+((t3 - t4) / cycle).toFixed(3)} cycles`), `Δt in ${cycle} ms cycles: "${text}"`);
  });

  await check('--can: the captured window holds one sample per SYNC, every cycle once, T4 in the SYNC after its status word', async () => {
    // The capture's window (the cursor check may have panned the view since).
    const rows = await cyclesFilling(page, t4 - before, t4 + span - before, cycle);
    const at = rows.filter((r) => r[2] === 4);
    // The status word that showed OPERATION ENABLED came with a TPDO after a SYNC; the transition
    // goes into the sample taken at the next SYNC: the first at or after the recording's T4.
    const next = rows.find((r) => r[1] >= t4);
    expect(at.length === 1 && at[0] === next && at[0][3] === 'OPERATION_ENABLED',
      `T4 in the cycle samples at ${JSON.stringify(at)}, the recording's T4 at ${t4}, the next SYNC's sample ${JSON.stringify(next)}`);
    const i = rows.indexOf(at[0]);
    expect(i > 0 && rows[i - 1][3] === 'SWITCHED_ON', `the SYNC before shows ${i > 0 && rows[i - 1][3]}`);
  });

  await check('--can: no errors in the browser console', async () => {
    expect(problems.length === 0, `console errors: ${JSON.stringify(problems)}`);
  });
  await page.close();
  await stopCleanly(server, 'serve');
  await stopServer(bus);
});
