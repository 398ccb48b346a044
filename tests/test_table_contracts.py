"""The table contracts' reader: a gfo table of an older version is refused, naming the file
and the renamed column, instead of being read under the column's old meaning."""

from __future__ import annotations

import re

import pandas as pd
import pytest

from synergrasp import table_contracts


def _gfo() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "object": ["box"] * 2,
            "pose": [0, 0],
            "alpha_deg": [0.0] * 2,
            "beta_deg": [0.0] * 2,
            "set_id": ["1", "1-2"],
            "n_synergies": [1, 2],
            "status": ["infeasible", "feasible"],
            "load_feasible": [False, True],
            "force_closure_def1": [False, False],
            "force_norm": [float("nan"), 3.0],
            "e_s": [1, 2],
            "rank_G": [6, 6],
            "n_contacts": [4, 4],
            "iterations": [7, 9],
            "solver": ["ipm"] * 2,
        }
    )


def test_a_current_gfo_table_reads_back_as_written(tmp_path):
    table_contracts.write(table_contracts.GFO, _gfo(), tmp_path / "gfo.parquet")
    read = table_contracts.read(table_contracts.GFO, tmp_path / "gfo.parquet")
    assert read["load_feasible"].tolist() == [False, True] and read["force_closure_def1"].tolist() == [False, False]


def test_an_older_gfo_table_is_refused_naming_the_file_and_the_old_column(tmp_path):
    """Before the rename, `force_closure` held what is now `load_feasible` (feasible under the
    weight, not Definition 1): read as it stands it would be taken for the study's verdict."""
    path = tmp_path / "gfo.parquet"
    _gfo().rename(columns={"load_feasible": "force_closure", "force_closure_def1": "strict_internal"}).to_parquet(path)
    expected = (
        f"gfo table '{path}': written by an older version of the study (column 'force_closure' (now "
        "'load_feasible'), 'strict_internal' (now 'force_closure_def1')); delete it (or its results folder) "
        "and rerun the study"
    )
    with pytest.raises(ValueError, match=f"^{re.escape(expected)}$"):
        table_contracts.read(table_contracts.GFO, path)
    # one old column alone is refused too (a table whose other column is current)
    _gfo().rename(columns={"load_feasible": "force_closure"}).to_parquet(path)
    with pytest.raises(ValueError, match=re.escape("column 'force_closure' (now 'load_feasible'));")):
        table_contracts.read(table_contracts.GFO, path)


def test_an_older_results_folder_is_found_from_the_schemas_with_the_readers_line(tmp_path):
    """The workflow's check before any job (input_checks.older_results_problems): every gfo
    table under the folder, scenarios' included, with the line table_contracts.read would give; a
    current table and an unreadable one (left to the step reading it) give none."""
    from synergrasp.input_checks import older_results_problems

    old = tmp_path / "results" / "scenarios" / "s" / "objects" / "obj1" / "gfo.parquet"
    current = tmp_path / "results" / "objects" / "obj1" / "gfo.parquet"
    broken = tmp_path / "results" / "objects" / "obj2" / "gfo.parquet"
    for path in (old, current, broken):
        path.parent.mkdir(parents=True)
    _gfo().rename(columns={"load_feasible": "force_closure"}).to_parquet(old)
    table_contracts.write(table_contracts.GFO, _gfo(), current)
    broken.write_bytes(b"not parquet")
    with pytest.raises(ValueError) as read:
        table_contracts.read(table_contracts.GFO, old)
    assert older_results_problems(tmp_path / "results") == [str(read.value)]
    assert older_results_problems(tmp_path / "none") == []
