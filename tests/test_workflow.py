"""End to end: the small config through Snakemake with -j2, in a temporary directory.

Checks every target exists and is non-empty, tables carry their documented columns and
sane values, a second run does nothing, -j1 gives the same tables as -j2, and a broken
config stops with the schema message and leaves earlier results untouched, and
`snakemake --report` gathers every figure and table. Then the rerun guarantees: every
synergrasp module a job loads is in the digest of its rule's code (a param), a changed module reruns
exactly the rules that load it, and a run killed mid-way (SIGINT, SIGKILL) reruns only
what did not finish and ends with the same tables as an uninterrupted run.
"""

import base64
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import zipfile
from collections.abc import Sequence
from pathlib import Path

import pandas as pd
import pytest
import yaml

from synergrasp.wiring import code_files

ROOT = Path(__file__).resolve().parents[1]
SMALL = ROOT / "tests" / "config" / "small.yaml"

pytestmark = pytest.mark.workflow


def command(workdir: Path, *args: str, configfile: Path = SMALL, root: Path = ROOT) -> list[str]:
    return [
        sys.executable,
        "-m",
        "snakemake",
        "-s",
        str(root / "Snakefile"),
        "--directory",
        str(workdir),
        "--configfile",
        str(configfile),
        "--replace-workflow-config",
        *args,
    ]


def snakemake(
    workdir: Path, *args: str, configfile: Path = SMALL, root: Path = ROOT, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess:
    return subprocess.run(
        command(workdir, *args, configfile=configfile, root=root), capture_output=True, text=True, timeout=1800, env=env
    )


def digest(paths: list[Path]) -> dict[str, str]:
    return {str(p): hashlib.sha256(p.read_bytes()).hexdigest() for p in paths}


# Loaded into every Python process of a run (as sitecustomize): at exit, a workflow script's
# process writes the synergrasp source files it loaded, relative to the package's parent
# (<pid>.txt), and every file it opened to read with the files its job declares (<pid>.json):
# its inputs, outputs and log, from the script's own `snakemake` object. Python's audit hook
# sees every open() (CSV, YAML, the hand's files); Parquet is read by pyarrow's C++ code,
# which no audit event reports, so pyarrow.parquet's readers are wrapped to say what they read.
_RECORD_MODULES = """
import atexit, json, os, sys

_READ = set()

def _read(path):
    if isinstance(path, (str, bytes, os.PathLike)):
        _READ.add(os.path.realpath(os.fsdecode(path)))

def _opened(event, args):
    if event != "open" or not args:
        return
    mode = args[1] if len(args) > 1 else None
    flags = args[2] if len(args) > 2 else 0
    reading = ("r" in mode and "+" not in mode) if isinstance(mode, str) else (flags or 0) & os.O_ACCMODE == os.O_RDONLY
    if reading:
        _read(args[0])

def _recording(reader):
    def read(source, *args, **kwargs):
        _read(source)
        return reader(source, *args, **kwargs)
    return read

_SCRIPT = "/.snakemake/scripts/" in (sys.argv[0] if sys.argv else "")
if _SCRIPT:
    sys.addaudithook(_opened)
    import pyarrow.parquet as _pq
    _pq.read_table, _pq.read_schema, _pq.read_metadata = map(_recording, (_pq.read_table, _pq.read_schema, _pq.read_metadata))

def _record():
    if not _SCRIPT or "synergrasp" not in sys.modules:
        return
    name = os.path.basename(sys.argv[0]).split(".")[-2]
    base = os.path.dirname(os.path.dirname(sys.modules["synergrasp"].__file__))
    files = sorted(os.path.relpath(m.__file__, base) for module, m in list(sys.modules.items())
                   if module.split(".")[0] == "synergrasp" and getattr(m, "__file__", None))
    folder = os.environ["SYNERGRASP_RECORD_MODULES"]
    with open(os.path.join(folder, f"{os.getpid()}.txt"), "w") as out:
        out.write("\\n".join([name] + files))
    job = sys.modules["__main__"].snakemake
    declared = {kind: sorted(os.path.realpath(str(f)) for f in getattr(job, kind)) for kind in ("input", "output", "log")}
    with open(os.path.join(folder, f"{os.getpid()}.json"), "w") as out:
        json.dump({"rule": job.rule, "read": sorted(_READ), **declared}, out)

atexit.register(_record)
"""


def _recording_env(hook_dir: Path, record_dir: Path) -> dict[str, str]:
    record_dir.mkdir()
    (hook_dir / "sitecustomize.py").write_text(_RECORD_MODULES)
    paths = [str(hook_dir), os.environ.get("PYTHONPATH", "")]
    return {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in paths if p), "SYNERGRASP_RECORD_MODULES": str(record_dir)}


