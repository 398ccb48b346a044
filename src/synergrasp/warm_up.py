"""The set-up after installation: what every job would otherwise build again, built once.

    python -m synergrasp.warm_up STEP [STEP ...]

Steps, in the order given, in one process:

- ``kernel``: the interior-point kernel's machine code (`optimisation.gfo.warm_up`);
- ``closure``: the kinematic closure's distance queries and steps (`simulation.closure.warm_up`);
- ``imports``: every module of the package, and the Snakemake modules that a job's script and
  the ``snakemake`` command load, imported once.

Every step writes the bytecode of the modules it imports, even where ``PYTHONDONTWRITEBYTECODE``
is set (as CI images often set it): otherwise every job would compile from source each module
it imports (0.7 CPU s a job, docs/measurements.md). The bytecode is written for what the
workflow imports, not for every installed file: compiling all of them costs more than the rest
of the installation. ``make warm-up`` (run first by ``make study`` and ``make test``) runs the
three steps in three processes side by side, the kernel's, the longest, ahead of the others.
"""

from __future__ import annotations

import importlib
import os
import pkgutil
import sys
from collections.abc import Callable, Sequence

__all__ = ["STEPS", "main"]

#: The Snakemake modules a job loads (its script's preamble and the job object it unpickles)
#: and those the ``snakemake`` command loads.
SNAKEMAKE_MODULES = ("snakemake.script", "snakemake.io", "snakemake.cli")


def _kernel() -> None:
    from synergrasp.optimisation.gfo import warm_up

    warm_up()


def _closure() -> None:
    from synergrasp.simulation.closure import warm_up

    warm_up()


def _imports() -> None:
    import compileall

    import synergrasp

    # the package's own modules first: those imported before this step started too
    compileall.compile_dir(synergrasp.__path__[0], quiet=1)
    names = [info.name for info in pkgutil.walk_packages(synergrasp.__path__, "synergrasp.")]
    for name in (*names, *SNAKEMAKE_MODULES):
        importlib.import_module(name)


#: The steps by name.
STEPS: dict[str, Callable[[], None]] = {"kernel": _kernel, "closure": _closure, "imports": _imports}


def main(argv: Sequence[str] | None = None) -> int:
    steps = list(sys.argv[1:] if argv is None else argv)
    unknown = [step for step in steps if step not in STEPS]
    if not steps or unknown:
        names = ", ".join(STEPS)
        problem = f"unknown step {', '.join(unknown)}" if unknown else "no step named"
        print(f"synergrasp.warm_up: {problem}; the steps are {names}", file=sys.stderr)
        return 2
    sys.dont_write_bytecode = False
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)  # and in the processes the steps start
    for step in steps:
        STEPS[step]()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
