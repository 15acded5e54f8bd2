"""``fma(a, b, c)``: ``a·b + c`` with one rounding, for the library's own sums.

The right-hand side, the L D Lᵀ routines and the fixed-step Runge–Kutta stage sums are
chains of multiply-adds.  numba compiles ``a * b + c`` as a multiplication and an
addition, each rounded (no ``fastmath``), so the hardware's fused multiply-add goes unused:
in the ensemble kernel's vectorized member loop that is about one instruction in four.  Letting
LLVM contract on its own (``fastmath={"contract"}``) would make the numbers depend on which
pairs it chooses to fuse in each differently shaped function, and the ensemble kernel
could no longer promise the same bits as :func:`stabdae.integrate`.  An explicit fused
operation is an IEEE 754 operation like any other: written at the same places in both
loops, it gives the same bits in both, for any thread count and block size, and on any
machine that has it.

``fma`` lowers to ``llvm.fma.f64`` (one ``vfmadd`` instruction, vectorized with the loop
around it) when the host CPU has FMA instructions (x86-64 since 2013, every AArch64).  On a
CPU without them ``llvm.fma`` would become a call to the C library's software ``fma``,
several times slower and in the way of vectorization; there ``fma`` is ``a * b + c`` with
two roundings.  Results then differ from an FMA machine's at the roundoff level, which
:data:`HOST_FMA` records and every dataset reports (attribute ``fused_multiply_add``).
"""

from __future__ import annotations

import math
from fractions import Fraction

import llvmlite.binding as llvm
import numpy as np
from numba import njit, types
from numba.extending import intrinsic

from .jit import JIT

__all__ = ["HOST_FMA", "fma"]


def _host_has_fma() -> bool:
    try:
        return bool(llvm.get_host_cpu_features().get("fma", False))
    except RuntimeError:  # features unknown on this host: the safe choice
        return False


#: whether ``fma`` is the hardware's fused multiply-add on this machine
HOST_FMA = _host_has_fma()


@intrinsic
def _fused(typingctx, a, b, c):
    if not all(isinstance(x, (types.Float, types.Integer)) for x in (a, b, c)):
        return None

    def codegen(context, builder, sig, args):
        a, b, c = (context.cast(builder, v, t, types.float64) for v, t in zip(args, sig.args))
        return builder.fma(a, b, c)  # llvm.fma.f64

    return types.float64(a, b, c), codegen


@njit(cache=True, forceinline=True, error_model="numpy")
def _fused_fma(a, b, c):
    return _fused(a, b, c)


@njit(cache=True, forceinline=True, error_model="numpy")
def _unfused_fma(a, b, c):
    return a * b + c


def _exact_fma(a, b, c):
    """``a · b + c`` rounded once, in Python (without the JIT: Python 3.11 has no
    ``math.fma``): exact rational arithmetic, then one correctly rounded conversion.  A
    NumPy float, so that a division by the result follows ``error_model="numpy"`` (inf or
    NaN, no exception) as the compiled code does."""
    a, b, c = float(a), float(b), float(c)
    if not (math.isfinite(a) and math.isfinite(b) and math.isfinite(c)):
        return np.float64(a) * b + c
    try:
        out = float(Fraction(a) * Fraction(b) + Fraction(c))
    except OverflowError:  # beyond the largest float: inf, as the hardware rounds it
        return np.float64(a) * b + c
    if out == 0.0:  # the sign of an exact zero, as IEEE gives it
        return np.float64(a) * b + c
    return np.float64(out)


def _python_unfused_fma(a, b, c):
    return np.float64(a) * b + c


if not JIT:
    fma = _exact_fma if HOST_FMA else _python_unfused_fma
else:
    fma = _fused_fma if HOST_FMA else _unfused_fma
fma.__doc__ = """``a · b + c`` rounded once (twice on a CPU without FMA, see :data:`HOST_FMA`)."""
