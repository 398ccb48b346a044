"""The set-up step `python -m synergrasp.warm_up`: its steps and the bytecode it leaves for the jobs."""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = ROOT / "workflow" / "scripts"

# Lists, in a process that writes no bytecode, every module that importing argv[1:] loads
# (not those the interpreter loaded at start-up, such as a site's sitecustomize) whose source
# has no bytecode under the prefix the test gives; the standard library's comes with Python.
MISSING = """
import importlib, importlib.util, os, sys, sysconfig
stdlib = os.path.realpath(sysconfig.get_paths()["stdlib"])
startup = set(sys.modules)
for name in sys.argv[1:]:
    importlib.import_module(name)
from synergrasp.snakemake_adapter import load_snakemake_modules
load_snakemake_modules()
for name, module in list(sys.modules.items()):
    path = getattr(module, "__file__", None)
    if name in startup or not path or not path.endswith(".py") or os.path.realpath(path).startswith(stdlib):
        continue
    if not os.path.exists(importlib.util.cache_from_source(path)):
        print(module.__name__)
"""


def _run(args: list[str], prefix: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1", "PYTHONPYCACHEPREFIX": str(prefix)}
    return subprocess.run([sys.executable, *args], cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)


def _job_imports() -> list[str]:
    """The modules the workflow's scripts import (their import statements)."""
    names: set[str] = set()  # the script preamble's modules: load_snakemake_modules in MISSING
    for script in SCRIPTS.glob("*.py"):
        for node in ast.walk(ast.parse(script.read_text())):
            if isinstance(node, ast.Import):
                names.update(alias.name for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0 and node.module != "__future__":
                names.add(node.module)
    return sorted(names)


def test_unknown_or_missing_step_is_refused_before_any_work(tmp_path):
    for args, named in ((["bytecode"], "unknown step bytecode"), ([], "no step named")):
        run = _run(["-m", "synergrasp.warm_up", *args], tmp_path)
        assert run.returncode == 2
        assert named in run.stderr and "kernel, closure, imports" in run.stderr
    assert not any(tmp_path.rglob("*.pyc"))  # nothing imported beyond the command itself


def test_imports_step_leaves_bytecode_for_every_module_a_job_imports(tmp_path):
    """With PYTHONDONTWRITEBYTECODE set, as on CI images, the step still writes the bytecode
    of every module the workflow's scripts import, transitively: no job compiles one again."""
    imports = _job_imports()
    assert "synergrasp.job_log" in imports and "synergrasp.table_contracts" in imports
    before = _run(["-c", MISSING, *imports], tmp_path)
    assert before.returncode == 0, before.stderr
    assert "pandas" in before.stdout.split()  # the check can fail: nothing is compiled yet

    step = _run(["-m", "synergrasp.warm_up", "imports"], tmp_path)
    assert step.returncode == 0, step.stderr
    after = _run(["-c", MISSING, *imports], tmp_path)
    assert after.returncode == 0, after.stderr
    assert after.stdout.split() == []


# Prints the distributions (normalised names) whose modules the kernel's step loads (numba
# imports some, such as cffi, only if they are installed: so they are installed first too).
KERNEL_DISTRIBUTIONS = """
import importlib.metadata, re, sys
startup = set(sys.modules)
from synergrasp.warm_up import STEPS
STEPS["kernel"]()
owners = importlib.metadata.packages_distributions()
new = [name for name, module in list(sys.modules.items()) if name not in startup and getattr(module, "__file__", None)]
loaded = {name.split(".")[0] for name in new}
print(" ".join(sorted({re.sub(r"[-_.]+", "-", d).lower() for name in loaded for d in owners.get(name, ())})))
"""


def test_kernel_compile_starts_on_what_is_installed_first():
    """`make venv` starts the kernel's compile once KERNEL_NEEDS are installed, beside uv
    installing the rest: the step must load nothing else, and each of them must be pinned with
    its hashes in environment.lock (uv checks the files against them, `-c`)."""
    makefile = (ROOT / "Makefile").read_text()
    needs = makefile.split("\nKERNEL_NEEDS = ", 1)[1].split("\n", 1)[0].split()
    run = subprocess.run([sys.executable, "-c", KERNEL_DISTRIBUTIONS], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    loaded = set(run.stdout.split()) - {"synergrasp"}
    assert {"numba", "numpy", "llvmlite"} <= loaded  # the check sees the kernel's libraries
    assert sorted(loaded - set(needs)) == []
    lock = (ROOT / "environment.lock").read_text()
    for name in needs:
        assert re.search(rf"^{re.escape(name)}==\S+ \\\n    --hash=sha256:[0-9a-f]{{64}}", lock, re.M), name
