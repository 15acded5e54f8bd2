"""Whether the library compiles, the compiled functions it is given, and the time it
spends compiling (:func:`compile_seconds`).

With ``NUMBA_DISABLE_JIT=1`` in the environment, ``@njit`` returns the Python function
itself: a model's functions then arrive as plain functions, the library's kernels run as
Python (slowly: for stepping through a kernel in a debugger, or measuring coverage), and
the intrinsics have Python stand-ins (:mod:`.fma`, :mod:`.workspace`).
"""

from __future__ import annotations

import inspect
import threading
import time

from numba import config, njit
from numba.core import event
from numba.core.dispatcher import Dispatcher
from numba.core.registry import CPUDispatcher

__all__ = ["JIT", "compile_seconds", "from_python", "internal", "is_njit", "python_function"]

#: False when numba's JIT is switched off (``NUMBA_DISABLE_JIT=1``)
JIT = not config.DISABLE_JIT


def is_njit(fn) -> bool:
    """A numba dispatcher, or, with the JIT switched off, a plain function (what ``@njit``
    returns then)."""
    return isinstance(fn, Dispatcher) or (not JIT and inspect.isfunction(fn))


def python_function(fn):
    """The Python function behind a dispatcher (the function itself without the JIT)."""
    return getattr(fn, "py_func", fn)


def internal(**options):
    """``njit(**options)`` for a function that compiled code calls (a kernel's pieces):
    numba then builds neither its CPython nor its C wrapper, code that boxes and unboxes
    every argument (a workspace is a tuple of arrays) and goes through LLVM with the rest
    of a model's first ensemble.  A call from Python goes
    to its twin with the wrappers, compiled when first called (:func:`from_python`)."""
    decorate = njit(no_cpython_wrapper=True, no_cfunc_wrapper=True, **options)

    def make(fn):
        dispatcher = decorate(fn)
        if JIT:
            dispatcher.__class__ = _Internal
        return dispatcher

    return make


def from_python(fn):
    """``fn`` callable from Python: for a dispatcher of :func:`internal`, a twin compiled
    with the same options and its wrappers (made once); anything else as it is."""
    if not isinstance(fn, _Internal):
        return fn
    twin = fn.__dict__.get("_from_python")
    if twin is None:
        kept = {k: v for k, v in fn.targetoptions.items()
                if k not in ("no_cpython_wrapper", "no_cfunc_wrapper", "nopython")}  # fmt: skip
        twin = fn.__dict__["_from_python"] = njit(**kept)(fn.py_func)
    return twin


class _Internal(CPUDispatcher):
    """A dispatcher of :func:`internal`: compiled code calls it as any other; a call from
    Python (which would jump into the wrapper it does not have) goes to its twin."""

    def __call__(self, *args, **kwargs):
        return from_python(self)(*args, **kwargs)


class _CompileClock(event.Listener):
    """Wall time during which some thread held (or waited for) numba's compiler lock."""

    def __init__(self):
        self.total, self.depth, self.since = 0.0, 0, 0.0
        self.lock = threading.Lock()

    def on_start(self, ev):
        with self.lock:
            if self.depth == 0:
                self.since = time.perf_counter()
            self.depth += 1

    def on_end(self, ev):
        with self.lock:
            self.depth -= 1
            if self.depth == 0:
                self.total += time.perf_counter() - self.since

    def seconds(self) -> float:
        with self.lock:
            return self.total + (time.perf_counter() - self.since if self.depth else 0.0)


_CLOCK = _CompileClock()
event.register("numba:compiler_lock", _CLOCK)


def compile_seconds() -> float:
    """Seconds this process has spent under numba's compiler lock since the library was
    imported: compiling, or loading compiled code from the cache (the first such load in
    a process also sets up numba's compiler, tenths of a second).  The difference of two
    readings is the compiling between them (the wall time during which some thread
    compiled or waited to)."""
    return _CLOCK.seconds()
