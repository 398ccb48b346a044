"""A page in a real headless browser: Debian's Chromium (``/usr/bin/chromium``, ``apt-get
install chromium``) driven by Playwright, with software WebGL (SwiftShader) for machines
without a GPU and nothing fetched from the network. The browser tier of the tests
(tests/test_browser.py) opens the 3-D pages with it; as a command it takes a screenshot:

    .venv/bin/python tools/browser.py results/figures/grasps_3d/obj4_1.html docs/figures/grasp_3d.png
"""

from __future__ import annotations

import argparse
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: The browser: Debian's package, never a download of Playwright's own.
CHROMIUM = Path(os.environ.get("SYNERGRASP_CHROMIUM", "/usr/bin/chromium"))
#: Headless, no sandbox (CI runs as root), no GPU but WebGL in software, nothing in the background.
ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
]
#: A plotly scene is drawn: its WebGL canvas exists and plotly has laid the figure out.
SCENE_DRAWN = (
    "() => { const g = document.getElementById('grasp'); "
    "return !!(window.Plotly && g && g._fullLayout && g.querySelector('.gl-container canvas')); }"
)


def missing() -> str | None:
    """What is missing to open a page (None: nothing)."""
    if not CHROMIUM.exists():
        return f"{CHROMIUM} is missing (Debian: apt-get install chromium)"
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "the playwright package is missing (make venv)"
    return None


def launch(playwright: Any) -> Any:
    """Chromium, headless, as ``ARGS`` say."""
    return playwright.chromium.launch(executable_path=str(CHROMIUM), args=ARGS)


@dataclass
class OpenedPage:
    """A page opened by :func:`open_page`: the Playwright page, its script errors (uncaught
    exceptions and console errors) and every address outside the machine it asked for (refused)."""

    page: Any
    errors: list[str] = field(default_factory=list)
    outside: list[str] = field(default_factory=list)


def open_page(
    browser: Any, path: str | Path, wait_for: str = SCENE_DRAWN, size: tuple[int, int] = (1200, 800), timeout_ms: int = 120_000
) -> OpenedPage:
    """Open the file ``path`` and wait until ``wait_for`` (a JavaScript function) is true."""
    page = browser.new_page(viewport={"width": size[0], "height": size[1]})
    opened = OpenedPage(page)
    page.on("pageerror", lambda err: opened.errors.append(str(err)))
    page.on("console", lambda msg: opened.errors.append(msg.text) if msg.type == "error" else None)

    def only_files(route: Any) -> None:
        if route.request.url.startswith(("file://", "data:", "about:", "blob:")):
            route.continue_()
        else:
            opened.outside.append(route.request.url)
            route.abort()

    page.route("**/*", only_files)
    page.goto(Path(path).resolve().as_uri())
    page.wait_for_function(wait_for, timeout=timeout_ms)
    page.wait_for_timeout(500)  # the first frames after the layout
    return opened


def main() -> None:
    parser = argparse.ArgumentParser(description="screenshot of a 3-D page in headless Chromium")
    parser.add_argument("page")
    parser.add_argument("png")
    parser.add_argument("--size", type=int, nargs=2, default=(1200, 800), metavar=("WIDTH", "HEIGHT"))
    args = parser.parse_args()
    problem = missing()
    if problem:
        raise SystemExit(problem)
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = launch(playwright)
        opened = open_page(browser, args.page, size=tuple(args.size))
        opened.page.screenshot(path=args.png)
        browser.close()
    if opened.errors or opened.outside:
        raise SystemExit(f"errors {opened.errors}, outside requests {opened.outside}")


if __name__ == "__main__":
    main()
