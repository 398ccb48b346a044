"""How the kernel is compiled (numba) and where its machine code is cached.

Three kinds of compiled function:

- `jit_alloc`: functions that allocate or return arrays, with numba's reference counting;
- `jit_call`: the iteration's larger steps, without reference counting (`_nrt=False`: with
  it, every slice, argument and tuple field taken in a loop costs an atomic increment and
  decrement, about half of the iteration's time), each compiled once and called;
- `jit_inline`: small steps inlined into their callers (numba's IR inlining), without
  reference counting. Inlining removes the call (the work arrays travel as a tuple of ~40
  arrays), but every inlined copy is typed and optimised again: a function called from
  several places, and the functions inlined into it, multiply the compile time. So only
  the cone algebra, the matrix products and the steps called from one place are inlined;
  the Newton solve and the direction are called. The arithmetic and its order are the same
  either way (no `fastmath`: IEEE arithmetic in program order).

Two costs of numba's compile shape the call graph: a called function's machine code is
optimised and generated again in every compiled function that calls it (numba links the
callee's code into the caller's), so each level of called functions above `hsde` compiles the
whole iteration once more; and typing grows faster than a function's size, so `hsde` itself
is called, never inlined (inlined into the per-set loop, the compile takes several times as
long). Hence one call site for each step that is inlined (`direction` and `max_step` in a
predictor-corrector loop, `reduced` in the refinement loop, the set loop's one `solve_one`).

The cache: the kernel's modules (`KERNEL_SOURCES`) are one compiled group
(`synergrasp.compiled_cache`), cached per user in ``synergrasp-ipm/<hash of their sources>``
(`cache_dir()`), so any checkout of the same kernel, in any path, loads the same machine code
and a change to any of its modules compiles afresh.
"""

from __future__ import annotations

import numba

from synergrasp.compiled_cache import register_group

__all__ = ["KERNEL_SOURCES", "KERNEL", "cache_dir", "jit_alloc", "jit_call", "jit_inline"]

#: The modules whose compiled code one cache directory holds (callers embed their callees).
KERNEL_SOURCES = (
    "compiled.py",
    "layout.py",
    "cone_algebra.py",
    "linear_systems.py",
    "certificates.py",
    "polish.py",
    "iteration.py",
    "sets.py",
)

#: The kernel's compiled group; registered before any of its modules defines a function.
KERNEL = register_group("ipm", [f"optimisation/ipm/{name}" for name in KERNEL_SOURCES])
cache_dir = KERNEL.cache_dir

jit_alloc = numba.njit(cache=True, nogil=True, error_model="numpy")
jit_call = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
jit_inline = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False, inline="always")
