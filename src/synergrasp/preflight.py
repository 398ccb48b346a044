"""Checks the workflow runs before any job besides the configuration's own (``config``): the
YAML files Snakemake reads itself, the wildcard values Snakemake's own guard must accept,
and the scheduler behind the cluster profile. Each problem is one line naming the file, the
key, the command or the variable; :func:`refuse` stops the run with those lines alone. And
how a job's outputs survive its failure (:func:`keep_outputs_until_replaced`). Imports
nothing of the project but ``yaml_io``.
"""

from __future__ import annotations

import os
import re
import shutil
import sys
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

from synergrasp.yaml_io import YamlFileError, read_yaml

__all__ = ["configfile_problems", "accept_configured_wildcards", "slurm_problems", "refuse",
           "keep_outputs_until_replaced", "outdate_failed_outputs"]

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


def keep_outputs_until_replaced(workflow: Any) -> None:
    """Keep every output of the workflow's rules until its replacement is complete.

    Snakemake deletes a job's existing outputs before the job starts and deletes what is
    there again when it fails (``Job.prepare``, ``Job.cleanup``), so a failing rerun (a
    corrupted input, a full disk) would cost finished results. Outputs flagged ``update``
    are kept instead: Snakemake copies each to ``.snakemake/backups`` before the job and
    copies it back when the job fails. The package's writers replace a file or folder only
    once its new content is complete (``synergrasp.file_output``), so an output is always its
    old or its new complete content. :func:`outdate_failed_outputs` makes the next run redo
    the outputs restored this way. Call once after every rule is defined."""
    import snakemake.persistence

    for rule in workflow.rules:
        for output in rule.output:
            flags = dict(output.flags)
            output.clone_flags(output)  # a plain name gets a flags mapping of its own (emptied)
            output.flags.update(flags, update=True)
    persistence = getattr(snakemake.persistence, "FileBackupMixin", None)  # Snakemake 9's backups
    if persistence is not None and not getattr(persistence.backup_output, "_replaces_stale", False):
        backup = persistence.backup_output

        def backup_output(self: Any, path: Path) -> None:
            # a killed run leaves its backup of a folder, which Snakemake cannot copy over
            stale = self._get_backup_path(path)
            if stale.is_dir() and path.is_dir():
                shutil.rmtree(stale)
            backup(self, path)

        backup_output._replaces_stale = True  # type: ignore[attr-defined]
        persistence.backup_output = backup_output


def outdate_failed_outputs(workflow: Any) -> list[str]:
    """After a failed run: make the next run redo each output a failed job kept
    (:func:`keep_outputs_until_replaced`). Snakemake records a failed job as finished, with
    its inputs' checksums, and would take the kept old output for the new one; so the
    record is removed (Snakemake's ``cleanup`` of a job's metadata) and the output dated one
    second before the job's newest input. Returns the paths outdated."""
    scheduler = getattr(workflow, "scheduler", None)
    outdated = []
    for job in getattr(scheduler, "failed", ()):
        inputs = [os.stat(f).st_mtime for f in job.input if os.path.exists(f)]
        if not inputs:
            continue
        workflow.persistence.cleanup(job)
        when = max(inputs) - 1.0
        for output in job.output:
            path = Path(output)
            for stamped in (path, path / ".snakemake_timestamp"):
                if stamped.exists():
                    os.utime(stamped, (when, when))
            if path.exists():
                outdated.append(str(path))
    return outdated
