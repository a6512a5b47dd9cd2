#!/usr/bin/python3
"""The camera's web app in a real browser (Debian's headless Chromium, driven by Selenium through
chromedriver) against a real parallaxd on the simulated camera: the gallery loads, the button
presses, progress events arrive, the clip appears and plays to its end in a video element, the
settings page saves a move, and the pages fit a phone's screen.

Usage: web_app_test.py PARALLAXD [--screenshots DIR] [--keep-screenshots]
Exit 77 (skipped) when Chromium, chromedriver or Selenium is missing. Screenshots of every page
visited are saved to DIR when a check fails (always with --keep-screenshots)."""

import argparse
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
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select, WebDriverWait
except ImportError:
    skip("python3-selenium is not installed (scripts/bootstrap --test installs it)")


class Daemon:
    """parallaxd on a temporary store, its web app on a free loopback port."""

    def __init__(self, binary, root):
        config = {
            "storage": {"root": os.path.join(root, "store"), "min_free_mb": 1},
            "control": {"socket": ""},
            "http": {"listen": "127.0.0.1:0"},
            "source": {"sim": {"tile_width": 160, "tile_height": 120}},
            "clip": {"duration_s": 1.0, "fps": 10, "preset": "ultrafast"},
        }
        config_path = os.path.join(root, "config.json")
        with open(config_path, "w") as f:
            json.dump(config, f)
        self.log = []
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
                 "--window-size=1200,900"):
        options.add_argument(flag)
    return webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)


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


def run(daemon, driver, checks):
    by_id = lambda name: driver.find_element(By.ID, name)
    driver.get(daemon.url)
    checks.wait(lambda: by_id("daemon-state").text == "idle", "the gallery loads and shows the daemon idle")
    checks.expect(by_id("empty").is_displayed(), "an empty gallery says so")
    checks.snap("gallery_empty")

    # Press; watch the progress the event stream brings while the job runs.
    stages = set()
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

    # Settings: the move for the next presses.
    driver.get(daemon.url + "#settings")
    checks.wait(lambda: by_id("settings-view").is_displayed(), "the settings page opens")
    Select(by_id("setting-move")).select_by_value("dolly_in")
    by_id("settings-form").find_element(By.TAG_NAME, "button").click()
    checks.wait(lambda: "dolly_in" in by_id("settings-message").text, "the settings page saves a move")
    checks.expect(daemon.api("/api/status").get("move") == "dolly_in", "the daemon uses the saved move")
    checks.wait(lambda: by_id("token-box").is_displayed(), "the page at the device shows the token's QR code")
    checks.snap("settings")

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
    parser.add_argument("--screenshots", default="web_app_screenshots")
    parser.add_argument("--keep-screenshots", action="store_true", help="save the screenshots even when all checks pass")
    args = parser.parse_args()
    for path in (CHROMIUM, CHROMEDRIVER):
        if not shutil.which(path):
            skip(f"{path} is missing (scripts/bootstrap --test installs chromium and chromium-driver)")
    root = tempfile.mkdtemp(prefix="px_web_")
    daemon = Daemon(args.parallaxd, root)
    driver = None
    try:
        driver = browser(os.path.join(root, "profile"))
        checks = Checks(driver, os.path.abspath(args.screenshots))
        try:
            run(daemon, driver, checks)
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
    finally:
        if driver:
            driver.quit()
        daemon.stop()
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
