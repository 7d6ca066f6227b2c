// What the instrument page's browser tests share (instrument_page.test.mjs,
// instrument_page_servers.test.mjs and the others; scope.test.mjs takes its start and server from
// here, and launches its own browser): Debian's chromium launched headless through playwright-core,
// `cia402 serve` and `cia402 bus` started and stopped as processes, and the page read as a person
// sees it (the present state black, the others gray, the last transition number accented).
// Environment: CIA402_NODE_MODULES (where npm ci put playwright-core), CIA402_CHROMIUM.
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import { createRequire } from 'node:module';
import os from 'node:os';
import path from 'node:path';

const modules = path.resolve(process.env.CIA402_NODE_MODULES || 'node_modules');
const { chromium } = createRequire(path.join(modules, 'resolve-from-here.js'))('playwright-core');
const executablePath = process.env.CIA402_CHROMIUM || '/usr/bin/chromium';

export const STATES = ['NOT_READY_TO_SWITCH_ON', 'SWITCH_ON_DISABLED', 'READY_TO_SWITCH_ON', 'SWITCHED_ON',
  'OPERATION_ENABLED', 'QUICK_STOP_ACTIVE', 'FAULT_REACTION_ACTIVE', 'FAULT'];

// How long a wait for the page may take before the check fails, in ms. Generous: on a loaded machine
// (ctest -j2 beside the model check) chromium may lag by seconds, and a wait ends as soon as its
// condition holds, so only a failing check pays for it.
export const patience = 20000;

// One test script's run: its binary and output folder, the checks passed, the processes it started,
// the browser and the page it looks at (for the failure's screenshot).
export const run = { cia402: null, outDir: null, passed: 0, servers: [], context: null, userDataDir: null, currentPage: null };

// Reads `node SCRIPT CIA402_BINARY OUTPUT_DIR [more...]`; the paths made absolute.
export function startRun(script, names) {
  const args = process.argv.slice(2);
  if (args.length !== names.length) {
    console.error(`usage: node ${script} ${names.join(' ')}`);
    process.exit(2);
  }
  const resolved = args.map((a) => path.resolve(a));
  [run.cia402, run.outDir] = resolved;
  fs.mkdirSync(run.outDir, { recursive: true });
  return resolved;
}

export function fail(message) {
  throw new Error(message);
}

export function expect(condition, message) {
  if (!condition) fail(message);
}

export async function check(name, fn) {
  await fn();
  run.passed += 1;
  console.log(`ok ${run.passed} - ${name}`);
}

// A fresh headless chromium at 1280x800 with downloads allowed.
export async function launchBrowser() {
  run.userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'cia402-chromium-'));
  run.context = await chromium.launchPersistentContext(run.userDataDir, {
    executablePath,
    headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
    viewport: { width: 1280, height: 800 },
    acceptDownloads: true,
  });
  return run.context;
}

// A new tab in `context`, the one a failure's screenshot shows; at `viewport` when given.
export async function newTab(context, viewport = null) {
  const page = await context.newPage();
  run.currentPage = page;
  if (viewport) await page.setViewportSize(viewport);
  return page;
}

export async function closeBrowser() {
  await run.context.close();
  run.context = null;
  fs.rmSync(run.userDataDir, { recursive: true, force: true });
}

// Runs the script's checks; on a failure: "not ok", a screenshot of the page, every process's
// output, exit status 1.
export function runChecks(main) {
  main().then(() => process.exit(0), async (e) => {
    console.error(`not ok ${run.passed + 1} - ${e.message}`);
    try {
      if (run.currentPage) await run.currentPage.screenshot({ path: path.join(run.outDir, 'failure.png'), fullPage: true });
    } catch { /* the page may be gone */ }
    for (const s of run.servers) {
      if (!s.exit) s.proc.kill('SIGKILL');
      console.error(`--- cia402 serve output ---\n${s.output}`);
    }
    if (run.context) await run.context.close().catch(() => {});
    process.exit(1);
  });
}

// A script's checks in one fresh browser, as every script but scope.test.mjs and control.test.mjs
// (browsers of their own) runs them: `checks(context)` between launchBrowser() and closeBrowser(),
// then TAP's plan line with the count of passed checks; a failure is reported as runChecks() does.
export function runInBrowser(checks) {
  runChecks(async () => {
    const context = await launchBrowser();
    await checks(context);
    await closeBrowser();
    console.log(`1..${run.passed}`);
  });
}

// --- cia402 serve ----------------------------------------------------------------------------

