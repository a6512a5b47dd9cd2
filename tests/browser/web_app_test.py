#!/usr/bin/python3
"""The camera's web app in a real browser (Debian's headless Chromium, driven by Selenium through
chromedriver) against a real parallaxd on the simulated camera: the gallery loads, the button
presses, progress events arrive, the clip appears and plays to its end in a video element; a shot
is authored on the live preview (two keyframes, a drag between them, a focus point clicked on the
picture) and rendered, and its clip's first and last frames match `parallax clip --shot` with the
same shot file; the settings page saves a move, effect, format and size, and the next press
makes that clip; the pages fit a phone's screen. It prints the
live preview's figures (pointer move to new picture, frames a second while dragging).

Usage: web_app_test.py PARALLAXD PARALLAX [--screenshots DIR] [--keep-screenshots] [--tile WxH]
Exit 77 (skipped) when Chromium, chromedriver or Selenium is missing. Screenshots of every page
visited are saved to DIR when a check fails (always with --keep-screenshots)."""

import argparse
import contextlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

SKIP = 77
CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"


def skip(reason):
    print(f"SKIP: {reason}")
    sys.exit(SKIP)


try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select, WebDriverWait
except ImportError:
    skip("python3-selenium is not installed (scripts/bootstrap --test installs it)")


class Daemon:
    """parallaxd on a temporary store, its web app on a free loopback port."""

    def __init__(self, binary, root, tile, duration_s=1.0):
        config = {
            "storage": {"root": os.path.join(root, "store"), "min_free_mb": 1},
            "control": {"socket": ""},
            "http": {"listen": "127.0.0.1:0"},
            "source": {"sim": {"tile_width": tile[0], "tile_height": tile[1]}},
            "clip": {"duration_s": duration_s, "fps": 10, "preset": "ultrafast"},
        }
        config_path = os.path.join(root, "config.json")
        with open(config_path, "w") as f:
            json.dump(config, f)
        self.log = []
        self.root = root
        self.tile = tile
        self.process = subprocess.Popen([binary, "--config", config_path], stdout=subprocess.DEVNULL,
                                        stderr=subprocess.PIPE, text=True)
        self.url = None
        found = threading.Event()

        def read_log():
            for line in self.process.stderr:
                self.log.append(line.rstrip())
                match = re.search(r"web app at (http://\S+/)", line)
                if match:
                    self.url = match.group(1)
                    found.set()
        threading.Thread(target=read_log, daemon=True).start()
        if not found.wait(30):
            self.stop()
            raise RuntimeError("parallaxd did not announce its web app:\n" + "\n".join(self.log))

    def api(self, path):
        with urllib.request.urlopen(self.url.rstrip("/") + path, timeout=10) as reply:
            return json.load(reply)

    def stop(self):
        self.process.terminate()
        try:
            self.process.wait(20)
        except subprocess.TimeoutExpired:
            self.process.kill()


def browser(profile):
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--disable-quic",
                 "--no-first-run", "--disable-background-networking", "--disable-component-update",
                 "--disable-sync", "--autoplay-policy=no-user-gesture-required", f"--user-data-dir={profile}",
                 "--window-size=1200,900",
                 # WebGL on the CPU (SwiftShader) for tests/browser/web_scene_bench.py: newer Chromium
                 # offers it to a headless browser only when asked.
                 "--enable-unsafe-swiftshader"):
        options.add_argument(flag)
    return webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)


@contextlib.contextmanager
def camera_and_browser(parallaxd, tile, duration_s=1.0):
    """A daemon on a temporary store and a headless Chromium, both ended (and the store removed) after."""
    root = tempfile.mkdtemp(prefix="px_web_")
    daemon = Daemon(parallaxd, root, tile, duration_s)
    driver = None
    try:
        driver = browser(os.path.join(root, "profile"))
        yield daemon, driver
    finally:
        if driver:
            driver.quit()
        daemon.stop()
        shutil.rmtree(root, ignore_errors=True)


