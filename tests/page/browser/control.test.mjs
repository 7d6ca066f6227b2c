// The page's control model in a real browser (issue 42; docs/instrument-page.md, "Control model"
// and "Sign of life"), against `cia402 serve --nodes 3`:
//   (a) a fresh serve that no page has opened reports no lost sign of life;
//   (d) the jog buttons are off outside OPERATION ENABLED, with the reason beside them;
//   (b) page A enables axis 1 and sets it turning, then shows axis 2 (and runs it too): for three
//       lease times axis 1 keeps turning, the page says which axes it holds;
//   (c) page B (another browser context) on axis 1 sees it held elsewhere, its jog is refused and
//       the refusal stays shown; B takes control with the button, A then sees axis 1 held elsewhere;
//   (e) closing A's tab lets the lease of the axis it holds (2) lapse: it is stopped as 0x6007 says,
//       within the documented bound, while axis 1 (held by B) turns on; closing B stops axis 1.
//
// Every time comes from the server: its drive time (`time_ms`), the lease (`/api/info` lease_ms),
// the recording's transition times. The test watches the drives only through requests that renew
// nothing: `/api/axes`, `/api/recording`, and `/api/state` under a client id of its own that holds
// no axis (a request without one would renew the lease it is watching).
//
//   node control.test.mjs CIA402_BINARY OUTPUT_DIR
// Environment: CIA402_NODE_MODULES (where npm ci put playwright-core), CIA402_CHROMIUM.
import { createRequire } from 'node:module';
import path from 'node:path';
import {
  patience, run, startRun, fail, expect, check, runChecks, startServer, waitPresent, stopCleanly, pageProblems, newTab,
} from './page_harness.mjs';

startRun('control.test.mjs', ['CIA402_BINARY', 'OUTPUT_DIR']);

const modules = path.resolve(process.env.CIA402_NODE_MODULES || 'node_modules');
const { chromium } = createRequire(path.join(modules, 'resolve-from-here.js'))('playwright-core');

const RPM_1 = 600;  // axis 1, set by page A, then 200 by page B
const RPM_2 = 300;  // axis 2, set by page A
const LOST = 'SIGN OF LIFE LOST';
// The sign of life's probe: a keep-alive at least every 250 ms, so a closed page is found at the
// second write after it (docs/instrument-page.md, "Sign of life", "The bound").
const PROBE_MS = 250;

let base = '';
// The watcher's own client id: a page that holds nothing, so its GET /api/state renews nothing.
const WATCHER = { 'X-Cia402-Client': 'control-test-watcher' };
const state = async (axis) => (await fetch(`${base}api/state?axis=${axis}`, { headers: WATCHER })).json();
const axes = async () => (await fetch(`${base}api/axes`)).json();
const axisOf = async (axis) => (await axes()).find((a) => a.axis === axis);
const recording = async (axis) => (await fetch(`${base}api/recording?axis=${axis}`)).json();
const turning = (a, rpm) => a.state === 'OPERATION_ENABLED' && Math.abs(a.velocity - rpm) < 1;
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Polls until `holds()` gives a truthy value; fails with `what` and `last()` after `timeout` ms.
async function until(holds, what, last = async () => '', timeout = patience) {
  const end = Date.now() + timeout;
  while (Date.now() < end) {
    const v = await holds();
    if (v) return v;
    await sleep(25);
  }
  fail(`${what} within ${timeout} ms; ${await last()}`);
  return null;
}

// Waits until the server's drive time has gone `ms` past `fromMs`; meanwhile `each()` must hold
// at every poll (it fails the check itself).
async function serverWait(fromMs, ms, each = async () => {}) {
  for (;;) {
    await each();
    const now = (await state(1)).time_ms;
    if (now >= fromMs + ms) return now;
    await sleep(50);
  }
}