// `cia402 COMMAND ...args`, kept in run.servers: resolves with it once its output matches `pattern`
// (`url` is the first group), rejects when it exits before that or says nothing for 15 s.
function startProcess(command, args, pattern, what) {
  return new Promise((resolve, reject) => {
    const proc = spawn(run.cia402, [command, ...args], {
      stdio: ['ignore', 'pipe', 'pipe'],
    });
    const child = { proc, output: '', url: null, exit: null };
    run.servers.push(child);
    const timer = setTimeout(() => reject(new Error(`no ${what} from cia402 ${command}:\n${child.output}`)),
      15000);
    proc.stdout.on('data', (d) => {
      child.output += d;
      const m = pattern.exec(child.output);
      if (m && !child.url) {
        child.url = m[1];
        clearTimeout(timer);
        resolve(child);
      }
    });
    proc.stderr.on('data', (d) => { child.output += d; });
    proc.on('exit', (code, signal) => {
      child.exit = { code, signal };
      if (!child.url) {
        clearTimeout(timer);
        reject(new Error(`cia402 ${command} exited (${code}, ${signal}):\n${child.output}`));
      }
    });
  });
}

// `cia402 serve --port 0`: resolves with the page's URL it printed.
export function startServer(extraArgs) {
  return startProcess('serve', ['--port', '0', ...extraArgs], /(http:\/\/\S+)/, 'URL');
}

// `cia402 bus --listen 127.0.0.1:0`: resolves with the socketcand port it printed.
export function startBus(extraArgs) {
  return startProcess('bus', ['--listen', '127.0.0.1:0', ...extraArgs], /socketcand on (127\.0\.0\.1:\d+)/, 'port');
}

// `cia402 bus` with node 1 and `cia402 serve --can` on that node over socketcand: the drive behind
// a bus the scripts check besides (or instead of) the drive in this process. The caller stops both,
// the server first.
export async function startCanServer() {
  const bus = await startBus(['--nodes', '1']);
  const server = await startServer(['--can', `socketcand://${bus.url}/can0`, '--node', '1']);
  return { bus, server };
}

// Ctrl-C: the server must stop cleanly, exit status 0.
export async function stopServer(server) {
  if (server.exit) return server.exit;
  const exited = new Promise((resolve) => server.proc.on('exit', (code, signal) => resolve({ code, signal })));
  server.proc.kill('SIGINT');
  const timeout = new Promise((resolve) => setTimeout(() => resolve(null), 5000));
  const result = await Promise.race([exited, timeout]);
  if (!result) {
    server.proc.kill('SIGKILL');
    fail(`cia402 serve did not stop within 5 s of SIGINT:\n${server.output}`);
  }
  return result;
}

// Stops `server` (a server or a bus) as stopServer does; it must have exited with status 0.
export async function stopCleanly(server, what) {
  const exit = await stopServer(server);
  expect(exit.code === 0, `${what} exit ${JSON.stringify(exit)}:\n${server.output}`);
  return exit;
}

// The errors `page` reports (console errors, uncaught exceptions), gathered as they come.
export function pageProblems(page) {
  const problems = [];
  page.on('console', (m) => { if (m.type() === 'error') problems.push(m.text()); });
  page.on('pageerror', (e) => problems.push(String(e)));
  return problems;
}

// --- reading the page ------------------------------------------------------------------------

export async function waitPresent(page, state, timeout = patience) {
  try {
    return await page.waitForSelector(`#diagram [id="state.${state}"].present`, { timeout });
  } catch (e) {
    // A timeout alone does not tell a slow browser from a drive in another state or a link that
    // never reported one: say what the page showed and what its server says now.
    const shown = await page.evaluate(() => ({
      present: [...document.querySelectorAll('#diagram .present')].map((x) => x.id),
      remote: document.getElementById('remote')?.dataset.status ?? null,
      banner: document.getElementById('remote')?.textContent ?? null,
    })).catch((why) => String(why));
    let server;
    try {
      server = JSON.stringify(await (await fetch(new URL('api/state', page.url()))).json());
    } catch (why) {
      server = String(why);
    }
    throw new Error(`${e.message}\nthe page showed ${JSON.stringify(shown)}\n` +
      `its server says ${server.slice(0, 3000)}`);
  }
}

export function waitResult(page, text, timeout = patience) {
  return page.waitForFunction((t) => document.getElementById('result').textContent.includes(t),
    text, { timeout });
}

// Computed colours of every state box: what a reader actually sees.
export function diagramStyle(page) {
  return page.evaluate(() => {
    const rgb = (s) => (s.match(/\d+(\.\d+)?/g) || []).slice(0, 3).map(Number);
    const states = [...document.querySelectorAll('#diagram .state')]
      .filter((g) => g.dataset.state !== 'START')
      .map((g) => {
        const rect = g.querySelector('rect');
        const text = g.querySelector('text');
        return {
          name: g.dataset.state,
          label: [...g.querySelectorAll('text')].map((t) => t.textContent).join(' '),
          present: g.classList.contains('present'),
          fill: rgb(getComputedStyle(rect).fill),
          stroke: rgb(getComputedStyle(rect).stroke),
          text: rgb(getComputedStyle(text).fill),
        };
      });
    const numbers = [...document.querySelectorAll('#diagram .number')].map((g) => {
      const t = g.querySelector('text');
      const r = g.querySelector('rect');
      const cs = getComputedStyle(t);
      return {
        number: Number(g.dataset.number),
        id: g.id,
        last: g.classList.contains('last'),
        weight: Number(cs.fontWeight),
        size: parseFloat(cs.fontSize),
        underline: cs.textDecorationLine.includes('underline'),
        boxed: getComputedStyle(r).stroke !== 'none' && parseFloat(getComputedStyle(r).strokeWidth) > 0,
      };
    });
    return { states, numbers };
  });
}

