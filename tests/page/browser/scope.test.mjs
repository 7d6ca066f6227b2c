// The instrument page's scope in a real browser (Debian's chromium, headless, playwright-core)
// against `cia402 serve --port 0`: a single-shot trigger on a transition captures the samples
// around it, the cursors snap to the recording's edges and their difference is the recording's to
// the cycle, the drive's cycles fill the captured window one sample per cycle with the transition
// in its cycle's sample, zoom changes the span shown, a level trigger fires at the drive's first
// cycle over the level, the CSV export of the view holds the rows the view shows, a status bit's
// edge triggers on the transition's cycle, homing on the index pulse (method 33: negative, the
// shaft stands past the positive limit switch by then) triggers the scope on the pulse's cycle
// (0x60FD bit 16), and the first load stays under 300 KB. The expected times come from the
// server's own recording (/api/recording) or its cycle samples as the event stream brought them;
// no wait asserts a duration.
//
//   node scope.test.mjs CIA402_BINARY OUTPUT_DIR
// Environment: CIA402_NODE_MODULES (where npm ci put playwright-core), CIA402_CHROMIUM.
import fs from 'node:fs';
import { createRequire } from 'node:module';
import os from 'node:os';
import path from 'node:path';
import { arm as armOn, cursorMs as cursorOf, cursorsFromTrigger, cyclesFilling, cycleMs as cycleOf, dataset as datasetOf,
  recording as recordingOf } from './scope_harness.mjs';
import { enableByClicks, pageProblems, startRun, startServer } from './page_harness.mjs';

const [, outDir] = startRun('scope.test.mjs', ['CIA402_BINARY', 'OUTPUT_DIR']);
const modules = path.resolve(process.env.CIA402_NODE_MODULES || 'node_modules');
const { chromium } = createRequire(path.join(modules, 'resolve-from-here.js'))('playwright-core');

// Generous: a wait ends as soon as its condition holds, so only a failing check pays for it.
const patience = 30000;
let passed = 0;
let server = null;
let context = null;
let page = null;

function expect(condition, message) {
  if (!condition) throw new Error(message);
}

async function check(name, fn) {
  await fn();
  passed += 1;
  console.log(`ok ${passed} - scope: ${name}`);
}

// The helpers of scope_harness.mjs on this script's page.
const recording = () => recordingOf(page);
const dataset = () => datasetOf(page);
const cursorMs = (id) => cursorOf(page, id);
const arm = (settings) => armOn(page, settings);

async function command(key) {
  await page.click(`button[data-command="${key}"]`);
}

async function waitState(state) {
  await page.waitForSelector(`#diagram [id="state.${state}"].present`, { timeout: patience });
}

async function download(id) {
  const [d] = await Promise.all([page.waitForEvent('download'), page.click(`#${id}`)]);
  const file = path.join(outDir, d.suggestedFilename());
  await d.saveAs(file);
  return file;
}

