"""tools/job_times.py: jobs, wall and CPU seconds per rule from Snakemake benchmark files."""

import importlib.util
from pathlib import Path

import pytest

SPEC = importlib.util.spec_from_file_location("job_times", Path(__file__).parents[1] / "tools" / "job_times.py")
job_times = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(job_times)

HEADER = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"


def _bench(path: Path, wall: float, cpu: float) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(HEADER + f"{wall}\t0:00:01\t1\t1\t1\t1\t0\t0\t50\t{cpu}\n")


def test_rules_are_summed_over_the_default_study_and_every_scenario(tmp_path):
    _bench(tmp_path / "benchmarks" / "optimise_shard" / "obj1_0.tsv", 4.0, 3.0)
    _bench(tmp_path / "scenarios" / "mu_1_0" / "benchmarks" / "optimise_shard" / "obj1_1.tsv", 2.0, 1.0)
    _bench(tmp_path / "benchmarks" / "simulate" / "obj1.tsv", 10.0, 5.0)
    _bench(tmp_path / "benchmarks" / "fig1.tsv", 1.0, 2.0)
    table = job_times.job_times(tmp_path)
    assert table.loc["optimise_shard", "jobs"] == 2 and table.loc["optimise_shard", "wall_s"] == 6.0
    assert table.loc["simulate", "cpu_s"] == 5.0 and table.loc["fig1", "jobs"] == 1
    assert table["cpu_percent"].sum() == pytest.approx(100.0)
    assert table.loc["optimise_shard", "cpu_percent"] == pytest.approx(100.0 * 4 / 11)  # 4 of 11 CPU seconds
    assert list(table.index) == ["simulate", "optimise_shard", "fig1"]  # largest CPU first


def test_a_jobs_cpu_seconds_come_from_its_log_where_it_records_them(tmp_path):
    """The benchmark read 3.0 s and 1.0 s; the first job's log says 7.5 s (what the benchmark's
    last sample missed), the second's log predates the line: 8.5 s in all, one logged."""
    from synergrasp.job_log import CPU_LINE

    _bench(tmp_path / "benchmarks" / "search" / "obj1.tsv", 4.0, 3.0)
    _bench(tmp_path / "benchmarks" / "search" / "obj2.tsv", 2.0, 1.0)
    (tmp_path / "logs" / "search").mkdir(parents=True)
    (tmp_path / "logs" / "search" / "obj1.log").write_text(f"a warning\n{CPU_LINE}7.500\n")
    (tmp_path / "logs" / "search" / "obj2.log").write_text("")
    table = job_times.job_times(tmp_path)
    assert table.loc["search", "cpu_s"] == pytest.approx(8.5) and table.loc["search", "logged"] == 1


def _measurements():
    spec = importlib.util.spec_from_file_location("measurements", Path(__file__).parents[1] / "tools" / "measurements.py")
    measurements = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(measurements)
    return measurements


def test_measurements_page_gives_cpu_per_pose_from_the_benchmarks_and_the_tables(tmp_path):
    """tools/measurements.py jobs: 3 CPU s of closure over 2 objects x 500 poses = 3 ms per pose."""
    import pandas as pd

    measurements = _measurements()
    results, inputs = tmp_path / "results", tmp_path / "inputs"
    for obj, cpu in (("a", 1.0), ("b", 2.0)):
        _bench(results / "benchmarks" / "simulate" / f"{obj}.tsv", 4.0, cpu)
        (results / "objects" / obj).mkdir(parents=True)
        pd.DataFrame({"pose": range(500)}).to_parquet(results / "objects" / obj / "contacts.parquet")
    _bench(results / "benchmarks" / "fig1.tsv", 1.0, 1.0)
    inputs.mkdir()
    measurements.study_jobs(results).to_csv(inputs / "study_jobs.csv", index=False)
    text = measurements.page(inputs)
    assert "| `simulate` | 2 | 8.0 | 3.0 | 75 | 1 | 3 ms per pose over 1,000 |" in text
    assert "| `fig1` | 1 | 1.0 | 1.0 | 25 | 1 |  |" in text
    assert "`benchmarks/results/gfo.csv`: not recorded yet" in text  # a benchmark not run yet is said so


def test_record_keeps_a_commands_machine_read_lines_with_its_load_and_time(tmp_path):
    """`record` writes one row per `key: number  (what)` line the command printed, and with
    --timed the command's wall and CPU seconds first; a failing command records nothing."""
    import sys

    import pandas as pd

    measurements = _measurements()
    script = "print('closure_median_ms: 6.10  (kinematic closure)'); print('status: {1: 2}'); print('n: 3')"
    path = measurements.record("closure", [sys.executable, "-c", script], timed=True, out=tmp_path)
    rows = pd.read_csv(path, dtype=str, keep_default_na=False)
    assert list(rows["figure"]) == ["wall_s", "cpu_s", "closure_median_ms", "n"]
    assert list(rows["value"][2:]) == ["6.10", "3"] and rows["description"][2] == "kinematic closure"
    assert rows["value"][1].isdigit()
    assert rows["load_average"][0].count("-") == 1 and rows["command"][0].endswith("print('n: 3')")
    with pytest.raises(SystemExit, match="exit code 3"):
        measurements.record("broken", [sys.executable, "-c", "raise SystemExit(3)"], out=tmp_path)
    assert not (tmp_path / "broken.csv").exists()
    text = measurements.page(tmp_path).split("## Closure")[1]  # the page shows it in its section
    assert "| `closure_median_ms` | 6.10 | kinematic closure |" in text and f"`{sys.executable} -c " in text
