// The page's parameter list and parameter files in a real browser (issue 35; docs/instrument-page.md,
// "Parameter list and parameter files"), on the drive in this process and on a drive behind
// `cia402 serve --can` (a `cia402 bus` node over socketcand): the list with search and filter, a
// write by index and sub-index marked as differing from the default, a refusal shown with its SDO
// abort code and text, and a parameter set saved, changed and loaded back to the same values with
// the refused entry listed with its abort text.
//   node parameters.test.mjs CIA402_BINARY OUTPUT_DIR
// Environment: CIA402_NODE_MODULES (where npm ci put playwright-core), CIA402_CHROMIUM.
import fs from 'node:fs';
import path from 'node:path';

import {
  patience,
  startRun,
  expect,
  check,
  runInBrowser,
  startServer,
  startCanServer,
  stopCleanly,
  newTab,
} from './page_harness.mjs';

const [, outDir] = startRun('parameters.test.mjs', ['CIA402_BINARY', 'OUTPUT_DIR']);

const rowValue = (page, key) => page.evaluate((k) => {
  const row = document.querySelector(`#param-rows tr[data-key="${k}"]`);
  return row ? { value: row.querySelector('.param-value').textContent, differs: row.classList.contains('differs') } : null;
}, key);

async function waitValue(page, key, value) {
  await page.waitForFunction(([k, v]) => {
    const row = document.querySelector(`#param-rows tr[data-key="${k}"]`);
    return row && row.querySelector('.param-value').textContent === v;
  }, [key, value], { timeout: patience });
}

async function writeInline(page, key, value) {
  const form = `#param-rows tr[data-key="${key}"] form`;
  await page.fill(`${form} input`, String(value));
  await page.click(`${form} button`);
}

