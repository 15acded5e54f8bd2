"""On-disk cache of the compiled model kernels, keyed by what they are compiled from.

A model's kernels are closures over the model's dispatchers and compile-time constants
(:mod:`.rhs`, :mod:`.ensemble`).  numba's own ``cache=True`` keys a closure on a pickle of its
cell contents; a dispatcher pickles with a per-process random id, so that key never
repeats and the cache never hits.  Here a kernel gets an explicit key instead:

* the library: the text of every stabdae module and numba's version;
* the model: for each of its functions the qualified name and the SHA-256 of the source
  file that defines it (so editing a model file, or any function in it, recompiles), the
  values of what it closes over, of the globals and module attributes it reads (numba
  freezes them into the code), the same for every function it calls wherever that lives,
  and the sizes ``n, m, k``;
* the kernel's own compile-time choices, one :class:`Spec` per factory (law kind, user law
  function, scheme pattern, block, …): the same object is the memo key on the model.

Functions defined without a source file (an interactive session), or reading a value that
has none (an arbitrary object), have no fingerprint; their kernels are compiled as before
and not cached.

The cache lives in ``$STABDAE_CACHE_DIR``, else ``$NUMBA_CACHE_DIR/stabdae``, else
``~/.cache/stabdae`` (``$XDG_CACHE_HOME`` honoured); ``STABDAE_CACHE_DIR=off`` disables it.
Entries are written with numba's machinery (temporary file, then rename), so concurrent
processes are safe.  Each compiled entry is headed by the key of the kernel it belongs to
and a SHA-256 checksum: a damaged entry, or another kernel's put in its place, is compiled
again (one warning naming the file), never run.
"""

from __future__ import annotations

import dataclasses
import hashlib
import inspect
import os
import shutil
import sys
import types
import warnings
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numba
import numpy as np

from .checked_cache import (
    CACHING_API,
    CompileResultCacheImpl,
    FunctionCache,
    _CacheLocator,
    _CheckedCacheFile,
)

from .fma import HOST_FMA
from .jit import JIT

__all__ = ["Spec", "cache_dir", "clear", "fingerprint", "function_fingerprint", "keyed_cache",
           "library_fingerprint", "memo", "tag"]  # fmt: skip


@dataclass(frozen=True)
class Spec:
    """What a compiled piece is built from besides the model: one object that is both
    its memo key on the model (:func:`memo`) and, with the model's fingerprint, its
    on-disk key (:meth:`key`).  A factory lists its compile-time choices here once.

    ``law_fn`` (the user's law function, or None) is compared by identity in the memo and
    keyed by its fingerprint on disk; every other field is a plain value."""

    kind: str  #: which factory: "rhs", "stepper", "block", "lanes", …
    law: int = -1  #: the law kind (:class:`stabdae._codes.LawKind`; −1: none)
    law_fn: object = None
    multiplier: str = "ldl"  #: "ldl" or "lstsq"
    pattern: tuple = ()  #: the scheme's (or pair's) pattern of nonzero coefficients
    stages: tuple = ()  #: stage counts (a pair's: s and the error estimate's)
    combined: bool = False  #: a pair's combined error norm (DOP853)
    block: int = 0  #: members per block, or lanes
    n_params: int = 0
    law_shape: tuple = ()
    pooled: int = -1  #: the decay measurement's pooled constraints (−1: the full map)
    sparse: bool = False  #: the sparse path of the right-hand side

    def key(self, base: str | None, *parts) -> str | None:
        """The on-disk key of this piece for a model (or pieces) keyed ``base``, and
        ``parts`` (one factory's several kernels: a name each); None (not cached) where
        ``base`` is None or the law function has no source file."""
        if base is None:
            return None
        fields = tuple((f.name, optional_fingerprint(self.law_fn) if f.name == "law_fn"
                        else getattr(self, f.name)) for f in dataclasses.fields(self))  # fmt: skip
        return fingerprint(base, fields, *parts)


def memo(model, spec: Spec, build):
    """``build()`` once per model and ``spec``, kept on the model: every kernel factory
    returns new closures, and every new closure is a new compilation."""
    store = model._kernel_cache
    if spec not in store:
        store[spec] = build()
    return store[spec]


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


def function_fingerprint(fn, _seen=None) -> str | None:
    """``module.qualname:line@sha256(source file)`` of a dispatcher or Python function, with
    the values it closes over and the globals it reads (numbers, strings, arrays: numba
    freezes them into the compiled code; functions: their own fingerprints, so that a
    helper in another file is keyed by that file).  ``None`` when it has no source file or
    reads something that has no fingerprint."""
    py_func = getattr(fn, "py_func", fn)
    try:
        path = inspect.getfile(py_func)
        st = os.stat(path)
        code = py_func.__code__
    except (TypeError, OSError, AttributeError):
        return None
    seen = set() if _seen is None else _seen
    if id(py_func) in seen:  # recursion: the function itself is already being keyed
        return f"{py_func.__module__}.{py_func.__qualname__}"
    seen.add(id(py_func))
    out = (f"{py_func.__module__}.{py_func.__qualname__}:{code.co_firstlineno}"
           f"@{_file_digest(path, st.st_mtime, st.st_size)}")  # fmt: skip
    reads = _global_names(code)  # globals and attribute names alike
    cells = []
    for cell in py_func.__closure__ or ():
        value = _value_fingerprint(cell.cell_contents, seen, reads)
        if value is None:
            return None
        cells.append(value)
    names = []
    for name in sorted(reads):
        if name not in py_func.__globals__:
            continue  # a builtin, or an attribute name
        value = _value_fingerprint(py_func.__globals__[name], seen, reads)
        if value is None:
            return None
        names.append(f"{name}={value}")
    return (out + (f"[{','.join(cells)}]" if cells else "")
            + (f"{{{','.join(names)}}}" if names else ""))  # fmt: skip


