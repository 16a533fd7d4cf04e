"""The screenshot of ``uamopt view`` in docs/view.png, taken with the browser test's own Chromium
set-up (tests/test_view_browser.py: headless, SwiftShader WebGL, network blocked). Run on demand:

    .venv/bin/uamopt schedule models/paper_case.toml --solver greedy --out out/pc
    .venv/bin/uamopt view out/pc
    .venv/bin/python tests/benchmarks/view_screenshot.py out/pc/view.html docs/view.png [--at 0.35]

``--at``: where on the time slider, as a fraction of the playback (the page is drawn at that frame
as a drag of the slider draws it).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from test_view_browser import _browser, _rendered


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("page", type=Path)
    parser.add_argument("png", type=Path)
    parser.add_argument("--at", type=float, default=0.35)
    args = parser.parse_args()
    driver = _browser()
    try:
        driver.get(args.page.resolve().as_uri())
        if not _rendered(driver, tries=400):
            sys.exit("the view never rendered")
        time.sleep(3.0)
        driver.execute_script("var g = document.querySelector('.js-plotly-plot'); var s = g.layout.sliders;"
                              "if (s && s.length) { var k = Math.floor(s[0].steps.length * arguments[0]);"
                              "Plotly.animate(g, s[0].steps[k].args[0], s[0].steps[k].args[1]); }", args.at)
        time.sleep(4.0)
        driver.save_screenshot(str(args.png))
        print(f"{args.png}: {args.png.stat().st_size / 1e3:.0f} kB")
    finally:
        driver.quit()


if __name__ == "__main__":
    main()
