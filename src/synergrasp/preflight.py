"""Checks the workflow runs before any job besides the configuration's own (``config``): the
YAML files Snakemake reads itself and the scheduler behind the cluster profile. Each problem
is one line naming the file, the key, the command or the variable; :func:`refuse` stops the
run with those lines alone. What the workflow needs of Snakemake's internals is in
``synergrasp.snakemake_adapter``. Imports nothing of the project but ``yaml_io``.
"""

from __future__ import annotations

import os
import re
import shutil
import sys
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from synergrasp.yaml_io import YamlFileError, read_yaml

__all__ = ["configfile_problems", "slurm_problems", "refuse"]

#: The first line of every refusal before any job.
REFUSED = "Invalid input, nothing was run:"


def refuse(problems: Iterable[str]) -> None:
    """If there is any problem: stop the workflow before any job with one line per problem
    (after :data:`REFUSED`) and exit status 1; nothing else, no traceback of the workflow's
    own frames (Snakemake prints those for an exception raised while it parses the workflow
    or plans a target). Nothing if ``problems`` is empty."""
    lines = list(problems)
    if lines:
        print("\n".join([REFUSED, *lines]), file=sys.stderr, flush=True)
        raise SystemExit(1)


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


_VARIABLE = re.compile(r"\$\{?([A-Za-z_][A-Za-z0-9_]*)\}?")


def slurm_problems(
    settings: Any,
    raw_resources: Mapping[str, Any],
    environ: Mapping[str, str] = os.environ,
    which: Callable[[str], str | None] = shutil.which,
) -> list[str]:
    """What keeps the SLURM executor from submitting from this shell, one item per problem:
    a variable the profile's default resources read (``$SBATCH_ACCOUNT``) that is not set,
    and each scheduler command the executor will call that is not on PATH: ``sbatch`` and
    ``scancel``; the status command (``sacct`` or ``squeue``); ``sacctmgr`` or ``sshare``
    to validate a given account, ``sacct`` to guess one when none is given (neither with
    ``--slurm-no-account``).

    ``settings``: the executor's settings (``status_command``, ``no_account``);
    ``raw_resources``: the default resources as written in the profile."""
    problems = [
        f"${name} is not set (the profile's {key} reads it; export it, empty if your site has none)"
        for key, raw in raw_resources.items()
        if isinstance(raw, str)
        for name in _VARIABLE.findall(raw)
        if name not in environ
    ]
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
