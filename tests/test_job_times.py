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
    _bench(tmp_path / "benchmarks" / "optimise" / "obj1_0.tsv", 4.0, 3.0)
    _bench(tmp_path / "scenarios" / "mu_1_0" / "benchmarks" / "optimise" / "obj1_1.tsv", 2.0, 1.0)
    _bench(tmp_path / "benchmarks" / "simulate_contacts" / "obj1.tsv", 10.0, 5.0)
    _bench(tmp_path / "benchmarks" / "fig1_synergy_postures.tsv", 1.0, 2.0)
    table = job_times.job_times(tmp_path)
    assert table.loc["optimise", "jobs"] == 2 and table.loc["optimise", "wall_s"] == 6.0
    assert table.loc["simulate_contacts", "cpu_s"] == 5.0 and table.loc["fig1_synergy_postures", "jobs"] == 1
    assert table["cpu_percent"].sum() == pytest.approx(100.0)
    assert table.loc["optimise", "cpu_percent"] == pytest.approx(100.0 * 4 / 11)  # 4 of 11 CPU seconds
    assert list(table.index) == ["simulate_contacts", "optimise", "fig1_synergy_postures"]  # largest CPU first


def test_measurements_page_gives_cpu_per_pose_from_the_benchmarks_and_the_tables(tmp_path):
    """tools/measurements.py: 3 CPU s of closure over 2 objects x 500 poses = 3 ms per pose."""
    import pandas as pd

    spec = importlib.util.spec_from_file_location("measurements", Path(__file__).parents[1] / "tools" / "measurements.py")
    measurements = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(measurements)
    for obj, cpu in (("a", 1.0), ("b", 2.0)):
        _bench(tmp_path / "benchmarks" / "simulate_contacts" / f"{obj}.tsv", 4.0, cpu)
        (tmp_path / "objects" / obj).mkdir(parents=True)
        pd.DataFrame({"pose": range(500)}).to_parquet(tmp_path / "objects" / obj / "contacts.parquet")
    text = measurements.page(tmp_path, "quiet")
    assert "| `simulate_contacts` | 2 | 8.0 | 3.0 | 100 | 1 | 3 ms per pose (1,000 poses) |" in text
    assert "(quiet)." in text
    # then the dynamic closure's engines and variants, one table row per row of their CSV
    engines = pd.read_csv(measurements.CLOSURE_ENGINES)
    section = text.split("## Dynamic closure: engines and variants")[1]
    assert [line.split(" | ")[0] for line in section.splitlines() if line.startswith("| ") and "`" in line] == [
        f"| {v}" for v in engines["variant"]]
