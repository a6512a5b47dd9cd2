#!/usr/bin/python3
"""The live preview drawn two ways, measured side by side: by the device (the authoring page's
renderer: the daemon's preview worker draws a frame, the page fetches it) and in the browser (the
device exports the layered scene once, POST /api/jobs/ID/preview/scene, and the GL back end's own
shaders draw it on WebGL 2, tests/browser/web_scene_renderer.js). A real parallaxd on the
simulated camera makes a clip; headless Chromium then opens its capture as the authoring page does
and, at viewpoints along a sideways drag of the clip's first keyframe, asks the device for the
frame (lossless) and draws the same camera itself. It prints, for each: the time from asking to a
frame on the page, frames a second while dragging, and what the browser must first download and
upload; and how far the browser's frames are from the device's (PSNR over the pixels the browser
drew, and the share it left as holes: its hole filling is the back end's CPU step, not ported).

Usage: web_scene_bench.py PARALLAXD [--tile 640x480] [--width 640] [--check-db DB] [--screenshot PNG]
--check-db: exit 1 unless the browser's frames agree with the device's to DB on the pixels it drew
(the test's use). Exit 77 (skipped) when Chromium, chromedriver, Selenium or WebGL 2 is missing."""

import argparse
import math
import os
import re
import shutil
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import web_app_test  # noqa: E402  (the daemon and browser helpers)
from gallery_bench import press_and_wait  # noqa: E402
from web_app_test import camera_and_browser, skip  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SHADERS = os.path.join(HERE, "..", "..", "pipeline", "render", "gl", "gl_render_shaders.h")
SHADER_NAMES = {"full_screen_vertex": "kFullScreenVertexShader", "view_weights": "kViewWeightsFragmentShader",
                "segment_vertex": "kSegmentVertexShader", "segment_fragment": "kSegmentFragmentShader",
                "soft_z_resolve": "kSoftZResolveFragmentShader"}


def back_end_shaders():
    """The GL back end's shader texts, read from its header: the browser runs the same code."""
    with open(SHADERS) as f:
        text = f.read()
    shaders = {}
    for key, name in SHADER_NAMES.items():
        match = re.search(name + r' = R"\((.*?)\)";', text, re.S)
        if not match:
            raise RuntimeError(f"{name} not found in {SHADERS}")
        shaders[key] = match.group(1)
    return shaders


