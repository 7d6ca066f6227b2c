// The jog's dead-man in a real browser (issue 35), on the local virtual drive and on node 1 of a
// `cia402 bus` behind `cia402 serve --can`: a held jog button runs the drive and its release stops
// it; a tab closed while the button is held, and a page whose network is cut (its event stream
// drops) while it is held, leave the motor standing. docs/instrument-page.md, "Enable, Stop and
// jog": the stop (0x60FF = 0) is commanded within the time-to-live + one cycle of the last renewal,
// then the shaft stands after the 0x6084 ramp from the jog speed.
//
// Every expected time comes from the server: the stop and the rest are read from its recording
// (/api/recording.csv, the drive's own time of each cycle), the page's time-to-live and renewal
// period from the jog.js it serves, 0x6084 from its parameter list. No check times anything on this side.
//
//   node jog.test.mjs CIA402_BINARY OUTPUT_DIR
// Environment: CIA402_NODE_MODULES (where npm ci put playwright-core), CIA402_CHROMIUM.
import {
  patience, run, startRun, fail, expect, check, runInBrowser, startServer, startCanServer,
  stopServer, waitPresent, driveState, untilDrive, stopCleanly, newTab,
} from './page_harness.mjs';
import net from 'node:net';

startRun('jog.test.mjs', ['CIA402_BINARY', 'OUTPUT_DIR']);

const SPEED = 120;  // rpm, typed into the page's slow jog field
const base = (server) => server.url.split('?')[0];
const atRest = (s) => Math.abs(s.velocity) < 1;
const atSpeed = (s) => s.target_velocity === SPEED && Math.abs(s.velocity - SPEED) < 1;

// The page's own dead-man values, as the server serves them to the browser (jog.js).
async function pageJogTimes(url) {
  const source = await (await fetch(new URL('jog.js', url))).text();
  const number = (name) => {
    const m = new RegExp(`const ${name} = (\\d+);`).exec(source);
    if (!m) fail(`jog.js as served has no ${name}`);
    return Number(m[1]);
  };
  return { ttl: number('TTL_MS'), renew: number('RENEW_MS') };
}

// The recording as the server's CSV gives it: each kept cycle's drive time (us), the actual
// velocity and the target velocity 0x60FF. A change of 0x60FF always keeps its cycle's row.
async function recordingRows(url) {
  const text = await (await fetch(new URL('api/recording.csv', url))).text();
  const [head, ...lines] = text.trim().split('\n');
  const col = head.split(',');
  const at = (name) => {
    const i = col.indexOf(name);
    if (i < 0) fail(`the recording has no column ${name}: ${head}`);
    return i;
  };
  const [t, v, target] = [at('time_us'), at('velocity_rpm'), at('target_rpm')];
  return lines.map((l) => l.split(',')).map((c) => ({ t: Number(c[t]), v: Number(c[v]), target: Number(c[target]) }));
}

// 0x6084 as the server's parameter list reads it from the drive (rpm/s; a drive on a bus is read
// by SDO, its snapshot's objects leave it out).
async function profileDeceleration(url) {
  const { entries } = await (await fetch(new URL('api/parameters', url))).json();
  const e = entries.find((x) => x.index === '0x6084' && x.sub === 0);
  expect(e && e.unit === 'rpm/s' && e.value > 0, `0x6084 from the server: ${JSON.stringify(e)}`);
  return e.value;
}

// One cycle of the server's clock, in ms: its drive time over the cycles it stepped.
const cycleMs = (s) => Math.max(1, Math.ceil(s.time_ms / Math.max(1, s.cycle)));

// From the recording after `fromMs` (the server's time before the button went down): the cycle
// where 0x60FF, as the server last read it, went from the jog speed to 0; when the drive began to
// slow down, told from the first cycle below the jog speed and 0x6084 (on a bus the server reads
// 0x60FF back from the drive some cycles after it commanded it, and the velocity from its TPDO);
// the first cycle at rest. The velocity never rises on the way and 0x60FF stays 0.
async function jogStopInRecording(url, fromMs, deceleration) {
  const rows = (await recordingRows(url)).filter((r) => r.t >= fromMs * 1000);
  const running = rows.findIndex((r) => r.target === SPEED);
  expect(running >= 0, `the recording after ${fromMs} ms has no cycle with 0x60FF = ${SPEED}`);
  const full = rows.findIndex((r, i) => i > running && r.v >= SPEED - 0.5);
  expect(full > 0, `the recording has no cycle at ${SPEED} rpm`);
  const below = rows.findIndex((r, i) => i > full && r.v < SPEED - 0.5);
  expect(below > 0, 'the recording has no cycle below the jog speed after it');
  const stop = rows.findIndex((r, i) => i > running && r.target !== SPEED);
  expect(stop > 0, 'the recording has no end of the jog');
  expect(rows[stop].target === 0, `the jog ended on 0x60FF = ${rows[stop].target}, not 0`);
  const rest = rows.findIndex((r, i) => i >= below && Math.abs(r.v) < 0.5);
  expect(rest >= below, 'the recording has no cycle at rest after the jog stop');
  for (let i = below; i <= rest; ++i) {
    expect(rows[i].v <= rows[i - 1].v, `the velocity rose on the way to rest: ${rows[i - 1].v} -> ${rows[i].v} rpm`);
  }
  for (let i = stop; i < rows.length; ++i) expect(rows[i].target === 0, `0x60FF went back to ${rows[i].target}`);
  const slowingMs = rows[below].t / 1000 - ((SPEED - rows[below].v) / deceleration) * 1000;
  return { stopMs: rows[stop].t / 1000, slowingMs, restMs: rows[rest].t / 1000 };
}

