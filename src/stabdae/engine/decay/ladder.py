"""The ladder: a float's level on a log scale read from its bits (no logarithm per
step), and per level the time and value of the last step on it; the envelope points read
from it (:func:`records`)."""

from __future__ import annotations

import math
import struct

import numpy as np
from llvmlite import ir
from numba import config, njit, types
from numba.cpython.unsafe.numbers import trailing_zeros as _numba_trailing_zeros
from numba.extending import intrinsic

from ..fma import fma

#: levels of the ladder per octave (the leading mantissa bits read: 3)
LEVELS_PER_OCTAVE = 8
_SHIFT = 52 - 3
#: levels of the ladder, and how many lie above the member's initial norm
NBINS = 512
ABOVE = 80
#: the level of every member's initial norm (:func:`ladder_base`)
START_LEVEL = NBINS - 1 - ABOVE


# --------------------------------------------------------------------- the ladder
@intrinsic
def _bits_intrinsic(typingctx, x):
    if not (isinstance(x, types.Float) and x.bitwidth == 64):
        return None

    def codegen(context, builder, sig, args):
        return builder.bitcast(args[0], ir.IntType(64))

    return types.int64(x), codegen


def _bits_python(x):
    return struct.unpack("<q", struct.pack("<d", x))[0]


float_bits = _bits_python if config.DISABLE_JIT else _bits_intrinsic
float_bits.__doc__ = """The IEEE-754 bits of a float64 as an int64 (monotone in a
non-negative value)."""


@intrinsic
def _from_bits_intrinsic(typingctx, i):
    if not (isinstance(i, types.Integer) and i.bitwidth == 64):
        return None

    def codegen(context, builder, sig, args):
        return builder.bitcast(args[0], ir.DoubleType())

    return types.float64(i), codegen


def _from_bits_python(i):
    return struct.unpack("<d", struct.pack("<q", i))[0]


float_from_bits = _from_bits_python if config.DISABLE_JIT else _from_bits_intrinsic
float_from_bits.__doc__ = """The float64 whose IEEE-754 bits are the int64 ``i``."""

# the natural logarithm of fdlibm (as in musl's log.c): x = 2^k (1 + f) with
# 1 + f in [√2/2, √2), log(1 + f) = f − f²/2 + s (f²/2 + R(s²)), s = f / (2 + f)
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
_LG1 = 6.666666666666735130e-01
_LG2 = 3.999999999940941908e-01
_LG3 = 2.857142874366239149e-01
_LG4 = 2.222219843214978396e-01
_LG5 = 1.818357216161805012e-01
_LG6 = 1.531383769920937332e-01
_LG7 = 1.479819860511658591e-01
#: the smallest positive normal float64
_TINY = 2.2250738585072014e-308


@njit(cache=True, forceinline=True, error_model="numpy")  # no branch on 2 + f = 0
def log_normal(x):
    """``log(x)`` within one ulp for a positive, finite, normal ``x`` (anything else gives
    a meaningless number): fdlibm's algorithm with no branch, so that a loop of them
    vectorizes, which the library's ``log`` does not."""
    ix = float_bits(x)
    hx = (ix >> 32) + (0x3FF00000 - 0x3FE6A09E)
    k = (hx >> 20) - 0x3FF
    hx = (hx & 0x000FFFFF) + 0x3FE6A09E
    f = float_from_bits((hx << 32) | (ix & 0xFFFFFFFF)) - 1.0
    hfsq = 0.5 * f * f
    s = f / (2.0 + f)
    z = s * s
    w = z * z
    t1 = w * (_LG2 + w * (_LG4 + w * _LG6))
    t2 = z * (_LG1 + w * (_LG3 + w * (_LG5 + w * _LG7)))
    dk = float(k)
    return s * (hfsq + t2 + t1) + dk * _LN2_LO - hfsq + f + dk * _LN2_HI


# log2(1 + m) on [0, 1) as m (c1 + m (c2 + m (c3 + m c4))), fitted for the least largest
# error (1.03e-4 on a grid of 2·10⁵ points; LOG2_BOUND allows twice that)
_B1 = 1.4390152347136267
_B2 = -0.6799482851725904
_B3 = 0.32560446869825643
_B4 = -0.08477398588203487
#: :func:`log2_biased` is within this of ``log2 x + 1023``
LOG2_BOUND = 2e-4


