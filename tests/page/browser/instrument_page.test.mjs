// The instrument page in a real browser: Debian's chromium, headless, driven by playwright-core,
// against `cia402 serve --port 0` on loopback. What it checks is what seed 003_83442f2f4b0b2bb9.txt
// asks of the screen page: the present state black, all others gray, the number of the last
// transition accented; the status word; commands, a fault and its reset; refused commands shown
// as refused; jog, the recorder, the operation modes, phone width; a server stopped under the page.
// instrument_page_servers.test.mjs goes on with the other servers (token, profiles, axes, --can).
//
//   node instrument_page.test.mjs CIA402_BINARY OUTPUT_DIR SCREENSHOT_PNG
// Environment: CIA402_NODE_MODULES (where npm ci put playwright-core), CIA402_CHROMIUM.
import fs from 'node:fs';
import path from 'node:path';

import {
  patience,
  run,
  startRun,
  expect,
  check,
  runInBrowser,
  startServer,
  waitResult,
  expectPresentState,
  expectAccented,
  statusWord,
  click,
  driveState,
  untilDrive,
  stopCleanly,
  pageProblems,
  enableByClicks,
  injectFault,
  clearAndResetFault,
} from './page_harness.mjs';

const [, outDir, screenshotPath] = startRun('instrument_page.test.mjs', ['CIA402_BINARY', 'OUTPUT_DIR', 'SCREENSHOT_PNG']);

