"""What a workflow job leaves behind: its log (with the traceback of a failure) and figure
files that are the same bytes in every run."""

import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from synergrasp.figures.fig3_rulegraph import canonical_rulegraph, parse_rulegraph  # noqa: E402
from synergrasp.figures.output import save_figure  # noqa: E402
from synergrasp.job_log import CPU_LINE, job_cpu_s, job_log  # noqa: E402


def test_job_log_holds_the_traceback_of_a_failure(tmp_path):
    log = tmp_path / "job.log"
    with pytest.raises(ZeroDivisionError):
        with job_log(log):
            print("a grasp without contacts", file=sys.stderr)
            1 / 0
    text = log.read_text()
    assert "a grasp without contacts" in text
    assert "Traceback (most recent call last)" in text and "ZeroDivisionError: division by zero" in text


def test_job_log_is_written_when_nothing_is_printed(tmp_path):
    with job_log(tmp_path / "quiet.log"):
        pass
    (line,) = (tmp_path / "quiet.log").read_text().splitlines()  # the CPU line alone
    assert line.startswith(CPU_LINE) and job_cpu_s(tmp_path / "quiet.log") >= 0.0


def _spin(seconds: float) -> None:
    end = time.process_time() + seconds
    while time.process_time() < end:
        pass


def test_job_log_counts_the_cpu_of_the_job_and_of_the_processes_it_waited_for(tmp_path):
    """0.3 s spun here and 0.3 s in a child process waited for: the logged CPU grows by at
    least 0.6 s over this process's own CPU before the block."""
    import resource
    import subprocess

    log = tmp_path / "job.log"
    own, waited = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    before = own.ru_utime + own.ru_stime + waited.ru_utime + waited.ru_stime
    with job_log(log):
        _spin(0.3)
        child = "import time\nend = time.process_time() + 0.3\nwhile time.process_time() < end: pass"
        subprocess.run([sys.executable, "-c", child], check=True)
    assert job_cpu_s(log) >= before + 0.6
    with pytest.raises(ZeroDivisionError):  # a failed job's log ends with the line too
        with job_log(tmp_path / "failed.log"):
            1 / 0
    assert job_cpu_s(tmp_path / "failed.log") is not None
    (tmp_path / "old.log").write_text("a log from before the line\n")
    assert job_cpu_s(tmp_path / "old.log") is None


def _figure() -> plt.Figure:
    fig, ax = plt.subplots(figsize=(3, 2))
    ax.plot([0.0, 1.0, 2.0], [1.0, 0.5, 2.0])
    ax.set_title("force (N)")
    return fig


def test_saved_figures_are_identical_bytes_across_runs(tmp_path):
    save_figure(_figure(), tmp_path / "a.png", tmp_path / "a.pdf", tight=True)
    time.sleep(1.1)  # a PDF with its creation date would differ after a second
    save_figure(_figure(), tmp_path / "b.png", tmp_path / "b.pdf", tight=True)
    assert (tmp_path / "a.pdf").read_bytes() == (tmp_path / "b.pdf").read_bytes()
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()
    assert b"CreationDate" not in (tmp_path / "a.pdf").read_bytes()


_HEADER = "digraph snakemake_dag {\n    graph[bgcolor=white, margin=0];\n"


def _dot(numbering: dict[str, int], edges: list[tuple[str, str]]) -> str:
    nodes = "".join(f'\t{i}[label = "{name}", color = "0.1 0.6 0.85", style="rounded"];\n' for name, i in numbering.items())
    return _HEADER + nodes + "".join(f"\t{numbering[a]} -> {numbering[b]}\n" for a, b in edges) + "}\n"


def test_canonical_rulegraph_does_not_depend_on_snakemake_order():
    edges = [("simulate", "optimise"), ("optimise", "tables"), ("simulate", "fig2"), ("tables", "all"), ("fig2", "all")]
    one = _dot({"all": 0, "simulate": 1, "optimise": 2, "tables": 3, "fig2": 4}, edges)
    other = _dot({"fig2": 0, "tables": 1, "all": 2, "optimise": 3, "simulate": 4}, edges[::-1])
    assert one != other
    assert canonical_rulegraph(one) == canonical_rulegraph(other)
    nodes, canonical_edges = parse_rulegraph(canonical_rulegraph(one))
    # numbered by name: all 0, fig2 1, optimise 2, simulate 3, tables 4; edges sorted
    assert nodes == {0: "all", 1: "fig2", 2: "optimise", 3: "simulate", 4: "tables"}
    assert canonical_edges == [(1, 0), (2, 4), (3, 1), (3, 2), (4, 0)]
    assert canonical_rulegraph(one).startswith(_HEADER)