# In the page: opens the preview, fetches the scene, then per viewpoint the device's frame and the
# browser's; then a drag of 3 s each way. Resolves with the figures.
MEASURE = r"""
const [job, shaders, width, steps, done] = arguments;
const post = async (path, body) => {
  const reply = await fetch(path, {method: 'POST', headers: {'Content-Type': 'application/json'}, body: JSON.stringify(body)});
  if (!reply.ok) throw new Error(`${path}: HTTP ${reply.status} ${await reply.text()}`);
  return reply;
};
const median = (values) => values.slice().sort((a, b) => a - b)[Math.floor(values.length / 2)];
(async () => {
  const details = await (await fetch(`/api/jobs/${job}`)).json();
  const path = details.report.camera_path;
  const clip = {width: path.width, height: path.height, cx: path.cx, cy: path.cy, aspect: path.aspect,
                output_scale: path.output_scale || 1};
  const shot = await (await fetch(`/api/jobs/${job}/shot`)).json();
  const opened = await (await post(`/api/jobs/${job}/preview`, {})).json();
  const centres = opened.scene.views.map((view) => view.centre_m);
  const extent = Math.max(...centres.map((c) => c[0])) - Math.min(...centres.map((c) => c[0]));
  const height = Math.round(width * clip.height / clip.width);
  const key0 = shot.segments[0].keyframes[0];
  delete key0.t;
  const keyAt = (s) => { const key = JSON.parse(JSON.stringify(key0)); key.position_m[0] += s * extent; return key; };
  const viewpoint = (key, extra) => ({keyframe: key, width, height, clip, ...extra});

  let started = performance.now();
  const sceneReply = await post(`/api/jobs/${job}/preview/scene`, {});
  const scene = await sceneReply.arrayBuffer();
  const downloadMs = performance.now() - started;
  const canvas = document.createElement('canvas');
  document.body.replaceChildren(canvas);
  const gl = canvas.getContext('webgl2', {antialias: false});
  if (!gl) { done({skip: 'no WebGL 2 in this browser'}); return; }
  if (!gl.getExtension('EXT_color_buffer_float')) { done({skip: 'no EXT_color_buffer_float (float targets) in this browser'}); return; }
  started = performance.now();
  const renderer = new WebSceneRenderer(gl, scene, shaders);
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));  // the uploads done
  const uploadMs = performance.now() - started;
  const work = document.createElement('canvas');
  const context2d = work.getContext('2d', {willReadFrequently: true});

  const cases = [];
  const jpegBytes = [];
  let firstCamera = null, lastCamera = null;
  for (let i = 0; i < steps; ++i) {
    const key = keyAt(-0.5 + i / (steps - 1));
    // The device, as the authoring page asks (a JPEG frame fetched and decoded) ...
    let t0 = performance.now();
    let reply = await post(`/api/jobs/${job}/preview/frame`, viewpoint(key, {}));
    const jpeg = await reply.blob();
    await createImageBitmap(jpeg);
    const deviceMs = performance.now() - t0;
    jpegBytes.push(jpeg.size);
    // ... then lossless, with the camera it drew, for the comparison.
    reply = await post(`/api/jobs/${job}/preview/frame`, viewpoint(key, {lossless: true}));
    const figures = JSON.parse(reply.headers.get('X-Preview'));
    const image = await createImageBitmap(await reply.blob());
    const camera = figures.camera;
    firstCamera = firstCamera || camera;
    lastCamera = camera;
    t0 = performance.now();
    if (i === 0) renderer.render(camera);  // the first frame compiles and allocates: timed apart
    const firstMs = performance.now() - t0;
    renderer.render(camera);
    const browserMs = renderer.stats.frame_ms;
    const setupMs = renderer.stats.setup_ms;
    if (image.width !== camera.width || image.height !== camera.height) {
      cases.push({deviceMs, browserMs, setupMs, firstMs, compared: false, deviceRenderMs: figures.render_ms});
      continue;
    }
    work.width = image.width;
    work.height = image.height;
    context2d.drawImage(image, 0, 0);
    const device = context2d.getImageData(0, 0, image.width, image.height).data;
    const ours = renderer.resolvedPixels();
    let sum = 0, drawn = 0;
    for (let p = 0; p < camera.width * camera.height; ++p) {
      if (ours[4 * p + 3] < 0.5) continue;
      drawn += 1;
      for (let c = 0; c < 3; ++c) {
        const mine = Math.min(255, Math.max(0, Math.round(ours[4 * p + 2 - c])));  // BGR -> RGB
        const d = mine - device[4 * p + c];
        sum += d * d;
      }
    }
    cases.push({deviceMs, browserMs, setupMs, firstMs, compared: true, holes: 1 - drawn / (camera.width * camera.height),
                mse: sum / Math.max(1, 3 * drawn), deviceRenderMs: figures.render_ms});
  }

  // A drag of 3 s along the same path for both: the browser draws every animation frame at the
  // moving camera; the device is asked for draft frames one after another, as the page asks (one
  // in flight). The drag's middle is the keyframe itself, halfway between the first and last
  // viewpoints compared (only the position moved, so the translation is halfway too).
  const middle = JSON.parse(JSON.stringify(firstCamera));
  middle.translation = middle.translation.map((value, i) => (value + lastCamera.translation[i]) / 2);
  const dragCamera = (s) => {
    const c = JSON.parse(JSON.stringify(middle));
    const world = [0, 1, 2].map((j) => -(c.rotation[j] * c.translation[0] + c.rotation[3 + j] * c.translation[1] + c.rotation[6 + j] * c.translation[2]));
    world[0] += s * extent;
    c.translation = [0, 1, 2].map((i) => -(c.rotation[3 * i] * world[0] + c.rotation[3 * i + 1] * world[1] + c.rotation[3 * i + 2] * world[2]));
    return c;
  };
  let frames = 0;
  started = performance.now();
  await new Promise((resolve) => {
    const step = () => {
      const s = (performance.now() - started) / 1000;
      if (s > 3) { resolve(); return; }
      renderer.render(dragCamera(0.4 * Math.sin(2 * s)));
      frames += 1;
      requestAnimationFrame(step);
    };
    requestAnimationFrame(step);
  });
  const browserFps = frames / ((performance.now() - started) / 1000);
  let deviceFrames = 0;
  started = performance.now();
  while (performance.now() - started < 3000) {
    const asked = performance.now();
    const s = (asked - started) / 1000;
    const reply = await post(`/api/jobs/${job}/preview/frame`, viewpoint(keyAt(0.4 * Math.sin(2 * s)), {draft: true}));
    await createImageBitmap(await reply.blob());
    deviceFrames += 1;
    // At most 40 requests a second: under the server's limit per address (http.requests_per_s).
    await new Promise((resolve) => setTimeout(resolve, Math.max(0, 25 - (performance.now() - asked))));
  }
  const deviceFps = deviceFrames / ((performance.now() - started) / 1000);
  const compared = cases.filter((c) => c.compared);
  done({
    views: opened.scene.views.length, jpeg_bytes: median(jpegBytes), scene_bytes: scene.byteLength, download_ms: downloadMs, upload_ms: uploadMs,
    renderer: gl.getParameter(gl.getExtension('WEBGL_debug_renderer_info').UNMASKED_RENDERER_WEBGL),
    size: [firstCamera.width, firstCamera.height], instances: renderer.stats.instances,
    first_frame_ms: cases[0].firstMs,
    device_ms: median(cases.map((c) => c.deviceMs)), device_render_ms: median(cases.map((c) => c.deviceRenderMs)),
    browser_ms: median(cases.map((c) => c.browserMs)), browser_setup_ms: median(cases.map((c) => c.setupMs)),
    browser_fps: browserFps, device_fps: deviceFps,
    mse: compared.map((c) => c.mse), holes: compared.map((c) => c.holes), compared: compared.length, steps,
  });
})().catch((error) => done({error: String(error && error.stack || error)}));
"""


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("parallaxd")
    parser.add_argument("--tile", default="640x480", help="the simulated Pop9's tile size, WxH")
    parser.add_argument("--width", type=int, default=640, help="the preview's width (the authoring page's: 640)")
    parser.add_argument("--steps", type=int, default=7, help="viewpoints along the drag compared (at least 2)")
    parser.add_argument("--check-db", type=float, default=None,
                        help="exit 1 unless every compared frame agrees with the device's to this PSNR (dB)")
    parser.add_argument("--screenshot", help="save the page (the browser's last frame) as this PNG")
    args = parser.parse_args()
    if args.steps < 2:
        parser.error("--steps: at least 2")
    for path in (web_app_test.CHROMIUM, web_app_test.CHROMEDRIVER):
        if not shutil.which(path):
            skip(f"{path} is missing (scripts/bootstrap --test installs chromium and chromium-driver)")
    with open(os.path.join(HERE, "web_scene_renderer.js")) as f:
        renderer_js = f.read()
    tile = [int(v) for v in args.tile.split("x")]
    with camera_and_browser(args.parallaxd, tile) as (daemon, driver):
        job = press_and_wait(daemon, 1)[0]
        if job["state"] != "done":
            print(f"FAIL the simulated capture's clip did not finish: {job}")
            return 1
        driver.get(daemon.url)
        driver.execute_script(renderer_js)
        driver.set_script_timeout(600)
        figures = driver.execute_async_script(MEASURE, job["id"], back_end_shaders(), args.width, args.steps)
        if args.screenshot:
            driver.save_screenshot(args.screenshot)
    if "skip" in figures:
        skip(figures["skip"])
    if "error" in figures:
        print("FAIL the measurement stopped: " + figures["error"])
        return 1
    if not figures["compared"]:
        print("FAIL no viewpoint could be compared: the device drew each at another size than it sent")
        return 1
    psnr = [10 * math.log10(255 * 255 / mse) if mse > 0 else float("inf") for mse in figures["mse"]]
    worst = min(psnr)
    size = "x".join(str(v) for v in figures["size"])
    print(f"the live preview of a simulated Pop9 capture ({figures['views']} views of {args.tile}), "
          f"frames of {size}, browser {figures['renderer']}")
    rows = [
        ("what the page fetches", f"each frame, a JPEG of {figures['jpeg_bytes'] / 1024:.0f} KB", f"the scene once, {figures['scene_bytes'] / 2**20:.1f} MiB "
         f"({figures['download_ms']:.0f} ms on loopback), uploaded in {figures['upload_ms']:.0f} ms"),
        ("pointer move to new picture (median)", f"{figures['device_ms']:.0f} ms (drawn in {figures['device_render_ms']:.0f} ms)",
         f"{figures['browser_ms']:.0f} ms ({figures['browser_setup_ms']:.0f} ms of it setting up "
         f"{figures['instances']} segments in script)"),
        ("first frame", "-", f"{figures['first_frame_ms']:.0f} ms (targets made, shaders readied by the driver)"),
        ("frames a second while dragging", f"{figures['device_fps']:.1f} (drafts at half size; asked at most 40 a second)",
         f"{figures['browser_fps']:.1f} (full size)"),
        ("agreement with the device's frame", "-",
         f"{statistics.mean(psnr):.1f} dB mean, {worst:.1f} dB worst over the pixels drawn "
         f"({figures['compared']} of {figures['steps']} viewpoints); holes left {100 * statistics.mean(figures['holes']):.2f} %"),
    ]
    print(f"| figure | on the device, streamed | in the browser, WebGL 2 |\n|---|---|---|")
    for row in rows:
        print("| " + " | ".join(row) + " |")
    if args.check_db is not None and not worst >= args.check_db:
        print(f"FAIL the browser's frames agree with the device's to {worst:.1f} dB, want {args.check_db} dB")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
