"""synergrasp.wiring (what workflow/rules/*.smk wire) and synergrasp.resolved (the derived
values every step reads), checked without Snakemake: paths and requests against cases written
out by hand, the import scanner against a package made here."""

from __future__ import annotations

import hashlib
import re
import shutil
import types
from pathlib import Path

import pytest

from synergrasp.config import defaults, validate_config
from synergrasp.ids import set_members, set_order
from synergrasp.resolved import effective_placement, friction_mu, study_object, study_objects, weight_N
from synergrasp.steps import rule_costs, step_config
from synergrasp.wiring import RuleFiles, Wiring, code_digest, code_files, job_size, mem_mb, report_archive, runtime_min

ROOT = Path(__file__).resolve().parents[1]


class _W(dict):
    """Wildcards as Snakemake hands them: attributes and ``keys``/``get``."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


def test_a_rules_paths_follow_its_step_scope_and_wildcards():
    fig4, shard, tables, fig3 = (RuleFiles(r) for r in ("fig4", "optimise_shard", "tables", "fig3"))
    assert fig4.outputs()["maps_png"] == "{root}/objects/{object}/fig4_force_maps.png"
    assert (fig4.log(), fig4.benchmark()) == ("{root}/logs/fig4/{object}.log", "{root}/benchmarks/fig4/{object}.tsv")
    assert shard.outputs() == {"out": "{root}/objects/{object}/gfo_shards/{shard}.parquet"}
    assert shard.log() == "{root}/logs/optimise_shard/{object}_{shard}.log"
    assert tables.log() == "{root}/logs/tables.log" and fig3.benchmark() == "results/benchmarks/fig3.tsv"
    assert fig4.report("maps_png") == {
        "caption": "../report/fig4_force_maps.rst",
        "category": "Fig. 4",
        "subcategory": "{object}",
    }
    assert fig4.report("maps_pdf") is None and tables.report("claims_csv")["category"] == "Tables"


def test_snakemake_flags_go_where_the_registry_says():
    def report(path, **entry):
        return ("report", path, entry.get("caption"))

    def directory(path):
        return ("directory", path)

    def temp(path):
        return ("temp", path)

    html = RuleFiles("fig2").snakemake_outputs(report, directory, temp, archive=False)
    archive = RuleFiles("fig2").snakemake_outputs(report, directory, temp, archive=True)
    assert html["pages"] == ("directory", "{root}/figures/grasps_3d")  # the one-file report refuses folders
    assert archive["pages"][0] == "report" and archive["pages"][1] == ("directory", "{root}/figures/grasps_3d")
    assert html["png"] == ("report", "{root}/figures/fig2_example_grasps.png", "../report/fig2.rst")
    assert html["pdf"] == "{root}/figures/fig2_example_grasps.pdf"
    assert RuleFiles("optimise_shard").snakemake_outputs(report, directory, temp, False) == {
        "out": ("temp", "{root}/objects/{object}/gfo_shards/{shard}.parquet")
    }


def test_job_size_and_requests_by_hand():
    cfg = defaults()  # 72 x 25 = 1,800 poses, 75 sets, 4 objects, one shard, kinematic closure
    assert job_size("simulate", cfg) == 1800 and job_size("optimise", cfg) == 1800 * 75
    assert job_size("tables", cfg) == 4 * 1800 * 75 and job_size("fig1", cfg) == 0
    dynamic = {**cfg, "closure": {**cfg["closure"], "model": "dynamic"}}
    assert job_size("simulate", dynamic) == 1800 * 9.0
    unknown = {**cfg, "closure": {**cfg["closure"], "model": "new_engine"}}
    assert job_size("simulate", unknown) == 1800 * 20.0  # charged high until measured
    # search: (80 s + 60 s compile) x 3 = 7 min; (700 + 150 MB) x 1.5 -> 1,300 MB
    assert runtime_min("search", cfg) == 7 and mem_mb("search", cfg) == 1300
    # simulate: (1.5 + 4.5e-3 x 1800) s x 3 = 28.8 s -> 1 min; (178 + 7.6e-3 x 1800) x 1.5 = 287.5 -> 300 MB
    assert runtime_min("simulate", cfg) == 1 and mem_mb("simulate", cfg) == 300
    assert rule_costs()["search"].threads == 2 and rule_costs()["simulate"].threads == 1


def test_the_import_scanner_follows_lazy_imports_and_packages(tmp_path):
    pkg = tmp_path / "synergrasp"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "sub" / "a.py").write_text("def f():\n    from synergrasp import b  # lazy\n")
    (pkg / "b.py").write_text("import synergrasp.c, os\n")
    (pkg / "c.py").write_text("from synergrasp.sub import (\n    a,\n)\n")
    (pkg / "unused.py").write_text("")
    script = tmp_path / "script.py"
    script.write_text("from synergrasp.sub.a import f\n")
    names = {p.relative_to(tmp_path).as_posix() for p in code_files(script, tmp_path)}
    assert names == {
        "synergrasp/__init__.py",
        "synergrasp/sub/__init__.py",
        "synergrasp/sub/a.py",
        "synergrasp/b.py",
        "synergrasp/c.py",
    }


@pytest.mark.parametrize(
    "argv, archive",
    [
        (["snakemake", "--report", "results/report.zip"], True),
        (["snakemake", "--report=results/report.zip"], True),
        (["snakemake", "--report", "results/report.html"], False),
        (["snakemake", "-j2", "figures"], False),
    ],
)
def test_report_archive_reads_the_command_line(argv, archive):
    assert report_archive(argv) is archive


def _wiring(**changes):
    """The wiring of the default configuration with ``changes`` (top-level keys) in this checkout."""
    return Wiring({**defaults(), **changes}, ROOT, error=RuntimeError, warn=lambda text: None)


def test_the_scenario_targets_and_a_step_not_made_hands_on_its_upstreams_file():
    wiring = _wiring()
    targets = wiring.scenario_targets()
    assert "results/objects/obj1/placement.csv" in targets  # the default placement is searched
    assert "results/figures/fig3_rulegraph.png" in targets and "results/sensitivity/claims.csv" not in targets
    assert not any("target_claims" in t or "placement_claims" in t for t in targets)  # optional steps
    # the kinematic closure selects no contact: the `contacts` step's input is the closure's table
    assert wiring.step_file("default", "contacts", "obj1") == "results/objects/obj1/contacts.parquet"
    assert wiring.step_input("search")(_W(root="results", object="obj1")) == "results/objects/obj1/placement.csv"


def test_a_rules_inputs_follow_the_registry_and_the_two_steps_scopes():
    """Each source is the file(s) the scopes say: the job's object's file for a rule per object,
    every object's for a rule per scenario, the scenario's file of a step per scenario, every
    scenario's for a rule run once for the workflow; and the code the rule runs."""
    wiring = _wiring(scenarios={"mu_1_0": {"mechanics": {"mu": 1.0}}})
    job, study = _W(root="results", object="obj2"), _W(root="results")
    minima = wiring.inputs("minima")
    assert minima["gfo"](job) == "results/objects/obj2/gfo.parquet"
    assert "code" not in minima  # a digest param, not a hundred inputs (the next test)
    tables = wiring.inputs("tables")
    assert tables["gfo"](study) == [f"results/objects/{o}/gfo.parquet" for o in ("obj1", "obj2", "obj3", "obj4")]
    assert tables["planners"](study) == "results/tables/planners.csv"
    assert str(ROOT / "src" / "synergrasp" / "data" / "hand.yaml") in tables["data"]  # the hand it loads
    summary = wiring.inputs("objects_summary")
    assert summary["enrollment"](study)[0] == "results/objects/obj1/enrollment.csv"
    claims = wiring.inputs("sensitivity")["claims"](_W())
    assert claims == ["results/tables/claims.csv", "results/scenarios/mu_1_0/tables/claims.csv"]
    assert wiring.inputs("optimise")["shards"](job) == ["results/objects/obj2/gfo_shards/0.parquet"]
    assert wiring.inputs("fig3")["rules"] == [str(p) for p in sorted((ROOT / "workflow" / "rules").glob("*.smk"))]
    assert set(wiring.params("fig5")) == {"cfg", "code"} and set(wiring.params("optimise")) == {"code"}
    assert wiring.params("fig5")["cfg"](study) == step_config(wiring.study, "fig5")


