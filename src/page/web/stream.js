// The event stream (/api/events): one snapshot per message, the newest the server has when it
// writes. Versions count the snapshots the drive published: a version that skips says the page
// missed some (the browser or the connection could not keep up), and the page says so.
import { api, clientId, el } from './page.js';

export function setControl(allowed) {
  document.body.classList.toggle('view-only', !allowed);
  el('view-only').hidden = allowed;
  for (const c of document.querySelectorAll('.control, .command, #target-input')) {
    c.disabled = !allowed || c.dataset.unavailable === 'true';
  }
}

// `take(snapshot, missed)`: each snapshot and how many versions before it never arrived;
// `takeSamples(batch)`: each batch of the drive's cycles (scope_samples.js).
export function connect(take, takeSamples = null) {
  let version = null;
  // The stream names this page (an EventSource sends no header): each write renews every axis it holds.
  const source = new EventSource(api(`/api/events?client=${clientId}`));
  // While the stream is down every value on the page is old: the whole instrument is marked stale
  // (grayed, controls off) until the next snapshot arrives.
  const stale = (on) => {
    document.body.classList.toggle('stale', on);
    el('stale').hidden = !on;
    for (const c of document.querySelectorAll('.control, .command, #target-input')) {
      if (on) {
        c.dataset.staleDisabled = c.disabled ? 'no' : 'yes';
        c.disabled = true;
      } else if (c.dataset.staleDisabled === 'yes') {
        c.disabled = false;
        delete c.dataset.staleDisabled;
      }
    }
  };
  source.onopen = () => {
    el('link').textContent = 'live';
    el('link').dataset.live = 'true';
  };
  source.onerror = () => {
    el('link').textContent = 'connection lost, retrying…';
    el('link').dataset.live = 'false';
    if (!document.body.classList.contains('stale')) stale(true);
  };
  if (takeSamples) {
    source.addEventListener('samples', (e) => {
      try { takeSamples(JSON.parse(e.data)); } catch (err) { console.error(err); }
    });
  }
  source.onmessage = (e) => {
    try {
      if (document.body.classList.contains('stale')) stale(false);
      const s = JSON.parse(e.data);
      // The first snapshot after a reconnect follows the outage: the versions in between are missed too.
      const missed = version !== null && s.version > version + 1 ? s.version - version - 1 : 0;
      if (version === null || s.version > version) version = s.version;
      take(s, missed);
      document.body.dataset.version = s.version;
    } catch (err) {
      console.error(err);
    }
  };
}