@njit(cache=True, forceinline=True)
def log2_biased(x):
    """``log2 x + 1023`` (≥ 1) within ``LOG2_BOUND`` for a positive, finite, normal ``x``:
    its biased exponent and a quartic in its mantissa, a fraction of :func:`log_normal`'s
    work and no division (for a pass that needs the logarithm only near its maximum: it
    takes this first, then the exact one where this comes within twice the bound of the
    largest; positive, so that its maximum is an integer maximum of the bits)."""
    ix = float_bits(x)
    m = float_from_bits((ix & 0x000FFFFFFFFFFFFF) | 0x3FF0000000000000) - 1.0
    return fma(m, fma(m, fma(m, fma(m, _B4, _B3), _B2), _B1), float(ix >> 52))


@njit(cache=True, forceinline=True)
def ladder_base(g0):
    """The ladder's offset for a member whose initial norm is ``g0``: its level is
    ``NBINS − 1 − ABOVE``.  (A zero or non-finite ``g0`` anchors the ladder at 1.)"""
    ref = g0 if (g0 > 0.0 and g0 < math.inf) else 1.0
    return (float_bits(ref) >> _SHIFT) - START_LEVEL


@njit(cache=True, forceinline=True)
def ladder_level(v, base):
    """The level of the norm ``v`` (≥ 0) on a ladder with offset ``base``, clamped."""
    b = (float_bits(v) >> _SHIFT) - base
    return min(max(b, 0), NBINS - 1)


@njit(cache=True, _nrt=False)
def ladder_clear_from(lt, j, first):
    """Ladder row ``j`` with no level visited, where none below ``first`` (≥ 0) was."""
    for b in range(max(first, 0), NBINS):
        lt[j, np.uint64(b)] = -1.0


@njit(cache=True, _nrt=False)
def ladder_clear(lt, j):
    """Ladder row ``j`` with no level visited."""
    ladder_clear_from(lt, j, 0)


@njit(cache=True, _nrt=False)
def ladder_top(lt, j):
    """The highest level of ladder row ``j`` visited (−1 for none).  A member's initial
    norm lies on level ``NBINS − 1 − ABOVE`` (unless it is zero or not finite), so the
    levels from there up are scanned first, in a loop without branches that vectorizes
    (a scan down from the top, stopping at the first visited level, went through the
    ``ABOVE`` levels one by one for every member that never rose above its start)."""
    row = lt[j]
    top = -1
    for b in range(START_LEVEL, NBINS):
        top = max(top, b if row[b] >= 0.0 else -1)
    if top < 0:
        for b in range(START_LEVEL - 1, -1, -1):
            if row[b] >= 0.0:
                return b
    return top


@njit(cache=True, _nrt=False)
def records(lt, lv, j, rt, ry, lowest=0, top=NBINS - 1):
    """The right-envelope points of ladder row ``j``, in time order, into ``rt`` (times)
    and ``ry`` (log norms); returns their number.  The last sample on a level lies on the
    envelope exactly when no higher level was visited later.  ``lowest``: no level below
    it was visited; ``top``: none above it (the scan runs between them: an unvisited
    level is never a point)."""
    n = 0
    latest = -1.0
    normal = True  # every norm positive, finite and normal
    for b in range(min(top, NBINS - 1), max(lowest, 0) - 1, -1):
        t = lt[j, b]
        if t > latest:
            latest = t
            v = lv[j, b]
            rt[n] = t
            ry[n] = v
            normal &= (v >= _TINY) & (v < math.inf)
            n += 1
    # the logarithms in a loop of their own, which vectorizes (a row with a norm below
    # the normal floats, or a zero, takes the library's log)
    if normal:
        for i in range(n):
            ry[i] = log_normal(ry[i])
    else:
        for i in range(n):
            v = ry[i]
            ry[i] = math.log(v) if v > 0.0 else -math.inf
    return n


def _trailing_zeros_python(x):
    return (int(x) & -int(x)).bit_length() - 1


trailing_zeros = _trailing_zeros_python if config.DISABLE_JIT else _numba_trailing_zeros
trailing_zeros.__doc__ = """The index of the lowest set bit of a non-zero int64."""


@njit(cache=True)
def ladders(rows):
    """Ladder buffers (times, values, offsets) for ``rows`` members at a time."""
    # A spare column for writes to be ignored (``NBINS``), and rows 4096 + 72 bytes
    # apart: rows a multiple of 4 kB apart share the L1 cache's sets, and the scattered
    # writes of a block's 64 members evicted each other.
    lt = np.empty((rows, NBINS + 9))
    lv = np.empty((rows, NBINS + 9))
    base = np.zeros(rows, dtype=np.int64)
    return lt, lv, base


@njit(cache=True)
def scratch():
    """The estimator's buffers for one thread: envelope times and log norms, the normal
    equations of the 3-parameter fit, logarithms."""
    return np.empty(NBINS), np.empty(NBINS), np.empty((3, 3)), np.empty(3), np.empty(NBINS)
