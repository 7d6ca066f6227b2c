// The docs' picture of each panel of the instrument page (docs/images/panel-<name>.png), taken from
// a virtual drive that has just done something worth seeing: enabled, a profile position move, a
// fault raised and reset, so the scope, the error history and the parameter list are not empty.
// Not a test: run.sh runs it only with CIA402_UPDATE_SCREENSHOT=1.
//   node panel_pictures.mjs CIA402_BINARY OUTPUT_DIR IMAGES_DIR
// Every `section.panel` is taken, named by its class (panel-scope -> panel-scope.png), so a new
// panel gets its picture without a change here.
import fs from 'node:fs';
import path from 'node:path';
import {
  closeBrowser, launchBrowser, patience, run, runChecks, startRun, startServer, stopServer, waitPresent,
} from './page_harness.mjs';

const [, , imagesDir] = startRun('panel_pictures.mjs', ['CIA402_BINARY', 'OUTPUT_DIR', 'IMAGES_DIR']);

async function post(base, route, body) {
  const res = await fetch(new URL(route, base), {
    method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify(body),
  });
  return res.status;
}

async function main() {
  const server = await startServer([]);
  await launchBrowser();
  const page = await run.context.newPage();
  run.currentPage = page;
  await page.goto(server.url);
  await waitPresent(page, 'SWITCH_ON_DISABLED');

  // Something on every panel: an enabled drive, a fault and its reset in the history, then a move.
  await post(server.url, 'api/enable', {});
  await waitPresent(page, 'OPERATION_ENABLED');
  await post(server.url, 'api/plant', { fault: true, fault_code: 0x2310 });
  await waitPresent(page, 'FAULT');
  await post(server.url, 'api/plant', { fault: false });
  await post(server.url, 'api/command', { command: 'fault_reset' });
  await waitPresent(page, 'SWITCH_ON_DISABLED');
  await post(server.url, 'api/enable', {});
  await waitPresent(page, 'OPERATION_ENABLED');
  await post(server.url, 'api/plant', { target_velocity: 1000 });
  await page.waitForTimeout(2500);

  // The parameter list opened, narrowed to the homing objects (the whole list is 200 rows).
  await page.click('#param-details summary');
  await page.waitForSelector('#param-rows tr', { timeout: patience });
  await page.fill('#param-search', '609');
  await page.waitForTimeout(300);

  const names = await page.$$eval('section.panel', (sections) => sections.map((s) =>
    [...s.classList].find((c) => c.startsWith('panel-')) ?? null));
  let taken = 0;
  for (const name of names) {
    if (!name) continue;
    const panel = page.locator(`section.${name}`).first();
    if (!(await panel.isVisible())) continue;
    await panel.scrollIntoViewIfNeeded({ timeout: patience });
    await panel.screenshot({ path: path.join(imagesDir, `${name}.png`) });
    taken += 1;
    console.log(`${name}.png`);
  }
  if (taken === 0) throw new Error('no panel was visible');

  // The plant panel in homing mode, method 3 under way: the homing form, its phase line and the
  // mode panel's bits by their homing names.
  await page.selectOption('#mode-select', '6');
  await page.waitForFunction(() => !document.getElementById('homing-form').hidden, null, { timeout: patience });
  await page.selectOption('#homing-method', '3');
  await page.click('#homing-start');
  await page.waitForTimeout(500);
  await page.locator('section.panel-plant').screenshot({ path: path.join(imagesDir, 'panel-plant-homing.png') });
  console.log('panel-plant-homing.png');
  fs.writeFileSync(path.join(run.outDir, 'panel-pictures.txt'), `${taken} panels\n`);
  await closeBrowser();
  await stopServer(server);
}

runChecks(main);
