// Authoring (paper section 4.4): a virtual camera that follows the pointer over a capture's scene,
// drawn live by the device's own renderer (POST /api/jobs/ID/preview/frame), keyframes on a
// Catmull-Rom spline, focal length, aperture and a focus point picked by clicking the picture,
// and a render of the shot as a new clip (POST /api/jobs/ID/render). Each frame's coverage says
// whether the viewpoint is inside H(V), the region the views can draw without visible holes, and a
// map shows H(V) over the plane the camera is dragged in, with the views, camera and keyframes.
'use strict';

const Author = (() => {
  const PREVIEW_WIDTH = 640;
  const VALID_H_V = 2;  // a viewpoint is valid when H(V) < 2 (pipeline/core/coverage_report.h)
  const el = (id) => document.getElementById(id);
  let job = null;       // the capture's job id
  let clip = null;      // the clip's frame: width, height, cx, cy, aspect
  let scene = null;     // from the preview session: views, focal_px, depth range
  let camera = null;    // the keyframe being looked through: position_m, direction, up, focal_px, ...
  let baseFocal = 1;    // the clip's first keyframe's focal length
  let extent = 0.1;     // the lens plane's extent, metres: how far one picture width of drag moves
  let keyframes = [];   // [{key, h_v}]
  let region = null;    // the last region drawn: its 3D box and its box in the centre view
  let regionMove = null;  // a taxonomy segment for a region, played before the keyframes
  let lastBitmap = null;  // the picture on show, to draw a region's rectangle over
  let inFlight = 0;
  let pending = false;
  let lastFigures = {};
  let measured = null;  // {key, h_v, valid}: H(V) of the last viewpoint it was measured at
  let map = null;       // H(V) over the plane the camera is dragged in (POST .../preview/map), and its key
  let mapTimer = null;
  const stats = {frames: 0, asked: 0, dropped: 0, coalesced: 0, latencies: []};  // pointer-to-picture times, for the preview benchmark

  const copy = (value) => JSON.parse(JSON.stringify(value));

  function viewpoint(key, width) {
    const height = Math.round(width * clip.height / clip.width);
    return {keyframe: key, width, height,
            clip: {width: clip.width, height: clip.height, cx: clip.cx, cy: clip.cy, aspect: clip.aspect,
                   output_scale: clip.output_scale}};
  }

  async function post(path, body) {
    const reply = await fetch(path, {method: 'POST', headers: {'Content-Type': 'application/json'}, body: JSON.stringify(body)});
    if (!reply.ok) {
      const error = await reply.json().catch(() => ({}));
      throw new Error(error.error || `HTTP ${reply.status}`);
    }
    return reply;
  }

  // Draws the current camera. One frame is on its way at a time (the worker draws one at a time,
  // and two requests could be answered out of order); moves meanwhile coalesce into one more, and
  // a frame older than the one on show would be dropped.
  let asked = 0;
  let shown = 0;
  async function draw(since = performance.now()) {
    if (!camera) return;
    if (inFlight >= 1) {
      if (pending !== false) stats.coalesced += 1;
      pending = pending === false ? since : pending;
      return;
    }
    inFlight += 1;
    const number = ++asked;
    stats.asked += 1;
    try {
      // H(V) costs a second pass: measured when the pointer rests, not on every frame of a drag.
      const key = copy(camera);
      const coverage = !drag;
      const draft = Boolean(drag);  // half size while dragging; the full frame when the pointer rests
      const reply = await post(`/api/jobs/${job}/preview/frame`, {...viewpoint(key, PREVIEW_WIDTH), coverage, draft});
      const figures = JSON.parse(reply.headers.get('X-Preview') || '{}');
      if (coverage) measured = {key: JSON.stringify(key), h_v: figures.h_v, valid: figures.valid};
      const bitmap = await createImageBitmap(await reply.blob());
      if (number > shown) {
        shown = number;
        const canvas = el('author-frame');
        if (canvas.width !== bitmap.width || canvas.height !== bitmap.height) {
          canvas.width = bitmap.width;
          canvas.height = bitmap.height;
        }
        canvas.getContext('2d').drawImage(bitmap, 0, 0);
        if (lastBitmap) lastBitmap.close();
        lastBitmap = bitmap;
        canvas.dataset.frames = String(Number(canvas.dataset.frames || 0) + 1);
        lastFigures = figures;
        if (map) drawMap();
        stats.frames += 1;
        stats.latencies.push(performance.now() - since);
        showStatus();
      } else {
        stats.dropped += 1;
        bitmap.close();
      }
    } catch (error) {
      el('author-status').textContent = `Preview failed: ${error.message}`;
    } finally {
      inFlight -= 1;
      if (pending !== false) {
        const next = pending;
        pending = false;
        draw(next);
      }
    }
  }

  function showStatus() {
    const current = measured && measured.key === JSON.stringify(camera);
    const position = camera.position_m.map((v) => (v * 1000).toFixed(0)).join(', ');
    const focus = camera.focus_at_m ? ` · focus at (${camera.focus_at_m.map((v) => v.toFixed(2)).join(', ')}) m` : '';
    const effects = (camera.effects || []).length;
    const layers = effects ? ` · ${effects} colour effect${effects > 1 ? 's' : ''} on regions` : '';
    const move = regionMove ? ` · opens with a ${regionMove.move} on a region` : '';
    el('author-status').textContent =
      `(${position}) mm · ${Math.round(lastFigures.render_ms)} ms · holes ${(100 * lastFigures.hole_ratio).toFixed(1)}% · ` +
      (!current ? 'H(V) is measured when the pointer rests'
        : measured.valid ? 'inside the valid region H(V)'
          : `outside the valid region: H(V) ${measured.h_v.toFixed(1)} ≥ ${VALID_H_V}`) +
      focus + layers + move;
    el('author-status').className = current && !measured.valid ? 'warning' : '';
  }

  // ---- The H(V) map: the plane the camera is dragged in, seen from behind the lenses ----------------
  // Cells where the views leave few enough holes (H(V) below 2) are green, shading to red beyond;
  // white dots are the views, the cross is the camera, numbered rings the keyframes (red: outside).
  const MAP_CELLS = 12;
  const mapKey = () => JSON.stringify([camera.position_m[2], camera.direction, camera.up, camera.focal_px]);

  function measureMapSoon() {
    clearTimeout(mapTimer);
    mapTimer = setTimeout(measureMap, 400);  // once the wheel or slider rests
  }

  async function measureMap() {
    if (!camera || (map && map.key === mapKey())) return drawMap();
    const key = mapKey();
    try {
      const reply = await post(`/api/jobs/${job}/preview/map`, {viewpoint: viewpoint(camera, PREVIEW_WIDTH), cells: MAP_CELLS});
      map = {...(await reply.json()), key};
      const valid = map.h_v.flat().filter((h) => h < map.valid_below).length;
      el('author-map-text').textContent =
        `H(V) at the camera's depth (${(map.z_m * 1000).toFixed(0)} mm): ${valid} of ${MAP_CELLS * MAP_CELLS} places ` +
        `valid, ${(map.x_m[MAP_CELLS - 1] - map.x_m[0] + map.x_m[1] - map.x_m[0]).toFixed(3)} m across; ` +
        `measured in ${Math.round(map.ms)} ms.`;
    } catch (error) {
      el('author-map-text').textContent = `H(V) map not measured: ${error.message}`;
    }
    drawMap();
  }

  function drawMap() {
    const canvas = el('author-map');
    const context = canvas.getContext('2d');
    context.fillStyle = '#222';
    context.fillRect(0, 0, canvas.width, canvas.height);
    if (!map || !camera) return;
    const n = map.x_m.length;
    const step = map.x_m[1] - map.x_m[0];
    const x0 = map.x_m[0] - step / 2;
    const y0 = map.y_m[0] - step / 2;
    const cell = canvas.width / n;
    const toCanvas = (p) => [(p[0] - x0) / step * cell, (p[1] - y0) / step * cell];
    for (let row = 0; row < n; ++row) {
      for (let column = 0; column < n; ++column) {
        const h = map.h_v[row][column];
        const over = Math.min(1, h / map.valid_below);
        context.fillStyle = h < map.valid_below
          ? `rgb(${Math.round(40 + 120 * over)}, ${Math.round(170 - 40 * over)}, 70)`
          : `rgb(${Math.round(150 + 60 * Math.min(1, h / (4 * map.valid_below)))}, 45, 45)`;
        context.fillRect(column * cell, row * cell, cell - 1, cell - 1);
      }
    }
    context.fillStyle = '#fff';
    for (const view of scene.views) {
      const [x, y] = toCanvas(view.centre_m);
      context.beginPath();
      context.arc(x, y, 2.5, 0, 2 * Math.PI);
      context.fill();
    }
    context.font = '11px system-ui, sans-serif';
    keyframes.forEach((entry, index) => {
      const [x, y] = toCanvas(entry.key.position_m);
      context.strokeStyle = entry.h_v >= VALID_H_V ? '#ff4d4d' : '#ffd43b';
      context.lineWidth = 2;
      context.beginPath();
      context.arc(x, y, 7, 0, 2 * Math.PI);
      context.stroke();
      context.fillStyle = context.strokeStyle;
      context.fillText(String(index + 1), x + 9, y + 4);
    });
    const [cx, cy] = toCanvas(camera.position_m);
    context.strokeStyle = '#4dabf7';
    context.lineWidth = 2;
    context.beginPath();
    context.moveTo(cx - 7, cy);
    context.lineTo(cx + 7, cy);
    context.moveTo(cx, cy - 7);
    context.lineTo(cx, cy + 7);
    context.stroke();
    canvas.dataset.cells = String(n * n);
  }

  function renderKeyframes() {
    el('author-keyframes').replaceChildren(...keyframes.map((entry, index) => {
      const key = entry.key;
      const item = document.createElement('li');
      const flagged = entry.h_v >= VALID_H_V;
      item.className = flagged ? 'warning' : '';
      const focus = key.focus_at_m ? `, focus at ${key.focus_at_m.map((v) => v.toFixed(2)).join(', ')} m` : '';
      item.textContent = `(${key.position_m.map((v) => (v * 1000).toFixed(0)).join(', ')}) mm, ` +
        `focal ${(key.focal_px / baseFocal).toFixed(2)}x, aperture ${(key.aperture_m * 1000).toFixed(1)} mm${focus}` +
        (flagged ? ' — outside H(V)' : '');
      const go = document.createElement('button');
      go.textContent = 'Look';
      go.onclick = () => { camera = copy(key); syncControls(); draw(); measureMapSoon(); };
      const remove = document.createElement('button');
      remove.textContent = 'Remove';
      remove.onclick = () => { keyframes.splice(index, 1); renderKeyframes(); drawMap(); };
      item.append(' ', go, ' ', remove);
      return item;
    }));
    el('author-render').disabled = keyframes.length < 2 && !regionMove;
    el('author-play').disabled = keyframes.length < 2;
  }

  function syncControls() {
    el('author-focal').value = (camera.focal_px / baseFocal).toFixed(2);
    el('author-aperture').value = (camera.aperture_m || 0) * 1000;
    el('author-aperture-text').textContent = camera.aperture_m > 0 ? `${(camera.aperture_m * 1000).toFixed(1)} mm` : 'pinhole';
  }

  // Uniform Catmull-Rom through the keyframes' positions (what the renderer's spline does), the
  // rest linear: the path preview's camera at t in [0, 1].
  function keyAt(t) {
    const keys = keyframes.map((entry) => entry.key);
    const segments = keys.length - 1;
    const s = Math.min(segments - 1e-9, Math.max(0, t * segments));
    const i = Math.floor(s);
    const u = s - i;
    const p = (k) => keys[Math.max(0, Math.min(keys.length - 1, k))].position_m;
    const [p0, p1, p2, p3] = [p(i - 1), p(i), p(i + 1), p(i + 2)];
    const position = [0, 1, 2].map((a) => 0.5 * ((2 * p1[a]) + (-p0[a] + p2[a]) * u +
      (2 * p0[a] - 5 * p1[a] + 4 * p2[a] - p3[a]) * u * u + (-p0[a] + 3 * p1[a] - 3 * p2[a] + p3[a]) * u * u * u));
    const key = copy(keys[i]);
    const next = keys[i + 1];
    key.position_m = position;
    key.direction = key.direction.map((v, a) => v + (next.direction[a] - v) * u);
    key.focal_px += (next.focal_px - key.focal_px) * u;
    key.aperture_m += (next.aperture_m - key.aperture_m) * u;
    return key;
  }

  async function playPath() {
    const steps = 24;
    for (let s = 0; s <= steps; ++s) {
      camera = keyAt(s / steps);
      await draw();
      while (inFlight > 0) await new Promise((resolve) => setTimeout(resolve, 5));
    }
  }

  function shot() {
    const count = keyframes.length;
    const segments = regionMove ? [copy(regionMove)] : [];
    if (count >= 2) {
      segments.push({interpolation: count > 2 ? 'catmull_rom' : 'linear', keyframes: keyframes.map((entry, index) => {
        const key = copy(entry.key);
        key.t = index / (count - 1);
        return key;
      })});
    }
    return {format: 'parallax-shot', version: 1, duration_s: Number(el('author-duration').value), fps: clip.fps, segments};
  }

  // ---- Regions: a rectangle on the picture becomes a colour effect's 3D box or a move's subject ----
  const EFFECTS = {
    saturation: {kind: 'saturation', amount: 1.6, invert: false},
    brightness: {kind: 'brightness', amount: 1.3, invert: false},
    desaturate_background: {kind: 'saturation', amount: 0.15, invert: true},
    dim_background: {kind: 'brightness', amount: 0.45, invert: true},
  };

  function drawRectangle(from, to) {
    const canvas = el('author-frame');
    const context = canvas.getContext('2d');
    if (lastBitmap) context.drawImage(lastBitmap, 0, 0);
    context.strokeStyle = '#ffd43b';
    context.lineWidth = 2;
    context.strokeRect(from.x, from.y, to.x - from.x, to.y - from.y);
  }

  function canvasPoint(event) {
    const canvas = el('author-frame');
    const rect = canvas.getBoundingClientRect();
    return {x: (event.clientX - rect.left) / rect.width * canvas.width, y: (event.clientY - rect.top) / rect.height * canvas.height};
  }

  async function measureRegion(from, to) {
    const rect = [Math.min(from.x, to.x), Math.min(from.y, to.y), Math.abs(to.x - from.x), Math.abs(to.y - from.y)];
    try {
      const reply = await post(`/api/jobs/${job}/preview/region`, {viewpoint: viewpoint(copy(camera), el('author-frame').width), rect});
      region = await reply.json();
      const size = region.region_max_m.map((v, a) => ((v - region.region_min_m[a]) * 100).toFixed(0)).join(' x ');
      el('author-region-text').textContent = `Region: a box of ${size} cm in the scene` +
        (region.box_px ? `, seen by view ${region.view}` : '');
      el('author-region').hidden = false;
    } catch (error) {
      el('author-status').textContent = `No region there: ${error.message}`;
    }
  }

  function applyRegion() {
    if (!region) return;
    const effect = EFFECTS[el('author-region-effect').value];
    if (effect) {
      const diagonal = Math.hypot(...region.region_max_m.map((v, a) => v - region.region_min_m[a]));
      const layer = {...effect, region_min_m: region.region_min_m, region_max_m: region.region_max_m,
                     falloff_m: Math.max(0.01, 0.1 * diagonal)};
      // Every keyframe lists the same layers in the same order (SHOT_FORMAT.md).
      for (const key of [camera, ...keyframes.map((entry) => entry.key)]) key.effects = [...(key.effects || []), layer];
    }
    const move = el('author-region-move').value;
    regionMove = move && region.box_px
      ? {move, effect: 'auto', subjects: [{box_px: region.box_px}], subject_view: -1} : regionMove;
    el('author-status').textContent = (effect ? `Effect ${el('author-region-effect').value} on the region. ` : '') +
      (move ? `The clip opens with a ${move} on the region.` : '');
    el('author-region').hidden = true;
    renderKeyframes();
    draw();
  }

  async function renderClip() {
    el('author-render').disabled = true;
    try {
      const reply = await post(`/api/jobs/${job}/render`, {shot: shot()});
      const body = await reply.json();
      el('author-status').textContent = `Rendering as job ${body.job}; it appears in the gallery when done.`;
      location.hash = '#gallery';
    } catch (error) {
      el('author-status').textContent = `Not rendered: ${error.message}`;
      el('author-render').disabled = false;
    }
  }

  // ---- Pointer: drag moves across the lens plane, wheel dollies, a click may focus ----
  let drag = null;
  let band = null;  // a region being drawn: its first corner, in canvas pixels
  function onPointerDown(event) {
    if (el('author-region-mode').checked) {
      band = {from: canvasPoint(event), to: canvasPoint(event)};
      return;
    }
    drag = {x: event.clientX, y: event.clientY, start: copy(camera.position_m), moved: false};
    event.target.setPointerCapture(event.pointerId);
  }
  function onPointerMove(event) {
    if (band) {
      band.to = canvasPoint(event);
      drawRectangle(band.from, band.to);
      return;
    }
    if (!drag) return;
    const since = performance.now();
    const canvas = el('author-frame');
    const dx = (event.clientX - drag.x) / canvas.clientWidth;
    const dy = (event.clientY - drag.y) / canvas.clientWidth;
    if (Math.abs(dx) + Math.abs(dy) > 0.003) drag.moved = true;
    // Dragging the picture right moves the camera left, as if pulling the scene along.
    camera.position_m = [drag.start[0] - dx * extent * 2, drag.start[1] - dy * extent * 2, drag.start[2]];
    draw(since);
  }
  async function onPointerUp(event) {
    if (band) {
      const drawn = band;
      band = null;
      return measureRegion(drawn.from, canvasPoint(event));
    }
    const wasDrag = drag && drag.moved;
    drag = null;
    if (wasDrag) draw();  // at rest: with its H(V)
    if (wasDrag || !el('author-focus-mode').checked) return;
    const rect = el('author-frame').getBoundingClientRect();
    const width = PREVIEW_WIDTH;
    const x = Math.round((event.clientX - rect.left) / rect.width * width);
    const y = Math.round((event.clientY - rect.top) / rect.height * Math.round(width * clip.height / clip.width));
    try {
      const reply = await post(`/api/jobs/${job}/preview/probe`, {viewpoint: viewpoint(camera, width), x, y});
      const body = await reply.json();
      camera.focus_at_m = body.point_m;
      delete camera.focus_depth_m;
      if (!(camera.aperture_m > 0)) camera.aperture_m = 0.005;
      syncControls();
      draw();
    } catch (error) {
      el('author-status').textContent = `No focus there: ${error.message}`;
    }
  }
  function onWheel(event) {
    event.preventDefault();
    camera.position_m[2] -= Math.sign(event.deltaY) * extent * 0.1;
    draw();
    measureMapSoon();
  }

  async function open(id) {
    job = id;
    keyframes = [];
    camera = null;
    region = null;
    regionMove = null;
    renderKeyframes();
    el('author-title').textContent = `Authoring on the capture of job ${id}`;
    el('author-back').href = `#job/${id}`;
    el('author-status').textContent = 'Building the scene (calibration and depth)…';
    try {
      const details = await (await fetch(`/api/jobs/${id}`)).json();
      const path = details.report.camera_path;
      clip = {width: path.width, height: path.height, cx: path.cx, cy: path.cy, aspect: path.aspect, fps: path.fps,
              output_scale: path.output_scale || 1};
      el('author-duration').value = path.duration_s;
      const original = await (await fetch(`/api/jobs/${id}/shot`)).json();
      const opened = await (await post(`/api/jobs/${id}/preview`, {})).json();
      scene = opened.scene;
      const centres = scene.views.map((view) => view.centre_m);
      const span = (axis) => Math.max(...centres.map((c) => c[axis])) - Math.min(...centres.map((c) => c[axis]));
      extent = Math.max(span(0), span(1), 0.02);
      camera = copy(original.segments[0].keyframes[0]);
      delete camera.t;
      baseFocal = camera.focal_px;
      map = null;
      syncControls();
      await draw();
      await measureMap();
    } catch (error) {
      el('author-status').textContent = `This capture cannot be authored: ${error.message}`;
    }
  }

  function init() {
    const canvas = el('author-frame');
    canvas.addEventListener('pointerdown', onPointerDown);
    canvas.addEventListener('pointermove', onPointerMove);
    canvas.addEventListener('pointerup', onPointerUp);
    canvas.addEventListener('wheel', onWheel, {passive: false});
    el('author-focal').addEventListener('input', () => {
      camera.focal_px = baseFocal * Number(el('author-focal').value);
      draw();
      measureMapSoon();
    });
    el('author-aperture').addEventListener('input', () => {
      camera.aperture_m = Number(el('author-aperture').value) / 1000;
      if (camera.aperture_m > 0 && !camera.focus_at_m && !camera.focus_depth_m) {
        camera.focus_depth_m = (scene.depth_min_m + scene.depth_max_m) / 2;
      }
      syncControls();
      draw();
    });
    el('author-add').addEventListener('click', async () => {
      if (!measured || measured.key !== JSON.stringify(camera)) await draw();  // its H(V), to flag it
      while (inFlight > 0) await new Promise((resolve) => setTimeout(resolve, 5));
      keyframes.push({key: copy(camera), h_v: measured ? measured.h_v : 0});
      renderKeyframes();
      drawMap();
    });
    el('author-play').addEventListener('click', playPath);
    el('author-region-apply').addEventListener('click', applyRegion);
    el('author-render').addEventListener('click', renderClip);
  }

  return {open, init, stats, shot: () => shot()};
})();

window.Author = Author;
Author.init();