export const isBlack = ([r, g, b]) => r === 0 && g === 0 && b === 0;
export const isWhite = ([r, g, b]) => r === 255 && g === 255 && b === 255;
export const isGray = ([r, g, b]) => r === g && g === b && r >= 100 && r <= 220;

export async function expectPresentState(page, state) {
  await waitPresent(page, state);
  const { states } = await diagramStyle(page);
  const present = states.filter((s) => s.present);
  expect(present.length === 1 && present[0].name === state,
    `exactly ${state} should be present, got ${JSON.stringify(present.map((s) => s.name))}`);
  const p = present[0];
  expect(p.label === state.replace(/_/g, ' '), `the present box reads "${p.label}"`);
  expect(isBlack(p.fill), `${state} should be drawn black, fill is rgb(${p.fill})`);
  for (const s of states.filter((x) => !x.present)) {
    expect(isWhite(s.fill) && isGray(s.stroke) && isGray(s.text),
      `${s.name} should be gray (fill ${s.fill}, stroke ${s.stroke}, text ${s.text})`);
  }
  expect(states.length === STATES.length, `8 states drawn, got ${states.length}`);
}

export async function expectAccented(page, number) {
  await page.waitForSelector(`#diagram .number.last[data-number="${number}"]`, { timeout: patience });
  const { numbers } = await diagramStyle(page);
  const last = numbers.filter((n) => n.last);
  expect(last.length === 1 && last[0].number === number,
    `only transition ${number} should be accented, got ${JSON.stringify(last.map((n) => n.id))}`);
  const a = last[0];
  const others = numbers.filter((n) => !n.last);
  expect(a.weight >= 700 && a.underline && a.boxed,
    `transition ${number} is accented by shape: weight ${a.weight}, underline ${a.underline}, box ${a.boxed}`);
  expect(others.every((n) => n.size < a.size && n.weight < 700 && !n.boxed && !n.underline),
    'the other transition numbers are plain');
}

// A fault through the page's plant switch: `code` typed into the fault-code field, the switch
// turned on, FAULT reached through T14 (accented) and the error code shown.
export async function injectFault(page, code) {
  await page.fill('#fault-code', code);
  await page.click('label:has(#fault-switch)');
  await expectPresentState(page, 'FAULT');
  await expectAccented(page, 14);
  await page.waitForFunction((c) => document.getElementById('error-code').textContent === c, code,
    { timeout: patience });
}

// The fault injectFault() set taken back: the plant switch turned off, the fault lamp OFF, then
// Fault reset, SWITCH ON DISABLED by T15 (accented).
export async function clearAndResetFault(page) {
  await page.click('label:has(#fault-switch)');
  await page.waitForFunction(() => document.getElementById('lamp-fault').textContent.includes('OFF'),
    null, { timeout: patience });
  await click(page, 'fault_reset');
  await expectPresentState(page, 'SWITCH_ON_DISABLED');
  await expectAccented(page, 15);
}

export async function statusWord(page) {
  return parseInt(await page.textContent('#sw-hex'), 16);
}

export async function click(page, command) {
  await page.click(`button[data-command="${command}"]`);
}

// Shutdown, Switch on and Enable operation clicked in turn, each once `until(page, state, transition)`
// saw the state the one before led to (waitPresent by default).
export async function enableByClicks(page, until = (p, state) => waitPresent(p, state)) {
  const steps = [['shutdown', 'READY_TO_SWITCH_ON', 2], ['switch_on', 'SWITCHED_ON', 3],
    ['enable_operation', 'OPERATION_ENABLED', 4]];
  for (const [command, state, transition] of steps) {
    await click(page, command);
    await until(page, state, transition);
  }
}

// The drive's snapshot as a script sees it (GET /api/state from here, not from the page).
export async function driveState(baseUrl) {
  return (await fetch(new URL('/api/state', baseUrl))).json();
}

// Polls the drive until `holds(snapshot)`; fails naming `what` after `timeout` ms.
export async function untilDrive(baseUrl, holds, what, timeout = patience) {
  const end = Date.now() + timeout;
  let s = null;
  while (Date.now() < end) {
    s = await driveState(baseUrl);
    if (holds(s)) return s;
    await new Promise((r) => setTimeout(r, 25));
  }
  fail(`${what}; last 0x60FF ${s && s.target_velocity}, velocity ${s && s.velocity}`);
  return null;
}
