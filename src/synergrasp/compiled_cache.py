"""Where numba keeps the package's compiled code: one directory per group of modules, named by their sources.

numba keys a cached function by its own file (its directory, modification time and size).
Two consequences: every new checkout path compiles again, and a compiled function keeps the
machine code of the compiled functions it calls from another module when only that module
changes (numba builds callees into their callers and does not look at the callees' files):
stale results, without an error. So the modules whose compiled functions call one another
form a *group* (`register_group`), and all its functions are cached in
``<base>/synergrasp-<group>/<hash>``: <hash> the SHA-256 of the group's sources and of this
module, <base> ``$NUMBA_CACHE_DIR`` when set, else ``$XDG_CACHE_HOME`` or ``~/.cache``. A change
to any module of the group names a new directory; any checkout of the same sources, in any
path, loads the same machine code. numba's own index keys each entry by signature, CPU model
and features and numba's version, so one directory serves several CPU models. Nothing
compiled is committed.

numba picks a function's cache locator when ``numba.njit(cache=True)`` wraps it, so a group
is registered by a module that each of its members imports before defining its functions
(``optimisation/ipm/compiled.py``, ``simulation/shapes/compiled.py``). A cache directory that
cannot be written falls back to numba's own locators (set ``NUMBA_CACHE_DIR`` instead).
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numba
from numba.core import caching

__all__ = ["CompiledGroup", "register_group", "files_digest", "sources_digest"]

#: The package directory; a group's files are named relative to it.
PACKAGE = Path(__file__).resolve().parent
_SELF = Path(__file__).name


def files_digest(names: Sequence[str], root: Path) -> str:
    """SHA-256 (hex) of the files ``names`` (paths relative to ``root``, in the order given):
    their names and bytes, not where the checkout is."""
    h = hashlib.sha256()
    for name in names:
        h.update(name.encode())
        h.update((root / name).read_bytes())
    return h.hexdigest()


def sources_digest(files: Sequence[str], root: Path = PACKAGE) -> str:
    """:func:`files_digest` of the files (relative to ``root``, the package) and of this module."""
    return files_digest((*files, _SELF), root)


@dataclass(frozen=True)
class CompiledGroup:
    """Modules whose compiled functions are cached together: ``files`` relative to the
    package, ``digest`` the SHA-256 of their sources (`sources_digest`)."""

    name: str
    files: tuple[str, ...]
    digest: str

    def cache_dir(self) -> Path:
        """The directory of the group's compiled code for these sources."""
        base = numba.config.CACHE_DIR or os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
        return Path(base) / f"synergrasp-{self.name}" / self.digest[:16]


#: Every registered group, by the resolved path of each of its files.
_GROUP_OF: dict[Path, CompiledGroup] = {}


def register_group(name: str, files: Sequence[str]) -> CompiledGroup:
    """The group ``name`` of ``files`` (relative to the package), registered so that the
    functions numba compiles with ``cache=True`` in these files from now on are cached in its
    `CompiledGroup.cache_dir`. ValueError if a file is in another group or two files share a
    name (numba names a cache entry by its file's name, not its path)."""
    names = [Path(f).name for f in files]
    if len(set(names)) != len(names):
        raise ValueError(f"compiled group {name!r}: two files with one name in {list(files)}")
    group = CompiledGroup(name, tuple(files), sources_digest(files))
    paths = [(PACKAGE / f).resolve() for f in files]
    for f, path in zip(files, paths):
        if _GROUP_OF.get(path, group) != group:
            raise ValueError(f"compiled group {name!r}: {f} is already in group {_GROUP_OF[path].name!r}")
    _GROUP_OF.update(dict.fromkeys(paths, group))
    return group


class _GroupCacheLocator(caching._CacheLocator):
    """numba cache locator for the functions of a registered group's files: the group's
    directory, its digest as the freshness stamp. Other functions are left to numba's own."""

    def __init__(self, group: CompiledGroup, lineno: int):
        self._group, self._lineno = group, lineno
        self._path = str(group.cache_dir())

    def get_cache_path(self):
        return self._path

    def get_source_stamp(self):
        return self._group.digest

    def get_disambiguator(self):
        return str(self._lineno)

    @classmethod
    def from_function(cls, py_func, py_file):
        group = _GROUP_OF.get(Path(py_file).resolve())
        if group is None:
            return None
        self = cls(group, py_func.__code__.co_firstlineno)
        try:
            self.ensure_cache_path()
        except OSError:  # not writable: numba's next locator
            return None
        return self


if _GroupCacheLocator not in caching.CacheImpl._locator_classes:
    caching.CacheImpl._locator_classes.insert(0, _GroupCacheLocator)
