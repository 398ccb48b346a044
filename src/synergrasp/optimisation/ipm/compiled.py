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

The cache. numba keys a cached function by the directory of its source, so every new
checkout compiled the kernel again. The kernel's functions are cached instead in a
directory named by the SHA-256 of the sources of this package (`KERNEL_SOURCES`): under
``$NUMBA_CACHE_DIR`` when set, else ``$XDG_CACHE_HOME`` or ``~/.cache``, in
``synergrasp-ipm/<hash>``. Any checkout of the same kernel, in any path, loads the same
machine code; a change to any of the package's modules changes the directory (numba itself
does not notice that a callee in another module changed). numba's own index keys each
entry by signature, CPU model and features and numba's version, so one directory serves
several CPU models. Nothing compiled is committed.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numba
from numba.core import caching

__all__ = ["KERNEL_SOURCES", "cache_dir", "jit_alloc", "jit_call", "jit_inline"]

#: The modules whose compiled code one cache directory holds (callers embed their callees).
KERNEL_SOURCES = ("compiled.py", "layout.py", "cone_algebra.py", "linear_systems.py", "certificates.py",
                  "polish.py", "iteration.py", "sets.py")

_PACKAGE = Path(__file__).resolve().parent


def _sources_digest() -> str:
    h = hashlib.sha256()
    for name in KERNEL_SOURCES:
        h.update(name.encode())
        h.update((_PACKAGE / name).read_bytes())
    return h.hexdigest()


_DIGEST = _sources_digest()


def cache_dir() -> Path:
    """The directory of the kernel's compiled code for these sources."""
    base = numba.config.CACHE_DIR or os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "synergrasp-ipm" / _DIGEST[:16]


class _KernelCacheLocator(caching._CacheLocator):
    """numba cache locator for the functions of this package: `cache_dir()`, the sources'
    digest as the freshness stamp. Other functions are left to numba's own locators."""

    def __init__(self, py_func, py_file):
        self._lineno = py_func.__code__.co_firstlineno
        self._path = str(cache_dir())

    def get_cache_path(self):
        return self._path

    def get_source_stamp(self):
        return _DIGEST

    def get_disambiguator(self):
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func, py_file):
        if Path(py_file).resolve().parent != _PACKAGE:
            return None
        self = cls(py_func, py_file)
        try:
            self.ensure_cache_path()
        except OSError:  # not writable: numba's next locator (next to the source)
            return None
        return self


if _KernelCacheLocator not in caching.CacheImpl._locator_classes:
    caching.CacheImpl._locator_classes.insert(0, _KernelCacheLocator)

jit_alloc = numba.njit(cache=True, nogil=True, error_model="numpy")
jit_call = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
jit_inline = numba.njit(cache=True, nogil=True, error_model="numpy", _nrt=False, inline="always")