@pytest.fixture(scope="module")
def run_j2(tmp_path_factory) -> Path:
    workdir = tmp_path_factory.mktemp("j2")
    hooks = tmp_path_factory.mktemp("hooks")
    out = snakemake(workdir, "-j2", "figures", env=_recording_env(hooks, workdir / "module_records"))
    assert out.returncode == 0, out.stderr[-5000:]
    return workdir


def expected_targets() -> list[str]:
    """Every output of the small study, from the step registry: the sweep's summary and the
    steps made only by their own target (optional) aside, and the contacts step's own table
    too, as the small study's kinematic closure records no loads to select contacts by."""
    from synergrasp.config import validate_config
    from synergrasp.steps import STEPS

    config = validate_config(yaml.safe_load(SMALL.read_text()))
    assert config["closure"]["model"] == "kinematic"
    where = {"object": [f"results/objects/{o}/" for o in config["objects"]], "scenario": ["results/"], "workflow": ["results/"]}
    # the small study's placement is not searched: its small sweep's placement_searched scenario
    # makes the search's table and the placement maps
    skipped = ("sensitivity", "contacts", "search", "placement_map")
    return [
        root + rel
        for name, step in STEPS.items()
        if name not in skipped and step.rules and not step.optional
        for root in where[step.scope]
        for rel in step.outputs.values()
    ]


def made(path: Path) -> bool:
    """A file target exists and is not empty; a folder of pages (the 3-D pages) has its non-empty index."""
    if path.is_dir():
        path = path / "index.html"
    return path.is_file() and path.stat().st_size > 0


def test_every_target_exists_and_is_not_empty(run_j2):
    for rel in expected_targets():
        assert made(run_j2 / rel), rel


def test_tables_have_documented_columns_and_sane_values(run_j2):
    tables = run_j2 / "results" / "tables"
    rates = pd.read_csv(tables / "success_rates.csv")
    for column in (
        "object",
        "set_id",
        "n_success",
        "success_rate",
        "absolute_share",
        "success_rate_force_closure",
        "success_rate_load_feasible",
        "force_ratio_median",
        "plain_mean_force_N",
        "plain_median_force_N",
    ):
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
    assert claims.loc[claims["headline"], "claim"].tolist() == list(range(1, 9))  # one headline row per claim
    assert set(claims["verdict"]) <= {"holds", "does not hold", "undefined"}
    planner, claims = claims[claims["claim"] == 8].iloc[0], claims[claims["claim"] != 8]
    assert claims.loc[claims["verdict"] != "undefined", "reason"].str.startswith("interval").all()
    decided = claims[claims["verdict"] != "undefined"]
    assert (decided["n_distinct_poses"] >= 30).all() and (decided["low"] <= decided["difference"]).all()
    # claim 8, over objects (docs/planner.md): both objects of the small study behind it, or no incremental planner
    across = pd.read_csv(tables / "planners_across.csv")
    assert across["recommended"].sum() == 1 and (across["objects"] == 2).all()
    assert planner["n_distinct_poses"] == 2 or planner["reason"].startswith("no incremental planner")
    checks = pd.read_csv(tables / "invariant_checks.csv")
    assert (checks.loc[checks["check"] == "alpha_period", "count"] == 0).all()  # results repeat every 90 deg
    gfo = pd.read_parquet(run_j2 / "results" / "objects" / "obj4" / "gfo.parquet")
    assert set(gfo["status"]) <= {"feasible", "infeasible", "rank_deficient", "no_grasp", "numerical_failure"}
    fc = gfo[gfo["load_feasible"]]
    assert (fc["force_norm"] > 0).all() and gfo.loc[~gfo["load_feasible"], "force_norm"].isna().all()


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
    # figures too: Fig. 3's rule graph in a fixed order, PDFs without creation dates
    figures = [p for p in (run_j2 / "results").rglob("*") if p.suffix in (".png", ".pdf", ".dot")]
    assert len(figures) >= 11
    for figure in figures:
        assert figure.read_bytes() == (tmp_path / figure.relative_to(run_j2)).read_bytes(), figure.name
    pages = list((run_j2 / "results" / "figures" / "grasps_3d").iterdir())  # the 3-D pages and their script
    assert len(pages) >= 3
    for page in pages:
        assert page.read_bytes() == (tmp_path / page.relative_to(run_j2)).read_bytes(), page.name