async function openPage(context, axis) {
  const page = await newTab(context);
  const errors = pageProblems(page);
  page.errors = errors;
  await page.goto(`${base}?axis=${axis}`);
  await page.waitForSelector('#diagram .present', { timeout: patience });
  await page.waitForSelector('.axis-card', { timeout: patience });
  return page;
}

const resultLine = (page) => page.evaluate(() => {
  const r = document.getElementById('result');
  return { outcome: r.dataset.outcome || '', text: r.textContent };
});
const cardText = (page, axis) => page.textContent(`.axis-card[data-axis="${axis}"] .axis-more`);
const waitCard = (page, axis, words) => page.waitForFunction(([k, w]) => {
  const c = document.querySelector(`.axis-card[data-axis="${k}"] .axis-more`);
  return c && c.textContent.includes(w);
}, [axis, words], { timeout: patience }).catch(async () => {
  fail(`axis card ${axis} does not say "${words}": "${await cardText(page, axis)}"`);
});
const banner = (page) => page.evaluate(() => {
  const b = document.getElementById('control-banner');
  const take = document.getElementById('take-control');
  return { hidden: b.hidden, control: b.dataset.control || '', text: document.getElementById('control-text').textContent,
    take: !take.hidden && !take.disabled };
});
const waitBanner = (page, holds, what) => page.waitForFunction(holds, null, { timeout: patience })
  .catch(async () => fail(`${what}; the banner: ${JSON.stringify(await banner(page))}`));

// The page's Enable, then its target velocity form; both from the page's own controls.
async function enableAndTurn(page, axis, rpm) {
  await page.waitForSelector('#enable:not([disabled])', { timeout: patience });
  await page.click('#enable');
  await waitPresent(page, 'OPERATION_ENABLED');
  await page.fill('#target-input', String(rpm));
  await page.click('#target-form button[type="submit"]');
  await until(async () => turning(await axisOf(axis), rpm), `axis ${axis} did not reach ${rpm} rpm`,
    async () => JSON.stringify(await axisOf(axis)));
}

// The sign-of-life stop of one axis in the server's record: its result, and the cycle the quick
// stop (T11) began, after `fromMs`.
async function lostSignOfLife(axis, fromMs, lease) {
  const s = await until(async () => {
    const x = await state(axis);
    const r = x.results.find((e) => e.action.startsWith(LOST));
    return r && r.outcome === 'done' ? { x, r } : null;
  }, `axis ${axis} has no "${LOST}" result done`, async () => JSON.stringify((await state(axis)).results));
  const code = s.x.objects && s.x.objects['0x6007'];
  expect(s.r.action.startsWith(`${LOST} (no page for ${lease} ms, 0x6007 = ${code === undefined ? '' : code}`),
    `axis ${axis}: the stop names the lease ${lease} ms and 0x6007 = ${code}: "${s.r.action}"`);
  const stop = (await recording(axis)).transitions.find((t) => t.time_ms >= fromMs && t.from === 'OPERATION_ENABLED');
  expect(stop, `axis ${axis}: the recording has no transition out of OPERATION ENABLED after ${fromMs} ms`);
  return { result: s.r, stop };
}

