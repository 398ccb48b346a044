"""The set-up after installation: what every job would otherwise build again, built once.

    python -m synergrasp.warm_up STEP [STEP ...]

Steps, in the order given, in one process:

- ``kernel``: the interior-point kernel's machine code (`optimisation.gfo.warm_up`);
- ``closure``: the kinematic closure's distance queries and steps (`simulation.closure.warm_up`);
- ``imports``: every module of the package compiled, the libraries it imports and the Snakemake
  modules that a job's script and the ``snakemake`` command load imported once.

Every step writes the bytecode of the modules it imports, even where ``PYTHONDONTWRITEBYTECODE``
is set (as CI images often set it): otherwise every job would compile from source each module
it imports (docs/measurements.md). The bytecode is written for what the
workflow imports, not for every installed file: compiling all of them costs more than the rest
of the installation. ``make venv`` runs the three steps in three processes while it installs:
the kernel's, the longest, as soon as what it imports is installed; ``make warm-up`` (run
first by ``make study`` and ``make test``) runs the two compiles again, which load their cache
unless their sources changed.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence

__all__ = ["STEPS", "main"]


def _kernel() -> None:
    from synergrasp.optimisation.gfo import warm_up

    warm_up()


def _closure() -> None:
    from synergrasp.simulation.closure import warm_up

    warm_up()


def _imports() -> None:
    import compileall

    import synergrasp
    from synergrasp.snakemake_adapter import load_snakemake_modules

    compileall.compile_dir(synergrasp.__path__[0], quiet=1)  # the package's modules, without running them
    # The libraries the package's modules import, and what they import in turn
    # (tests/test_warm_up.py: every module a workflow script loads then has its bytecode).
    import clarabel  # noqa: F401
    import cvxpy  # noqa: F401
    import jsonschema  # noqa: F401
    import matplotlib.pyplot  # noqa: F401
    import mujoco  # noqa: F401
    import numba  # noqa: F401
    import pandas  # noqa: F401
    import piqp  # noqa: F401
    import plotly.io  # noqa: F401
    import plotly.offline  # noqa: F401
    import pyarrow.parquet  # noqa: F401
    import pybullet  # noqa: F401
    import scipy.linalg  # noqa: F401
    import scipy.optimize  # noqa: F401
    import scipy.sparse.csgraph  # noqa: F401
    import scipy.spatial.transform  # noqa: F401
    import yaml  # noqa: F401

    load_snakemake_modules()


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
    for step in steps:
        STEPS[step]()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