def test_broken_config_fails_before_work_and_keeps_results(run_j2, tmp_path):
    files = [p for p in (run_j2 / "results").rglob("*") if p.is_file()]
    before = digest(files)
    broken = yaml.safe_load(SMALL.read_text())
    broken["mechanics"]["friction"] = 1.0
    broken["objects"]["obj4"]["shape"]["box"]["size_mm"] = [100, -60, 100]
    path = tmp_path / "broken.yaml"
    path.write_text(yaml.safe_dump(broken))
    out = snakemake(run_j2, "-j2", "figures", "--forceall", configfile=path)
    assert out.returncode != 0
    message = out.stdout + out.stderr
    assert "config error at 'mechanics': unknown key(s) ['friction']" in message
    assert "objects.obj4.shape.box.size_mm[1]" in message
    assert digest(files) == before


def test_report_holds_every_figure_and_table(run_j2):
    out = snakemake(run_j2, "--report", "results/report.html")
    assert out.returncode == 0, out.stderr[-3000:]
    html = (run_j2 / "results" / "report.html").read_text(errors="replace")
    for name in (
        "fig1_synergy_postures.png",
        "fig2_example_grasps.png",
        "fig3_rulegraph.png",
        "fig4_force_maps.png",
        "fig4_exploded.png",
        "fig5a_hierarchy_success.png",
        "fig5b_hierarchy_force.png",
        "table2_success_rates.csv",
        "minimum_preservation.csv",
        "full_not_first7.csv",
        "verdict_disagreements.csv",
        "claims.csv",
        "preservation_vs_chance.csv",
        "invariant_checks.csv",
        "grasp_realism.png",
        "grasp_realism.csv",
    ):
        assert name in html, name
    assert "Pisa/IIT SoftHand" in html  # the workflow's description page (report: in the Snakefile)
    out = snakemake(run_j2, "--report", "results/report.zip")
    assert out.returncode == 0, out.stderr[-3000:]
    with zipfile.ZipFile(run_j2 / "results" / "report.zip") as archive:
        names = archive.namelist()
    assert "report/report.html" in names
    assert any(name.endswith("fig3_rulegraph.png") for name in names)
    # the archive holds the 3-D pages of Fig. 2's grasps beside their index, with one plotly
    # script for all; the one-file report (which cannot hold a folder) does not
    pages = sorted(p.name for p in (run_j2 / "results" / "figures" / "grasps_3d").glob("*.html"))
    folders = {name.rsplit("/", 1)[0] for name in names if name.endswith("/index.html")}
    assert len(folders) == 1
    (folder,) = folders
    assert sorted(n.rsplit("/", 1)[1] for n in names if n.startswith(folder + "/") and n.endswith(".html")) == pages
    assert sum(name.endswith("/plotly.min.js") for name in names) == 1
    assert "data:text/html" not in html  # no page embedded in the one-file report


def planned_jobs(workdir: Path, root: Path = ROOT, env: dict[str, str] | None = None) -> dict[str, int]:
    """Rule -> number of jobs that `snakemake -n figures` would run (its job stats table)."""
    out = snakemake(workdir, "-n", "figures", root=root, env=env)
    assert out.returncode == 0, out.stderr[-3000:]
    lines = (out.stdout + out.stderr).splitlines()
    if "Job stats:" not in lines:
        return {}
    jobs = {}
    for line in lines[lines.index("Job stats:") + 3 :]:
        fields = line.split()
        if len(fields) != 2 or fields[0] == "total":
            break
        jobs[fields[0]] = int(fields[1])
    return jobs


