"""The 3-D pages in a real headless browser (the `browser` tier, README "Tests"): Debian's
Chromium driven by Playwright with software WebGL (tools/browser.py). `make test` leaves it
out; CI installs Chromium and runs it, and there a missing browser fails the tier."""

from __future__ import annotations

import importlib.util
import io
import os
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from synergrasp.cli import main

pytestmark = pytest.mark.browser

ROOT = Path(__file__).parents[1]
SMALL = ROOT / "tests" / "config" / "small.yaml"
POSE = ("obj4", -150.0, -20.0)
SPEC = importlib.util.spec_from_file_location("browser_tool", ROOT / "tools" / "browser.py")
browser_tool = sys.modules.setdefault("browser_tool", importlib.util.module_from_spec(SPEC))
SPEC.loader.exec_module(browser_tool)


@pytest.fixture(scope="module")
def browser():
    problem = browser_tool.missing()
    if problem:
        if os.environ.get("CI"):
            pytest.fail(f"the browser tier needs a browser in CI: {problem}")
        pytest.skip(problem)
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        chromium = browser_tool.launch(playwright)
        yield chromium
        chromium.close()


@pytest.fixture(scope="module")
def inspection():
    from synergrasp.inspector import inspect_grasp

    return inspect_grasp(yaml.safe_load(SMALL.read_text()), *POSE, [tuple(range(1, 16))])


@pytest.fixture(scope="module")
def page_file(tmp_path_factory):
    out = tmp_path_factory.mktemp("page") / "grasp.html"
    assert (
        main(
            [
                "grasp",
                POSE[0],
                "--alpha",
                str(POSE[1]),
                "--beta",
                str(POSE[2]),
                "--sets",
                "1-15",
                "--html",
                str(out),
                "--configfile",
                str(SMALL),
            ]
        )
        == 0
    )
    return out


def _rgb(png: bytes) -> np.ndarray:
    from matplotlib.image import imread

    return imread(io.BytesIO(png), format="png")[..., :3]


def _check_scene(page, expected_legend):
    """WebGL drew the scene (hiding every trace changes many pixels) and the legend reads as expected."""
    has_webgl = page.evaluate("""() => {
        const c = document.querySelector('#grasp .gl-container canvas');
        return !!(c.getContext('webgl') || c.getContext('webgl2') || c.getContext('experimental-webgl')); }""")
    assert has_webgl
    legend = [t.split(":")[0] for t in page.locator("#grasp .legendtext").all_text_contents()]
    assert legend == expected_legend
    canvas = page.locator("#grasp .gl-container canvas").first
    drawn = _rgb(canvas.screenshot())
    assert len(np.unique((drawn * 255).astype(np.uint8).reshape(-1, 3), axis=0)) > 200  # shaded, not blank
    # hidden but kept in the legend, so that the scene keeps its size
    page.evaluate("() => Plotly.restyle('grasp', {visible: 'legendonly'})")
    page.wait_for_timeout(500)
    empty = _rgb(canvas.screenshot())
    changed = np.abs(drawn - empty).max(axis=2) > 0.1
    assert changed.mean() > 0.02, changed.mean()  # the hand and the object cover a good part of it


def _legend_names(inspection) -> list[str]:
    hand = inspection.hand
    return [hand.link_names[k].replace("_", " ") for k in sorted(set(inspection.contacts["link"]))]


def test_the_page_opens_draws_its_webgl_scene_and_lists_the_touching_links(browser, page_file, inspection):
    opened = browser_tool.open_page(browser, page_file)
    try:
        assert opened.errors == [] and opened.outside == []
        _check_scene(opened.page, _legend_names(inspection))
    finally:
        opened.page.close()


def test_report_pages_load_the_shared_script_beside_them(browser, inspection, tmp_path):
    from synergrasp.figures.grasp_3d import GraspScene, write_grasp_pages
    from synergrasp.inspector import _object_in_picture

    links = inspection.contacts["link"].to_numpy()
    points = np.array(list(inspection.contacts["point_mm"]))
    scene = GraspScene.of(
        inspection.hand,
        inspection.q_rad,
        _object_in_picture(inspection),
        links,
        points,
        inspection.sets[-1].forces_N,
        "{S1..S15}",
        "a grasp",
    )
    write_grasp_pages(tmp_path, {"a": ("first", scene), "b": ("second", scene)}, "grasps")
    opened = browser_tool.open_page(browser, tmp_path / "b.html")
    try:
        assert opened.errors == [] and opened.outside == []
        _check_scene(opened.page, _legend_names(inspection))
    finally:
        opened.page.close()
    index = browser_tool.open_page(browser, tmp_path / "index.html", wait_for="() => true")
    try:
        frame = index.page.frame(name="view")
        frame.wait_for_function(browser_tool.SCENE_DRAWN, timeout=120_000)
        assert index.errors == [] and index.outside == []
        assert [t.split(":")[0] for t in frame.locator(".legendtext").all_text_contents()] == _legend_names(inspection)
    finally:
        index.page.close()
