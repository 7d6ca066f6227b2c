// Homing made visible and the drive's own error list, in a real browser (issue 35), on the local
// virtual drive and on a drive behind `cia402 serve --can` (a `cia402 bus` node over socketcand):
// the homing panel writes its parameters (0x6098, 0x6099:1/2) and runs method 3, the home-switch
// lamp lights on the way and the phase line says "homing attained"; the mode panel shows the mode's
// set-point (none in homing), names the handshake bits as homing mode names them and says what the
// drive does; a fault shows its text, enters the page's history and the drive's 0x1003 list, and
// Clear empties that list.
//
//   node homing.test.mjs CIA402_BINARY OUTPUT_DIR
// Environment: CIA402_NODE_MODULES (where npm ci put playwright-core), CIA402_CHROMIUM.
import {
  patience, startRun, expect, check, runInBrowser, startServer, startCanServer,
  stopServer, waitPresent, click, stopCleanly, newTab,
} from './page_harness.mjs';

startRun('homing.test.mjs', ['CIA402_BINARY', 'OUTPUT_DIR']);

const text = (page, id) => page.evaluate((i) => document.getElementById(i).textContent, id);

async function homingChecks(page, where, server) {
  await check(`${where}: the mode panel shows the set-point of the mode: pv's 0x60FF, none in homing`, async () => {
    await page.waitForFunction(() => document.getElementById('mode-setpoint').textContent
      .startsWith('Set-point 0x60FF Target velocity: '), null, { timeout: patience });
    await page.selectOption('#mode-select', '6');
    await page.waitForFunction(() => document.getElementById('mode-setpoint').textContent === '',
      null, { timeout: patience });
  });
  await check(`${where}: homing mode names its bits and says what the drive does`, async () => {
    await page.selectOption('#mode-select', '6');
    await page.waitForFunction(() => !document.getElementById('homing-form').hidden, null, { timeout: patience });
    await page.waitForFunction(() => document.getElementById('mode-bits').textContent.includes('Homing attained'),
      null, { timeout: patience });
    const bits = await text(page, 'mode-bits');
    expect(bits.includes('control 4 Homing operation start') && bits.includes('status 13 Homing error'),
      `mode bits: "${bits}"`);
    const doing = await text(page, 'doing-now');
    expect(doing === 'Now: no motion: not OPERATION ENABLED', `doing now: "${doing}"`);
  });
  await check(`${where}: method 3 from the page lights the home switch and is attained`, async () => {
    // The lamp is on only while the shaft stands on the switch: watched from the page's start.
    await page.evaluate(() => {
      window.homeLampSeen = false;
      const lamp = document.getElementById('lamp-home');
      new MutationObserver(() => { if (lamp.classList.contains('on')) window.homeLampSeen = true; })
        .observe(lamp, { attributes: true, attributeFilter: ['class'] });
    });
    await page.selectOption('#homing-method', '3');
    await page.fill('#homing-fast', '300');
    await page.fill('#homing-slow', '40');
    await page.click('#homing-start');
    await page.waitForFunction(() => document.getElementById('homing-phase').textContent.includes('homing attained'),
      null, { timeout: patience });
    expect(await page.evaluate(() => window.homeLampSeen), 'the home switch lamp never lit');
    await page.waitForFunction(() => document.getElementById('doing-now').textContent === 'Now: homing: homing attained',
      null, { timeout: patience });
    const s = await (await fetch(`${server.url.split('?')[0]}api/state`)).json();
    expect(s.homing.method === 3 && s.homing.fast === 300 && s.homing.slow === 40,
      `homing parameters: ${JSON.stringify(s.homing)}`);
    expect(s.results[0].text.startsWith('done: homing attained'), `result: ${s.results[0].text}`);
  });
}

async function errorChecks(page, where) {
  await check(`${where}: a fault shows its text, enters the history and the drive's 0x1003; Clear empties it`, async () => {
    await page.fill('#fault-code', '0x2310');
    await page.check('#fault-switch');
    await waitPresent(page, 'FAULT');
    await page.waitForFunction(() => document.getElementById('drive-errors').textContent.includes('0x2310'),
      null, { timeout: patience });
    const list = await text(page, 'drive-errors');
    expect(list.includes('over-current'), `0x1003 list: "${list}"`);
    expect((await text(page, 'error-text')).includes('over-current'), 'no error text');
    expect((await text(page, 'error-history')).includes('0x2310'), 'not in the history');
    await page.click('#drive-errors-clear');
    await page.waitForFunction(() => document.getElementById('drive-errors-note').textContent === 'empty',
      null, { timeout: patience });
    expect((await text(page, 'drive-errors')) === '', 'the list still shows entries');
  });
}

runInBrowser(async (context) => {
  const local = await startServer([]);
  const lp = await newTab(context);
  await lp.goto(local.url);
  await waitPresent(lp, 'SWITCH_ON_DISABLED');
  await homingChecks(lp, 'local drive', local);
  await errorChecks(lp, 'local drive');
  await lp.close();
  await stopCleanly(local, 'local server');

  const { bus, server: remote } = await startCanServer();
  const rp = await newTab(context);
  await rp.goto(remote.url);
  await rp.waitForSelector('#remote[data-status="running"]', { timeout: patience });
  await waitPresent(rp, 'SWITCH_ON_DISABLED');
  await homingChecks(rp, '--can', remote);
  await rp.waitForFunction(() => !document.getElementById('fault-switch').disabled, null, { timeout: patience });
  await errorChecks(rp, '--can');
  await rp.close();
  await stopServer(remote);
  await stopServer(bus);
});
