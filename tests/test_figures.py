"""Figure helpers: the force grid, the rule-graph parser, and files written for the study's plots."""

import numpy as np
import pandas as pd
import pytest

from synergrasp.figures.fig3_rulegraph import parse_rulegraph
from synergrasp.figures.fig4_fig5_forces_hierarchy import figure_exploded_views, figure_force_maps, figure_hierarchy, force_grid
from synergrasp.table_contracts import write_study_table


def _gfo() -> pd.DataFrame:
    """Two α × three β poses, set "1": a success except at (α=0, β=10) (the analysis
    columns ``success`` and ``success_force`` of ``with_verdicts``)."""
    rows = []
    for alpha in (0.0, 180.0):
        for beta in (-10.0, 0.0, 10.0):
            fc = not (alpha == 0.0 and beta == 10.0)
            rows.append(
                {
                    "set_id": "1",
                    "alpha_deg": alpha,
                    "beta_deg": beta,
                    "success": fc,
                    "success_force": (1.0 + alpha / 90.0 + beta / 10.0 + 2.0) if fc else np.nan,
                }
            )
    return pd.DataFrame(rows)


def test_force_grid_places_each_pose_and_leaves_no_closure_empty():
    alphas, betas, force = force_grid(_gfo(), "1")
    np.testing.assert_array_equal(alphas, [0.0, 180.0])
    np.testing.assert_array_equal(betas, [-10.0, 0.0, 10.0])
    assert force.shape == (3, 2)
    assert force[0, 0] == 2.0 and force[1, 1] == 5.0 and force[2, 1] == 6.0
    assert np.isnan(force[2, 0])


def test_parse_rulegraph_reads_nodes_and_edges():
    dot = 'digraph {\n\t0[label = "all", color = "x"];\n\t1[label = "simulate", color = "y"];\n\t1 -> 0\n}'
    nodes, edges = parse_rulegraph(dot)
    assert nodes == {0: "all", 1: "simulate"}
    assert edges == [(1, 0)]


def test_figures_and_tables_are_written(tmp_path):
    gfo = _gfo()
    minima = gfo.iloc[[0]]
    figure_force_maps(gfo, minima, [1], "box", tmp_path / "m.png", tmp_path / "m.pdf")
    # the β slice at 10 deg has force closure only at α = 180; the α slice at β = 99 -> 10 deg
    figure_exploded_views(gfo, [1], 0.0, 99.0, "box", tmp_path / "e.png", tmp_path / "e.pdf")
    matrices = pd.DataFrame(
        {
            "k": [1, 1, 2],
            "i": [1, 1, 2],
            "j": [1, 2, 2],
            "success_rate": [50.0, 80.0, 0.0],
            "force_ratio_median": [3.0, 3000.0, np.nan],
        }
    )
    figure_hierarchy(
        matrices,
        "force_ratio_median",
        2,
        "t",
        ".1f",
        (1.0, 10.0),
        "ratio",
        tmp_path / "h.png",
        tmp_path / "h.pdf",
        log_scale=True,
    )
    write_study_table(pd.DataFrame({"a": [1.23456]}), tmp_path / "t.csv", tmp_path / "t.md", title="T")
    for name in ("m.png", "m.pdf", "e.png", "e.pdf", "h.png", "h.pdf"):
        assert (tmp_path / name).stat().st_size > 1000, name
    assert (tmp_path / "t.md").read_text().startswith("# T\n")
    assert pd.read_csv(tmp_path / "t.csv")["a"].iloc[0] == 1.23456


def test_hierarchy_grey_scale_is_black_at_the_low_end_and_prints_every_cell():
    import matplotlib.pyplot as plt
    from matplotlib.colors import Normalize

    from synergrasp.figures.fig4_fig5_forces_hierarchy import _hierarchy_panel

    fig, ax = plt.subplots()
    image = _hierarchy_panel(ax, np.array([[0.0, 100.0], [np.nan, 50.0]]), Normalize(0.0, 100.0), ".0f", ["S1", "S2"])
    assert tuple(image.cmap(image.norm(0.0))[:3]) == (0.0, 0.0, 0.0)  # 0 % black
    assert tuple(image.cmap(image.norm(100.0))[:3]) == (1.0, 1.0, 1.0)  # 100 % white
    assert sorted(t.get_text() for t in ax.texts) == ["0", "100", "50", "–"]
    plt.close(fig)


def test_a_map_constant_to_round_off_is_one_colour():
    """A sphere's grasp is the same at every pose to ~1e-12: its maps (Fig. 4, the quality
    maps) get a range about their value, not their round-off stretched over the colour bar."""
    from synergrasp.figures.output import colour_range

    noise = 0.2557 + 1e-12 * np.random.default_rng(3).normal(size=(25, 72))
    lo, hi = colour_range(noise)
    assert lo < 0.2557 - 0.1 and hi > 0.2557 + 0.1 and abs(0.5 * (lo + hi) - 0.2557) < 1e-9
    assert colour_range(np.full(4, np.nan)) == (0.0, 1.0)
    varied = np.linspace(0.0, 1.0, 101)
    assert colour_range(varied) == pytest.approx((0.01, 0.99))  # the 1st and 99th percentiles, as before
