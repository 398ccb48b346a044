"""Checks the workflow runs before any job besides the configuration's own (``config``): the
YAML files Snakemake reads itself, the scheduler behind the cluster profile, and the size of the
group jobs the profile submits against the partition's nodes. Each problem is one line naming
the file, the key, the command or the variable; :func:`refuse` stops the run with those lines
alone. What the workflow needs of Snakemake's internals is in
``synergrasp.snakemake_adapter``. Imports nothing of the project but ``yaml_io``.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from synergrasp.yaml_io import YamlFileError, read_yaml

__all__ = ["configfile_problems", "slurm_problems", "group_problems", "partition_nodes", "refuse"]

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


def partition_nodes(partition: str, run: Callable[..., Any] = subprocess.run) -> list[tuple[int, int]] | str:
    """The nodes of SLURM partition ``partition`` (the default partition if empty) as ``sinfo``
    reports them: (CPUs, memory in MB) of each kind of node; or, when sinfo cannot tell, the
    one line saying why. A value sinfo marks ``+`` (nodes of one line differing) is read as
    its smallest."""
    command = ["sinfo", "--noheader", "--format=%c %m", *(["--partition", partition] if partition else [])]
    try:
        done = run(command, capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.SubprocessError) as err:
        return f"{' '.join(command)} could not run ({err})"
    if done.returncode != 0:
        said = (done.stderr or "").strip().splitlines()  # sinfo's last line says why
        return f"{' '.join(command)} failed: {said[-1] if said else f'exit status {done.returncode}'}"
    nodes = []
    for line in done.stdout.splitlines():
        fields = line.replace("+", "").split()
        if len(fields) == 2 and all(f.isdigit() for f in fields):
            nodes.append((int(fields[0]), int(fields[1])))
    return nodes or f"{' '.join(command)} lists no node"


def group_problems(
    groups: Mapping[str, str],
    cores: int | None,
    mem_mb: int | None,
    requests: Iterable[tuple[str, int]],
    raw_resources: Mapping[str, Any],
    environ: Mapping[str, str] = os.environ,
    nodes_of: Callable[[str], list[tuple[int, int]] | str] = partition_nodes,
) -> list[str]:
    """What would make a cluster job ask for more than one node has, one item per problem,
    before any job (docs/cluster.md, "Job groups").

    Snakemake lays the jobs of a group side by side within ``--cores`` (``cores``, CPUs) and
    ``--resources mem_mb`` (``mem_mb``, MB), the rest one after another, so a group job asks for
    at most those; without them it asks for all its jobs side by side. Problems: a grouping
    (``groups``: rule -> group) without either limit; limits that no node of the profile's
    partition (``slurm_partition`` of ``raw_resources``, its variables read from ``environ``)
    holds both of, as ``nodes_of`` (sinfo) reports them; a job asking for more memory than
    ``mem_mb``, which Snakemake would refuse only when the job is ready to run (the jobs run
    where Snakemake runs count against ``mem_mb`` too). ``requests``: (rule, memory request of
    one job in MB) of every job the run may start, one line per rule at its largest request."""
    problems = []
    if groups:
        grouped = ", ".join(sorted(groups))
        if cores is None:
            problems.append(
                f"groups ({grouped}) without cores: a group job would ask for the CPUs of all its jobs side by side; "
                "set cores (--cores N) to a node's CPUs"
            )
        if mem_mb is None:
            problems.append(
                f"groups ({grouped}) without resources mem_mb: a group job would ask for the memory of all its jobs "
                "side by side; set it (--resources mem_mb=M) to a node's memory in MB"
            )
        if cores is not None and mem_mb is not None:
            partition = _VARIABLE.sub(lambda m: environ.get(m.group(1), ""), str(raw_resources.get("slurm_partition") or ""))
            nodes = nodes_of(partition.strip())
            where = f"partition '{partition.strip()}'" if partition.strip() else "the default partition"
            if isinstance(nodes, str):
                problems.append(
                    f"the size of a node of {where} cannot be read, so a group job cannot be checked to fit one: {nodes}"
                )
            elif not any(cpus >= cores and memory >= mem_mb for cpus, memory in nodes):
                cpus, memory = max(nodes)
                problems.append(
                    f"a group job may ask for {cores} CPUs and {mem_mb} MB (cores and resources mem_mb), more than any node "
                    f"of {where} has (sinfo: {', '.join(f'{c} CPUs {m} MB' for c, m in sorted(set(nodes)))}); "
                    f"set them to a node's size, e.g. --cores {cpus} --resources mem_mb={memory}"
                )
    if mem_mb is not None:
        largest: dict[str, int] = {}
        for rule, request in requests:
            largest[rule] = max(request, largest.get(rule, 0))
        problems += [
            f"rule {rule}: a job asks for {request} MB, more than resources mem_mb ({mem_mb} MB, the size of a node "
            f"that groups are cut to; Snakemake would refuse the job when it is ready to run): raise it to at least "
            f"{request} if a node has that much (--resources mem_mb={request})"
            for rule, request in largest.items()
            if request > mem_mb
        ]
    return problems
