// The camera's web app: the button with live progress, the gallery, a job's details and the
// settings, on one page switched by the address's fragment (#gallery, #job/ID, #settings).
// Everything comes from the daemon's JSON API (openapi.yaml) and its event stream; no framework
// and nothing fetched from elsewhere.
'use strict';

const $ = (id) => document.getElementById(id);
const jobs = new Map();  // id -> job record, as /api/jobs lists them

async function api(path, options = {}) {
  const reply = await fetch(path, {credentials: 'same-origin', ...options});
  if (reply.status === 401) {
    location.href = '/login.html';
    throw new Error('not logged in');
  }
  const body = await reply.json().catch(() => ({ok: false, error: `HTTP ${reply.status}`}));
  if (!reply.ok) throw new Error(body.error || `HTTP ${reply.status}`);
  return body;
}

function say(text) { $('message').textContent = text; }

function element(tag, props = {}, children = []) {
  const node = document.createElement(tag);
  Object.assign(node, props);
  for (const child of children) node.append(child);
  return node;
}

// ---- The gallery ------------------------------------------------------------------------------

function card(job) {
  const item = element('li', {className: `card state-${job.state}`});
  item.dataset.job = job.id;
  const link = element('a', {href: `#job/${job.id}`});
  if (job.state === 'done') {
    const poster = element('img', {src: `/api/jobs/${job.id}/poster`, alt: `clip ${job.id}`, loading: 'lazy'});
    // The small looping preview plays while the pointer rests on the card.
    link.addEventListener('pointerenter', () => { poster.src = `/api/jobs/${job.id}/preview`; });
    link.addEventListener('pointerleave', () => { poster.src = `/api/jobs/${job.id}/poster`; });
    poster.addEventListener('error', () => poster.replaceWith(element('div', {className: 'placeholder', textContent: 'no poster'})));
    link.append(poster);
  } else {
    link.append(element('div', {className: 'placeholder', textContent: job.state}));
  }
  const caption = element('span', {className: 'caption', textContent: `${job.id} · ${job.state}`});
  link.append(caption);
  item.append(link);
  return item;
}

function renderGallery() {
  const list = $('gallery');
  list.replaceChildren(...[...jobs.values()].reverse().map(card));
  $('empty').hidden = jobs.size > 0;
}

async function loadJobs() {
  const body = await api('/api/jobs');
  jobs.clear();
  for (const job of body.jobs) jobs.set(job.id, job);
  renderGallery();
}

// ---- The button and live progress ---------------------------------------------------------------

async function press() {
  $('press').disabled = true;
  try {
    const body = await api('/api/press', {method: 'POST'});
    say(`Job ${body.job}: capturing…`);
  } catch (error) {
    say(`The press failed: ${error.message}`);
  } finally {
    setTimeout(() => { $('press').disabled = false; }, 500);
  }
}

function showProgress(job, stage, fraction) {
  $('progress').hidden = false;
  $('progress-job').textContent = `Job ${job}`;
  $('progress-stage').textContent = stage;
  $('progress-bar').value = fraction;
}

function onEvent(event) {
  if (event.type === 'progress') {
    showProgress(event.job, event.stage, event.progress);
  } else if (event.type === 'job') {
    const job = event.job;
    jobs.set(job.id, job);
    renderGallery();
    if (job.state === 'done') {
      $('progress').hidden = true;
      say(`Job ${job.id}: the clip is ready.`);
    } else if (job.state === 'failed') {
      $('progress').hidden = true;
      say(`Job ${job.id} failed: ${job.error}`);
    } else {
      showProgress(job.id, job.state, 0);
    }
    if (location.hash === `#job/${job.id}`) showJob(job.id);
  } else if (event.type === 'deleted') {
    jobs.delete(event.job);
    renderGallery();
  } else if (event.type === 'state') {
    $('daemon-state').textContent = event.stopping ? `${event.state}, stopping` : event.state;
    $('daemon-state').dataset.state = event.state;
  }
}

function listen() {
  const stream = new EventSource('/api/events');
  stream.onmessage = (message) => onEvent(JSON.parse(message.data));
  stream.addEventListener('resync', () => loadJobs());
  stream.onopen = () => loadStatus();
  stream.onerror = () => { $('daemon-state').textContent = 'reconnecting'; };
}

async function loadStatus() {
  const status = await api('/api/status');
  $('daemon-state').textContent = status.stopping ? `${status.state}, stopping` : status.state;
  $('daemon-state').dataset.state = status.state;
  if (status.processing) showProgress(status.processing.job, status.processing.stage, status.processing.progress);
  showSettings(status.settings);
  const storage = status.storage || {};
  $('storage-facts').replaceChildren(...facts({
    'Free': storage.free_mb !== undefined ? `${Math.round(storage.free_mb)} MB` : '?',
    'Used': storage.used_mb !== undefined ? `${storage.used_mb.toFixed(1)} MB` : '?',
    'Full': storage.full ? `yes: ${storage.reason}` : 'no',
    'Source': status.source,
  }));
  return status;
}

// ---- A job's details -------------------------------------------------------------------------------

function facts(pairs) {
  const nodes = [];
  for (const [key, value] of Object.entries(pairs)) {
    if (value === undefined || value === null || value === '') continue;
    nodes.push(element('dt', {textContent: key}), element('dd', {textContent: String(value)}));
  }
  return nodes;
}

