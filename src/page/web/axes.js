// The profile (a virtual drive starts again under the one chosen) and the overview of several axes.
import { el, label, page, post } from './page.js';

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
      const res = await fetch('/api/axes');
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
        const name = document.createElement('b');
        name.textContent = a.label;
        const state = document.createElement('span');
        state.className = 'axis-state';
        state.textContent = a.state ? label(a.state) : '–';
        const more = document.createElement('span');
        more.className = 'axis-more';
        more.textContent = `${a.status_word || ''} · ${a.velocity === null || a.velocity === undefined ? '–' : a.velocity} rpm` +
          (a.error_code && a.error_code !== '0x0000' ? ` · error ${a.error_code}${a.error_text ? ` (${a.error_text})` : ''}` : '');
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