def declared_code(rules: Sequence[str]) -> dict[str, set[str]]:
    """Rule -> the files inside the synergrasp package (relative to src/) whose digest is its
    ``code`` param (``Wiring.code``: what its script imports, transitively)."""
    src = ROOT / "src"
    scripts = {rule: ROOT / "workflow" / "scripts" / f"{rule}.py" for rule in rules}
    return {rule: {f.relative_to(src).as_posix() for f in code_files(script, src)} for rule, script in scripts.items()}


#: The rules of the small study's run (its placement is not searched, its closure kinematic).
_RULES_RUN = (
    "simulate",
    "optimise_shard",
    "optimise",
    "minima",
    "tables",
    "fig1",
    "fig2",
    "fig3",
    "fig4",
    "fig5",
    "realism",
    "quality",
    "blockers",
    "blockers_table",
    "planners",
    "reach",
    "hand_reach",
)


def test_a_rules_code_digest_covers_every_module_a_job_loads(run_j2):
    """For every rule, the synergrasp files its script had in sys.modules when it ran are among
    the files of the rule's ``code`` digest (lazy imports included), so editing any of them
    reruns the rule (the tests below)."""
    declared = declared_code(_RULES_RUN)
    loaded: dict[str, set[str]] = {}
    for record in (run_j2 / "module_records").glob("*.txt"):
        script, *files = record.read_text().splitlines()
        loaded.setdefault(script, set()).update(files)
    assert set(loaded) == set(_RULES_RUN)
    for script, files in loaded.items():
        assert files, script
        assert files <= declared[script], (script, sorted(files - declared[script]))


def undeclared_reads(workdir: Path, root: Path = ROOT) -> dict[str, list[str]]:
    """Per rule, the files its jobs read that are not declared by the job: every file under the
    project (``root``, its environment and source code aside: the code digest is checked by
    the test above) or under the run's folder (Snakemake's own files aside) that a job's
    script opened to read and is none of its job's inputs, outputs or log. The shipped schema
    reaches a job through its params (its defaults), not as a file (``wiring.shipped_data``)."""
    root, workdir = Path(os.path.realpath(root)), Path(os.path.realpath(workdir))
    schema = str(root / "src" / "synergrasp" / "data" / "config.schema.yaml")

    def project_file(path: str) -> bool:
        p = Path(path)
        if p.is_relative_to(workdir):
            return not p.is_relative_to(workdir / ".snakemake")
        return p.is_relative_to(root) and not p.is_relative_to(root / ".venv") and p.suffix not in (".py", ".pyc")

    missing: dict[str, set[str]] = {}
    for record in (workdir / "module_records").glob("*.json"):
        job = json.loads(record.read_text())
        declared = {*job["input"], *job["log"], schema}
        within = tuple(f"{out}/" for out in job["output"])  # a folder of pages is an output
        for path in job["read"]:
            if project_file(path) and path not in declared and path not in job["output"] and not path.startswith(within):
                missing.setdefault(job["rule"], set()).add(path)
    return {rule: sorted(paths) for rule, paths in missing.items()}


def test_every_file_a_job_reads_is_an_input_of_its_job(run_j2):
    """A step's inputs follow from what its code reads: every file of the project or of the
    run that a job's script opened to read (upstream outputs, the hand and synergy files, a
    manifest) is one of the inputs its job declares (so a change to it reruns the job and
    Snakemake makes it first), or the job's own output or log. Recorded for every job."""
    records = [json.loads(r.read_text()) for r in (run_j2 / "module_records").glob("*.json")]
    reads = {job["rule"]: set() for job in records}
    for job in records:
        reads[job["rule"]].update(job["read"])
    assert set(reads) == set(_RULES_RUN)
    # the recorder sees what each kind of read reports: a parquet file (pyarrow), a CSV and the hand (open)
    assert any(p.endswith("/gfo.parquet") for p in reads["minima"])
    assert any(p.endswith("/tables/planners.csv") for p in reads["tables"])
    assert any("/synergrasp/data/" in p and p.endswith(".yaml") for p in reads["simulate"])
    assert undeclared_reads(run_j2) == {}