async function main() {
  server = await startServer([]);
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'cia402-scope-'));
  context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: process.env.CIA402_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    viewport: { width: 1280, height: 900 },
    acceptDownloads: true,
  });
  page = context.pages()[0] || await context.newPage();
  const problems = pageProblems(page);
  // The first request for one module fails, as Chromium fails the requests in flight when the
  // machine's network interfaces change: the page must load anyway (boot.js reloads it).
  let aborted = 0;
  await page.route('**/words.js', (route) => (aborted++ === 0 ? route.abort('failed') : route.continue()));
  await page.goto(server.url);
  await check('a module that did not arrive once does not leave the page dead', async () => {
    await waitState('SWITCH_ON_DISABLED');
    expect(aborted >= 2, `words.js asked for ${aborted} times`);
  });
  await page.unroute('**/words.js');
  problems.length = 0;  // the aborted request's console error was the point

  await check('the first load (the page and its modules, as embedded) stays under 300 KB', async () => {
    const load = await page.evaluate(() => {
      const files = [...performance.getEntriesByType('navigation'), ...performance.getEntriesByType('resource')]
        .filter((e) => !e.name.includes('/api/'));
      // Decoded: the files' own size, whether or not the server compressed them on the wire.
      return { bytes: files.reduce((sum, e) => sum + e.decodedBodySize, 0),
        wire: files.reduce((sum, e) => sum + e.encodedBodySize, 0), files: files.length };
    });
    console.log(`# first load: ${load.files} files, ${load.bytes} bytes (${load.wire} on the wire)`);
    expect(load.files >= 4 && load.bytes > 0 && load.bytes < 300 * 1024, `first load ${JSON.stringify(load)}`);
  });

  let t4 = null;
  await check('single shot on transition 4 captures the samples around it, the trigger at the pre-trigger fraction', async () => {
    await arm({ mode: 'single', type: 'transition', transition: 4, pre: 50, div: 20 });
    await enableByClicks(page, (p, state) => waitState(state));
    await page.waitForSelector('#scope-status[data-state="stopped"]', { timeout: patience });
    const rec = await recording();
    const fired = rec.transitions.filter((t) => t.number === 4);
    expect(fired.length === 1, `one T4 in the recording: ${JSON.stringify(rec.transitions)}`);
    t4 = fired[0].time_ms;
    const d = await dataset();
    expect(d.trigger === t4, `trigger at ${d.trigger}, the recording's T4 at ${t4}`);
    expect(d.span === 200, `20 ms/div is a span of 200 ms, not ${d.span}`);
    expect(d.t0 === t4 - 100 && d.t1 === t4 + 100, `window ${d.t0}..${d.t1} around ${t4}`);
    // The recording's rows on either side of the trigger are in the view.
    const rows = rec.rows.filter((r) => r[0] >= d.t0 && r[0] <= d.t1);
    expect(rows.some((r) => r[0] < t4) || rec.rows.some((r) => r[0] < d.t0), 'something before the trigger');
    expect(d.samples >= rows.length && d.samples > 0, `${d.samples} samples shown, ${rows.length} recording rows in the window`);
  });

  let t3 = null;
  await check('cursors snap to the transitions and read their difference to the cycle', async () => {
    // A click on the trigger's line puts cursor A on the transition's cycle; B steps back edge by
    // edge (transitions and word changes) to transition 3.
    t3 = (await recording()).transitions.find((t) => t.number === 3).time_ms;
    const at = await cursorsFromTrigger(page, t4, t3);
    expect(at.a === t4, `cursor A at ${at.a}, T4 at ${t4}`);
    expect(await cursorMs('cursor-b-time') === t3, `cursor B at ${await cursorMs('cursor-b-time')}, T3 at ${t3}`);
    // Read from the trigger, as the time axis: A on the trigger is 0, B on T3 before it negative.
    const aText = await page.textContent('#cursor-a-time');
    const bText = await page.textContent('#cursor-b-time');
    expect(aText === '0.000 s', `cursor A reads "${aText}" on the trigger`);
    expect(bText === `${((t3 - t4) / 1000).toFixed(3)} s`, `cursor B reads "${bText}", ${t3 - t4} ms from the trigger`);
    expect(await cursorMs('cursor-dt') === t3 - t4, `Δt ${await cursorMs('cursor-dt')}, the recording says ${t3 - t4}`);
    const cycleMs = await cycleOf(page);
    const text = await page.textContent('#cursor-dt');
    expect(text.includes(`${(t3 - t4) / cycleMs} cycles`), `Δt in cycles: "${text}"`);
  });

  await check("the drive's cycles fill the captured window: every cycle once, T4 in the sample of its cycle", async () => {
    // The capture's window (the cursor check may have panned the view since).
    const d = { t0: t4 - 100, t1: t4 + 100 };
    const rows = await cyclesFilling(page, d.t0, d.t1, await cycleOf(page));
    const at = rows.filter((r) => r[2] === 4);
    expect(at.length === 1 && at[0][1] === t4 && at[0][3] === 'OPERATION_ENABLED',
      `T4 in the cycle samples at ${JSON.stringify(at)}, the recording's T4 at ${t4}`);
    // The cursor difference from T3 to T4 in the cycles equals the recording's, to the cycle.
    const t3row = rows.find((r) => r[2] === 3);
    if (t3row) expect(t4 - t3row[1] === t4 - t3, `T3 at ${t3row[1]} in the cycles, ${t3} in the recording`);
  });

  await check('zoom changes the time span shown', async () => {
    await page.click('#scope-live');
    await page.selectOption('#scope-div', '100');
    await page.waitForFunction(() => document.getElementById('plot').dataset.span === '1000', null, { timeout: patience });
    await page.click('#scope-zoom-out');
    await page.waitForFunction(() => document.getElementById('plot').dataset.span === '2000', null, { timeout: patience });
    await page.click('#scope-zoom-in');
    await page.click('#scope-zoom-in');
    await page.waitForFunction(() => document.getElementById('plot').dataset.span === '500', null, { timeout: patience });
    expect((await page.inputValue('#scope-div')) === '50', 'the time base follows the zoom');
  });

  await check("a level trigger fires at the drive's first cycle with the velocity over the level", async () => {
    await arm({ mode: 'single', type: 'level', signal: 'v', level: 500, edge: 'rising', pre: 25, div: 200 });
    const armedAt = (await recording()).rows.at(-1)[0];
    await page.fill('#target-input', '1500');
    await page.click('#target-form button[type="submit"]');
    await page.waitForSelector('#scope-status[data-state="stopped"]', { timeout: patience });
    // The cycles as the server sent them (its sample ring over the event stream); the recording's
    // rows keep the velocity only every 20 ms, so its first row over the level may come later.
    const cycles = await page.evaluate(async () => (await import('/scope_data.js')).store.cyc.map((r) => [r.t, r.v]));
    const first = cycles.find((r, i) => i > 0 && r[0] > armedAt && r[1] >= 500 && cycles[i - 1][1] < 500);
    const rec = await recording();
    const firstRow = rec.rows.find((r, i) => i > 0 && r[0] > armedAt && r[5] >= 500 && rec.rows[i - 1][5] < 500);
    const d = await dataset();
    expect(first && d.trigger === first[0], `trigger at ${d.trigger}, the first cycle over 500 rpm: ${JSON.stringify(first)}`);
    expect(firstRow && firstRow[0] >= first[0] && firstRow[0] - first[0] <= 20, `the recording's first row over it at ${firstRow && firstRow[0]}`);
    expect(d.t0 === first[0] - 500 && d.span === 2000, `25 % of 2 s before the trigger: ${d.t0}..${d.t1}`);
  });

  await check('the CSV export of the view has the rows the view shows, in its window', async () => {
    const before = await page.evaluate(() => document.getElementById('plot').clientHeight);
    await page.check('input[data-signal="cw3"]');  // a control-word bit as a lane of its own
    await page.waitForFunction((h) => document.getElementById('plot').clientHeight > h, before, { timeout: patience });
    const d = await dataset();
    const text = fs.readFileSync(await download('scope-csv'), 'utf8').trim().split('\n');
    const header = text[0].split(',');
    expect(header[0] === 'time_ms' && header.includes('velocity 0x606C'), `header ${text[0]}`);
    const bit = header.findIndex((h) => h.startsWith('CW 3 '));
    expect(bit > 0 && text.slice(1).every((l) => l.split(',')[bit] === '1'), 'CW 3 (enable operation) is 1 throughout');
    const times = text.slice(1).map((l) => Number(l.split(',')[0]));
    expect(times.length === d.samples, `${times.length} CSV rows, ${d.samples} samples shown`);
    expect(times.every((t, i) => t >= d.t0 && t <= d.t1 && (i === 0 || t > times[i - 1])),
      `times rising within ${d.t0}..${d.t1}`);
    expect(times.includes(d.trigger), 'the trigger sample is a row');
    const png = fs.readFileSync(await download('scope-png'));
    expect(png.subarray(1, 4).toString() === 'PNG', 'the PNG export is a PNG');
  });

  await check("a trigger on a status bit's falling edge fires on the cycle of the transition that clears it", async () => {
    await arm({ mode: 'single', type: 'bit', bit: 'sw2', edge: 'falling', pre: 50, div: 50 });
    await command('disable_operation');
    await waitState('SWITCHED_ON');
    await page.waitForSelector('#scope-status[data-state="stopped"]', { timeout: patience });
    const t5 = (await recording()).transitions.find((t) => t.number === 5);
    const d = await dataset();
    expect(t5 && d.trigger === t5.time_ms, `trigger at ${d.trigger}, T5 (operation enabled bit 2 falls) at ${t5 && t5.time_ms}`);
  });

  await check("homing on the index pulse (method 33) triggers the scope on the pulse's cycle", async () => {
    const post = (pathName, body) => page.evaluate(async ([u, b]) => (await fetch(u, {
      method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(b) })).status,
    [pathName, body]);
    expect(await post('/api/object', { index: '0x6098', value: 33 }) === 200, 'method 33 written');
    expect(await post('/api/object', { index: '0x6060', value: 6 }) === 200, 'homing mode written');
    await command('enable_operation');
    await waitState('OPERATION_ENABLED');
    await page.waitForFunction(async () => {
      const { store } = await import('/scope_data.js');
      return store.cyc.length && store.cyc[store.cyc.length - 1].mode === 6;
    }, null, { timeout: patience, polling: 100 });
    const startedAt = await page.evaluate(async () => {
      const { store } = await import('/scope_data.js');
      return store.cyc[store.cyc.length - 1].t;
    });
    await page.check('input[data-signal="di16"]');
    await arm({ mode: 'single', type: 'bit', bit: 'di16', edge: 'rising', pre: 50, div: 10 });
    expect(await post('/api/command', { command: 'toggle_bit', bit: 4 }) === 200, 'homing started (bit 4)');
    try {
      await page.waitForSelector('#scope-status[data-state="stopped"]', { timeout: patience });
    } catch (e) {
      // What the page had: a trigger that did not fire told from a homing that did not run.
      const dump = await page.evaluate(async (from) => {
        const { store } = await import('/scope_data.js');
        const runs = [];
        for (const r of store.cyc.filter((c) => c.t >= from)) {
          const k = `${r.di}/${r.mode}/${r.cw}/${r.pos}`;
          if (!runs.length || runs[runs.length - 1][1] !== k) runs.push([r.t, k]);
        }
        return { status: document.getElementById('scope-status').textContent,
          bit: document.getElementById('trig-bit').value, runs: runs.slice(0, 40) };
      }, startedAt);
      throw new Error(`${e.message}: ${JSON.stringify(dump)}`);
    }
    // The first cycle after the start with the pulse, as the server's cycles say.
    const pulses = await page.evaluate(async (from) => {
      const { series, catalogue } = await import('/scope_data.js');
      const index = catalogue().find((sig) => sig.key === 'di16');
      return series(index, from).filter((p) => p.src === 'cyc').map((p) => [p.t, p.v]);
    }, startedAt);
    const first = pulses.find((p, i) => i > 0 && p[1] === 1 && pulses[i - 1][1] === 0);
    const d = await dataset();
    expect(first && d.trigger === first[0], `trigger at ${d.trigger}, the first index pulse at ${first && first[0]}`);
  });

  await check('no errors in the browser console', async () => {
    expect(problems.length === 0, `console errors: ${JSON.stringify(problems)}`);
  });
  // The picture for docs/instrument-page.md: cursor A on the trigger, B late in the ramp.
  const d = await dataset();
  await page.click('#cur-clear');
  await page.click('#plot', { position: { x: Math.round(d.left + 0.25 * d.width), y: 60 } });
  await page.click('#plot', { position: { x: Math.round(d.left + 0.6 * d.width), y: 60 } });
  await page.waitForFunction(() => document.getElementById('cursor-dt').dataset.ms !== '', null, { timeout: patience });
  const scopePanel = await page.$('.panel-scope');
  await scopePanel.screenshot({ path: path.join(outDir, 'scope-1280.png') });

  await context.close();
  fs.rmSync(userDataDir, { recursive: true, force: true });
  server.proc.kill('SIGINT');
  console.log(`# ${passed} scope checks passed`);
}

main().then(() => process.exit(0), async (e) => {
  console.error(`not ok ${passed + 1} - scope: ${e.message}`);
  try {
    if (page) await page.screenshot({ path: path.join(outDir, 'scope-failure.png'), fullPage: true });
  } catch { /* the page may be gone */ }
  if (server) {
    server.proc.kill('SIGKILL');
    console.error(`--- cia402 serve output ---\n${server.output}`);
  }
  if (context) await context.close().catch(() => {});
  process.exit(1);
});
