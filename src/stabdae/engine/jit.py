"""Whether the library compiles, and the compiled functions it is given.

With ``NUMBA_DISABLE_JIT=1`` in the environment, ``@njit`` returns the Python function
itself: a model's functions then arrive as plain functions, the library's kernels run as
Python (slowly: for stepping through a kernel in a debugger, or measuring coverage), and
the intrinsics have Python stand-ins (:mod:`.fma`, :mod:`.workspace`).
"""

from __future__ import annotations

import inspect

from numba import config
from numba.core.dispatcher import Dispatcher

__all__ = ["JIT", "is_njit", "python_function"]

#: False when numba's JIT is switched off (``NUMBA_DISABLE_JIT=1``)
JIT = not config.DISABLE_JIT


def is_njit(fn) -> bool:
    """A numba dispatcher, or, with the JIT switched off, a plain function (what ``@njit``
    returns then)."""
    return isinstance(fn, Dispatcher) or (not JIT and inspect.isfunction(fn))


def python_function(fn):
    """The Python function behind a dispatcher (the function itself without the JIT)."""
    return getattr(fn, "py_func", fn)