def _log_paths(workdir: Path) -> list[str]:
    out = snakemake(workdir, "-n", "--forceall", "figures")
    return [line.split(":", 1)[1].strip() for line in (out.stdout + out.stderr).splitlines() if line.strip().startswith("log:")]


def test_every_declared_log_is_written(run_j2):
    logs = _log_paths(run_j2)
    assert len(logs) >= 10
    for log in logs:
        assert (run_j2 / log.split(" (")[0]).is_file(), log


def test_a_failed_job_has_its_traceback_in_its_log(run_j2, tmp_path):
    shutil.copytree(run_j2 / "results", tmp_path / "results")
    (tmp_path / "results" / "objects" / "obj1" / "gfo.parquet").write_bytes(b"not a parquet file")
    out = snakemake(tmp_path, "-j1", "results/objects/obj1/minima.parquet")
    assert out.returncode != 0
    log = (tmp_path / "results" / "logs" / "minima" / "obj1.log").read_text()
    assert "Traceback (most recent call last)" in log and "Parquet" in log


@pytest.fixture(scope="module")
def project_copy(tmp_path_factory) -> tuple[Path, Path, dict[str, str]]:
    """A copy of the workflow and its sources (modification times kept, compiled-solver cache
    included) and a finished run of the small config made with that copy's code."""
    root = tmp_path_factory.mktemp("project")
    for name in ("Snakefile", "environment.lock"):
        shutil.copy2(ROOT / name, root / name)
    for name in ("workflow", "src", "config", "profiles"):
        shutil.copytree(ROOT / name, root / name, copy_function=shutil.copy2, ignore=shutil.ignore_patterns("*.egg-info"))
    env = {**os.environ, "PYTHONPATH": str(root / "src")}
    workdir = root / "run"
    out = snakemake(workdir, "-j2", "figures", root=root, env=env)
    assert out.returncode == 0, out.stderr[-5000:]
    return root, workdir, env


def _planned_after_edit(project_copy, module: str) -> dict[str, int]:
    """Jobs a dry run plans after one line is added to ``module`` (the file is then restored,
    modification time included)."""
    root, workdir, env = project_copy
    path = root / "src" / "synergrasp" / module
    text, stat = path.read_text(), path.stat()
    try:
        path.write_text(text + "# one more line\n")
        return planned_jobs(workdir, root=root, env=env)
    finally:
        path.write_text(text)
        os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))


FIGURE_RULES = {"fig1", "fig2", "fig3", "fig4", "fig5", "realism", "figures"}


def test_changing_the_config_module_reruns_the_optimisation(project_copy):
    root, workdir, env = project_copy
    assert planned_jobs(workdir, root=root, env=env) == {}
    planned = _planned_after_edit(project_copy, "config.py")
    assert planned.get("optimise_shard") == 4, planned  # 2 objects x 2 shards
    assert planned_jobs(workdir, root=root, env=env) == {}


@pytest.mark.parametrize("module", ["figures/fig4_fig5_forces_hierarchy.py", "figures/fig1_fig2_postures_grasps.py"])
def test_changing_a_figure_module_reruns_only_figures(project_copy, module):
    planned = _planned_after_edit(project_copy, module)
    assert planned and set(planned) <= FIGURE_RULES, planned


def _outputs(workdir: Path) -> dict[str, tuple[int, str]]:
    """Every result file (logs and benchmarks aside): modification time and content digest."""
    files = [
        p
        for p in (workdir / "results").rglob("*")
        if p.is_file() and p.relative_to(workdir / "results").parts[0] not in ("logs", "benchmarks")
    ]
    return {str(p.relative_to(workdir)): (p.stat().st_mtime_ns, hashlib.sha256(p.read_bytes()).hexdigest()) for p in files}


