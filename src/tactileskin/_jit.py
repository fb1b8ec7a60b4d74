"""numba.njit for the compiled modules (fe._kernels_nb, fe._sparse_nb, materials._prony_nb,
materials._hyperfoam_nb): the on-disk cache when numba can place one, in-memory compilation
otherwise.

numba's cache=True raises "no locator available" at decoration time (so at import) when none
of its cache folders is writable: the package's __pycache__, ~/.cache/numba, NUMBA_CACHE_DIR.
A read-only install (a container, site-packages owned by root, HOME unwritable) could then not
import the solver at all. Here such a module compiles without the cache (each process pays the
compile time again) and one log line says so and how to keep it.
"""

from __future__ import annotations

import functools
import inspect
import logging

import numba

log = logging.getLogger(__name__)


_usable: dict[str, bool] = {}


def _cache_usable(py_func) -> bool:
    """True if numba finds a writable cache folder for py_func: the same FunctionCache that
    njit(cache=True) builds, so the same condition. numba picks the folder from the source
    file alone, so one probe per file."""
    from numba.core.caching import FunctionCache

    source = inspect.getfile(py_func)
    if source not in _usable:
        try:
            FunctionCache(py_func)
            _usable[source] = True
        except RuntimeError as e:
            if "no locator available" not in str(e):
                raise
            _note_once()
            _usable[source] = False
    return _usable[source]


@functools.lru_cache(maxsize=None)
def _note_once() -> None:
    log.warning("numba has no writable cache folder (the package's __pycache__, ~/.cache/numba, "
                "NUMBA_CACHE_DIR): compiling the solver kernels in memory, again in every process; "
                "set NUMBA_CACHE_DIR to a writable folder to keep them")


def njit(*signatures, **options):
    """A decorator like numba.njit(*signatures, **options) (always called with arguments);
    cache=True falls back to cache=False where numba cannot place its cache."""
    def decorate(py_func):
        opts = dict(options)
        if opts.get("cache") and not _cache_usable(py_func):
            opts["cache"] = False
        return numba.njit(*signatures, **opts)(py_func)
    return decorate