def test_a_rules_code_param_is_the_digest_of_the_modules_its_script_imports(tmp_path):
    """Every rule is handed the digest of the code it runs: the modules its script imports
    (transitively) and the lock, named relative to the checkout; an edited module changes the
    digest of the rules that load it and of no other, and another checkout gives the same."""
    wiring = _wiring()
    assert str(ROOT / "src" / "synergrasp" / "analysis" / "minima.py") in wiring.code("minima")
    assert str(ROOT / "environment.lock") in wiring.code("fig5")
    assert wiring.params("minima")["code"] == wiring.code_digest("minima") != wiring.code_digest("fig5")
    copy = tmp_path / "copy"
    files = [Path(f) for f in wiring.code("minima")]
    for f in files:
        (copy / f.relative_to(ROOT)).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(f, copy / f.relative_to(ROOT))
    moved = [copy / f.relative_to(ROOT) for f in files]
    assert code_digest(moved, copy) == code_digest(files, ROOT)  # any checkout path
    edited = copy / "src" / "synergrasp" / "analysis" / "minima.py"
    edited.write_text(edited.read_text() + "# one more line\n")
    assert code_digest(moved, copy) != code_digest(files, ROOT)
    by_hand = hashlib.sha256()
    for f in sorted(files, key=lambda f: f.relative_to(ROOT).as_posix()):
        by_hand.update(f.relative_to(ROOT).as_posix().encode())
        by_hand.update(f.read_bytes())
    assert code_digest(files, ROOT) == by_hand.hexdigest()


