// Starts the page: loads its ES modules and runs app.js's start(). A load that fails is retried by
// reloading the page, at most 3 times in a row: Chromium aborts the requests in flight when the
// machine's network interfaces change (ERR_NETWORK_CHANGED), and one module that did not arrive
// would otherwise leave the whole page dead. A classic script, so it can catch that failure.
'use strict';

(() => {
  const key = 'cia402-boot-retries';
  let tries = null;  // null: no storage, so no count to bound the reloads by: no retry
  try { tries = Number(sessionStorage.getItem(key)) || 0; } catch (e) { /* storage off */ }
  const give_up = (e) => {
    const link = document.getElementById('link');
    if (link) link.textContent = `cannot load the page: ${e && e.message ? e.message : e}`;
    console.error(e);
  };
  import('/app.js')
    .then((app) => app.start())
    .then(() => {
      try { sessionStorage.removeItem(key); } catch (e) { /* storage off */ }
    })
    .catch((e) => {
      if (tries === null || tries >= 3) {
        give_up(e);
        return;
      }
      sessionStorage.setItem(key, String(tries + 1));
      setTimeout(() => location.reload(), 500);
    });
})();
