"""End to end: the small config through Snakemake with -j2, in a temporary directory.

Checks every target exists and is non-empty, tables carry their documented columns and
sane values, a second run does nothing, -j1 gives the same tables as -j2, and a broken
config stops with the schema message and leaves earlier results untouched, and
`snakemake --report` gathers every figure and table.
"""
import hashlib
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
SMALL = ROOT / "tests" / "config" / "small.yaml"

pytestmark = pytest.mark.workflow


def snakemake(workdir: Path, *args: str, configfile: Path = SMALL) -> subprocess.CompletedProcess:
    command = [sys.executable, "-m", "snakemake", "-s", str(ROOT / "Snakefile"), "--directory",
               str(workdir), "--configfile", str(configfile), "--replace-workflow-config", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=1800)


def digest(paths: list[Path]) -> dict[str, str]:
    return {str(p): hashlib.sha256(p.read_bytes()).hexdigest() for p in paths}


@pytest.fixture(scope="module")
def run_j2(tmp_path_factory) -> Path:
    workdir = tmp_path_factory.mktemp("j2")
    out = snakemake(workdir, "-j2", "figures")
    assert out.returncode == 0, out.stderr[-5000:]
    return workdir


def expected_targets() -> list[str]:
    config = yaml.safe_load(SMALL.read_text())
    figures = [f"results/figures/{n}.{e}" for n in ("fig1_synergy_postures", "fig2_example_grasps",
               "fig3_rulegraph", "fig5a_hierarchy_success", "fig5b_hierarchy_force", "grasp_realism")
               for e in ("png", "pdf")]
    tables = [f"results/tables/{t}.{e}" for t in ("success_rates", "table2_success_rates", "hierarchy",
              "minimum_preservation", "full_not_first7", "verdict_disagreements", "preservation_vs_chance",
              "invariant_checks", "claims", "grasp_realism") for e in ("csv", "md")]
    per_object = [f"results/objects/{o}/{f}" for o in config["objects"] for f in (
        "contacts.parquet", "gfo.parquet", "minima.parquet", "fig4_force_maps.png", "fig4_force_maps.pdf",
        "fig4_exploded.png", "fig4_exploded.pdf")]
    return figures + tables + per_object


def test_every_target_exists_and_is_not_empty(run_j2):
    for rel in expected_targets():
        path = run_j2 / rel
        assert path.is_file(), rel
        assert path.stat().st_size > 0, rel


def test_tables_have_documented_columns_and_sane_values(run_j2):
    tables = run_j2 / "results" / "tables"
    rates = pd.read_csv(tables / "success_rates.csv")
    for column in ("object", "set_id", "n_success", "success_rate", "absolute_share", "success_rate_force_closure",
                   "success_rate_load_feasible", "force_ratio_median", "plain_mean_force_N", "plain_median_force_N"):
        assert column in rates.columns, column
    defined = rates["success_rate"].dropna()
    assert ((defined >= 0) & (defined <= 100)).all()
    assert ((rates["absolute_share"] >= 0) & (rates["absolute_share"] <= 100)).all()
    full = rates[rates["set_id"] == "-".join(str(i) for i in range(1, 16))]
    # the full set is the normalisation: 100 where it ever succeeds, undefined where it never does
    for _, row in full.iterrows():
        if row["n_success"] > 0:
            assert row["success_rate"] == pytest.approx(100.0)
        else:
            assert pd.isna(row["success_rate"])
    preservation = pd.read_csv(tables / "minimum_preservation.csv")
    share = preservation["preserved_percent"].dropna()
    assert ((share >= 0) & (share <= 100)).all()
    claims = pd.read_csv(tables / "claims.csv")
    assert claims["claim"].tolist() == list(range(1, 8))
    assert set(claims["verdict"]) <= {"holds", "does not hold", "undefined"}
    checks = pd.read_csv(tables / "invariant_checks.csv")
    assert (checks.loc[checks["check"] == "alpha_period", "count"] == 0).all()  # results repeat every 90 deg
    gfo = pd.read_parquet(run_j2 / "results" / "objects" / "obj4" / "gfo.parquet")
    assert set(gfo["status"]) <= {"force_closure", "infeasible", "rank_deficient", "no_grasp", "numerical_failure"}
    fc = gfo[gfo["force_closure"]]
    assert (fc["force_norm"] > 0).all() and gfo.loc[~gfo["force_closure"], "force_norm"].isna().all()


