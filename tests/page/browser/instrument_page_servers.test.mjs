// The instrument page in a real browser against the servers other than the plain one: a server that
// requires its token (view-only without it, the token leaving the address bar), a PROFIBUS profile
// in its seed's words, several axes, and a drive on a CAN bus (`cia402 serve --can` against a
// `cia402 bus` node over socketcand: inferred transition numbers, the DC-link and STO switches
// disabled with the reason, a fault through 0x2001, the bus going away).
//
//   node instrument_page_servers.test.mjs CIA402_BINARY OUTPUT_DIR
// Environment: CIA402_NODE_MODULES (where npm ci put playwright-core), CIA402_CHROMIUM.
import path from 'node:path';

import {
  patience,
  startRun,
  expect,
  check,
  runInBrowser,
  startServer,
  startCanServer,
  waitPresent,
  expectPresentState,
  expectAccented,
  click,
  stopCleanly,
  pageProblems,
  enableByClicks,
  injectFault,
  clearAndResetFault,
  newTab,
} from './page_harness.mjs';

const [, outDir] = startRun('instrument_page_servers.test.mjs', ['CIA402_BINARY', 'OUTPUT_DIR']);

async function main(context) {

  // --- a server that requires its token -------------------------------------------------------
  const guarded = await startServer(['--token-required']);
  await check('--token-required prints a URL with ?token=', async () => {
    expect(/\?token=[0-9a-f]{32}$/.test(guarded.url), `URL ${guarded.url}`);
  });
  const viewer = await newTab(context, { width: 1280, height: 800 });
  await check('without the token the page is view-only: banner shown, controls disabled', async () => {
    await viewer.goto(guarded.url.replace(/\?token=.*$/, ''));
    await waitPresent(viewer, 'SWITCH_ON_DISABLED');
    await viewer.waitForSelector('#view-only:not([hidden])', { timeout: patience });
    // The scope's own tools only look at the samples, and the parameter list's search, filter, read
    // and save only read: they stay usable without the token.
    const enabled = await viewer.evaluate(() =>
      [...document.querySelectorAll('button, input, select')]
        .filter((c) => !c.disabled && !c.closest('.panel-scope, .param-view')).length);
    expect(enabled === 0, `${enabled} controls still enabled`);
  });
  await viewer.screenshot({ path: path.join(outDir, 'view-only-1280x800.png') });
  await check('with the token the same server obeys: Shutdown leads to READY TO SWITCH ON', async () => {
    await viewer.goto(guarded.url);
    await waitPresent(viewer, 'SWITCH_ON_DISABLED');
    expect(await viewer.isHidden('#view-only'), 'no view-only banner');
    await click(viewer, 'shutdown');
    await expectPresentState(viewer, 'READY_TO_SWITCH_ON');
    await expectAccented(viewer, 2);
  });
  await check('the token leaves the address bar at once and control survives a reload', async () => {
    const address = await viewer.evaluate(() => location.href);
    expect(!address.includes('token'), `address bar still shows ${address}`);
    await viewer.reload();
    await waitPresent(viewer, 'READY_TO_SWITCH_ON');
    expect(await viewer.isHidden('#view-only'), 'view-only after a reload');
    await click(viewer, 'disable_voltage');
    await expectPresentState(viewer, 'SWITCH_ON_DISABLED');
  });
  await stopCleanly(guarded, 'guarded server');
  await viewer.close();

  // --- a PROFIBUS profile: the seed's names, no Halt -------------------------------------------
  const profibus = await startServer(['--profile', 's300-profibus']);
  const pb = await newTab(context, { width: 1280, height: 800 });
  await check('s300-profibus: no Halt button (bit 8 is Jog there), bits named as STW/ZSW', async () => {
    await pb.goto(profibus.url);
    await waitPresent(pb, 'SWITCH_ON_DISABLED');
    expect(await pb.locator('button[data-command="halt"]').count() === 0, 'a Halt button is offered');
    const text = await pb.textContent('body');
    expect(text.includes('Jog'), 'bit 8 is not named Jog');
    expect(text.includes('Inhibit voltage (active low)'), 'STW bit 1 lacks "(active low)"');
  });

  await check("s300-profibus: the seed's own words, its meanings and events as hover text, no jargon", async () => {
    const words = await pb.evaluate(() => ({
      box: document.getElementById('state.SWITCH_ON_DISABLED').textContent,
      boxTitle: document.querySelector('[id="state.SWITCH_ON_DISABLED"] title').textContent,
      quickStop: document.querySelector('button[data-command="quick_stop"]').textContent,
      disableVoltage: document.querySelector('button[data-command="disable_voltage"]').textContent,
      faultReset: document.querySelector('button[data-command="fault_reset"]').textContent,
      t11: document.querySelector('[id^="n11."] title').textContent,
      summary: document.getElementById('state-name').textContent,
      header: document.querySelector('header').textContent,
    }));
    expect(words.box.includes('SWITCH-ON') && words.box.includes('INHIBITED'), `box '${words.box}'`);
    expect(words.boxTitle.includes('Parameters can be transferred'), `hover '${words.boxTitle}'`);
    expect(words.quickStop === 'Fast stop' && words.disableVoltage === 'Inhibit voltage' &&
      words.faultReset === 'Error reset', `commands ${JSON.stringify(words)}`);
    expect(words.t11.includes('Event: Bit 2 is canceled') && words.t11.includes('emergency ramp'),
      `T11 hover '${words.t11}'`);
    expect(words.summary === 'Switch-on inhibited', `summary '${words.summary}'`);
    expect(!/\.txt|semantics\.md|S1\.\./.test(words.header), `header '${words.header}'`);
  });
  await stopCleanly(profibus, 'profibus server');
  await pb.close();

  // --- several axes, and choosing the profile on the page ----------------------------------------
  const multi = await startServer(['--nodes', '3']);
  const mp = await newTab(context, { width: 1280, height: 800 });
  const cardState = (k) => mp.textContent(`.axis-card[data-axis="${k}"] .axis-state`);
  await check('--nodes 3: an overview card per axis, the one shown marked', async () => {
    await mp.goto(multi.url);
    await waitPresent(mp, 'SWITCH_ON_DISABLED');
    await mp.waitForFunction(() => document.querySelectorAll('.axis-card').length === 3, null,
      { timeout: patience });
    expect(await mp.getAttribute('.axis-card[data-axis="1"]', 'aria-current') === 'page', 'axis 1 marked');
    expect((await mp.textContent('h1')).startsWith('axis 1'), 'the heading names the axis');
  });
  await check('--nodes 3: axis 2 is a drive of its own: its Shutdown leaves axes 1 and 3 alone', async () => {
    await mp.click('.axis-card[data-axis="2"]');
    await mp.waitForURL(/axis=2/);
    await waitPresent(mp, 'SWITCH_ON_DISABLED');
    await click(mp, 'shutdown');
    await waitPresent(mp, 'READY_TO_SWITCH_ON');
    await mp.waitForFunction(() => document.querySelector('.axis-card[data-axis="2"] .axis-state')
      .textContent === 'READY TO SWITCH ON', null, { timeout: patience });
    expect(await cardState(1) === 'SWITCH ON DISABLED' && await cardState(3) === 'SWITCH ON DISABLED',
      `axes 1 and 3: ${await cardState(1)}, ${await cardState(3)}`);
    await mp.screenshot({ path: path.join(outDir, 'axes-1280x800.png') });
  });
  await check('choosing s300-profibus on the page restarts axis 2 under it, in its own words', async () => {
    await mp.selectOption('#profile-select', 's300-profibus');
    await mp.waitForFunction(() => document.getElementById('profile').textContent.includes('s300-profibus'),
      null, { timeout: patience });
    await waitPresent(mp, 'SWITCH_ON_DISABLED');
    expect(await mp.textContent('#state-name') === 'Switch-on inhibited', 'seed 003 state name');
    expect(await mp.locator('button[data-command="halt"]').count() === 0, 'no Halt on PROFIBUS');
    const r = await (await fetch(`${multi.url.split('?')[0]}api/state?axis=1`)).json();
    expect(r.profile === 'cia402', `axis 1 runs ${r.profile}`);
  });
  await stopCleanly(multi, '--nodes server');
  await mp.close();

  // --- a drive on a CAN bus: cia402 serve --can against a cia402 bus node ----------------------
  const { bus, server: remote } = await startCanServer();
  const rp = await newTab(context);
  // Its own list: the earlier pages keep retrying their stopped servers.
  const remoteProblems = pageProblems(rp);
  await rp.setViewportSize({ width: 1280, height: 800 });
  await check('--can: the page shows node 1 of the bus, its state, and says numbers are inferred', async () => {
    await rp.goto(remote.url);
    await rp.waitForSelector('#remote[data-status="running"]', { timeout: patience });
    const text = await rp.textContent('#remote');
    expect(text.includes('node 1') && text.includes('inferred'), `banner: "${text}"`);
    await expectPresentState(rp, 'SWITCH_ON_DISABLED');
  });
  await check('--can: DC-link and STO switches disabled with the reason, fault injection offered', async () => {
    await rp.waitForFunction(() => !document.getElementById('fault-switch').disabled, null,
      { timeout: patience });
    const sw = await rp.evaluate(() => ['dc-switch', 'sto-switch'].map((id) => {
      const e = document.getElementById(id);
      return { disabled: e.disabled, title: e.title };
    }));
    for (const s of sw) {
      expect(s.disabled && s.title === 'not available on a remote drive', `switch ${JSON.stringify(s)}`);
    }
    const note = await rp.textContent('#switches-note');
    expect(note.includes('not available on a remote drive'), `note: "${note}"`);
    expect((await rp.textContent('#lamp-sto b')) === 'unknown', 'STO lamp says unknown');
  });
  await check('--can: Shutdown, Switch on, Enable operation: T2, T3, T4 accented, inferred', async () => {
    await enableByClicks(rp, async (p, state, transition) => {
      await expectPresentState(p, state);
      await expectAccented(p, transition);
    });
    const last = await rp.textContent('#last-transition');
    expect(last.includes('inferred'), `last transition "${last}"`);
    expect((await rp.textContent('#cw-hex')) === '0x000F', 'control word 0x000F');
  });
  await rp.screenshot({ path: path.join(outDir, 'remote-operation-enabled-1280x800.png') });
  await check('--can: fault through 0x2001 gives FAULT (T14), reset after clearing gives T15', async () => {
    await injectFault(rp, '0x2310');
    await clearAndResetFault(rp);
  });
  await check('--can: when the bus goes away the page says so and shows no present state', async () => {
    await stopCleanly(bus, 'cia402 bus');
    await rp.waitForSelector('#remote:not([data-status="running"])', { timeout: patience });
    const text = await rp.textContent('#remote');
    expect(text.includes('bus connection failed'), `banner: "${text}"`);
    await rp.waitForFunction(() => document.querySelectorAll('#diagram .state.present').length === 0,
      null, { timeout: patience });
  });
  await rp.screenshot({ path: path.join(outDir, 'remote-bus-gone-1280x800.png') });
  await check('--can: no console errors; Ctrl-C stops the server with exit status 0', async () => {
    expect(remoteProblems.length === 0, `console errors: ${JSON.stringify(remoteProblems)}`);
    await stopCleanly(remote, 'cia402 serve');
  });

}

runInBrowser(main);