// A TCP relay between the browser and the server, to cut the page's network as a pulled cable
// would: the open event stream breaks and every later connection (a reconnect, a renewal, the
// page's own release) is refused. Chromium's offline emulation alone leaves an open stream running.
function startRelay(serverUrl) {
  const target = new URL(serverUrl);
  const sockets = new Set();
  let cut = false;
  const listener = net.createServer((client) => {
    if (cut) return client.destroy();
    const upstream = net.connect(Number(target.port), target.hostname);
    const end = () => {
      client.destroy();
      upstream.destroy();
      sockets.delete(client);
      sockets.delete(upstream);
    };
    for (const s of [client, upstream]) {
      sockets.add(s);
      s.on('error', end);
      s.on('close', end);
    }
    client.pipe(upstream);
    upstream.pipe(client);
    return undefined;
  });
  return new Promise((resolve) => listener.listen(0, '127.0.0.1', () => resolve({
    url: `http://127.0.0.1:${listener.address().port}/`,
    cut() {
      cut = true;
      for (const s of sockets) s.destroy();
    },
    close() { listener.close(); },
  })));
}

async function openPage(context, server, remote, pageUrl = server.url) {
  const page = await newTab(context);
  await page.goto(pageUrl);
  if (remote) await page.waitForSelector('#remote[data-status="running"]', { timeout: patience });
  await page.waitForSelector('#diagram .present', { timeout: patience });
  return page;
}

// The page's Enable button, unless the drive is enabled already (a closed page's lease may have
// stopped it meanwhile: then it is enabled again, as a page that comes back may).
async function enable(page, url) {
  if ((await driveState(url)).state !== 'OPERATION_ENABLED') {
    await page.waitForSelector('#enable:not([disabled])', { timeout: patience });
    await page.click('#enable');
  }
  await waitPresent(page, 'OPERATION_ENABLED');
}

// Mouse down over the positive slow jog button; resolves with the server's snapshot once the drive
// turns at the jog speed, and the server's time before the button went down.
async function holdJog(page, url) {
  await page.fill('#jog-slow', String(SPEED));
  const fromMs = (await driveState(url)).time_ms;
  // The jog buttons are live only once the page's own snapshot shows OPERATION ENABLED (jog.js).
  await page.waitForSelector('button.jog[data-sign="1"][data-speed="slow"]:not([disabled])', { timeout: patience });
  await page.locator('button.jog[data-sign="1"][data-speed="slow"]').hover();
  await page.mouse.down();
  const running = await untilDrive(url, atSpeed, `the held jog did not reach ${SPEED} rpm`);
  return { running, fromMs };
}

// The jog's own entry in the results: why 0x60FF went to 0 ("released", "no keep-alive for N ms").
function jogEnding(s) {
  const r = s.results.find((x) => x.action === `JOG ${SPEED} rpm`);
  expect(r && r.outcome === 'done', `the jog's result: ${JSON.stringify(r)}`);
  const m = /0x60FF = 0: (.*)$/.exec(r.text);
  expect(m, `the jog's result names no stop: "${r.text}"`);
  return m[1];
}