def _incomplete(workdir: Path) -> set[str]:
    """Outputs Snakemake marked as incomplete (jobs that started and did not finish)."""
    marks = workdir / ".snakemake" / "incomplete"
    names = set()
    for mark in marks.rglob("*") if marks.exists() else []:
        if mark.is_file():  # the path, URL-safe base64, split in '@'-prefixed parts when long
            encoded = "".join(part.lstrip("@") for part in mark.relative_to(marks).parts)
            names.add(base64.urlsafe_b64decode(encoded).decode())
    return names


@pytest.mark.parametrize("kill", [signal.SIGINT, signal.SIGKILL], ids=["SIGINT", "SIGKILL"])
def test_a_killed_run_reruns_only_what_did_not_finish(run_j2, tmp_path, kill):
    with open(tmp_path / "killed.log", "w") as log:
        # SIGINT handled as in a terminal even when the suite itself was started in the
        # background (a shell then starts it, and so every child, with SIGINT ignored)
        run = subprocess.Popen(
            command(tmp_path, "-j2", "figures"),
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        )
        deadline = time.monotonic() + 900
        while not list((tmp_path / "results" / "objects").glob("*/gfo_shards/*.parquet")):
            assert run.poll() is None, "the run ended before its first optimisation output"
            assert time.monotonic() < deadline
            time.sleep(0.05)
        missing = [t for t in expected_targets() if not (tmp_path / t).exists()]
        os.killpg(run.pid, kill)  # the whole session: Snakemake and its running jobs
        run.wait(timeout=300)
    assert missing, "every target existed when the run was killed"
    assert run.returncode != 0
    finished = _outputs(tmp_path)
    unfinished = _incomplete(tmp_path)

    rerun = snakemake(tmp_path, "-j2", "figures")
    if kill == signal.SIGKILL:  # the lock of the killed run stays: the README says --unlock
        assert rerun.returncode != 0 and "--unlock" in rerun.stdout + rerun.stderr
        assert snakemake(tmp_path, "--unlock").returncode == 0
        rerun = snakemake(tmp_path, "-j2", "figures")
    assert rerun.returncode == 0, rerun.stderr[-5000:]

    after = _outputs(tmp_path)
    # a file of a folder output (the 3-D pages) is unfinished when its folder is
    kept = {
        path
        for path in finished
        if path in after and not any(path == u or path.startswith(u.rstrip("/") + "/") for u in unfinished)
    }
    assert kept, "nothing had finished before the kill"
    for path in kept:  # finished work is not recomputed
        assert after[path] == finished[path], path
    for rel in missing:  # what was missing is made
        assert made(tmp_path / rel), rel
    for table in sorted((run_j2 / "results" / "tables").iterdir()):
        assert table.read_bytes() == (tmp_path / "results" / "tables" / table.name).read_bytes(), table.name
    for parquet in sorted((run_j2 / "results" / "objects").rglob("*.parquet")):
        assert parquet.read_bytes() == (tmp_path / parquet.relative_to(run_j2)).read_bytes(), parquet


def test_small_sweep_summary_has_one_row_per_scenario(run_j2, tmp_path):
    """The small config with its scenarios: `sensitivity` builds what the summary reads of every
    scenario from the default's results, and a summary with one row per scenario, default first."""
    config = yaml.safe_load(SMALL.read_text())
    config.update(yaml.safe_load((ROOT / "tests" / "config" / "small_sweep.yaml").read_text()))
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(config))
    workdir = tmp_path / "work"
    shutil.copytree(run_j2 / "results", workdir / "results")
    out = snakemake(workdir, "-j2", "sensitivity", configfile=path)
    assert out.returncode == 0, out.stderr[-5000:]
    summary = pd.read_csv(workdir / "results" / "sensitivity" / "claims.csv")
    assert list(summary["scenario"]) == ["default", *config["scenarios"]]
    claims = pd.read_csv(workdir / "results" / "tables" / "claims.csv")
    assert {f"claim{c}_verdict" for c in claims["claim"]} <= set(summary.columns)
    for name in ("claims_grid", "table2_curves"):
        assert (workdir / "results" / "sensitivity" / f"{name}.png").stat().st_size > 0
    # the optimisation and analysis scenarios share the default's simulation: no contacts of
    # their own; the searched one searches, closes at its targets and draws its placement maps
    scenarios = workdir / "results" / "scenarios"
    assert not list(scenarios.glob("mu_1_0/objects/*/contacts.parquet"))
    assert not list(scenarios.glob("success_load_feasible/objects/*/contacts.parquet"))
    for name in ("placement.csv", "contacts.parquet"):
        assert len(list(scenarios.glob(f"placement_searched/objects/*/{name}"))) == 2, name
    # the summary reads each scenario's tables and grasp realism, not its figures
    assert not list(scenarios.glob("*/objects/*/placement_map.png"))
    assert not list(scenarios.glob("*/objects/*/fig4_force_maps.png"))
    assert (scenarios / "placement_searched" / "tables" / "grasp_realism.csv").exists()
    assert summary["grasp_contacts_median"].str.count("/").eq(1).all()  # two objects
    placement = dict(zip(summary["scenario"], summary["placement"]))
    assert placement["default"] == "approach" and placement["placement_searched"] == "searched, rank 1 (own search)"