def _global_names(code) -> set[str]:
    names = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            names |= _global_names(const)
    return names


#: modules whose functions are keyed by name (their versions change with the library's)
_LIBRARY_MODULES = ("math", "cmath", "numpy", "numba", "scipy", "stabdae", "builtins")


def _value_fingerprint(value, seen=None, reads=frozenset()) -> str | None:
    if value is None or isinstance(value, (bool, int, float, complex, str, bytes)):
        return f"{type(value).__name__}:{value!r}"
    if isinstance(value, np.ndarray):
        digest = hashlib.sha256(np.ascontiguousarray(value).tobytes()).hexdigest()
        return f"array:{value.dtype.str}:{value.shape}:{digest}"
    if isinstance(value, np.generic):
        return f"{type(value).__name__}:{value!r}"
    if isinstance(value, tuple):
        parts = [_value_fingerprint(v, seen) for v in value]
        return None if None in parts else f"({','.join(parts)})"
    if isinstance(value, types.ModuleType):
        return _module_fingerprint(value, seen, reads)
    module = getattr(value, "__module__", None) or ""
    if callable(value) and module.split(".")[0] in _LIBRARY_MODULES:
        return f"function:{module}.{getattr(value, '__qualname__', repr(value))}"
    if isinstance(value, np.ufunc):
        return f"ufunc:{value.__name__}"
    if callable(value):
        return function_fingerprint(value, seen)
    return None


def _module_fingerprint(module, seen, reads) -> str | None:
    """A module a function reads attributes of (``consts.G``): numba freezes those values
    into the compiled code like globals, so the attributes named in the function's code
    are keyed by value (modules of the library by name).  ``reads`` holds every name the
    code uses; those that are not the module's attributes are left out."""
    name = getattr(module, "__name__", "?")
    if name.split(".")[0] in _LIBRARY_MODULES:
        return f"module:{name}"
    seen = set() if seen is None else seen
    if id(module) in seen:  # modules that import each other
        return f"module:{name}"
    seen.add(id(module))
    attrs = []
    for attr in sorted(reads):
        if attr in vars(module):
            value = _value_fingerprint(vars(module)[attr], seen, reads)
            if value is None:
                return None
            attrs.append(f"{attr}={value}")
    seen.discard(id(module))  # read again through another path: keyed again
    return f"module:{name}" + (f"{{{','.join(attrs)}}}" if attrs else "")


def fingerprint(*parts) -> str | None:
    """A key made of the library fingerprint and ``parts`` (strings, numbers, ``None`` for
    an absent piece); ``None`` if any part is :data:`UNKNOWN`."""
    if _has_unknown(parts):
        return None
    h = hashlib.sha256(library_fingerprint().encode())
    # NUMBA_BOUNDSCHECK=1 compiles checked kernels: an unchecked one from the cache would
    # defeat the run that asked for the checks (read here: it may be set at run time)
    h.update(f"boundscheck {bool(numba.config.BOUNDSCHECK)}".encode())
    for part in parts:
        h.update(b"\x00" + repr(part).encode())
    return h.hexdigest()


def _has_unknown(part) -> bool:
    if part is UNKNOWN:
        return True
    return isinstance(part, tuple) and any(_has_unknown(p) for p in part)


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
        self._cache_file = _CheckedCacheFile(
            cache_path=self._cache_path,
            filename_base=self._impl.filename_base,
            source_stamp=key,
        )
        self.enable()

    def _index_key(self, sig, codegen):
        return (sig, codegen.magic_tuple(), self._key)

    def load_overload(self, sig, target_context):
        """The cached kernel, or None (compile it) when the entry cannot be loaded: a
        truncated file, another numba, a kernel whose model module cannot be imported."""
        try:
            return super().load_overload(sig, target_context)
        except Exception as exc:
            _warn_once(f"a cached kernel could not be loaded ({type(exc).__name__}: {exc}); "
                       "compiling it again",
                       key=f"{self._cache_path}/{self._impl.filename_base}")  # fmt: skip
            return None

    def save_overload(self, sig, data):
        """Store the kernel; a cache folder that cannot be written (read-only, full, a
        file in its place) costs the next process a compilation, nothing else."""
        try:
            super().save_overload(sig, data)
        except Exception as exc:
            _warn_once(f"a kernel could not be written to the cache {self._cache_path} "
                       f"({type(exc).__name__}: {exc}); it runs, compiled in memory")  # fmt: skip


_WARNED: set[str] = set()


def _warn_once(message: str, key: str | None = None) -> None:
    """Warn once per ``key`` (default: the message's kind, its text before " ("): a
    damaged entry is named once, not at every call that finds it."""
    kind = key or message.split(" (", 1)[0]
    if kind not in _WARNED:
        _WARNED.add(kind)
        warnings.warn(f"stabdae: {message}", RuntimeWarning, stacklevel=3)




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
    if not CACHING_API:
        _warn_once("kernel cache unavailable (this numba has no numba.core.caching); "
                   "compiling in memory")  # fmt: skip
        return dispatcher
    try:
        dispatcher._cache = _KeyedCache(dispatcher.py_func, key, path / "kernels")
    except Exception as exc:  # numba internals changed, or the folder is unusable
        _warn_once(f"kernel cache unavailable ({type(exc).__name__}: {exc}); compiling in "
                   "memory")  # fmt: skip
    return dispatcher