runChecks(async () => {
  // A lease of 2 s, not the default 1 s: the test times every check from it, and a browser on a
  // loaded 2-core machine can miss a 1 s lease between two probes without any fault of the page.
  const server = await startServer(['--nodes', '3', '--lease', '2000']);
  base = server.url.split('?')[0];
  const info = await (await fetch(`${base}api/info`)).json();
  const lease = info.lease_ms;
  expect(info.axes === 3 && lease > 0, `/api/info: ${info.axes} axes, lease ${lease} ms`);

  await check(`(a) a fresh serve, no page for longer than the lease (${lease} ms): no axis reports a lost sign of life`, async () => {
    await serverWait(0, lease + 2 * PROBE_MS);
    for (const k of [1, 2, 3]) {
      const s = await state(k);
      expect(!s.results.some((r) => r.action.startsWith(LOST)), `axis ${k}: ${JSON.stringify(s.results)}`);
    }
  });

  const browser = await chromium.launch({
    executablePath: process.env.CIA402_CHROMIUM || '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  run.context = browser;  // closed on a failure
  // Two browser contexts: two users' tabs, nothing shared (storage, cookies, connections).
  const contextA = await browser.newContext({ viewport: { width: 1280, height: 800 } });
  const contextB = await browser.newContext({ viewport: { width: 1280, height: 800 } });
  let pageA = await openPage(contextA, 1);

  await check('(a) the first page opened shows no lost sign of life either', async () => {
    const shown = await pageText(pageA, '#result, #results');
    expect(!shown.includes(LOST), `page A shows "${shown}"`);
  });

  await check('(d) in SWITCH ON DISABLED the jog buttons are off, the reason beside them; Enable turns them on', async () => {
    const jog = () => pageA.evaluate(() => ({
      buttons: [...document.querySelectorAll('button.jog')].map((b) => ({ disabled: b.disabled, title: b.title })),
      note: document.getElementById('jog-note').hidden ? null : document.getElementById('jog-note').textContent,
    }));
    const off = await jog();
    const reason = 'jog runs in OPERATION ENABLED only (now SWITCH ON DISABLED): Enable first';
    expect(off.buttons.length === 4 && off.buttons.every((b) => b.disabled && b.title === reason),
      `the jog buttons: ${JSON.stringify(off.buttons)}`);
    expect(off.note === reason, `the note beside them: ${JSON.stringify(off.note)}`);
    await enableAndTurn(pageA, 1, RPM_1);
    await pageA.waitForFunction(() => [...document.querySelectorAll('button.jog')].every((b) => !b.disabled),
      null, { timeout: patience });
    const on = await jog();
    expect(on.note === null && on.buttons.every((b) => !b.title.includes('OPERATION ENABLED only')),
      `enabled: ${JSON.stringify(on)}`);
  });

  await check(`(b) page A shows axis 2 instead: axis 1 turns on for 3 lease times, the page says it holds axes 1 and 2`, async () => {
    await waitCard(pageA, 1, 'held here');
    await pageA.click('.axis-card[data-axis="2"]');
    await pageA.waitForURL(/axis=2/);
    await pageA.waitForSelector('#diagram .present', { timeout: patience });
    const from = (await state(1)).time_ms;
    await waitBanner(pageA, () => {
      const b = document.getElementById('control-banner');
      return !b.hidden && document.getElementById('control-text').textContent === 'This page controls axis 1.';
    }, 'page A on axis 2 does not say it controls axis 1');
    await enableAndTurn(pageA, 2, RPM_2);
    await waitBanner(pageA, () => document.getElementById('control-text').textContent === 'This page controls axis 1, axis 2.',
      'page A does not say it controls axes 1 and 2');
    await waitCard(pageA, 1, 'held here');
    await waitCard(pageA, 2, 'held here');
    await serverWait(from, 3 * lease, async () => {
      const a = await axes();
      expect(turning(a[0], RPM_1), `axis 1 stopped while page A showed axis 2: ${JSON.stringify(a[0])}`);
    });
    expect(turning(await axisOf(2), RPM_2), `axis 2: ${JSON.stringify(await axisOf(2))}`);
    const s1 = await state(1);
    expect(!s1.results.some((r) => r.action.startsWith(LOST)), `axis 1 lost its sign of life: ${JSON.stringify(s1.results)}`);
    expect(!(await recording(1)).transitions.some((t) => t.from === 'OPERATION_ENABLED'), 'axis 1 left OPERATION ENABLED');
  });

  let pageB = await openPage(contextB, 1);
  await check('(c) page B on axis 1 sees it controlled elsewhere; its jog is refused, the refusal stays shown', async () => {
    await waitBanner(pageB, () => document.getElementById('control-banner').dataset.control === 'elsewhere',
      'page B does not see axis 1 controlled elsewhere');
    const b = await banner(pageB);
    expect(!b.hidden && b.take && b.text.includes('Axis 1 is controlled by another page'),
      `page B's banner: ${JSON.stringify(b)}`);
    await waitCard(pageB, 1, 'held elsewhere');
    await waitPresent(pageB, 'OPERATION_ENABLED');
    // The jog is on (the drive is enabled); the server decides who may command it.
    const jog = pageB.locator('button.jog[data-sign="1"][data-speed="slow"]');
    await pageB.waitForSelector('button.jog[data-sign="1"][data-speed="slow"]:not([disabled])', { timeout: patience });
    await jog.hover();
    await pageB.mouse.down();
    await pageB.waitForFunction(() => document.getElementById('result').dataset.outcome === 'refused', null,
      { timeout: patience }).catch(async () => fail(`no refusal shown on page B: ${JSON.stringify(await resultLine(pageB))}`));
    await pageB.mouse.up();
    await pageB.mouse.move(5, 5);
    // Snapshots go on arriving (the position readout moves) and the refusal is still the result shown.
    const position = await pageB.textContent('#position');
    await pageB.waitForFunction((p) => document.getElementById('position').textContent !== p, position,
      { timeout: patience });
    await serverWait((await state(1)).time_ms, 10 * info.publish_ms);
    const r = await resultLine(pageB);
    expect(r.outcome === 'refused' && r.text === 'axis 1 is controlled by another page: take control to command it here',
      `page B's result line: ${JSON.stringify(r)}`);
    const a1 = await state(1);
    expect(a1.target_velocity === RPM_1 && turning(await axisOf(1), RPM_1), `axis 1 changed: 0x60FF ${a1.target_velocity}`);
    expect(!a1.results.some((x) => /^JOG/.test(x.action)), `a jog reached axis 1: ${JSON.stringify(a1.results)}`);
  });

  await check('(c) page B takes control with the button and commands axis 1; page A sees axis 1 held elsewhere, and on it Take control', async () => {
    await pageB.click('#take-control');
    await pageB.waitForFunction(() => document.getElementById('result').textContent === 'took control of axis 1',
      null, { timeout: patience }).catch(async () => fail(`page B's result line: ${JSON.stringify(await resultLine(pageB))}`));
    expect((await resultLine(pageB)).outcome === 'done', 'taking control is shown as done');
    await waitCard(pageB, 1, 'held here');
    const idB = await pageB.evaluate(() => sessionStorage.getItem('cia402-client'));
    const c = await (await fetch(`${base}api/control?axis=1`, { headers: { 'X-Cia402-Client': idB } })).json();
    expect(c.control === 'here' && JSON.stringify(c.held) === '[1]', `the server for page B: ${JSON.stringify(c)}`);
    await pageB.fill('#target-input', '200');
    await pageB.click('#target-form button[type="submit"]');
    await until(async () => turning(await axisOf(1), 200), 'axis 1 did not follow page B to 200 rpm');

    await waitCard(pageA, 1, 'held elsewhere');
    await waitBanner(pageA, () => document.getElementById('control-text').textContent === 'This page controls axis 2.',
      'page A still says it controls axis 1');
    await pageA.click('.axis-card[data-axis="1"]');
    await pageA.waitForURL(/axis=1/);
    await pageA.waitForSelector('#diagram .present', { timeout: patience });
    await waitBanner(pageA, () => document.getElementById('control-banner').dataset.control === 'elsewhere',
      'page A on axis 1 does not see it controlled elsewhere');
    const b = await banner(pageA);
    expect(!b.hidden && b.take && b.text === 'This page controls axis 2. Axis 1 is controlled by another page: its commands are refused here.',
      `page A's banner: ${JSON.stringify(b)}`);
  });

  await check(`(e) page A's tab closed: axis 2, which it holds, is stopped as 0x6007 says within lease + ${2 * PROBE_MS} ms + 1 ms; axis 1 (page B's) turns on`, async () => {
    const before = (await state(2)).time_ms;
    expect(turning(await axisOf(2), RPM_2), `axis 2 was not turning before the close: ${JSON.stringify(await axisOf(2))}`);
    await pageA.close();
    const after = (await state(2)).time_ms;
    run.currentPage = pageB;
    const { result, stop } = await lostSignOfLife(2, before, lease);
    const bound = after + lease + 2 * PROBE_MS + 1;
    expect(!/Quick stop/.test(result.action) || stop.number === 11, `axis 2 left OPERATION ENABLED by T${stop.number}: ${result.action}`);
    expect(stop.time_ms <= bound, `axis 2's stop T${stop.number} at ${stop.time_ms} ms, after the bound ${bound} ms ` +
      `(closed by ${after} ms + lease ${lease} + ${2 * PROBE_MS} + 1)`);
    expect(stop.time_ms >= before + lease - PROBE_MS, `axis 2 stopped at ${stop.time_ms} ms, sooner than the lease ` +
      `${lease} ms after the last renewal (the tab closed after ${before} ms)`);
    const a2 = await until(async () => {
      const a = await axisOf(2);
      return a.state !== 'OPERATION_ENABLED' && Math.abs(a.velocity) < 1 ? a : null;
    }, 'axis 2 did not come to rest', async () => JSON.stringify(await axisOf(2)));
    console.log(`# axis 2: ${result.action}: ${result.text}; T${stop.number} ${stop.time_ms - after} ms after the close ` +
      `(${stop.time_ms - before} ms after the last look before it), now ${a2.state}`);
    // Axis 1 turns on for another lease time: page B holds it.
    await serverWait(stop.time_ms, lease, async () => {
      expect(turning(await axisOf(1), 200), `axis 1 stopped with page A: ${JSON.stringify(await axisOf(1))}`);
    });
    expect(!(await state(1)).results.some((r) => r.action.startsWith(LOST)), 'axis 1 lost its sign of life');
  });

  await check('(e) page B closed too: axis 1 is stopped the same way', async () => {
    const before = (await state(1)).time_ms;
    await pageB.close();
    const after = (await state(1)).time_ms;
    run.currentPage = null;
    const { stop } = await lostSignOfLife(1, before, lease);
    const bound = after + lease + 2 * PROBE_MS + 1;
    expect(stop.time_ms <= bound && stop.time_ms >= before + lease - PROBE_MS,
      `axis 1's stop T${stop.number} at ${stop.time_ms} ms, outside [${before + lease - PROBE_MS}, ${bound}] ms`);
    await until(async () => {
      const a = await axisOf(1);
      return a.state !== 'OPERATION_ENABLED' && Math.abs(a.velocity) < 1;
    }, 'axis 1 did not come to rest', async () => JSON.stringify(await axisOf(1)));
    const a3 = await axisOf(3);
    expect(a3.state === 'SWITCH_ON_DISABLED' && !(await state(3)).results.length,
      `axis 3, never commanded, was touched: ${JSON.stringify(a3)}`);
  });

  await check('no console errors on either page but the one refusal (409) page B was shown', async () => {
    // Chromium logs every 4xx answer to a fetch; page B's refused jog is the one expected.
    const refusal = /status of 409 \(Conflict\)/;
    expect(pageB.errors.filter((e) => refusal.test(e)).length === 1, `page B's console: ${JSON.stringify(pageB.errors)}`);
    const errors = [...pageA.errors, ...pageB.errors.filter((e) => !refusal.test(e))];
    expect(errors.length === 0, `console errors: ${JSON.stringify(errors)}`);
  });

  await browser.close();
  run.context = null;
  await stopCleanly(server, 'cia402 serve');
  console.log(`1..${run.passed}`);
});

async function pageText(page, selector) {
  return (await page.$$eval(selector, (els) => els.map((e) => e.textContent))).join(' | ');
}
