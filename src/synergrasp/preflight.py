"""Checks the workflow runs before any job besides the configuration's own (``config``): the
YAML files Snakemake reads itself, the wildcard values Snakemake's own guard must accept,
and the scheduler behind the cluster profile. Each problem is one line naming the file, the
key, the command or the variable. Imports nothing of the project but ``yaml_io``.
"""

from __future__ import annotations

import os
import re
import shutil
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from synergrasp.yaml_io import YamlFileError, read_yaml

__all__ = ["configfile_problems", "accept_configured_wildcards", "slurm_problems"]


def configfile_problems(paths: Iterable[Any]) -> list[str]:
    """What Snakemake's own reading of the configuration files hides: a file that cannot be
    read again, and keys repeated in one mapping (Snakemake keeps the last value silently).
    One line per problem, naming the file, the line and the key."""
    problems = []
    for path in dict.fromkeys(str(p) for p in paths):
        try:
            read_yaml(path, "config file")
        except YamlFileError as err:
            problems += str(err).splitlines()
    return problems


def accept_configured_wildcards(values: Iterable[str]) -> None:
    """Let Snakemake's guard against endlessly recursing wildcards (a value ending in one
    substring repeated 20 times, e.g. ``obj_`` and twenty zeros) accept ``values``.

    The guard protects rules whose wildcards may match anything; this workflow constrains
    each wildcard to the configured names exactly (common.smk), so a configured name cannot
    recurse. Every other value is still checked by Snakemake's own detector."""
    import snakemake.dag

    base = getattr(snakemake.dag.PeriodicityDetector, "_snakemake_detector", snakemake.dag.PeriodicityDetector)
    accepted = frozenset(values)

    class ConfiguredNames(base):  # type: ignore[misc, valid-type]
        _snakemake_detector = base

        def is_periodic(self, value: str) -> Any:
            return None if value in accepted else super().is_periodic(value)

    snakemake.dag.PeriodicityDetector = ConfiguredNames


_VARIABLE = re.compile(r"\$\{?([A-Za-z_][A-Za-z0-9_]*)\}?")


def slurm_problems(settings: Any, raw_resources: Mapping[str, Any],
                   environ: Mapping[str, str] = os.environ,
                   which: Callable[[str], str | None] = shutil.which) -> list[str]:
    """What keeps the SLURM executor from submitting from this shell, one item per problem:
    a variable the profile's default resources read (``$SBATCH_ACCOUNT``) that is not set,
    and each scheduler command the executor will call that is not on PATH: ``sbatch`` and
    ``scancel``; the status command (``sacct`` or ``squeue``); ``sacctmgr`` or ``sshare``
    to validate a given account, ``sacct`` to guess one when none is given (neither with
    ``--slurm-no-account``).

    ``settings``: the executor's settings (``status_command``, ``no_account``);
    ``raw_resources``: the default resources as written in the profile."""
    problems = [f"${name} is not set (the profile's {key} reads it; export it, empty if your site has none)"
                for key, raw in raw_resources.items() if isinstance(raw, str)
                for name in _VARIABLE.findall(raw) if name not in environ]
    status = getattr(settings, "status_command", None)
    needed: list[tuple[str, ...]] = [("sbatch",), ("scancel",), (status,) if status else ("sacct", "squeue")]
    account = raw_resources.get("slurm_account")
    account = _VARIABLE.sub(lambda m: environ.get(m.group(1), m.group(0)), str(account or ""))
    if not getattr(settings, "no_account", False):
        needed.append(("sacctmgr", "sshare") if account.strip() and "$" not in account else ("sacct",))
    missing: list[tuple[str, ...]] = []
    for commands in dict.fromkeys(needed):
        if not any(which(c) for c in commands) and not any(set(commands) <= set(m) for m in missing):
            missing.append(commands)
    if missing:
        problems.append(f"not on PATH: {', '.join(' or '.join(c) for c in missing)}")
    return problems
