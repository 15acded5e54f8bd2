"""Whether the library compiles, the compiled functions it is given, and the time it
spends compiling (:func:`compile_seconds`).

With ``NUMBA_DISABLE_JIT=1`` in the environment, ``@njit`` returns the Python function
itself: a model's functions then arrive as plain functions, the library's kernels run as
Python (slowly: for stepping through a kernel in a debugger, or measuring coverage), and
the intrinsics have Python stand-ins (:mod:`.fma`, :mod:`.workspace`).
"""

from __future__ import annotations

import contextlib
import inspect
import threading
import time
import types

from numba import _dynfunc, config, njit
from numba.core import event
from numba.core.codegen import JITCodeLibrary
from numba.core.compiler import Flags
from numba.core.dispatcher import Dispatcher, _FunctionCompiler
from numba.core.registry import CPUDispatcher

__all__ = ["JIT", "compile_seconds", "compiling_elsewhere", "from_python", "internal", "is_njit",
           "python_function", "variant"]

#: False when numba's JIT is switched off (``NUMBA_DISABLE_JIT=1``)
JIT = not config.DISABLE_JIT


#: numba's hooks for compiling a function to LLVM IR only (internal API: without them,
#: :func:`internal` functions get machine code of their own, as any other)
_LINK_ONLY = (hasattr(_FunctionCompiler, "_customize_flags")
              and "no_compile" in getattr(Flags, "options", {}))


def is_njit(fn) -> bool:
    """A numba dispatcher, or, with the JIT switched off, a plain function (what ``@njit``
    returns then)."""
    return isinstance(fn, Dispatcher) or (not JIT and inspect.isfunction(fn))


def python_function(fn):
    """The Python function behind a dispatcher (the function itself without the JIT)."""
    return getattr(fn, "py_func", fn)


def variant(fn, name: str, **replace):
    """A copy of the Python function behind ``fn`` named ``name``, in which the global
    names of ``replace`` refer to the objects given: the same source compiled on its own,
    with other options or other callees (numba types a function's callees with the
    caller's options, so a function compiled without reference counting cannot call one
    that allocates; its variant can call a variant that does not).  Cached under its own
    name (numba's cache files are named after the function).  The copy's globals are
    those of ``fn``'s module when it is made: make it at the module's end."""
    py = python_function(fn)
    scope = dict(py.__globals__)
    scope.update(replace)
    copy = types.FunctionType(py.__code__, scope, name, py.__defaults__, py.__closure__)
    copy.__qualname__ = name
    copy.__module__ = py.__module__
    copy.__doc__ = py.__doc__
    copy.__kwdefaults__ = py.__kwdefaults__
    return copy


def internal(**options):
    """``njit(**options)`` for a function that compiled code calls (a kernel's pieces):
    numba then builds neither its CPython nor its C wrapper, code that boxes and unboxes
    every argument (a workspace is a tuple of arrays) and goes through LLVM with the rest
    of a model's first ensemble.  Unless it is cached on disk (``cache=True``), its
    compilation also stops at the optimized LLVM IR that its callers link in and compile
    with their own code: no machine code of its own, which nothing would run (callers
    never call into another library's machine code).  A call from Python goes to its
    twin with the wrappers, compiled when first called (:func:`from_python`)."""
    decorate = njit(no_cpython_wrapper=True, no_cfunc_wrapper=True, **options)

    def make(fn):
        dispatcher = decorate(fn)
        if JIT:
            dispatcher.__class__ = _Internal
            if _LINK_ONLY and not options.get("cache"):
                dispatcher._compiler.__class__ = _LinkOnlyCompiler
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

    def add_overload(self, cres):
        if cres.entry_point is None and not cres.objectmode:  # compiled for linking only
            # what numba's lowering registers for a compiled function, without asking
            # the library for an address (the call target is the function in the IR its
            # callers link in; the Python-facing address of a function without wrappers
            # is null either way)
            library, fndesc, env = cres.library, cres.fndesc, cres.environment
            library.__class__ = _LinkOnlyLibrary
            library.env_global = (self.targetctx.get_env_name(fndesc), env)
            entry = _dynfunc.make_function(fndesc.lookup_module(),
                                           fndesc.qualname.split(".")[-1],
                                           f"compiled for linking only: {fndesc.qualname!r}",
                                           0, env, (library,))  # fmt: skip
            self.targetctx.insert_user_function(entry, fndesc, [library])
            cres = cres._replace(entry_point=entry)
        super().add_overload(cres)


class _LinkOnlyCompiler(_FunctionCompiler):
    """Compiles to LLVM IR and stops there (numba's ``no_compile``)."""

    def _customize_flags(self, flags):
        flags = super()._customize_flags(flags)
        flags.no_compile = True
        return flags


class _LinkOnlyLibrary(JITCodeLibrary):
    """The code library of a function compiled for linking only: finalized (its IR
    optimized, as callers link it) without the machine code of its own, unless its code
    reads its environment, which only an engine that holds the code can point to."""

    env_global: tuple = ("", None)

    def _finalize_final_module(self):
        name, env = self.env_global
        # the module defines the global once; any other mention is a use
        if str(self._final_module).count(name) > 1:
            super()._finalize_final_module()
            self.codegen.set_env(name, env)
            return
        self._finalize_dynamic_globals()
        self._verify_declare_only_symbols()
        self._finalized = True


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


@contextlib.contextmanager
def compiling_elsewhere():
    """Book the time inside the block as compiling (:func:`compile_seconds`): this process
    waits for another one that compiles its code (:mod:`.ahead`)."""
    _CLOCK.on_start(None)
    try:
        yield
    finally:
        _CLOCK.on_end(None)


def compile_seconds() -> float:
    """Seconds this process has spent under numba's compiler lock since the library was
    imported: compiling, or loading compiled code from the cache (the first such load in
    a process also sets up numba's compiler, tenths of a second).  The difference of two
    readings is the compiling between them (the wall time during which some thread
    compiled or waited to)."""
    return _CLOCK.seconds()