async function checks(context, name, server) {
  const page = await newTab(context);
  const problems = [];
  page.on('pageerror', (e) => problems.push(String(e)));
  await check(`${name}: the Parameters panel lists the drive's entries with type, unit, limits and default`, async () => {
    await page.goto(server.url);
    // The page's modules run and have the drive (a state drawn) before the panel is opened: a page
    // that boot.js reloads for a module lost in flight would come back with the panel closed.
    await page.waitForSelector('#diagram .present', { timeout: patience });
    await page.click('#param-details summary');
    await page.waitForSelector('#param-rows tr[data-key="0x6099:1"]', { timeout: patience });
    const cells = await page.$$eval('#param-rows tr[data-key="0x6099:1"] td', (tds) => tds.map((t) => t.textContent));
    expect(cells[1] === 'Speed during search for switch' && cells[2] === 'unsigned32' && cells[3] === 'rpm' &&
      cells[6] === '1000', `0x6099:1 row ${JSON.stringify(cells)}`);
    // The status word in hex with its bits named: SWITCH ON DISABLED shows bit 6 by its name.
    const status = await page.textContent('#param-rows tr[data-key="0x6041:0"] td.param-value');
    expect(/^0x[0-9A-F]{4}: .*Switch on disabled/.test(status), `0x6041 reads "${status}"`);
    // An option code's limits are the values it takes (semantics: 0x605A 0..8), not INT16's range.
    const quickStop = await page.$$eval('#param-rows tr[data-key="0x605A:0"] td', (tds) => tds.map((t) => t.textContent));
    expect(quickStop[5] === '0 … 8', `0x605A limits "${quickStop[5]}"`);
  });
  await check(`${name}: search by index or name and the filters narrow the list`, async () => {
    await page.fill('#param-search', '6099');
    let keys = await page.$$eval('#param-rows tr', (rows) => rows.map((r) => r.dataset.key));
    expect(JSON.stringify(keys) === '["0x6099:0","0x6099:1","0x6099:2"]', `search 6099: ${keys}`);
    await page.fill('#param-search', 'homing method');
    keys = await page.$$eval('#param-rows tr', (rows) => rows.map((r) => r.dataset.key));
    expect(keys.includes('0x6098:0'), `search 'homing method': ${keys}`);
    await page.fill('#param-search', '');
    await page.selectOption('#param-filter', 'writable');
    const writable = await page.$$eval('#param-rows tr', (rows) => rows.map((r) => r.cells[4].textContent));
    expect(writable.length > 10 && writable.every((a) => a === 'rw' || a === 'wo'), `writable: ${writable}`);
    await page.selectOption('#param-filter', 'all');
  });
  await check(`${name}: a write of 0x6099:1 shows the new value marked as differing from the default`, async () => {
    await writeInline(page, '0x6099:1', 500);
    await waitValue(page, '0x6099:1', '500');
    const v = await rowValue(page, '0x6099:1');
    expect(v.differs, `0x6099:1 ${JSON.stringify(v)}`);
    await page.selectOption('#param-filter', 'differs');
    const keys = await page.$$eval('#param-rows tr', (rows) => rows.map((r) => r.dataset.key));
    expect(keys.includes('0x6099:1'), `differs filter: ${keys}`);
    await page.selectOption('#param-filter', 'all');
  });
  await check(`${name}: a refused write shows the SDO abort code and its text`, async () => {
    await writeInline(page, '0x605A:0', 100);
    await page.waitForFunction(() => document.getElementById('param-outcome').textContent.includes('0x06090030'),
      null, { timeout: patience });
    const text = await page.textContent('#param-outcome');
    expect(text.includes('invalid value for parameter'), `outcome: ${text}`);
    expect(text.split('0x06090030').length === 2 && text.split('invalid value for parameter').length === 2,
      `the abort printed once: ${text}`);
  });
  await check(`${name}: a parameter set saved, changed and loaded back gives the same values and lists the refused`, async () => {
    const [download] = await Promise.all([page.waitForEvent('download'), page.click('#param-save')]);
    const saved = fs.readFileSync(await download.path(), 'utf8');
    expect(/\[6099sub1\][^[]*ParameterValue=0x000001F4/.test(saved), 'the file has 0x6099:1 = 500');
    await writeInline(page, '0x6099:1', 900);
    await waitValue(page, '0x6099:1', '900');
    // An option code the profile does not have: the drive refuses it, the rest is written.
    const edited = saved.replace(/(\[605A\][^[]*?)ParameterValue=[^\n]*/, '$1ParameterValue=100');
    const file = path.join(outDir, `${name}-parameters.dcf`);
    fs.writeFileSync(file, edited);
    await page.setInputFiles('#param-load', file);
    await page.waitForFunction(() => document.getElementById('param-outcome').textContent.includes('written'),
      null, { timeout: patience });
    await waitValue(page, '0x6099:1', '500');
    const result = await page.textContent('#param-load-result');
    expect(/refused: 1/.test(result) && result.includes('0x605A:0 = 100: 0x06090030 invalid value for parameter'),
      `load result: ${result}`);
    expect(/skipped: \d+/.test(result) && result.includes('0x6041:0: read-only'), `skipped: ${result}`);
  });
  await check(`${name}: a file that does not parse changes nothing and says its line`, async () => {
    const file = path.join(outDir, `${name}-bad.dcf`);
    fs.writeFileSync(file, '[6099sub1]\nDataType=0x0007\nParameterValue=0x10\nnot a key\n');
    await page.setInputFiles('#param-load', file);
    await page.waitForFunction(() => document.getElementById('param-outcome').textContent.includes('nothing changed'),
      null, { timeout: patience });
    const text = await page.textContent('#param-outcome');
    expect(text.includes('line 4'), `outcome: ${text}`);
    await page.click('#param-read');
    await waitValue(page, '0x6099:1', '500');
  });
  await page.screenshot({ path: path.join(outDir, `parameters-${name}-1280x800.png`) });
  expect(problems.length === 0, `page errors: ${JSON.stringify(problems)}`);
  await page.close();
}

async function main(context) {
  const local = await startServer([]);
  await checks(context, 'local', local);
  await stopCleanly(local, 'local server');

  const { bus, server: remote } = await startCanServer();
  await checks(context, 'can', remote);
  await stopCleanly(remote, '--can server');
  await stopCleanly(bus, 'cia402 bus');
}

runInBrowser(main);