def test_only_a_step_reading_the_search_rank_refuses_a_table_without_it(tmp_path):
    """A search table holding fewer distinct targets than ``search_rank`` stops the closure
    (which places the box at that rank) before any job; the placement map reads the same
    table but not the rank."""
    table = tmp_path / "placement.csv"
    table.write_text("object,distinct_rank\nobj1,1\nobj1,0\n")  # one distinct target
    config = defaults()
    config["placement"]["search_rank"] = 2
    wiring = _wiring(placement=config["placement"])
    wiring.step_input = lambda step: lambda w: str(table)
    assert wiring.search_input("placement_map")(_W(root="results", object="obj1")) == str(table)
    with pytest.raises(RuntimeError, match="search_rank"):
        wiring.search_input("simulate")(_W(root="results", object="obj1"))


def test_an_approach_placement_has_no_search_and_no_map():
    config = defaults()
    config["placement"]["mode"] = "approach"
    wiring = _wiring(placement=config["placement"])
    targets = wiring.object_targets("obj1")
    assert not any(t.endswith(("placement.csv", "placement_map.png")) for t in targets)
    assert wiring.step_input("search")(_W(root="results", object="obj1")) == []
    assert wiring.placement_label("default") == "approach"


def test_the_memory_requests_checked_against_a_node_are_those_of_the_checked_scenarios():
    grid = {"alpha_deg": {"start": -180, "stop": 150, "step": 30}, "beta_deg": {"start": -60, "stop": 60, "step": 20}}
    wiring = _wiring(scenarios={"coarse": {"grid": grid}})
    rules = list(rule_costs())
    # only the default scenario is checked yet: one request per rule, the rule's own
    assert wiring.memory_requests() == [(rule, mem_mb(rule, wiring.study)) for rule in rules]
    assert dict(wiring.memory_requests())["search"] == 1300  # (700 + 150 MB) x 1.5, by hand above
    # tables: 4 objects x 1,800 poses x 75 sets: (400 + 1.4e-5 x 540,000) x 1.5 = 611.3 -> 700 MB
    assert dict(wiring.memory_requests())["tables"] == 700
    wiring.scenario("coarse")  # a job of the scenario needs it: its requests join (12 x 7 poses)
    coarse = [request for rule, request in wiring.memory_requests()[len(rules) :] if rule == "tables"]
    assert len(wiring.memory_requests()) == 2 * len(rules) and coarse == [700]  # (400 + 1.4e-5 x 25,200) x 1.5 = 600.5


def test_a_bad_scenario_is_one_error_naming_it():
    wiring = _wiring(scenarios={"s1": {"mechanics": {"muu": 1.0}}})
    with pytest.raises(RuntimeError, match="Invalid input, nothing was run:\nscenario 's1': config error at 'mechanics'"):
        wiring.scenario("s1")


# --------------------------------------------------------------------------- synergrasp.resolved


