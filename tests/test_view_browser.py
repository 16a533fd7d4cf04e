"""``uamopt view`` in a real browser: Debian's Chromium driven by Selenium, headless, software
WebGL (SwiftShader), the page opened from a file:// URL with every host name resolving to
nothing, so any network request would fail and is recorded (Chrome's performance log).

The Makefile installs chromium and chromium-driver with apt-get when they are missing (target
.venv/.browser); the test is skipped only on a machine where that cannot work (no apt-get, or not
root), with the reason. It checks: the first render is not blank (pixel variance; the buildings'
grey and the tracks' colours present), moving the time slider changes the aircraft layer and the
picture, and the page made no request beyond its own file.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

import numpy as np
import pytest

from uamopt.cli import main

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM, DRIVER = shutil.which("chromium"), shutil.which("chromedriver")


def _browser():
    if not (CHROMIUM and DRIVER):
        if shutil.which("apt-get") and os.geteuid() == 0:
            pytest.fail("chromium or chromedriver missing on a machine with apt-get as root: make .venv/.browser "
                        "installs them (apt-get install -y chromium chromium-driver)")
        pytest.skip("no chromium/chromedriver and no root apt-get to install them (make .venv/.browser)")
    webdriver = pytest.importorskip("selenium.webdriver", reason="selenium (the dev extra) drives the browser")
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    o = Options()
    for a in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--use-gl=angle", "--use-angle=swiftshader",
              "--enable-unsafe-swiftshader", "--window-size=1400,1000", "--host-resolver-rules=MAP * ~NOTFOUND",
              "--disable-background-networking", "--no-first-run", "--disable-component-update"):
        o.add_argument(a)
    o.binary_location = CHROMIUM
    o.set_capability("goog:loggingPrefs", {"performance": "ALL"})
    return webdriver.Chrome(service=Service(DRIVER), options=o)


def _rendered(driver, tries: int) -> bool:
    """Wait for the first render (plotly has drawn its WebGL scene), polling every 0.25 s."""
    for _ in range(tries):
        if driver.execute_script("var g = document.querySelector('.js-plotly-plot');"
                                 "return !!(g && g._fullLayout && document.querySelector('canvas'))"):
            return True
        time.sleep(0.25)
    return False


def _pixels(driver) -> np.ndarray:
    import io

    import matplotlib.image as mpimg

    return mpimg.imread(io.BytesIO(driver.get_screenshot_as_png()), format="png")[..., :3]


def _requests(driver) -> list[str]:
    urls = []
    for entry in driver.get_log("performance"):
        msg = json.loads(entry["message"])["message"]
        if msg.get("method") == "Network.requestWillBeSent":
            urls.append(msg["params"]["request"]["url"])
    return urls


@pytest.fixture(scope="module")
def page(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("browser") / "sched"
    args = ["schedule", str(ROOT / "models" / "paper_case.toml"), "--solver", "greedy", "--out", str(folder)]
    for k in ('network.tracks="straight"', "schedule.aircraft=8", "schedule.flights=24"):
        args += ["--set", k]
    assert main(args) == 0
    assert main(["view", str(folder)]) == 0
    return folder / "view.html"


def test_the_view_renders_and_plays_offline_in_chromium(page):
    driver = _browser()
    try:
        driver.get(page.as_uri())
        if not _rendered(driver, tries=120):
            pytest.fail("the view never rendered")
        time.sleep(2.0)
        first = _pixels(driver)
        assert first.std() > 0.05  # not blank
        grey = np.all(np.abs(first - 0x8c / 255) < 0.25, axis=2) & (np.ptp(first, axis=2) < 0.03)
        coloured = np.ptp(first, axis=2) > 0.3  # saturated pixels: tracks, vertiport labels, buttons
        assert grey.mean() > 0.01 and coloured.mean() > 0.0005
        # the slider's step k does what a drag to it does: Plotly.animate with the step's arguments
        count = driver.execute_script(
            "var g = document.querySelector('.js-plotly-plot'); var s = g.layout.sliders[0].steps;"
            "var k = Math.floor(s.length / 3); window.__k = k;"
            "Plotly.animate(g, s[k].args[0], s[k].args[1]); return s.length")
        assert count > 50
        time.sleep(2.0)
        later = _pixels(driver)
        state = driver.execute_script(
            "var g = document.querySelector('.js-plotly-plot'); var d = g._fullData.filter(t => t.name && "
            "t.name.indexOf('aircraft (colour: route)') == 0)[0];"
            "return [g.layout.sliders[0].active, d.x.length, document.querySelector('.slider-group') !== null]")
        assert state[0] > 0 and state[1] > 0  # the slider moved; aircraft airborne at a third of the schedule
        # the aircraft changed the 3-D scene itself (the slider below it and the legend beside it left out)
        h, w = first.shape[:2]
        scene = (slice(80, h - 220), slice(0, w - 260))
        changed = int((np.abs(later[scene] - first[scene]).max(axis=2) > 0.1).sum())
        assert changed > 20, changed
        requests = _requests(driver)
        assert requests and all(u.startswith(("file://", "data:", "blob:")) for u in requests), requests
        (ROOT / "out").mkdir(exist_ok=True)
        driver.save_screenshot(str(ROOT / "out" / "view_screenshot.png"))  # docs/view.png is made from this
        print(f"chromium: {len(requests)} requests, all local; aircraft airborne at frame {state[0]}: {state[1]}")
    finally:
        driver.quit()
