"""The compiled code's cache (synergrasp.compiled_cache): one directory per group of modules,
named by their sources, so that a change to a callee's module never loads a caller's stale
machine code, and any checkout path of the same sources loads the same code."""

from __future__ import annotations

import ast
import importlib
import os
import re
import shutil
import subprocess
import sys

import pytest

from synergrasp import compiled_cache
from synergrasp.optimisation.ipm import compiled as ipm_compiled
from synergrasp.simulation.shapes import compiled as shapes_compiled

GROUPS = (ipm_compiled.KERNEL, shapes_compiled.GROUP)
PACKAGE = compiled_cache.PACKAGE
_COMPILED = re.compile(r"^\s*@[\w.]*jit\w*\b|njit\(", re.MULTILINE)


def _module(rel: str):
    return importlib.import_module("synergrasp." + rel[:-3].replace("/", "."))


def _group_of(rel: str):
    return next((g for g in GROUPS if rel in g.files), None)


def test_every_module_with_compiled_functions_is_in_a_group():
    with_compiled = {
        str(p.relative_to(PACKAGE))
        for p in PACKAGE.rglob("*.py")
        if _COMPILED.search(p.read_text()) and p.name != "compiled_cache.py"
    }
    assert with_compiled == {f for g in GROUPS for f in g.files}
    assert all(f.count("/") >= 1 and (PACKAGE / f).is_file() for g in GROUPS for f in g.files)


def test_a_module_importing_another_groups_compiled_module_is_in_that_group():
    """Callers embed their callees' machine code: a module of a group imports compiled
    functions only from modules of its own group."""
    for group in GROUPS:
        for rel in group.files:
            tree = ast.parse((PACKAGE / rel).read_text())
            for node in ast.walk(tree):
                if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("synergrasp."):
                    target = node.module.removeprefix("synergrasp.").replace(".", "/") + ".py"
                    other = _group_of(target)
                    assert other is None or other == group, f"{rel} imports {target} of group {other.name}"


@pytest.mark.parametrize("group", GROUPS, ids=lambda g: g.name)
def test_every_compiled_function_is_cached_by_its_groups_sources(group):
    for rel in group.files:
        module = _module(rel)
        dispatchers = [d for d in vars(module).values() if hasattr(d, "py_func") and d.py_func.__module__ == module.__name__]
        assert dispatchers or rel.endswith("compiled.py"), rel
        for d in dispatchers:
            assert d._cache.cache_path == str(group.cache_dir()), (rel, d.py_func.__name__)
            assert d._cache._impl.locator.get_source_stamp() == group.digest
    assert group.cache_dir().parent.name == f"synergrasp-{group.name}"
    assert group.cache_dir().name == group.digest[:16]
    assert str(PACKAGE) not in str(group.cache_dir())


@pytest.mark.parametrize("group", GROUPS, ids=lambda g: g.name)
def test_the_key_follows_every_source_of_the_group_not_the_checkout_path(tmp_path, group):
    files = (*group.files, "compiled_cache.py")
    for rel in files:
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(PACKAGE / rel, tmp_path / rel)
    assert compiled_cache.sources_digest(group.files, tmp_path) == group.digest
    for rel in files:
        original = (tmp_path / rel).read_bytes()
        (tmp_path / rel).write_bytes(original + b"\n")
        assert compiled_cache.sources_digest(group.files, tmp_path) != group.digest, rel
        (tmp_path / rel).write_bytes(original)


def test_a_group_refuses_a_file_of_another_group_and_two_files_of_one_name():
    with pytest.raises(ValueError, match="already in group 'shapes'"):
        compiled_cache.register_group("other", ["simulation/capsules.py"])
    with pytest.raises(ValueError, match="one name"):
        compiled_cache.register_group("other", ["simulation/shapes/compiled.py", "optimisation/ipm/compiled.py"])


_PAIR_GAPS = """
import numpy as np, synergrasp
from synergrasp.simulation.capsules import pair_gaps
assert synergrasp.__file__.startswith({root!r}), synergrasp.__file__
p0, p1 = np.array([[30.0, 0.0, 0.0]]), np.array([[30.0, 10.0, 0.0]])
gap = pair_gaps(p0, p1, np.array([1.0]), np.array([0]), np.array([-1]), np.eye(3)[None], np.zeros((1, 3)),
                np.full((1, 3), 10.0))
print(repr(float(gap[0])))
"""


def test_a_change_to_a_callees_module_is_compiled_again_not_loaded_stale(tmp_path):
    """`capsules.pair_gaps` calls `shapes.kernels.segment_box`: after a change to kernels.py
    alone, a copy of the package with the same cache must give the changed result (numba's
    own cache, keyed by capsules.py, would load the first run's machine code)."""
    shutil.copytree(PACKAGE, tmp_path / "synergrasp", ignore=shutil.ignore_patterns("__pycache__"))
    env = dict(os.environ, PYTHONPATH=str(tmp_path), NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    script = _PAIR_GAPS.format(root=str(tmp_path))

    def gap() -> float:
        run = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        return float(run.stdout)

    assert gap() == pytest.approx(19.0)  # the axis 20 mm from the box's face, radius 1 mm
    kernels = tmp_path / "synergrasp" / "simulation" / "shapes" / "kernels.py"
    text = kernels.read_text()
    outside = "        return np.sqrt(best_sq), 0.5 * (t_lo + t_hi)\n"
    assert text.count(outside) == 1
    kernels.write_text(text.replace(outside, outside.replace("np.sqrt(best_sq)", "np.sqrt(best_sq) + 100.0")))
    assert gap() == pytest.approx(119.0)


def test_the_shapes_package_imports_no_compiled_code():
    """Every Snakemake start imports the shapes (the configuration's checks): numba only where
    a compiled query is asked for."""
    code = "import sys, synergrasp.config, synergrasp.simulation.shapes; print('numba' in sys.modules)"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.strip() == "False"
