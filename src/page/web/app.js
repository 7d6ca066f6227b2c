// The instrument control page: its parts, started once /api/info is in, and each snapshot of the
// event stream handed to them. boot.js loads it and calls start().
import { buildAxes, buildProfileChoice, watchControl } from './axes.js';
import { drawDiagram, updateDiagram } from './diagram.js';
import { api, el, headers, page, stateLabel } from './page.js';
import { applyCapabilities, buildObjects, buildPlant, buildSetpoints, showPlant } from './plant.js';
import { buildModePanel, showModePanel } from './modes.js';
import { drawTimeline, onRecording, pollRecording } from './recorder.js';
import { buildScope, drawScopeFrame } from './scope.js';
import { addRows, addSamples, addSnapshot } from './scope_data.js';
import { connect, setControl } from './stream.js';
import { buildBits, buildCommands, buildModes, showWords } from './words.js';
import { showJog } from './jog.js';
import { buildParameters } from './parameters.js';

function update(s, missed) {
  if (s.profile && page.info && s.profile !== page.info.profile.name) {
    // The drive runs under another profile now (chosen here or in another page): draw it anew.
    location.reload();
    return;
  }
  page.snapshot = s;
  page.received = performance.now();
  el('state-name').textContent = stateLabel(s.state);
  const last = s.last_transition;
  const number = last && last.number !== null ? last.number : '?';
  el('last-transition').textContent = last
    ? `${number} (${stateLabel(last.from)} → ${stateLabel(last.to)})${last.inferred ? ', inferred' : ''}`
    : 'none';
  updateDiagram(s);
  showWords(s);
  showPlant(s);
  showModePanel(s);
  showJog(s);
  addSnapshot(s, missed);
}

function animate() {
  drawScopeFrame();
  drawTimeline();
  setTimeout(() => requestAnimationFrame(animate), 50);
}

export async function start() {
  const res = await fetch(api('/api/info'), { headers: headers() });
  page.info = await res.json();
  const p = page.info.profile;
  el('profile').textContent = `${p.title} (profile ${p.name})`;
  if (p.seed) el('profile').title = `transition table from the drive manual ${p.seed}`;
  document.title = `${p.name}: instrument control`;
  for (const a of document.querySelectorAll('.exports a')) a.href = api(a.getAttribute('href'));
  buildProfileChoice();
  buildAxes();
  if (page.info.control) watchControl();
  drawDiagram();
  buildBits();
  buildCommands();
  buildObjects();
  buildModes();
  buildSetpoints();
  buildModePanel();
  buildPlant();
  buildScope();
  buildParameters();
  setControl(page.info.control);
  applyCapabilities(page.info.capabilities);
  onRecording(addRows);
  connect(update, addSamples);
  animate();
  pollRecording();
  setInterval(pollRecording, 500);
}