class Checks:
    def __init__(self, driver, screenshots):
        self.driver = driver
        self.screenshots = screenshots
        self.pages = []
        self.failures = []

    def snap(self, name):
        """Keeps a screenshot of the page as it is now (written out if a check fails)."""
        self.pages.append((name, self.driver.get_screenshot_as_png()))

    def expect(self, ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            self.failures.append(what)

    def wait(self, condition, what, timeout=30):
        try:
            WebDriverWait(self.driver, timeout, poll_frequency=0.05).until(lambda d: condition())
            self.expect(True, what)
            return True
        except Exception as error:  # a timeout, or the page's state is not what was waited for
            self.expect(False, f"{what} ({type(error).__name__})")
            return False

    def save_screenshots(self):
        os.makedirs(self.screenshots, exist_ok=True)
        self.snap("at_end")
        for index, (name, png) in enumerate(self.pages):
            with open(os.path.join(self.screenshots, f"{index:02d}_{name}.png"), "wb") as f:
                f.write(png)
        print(f"screenshots in {self.screenshots}")


def frame_psnr(a, b, which):
    """PSNR in dB between the first (which=0) or last (which=-1) frames of two clips, by ffmpeg."""
    stats = tempfile.NamedTemporaryFile(suffix=".log", delete=False).name
    subprocess.run(["ffmpeg", "-v", "error", "-i", a, "-i", b, "-lavfi", f"psnr=stats_file={stats}", "-f", "null", "-"],
                   check=True)
    with open(stats) as f:
        lines = [line for line in f if "psnr_avg" in line]
    os.unlink(stats)
    value = re.search(r"psnr_avg:(\S+)", lines[which]).group(1)
    return float("inf") if value == "inf" else float(value)


def author(daemon, driver, checks, parallax):
    """Authors a shot on the live preview, renders it, and checks it against parallax clip --shot."""
    by_id = lambda name: driver.find_element(By.ID, name)
    source_job = daemon.api("/api/jobs")["jobs"][0]["id"]
    by_id("job-author").click()
    loaded = lambda: driver.execute_script("return document.getElementById('author-frame').dataset.frames || null;")
    checks.wait(loaded, "the authoring page shows the live preview", timeout=120)
    checks.wait(lambda: "inside the valid region" in by_id("author-status").text,
                "the preview says the clip's start is inside H(V)")
    checks.wait(lambda: by_id("author-map").get_attribute("data-cells") == "144"
                and " of 144 places valid" in by_id("author-map-text").text,
                "the authoring page draws H(V) as a map of where the camera may go", timeout=60)
    valid_places = int(by_id("author-map-text").text.split(":")[1].split(" of ")[0])
    checks.expect(0 < valid_places < 144, f"the map shows valid and invalid places ({valid_places} of 144 valid)")
    checks.snap("author_map")
    by_id("author-add").click()

    # Drag the picture: the camera moves across the lens plane and a new picture arrives.
    before = loaded()
    frame = by_id("author-frame")
    ActionChains(driver).move_to_element(frame).click_and_hold().move_by_offset(-60, -20).move_by_offset(-60, -20) \
        .release().perform()
    checks.wait(lambda: loaded() and loaded() != before and "mm" in by_id("author-status").text,
                "dragging the picture draws the scene from the moved camera")
    time.sleep(0.5)

    # A click on the middle of the picture sets the focus there, with an aperture.
    by_id("author-focus-mode").click()
    ActionChains(driver).move_to_element(frame).click().perform()
    checks.wait(lambda: "focus at" in by_id("author-status").text, "a click on the picture focuses there")
    time.sleep(0.5)

    # A region drawn on the picture, everything else desaturated: the preview shows it at once.
    by_id("author-focus-mode").click()
    by_id("author-region-mode").click()
    frames_before = int(loaded())
    ActionChains(driver).move_to_element_with_offset(frame, -80, -60).click_and_hold().move_by_offset(160, 120) \
        .release().perform()
    checks.wait(lambda: by_id("author-region").is_displayed() and "cm in the scene" in by_id("author-region-text").text,
                "a rectangle drawn on the picture becomes a region of the scene")
    Select(by_id("author-region-effect")).select_by_value("desaturate_background")
    by_id("author-region-apply").click()
    checks.wait(lambda: int(loaded()) > frames_before and "colour effect" in by_id("author-status").text,
                "the region's colour effect shows in the preview")
    saturation = driver.execute_script("""
        const c = document.getElementById('author-frame');
        const d = c.getContext('2d').getImageData(0, 0, 40, 40).data;  // a corner, outside the region
        let spread = 0;
        for (let i = 0; i < d.length; i += 4) spread += Math.max(d[i], d[i + 1], d[i + 2]) - Math.min(d[i], d[i + 1], d[i + 2]);
        return spread / (d.length / 4);""")
    checks.expect(saturation < 25, f"outside the region the picture is desaturated (mean channel spread {saturation:.1f})")
    by_id("author-region-mode").click()
    by_id("author-add").click()
    keys = driver.find_elements(By.CSS_SELECTOR, "#author-keyframes li")
    checks.expect(len(keys) == 2 and "focus at" in keys[1].text, f"two keyframes, the second focused ({len(keys)})")
    checks.snap("author")
    shot = driver.execute_script("return window.Author.shot();")

    # The live preview's speed: pointer moves at 30 a second for 3 s while a drag is held.
    figures = driver.execute_async_script("""
        const done = arguments[arguments.length - 1];
        const image = document.getElementById('author-frame');
        const box = image.getBoundingClientRect();
        const start = window.Author.stats.frames;
        window.Author.stats.latencies.length = 0;
        const at = (x) => ({clientX: box.left + x, clientY: box.top + box.height / 2, pointerId: 1, bubbles: true});
        image.dispatchEvent(new PointerEvent('pointerdown', at(box.width / 2)));
        let step = 0;
        const began = performance.now();
        const timer = setInterval(() => {
          step += 1;
          image.dispatchEvent(new PointerEvent('pointermove', at(box.width / 2 + 40 * Math.sin(step / 8))));
          if (performance.now() - began > 3000) {
            clearInterval(timer);
            setTimeout(() => {
              image.dispatchEvent(new PointerEvent('pointerup', at(box.width / 2)));
              const l = window.Author.stats.latencies.slice().sort((a, b) => a - b);
              done({frames: window.Author.stats.frames - start, moves: step, stats: window.Author.stats, seconds: (performance.now() - began) / 1000,
                    median_ms: l[Math.floor(l.length / 2)], p90_ms: l[Math.floor(l.length * 0.9)]});
            }, 300);
          }
        }, 33);
    """)
    print(f"figure: live preview 640 px wide, views of {daemon.tile[0]}x{daemon.tile[1]}: pointer move to new picture median {figures['median_ms']:.0f} ms, "
          f"90th percentile {figures['p90_ms']:.0f} ms; {figures['frames'] / figures['seconds']:.1f} frames a second "
          f"while dragging ({figures['frames']} frames for {figures['moves']} pointer moves in {figures['seconds']:.1f} s)")

    # Render the authored shot: a new job, and its clip matches parallax clip --shot on the capture.
    by_id("author-render").click()
    deadline = time.time() + 180
    rendered = None
    while time.time() < deadline and not rendered:
        jobs = daemon.api("/api/jobs")["jobs"]
        done = [j for j in jobs if j["id"] != source_job and j["state"] in ("done", "failed")]
        rendered = done[0] if done else None
        time.sleep(0.3)
    checks.expect(rendered is not None and rendered["state"] == "done", f"the authored shot renders as a new job ({rendered})")
    if not rendered or rendered["state"] != "done":
        return
    checks.wait(lambda: len(driver.find_elements(By.CSS_SELECTOR, "li.card.state-done")) == 2,
                "the authored clip appears in the gallery")
    workdir = tempfile.mkdtemp(prefix="px_author_")
    shot_path = os.path.join(workdir, "authored.shot.json")
    with open(shot_path, "w") as f:
        json.dump(shot, f)
    reference = os.path.join(workdir, "reference.mp4")
    subprocess.run([parallax, "clip", rendered["capture_dir"], "--shot", shot_path, "-o", reference,
                    "--preset", "ultrafast", "--quiet"], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    made = os.path.join(daemon.root, "store", "clips", rendered["id"] + ".mp4")
    first, last = frame_psnr(made, reference, 0), frame_psnr(made, reference, -1)
    checks.expect(first > 40 and last > 40,
                  f"the authored clip's first and last frames match parallax clip --shot ({first:.1f}, {last:.1f} dB)")
    shutil.rmtree(workdir, ignore_errors=True)


def settings_make_the_next_clip(daemon, driver, checks):
    """A press after the settings were saved makes a square GIF with the move and effect chosen."""
    by_id = lambda name: driver.find_element(By.ID, name)
    driver.get(daemon.url + "#gallery")
    done_before = len(driver.find_elements(By.CSS_SELECTOR, "li.card.state-done"))
    by_id("press").click()
    checks.wait(lambda: len(driver.find_elements(By.CSS_SELECTOR, "li.card.state-done")) > done_before,
                "a press after saving the settings makes a clip", timeout=180)
    job = daemon.api("/api/jobs")["jobs"][-1]
    checks.expect(job.get("clip_path", "").endswith(".gif") and job.get("format") == "gif",
                  f"the clip is a GIF, as set ({job.get('clip_path')})")
    report = daemon.api(f"/api/jobs/{job['id']}").get("report") or {}
    path = report.get("camera_path") or {}
    # The simulated scene has no face: the direction says it could not honour what needs one.
    reason = path.get("reason", "")
    checks.expect("requested dolly_in" in reason and "requested effect saturation" in reason,
                  f"the clip's direction weighed the move and effect set ({reason[:160]})")
    size = (report.get("width"), report.get("height"))
    checks.expect(size == (1080, 1080), f"the clip has the size set ({size})")
    driver.get(daemon.url + f"#job/{job['id']}")
    checks.wait(lambda: driver.execute_script(
        "const i = document.getElementById('job-animation');"
        "return !i.hidden && i.complete && i.naturalWidth === 1080;"),
        "the job's page plays the GIF clip as an image")


def run(daemon, driver, checks, parallax):
    by_id = lambda name: driver.find_element(By.ID, name)
    driver.get(daemon.url)
    checks.wait(lambda: by_id("daemon-state").text == "idle", "the gallery loads and shows the daemon idle")
    checks.expect(by_id("empty").is_displayed(), "an empty gallery says so")
    checks.snap("gallery_empty")

    # Press; watch the progress the event stream brings while the job runs. Every stage the page
    # shows is recorded in the page itself: a small simulated shot can render and encode between
    # two polls from here.
    stages = set()
    driver.execute_script(
        "window.pxStages = [];"
        "const stage = document.getElementById('progress-stage');"
        "new MutationObserver(() => window.pxStages.push(stage.textContent))"
        ".observe(stage, {childList: true, characterData: true, subtree: true});")
    by_id("press").click()
    deadline = time.time() + 180
    while time.time() < deadline and not driver.find_elements(By.CSS_SELECTOR, "li.card.state-done"):
        if by_id("progress").is_displayed():
            stages.add(by_id("progress-stage").text)
            if "render" in stages and not any(name == "progress" for name, _ in checks.pages):
                checks.snap("progress")
        time.sleep(0.05)
    cards = driver.find_elements(By.CSS_SELECTOR, "li.card.state-done")
    checks.expect(len(cards) == 1, "the pressed job's clip appears in the gallery")
    stages.update(driver.execute_script("return window.pxStages;") or [])
    checks.expect(len(stages & {"depth", "render", "encode", "processing"}) >= 2,
                  f"progress showed the job's stages live ({sorted(stages)})")
    checks.wait(lambda: "ready" in by_id("message").text, "the page says the clip is ready")
    checks.wait(lambda: driver.execute_script(
        "const i = document.querySelector('li.card img'); return i && i.complete && i.naturalWidth > 0;"),
        "the card shows the clip's poster")
    checks.snap("gallery_one_clip")
    if not cards:
        return

    # The job's page: play the clip to its end.
    cards[0].find_element(By.TAG_NAME, "a").click()
    checks.wait(lambda: by_id("job-view").is_displayed() and by_id("job-video").get_attribute("src"),
                "the job's page opens with its clip")
    ended = driver.execute_async_script("""
        const done = arguments[arguments.length - 1];
        const video = document.getElementById('job-video');
        video.loop = false;
        video.muted = true;
        const timer = setTimeout(() => done({error: 'no ended event in 30 s', t: video.currentTime,
                                             d: video.duration, e: video.error && video.error.code}), 30000);
        video.addEventListener('ended', () => { clearTimeout(timer); done({t: video.currentTime, d: video.duration}); });
        video.currentTime = 0;
        video.play().catch((e) => { clearTimeout(timer); done({error: String(e)}); });
    """)
    checks.expect("error" not in ended and abs(ended["d"] - 1.0) < 0.15 and ended["t"] >= ended["d"] - 0.05,
                  f"the clip plays to its end in a video element ({ended})")
    facts = by_id("job-facts").text
    checks.expect("Move" in facts and "Made as" in facts, "the job's page names its move and how it was made")
    checks.expect(len(driver.find_elements(By.CSS_SELECTOR, "#job-stages tr")) >= 4, "the job's page lists stage timings")
    checks.snap("job")
    author(daemon, driver, checks, parallax)

    # Settings: the move, effect, format and size for the next presses.
    driver.get(daemon.url + "#settings")
    checks.wait(lambda: by_id("settings-view").is_displayed(), "the settings page opens")
    Select(by_id("setting-move")).select_by_value("dolly_in")
    Select(by_id("setting-effect")).select_by_value("saturation")
    Select(by_id("setting-format")).select_by_value("gif")
    Select(by_id("setting-size")).select_by_value("1080x1080")
    by_id("settings-form").find_element(By.TAG_NAME, "button").click()
    checks.wait(lambda: "dolly_in" in by_id("settings-message").text, "the settings page saves a move")
    saved = daemon.api("/api/status").get("settings") or {}
    checks.expect(saved == {"move": "dolly_in", "effect": "saturation", "format": "gif", "size": "1080x1080"},
                  f"the daemon keeps the saved settings ({saved})")
    checks.wait(lambda: by_id("token-box").is_displayed(), "the page at the device shows the token's QR code")
    checks.snap("settings")
    settings_make_the_next_clip(daemon, driver, checks)

    # A phone's screen: nothing wider than it.
    driver.set_window_size(390, 844)
    for page in ("#gallery", "#settings"):
        driver.get(daemon.url + page)
        time.sleep(0.3)
        width = driver.execute_script("return [document.documentElement.scrollWidth, window.innerWidth]")
        checks.expect(width[0] <= width[1], f"{page} fits a phone's width ({width[0]} <= {width[1]} px)")
        checks.snap("phone_" + page.strip("#"))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("parallaxd")
    parser.add_argument("parallax", help="the parallax command, for the clip an authored shot is checked against")
    parser.add_argument("--screenshots", default="web_app_screenshots")
    parser.add_argument("--tile", default="160x120",
                        help="the simulated Pop9's tile size, WxH (640x480 is the camera's own: for the preview's figures)")
    parser.add_argument("--keep-screenshots", action="store_true", help="save the screenshots even when all checks pass")
    args = parser.parse_args()
    for path in (CHROMIUM, CHROMEDRIVER):
        if not shutil.which(path):
            skip(f"{path} is missing (scripts/bootstrap --test installs chromium and chromium-driver)")
    with camera_and_browser(args.parallaxd, [int(v) for v in args.tile.split("x")]) as (daemon, driver):
        checks = Checks(driver, os.path.abspath(args.screenshots))
        try:
            run(daemon, driver, checks, args.parallax)
        except Exception as error:
            checks.expect(False, f"the run stopped: {type(error).__name__}: {error}")
        console = [entry for entry in driver.get_log("browser") if entry.get("level") == "SEVERE"]
        checks.expect(not console, f"no errors in the browser's console ({console[:3]})")
        if checks.failures:
            checks.save_screenshots()
            print("daemon log tail:\n" + "\n".join(daemon.log[-30:]))
            return 1
        if args.keep_screenshots:
            checks.save_screenshots()
        print(f"all {len(checks.pages)} pages checked")
        return 0


if __name__ == "__main__":
    sys.exit(main())