def test_an_objects_placement_is_the_global_one_with_its_override():
    config = defaults()
    config["objects"]["obj2"]["placement"] = {"search_rank": 2, "search": {"spacing_mm": 4.0}}
    config = validate_config(config)
    placement = effective_placement(config, "obj2")
    assert placement["search_rank"] == 2 and placement["search"]["spacing_mm"] == 4.0
    assert placement["search"]["coarse_spacing_mm"] == config["placement"]["search"]["coarse_spacing_mm"]
    assert placement["mode"] == config["placement"]["mode"]
    assert effective_placement(config, "obj1") == config["placement"]


def test_weight_and_friction_are_stated_once():
    config = defaults()
    config["objects"]["obj1"]["mass_kg"] = 0.5
    config["mechanics"]["g_m_per_s2"] = 9.0
    assert weight_N(config, "obj1") == 4.5 and friction_mu(config) == 1.5
    objects = study_objects(config)
    assert list(objects) == ["obj1", "obj2", "obj3", "obj4"] and objects["obj1"].weight_N == 4.5
    # a step's own part of the configuration: what it does not read resolves to None
    part = step_config(config, "fig2")  # shapes and masses, the mechanics; no placement
    obj = study_object(part, "obj1")
    assert obj.mass_kg == 0.5 and obj.weight_N == 4.5 and obj.placement is None and obj.shape is not None
    part = step_config(config, "simulate", "obj1")  # kinematic: no mass
    assert study_object(part, "obj1").weight_N is None and study_object(part, "obj1").placement is not None


def test_set_ids_are_read_in_one_place():
    assert set_members("1-2-10") == (1, 2, 10)
    assert sorted(["1-2-3", "10", "2", "1-3", "1-10"], key=set_order) == ["2", "10", "1-3", "1-10", "1-2-3"]


@pytest.mark.parametrize(
    "model, unloaded, contacts",
    [
        ("kinematic", "keep", "contacts.parquet"),
        ("dynamic", "keep", "contacts.parquet"),
        ("dynamic", "drop", "load_carrying_contacts.parquet"),
    ],
)
def test_the_commands_read_the_files_the_workflow_reads(model, unloaded, contacts):
    """``synergrasp plan`` and ``synergrasp grasp`` find an object's tables by
    ``steps.object_file``, the workflow by ``Wiring.step_file``: the same file, whatever
    else is on disk (the contact selection's table only where the configuration makes it)."""
    from synergrasp.steps import RESULTS, object_file

    closure = defaults()["closure"]
    w = _wiring(closure={**closure, "model": model, "dynamic": {**closure["dynamic"], "unloaded_contacts": unloaded}})
    for obj in w.objects:
        for step in ("search", "simulate", "contacts", "optimise", "minima"):
            assert w.step_file("default", step, obj) == object_file(w.study, step, obj).as_posix(), (obj, step)
        assert object_file(w.study, "contacts", obj) == Path(RESULTS) / "objects" / obj / contacts
        assert object_file(w.study, "contacts", obj, "elsewhere") == Path("elsewhere") / "objects" / obj / contacts


def test_a_mesh_object_reads_its_parts_from_a_job_named_by_the_files_content(tmp_path):
    """The workflow names each mesh's parts file by the content's hash (two files with the same
    bytes share one job) and makes it in the rule mesh_parts; the checks decompose nothing."""
    import shutil

    box = ROOT / "tests" / "data" / "box_30x60x100.obj"
    shutil.copy(box, tmp_path / "copy.obj")
    objects = {
        name: {"shape": {"mesh": {"path": str(path), "scale": 1.0}}, "mass_kg": 0.2}
        for name, path in (("a", box), ("b", tmp_path / "copy.obj"))
    }
    wiring = _wiring(objects=objects)
    parts = {name: wiring.study["objects"][name]["shape"]["mesh"]["parts"] for name in objects}
    assert parts["a"] == parts["b"] and re.fullmatch(r"results/meshes/[0-9a-f]{24}\.obj", parts["a"])
    key = parts["a"].removeprefix("results/meshes/").removesuffix(".obj")
    assert wiring.mesh_file(types.SimpleNamespace(mesh=key)) in (str(box), str(tmp_path / "copy.obj"))
    jobs = types.SimpleNamespace(object="a", keys=lambda: ["object"])
    assert parts["a"] in wiring.user_files(jobs) and str(box) in wiring.user_files(jobs)
    assert RuleFiles("mesh_parts").log() == "results/logs/mesh_parts/{mesh}.log"
