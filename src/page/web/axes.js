// The profile (a virtual drive starts again under the one chosen) and the overview of several axes.
import { api, el, headers, label, page, post, showResult } from './page.js';

export function buildProfileChoice() {
  const wrap = el('profile-choice');
  if (!page.info.profiles || page.info.profiles.length < 2) return;
  const sel = el('profile-select');
  for (const p of page.info.profiles) {
    const o = document.createElement('option');
    o.value = p.name;
    o.textContent = `${p.name}: ${p.title}`;
    o.selected = p.name === page.info.profile.name;
    sel.appendChild(o);
  }
  wrap.hidden = false;
  sel.classList.add('control');
  sel.addEventListener('change', async () => {
    const r = await post('/api/profile', { profile: sel.value });
    if (r) location.reload();
    else sel.value = page.info.profile.name;
  });
}

function axisHref(k) {
  const q = new URLSearchParams(location.search);
  q.set('axis', String(k));
  return `?${q.toString()}`;
}

export function buildAxes() {
  if (!page.info.axes || page.info.axes < 2) return;
  el('axes').hidden = false;
  el('axis-name').textContent = `${page.info.axis_label}: `;
  const refresh = async () => {
    try {
      const res = await fetch('/api/axes', { headers: headers() });
      if (!res.ok) return;
      const list = await res.json();
      const nav = el('axes');
      nav.textContent = '';
      for (const a of list) {
        const link = document.createElement('a');
        link.className = 'axis-card';
        link.href = axisHref(a.axis);
        link.dataset.axis = a.axis;
        if (a.axis === page.info.axis) link.setAttribute('aria-current', 'page');
        link.dataset.control = a.control;
        const name = document.createElement('b');
        name.textContent = a.label;
        const state = document.createElement('span');
        state.className = 'axis-state';
        state.textContent = a.state ? label(a.state) : '–';
        const more = document.createElement('span');
        more.className = 'axis-more';
        more.textContent = `${a.status_word || ''} · ${a.velocity === null || a.velocity === undefined ? '–' : a.velocity} rpm` +
          (a.error_code && a.error_code !== '0x0000' ? ` · error ${a.error_code}${a.error_text ? ` (${a.error_text})` : ''}` : '');
        // Which page controls it: this one, another one (none: nothing said).
        more.textContent += a.control === 'here' ? ' · held here' : a.control === 'elsewhere' ? ' · held elsewhere' : '';
        link.append(name, state, more);
        nav.appendChild(link);
      }
    } catch (e) {
      // The stale marking tells that the server is gone.
    }
  };
  refresh();
  setInterval(refresh, 1000);
}


// The control model (docs/instrument-page.md, "Control model"): which axes this page holds, and
// whether the one it shows is controlled by another page, which it can take over explicitly.
export function watchControl() {
  const banner = el('control-banner');
  const take = el('take-control');
  take.disabled = false;  // a page that may control (app.js starts this only then)
  const show = (c) => {
    const held = c.held.length ? `This page controls axis ${c.held.join(', axis ')}.` : 'This page controls no axis yet.';
    const here = c.control === 'elsewhere' ? ` Axis ${c.axis} is controlled by another page: its commands are refused here.` : '';
    el('control-text').textContent = held + here;
    banner.dataset.control = c.control;
    // Only where it tells something the cards do not: another page has this axis, or this page
    // holds another one besides.
    banner.hidden = c.control !== 'elsewhere' && !c.held.some((k) => k !== c.axis);
    take.hidden = c.control !== 'elsewhere';
  };
  const refresh = async () => {
    try {
      const res = await fetch(api('/api/control'), { headers: headers() });
      if (res.ok) show(await res.json());
    } catch (e) {
      // The stale marking tells that the server is gone.
    }
  };
  take.addEventListener('click', async () => {
    const c = await post('/api/control', { hold: true });
    if (c) {
      show(c);
      showResult('done', `took control of axis ${c.axis}`);
    }
  });
  refresh();
  setInterval(refresh, 1000);
}