def test_no_pose_is_dropped(run_j2):
    """The approach placement: every pose of the small grid is a closure (none intersects the open hand)."""
    config = yaml.safe_load(SMALL.read_text())
    n_poses = 1
    for axis in ("alpha_deg", "beta_deg"):
        g = config["grid"][axis]
        n_poses *= int(round((g["stop"] - g["start"]) / g["step"])) + 1
    for name in config["objects"]:
        contacts = pd.read_parquet(run_j2 / "results" / "objects" / name / "contacts.parquet")
        assert len(contacts) == n_poses and contacts["pose"].nunique() == n_poses
        assert set(contacts["status"]) <= {"grasp", "no_contact"}


def test_second_run_does_nothing(run_j2):
    before = digest([p for p in (run_j2 / "results").rglob("*") if p.is_file()])
    out = snakemake(run_j2, "-j2", "figures")
    assert out.returncode == 0, out.stderr[-3000:]
    assert "Nothing to be done" in out.stdout + out.stderr
    after = digest([p for p in (run_j2 / "results").rglob("*") if p.is_file()])
    assert before == after


def test_j1_gives_the_same_tables(run_j2, tmp_path):
    out = snakemake(tmp_path, "-j1", "figures")
    assert out.returncode == 0, out.stderr[-3000:]
    for csv in sorted((run_j2 / "results" / "tables").glob("*.csv")):
        assert csv.read_bytes() == (tmp_path / "results" / "tables" / csv.name).read_bytes(), csv.name
    for parquet in sorted((run_j2 / "results" / "objects").rglob("*.parquet")):
        other = tmp_path / parquet.relative_to(run_j2)
        pd.testing.assert_frame_equal(pd.read_parquet(parquet), pd.read_parquet(other))


def test_broken_config_fails_before_work_and_keeps_results(run_j2, tmp_path):
    files = [p for p in (run_j2 / "results").rglob("*") if p.is_file()]
    before = digest(files)
    broken = yaml.safe_load(SMALL.read_text())
    broken["mechanics"]["friction"] = 1.0
    broken["objects"]["obj4"]["size_mm"] = [100, -60, 100]
    path = tmp_path / "broken.yaml"
    path.write_text(yaml.safe_dump(broken))
    out = snakemake(run_j2, "-j2", "figures", "--forceall", configfile=path)
    assert out.returncode != 0
    message = out.stdout + out.stderr
    assert "config error at 'mechanics': unknown key(s) ['friction']" in message
    assert "objects.obj4.size_mm[1]" in message
    assert digest(files) == before


def test_report_holds_every_figure_and_table(run_j2):
    out = snakemake(run_j2, "--report", "results/report.html")
    assert out.returncode == 0, out.stderr[-3000:]
    html = (run_j2 / "results" / "report.html").read_text(errors="replace")
    for name in ("fig1_synergy_postures.png", "fig2_example_grasps.png", "fig3_rulegraph.png",
                 "fig4_force_maps.png", "fig4_exploded.png", "fig5a_hierarchy_success.png",
                 "fig5b_hierarchy_force.png", "table2_success_rates.csv", "minimum_preservation.csv",
                 "full_not_first7.csv", "verdict_disagreements.csv", "claims.csv", "preservation_vs_chance.csv",
                 "invariant_checks.csv", "grasp_realism.png", "grasp_realism.csv"):
        assert name in html, name
