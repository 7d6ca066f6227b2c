// One-click Enable and Stop, and the jog with its dead-man (issue 35; docs/instrument-page.md,
// "Enable, Stop and jog"). An ES module, as the rest of the page. A jog runs only while its
// button is held: the page renews it every RENEW_MS with a time-to-live of TTL_MS, and the server
// stops the drive by itself when the renewals stop, whatever happens to this page. The page also
// releases at once when the button is let go, the pointer leaves it, the tab loses focus or is
// hidden, or the event stream is lost.
import { el, label, page, post } from './page.js';

const TTL_MS = 300;
const RENEW_MS = 100;
let held = null;  // { velocity, button, timer }

const speed = (which) => {
  const v = Number(document.getElementById(`jog-${which}`).value);
  return Number.isFinite(v) && v > 0 ? Math.round(v) : 0;
};

// One jog request at a time, in order: a renewal still on its way must not reach the server after
// the release and start the jog again.
let queue = Promise.resolve();
let renewing = false;
const send = (body) => {
  queue = queue.then(() => post('/api/jog', body));
  return queue;
};

const renew = () => {
  if (!held || renewing) return;
  const mine = held;
  renewing = true;
  send({ velocity: mine.velocity, ttl_ms: TTL_MS }).then((reply) => {
    renewing = false;
    // Refused (shown): stop asking. No release is sent: no jog runs, and its "nothing to do" would
    // take the place of the refusal on the page.
    if (reply === null && held === mine) drop();
  });
};

function drop() {
  clearInterval(held.timer);
  held.button.classList.remove('held');
  held = null;
}

function release() {
  if (!held) return;
  drop();
  send({ velocity: 0 });
}

// The jog buttons act in OPERATION ENABLED only (the server refuses a jog elsewhere with 409): off
// otherwise, with the reason as their title.
export function showJog(s) {
  const reason = s.state === 'OPERATION_ENABLED' ? ''
    : `jog runs in OPERATION ENABLED only (now ${label(s.state)}): Enable first`;
  el('jog-note').textContent = reason;
  el('jog-note').hidden = !reason;
  for (const b of document.querySelectorAll('.jog')) {
    b.disabled = Boolean(reason) || !(page.info && page.info.control);
    b.title = reason || 'hold to run; released when let go';
  }
  if (reason && held) drop();
}

const hold = (button, event) => {
  event.preventDefault();
  if (held || button.disabled) return;
  const rpm = speed(button.dataset.speed) * Number(button.dataset.sign);
  if (rpm === 0) return;
  button.classList.add('held');
  held = { velocity: rpm, button, timer: setInterval(renew, RENEW_MS) };
  renew();
};

for (const button of document.querySelectorAll('.jog')) {
  button.addEventListener('pointerdown', (e) => hold(button, e));
  // No pointer capture: leaving the button must release it, and a captured pointer never leaves.
  for (const end of ['pointerup', 'pointercancel', 'pointerleave']) {
    button.addEventListener(end, release);
  }
  // The keyboard: held while Space or Enter is down.
  button.addEventListener('keydown', (e) => {
    if ((e.key === ' ' || e.key === 'Enter') && !e.repeat) hold(button, e);
  });
  button.addEventListener('keyup', release);
  button.addEventListener('blur', release);
}
window.addEventListener('blur', release);
window.addEventListener('pagehide', release);
document.addEventListener('visibilitychange', () => {
  if (document.hidden) release();
});
// stream.js marks the page stale when the event stream is lost.
new MutationObserver(() => {
  if (document.body.classList.contains('stale')) release();
}).observe(document.body, { attributes: true, attributeFilter: ['class'] });

document.getElementById('enable').addEventListener('click', () => post('/api/enable', {}));
document.getElementById('stop').addEventListener('click', () => {
  release();
  post('/api/stop', {});
});