@pytest.mark.parametrize("example, n_joints", [("shadow_hand", 17), ("inspire_hand", 6)])
def test_small_study_on_a_shipped_hand(tmp_path, example, n_joints):
    """config/examples/<hand>.yaml over the small config: every step runs on the second
    (Shadow: MJCF, 17 joints) and the third shipped hand (Inspire: MJCF with fitted collision
    meshes, 6 joints, 6 synergies) and grasps the box obj4 with its own links."""
    from synergrasp.config import overlay

    config = overlay(
        yaml.safe_load(SMALL.read_text()), yaml.safe_load((ROOT / "config" / "examples" / f"{example}.yaml").read_text())
    )
    configfile = tmp_path / f"{example}_small.yaml"
    configfile.write_text(yaml.safe_dump(config))
    out = snakemake(tmp_path, "-j2", "figures", configfile=configfile)
    assert out.returncode == 0, out.stderr[-5000:]
    realism = pd.read_csv(tmp_path / "results" / "tables" / "grasp_realism.csv").set_index("object")
    assert realism.loc["obj4", "contacts_median"] >= 3 and realism.loc["obj4", "pct_force_closure"] > 0
    contacts = pd.read_parquet(tmp_path / "results" / "objects" / "obj4" / "contacts.parquet")
    assert contacts["q"].map(len).eq(n_joints).all()
    table2 = pd.read_csv(tmp_path / "results" / "tables" / "table2_success_rates.csv")
    assert list(table2.columns[1:]) == [str(k) for k in range(1, config["analyses"]["table2_k_max"] + 1)]


def test_random_objects_example_plans_every_drawn_object(tmp_path):
    """config/examples/random_objects.yaml (n_objects: 3): a dry run of `across_objects`
    plans the steps of each drawn object that is studied, their meshes' convex parts as jobs,
    and the summary across objects; on a machine that has never seen the meshes it makes no
    parts (an empty cache stays empty)."""
    import os
    import re

    import yaml

    from synergrasp.config import overlay
    from synergrasp.simulation.random_objects import drawn_objects

    example = yaml.safe_load((ROOT / "config" / "examples" / "random_objects.yaml").read_text())
    spec = {**example["random_objects"], "n_objects": 3, "sha256_file": str(ROOT / example["random_objects"]["sha256_file"])}
    configfile = tmp_path / "three_random.yaml"
    configfile.write_text(yaml.safe_dump(overlay(overlay(yaml.safe_load(SMALL.read_text()), example), {"random_objects": spec})))
    cache = tmp_path / "cache"
    out = snakemake(tmp_path, "-n", "across_objects", configfile=configfile, env={**os.environ, "XDG_CACHE_HOME": str(cache)})
    assert out.returncode == 0, out.stderr[-5000:]
    studied = [o.name for o in drawn_objects(spec, ROOT) if not o.problem]
    assert studied
    for name in studied:
        assert f"object={name}" in out.stdout, name
    assert "objects_summary" in out.stdout
    assert re.search(rf"^mesh_parts\s+{len(studied)}$", out.stdout, re.MULTILINE), out.stdout[-3000:]
    assert not (cache / "synergrasp-meshes").exists() and not (tmp_path / "results" / "meshes").exists()
