"""On-disk cache of the compiled model kernels, keyed by what they are compiled from.

A model's kernels are closures over the model's dispatchers and compile-time constants
(:mod:`.rhs`, :mod:`.ensemble`).  numba's own ``cache=True`` keys a closure on a pickle of its
cell contents; a dispatcher pickles with a per-process random id, so that key never
repeats and the cache never hits.  Here a kernel gets an explicit key instead:

* the library: the text of every stabdae module and numba's version;
* the model: for each of its functions the qualified name and the SHA-256 of the source
  file that defines it (so editing a model file, or any function in it, recompiles), and
  the sizes ``n, m, k``;
* the kernel's own compile-time choices (law kind, user law function, stage count, block).

Functions defined without a source file (an interactive session) have no fingerprint;
their kernels are compiled as before and not cached.  A change in a helper function that a
model function calls *from another file* is not seen (as with numba's own cache): clear the
cache (:func:`clear`) after editing such a helper.

The cache lives in ``$STABDAE_CACHE_DIR``, else ``$NUMBA_CACHE_DIR/stabdae``, else
``~/.cache/stabdae`` (``$XDG_CACHE_HOME`` honoured); ``STABDAE_CACHE_DIR=off`` disables it.
Entries are written with numba's machinery (temporary file, then rename), so concurrent
processes are safe.
"""

from __future__ import annotations

import hashlib
import inspect
import os
import shutil
import sys
import warnings
from functools import cache
from pathlib import Path

import numba
import numpy as np
from numba.core.caching import (
    CompileResultCacheImpl,
    FunctionCache,
    IndexDataCacheFile,
    _CacheLocator,
)

from .fma import HOST_FMA
from .jit import JIT

__all__ = ["cache_dir", "clear", "fingerprint", "function_fingerprint", "kernel_key", "keyed_cache",
           "library_fingerprint",
           "memo", "tag"]


def memo(model, key: tuple, build):
    """``build()`` once per model and ``key``, kept on the model: every kernel factory
    returns new closures, and every new closure is a new compilation."""
    store = model._kernel_cache
    if key not in store:
        store[key] = build()
    return store[key]


def cache_dir() -> Path | None:
    """Folder of the kernel cache, or ``None`` when caching is switched off."""
    explicit = os.environ.get("STABDAE_CACHE_DIR")
    if explicit is not None:
        if explicit.strip().lower() in ("", "0", "off", "none", "false"):
            return None
        return Path(explicit).expanduser()
    numba_dir = os.environ.get("NUMBA_CACHE_DIR")
    if numba_dir:
        return Path(numba_dir).expanduser() / "stabdae"
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base).expanduser() / "stabdae"


def clear() -> None:
    """Remove every cached kernel."""
    path = cache_dir()
    if path is not None and path.is_dir():
        shutil.rmtree(path / "kernels", ignore_errors=True)