async function showJob(id) {
  const body = await api(`/api/jobs/${id}`);
  const job = body.job;
  const report = body.report || {};
  $('job-title').textContent = `Job ${job.id}: ${job.state}`;
  const video = $('job-video');
  const clipName = body.files.clip || '';
  if (clipName.endsWith('.mp4')) {
    if (!video.src.endsWith(body.links.clip)) {
      video.src = body.links.clip;
      video.poster = body.links.poster;
    }
    video.hidden = false;
  } else {
    video.removeAttribute('src');
    video.hidden = true;
  }
  // A GIF or WebP clip (the settings' format) plays as an image.
  const animated = /\.(gif|webp)$/.test(clipName);
  if (animated && !$('job-animation').src.endsWith(body.links.clip)) $('job-animation').src = body.links.clip;
  if (!animated) $('job-animation').removeAttribute('src');
  $('job-animation').hidden = !animated;
  const downloads = [];
  if (clipName) downloads.push(element('a', {href: body.links.clip, download: `parallax-${clipName}`, textContent: `Download ${clipName}`}));
  if (body.files.preview) downloads.push(' ', element('a', {href: body.links.preview, download: `parallax-${job.id}.webp`, textContent: 'Download the preview (WebP)'}));
  $('job-downloads').replaceChildren(...downloads);
  const path = report.camera_path || {};
  $('job-facts').replaceChildren(...facts({
    'Move': path.move,
    'Made as': path.kind,  // novel_view (a 3D move), morph or pan_zoom_2d
    'Why': path.reason,
    'Subjects': Array.isArray(path.subjects) ? path.subjects.length : undefined,
    'Views': report.num_views,
    'Size': report.width ? `${report.width}x${report.height}, ${report.frames} frames` : undefined,
    'Renderer': report.render_backend ? report.render_backend.name : undefined,
    'Pressed': job.created_at,
    'Processing': job.process_ms ? `${(job.process_ms / 1000).toFixed(1)} s` : undefined,
    'Note': job.note,
    'Error': job.error,
  }));
  const warnings = report.warnings || [];
  $('job-warnings').replaceChildren(...(warnings.length ? warnings.map((w) => element('li', {textContent: w}))
                                                         : [element('li', {textContent: 'none'})]));
  const stages = report.timings_ms || {};
  $('job-stages').tBodies[0].replaceChildren(...Object.entries(stages).map(([stage, ms]) =>
    element('tr', {}, [element('td', {textContent: stage}), element('td', {textContent: `${Math.round(ms)} ms`})])));
  $('job-report').textContent = JSON.stringify(report, null, 2);
  $('job-author').href = `#author/${job.id}`;
  $('job-author').hidden = !body.files.shot;
  $('job-delete').onclick = async () => {
    if (!confirm(`Delete job ${job.id}'s clip and its raw capture?`)) return;
    try {
      await api(`/api/jobs/${job.id}`, {method: 'DELETE'});
      location.hash = '#gallery';
    } catch (error) {
      say(`Not deleted: ${error.message}`);
    }
  };
}

// ---- Settings ----------------------------------------------------------------------------------------

// What the settings page sets for the next presses; "" (null in the API) = the daemon's config.
const SETTINGS = ['move', 'effect', 'format', 'size'];

function showSettings(settings) {
  for (const field of SETTINGS) $(`setting-${field}`).value = (settings && settings[field]) || '';
}

async function saveSettings(event) {
  event.preventDefault();
  try {
    const wanted = {};
    for (const field of SETTINGS) wanted[field] = $(`setting-${field}`).value || null;
    const body = await api('/api/settings', {
      method: 'PUT',
      headers: {'Content-Type': 'application/json'},
      body: JSON.stringify(wanted),
    });
    const said = SETTINGS.map((field) => `${field} ${body.settings[field] || 'as configured'}`);
    $('settings-message').textContent = `Saved: the next presses use ${said.join(', ')}.`;
  } catch (error) {
    $('settings-message').textContent = `Not saved: ${error.message}`;
  }
}

async function showTokenQr() {
  const reply = await fetch('/api/token.svg');
  if (!reply.ok) return;  // shown only at the device itself
  const loginUrl = reply.headers.get('X-Parallax-Login-Url');
  $('token-qr').src = URL.createObjectURL(await reply.blob());
  $('token-how').textContent = loginUrl
    ? `Scan with a phone on the same network to open ${loginUrl} logged in.`
    : 'The web app listens on this device only (config http.listen); listen on 0.0.0.0:8080 to reach it ' +
      'from a phone. The code holds the access token.';
  $('token-box').hidden = false;
}

// ---- Views ---------------------------------------------------------------------------------------------

function route() {
  const hash = location.hash || '#gallery';
  const jobMatch = hash.match(/^#job\/(\d+)$/);
  const authorMatch = hash.match(/^#author\/(\d+)$/);
  $('gallery-view').hidden = !(hash === '#gallery');
  $('shoot').hidden = !(hash === '#gallery');
  $('job-view').hidden = !jobMatch;
  $('author-view').hidden = !authorMatch;
  $('settings-view').hidden = hash !== '#settings';
  if (!jobMatch) $('job-video').pause();
  if (jobMatch) showJob(jobMatch[1]).catch((error) => say(error.message));
  if (authorMatch) window.Author.open(authorMatch[1]);
  if (hash === '#settings') { loadStatus(); showTokenQr(); }
}

$('press').addEventListener('click', press);
$('settings-form').addEventListener('submit', saveSettings);
window.addEventListener('hashchange', route);
route();
loadJobs().catch((error) => say(error.message));
listen();