// The documented bound, from the server's record: the drive slows down no later than the
// time-to-live + one cycle after `markMs` (the server's time once the page could renew no more; a
// renewal the page sent just before may still be on its way, hence one renewal period more), and
// stands after 0x6084's ramp from the jog speed (two cycles either side: 0x60FF and the velocity
// are sampled in the same cycle).
async function expectStoodWithinBound(url, times, fromMs, markMs, remote) {
  const now = await untilDrive(url, (s) => s.target_velocity === 0 && atRest(s), 'the motor did not come to rest');
  const cycle = cycleMs(now);
  const deceleration = await profileDeceleration(url);
  const { stopMs, slowingMs, restMs } = await jogStopInRecording(url, fromMs, deceleration);
  const stopBound = markMs + times.ttl + cycle + times.renew;
  expect(slowingMs <= stopBound, `the drive slowed down from ${slowingMs} ms, after the bound ${stopBound} ms ` +
    `(mark ${markMs} + ttl ${times.ttl} + cycle ${cycle} + one renewal ${times.renew})`);
  if (!remote) expect(stopMs <= stopBound, `0x60FF = 0 at ${stopMs} ms, after the bound ${stopBound} ms`);
  const rampMs = (SPEED / deceleration) * 1000;
  // On a bus the ramp runs on the `cia402 bus` process's clock and reaches this server as TPDOs
  // on its own: the ramp's length in this server's time moves with the load of the machine (126 to
  // 135 ms seen for 120 ms), so there only its order and values are asserted (above).
  const slack = 2 * cycle;
  expect(remote || Math.abs(restMs - slowingMs - rampMs) <= slack,
    `at rest ${restMs - slowingMs} ms after slowing down; 0x6084 = ${deceleration} rpm/s from ${SPEED} rpm ` +
    `gives ${rampMs} ms (± ${slack})`);
  return { stopMs, slowingMs, restMs, rampMs, now };
}

async function jogChecks(context, server, where, remote) {
  const url = base(server);
  const times = await pageJogTimes(url);
  let page = await openPage(context, server, remote);
  await enable(page, url);

  await check(`${where}: a held jog turns the drive; its release sets 0x60FF = 0 and the shaft stands`, async () => {
    const { running, fromMs } = await holdJog(page, url);
    expect(running.velocity > 0, `velocity ${running.velocity} while held`);
    await page.mouse.up();
    const markMs = (await driveState(url)).time_ms;
    const { now } = await expectStoodWithinBound(url, times, fromMs, markMs, remote);
    expect(jogEnding(now) === 'released', `the release ended the jog as "${jogEnding(now)}"`);
    expect(now.state === 'OPERATION_ENABLED', `a jog stop leaves the drive enabled, not ${now.state}`);
  });

  await check(`${where}: the tab closed while the jog is held: the drive slows down within ttl + one cycle and stands`, async () => {
    await page.mouse.move(5, 5);
    await untilDrive(url, atRest, 'the drive was not at rest before the second jog');
    const { fromMs } = await holdJog(page, url);
    await page.close();
    run.currentPage = null;
    const markMs = (await driveState(url)).time_ms;
    const r = await expectStoodWithinBound(url, times, fromMs, markMs, remote);
    // The page's pagehide release may or may not leave a closing tab; the server's dead-man
    // stops the jog either way.
    const why = jogEnding(r.now);
    expect(why === 'released' || why === `no keep-alive for ${times.ttl} ms`, `the jog ended as "${why}"`);
    console.log(`# ${where}, tab closed: slowing ${r.slowingMs - markMs} ms after the close (${why}; ` +
      `0x60FF = 0 read at ${r.stopMs - markMs} ms), at rest ${r.restMs - r.slowingMs} ms later (ramp ${r.rampMs} ms)`);
  });

  const relay = await startRelay(url);
  page = await openPage(context, server, remote, relay.url);
  // The closed tab held the axis, and its hold lapses only once nothing renewed it for a second
  // (docs/instrument-page.md, "Control model"): until then this new tab's commands are refused.
  // How soon that is after the close depends on the machine's speed, so wait for the page to say so.
  await page.waitForFunction(() => {
    const c = document.getElementById('control-banner').dataset.control;
    return c !== undefined && c !== 'elsewhere';
  }, null, { timeout: patience });
  await enable(page, url);
  await check(`${where}: the page's network cut while the jog is held: its event stream drops, the page goes stale, the server's dead-man stops the jog in the bound`, async () => {
    const { fromMs } = await holdJog(page, url);
    relay.cut();
    const markMs = (await driveState(url)).time_ms;
    await page.waitForFunction(() => document.body.classList.contains('stale'), null, { timeout: patience });
    const r = await expectStoodWithinBound(url, times, fromMs, markMs, remote);
    const why = jogEnding(r.now);
    // Cut off, the page's own release cannot reach the server: the stop is the server's.
    expect(why === `no keep-alive for ${times.ttl} ms`, `the jog ended as "${why}", not by the server's dead-man`);
    console.log(`# ${where}, network cut: slowing ${r.slowingMs - markMs} ms after the cut (${why}; ` +
      `0x60FF = 0 read at ${r.stopMs - markMs} ms), at rest ${r.restMs - r.slowingMs} ms later (ramp ${r.rampMs} ms)`);
    await page.mouse.up();
  });
  await page.close();
  relay.close();
  run.currentPage = null;
}

runInBrowser(async (context) => {
  const local = await startServer([]);
  await jogChecks(context, local, 'local drive', false);
  await stopCleanly(local, 'local server');

  const { bus, server: remote } = await startCanServer();
  await jogChecks(context, remote, '--can', true);
  await stopServer(remote);
  await stopServer(bus);
});
