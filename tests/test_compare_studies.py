"""tools/compare_studies.py: two results folders compared table by table."""

import importlib.util
from pathlib import Path

import numpy as np
import pandas as pd

SPEC = importlib.util.spec_from_file_location("compare_studies", Path(__file__).parents[1] / "tools" / "compare_studies.py")
compare_studies = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(compare_studies)


def _study(root: Path, gfo: pd.DataFrame, claims: pd.DataFrame) -> Path:
    (root / "objects" / "obj1").mkdir(parents=True)
    (root / "tables").mkdir()
    gfo.to_parquet(root / "objects" / "obj1" / "gfo.parquet", index=False)
    claims.to_csv(root / "tables" / "claims.csv", index=False)
    return root


GFO = pd.DataFrame(
    {
        "pose": [0, 0, 1],
        "set_id": ["1", "1-2", "1"],
        "status": ["infeasible", "feasible", "no_grasp"],
        "force_closure_def1": [False, True, False],
        "force_norm": [np.nan, 12.5, np.nan],
        "iterations": [9, 14, 0],
        "solver": ["ipm", "clarabel_fallback", "none"],
        "normal_force_N": [[np.nan], [1.0, 2.0], []],
    }
)  # a list column, NaN in it
CLAIMS = pd.DataFrame({"claim": ["c1"], "holds": [True], "rate_pct": [40.0]})


def test_equal_studies_differ_only_in_how_problems_were_decided(tmp_path):
    other = GFO.assign(iterations=[7, 20, 0], solver=["ipm", "ipm", "none"], force_norm=[np.nan, 12.5 * (1 + 1e-8), np.nan])
    result = compare_studies.compare(_study(tmp_path / "a", GFO, CLAIMS), _study(tmp_path / "b", other, CLAIMS), 1e-6)
    assert result == {"objects/obj1/gfo.parquet": (3, []), "tables/claims.csv": (1, [])}


def test_a_changed_verdict_a_far_norm_and_a_missing_table_are_reported(tmp_path):
    other = GFO.assign(
        status=["feasible", "feasible", "no_grasp"],
        force_norm=[np.nan, 12.5 * 1.001, np.nan],
        force_closure_def1=[True, True, False],
    )
    b = _study(tmp_path / "b", other, CLAIMS.assign(rate_pct=[40.0 + 1e-9]))
    (b / "tables" / "claims.csv").unlink()
    result = compare_studies.compare(_study(tmp_path / "a", GFO, CLAIMS), b, 1e-6)
    diffs = result["objects/obj1/gfo.parquet"][1]
    assert [d.split(":")[0] for d in diffs] == ["status", "force_closure_def1", "force_norm"]
    assert "1 rows beyond rtol 1e-06 (largest relative difference 0.001)" in diffs[2]
    assert result["tables/claims.csv"] == (1, ["missing"])