@cache
def library_fingerprint() -> str:
    # the library's multiply-adds compile differently without FMA (.fma)
    text = f"numba {numba.__version__} py {sys.version_info[:2]} fma {HOST_FMA}"
    h = hashlib.sha256(text.encode())
    package = Path(__file__).resolve().parents[1]
    for path in sorted(package.rglob("*.py")):
        if path.relative_to(package).parts[0] == "scenes":  # the models are keyed apart
            continue
        h.update(path.relative_to(package).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()


@cache
def _file_digest(path: str, mtime: float, size: int) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def function_fingerprint(fn) -> str | None:
    """``module.qualname:line@sha256(source file)`` of a dispatcher or Python function, with
    the values it closes over; ``None`` when it has no source file or closes over something
    other than numbers, strings, arrays or other fingerprintable functions."""
    py_func = getattr(fn, "py_func", fn)
    try:
        path = inspect.getfile(py_func)
        st = os.stat(path)
        code = py_func.__code__
    except (TypeError, OSError, AttributeError):
        return None
    out = (f"{py_func.__module__}.{py_func.__qualname__}:{code.co_firstlineno}"
           f"@{_file_digest(path, st.st_mtime, st.st_size)}")  # fmt: skip
    cells = []
    for cell in py_func.__closure__ or ():
        value = _value_fingerprint(cell.cell_contents)
        if value is None:
            return None
        cells.append(value)
    return out + (f"[{','.join(cells)}]" if cells else "")


def _value_fingerprint(value) -> str | None:
    if value is None or isinstance(value, (bool, int, float, complex, str, bytes)):
        return f"{type(value).__name__}:{value!r}"
    if isinstance(value, np.ndarray):
        digest = hashlib.sha256(np.ascontiguousarray(value).tobytes()).hexdigest()
        return f"array:{value.dtype.str}:{value.shape}:{digest}"
    if isinstance(value, tuple):
        parts = [_value_fingerprint(v) for v in value]
        return None if None in parts else f"({','.join(parts)})"
    if callable(value):
        return function_fingerprint(value)
    return None


def fingerprint(*parts) -> str | None:
    """A key made of the library fingerprint and ``parts`` (strings, numbers, ``None`` for
    an absent piece); ``None`` if any part is :data:`UNKNOWN`."""
    if _has_unknown(parts):
        return None
    h = hashlib.sha256(library_fingerprint().encode())
    for part in parts:
        h.update(b"\x00" + repr(part).encode())
    return h.hexdigest()


def _has_unknown(part) -> bool:
    if part is UNKNOWN:
        return True
    return isinstance(part, tuple) and any(_has_unknown(p) for p in part)


def kernel_key(base: str | None, *parts) -> str | None:
    """The key of a kernel built on kernels keyed ``base`` (``None`` stays ``None``)."""
    return None if base is None else fingerprint(base, *parts)


class _Unknown:
    def __repr__(self):
        return "UNKNOWN"


#: marks a part without a fingerprint (a function without a source file)
UNKNOWN = _Unknown()


def optional_fingerprint(fn):
    """Fingerprint of an optional function for :func:`fingerprint` (``None`` when absent,
    :data:`UNKNOWN` when it has no source file)."""
    if fn is None:
        return None
    out = function_fingerprint(fn)
    return UNKNOWN if out is None else out


class _KeyedLocator(_CacheLocator):
    def __init__(self, py_func, key: str, path: Path):
        self._py_file = inspect.getfile(py_func)
        self._lineno = py_func.__code__.co_firstlineno
        self._key = key
        self._path = path

    def get_cache_path(self):
        return str(self._path)

    def get_source_stamp(self):
        return self._key

    def get_disambiguator(self):
        return self._key[:24]

    @classmethod
    def from_function(cls, py_func, py_file):  # only built explicitly
        return None


class _KeyedImpl(CompileResultCacheImpl):
    def __init__(self, py_func, locator):  # noqa: D107 (no locator search)
        self._lineno = py_func.__code__.co_firstlineno
        self._locator = locator
        modname = os.path.splitext(os.path.basename(inspect.getfile(py_func)))[0]
        fullname = f"{modname}.{py_func.__qualname__}"
        self._filename_base = self.get_filename_base(fullname, getattr(sys, "abiflags", ""))


class _KeyedCache(FunctionCache):
    """numba's function cache with an explicit key in place of the closure pickle."""

    def __init__(self, py_func, key: str, path: Path):  # noqa: D107
        self._name = repr(py_func)
        self._py_func = py_func
        self._impl = _KeyedImpl(py_func, _KeyedLocator(py_func, key, path))
        self._cache_path = str(path)
        self._key = key
        self._cache_file = IndexDataCacheFile(
            cache_path=self._cache_path,
            filename_base=self._impl.filename_base,
            source_stamp=key,
        )
        self.enable()

    def _index_key(self, sig, codegen):
        return (sig, codegen.magic_tuple(), self._key)


def tag(key: str | None, *dispatchers) -> None:
    """Make the compiled symbol names of closures unique to ``key``.

    numba names a compiled function after its qualified name and a per-process counter.
    Two closures of the same qualified name (the same kernel built for two models),
    compiled in two processes, can therefore get the same symbol, and once both are loaded
    from the cache into one process a call may resolve to the other model's code (seen:
    the double pendulum's ensemble running the pendulum's energy function).  Appending the
    kernel key to the qualified name of every closure that is compiled on its own rules
    that out.  Must run before the first compilation.
    """
    if key is None:
        return
    for d in dispatchers:
        py_func = getattr(d, "py_func", d)
        suffix = f"_{key[:16]}"
        if not py_func.__qualname__.endswith(suffix):
            py_func.__qualname__ += suffix


def keyed_cache(dispatcher, key: str | None):
    """Give ``dispatcher`` an on-disk cache under ``key`` (no-op for ``key=None`` or when
    caching is off); returns the dispatcher."""
    tag(key, dispatcher)
    path = cache_dir()
    if key is None or path is None or not JIT:
        return dispatcher
    try:
        dispatcher._cache = _KeyedCache(dispatcher.py_func, key, path / "kernels")
    except Exception as exc:  # numba internals changed: compile without a cache
        warnings.warn(f"stabdae: kernel cache unavailable ({exc!r}); compiling in memory",
                      RuntimeWarning, stacklevel=2)  # fmt: skip
    return dispatcher
