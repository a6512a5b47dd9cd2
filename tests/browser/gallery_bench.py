#!/usr/bin/python3
"""The web app's page-load figures: a real parallaxd on the simulated camera makes N clips (small
ones: 160x120 views, 0.3 s), then headless Chromium loads the gallery on loopback and reports how
long until the cards and the posters in view are shown, and how much the page itself weighs (its
HTML, scripts and style, without clips, posters or previews). With --screenshots DIR it saves the
gallery and the authoring page as PNG (the README's pictures).

Usage: gallery_bench.py PARALLAXD [--clips 100] [--screenshots DIR]
Prints one line per figure; exits 77 when Chromium, chromedriver or Selenium is missing."""

import argparse
import os
import shutil
import sys
import time
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import web_app_test  # noqa: E402  (the daemon and browser helpers)
from web_app_test import By, camera_and_browser, skip  # noqa: E402

MEDIA = ("/poster", "/preview", "/clip", "/api/")


def press_and_wait(daemon, clips):
    for _ in range(clips):
        urllib.request.urlopen(urllib.request.Request(daemon.url + "api/press", data=b"", method="POST"), timeout=10)
        time.sleep(0.05)  # under the per-address request rate
    started = time.time()
    while True:
        jobs = daemon.api("/api/jobs")["jobs"]
        finished = sum(1 for j in jobs if j["state"] in ("done", "failed"))
        print(f"\rclips: {finished}/{clips} made ({time.time() - started:.0f} s)", end="", flush=True)
        if finished >= clips:
            print()
            return jobs
        time.sleep(1)


def measure_gallery(driver, url, runs=5):
    """Median over runs: navigation to cards and visible posters shown; the page's own bytes."""
    loads = []
    weight = 0
    for _ in range(runs):
        driver.get("about:blank")
        driver.get(url)
        ms = driver.execute_async_script("""
            const done = arguments[arguments.length - 1];
            const check = () => {
              const cards = document.querySelectorAll('li.card');
              const visible = [...document.querySelectorAll('li.card img')].filter((i) => {
                const r = i.getBoundingClientRect();
                return r.top < innerHeight && r.bottom > 0;
              });
              if (cards.length > 0 && visible.length > 0 && visible.every((i) => i.complete && i.naturalWidth > 0)) {
                done(performance.now());
              } else {
                setTimeout(check, 5);
              }
            };
            check();""")
        loads.append(ms)
        entries = driver.execute_script("""
            return [performance.getEntriesByType('navigation')[0], ...performance.getEntriesByType('resource')]
              .map((e) => [e.name, e.encodedBodySize || e.transferSize || 0]);""")
        weight = sum(size for name, size in entries if not any(part in name for part in MEDIA))
        cards = len(driver.find_elements(By.CSS_SELECTOR, "li.card"))
    loads.sort()
    return loads[len(loads) // 2], weight, cards


def save_screenshots(driver, daemon, jobs, folder):
    os.makedirs(folder, exist_ok=True)
    driver.set_window_size(1200, 800)
    driver.get(daemon.url)
    time.sleep(1.5)
    driver.save_screenshot(os.path.join(folder, "web-gallery.png"))
    driver.set_window_size(1200, 1050)
    driver.get(daemon.url + "#author/" + jobs[0]["id"])
    time.sleep(8)  # the scene is built, then the first frame drawn
    driver.execute_script("document.getElementById('author-back').scrollIntoView({block: 'start'})")
    time.sleep(0.5)
    driver.save_screenshot(os.path.join(folder, "web-authoring.png"))
    print(f"screenshots in {folder}")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("parallaxd")
    parser.add_argument("--clips", type=int, default=100)
    parser.add_argument("--screenshots", help="save the gallery and the authoring page here as PNG")
    args = parser.parse_args()
    for path in (web_app_test.CHROMIUM, web_app_test.CHROMEDRIVER):
        if not shutil.which(path):
            skip(f"{path} is missing (scripts/bootstrap --test installs chromium and chromium-driver)")
    with camera_and_browser(args.parallaxd, [160, 120], duration_s=0.3) as (daemon, driver):
        jobs = press_and_wait(daemon, args.clips)
        load_ms, weight, cards = measure_gallery(driver, daemon.url)
        print(f"figure: gallery of {cards} clips on loopback: cards and the posters in view shown {load_ms:.0f} ms "
              f"after navigation (median of 5)")
        print(f"figure: page weight without clips, posters and previews: {weight / 1024:.1f} KB")
        if args.screenshots:
            save_screenshots(driver, daemon, jobs, args.screenshots)
        return 0


if __name__ == "__main__":
    sys.exit(main())
