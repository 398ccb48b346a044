"""How the closure's distance queries are compiled (numba) and where their machine code is cached.

The shapes' segment queries (`kernels`, `polytope`, `polytope_axes`) and the hand's capsules
(`synergrasp.simulation.capsules`, whose compiled functions call them) are one compiled group
(`synergrasp.compiled_cache`): cached per user in ``synergrasp-shapes/<hash of their sources>``
(`GROUP.cache_dir()`), so a change to any of these modules compiles all of them afresh (numba
alone would keep a caller's copy of a changed callee) and any checkout of the same sources, in
any path, loads the same machine code.
"""

from __future__ import annotations

import numba

from synergrasp.compiled_cache import register_group

__all__ = ["SOURCES", "GROUP", "jit", "jit_inline"]

#: The modules whose compiled functions call one another (relative to the package).
SOURCES = (
    "simulation/shapes/compiled.py",
    "simulation/shapes/kernels.py",
    "simulation/shapes/polytope.py",
    "simulation/shapes/polytope_axes.py",
    "simulation/capsules.py",
    "simulation/closure_march.py",
)

#: The group; registered before any of its modules defines a function.
GROUP = register_group("shapes", SOURCES)

jit = numba.njit(cache=True)
#: For the free steps' helpers (`closure_march`), called from compiled code only. numba optimises
#: and generates a called function's code again in every compiled caller, so each level of calls
#: above the distance queries compiles them once more; an inlined helper (numba's IR inlining:
#: the same operations in the same order) is typed in its caller and its level is gone. The
#: distance queries stay called: Python calls them too, and each inlined copy is typed again.
jit_inline = numba.njit(cache=True, inline="always")
