"""The 3-D page of a grasp, read as a page (structure; the browser tier opens it: test_browser.py)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from synergrasp.cli import main
from synergrasp.figures.grasp_3d import ARROW_REACH, PLOTLY_JS, ZERO_FORCE_N, arrow_scale, write_grasp_pages
from synergrasp.inspector import inspect_grasp

SMALL = Path(__file__).parent / "config" / "small.yaml"
POSE = ("obj4", -150.0, -20.0)
FULL = tuple(range(1, 16))


@pytest.fixture(scope="module")
def inspection():
    return inspect_grasp(yaml.safe_load(SMALL.read_text()), *POSE, [(1,), FULL])


def plot_call(page: str) -> tuple[list[dict], dict]:
    """The traces and layout the page hands to Plotly.newPlot, decoded from the page's own text."""
    start = page.index("Plotly.newPlot(")
    decoder = json.JSONDecoder()
    at = page.index("[", start)
    data, end = decoder.raw_decode(page, at)
    layout, _ = decoder.raw_decode(page, page.index("{", end))
    return data, layout


def values(array) -> np.ndarray:
    """A trace's array as the page holds it: a list, or plotly's typed array {dtype, bdata (base64)}."""
    if isinstance(array, dict):
        import base64

        return np.frombuffer(base64.b64decode(array["bdata"]), dtype=np.dtype(array["dtype"]))
    return np.asarray(array)


def external_references(page: str) -> list[str]:
    """Addresses the page's tags would load (scripts, style sheets, frames, images)."""
    return re.findall(r"<(?:script|link|iframe|img)\b[^>]*\b(?:src|href)=[\"']([^\"']+)", page)


def test_the_page_holds_plotly_once_and_fetches_nothing(tmp_path):
    out = tmp_path / "grasp.html"
    assert (
        main(
            [
                "grasp",
                *POSE[:1],
                "--alpha",
                str(POSE[1]),
                "--beta",
                str(POSE[2]),
                "--sets",
                "1",
                "1-15",
                "--html",
                str(out),
                "--configfile",
                str(SMALL),
            ]
        )
        == 0
    )
    page = out.read_text()
    assert page.count("* plotly.js v") == 1  # the library's banner: its script inlined once
    assert page.count("Plotly.newPlot(") == 1
    assert external_references(page) == []


def test_the_scene_shows_the_object_the_links_and_one_arrow_per_loaded_contact(inspection):
    from synergrasp.figures.grasp_3d import grasp_page
    from synergrasp.inspector import grasp_view

    data, layout = plot_call(grasp_page(grasp_view(inspection, FULL)))
    assert layout["scene"]["aspectmode"] == "data"
    meshes = [t for t in data if t["type"] == "mesh3d"]
    assert sum(t["name"].startswith("object") for t in meshes) == 1
    hand = inspection.hand
    links = inspection.contacts["link"].to_numpy()
    touching = sorted(set(links.tolist()))
    # the legend: exactly the links touching the object, each named, one mesh per link
    legend = [t for t in data if t.get("showlegend")]
    assert [t["legendgroup"] for t in legend] == [f"link {k}" for k in touching]
    assert [t["name"].split(":")[0] for t in legend] == [hand.link_names[k].replace("_", " ") for k in touching]
    assert all(t["type"] == "mesh3d" for t in legend)
    assert any(t["name"] == "hand" for t in meshes)  # the links not touching, in one mesh
    # arrows: one cone per contact with a nonzero force, at the contact's link
    forces = np.asarray(next(s for s in inspection.sets if s.synergies == FULL).forces_N).reshape(-1, 3)
    loaded = np.linalg.norm(forces, axis=1) > ZERO_FORCE_N
    cones = [t for t in data if t["type"] == "cone"]
    assert sum(len(values(t["x"])) for t in cones) == int(loaded.sum()) > 0
    for t in cones:
        link = int(t["legendgroup"].split()[1])
        assert len(values(t["x"])) == int((loaded & (links == link)).sum())
    # the arrow scale is stated in the legend's title
    scale = arrow_scale(forces, ARROW_REACH * inspection.shape.bounding_radius_mm)
    assert f"1 N = {scale:g} mm" in layout["legend"]["title"]["text"]


def test_an_infeasible_set_draws_no_arrows(inspection):
    from synergrasp.figures.grasp_3d import grasp_page
    from synergrasp.inspector import grasp_view

    single = next(s for s in inspection.sets if s.synergies == (1,))
    data, layout = plot_call(grasp_page(grasp_view(inspection, (1,))))
    cones = sum(len(values(t["x"])) for t in data if t["type"] == "cone")
    assert cones == (0 if not single.load_feasible else len(inspection.contacts))
    if not single.load_feasible:
        assert "no arrows: {S1} is not feasible" in layout["legend"]["title"]["text"]


def test_arrow_scale_is_a_1_2_5_step_within_the_reach():
    assert arrow_scale(np.array([[0.0, 0.0, 10.0]]), 46.0) == 2.0
    assert arrow_scale(np.array([[3.0, 4.0, 0.0]]), 46.0) == 5.0
    assert arrow_scale(np.array([[0.0, 0.0, 100.0]]), 46.0) == 0.2


def test_report_pages_share_one_copy_of_plotly(inspection, tmp_path):
    from synergrasp.figures.grasp_3d import GraspScene
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
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.html", "b.html", "index.html", PLOTLY_JS]
    assert (tmp_path / PLOTLY_JS).read_text().count("* plotly.js v") == 1
    for name in ("a", "b"):
        page = (tmp_path / f"{name}.html").read_text()
        assert "* plotly.js v" not in page and external_references(page) == [PLOTLY_JS]
    index = (tmp_path / "index.html").read_text()
    assert external_references(index) == ["a.html"] and 'href="b.html"' in index
