"""Screenshots of the page at ``GET /`` for the README, taken in headless Chromium.

    python -m benchmarks.screenshots            # writes docs/screenshots/*.png

Starts ``python -m inertia serve`` on a free loopback port, drives Debian's ``chromium`` through
Playwright (as the end-to-end tests do) and saves three views:

- ``asymmetric.png``: the L-bracket (an asymmetric top) with its principal axes and inertia ellipsoid;
- ``tennis-racket.png``: the 1 x 2 x 3 box spun nearly about its intermediate axis, paused in the middle
  of its first flip, with Ω(t) and the polhode running along the separatrix;
- ``phone.png``: the same motion on a 390 x 844 screen.
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path
from typing import TYPE_CHECKING, Any

from benchmarks.harness import Server

if TYPE_CHECKING:
    from playwright.sync_api import FloatRect

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "sample_meshes"
OUT = ROOT / "docs" / "screenshots"
# headless without a GPU: WebGL through SwiftShader (software), nothing fetched from the network;
# the end-to-end tests launch Chromium with the same flags
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--use-gl=angle",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
]
FLIP = {"omega": "0.01,1,0.01", "duration": "110", "samples": "1100"}


def _analyze(page: Any, url: str, name: str, **fields: str) -> None:
    page.goto(f"{url}/")
    page.wait_for_selector("body[data-state=idle]")
    page.set_input_files("#file", str(SAMPLES / name))
    for key, value in fields.items():
        page.fill(f"#{key}", value)
    page.click("#analyze")
    page.wait_for_selector("body[data-state=ready]", timeout=120_000)
    page.evaluate("document.activeElement.blur(); window.scrollTo(0, 0)")


def _to_first_flip(page: Any) -> None:
    """Seek to where Ω2 first passes through zero: the middle of the first flip."""
    page.evaluate("""() => {
      const tr = window.inertiaPage.trajectory;
      const i = tr.omega_body.findIndex((w) => w[1] < 0);
      const T = tr.t[tr.t.length - 1];
      const slider = document.getElementById('time');
      slider.value = String(Math.round(1000 * tr.t[i] / T));
      slider.dispatchEvent(new Event('input'));
    }""")


def _clip(page: Any, *selectors: str) -> FloatRect:
    boxes = [page.locator(s).bounding_box() for s in selectors]
    x0, y0 = min(b["x"] for b in boxes), min(b["y"] for b in boxes)
    x1, y1 = max(b["x"] + b["width"] for b in boxes), max(b["y"] + b["height"] for b in boxes)
    return {"x": x0, "y": y0, "width": x1 - x0, "height": y1 - y0}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--chromium", default=shutil.which("chromium") or "/usr/bin/chromium")
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    args.out.mkdir(parents=True, exist_ok=True)
    with Server({"INERTIA_COMPUTE_PROCESSES": "1"}, startup_s=60.0) as server, sync_playwright() as p:
        url = server.url
        browser = p.chromium.launch(executable_path=args.chromium, args=CHROMIUM_ARGS)
        desktop = browser.new_page(viewport={"width": 1280, "height": 1400})
        _analyze(desktop, url, "l_bracket.stl")
        desktop.screenshot(path=args.out / "asymmetric.png", clip={"x": 0, "y": 0, "width": 1280, "height": 790})
        _analyze(desktop, url, "box.stl", **FLIP)
        _to_first_flip(desktop)
        desktop.screenshot(path=args.out / "tennis-racket.png", clip=_clip(desktop, "#view-section", "#motion"))
        phone = browser.new_page(viewport={"width": 390, "height": 844}, device_scale_factor=2)
        _analyze(phone, url, "box.stl", **FLIP)
        _to_first_flip(phone)
        phone.evaluate("document.getElementById('view-section').scrollIntoView()")
        phone.screenshot(path=args.out / "phone.png")
        browser.close()
    for name in ("asymmetric.png", "tennis-racket.png", "phone.png"):
        print(args.out / name)


if __name__ == "__main__":
    main()