async function main(context) {
  const main = await startServer([]);
  await check('cia402 serve prints a loopback URL without a token', async () => {
    expect(/^http:\/\/127\.0\.0\.1:\d+\/$/.test(main.url), `URL ${main.url}`);
  });

  const page = context.pages()[0] || await context.newPage();
  run.currentPage = page;
  const problems = pageProblems(page);

  await page.goto(main.url);

  await check('power-up: SWITCH ON DISABLED black, the others gray, transition 1 accented', async () => {
    await page.waitForSelector('#link[data-live="true"]', { timeout: patience });
    await expectPresentState(page, 'SWITCH_ON_DISABLED');
    await expectAccented(page, 1);
  });

  const diagramTop = () => page.evaluate(() => document.getElementById('diagram').getBoundingClientRect().top);
  const diagramAtStart = await diagramTop();

  await check('at 1280x800 the target velocity and the fault, DC-link and STO switches are in view', async () => {
    const bottoms = await page.evaluate(() => ['target-input', 'fault-switch', 'dc-switch', 'sto-switch']
      .map((id) => Math.round(document.getElementById(id).getBoundingClientRect().bottom)));
    expect(bottoms.every((b) => b > 0 && b <= 800), `bottoms ${bottoms} (the fold is at 800)`);
  });

  await check('all 16 control-word and 16 status-word bits are shown with names', async () => {
    const n = await page.evaluate(() => [
      document.querySelectorAll('#control-bits button.bit').length,
      document.querySelectorAll('#status-bits .bit').length,
      document.querySelector('#control-bits button[data-bit="8"] .name').textContent,
    ]);
    expect(n[0] === 16 && n[1] === 16, `bits shown: ${n}`);
    expect(n[2] === 'Halt', `bit 8 is named "${n[2]}"`);
  });

  await check('Enable operation from SWITCH ON DISABLED is shown as refused', async () => {
    await click(page, 'enable_operation');
    await waitResult(page, 'refused: no transition from SWITCH_ON_DISABLED for ENABLE_OPERATION');
    expect(await page.getAttribute('#result', 'data-outcome') === 'refused', 'marked refused');
    await expectPresentState(page, 'SWITCH_ON_DISABLED');
  });

  await check('why Enable is blocked: STO named under Enable while asserted, gone once released; 0x60FD lamps', async () => {
    expect(await page.isHidden('#enable-blocker'), 'a blocker shown with nothing blocking');
    await page.click('label:has(#sto-switch)');
    await page.waitForSelector('#enable-blocker:not([hidden])', { timeout: patience });
    const text = await page.textContent('#enable-blocker');
    expect(text.includes('STO'), `blocker "${text}"`);
    await page.click('label:has(#sto-switch)');
    await page.waitForSelector('#enable-blocker[hidden]', { state: 'attached', timeout: patience });
    for (const id of ['lamp-neg-limit', 'lamp-pos-limit', 'lamp-home']) {
      const lamp = await page.textContent(`#${id} b`);
      expect(lamp === 'OFF', `${id} reads "${lamp}" at position 0`);
    }
  });

  await check('Shutdown, Switch on: READY TO SWITCH ON by T2, SWITCHED ON by T3', async () => {
    await click(page, 'shutdown');
    await expectPresentState(page, 'READY_TO_SWITCH_ON');
    await expectAccented(page, 2);
    await click(page, 'switch_on');
    await expectPresentState(page, 'SWITCHED_ON');
    await expectAccented(page, 3);
  });

  await check('Enable operation: OPERATION ENABLED black, the others gray, transition 4 accented', async () => {
    await click(page, 'enable_operation');
    await expectPresentState(page, 'OPERATION_ENABLED');
    await expectAccented(page, 4);
    expect((await page.textContent('#state-name')) === 'Operation enabled', 'summary names the state');
  });

  await check('Enable operation again is shown as nothing to do, not as refused', async () => {
    await click(page, 'enable_operation');
    await waitResult(page, 'nothing to do: already OPERATION_ENABLED');
    expect(await page.getAttribute('#result', 'data-outcome') === 'nothing to do', 'marked nothing to do');
  });

  // That a renewed jog outlives its time-to-live is the C++ test's (commissioning_test.cpp): here a
  // loaded machine may delay the page's renewals past 300 ms, and the server then stops it, rightly.
  await check('jog: runs while held, 0x60FF = 0 on release and on leaving the button', async () => {
    await page.fill('#jog-slow', '120');
    const button = page.locator('button.jog[data-sign="1"][data-speed="slow"]');
    // Live only once the page's own snapshot shows OPERATION ENABLED (jog.js).
    await page.waitForSelector('button.jog[data-sign="1"][data-speed="slow"]:not([disabled])', { timeout: patience });
    await button.hover();
    await page.mouse.down();
    await untilDrive(main.url, (s) => s.target_velocity === 120 && s.velocity > 0, 'the jog did not start');
    await page.mouse.up();
    await untilDrive(main.url, (s) => s.target_velocity === 0, 'the release did not stop the jog');
    // At rest the panel above stops changing height, so the button stays under the pointer.
    await untilDrive(main.url, (s) => s.velocity === 0, 'the motor did not come to rest');
    await page.waitForTimeout(300);
    await button.hover();
    await page.mouse.down();
    await untilDrive(main.url, (s) => s.target_velocity === 120, 'the jog did not start again');
    await page.mouse.move(5, 5);  // the pointer leaves the button, still pressed
    await untilDrive(main.url, (s) => s.target_velocity === 0, 'leaving the button did not stop the jog');
    await page.mouse.up();
    await untilDrive(main.url, (s) => s.velocity === 0, 'the motor did not come to rest');
    expect((await driveState(main.url)).state === 'OPERATION_ENABLED', 'a jog stop leaves the drive enabled');
  });

  await check('status word 0x0237 in bits 0..9 and its bits lit', async () => {
    const sw = await statusWord(page);
    // Bits 10..15 are the mode's and the plant's (target reached, pv speed 0 at standstill).
    expect((sw & 0x03ff) === 0x0237, `status word ${sw.toString(16)}: bits 0..9 should read 0x237`);
    const lit = await page.evaluate(() => [...document.querySelectorAll('#status-bits .bit')]
      .filter((li) => li.classList.contains('on')).map((li) => Number(li.dataset.bit)));
    for (const b of [0, 1, 2, 4, 5, 9]) expect(lit.includes(b), `status bit ${b} lit`);
    for (const b of [3, 6]) expect(!lit.includes(b), `status bit ${b} dark`);
    expect((await page.textContent('#cw-hex')) === '0x000F', 'control word 0x000F');
  });

  await check('target velocity: the motor turns, torque ON, brake released, the plot draws', async () => {
    await page.fill('#target-input', '1500');
    await page.click('#target-form button[type="submit"]');
    await page.waitForFunction(() => Number(document.getElementById('velocity').textContent) > 300,
      null, { timeout: patience });
    expect((await page.textContent('#lamp-torque b')) === 'ON', 'torque lamp ON');
    expect((await page.textContent('#lamp-brake b')).startsWith('OFF'), 'brake lamp OFF (released)');
    const inked = await page.evaluate(() => {
      const c = document.getElementById('plot');
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let n = 0;
      for (let i = 3; i < d.length; i += 4) if (d[i] > 0) n += 1;
      return n;
    });
    expect(inked > 500, `the plot has ink (${inked} pixels)`);
  });

  await page.waitForTimeout(2200);  // let the plot show the ramp and the plateau
  await page.evaluate(() => { document.activeElement.blur(); window.scrollTo(0, 0); });
  fs.mkdirSync(path.dirname(screenshotPath), { recursive: true });
  await page.screenshot({ path: screenshotPath, fullPage: true });
  await page.screenshot({ path: path.join(outDir, 'operation-enabled-1280x800.png') });

  await check('injected fault 0x2310: T13, T14 to FAULT, error code shown, transition 14 accented', async () => {
    await injectFault(page, '0x2310');
    expect((await page.textContent('#error-text')) === 'continuous over-current', 'the error code\'s text');
    expect((await page.textContent('#lamp-fault b')).startsWith('ON'), 'fault lamp ON');
    expect((await page.textContent('#lamp-torque b')) === 'OFF', 'torque lamp OFF');
    const seen = await page.$$eval('#error-history li', (items) => items.map((li) => li.textContent));
    expect(seen.length === 1 && seen[0].includes('0x2310 continuous over-current'),
      `the errors seen: ${JSON.stringify(seen)}`);
    const year = new Date().getUTCFullYear();
    expect(seen[0].startsWith(`${year}-`), `the time of day first: ${seen[0]}`);
    expect(await page.isHidden('#error-history-none'), '"none" shown beside an error');
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#error-history-export')]);
    const csv = fs.readFileSync(await download.path(), 'utf8').trim().split('\n');
    expect(csv.length === 2 && csv[0] === 'time of day (UTC),drive time (s),code,text' &&
      csv[1].startsWith(`${year}-`) && csv[1].includes(',0x2310,"continuous over-current"'), `the export: ${csv}`);
  });
  await page.screenshot({ path: path.join(outDir, 'fault-1280x800.png') });

  await check('Fault reset while the cause persists is shown as refused', async () => {
    await click(page, 'fault_reset');
    await waitResult(page, 'refused: no transition from FAULT for FAULT_RESET');
    await expectPresentState(page, 'FAULT');
  });

  await check('cause gone, Fault reset: SWITCH ON DISABLED by T15, transition 15 accented', async () => {
    await clearAndResetFault(page);
    await waitResult(page, 'done: T15');
    const cw = parseInt(await page.textContent('#cw-hex'), 16);
    expect((cw & 0x80) === 0, `bit 7 cleared after the edge (control word ${cw.toString(16)})`);
  });
  await page.screenshot({ path: path.join(outDir, 'after-fault-reset-1280x800.png') });

  await check('a control-word bit toggles by click, the other bits kept', async () => {
    const bit4 = '#control-bits button[data-bit="4"]';
    const before = parseInt(await page.textContent('#cw-hex'), 16);
    const was = await page.getAttribute(bit4, 'aria-checked');
    await page.click(bit4);
    await page.waitForFunction((w) => document.getElementById('cw-hex').textContent === w,
      `0x${(before ^ 0x10).toString(16).toUpperCase().padStart(4, '0')}`, { timeout: patience });
    expect(await page.getAttribute(bit4, 'aria-checked') !== was, 'bit 4 shows the new value');
    await page.click(bit4);
    await page.waitForFunction((w) => document.getElementById('cw-hex').textContent === w,
      `0x${before.toString(16).toUpperCase().padStart(4, '0')}`, { timeout: patience });
  });

  await check('the recorder lists every transition newest first and draws the timeline', async () => {
    await page.waitForFunction(() => document.querySelectorAll('#history tr').length >= 8,
      null, { timeout: patience });
    const numbers = await page.$$eval('#history tr', (rows) => rows.map((r) => r.dataset.number));
    // Newest first: T15 (fault reset), T14, T13 (the fault), T4, T3, T2, then T1, T0 at power-up.
    expect(numbers.join(' ') === '15 14 13 4 3 2 1 0', `history ${numbers.join(' ')}`);
    const first = await page.$$eval('#history tr:first-child td', (tds) => tds.map((t) => t.textContent));
    expect(/^\d+\.\d{3} s$/.test(first[0]), `time cell '${first[0]}'`);
    expect(/^0x[0-9A-F]{4}$/.test(first[3]) && /^0x[0-9A-F]{4}$/.test(first[4]), `words ${first}`);
    expect(/transitions recorded/.test(await page.textContent('#recorder-count')), 'count shown');
    expect(Number(await page.getAttribute('#timeline', 'data-rows')) > 3, 'timeline has rows');
    // "Last transition 15 (FAULT → SWITCH ON DISABLED)" is longer than at power-up: nothing moved.
    expect(await diagramTop() === diagramAtStart, `diagram moved from ${diagramAtStart} to ${await diagramTop()}`);
    await page.screenshot({ path: path.join(outDir, 'full-1280.png'), fullPage: true });
  });

  await check('the recorder exports CSV and VCD from the page', async () => {
    for (const [id, start] of [['export-csv', 'time_us,controlword'], ['export-vcd', '$timescale'],
      ['export-vcd-gtkwave', '$timescale']]) {
      const [download] = await Promise.all([page.waitForEvent('download'), page.click(`#${id}`)]);
      const file = path.join(outDir, download.suggestedFilename());
      await download.saveAs(file);
      const text = fs.readFileSync(file, 'utf8');
      expect(text.startsWith(start) || text.includes(start), `${id}: starts ${text.slice(0, 40)}`);
      if (id === 'export-csv') {
        expect(/,FAULT,14,/.test(text) && /,SWITCH_ON_DISABLED,15,/.test(text), 'CSV holds T14, T15');
      }
      if (id === 'export-vcd') expect(!text.includes('$var string'), 'IEEE form has no $var string');
      if (id === 'export-vcd-gtkwave') expect(text.includes('$var string'), 'GTKWave form');
    }
  });

  await check('a value the profile does not take is refused on the page, without a failed request', async () => {
    await page.selectOption('#object-index', '0x605A');
    await page.fill('#object-value', '9');
    await page.click('#object-form button');
    await waitResult(page, 'WRITE 0x605A = 9: refused: profile cia402 supports 0, 1, 2, 3, 4, 5, 6, 7, 8');
    await page.fill('#object-value', '-5');
    await page.selectOption('#object-index', '0x6083');
    await page.fill('#object-value', '-5');
    await page.click('#object-form button');
    await waitResult(page, 'WRITE 0x6083 = -5: refused: outside');
  });

  const visible = (id) => page.evaluate((i) => {
    const n = document.getElementById(i);
    return !!n && !n.hidden && n.getBoundingClientRect().height > 0;
  }, id);
  const statusBitOn = (bit) => page.waitForFunction(
    (b) => document.querySelector(`#status-bits li[data-bit="${b}"]`).classList.contains('on'), bit,
    { timeout: patience });
  const positionIs = (value) => page.waitForFunction(
    (v) => document.getElementById('position').textContent === v, value, { timeout: patience });
  // The operation mode chosen in the select, once the page shows it.
  const selectMode = async (mode) => {
    await page.selectOption('#mode-select', mode);
    await page.waitForFunction((m) => document.getElementById('mode').textContent.startsWith(`${m} `), mode,
      { timeout: patience });
  };
  // The names the page gives the control or status bits, by number.
  const expectBitNames = async (list, names) => {
    const item = list === 'control' ? '#control-bits button' : '#status-bits li';
    for (const [bit, name] of Object.entries(names)) {
      const shown = await page.textContent(`${item}[data-bit="${bit}"] .name`);
      expect(shown === name, `${list} bit ${bit} is named "${shown}", not "${name}"`);
    }
  };

  await check('operation modes: the select offers the modes 0x6502 announces, by name', async () => {
    const options = await page.$$eval('#mode-select option', (os) => os.map((o) => `${o.value} ${o.textContent}`));
    expect(options.join('|') === '1 Profile position (pp)|3 Profile velocity (pv)|4 Profile torque (tq)|' +
      '6 Homing (hm)|8 Cyclic synchronous position (csp)|9 Cyclic synchronous velocity (csv)|' +
      '10 Cyclic synchronous torque (cst)', `modes offered: ${options.join('|')}`);
    expect(await page.textContent('#mode') === '3 Profile velocity (pv)', 'pv at power-up');
    expect(await visible('target-form') && !(await visible('position-form')), 'pv: the target velocity');
    await expectBitNames('status', { 12: 'Speed = 0' });
  });

  await check('pp: a target and the new set-point handshake move the drive; the bits take pp names', async () => {
    await selectMode('1');
    await expectBitNames('control', { 4: 'New set-point', 5: 'Change set immediately', 6: 'Relative (0 absolute)' });
    await expectBitNames('status', { 10: 'Target reached', 12: 'Set-point acknowledge' });
    expect(await visible('position-form') && await visible('pp-options') && !(await visible('target-form')),
      'pp: target position, relative and immediate instead of the target velocity');
    await enableByClicks(page, expectPresentState);
    await page.fill('#position-input', '20000');
    await page.click('#position-go');
    await waitResult(page, 'NEW SET-POINT: done: 0x607A = 20000');
    await positionIs('20000');
    await statusBitOn(10);
    const cw = parseInt(await page.textContent('#cw-hex'), 16);
    expect((cw & 0x10) === 0, `bit 4 down after the handshake, control word 0x${cw.toString(16)}`);
    await page.click('label:has(#pp-relative)');
    await page.waitForFunction(() => (parseInt(document.getElementById('cw-hex').textContent, 16) & 0x40) !== 0,
      null, { timeout: patience });
    await page.fill('#position-input', '-5000');
    await page.click('#position-go');
    await waitResult(page, 'relative');
    await positionIs('15000');
    await page.screenshot({ path: path.join(outDir, 'pp-1280x800.png'), fullPage: true });
    await page.click('label:has(#pp-relative)');
    await page.waitForFunction(() => (parseInt(document.getElementById('cw-hex').textContent, 16) & 0x40) === 0,
      null, { timeout: patience });
    expect(await diagramTop() === diagramAtStart, `diagram moved from ${diagramAtStart} to ${await diagramTop()}`);
  });

  await check('hm: homing method 37 and homing start set the position to the home offset', async () => {
    await selectMode('6');
    await expectBitNames('status', { 12: 'Homing attained', 13: 'Homing error' });
    await expectBitNames('control', { 4: 'Homing operation start' });
    expect(await visible('homing-form') && !(await visible('position-form')), 'hm: the homing inputs');
    await page.selectOption('#object-index', '0x607C');
    await page.fill('#object-value', '777');
    await page.click('#object-form button');
    await waitResult(page, 'WRITE 0x607C = 777');
    await page.selectOption('#homing-method', '37');
    await page.click('#homing-start');
    await positionIs('777');
    await statusBitOn(12);
    // The run (POST /api/homing) ends once attained: bit 4 down again, the button back to Start.
    await waitResult(page, 'done: homing attained');
    const method = await page.$eval('#object-values', (t) => [...t.querySelectorAll('tr')]
      .find((r) => r.querySelector('th').textContent.startsWith('0x6098')).querySelector('td').textContent);
    expect(method === '37', `0x6098 reads ${method}`);
    await page.waitForFunction(() => document.getElementById('homing-start').textContent === 'Start homing',
      null, { timeout: patience });
    await click(page, 'disable_voltage');
    await expectPresentState(page, 'SWITCH_ON_DISABLED');
    await selectMode('3');
    await expectBitNames('control', { 4: 'Reserved in pv' });
  });

  await check('the recording exports position and torque as its last columns', async () => {
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#export-csv')]);
    const file = path.join(outDir, 'modes-recording.csv');
    await download.saveAs(file);
    const lines = fs.readFileSync(file, 'utf8').trim().split('\n');
    expect(lines[0].endsWith(',position,position_demand,torque_permille,mode'), `header ${lines[0]}`);
    const positions = lines.slice(1).map((l) => l.split(',')).map((c) => Number(c[c.length - 4]));
    expect(positions.includes(20000) && positions.includes(15000) && positions.includes(777),
      'the recording holds the positions reached');
  });

  await check('phone width 390x844: one column, diagram first, nothing wider than the screen', async () => {
    await page.setViewportSize({ width: 390, height: 844 });
    await page.waitForTimeout(300);
    const m = await page.evaluate(() => {
      const top = (sel) => document.querySelector(sel).getBoundingClientRect().top;
      const d = document.getElementById('diagram').getBoundingClientRect();
      return {
        scrollWidth: document.documentElement.scrollWidth,
        diagramWidth: d.width,
        order: top('.panel-diagram') < top('.panel-commands') && top('.panel-commands') < top('.panel-plant'),
        statusBelowCommands: top('.panel-status') - top('.panel-commands'),
      };
    });
    expect(m.scrollWidth <= 390, `page is ${m.scrollWidth} px wide`);
    expect(m.diagramWidth > 300 && m.diagramWidth <= 390, `diagram is ${m.diagramWidth} px wide`);
    expect(m.order, 'diagram, commands, plant from the top');
    expect(m.statusBelowCommands > 0 && m.statusBelowCommands < 700,
      `the status word starts ${m.statusBelowCommands} px below the commands`);
    await expectPresentState(page, 'SWITCH_ON_DISABLED');
    await page.screenshot({ path: path.join(outDir, 'phone-390x844.png') });
    await page.screenshot({ path: path.join(outDir, 'phone-390x844-full.png'), fullPage: true });
  });

  await check('no errors in the browser console (CSP, script)', async () => {
    expect(problems.length === 0, `console errors: ${JSON.stringify(problems)}`);
  });

  await check('Ctrl-C stops cia402 serve cleanly with exit status 0', async () => {
    await stopCleanly(main, 'cia402 serve');
    expect(main.output.includes('stopping (SIGINT)'), 'it says it stops');
  });

  await check('with the server gone the whole instrument is marked stale and its controls are off', async () => {
    await page.waitForSelector('#stale:not([hidden])', { timeout: patience });
    expect(await page.evaluate(() => document.body.classList.contains('stale')), 'body not marked stale');
    const enabled = await page.evaluate(() =>
      [...document.querySelectorAll('.command, .control')].filter((c) => !c.disabled).length);
    expect(enabled === 0, `${enabled} controls still enabled on a dead page`);
    await page.screenshot({ path: path.join(outDir, 'stale-1280x800.png') });
  });
  // A page whose server is gone keeps retrying it: closed, so it takes no time from the next pages.
  await page.close();

  console.log(`# screenshot: ${screenshotPath}`);
}

runInBrowser(main);
