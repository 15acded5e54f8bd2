"""Decay rate, prefactor and floor of each member's residual, measured at every step.

A member's ``‖g‖∞`` first decays at the rate of the law (continuous: ``−max Re λ(Ã)``;
discrete: ``−ln ρ(R(τÃ))/τ``) and then settles on a floor set by the scheme's local error
(the paper's §5).  The kernels measure it where the step evaluates the residual, not on
the stored samples (the fixed-step kernel every ``s``-th step, over which no mode of the
law changes by more than a tenth: :func:`stabdae._ensemble.measure_stride`), with O(1)
work per step and a fixed amount of memory per member (a *ladder*):

* the norm's level on a log scale of ``LEVELS_PER_OCTAVE`` levels per octave (read from
  the float's exponent and leading mantissa bits: no logarithm per step), over
  ``NBINS`` levels from ``2^-54`` to about ``940`` times the member's initial norm;
* per level, the time and value of the *last* step at which the norm lay on it.

From the ladder the estimator reads the right envelope of the whole trace at step
resolution: the last sample on a level is a point of the envelope (no later sample is as
large) exactly when no higher level was visited later (:func:`records`).  These points,
one per level, are what the decay rate of an oscillating residual is read from, and they
are the samples of a monotone one.  Also per member: the largest norm over each fifth of
the run (``W0 … W4``); ``W4``, the largest over the last fifth, is the *floor*.

The estimator (:func:`estimate`), per member, at the end of its run:

1. the transient: the envelope points from the start until the envelope first comes
   within a margin of the floor (1000, 100, then ``FLOOR_MARGIN`` = 30 when that leaves
   too little: the floor is a forced response that bends the trace well above its own
   level), or all of them when the run ended while the residual was still decaying (each
   of the last three fifths at least ``STILL_DECAYING`` times below the one before);
2. the fit window: the transient after its first ``LEAD_FRACTION`` of decades, where
   faster modes have died out.  It must span a decade (``MIN_DECADES``) with
   ``MIN_POINTS`` points; otherwise β is NaN with the reason ``no transient``;
3. fits ``log ‖g‖ ≈ a − β t`` and ``log ‖g‖ ≈ a − β t + ν log(t + s)`` by least squares
   (``s`` by a grid search refined by Brent's method) and keeps the better.  The
   ``ν log(t + s)`` term absorbs the polynomial prefactor of repeated eigenvalues:
   critically damped Baumgarte decays like ``|c0 + c1 t| e^{−ωt}`` (the schemes'
   ``R(τÃ)`` is then a Jordan block, ``‖g_k‖ ~ |a + bk| ρ^k``).  When neither fits the
   points to ``SMOOTH_RMS`` in the logarithm, the residual oscillates (under-damped laws):
   the envelope is then ``e^{−βt}`` times a periodic function, and the time of each level
   regressed on the level (``t ≈ a − log ‖g‖ / β``, levels equally spaced) has a bias that
   falls like the square of the number of periods in the window;
4. ``γ = max ‖g(t)‖ e^{βt}`` over the transient's envelope points, the smallest prefactor
   with ``‖g(t)‖ ≤ γ e^{−βt}`` there (the largest of a trace is always on its envelope).

A member that stopped, or whose envelope does not fall, gets ``β = γ = NaN`` and a reason
(:data:`REASONS`), never a fitted number.

:func:`predict` runs a member's linear prediction ``g_{k+1} = R g_k`` from its own
``α⁰`` (``R = R(τÃ)`` for fixed steps, ``e^{Ãh}`` for adaptive ones) through the same
ladder and fits it over the same time window with the same kind of fit, so that what the
estimator does to a window cancels in the ratio of measured to predicted rate.
"""

from __future__ import annotations

import math
import struct

import numpy as np
from llvmlite import ir
from numba import config, njit, types
from numba.cpython.unsafe.numbers import trailing_zeros as _numba_trailing_zeros
from numba.extending import intrinsic

from .threads import run_chunks
from .workspace import stack1

#: levels of the ladder per octave (the leading mantissa bits read: 3)
LEVELS_PER_OCTAVE = 8
_SHIFT = 52 - 3
#: levels of the ladder, and how many lie above the member's initial norm
NBINS = 512
ABOVE = 80
_START_BIN = NBINS - 1 - ABOVE

FLOOR_MARGIN = 30.0
LEAD_FRACTION = 0.3
MIN_POINTS = 12
MIN_DECADES = 1.0
#: a fit whose RMS deviation in log ‖g‖ exceeds this is not of a smooth decay
SMOOTH_RMS = 0.01
#: growth of the largest norm from the third fifth of the run to the last that, with the
#: last three fifths increasing, marks a member growing (:func:`grows`)
GROWTH = 1.5
#: the run ended inside the transient: each of the last three fifths fell by this factor
STILL_DECAYING = 3.0
N_SHIFTS = 16
#: Brent's search for the shift stops within this fraction of its bracket (two grid steps)
BRENT_TOL = 3e-5

#: columns of the per-member measurement array (``measures``)
COLUMNS = ("beta", "gamma", "floor", "initial", "largest", "final", "w0", "w1", "w2", "w3",
           "w4", "fit_start", "fit_end", "fit_points", "reason", "fit_kind", "shift",
           "floor_reached", "beta_predicted", "d2", "d3", "d4")  # fmt: skip
(C_BETA, C_GAMMA, C_FLOOR, C_INITIAL, C_LARGEST, C_FINAL, C_W0, C_W1, C_W2, C_W3, C_W4,
 C_FIT_START, C_FIT_END, C_POINTS, C_REASON, C_KIND, C_SHIFT, C_FLOOR_REACHED,
 C_BETA_PRED, C_D2, C_D3, C_D4) = range(len(COLUMNS))  # fmt: skip
NCOLS = len(COLUMNS)

#: reason codes of ``beta_reason``
R_FITTED, R_NO_TRANSIENT, R_STOPPED, R_NOT_DECAYING = 0, 1, 2, 3
REASONS = {
    R_FITTED: "fitted",
    R_NO_TRANSIENT: "no transient: under a decade of decay above the floor",
    R_STOPPED: "stopped",
    R_NOT_DECAYING: "not decaying",
}
#: kinds of fit (``fit_kind``)
K_NONE, K_EXPONENTIAL, K_POLYNOMIAL, K_OSCILLATING, K_MAP = 0, 1, 2, 3, 4
KINDS = {K_NONE: "none", K_EXPONENTIAL: "exponential",
         K_POLYNOMIAL: "exponential with polynomial prefactor",
         K_OSCILLATING: "oscillating (level times regressed on levels)",
         K_MAP: "one-step map (spectral radius of the fitted g_k -> g_k+1)"}  # fmt: skip

#: the one-step map is fitted for residuals of at most this many components (its sums
#: take 2 ng² numbers per bin and member)
MAP_MAX_NG = 12
#: its pairs are binned by the ladder level of ``‖g_k‖`` in bins of ``2^MAP_SHIFT``
#: levels (two octaves)
MAP_SHIFT = 4
MAP_BINS = NBINS >> MAP_SHIFT
#: eigenvalues of a fitted map whose rates differ by less than this fraction count as
#: one repeated eigenvalue (:func:`_cluster_radius`); the rate read is then off by at most
#: half of it
CLUSTER = 0.02
#: directions of the whitened pairs with less than this fraction of the largest's sum
#: of squares are left out of the fit (no transient moves there: what is seen there is
#: the floor's motion)
MAP_RANK_TOL = 1e-12
#: the pairs used lie above this many times the floor (then ``FLOOR_MARGIN``)
MAP_MARGIN = 100.0
#: all pairs are used when the largest norm fell from each of the last three fifths to
#: the next, by this factor from the third to the fifth: the run ended inside the
#: transient, where the largest norm of the last fifth is no floor (the map needs no
#: window that ends above a floor, so a slower fall than the envelope's
#: ``STILL_DECAYING`` suffices)
MAP_STILL_DECAYING = 2.0


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


@njit(cache=True, forceinline=True)
def ladder_base(g0):
    """The ladder's offset for a member whose initial norm is ``g0``: its level is
    ``NBINS − 1 − ABOVE``.  (A zero or non-finite ``g0`` anchors the ladder at 1.)"""
    ref = g0 if (g0 > 0.0 and g0 < math.inf) else 1.0
    return (float_bits(ref) >> _SHIFT) - _START_BIN


@njit(cache=True, forceinline=True)
def ladder_level(v, base):
    """The level of the norm ``v`` (≥ 0) on a ladder with offset ``base``, clamped."""
    b = (float_bits(v) >> _SHIFT) - base
    return min(max(b, 0), NBINS - 1)


@njit(cache=True)
def ladder_clear(lt, j):
    for b in range(NBINS):
        lt[j, b] = -1.0


@njit(cache=True)
def records(lt, lv, j, rt, ry):
    """The right-envelope points of ladder row ``j``, in time order, into ``rt`` (times)
    and ``ry`` (log norms); returns their number.  The last sample on a level lies on the
    envelope exactly when no higher level was visited later."""
    n = 0
    latest = -1.0
    normal = True  # every norm positive, finite and normal
    for b in range(NBINS - 1, -1, -1):
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


# --------------------------------------------------------------------- fits
@njit(cache=True)
def _solve3(a, b):
    """Solve the 3×3 system ``a x = b`` by Gaussian elimination with partial pivoting;
    returns False when it is singular.  ``a`` and ``b`` are overwritten."""
    for c in range(3):
        piv = c
        for r in range(c + 1, 3):
            if abs(a[r, c]) > abs(a[piv, c]):
                piv = r
        if a[piv, c] == 0.0:
            return False
        if piv != c:
            for k in range(3):
                a[c, k], a[piv, k] = a[piv, k], a[c, k]
            b[c], b[piv] = b[piv], b[c]
        for r in range(c + 1, 3):
            fac = a[r, c] / a[c, c]
            for k in range(c, 3):
                a[r, k] -= fac * a[c, k]
            b[r] -= fac * b[c]
    for c in range(2, -1, -1):
        s = b[c]
        for k in range(c + 1, 3):
            s -= a[c, k] * b[k]
        b[c] = s / a[c, c]
    return True


@njit(cache=True)
def _centered_sums(rt, ry, start, end):
    """Means of ``t`` and ``y`` on [start, end) and the centred sums ``Σ(t − t̄)²``,
    ``Σ(t − t̄)(y − ȳ)``, ``Σ(y − ȳ)²`` of both regressions."""
    cnt = end - start
    st = sy = 0.0
    for i in range(start, end):
        st += rt[i]
        sy += ry[i]
    tm, ym = st / cnt, sy / cnt
    stt = sty = syy = 0.0
    for i in range(start, end):
        stt += (rt[i] - tm) ** 2
        sty += (rt[i] - tm) * (ry[i] - ym)
        syy += (ry[i] - ym) ** 2
    return tm, ym, stt, sty, syy


@njit(cache=True)
def _fit_linear(rt, ry, start, end):
    """Least squares ``y ≈ c − β t`` on points [start, end); returns (β, SSE)."""
    tm, ym, stt, sty, _ = _centered_sums(rt, ry, start, end)
    if stt == 0.0:
        return math.nan, math.inf
    slope = sty / stt
    sse = 0.0
    for i in range(start, end):
        r = ry[i] - ym - slope * (rt[i] - tm)
        sse += r * r
    return -slope, sse


@njit(cache=True)
def _fit_inverse(rt, ry, start, end):
    """Least squares ``t ≈ a + b y`` on [start, end); returns ``β = −1/b``."""
    _, _, _, sty, syy = _centered_sums(rt, ry, start, end)
    if sty == 0.0:
        return math.nan
    return -syy / sty


@njit(cache=True)
def _shift_free_sums(rt, ry, start, end):
    """The sums of the ``ν log(t + s)`` fit's normal equations that do not depend on the
    shift (the count, ``Σ −t``, ``Σ t²``, ``Σ y``, ``Σ −t y`` on [start, end)): formed once
    per search of the shift, in the order the fit would form them."""
    s00 = s01 = s11 = b0 = b1 = 0.0
    for i in range(start, end):
        r1 = -rt[i]
        s00 += 1.0
        s01 += r1
        s11 += r1 * r1
        b0 += ry[i]
        b1 += r1 * ry[i]
    return s00, s01, s11, b0, b1


@njit(cache=True, forceinline=True)
def _residual2(rt, ry, lg, i, c0, c1, c2):
    """The squared residual of point ``i`` of the fit ``y ≈ c0 − c1 t + c2 log(t + s)``."""
    r = ry[i] - c0 + c1 * rt[i] - c2 * lg[i]
    return r * r


@njit(cache=True)
def _fit_with_log(rt, ry, start, end, shift, a, b, lg, fixed):
    """Least squares ``y ≈ c − β t + ν log(t + shift)`` on [start, end); returns (β, SSE),
    SSE = inf when the normal equations are singular.  ``fixed``: the shift-free sums
    (:func:`_shift_free_sums`); ``lg`` is scratch."""
    # the logarithms first, in a loop of their own that vectorizes (they are most of a
    # fit's cost, and a member's fits take some fifty shifts); the times are increasing
    if rt[start] + shift >= _TINY and rt[end - 1] + shift < math.inf:
        for i in range(start, end):
            lg[i] = log_normal(rt[i] + shift)
    else:
        for i in range(start, end):
            lg[i] = math.log(rt[i] + shift)
    # the sums in locals (in arrays, every term was a store and a load: they may alias)
    s00, s01, s11, b0, b1 = fixed
    s02 = s12 = s22 = b2 = 0.0
    for i in range(start, end):
        r2 = lg[i]
        s02 += r2
        s12 += -rt[i] * r2
        s22 += r2 * r2
        b2 += r2 * ry[i]
    a[0, 0], a[0, 1], a[0, 2] = s00, s01, s02
    a[1, 0], a[1, 1], a[1, 2] = s01, s11, s12
    a[2, 0], a[2, 1], a[2, 2] = s02, s12, s22
    b[0], b[1], b[2] = b0, b1, b2
    if not _solve3(a, b):
        return math.nan, math.inf
    c0, c1, c2 = b[0], b[1], b[2]
    # four partial sums (a single chain of additions waits on each one in turn)
    e0 = e1 = e2 = e3 = 0.0
    i = start
    while i + 4 <= end:
        e0 += _residual2(rt, ry, lg, i, c0, c1, c2)
        e1 += _residual2(rt, ry, lg, i + 1, c0, c1, c2)
        e2 += _residual2(rt, ry, lg, i + 2, c0, c1, c2)
        e3 += _residual2(rt, ry, lg, i + 3, c0, c1, c2)
        i += 4
    while i < end:
        e0 += _residual2(rt, ry, lg, i, c0, c1, c2)
        i += 1
    return c1, (e0 + e1) + (e2 + e3)


@njit(cache=True)
def _brent(rt, ry, start, end, t_w, lo_u, hi_u, x, fx, bx, a, b, lg, fixed):
    """Brent's minimization (parabolic steps, golden sections when they fail) of the
    ``ν log(t + s)`` fit's SSE over ``u = log(s + t_w)`` in ``[lo_u, hi_u]``, from the
    grid's best point ``x`` (SSE ``fx``, β ``bx``), to ``BRENT_TOL`` of the bracket.
    Returns the smallest SSE seen, its β and its ``u``."""
    CG = 0.3819660112501051
    tol1 = BRENT_TOL * (hi_u - lo_u)
    tol2 = 2.0 * tol1
    lo, hi = lo_u, hi_u
    w = v = x
    fw = fv = fx
    d = e = 0.0
    best, beta, ubest = fx, bx, x
    for _ in range(40):
        xm = 0.5 * (lo + hi)
        if abs(x - xm) <= tol2 - 0.5 * (hi - lo):
            break
        golden = True
        if abs(e) > tol1 and math.isfinite(fx) and math.isfinite(fw) and math.isfinite(fv):
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            etemp = e
            e = d
            if not (abs(p) >= abs(0.5 * q * etemp) or p <= q * (lo - x) or p >= q * (hi - x)):
                d = p / q
                u = x + d
                if u - lo < tol2 or hi - u < tol2:
                    d = tol1 if xm >= x else -tol1
                golden = False
        if golden:
            e = (lo - x) if x >= xm else (hi - x)
            d = CG * e
        u = x + d if abs(d) >= tol1 else x + (tol1 if d >= 0.0 else -tol1)
        bu, fu = _fit_with_log(rt, ry, start, end, math.exp(u) - t_w, a, b, lg, fixed)
        if fu < best:
            best, beta, ubest = fu, bu, u
        if fu <= fx:
            if u >= x:
                lo = x
            else:
                hi = x
            v, fv = w, fw
            w, fw = x, fx
            x, fx = u, fu
        else:
            if u < x:
                lo = u
            else:
                hi = u
            if fu <= fw or w == x:
                v, fv = w, fw
                w, fw = u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
    return best, beta, ubest


@njit(cache=True)
def _fit_polynomial(rt, ry, start, end, dt, a, b, lg, hint=math.nan):
    """The ``ν log(t + s)`` fit with the best shift: a log-spaced grid of shifts
    ``s = e^u − t_w`` over ``(−t_w, ∞)`` (``t_w`` the window's first time: a negative
    ``s`` puts a zero crossing of ``c0 + c1 t`` just before the window), refined by
    Brent's method around the best grid point.  With a ``hint`` (a shift found for a
    neighbouring curve: the measured member's, for its prediction), Brent's method first
    searches the two grid steps around it, and the grid runs only when the minimum lies
    on that bracket's edge.  Returns (β, SSE, s)."""
    t_w = rt[start]
    span = rt[end - 1] - t_w
    lo = math.log(0.25 * dt)
    hi = math.log(t_w + 4.0 * span + dt)
    step_u = (hi - lo) / (N_SHIFTS - 1)
    fixed = _shift_free_sums(rt, ry, start, end)
    if hint + t_w > 0.0:
        uh = min(max(math.log(hint + t_w), lo), hi)
        ua = max(uh - step_u, lo)
        ub = min(uh + step_u, hi)
        bh, fh = _fit_with_log(rt, ry, start, end, math.exp(uh) - t_w, a, b, lg, fixed)
        best, beta, u = _brent(rt, ry, start, end, t_w, ua, ub, uh, fh, bh, a, b, lg,
                               fixed)  # fmt: skip
        edge = 4.0 * BRENT_TOL * (ub - ua)
        inside = (u - ua > edge or ua == lo) and (ub - u > edge or ub == hi)
        if inside and best < math.inf:
            return beta, best, math.exp(u) - t_w
    k_best = -1
    best, beta = math.inf, math.nan
    for k in range(N_SHIFTS):
        u = lo + k * step_u
        bk, sse = _fit_with_log(rt, ry, start, end, math.exp(u) - t_w, a, b, lg, fixed)
        if sse < best:
            best, beta, k_best = sse, bk, k
    if k_best < 0:
        return math.nan, math.inf, math.nan
    ua = lo + max(k_best - 1, 0) * step_u
    ub = lo + min(k_best + 1, N_SHIFTS - 1) * step_u
    best, beta, u = _brent(rt, ry, start, end, t_w, ua, ub, lo + k_best * step_u, best, beta,
                           a, b, lg, fixed)  # fmt: skip
    return beta, best, math.exp(u) - t_w


@njit(cache=True)
def _window(rt, ry, n, floor, still_decaying):
    """The fit window ``[start, end)`` of the envelope points: the transient (down to a
    margin above the floor, or all points when the run ended still decaying) after its
    first ``LEAD_FRACTION`` of decades.  ``end`` is 0 when no window spans
    ``MIN_DECADES`` with ``MIN_POINTS`` points."""
    lnfloor = math.log(floor) if floor > 0.0 else -math.inf
    for margin in (1000.0, 100.0, FLOOR_MARGIN, -1.0):
        if margin < 0.0:
            if not still_decaying:
                break
            end = n
        else:
            level = lnfloor + math.log(margin)
            end = n
            for i in range(n):
                if ry[i] <= level:
                    end = i
                    break
        if end < 2:
            continue
        cut = ry[0] - LEAD_FRACTION * (ry[0] - ry[end - 1])
        start = 0
        for i in range(end):
            if ry[i] <= cut:
                start = i
                break
        if (end - start >= MIN_POINTS
                and ry[start] - ry[end - 1] >= MIN_DECADES * math.log(10.0)):
            return start, end
    return 0, 0


@njit(cache=True)
def estimate(rt, ry, n, floor, still_decaying, dt, a, b, lg, out):
    """β, γ and the fit's window, kind and shift from the ``n`` envelope points into
    ``out`` (columns of :data:`COLUMNS`; ``reason`` too)."""
    out[C_BETA] = math.nan
    out[C_GAMMA] = math.nan
    out[C_FIT_START] = math.nan
    out[C_FIT_END] = math.nan
    out[C_POINTS] = 0
    out[C_KIND] = K_NONE
    out[C_SHIFT] = math.nan
    if n < 2 or not math.isfinite(ry[0]):
        out[C_REASON] = R_NOT_DECAYING if n < 2 else R_NO_TRANSIENT
        return
    start, end = _window(rt, ry, n, floor, still_decaying)
    if end == 0:
        # no decade of decay above the floor: growing, or started near its floor
        out[C_REASON] = (R_NOT_DECAYING if grows(out[C_D2], out[C_D3], out[C_D4])
                         else R_NO_TRANSIENT)  # fmt: skip
        return
    beta, sse = _fit_linear(rt, ry, start, end)
    kind = K_EXPONENTIAL
    shift = math.nan
    if end - start >= 6:
        bp, sp, s = _fit_polynomial(rt, ry, start, end, dt, a, b, lg)
        if sp < sse:
            beta, sse, kind, shift = bp, sp, K_POLYNOMIAL, s
    if math.sqrt(sse / (end - start)) > SMOOTH_RMS:
        beta = _fit_inverse(rt, ry, start, end)
        kind = K_OSCILLATING
        shift = math.nan
    out[C_FIT_START] = rt[start]
    out[C_FIT_END] = rt[end - 1]
    out[C_POINTS] = end - start
    out[C_KIND] = kind
    out[C_SHIFT] = shift
    if not (beta > 0.0):
        out[C_REASON] = R_NOT_DECAYING
        return
    top = -math.inf  # the exponential is monotone: one call, on the largest exponent
    for i in range(end):
        top = max(top, ry[i] + beta * rt[i])
    gamma = math.exp(top)
    out[C_BETA] = beta
    out[C_GAMMA] = gamma
    out[C_REASON] = R_FITTED


@njit(cache=True)
def refit(rt, ry, n, t_lo, t_hi, kind, dt, a, b, lg, shift=math.nan):
    """β of the envelope points with times in ``[t_lo, t_hi]`` by the fit ``kind`` (the
    measured member's window and kind, for its prediction; ``shift`` its shift, where
    the search for the prediction's starts)."""
    start, end = n, 0
    for i in range(n):
        if rt[i] >= t_lo and start == n:
            start = i
        if rt[i] <= t_hi:
            end = i + 1
    if end - start < 3:
        return math.nan
    if kind == K_EXPONENTIAL:
        return _fit_linear(rt, ry, start, end)[0]
    if kind == K_POLYNOMIAL:
        return _fit_polynomial(rt, ry, start, end, dt, a, b, lg, shift)[0]
    if kind == K_OSCILLATING:
        return _fit_inverse(rt, ry, start, end)
    return math.nan


@njit(cache=True)
def grows(w2, w3, w4):
    """Whether the largest norms of the last three fifths of a run (scalars or arrays)
    increase, by ``GROWTH`` from the third fifth to the fifth: a growing member."""
    return (w4 > GROWTH * w2) & (w4 >= w3) & (w3 >= w2)


# --------------------------------------------------------------------- per member
@njit(cache=True, forceinline=True)  # once per accepted step: a call with four arrays
def observe(lt, lv, base, meas, j, row, t, v, d, window):  # costs as much as the step
    """Step time ``t`` (from the start) of member ``row`` (ladder row ``j``), in fifth
    ``window`` of the run: ``v`` its residual norm (the largest per fifth is kept), ``d``
    the norm whose decay is measured (the ladder's; ``v`` itself, or the distance of the
    residual from a reference trajectory's).  Non-finite norms are left out."""
    if v < math.inf:
        c = C_W0 + window
        if not (meas[row, c] >= v):
            meas[row, c] = v
    if d < math.inf:
        b = ladder_level(d, base[j])
        lt[j, b] = t
        lv[j, b] = d
        if window >= 2:
            c = C_D2 + window - 2
            if not (meas[row, c] >= d):
                meas[row, c] = d


@njit(cache=True)
def begin(lt, lv, base, meas, j, row, g0, d0):
    """Start member ``row`` on ladder row ``j`` with its initial norms (as
    :func:`observe`'s)."""
    ladder_clear(lt, j)
    base[j] = ladder_base(d0)
    for c in range(NCOLS):
        meas[row, c] = math.nan
    for w in range(5):
        meas[row, C_W0 + w] = -math.inf
    for w in range(3):
        meas[row, C_D2 + w] = -math.inf
    meas[row, C_INITIAL] = g0
    observe(lt, lv, base, meas, j, row, 0.0, g0, d0, 0)


@njit(cache=True)
def finish(lt, lv, meas, j, row, final, stopped, dt, rt, ry, a, b, lg):
    """Member ``row``'s measures from ladder row ``j`` at the end of its run (``final``:
    the norm at its last state; ``stopped``: it did not run to the end)."""
    still = summarize(meas, row, final, stopped)
    if not stopped:
        fit_envelope(lt, lv, meas, j, row, still, dt, rt, ry, a, b, lg)


@njit(cache=True)
def finish_with_map(lt, lv, S, meas, j, row, final, stopped, ng, pm, base_j, lowest, dt, rt,
                    ry, a, b, lg):  # fmt: skip
    """:func:`finish` for a member with one-step map sums ``S`` (:func:`map_estimate`,
    ``dt`` the time between the map's pairs; ``lowest`` a level below which ladder row
    ``j`` has no point): β from the map where it has one, else from
    the envelope.  A member whose largest norms grow (:func:`grows`) gets the map only
    when the envelope does not find it growing (it may decay first, which the map would
    read), so its envelope is fitted first."""
    still = summarize(meas, row, final, stopped)
    if stopped:
        return
    out = meas[row]
    if grows(out[C_D2], out[C_D3], out[C_D4]):
        fit_envelope(lt, lv, meas, j, row, still, dt, rt, ry, a, b, lg)
        if out[C_REASON] != R_NOT_DECAYING:
            map_estimate(S, j, ng, pm, lt, lv, base_j, meas, row, dt, rt, ry, lowest)
    elif not map_estimate(S, j, ng, pm, lt, lv, base_j, meas, row, dt, rt, ry, lowest):
        fit_envelope(lt, lv, meas, j, row, still, dt, rt, ry, a, b, lg)


@njit(cache=True)
def fit_envelope(lt, lv, meas, j, row, still, dt, rt, ry, a, b, lg):
    """β and γ of member ``row`` from the envelope of ladder row ``j`` (:func:`estimate`;
    ``still``: the run ended while it was decaying)."""
    n = records(lt, lv, j, rt, ry)
    estimate(rt, ry, n, meas[row, C_D4], still, dt, a, b, lg, meas[row])


@njit(cache=True)
def summarize(meas, row, final, stopped):
    """Member ``row``'s columns other than the fit at the end of its run (``final``: the
    norm at its last state; ``stopped``: it did not run to the end; then the fit's
    columns say so).  Returns whether the measured norm was still decaying at the end."""
    out = meas[row]
    out[C_FINAL] = final
    largest = -math.inf
    for w in range(5):
        if out[C_W0 + w] == -math.inf:
            out[C_W0 + w] = math.nan
        else:
            largest = max(largest, out[C_W0 + w])
    out[C_LARGEST] = largest if largest > -math.inf else math.nan
    out[C_FLOOR] = out[C_W4]
    # whether the measured norm is still falling at the end
    still = (out[C_D2] >= STILL_DECAYING * out[C_D3]
             and out[C_D3] >= STILL_DECAYING * out[C_D4])  # fmt: skip
    out[C_FLOOR_REACHED] = 0.0 if still else 1.0
    if stopped:
        for c in (C_BETA, C_GAMMA, C_FIT_START, C_FIT_END, C_SHIFT):
            out[c] = math.nan
        out[C_POINTS] = 0
        out[C_KIND] = K_NONE
        out[C_REASON] = R_STOPPED
    return still


@njit(cache=True)
def predict(R, alpha, nsteps, h, lt, lv, base, meas, j, row, rt, ry, a, b, lg, g, gn,
            rho_R=math.nan):  # fmt: skip
    """Member ``row``'s predicted rate: ``g_{k+1} = R g_k`` from ``g_0 = alpha`` over the
    steps up to its fit window's end, through ladder row ``j``, fitted over the measured
    window with the measured kind; ``−ln ρ(R)/h`` for a member measured by its one-step
    map (``rho_R``: ``ρ(R)`` when known).  ``g``, ``gn`` are scratch of the residual's
    size."""
    out = meas[row]
    out[C_BETA_PRED] = math.nan
    if out[C_REASON] != R_FITTED:
        return
    if out[C_KIND] == K_MAP:  # the map fitted to g_{k+1} = R g_k is R itself
        rho = rho_R if rho_R == rho_R else spectral_radius_of(R)
        out[C_BETA_PRED] = -math.log(rho) / h
        return
    ng = alpha.shape[0]
    ladder_clear(lt, j)
    nrm = 0.0
    for i in range(ng):
        g[i] = alpha[i]
        nrm = max(nrm, abs(g[i]))
    base[j] = ladder_base(nrm)
    t_hi = out[C_FIT_END]
    last = min(nsteps, int(math.ceil(t_hi / h - 1e-9)) + 1)
    for k in range(last + 1):
        if k > 0:
            nrm = 0.0
            for r in range(ng):
                s = 0.0
                for c in range(ng):
                    s += R[r, c] * g[c]
                gn[r] = s
            for r in range(ng):
                g[r] = gn[r]
                nrm = max(nrm, abs(gn[r]))
        if nrm < math.inf:
            lev = ladder_level(nrm, base[j])
            lt[j, lev] = k * h
            lv[j, lev] = nrm
    n = records(lt, lv, j, rt, ry)
    out[C_BETA_PRED] = refit(rt, ry, n, out[C_FIT_START], t_hi, out[C_KIND], h, a, b, lg,
                             out[C_SHIFT])  # fmt: skip


# --------------------------------------------------------------------- one-step map
@njit(cache=True)
def map_buffers(rows, ng, pm):
    """The one-step map's sums for ``rows`` members at a time: per member and bin ``b``
    the sums of the pairs' outer products and their number (:func:`map_width` columns)
    over the pairs ``(g_k, g_{k+1})`` with ``g_k`` before the member's measured norm
    first fell below bin ``b`` (below ladder level ``b · 2^MAP_SHIFT``): the pairs of the
    transient above that level, none of the floor's once the floor lies below it.

    (Binned by when rather than by each pair's level, so that a member adds to its bins
    once per bin crossed: a residual on its floor moves between levels at random, and
    a member that moved its sums at every change of bin did so at every few measured
    states, about a fifth of the measurement's cost on the pendulum.)"""
    return np.zeros((rows, MAP_BINS, map_width(ng, pm)))


@njit(cache=True)
def map_width(ng, pm):
    """The one-step map's sums per bin.

    With ``pm ≥ 0`` the law acts alike on each of the ``pm`` holonomic constraints (one
    2 × 2 block on every ``(f_i, ḟ_i)``) and on each nonholonomic one (one number on
    every ``h_j``): the pairs of all constraints are pooled into one 2 × 2 and one 1 × 1
    fit (11 sums).  Otherwise the full ``ng × ng`` map is fitted (``2 ng² + 1`` sums),
    for residuals of at most ``MAP_MAX_NG`` components (none above)."""
    if pm >= 0:
        return 11
    return 2 * ng * ng + 1 if ng <= MAP_MAX_NG else 0


@njit(cache=True)
def map_begin(S, j):
    """Clear slot ``j``'s sums for a new member."""
    for b in range(S.shape[1]):
        for c in range(S.shape[2]):
            S[j, b, c] = 0.0


def _trailing_zeros_python(x):
    return (int(x) & -int(x)).bit_length() - 1


trailing_zeros = _trailing_zeros_python if config.DISABLE_JIT else _numba_trailing_zeros
trailing_zeros.__doc__ = """The index of the lowest set bit of a non-zero int64."""


def full_rows(ng: int) -> int:
    """The rows of the full one-step map's running sums (:func:`pairs_full`) for a residual
    of ``ng`` components: Σ p pᵀ's upper triangle, Σ p' pᵀ, the count; 1 when
    ``ng > MAP_MAX_NG`` (no full map)."""
    return ng * (ng + 1) // 2 + ng * ng + 1 if ng <= MAP_MAX_NG else 1


# The decay measurement of a block of members in lockstep (the ensemble kernel's): what
# :func:`observe` and the one-step map's sums do member by member, here for the whole block
# at once, in loops over its members (structure of arrays, member index innermost: they
# vectorize), with the scattered writes deferred:
#
# * the ladder: each member's level (``block_levels``, vectorized), then the time and norm
#   written on it (by the kernel, a scatter);
# * the one-step map: the pairs' running sums in ``A`` (a row per sum, the symmetric
#   ``Σ p pᵀ`` once), copied to the member's row of ``S`` for each bin its level goes below
#   for the first time (``bin_flush``: a scalar loop over the members whose bit is set in
#   the mask ``block_levels`` returns; a member crosses each bin once, where a flush at
#   every change of bin came at every few measured states of a residual on its floor), and
#   at the end for the bins it never went below (``end_flush``);
# * the largest norms of the current fifth of the run in ``wmax`` and ``dmax``, written to
#   the member's row when the fifth ends or the member stops (``windows_flush``).
#
# The ladder is :func:`observe`'s; bin ``b`` of the map's sums holds the pairs whose first
# state came before the member's level first went below bin ``b`` (:func:`map_buffers`).
# The block's size, the residual's and the constraints' come from the arrays' shapes and
# the arguments, not from a closure: a closure per model was compiled on its own at each
# new model's first ensemble (about a second in all).  Compiled once for every model
# (cached) and inlined into the kernel, whose buffers have constant shapes.  (The
# ladder's scatter is written in the kernel itself, and the full map's pairs and flushes
# are closures, :func:`pairs_full_for` and :func:`flushes_for`: optimized on their own
# over unknown sizes first, the scatter lost its vectorization and the copies their
# unrolling, the pendulum's kernel 25 % and the double pendulum's 5 % slower.)


@njit(cache=True, forceinline=True, error_model="numpy")
def difference_norms(Dv, gr, gn, dn):
    """The block's residuals ``Dv`` (``g``, one column per slot) made ``g − gr``; their
    norms ``‖g‖∞`` into ``gn`` and ``‖g − gr‖∞`` into ``dn``."""
    ng, B = Dv.shape
    for j in range(B):
        gn[j] = 0.0
        dn[j] = 0.0
    for l in range(ng):
        r = gr[l]
        for j in range(B):
            g = Dv[l, j]
            d = g - r
            Dv[l, j] = d
            gn[j] = max(gn[j], abs(g))
            dn[j] = max(dn[j], abs(d))


@njit(cache=True, forceinline=True, error_model="numpy")
def pairs_pooled(Dv, P, A, w, pm):
    """The pairs (``P``: the previous measured residuals, ``Dv``: the current; their first
    ``2 pm`` rows ``(f, ḟ)``, ``pm`` the holonomic constraints) added with weight ``w`` (0:
    no previous one yet) to the pooled sums (10 rows: Σ p pᵀ's 3, Σ p' pᵀ's 4 over
    ``p = (f_i, ḟ_i)``, Σ h², Σ h' h, the count); then ``P = Dv``."""
    ng, B = Dv.shape
    for i in range(pm):
        for j in range(B):
            a0 = P[i, j]
            a1 = P[pm + i, j]
            c0 = Dv[i, j]
            c1 = Dv[pm + i, j]
            A[0, j] += w * (a0 * a0)
            A[1, j] += w * (a0 * a1)
            A[2, j] += w * (a1 * a1)
            A[3, j] += w * (c0 * a0)
            A[4, j] += w * (c0 * a1)
            A[5, j] += w * (c1 * a0)
            A[6, j] += w * (c1 * a1)
    for i in range(2 * pm, ng):
        for j in range(B):
            A[7, j] += w * (P[i, j] * P[i, j])
            A[8, j] += w * (Dv[i, j] * P[i, j])
    for j in range(B):
        A[9, j] += w
    for l in range(ng):
        for j in range(B):
            P[l, j] = Dv[l, j]


@njit(cache=True, forceinline=True, error_model="numpy")
def block_levels(gn, dn, base, low, nlev, wmax, dmax):
    """The block's norms ``gn`` (of ``g``) and ``dn`` (measured) at a state: the largest of
    the fifth, each slot's ladder level into ``nlev`` (``NBINS``, the ladder's spare
    column, for a non-finite norm, which :func:`observe` leaves out); returns a mask of
    the slots whose level went below ``low``, the lowest of the map's bins they had
    reached (at most 64 slots)."""
    changed = 0
    for j in range(gn.shape[0]):
        v = gn[j]
        wm = wmax[j]
        wmax[j] = v if (v < math.inf and not (wm >= v)) else wm
        d = dn[j]
        ok = d < math.inf
        dm = dmax[j]
        dmax[j] = d if (ok and not (dm >= d)) else dm
        b = ladder_level(d, base[j])
        nlev[j] = b if ok else NBINS
        lower = ok and (b >> MAP_SHIFT) < low[j]
        changed |= (1 if lower else 0) << j
    return changed


@njit(cache=True, forceinline=True)
def _store(S, A, j, bin_, pooled, full):
    """Slot ``j``'s sums so far as those of its bin ``bin_`` (``pooled ≥ 0``: the pooled
    map's; else the full map's of ``full`` components, none when 0)."""
    if pooled >= 0:
        S[j, bin_, 0] = A[0, j]
        S[j, bin_, 1] = A[1, j]
        S[j, bin_, 2] = A[1, j]
        S[j, bin_, 3] = A[2, j]
        for c in range(4):
            S[j, bin_, 4 + c] = A[3 + c, j]
        S[j, bin_, 8] = A[7, j]
        S[j, bin_, 9] = A[8, j]
        S[j, bin_, 10] = A[9, j]
    elif full:
        c = 0
        for r in range(full):
            for q in range(r, full):
                S[j, bin_, r * full + q] = A[c, j]
                if q != r:
                    S[j, bin_, q * full + r] = A[c, j]
                c += 1
        for r in range(full * full):
            S[j, bin_, full * full + r] = A[c, j]
            c += 1
        S[j, bin_, 2 * full * full] = A[c, j]


@njit(cache=True, error_model="numpy")
def bin_flush(S, A, nlev, low, mask, pooled, full):
    """The slots of the set bits of ``mask``, whose level went below the lowest bin they
    had reached: their sums so far (the pair just added, from a state above, included)
    become those of each bin passed, down to the new one's, which is then the lowest
    (``pooled``, ``full``: :func:`_store`)."""
    while mask != 0:
        j = trailing_zeros(mask)
        mask &= mask - 1
        nb = nlev[j] >> MAP_SHIFT
        for b in range(nb + 1, low[j] + 1):
            _store(S, A, j, b, pooled, full)
        low[j] = nb


@njit(cache=True, error_model="numpy")
def end_flush(S, A, low, active, pooled, full):
    """At the end of the run: each running slot's sums as those of the bins it did not go
    below."""
    for j in range(low.shape[0]):
        if active[j]:
            for b in range(low[j] + 1):
                _store(S, A, j, b, pooled, full)


@njit(cache=True, error_model="numpy")
def windows_flush(meas, wmax, dmax, window, active, lo, cnt):
    """The largest norms of fifth ``window`` so far to the rows of the running members;
    then cleared."""
    for j in range(cnt):
        if active[j]:
            row = lo + j
            c = C_W0 + window
            if wmax[j] > -math.inf and not (meas[row, c] >= wmax[j]):
                meas[row, c] = wmax[j]
            if window >= 2:
                c = C_D2 + window - 2
                if dmax[j] > -math.inf and not (meas[row, c] >= dmax[j]):
                    meas[row, c] = dmax[j]
    for j in range(wmax.shape[0]):
        wmax[j] = -math.inf
        dmax[j] = -math.inf


def pairs_full_for(B: int, ng: int):
    """As :func:`pairs_pooled` for the full map of ``ng`` components over blocks of ``B``
    slots, ``pairs(Dv, P, A, w)`` (``A``: :func:`full_rows` rows): Σ p pᵀ (upper
    triangle), Σ p' pᵀ, the count.  A closure over the sizes, compiled per kernel that
    uses it: sized by its arrays and optimized on its own, its 2 ng² short loops each
    checked their arrays for overlap at run time (the double pendulum's RK4 ensemble 5 %
    slower)."""

    @njit(forceinline=True, error_model="numpy")
    def pairs_full(Dv, P, A, w):
        c = 0
        for r in range(ng):
            for q in range(r, ng):
                for j in range(B):
                    A[c, j] += w * (P[r, j] * P[q, j])
                c += 1
        for r in range(ng):
            for q in range(ng):
                for j in range(B):
                    A[c, j] += w * (Dv[r, j] * P[q, j])
                c += 1
        for j in range(B):
            A[c, j] += w
        for l in range(ng):
            for j in range(B):
                P[l, j] = Dv[l, j]

    return pairs_full


def flushes_for(FULL: int):
    """``(bin_flush, end_flush)`` for a kernel whose one-step map is the full one of
    ``FULL`` components: closures over it (the full map's copy of a slot's sums, sized
    at run time in :func:`bin_flush`, made the double pendulum's RK4 ensemble with a
    full law matrix 5 % slower than this unrolled one).  For ``FULL = 0`` (the pooled
    map, or none) :func:`bin_flush` and :func:`end_flush` themselves, compiled once for
    every model.  Both take ``(…, pooled, full)`` as those do."""
    if not FULL:
        return bin_flush, end_flush

    @njit(forceinline=True)
    def _store_full(S, A, j, bin_):
        c = 0
        for r in range(FULL):
            for q in range(r, FULL):
                S[j, bin_, r * FULL + q] = A[c, j]
                if q != r:
                    S[j, bin_, q * FULL + r] = A[c, j]
                c += 1
        for r in range(FULL * FULL):
            S[j, bin_, FULL * FULL + r] = A[c, j]
            c += 1
        S[j, bin_, 2 * FULL * FULL] = A[c, j]

    @njit(error_model="numpy")
    def bin_flush_full(S, A, nlev, low, mask, pooled, full):
        while mask != 0:
            j = trailing_zeros(mask)
            mask &= mask - 1
            nb = nlev[j] >> MAP_SHIFT
            for b in range(nb + 1, low[j] + 1):
                _store_full(S, A, j, b)
            low[j] = nb

    @njit(error_model="numpy")
    def end_flush_full(S, A, low, active, pooled, full):
        for j in range(low.shape[0]):
            if active[j]:
                for b in range(low[j] + 1):
                    _store_full(S, A, j, b)

    return bin_flush_full, end_flush_full


@njit(cache=True)
def _cluster_radius(moduli, n):
    """The largest modulus, or the geometric mean of those within ``CLUSTER`` of it in
    rate (``ln`` of the modulus): a repeated eigenvalue (a Jordan block, as critically
    damped laws give) splits by the square root of a perturbation of the matrix, its
    mean by the perturbation itself."""
    top = 0.0
    for i in range(n):
        top = max(top, moduli[i])
    if not (top > 0.0) or top == math.inf:
        return top
    width = CLUSTER * abs(math.log(top))
    logs = 0.0
    count = 0
    for i in range(n):
        if moduli[i] > 0.0 and math.log(top / moduli[i]) <= width:
            logs += math.log(moduli[i])
            count += 1
    return math.exp(logs / count)


@njit(cache=True)
def _radius2(r00, r01, r10, r11):
    """:func:`spectral_radius_of` of the 2 × 2 matrix ``[[r00, r01], [r10, r11]]`` in
    closed form, without arrays (NaN for non-finite entries)."""
    half = 0.5 * (r00 + r11)
    det = r00 * r11 - r01 * r10
    disc = half * half - det
    if disc < 0.0:
        return math.sqrt(det)
    big = abs(half + math.sqrt(disc))
    small = abs(half - math.sqrt(disc))
    if big < small:
        big, small = small, big
    if not (big > 0.0) or big == math.inf or not (small > 0.0):
        return big
    if math.log(big / small) <= CLUSTER * abs(math.log(big)):  # as _cluster_radius
        return math.sqrt(big * small)
    return big


@njit(cache=True)
def spectral_radius_of(R):
    """``ρ(R)`` of a small real matrix (closed form up to 2 × 2), where eigenvalues of
    nearly the same modulus count as one repeated eigenvalue (:func:`_cluster_radius`):
    the rate an ensemble measures from a fitted map, and the one a finite run shows."""
    n = R.shape[0]
    if n == 1:
        return abs(R[0, 0])
    if n == 2:
        return _radius2(R[0, 0], R[0, 1], R[1, 0], R[1, 1])
    for i in range(n):
        for q in range(n):
            if not math.isfinite(R[i, q]):
                return math.nan
    # complex input: numba's real eigvals refuses complex eigenvalues
    lam = np.linalg.eigvals(R.astype(np.complex128))
    moduli = np.empty(n)
    for i in range(n):
        moduli[i] = abs(lam[i])
    return _cluster_radius(moduli, n)


@njit(cache=True)
def _pooled_radius(S, j, first):
    """``ρ`` of the pooled fits (:func:`map_buffers`): the larger of the 2 × 2 map of
    the ``(f_i, ḟ_i)`` pairs and the 1 × 1 map of the ``h_j``, each where it has data,
    from the pairs of bin ``first`` (those before the level first fell below it); the
    number of pairs."""
    s = stack1(11)
    for c in range(11):
        s[c] = S[j, first, c] if first < S.shape[1] else 0.0
    rho = -1.0
    det = s[0] * s[3] - s[1] * s[2]
    if s[0] > 0.0 and s[3] > 0.0 and abs(det) > 1e-14 * s[0] * s[3]:  # S1 S0⁻¹
        rho = _radius2((s[4] * s[3] - s[5] * s[2]) / det, (s[5] * s[0] - s[4] * s[1]) / det,
                       (s[6] * s[3] - s[7] * s[2]) / det, (s[7] * s[0] - s[6] * s[1]) / det)
    if s[8] > 0.0:
        rho = max(rho, abs(s[9] / s[8]))
    return (rho if rho >= 0.0 else math.nan), s[10]


@njit(cache=True)
def _map_radius(S, j, ng, first):
    """``ρ`` of the least-squares one-step map ``R̂ = S1 S0⁻¹`` from bin ``first`` of
    slot ``j`` (the pairs before its level first fell below that bin), on the directions
    its pairs span, and the number of pairs; NaN with fewer than ``2 ng`` pairs."""
    S0 = np.zeros((ng, ng))
    S1 = np.zeros((ng, ng))
    pairs = 0.0
    if first < S.shape[1]:
        c = 0
        for r in range(ng):
            for q in range(ng):
                S0[r, q] = S[j, first, c]
                c += 1
        for r in range(ng):
            for q in range(ng):
                S1[r, q] = S[j, first, c]
                c += 1
        pairs = S[j, first, c]
    if pairs < 2.0 * ng:
        return math.nan, pairs
    # Whitened (each component scaled to unit sum of squares) and restricted to the
    # directions the pairs span: Baumgarte's law acts alike on every constraint, so the
    # residual of m constraints moves in a plane of its 2m dimensions, and a fit over all
    # of them gives the remaining directions the floor's dynamics.
    w = np.zeros(ng)
    for r in range(ng):
        if S0[r, r] > 0.0:
            w[r] = 1.0 / math.sqrt(S0[r, r])
    for r in range(ng):
        for q in range(ng):
            S0[r, q] *= w[r] * w[q]
            S1[r, q] *= w[r] * w[q]
    lam, U = np.linalg.eigh(S0)
    top = lam[ng - 1]
    if not (top > 0.0):
        return math.nan, pairs
    keep = 0
    for i in range(ng):
        if lam[i] >= MAP_RANK_TOL * top:
            keep += 1
    V = np.ascontiguousarray(U[:, ng - keep:])
    # R̂ on that subspace: (Vᵀ S1 V)(Vᵀ S0 V)⁻¹, Vᵀ S0 V the kept eigenvalues
    Rr = np.ascontiguousarray(V.T) @ S1 @ V
    for q in range(keep):
        for r in range(keep):
            Rr[r, q] /= lam[ng - keep + q]
    return spectral_radius_of(Rr), pairs


@njit(cache=True, error_model="numpy")
def _map_gamma(lt, lv, j, lo, top, beta, u):
    """``γ = max ‖g(t)‖ e^{βt}`` over the envelope's points on levels ``lo … top`` of
    ladder row ``j``, and the latest time on them (``u``: scratch of ``NBINS``).

    Taken over every visited level, not only the envelope's: a level's last visit that
    is not on the envelope has a higher level visited later, whose larger norm at a later
    time gives a larger product (β > 0), so the maximum is the same.  Without the
    envelope's running comparison, and with ``ln ‖g‖ + βt`` computed in a loop of its own
    (branch-free: it vectorizes) and the exponential taken once, of the largest (it is
    monotone), this costs a fraction of the envelope's loop with an exponential per
    point, which was most of the cost of a member's end.  (A zero or subnormal norm,
    where :func:`log_normal` does not hold, is left out: a zero's product is zero, and a
    subnormal one, below 1e-308, lies on the ladder's bottom level, far under any
    transient.)

    The levels are indexed unsigned: numba wraps a negative index around, and an index
    that may be negative (``lo`` is not known to be ≥ 0) turns every load of the
    vectorized loop into a gather and its store into a scatter (2.6× the time of the
    whole pass, 231 levels).  The maxima are kept in eight running ones (a single one
    is a chain of dependent comparisons); the maximum of a set is the same in any
    order."""
    lo = max(lo, 0)
    ltj = lt[j]
    lvj = lv[j]
    for i in range(top + 1 - lo):
        b = np.uint64(lo + i)
        t = ltj[b]
        v = lvj[b]
        ok = (t >= 0.0) & (v >= _TINY) & (v < math.inf)
        u[b] = (log_normal(v if ok else 1.0) + beta * t) if ok else -math.inf
    acc = stack1(16)  # eight running maxima of the products, eight of the times
    for i in range(8):
        acc[i] = -math.inf
        acc[8 + i] = -1.0
    b0 = lo
    while b0 + 8 <= top + 1:
        for i in range(8):
            b = np.uint64(b0 + i)
            acc[i] = max(acc[i], u[b])
            acc[8 + i] = max(acc[8 + i], ltj[b])
        b0 += 8
    best = -math.inf
    t_end = -1.0
    for i in range(8):
        best = max(best, acc[i])
        t_end = max(t_end, acc[8 + i])
    for b in range(b0, top + 1):
        best = max(best, u[b])
        t_end = max(t_end, ltj[b])
    return (math.exp(best) if best > -math.inf else 0.0), t_end


@njit(cache=True)
def map_estimate(S, j, ng, pm, lt, lv, base_j, meas, row, tau, rt, ry, lowest=0):
    """β of member ``row`` from its one-step map, replacing the envelope's fit.

    The residual's pairs ``(g_k, g_{k+1})``, all of them when the run ended while it was
    still decaying (``MAP_STILL_DECAYING``), else those from its start until its level
    first fell below ``MAP_MARGIN`` (then ``FLOOR_MARGIN``) times its floor (rounded up
    to a bin of :func:`map_buffers`), give ``R̂`` by least squares; ``β = −ln ρ(R̂)/τ``.
    For a residual that follows ``g_{k+1} = R g_k`` this is ``−ln ρ(R)/τ`` exactly,
    whatever the window, the modes' mix or a repeated eigenvalue's polynomial prefactor,
    where a fit of the norm's envelope over a short transient is biased.  The pairs must
    span a decade (``MIN_DECADES``) above the cut; a member without such pairs, or whose
    map is singular or has ``ρ ≥ 1``, is left to the envelope's fit
    (:func:`fit_envelope`).
    ``lowest``: no level below it was visited (γ's pass starts there).  Returns whether
    it gave β."""
    out = meas[row]
    if S.shape[2] == 0:
        return False
    floor = out[C_D4]
    still = (out[C_D2] > out[C_D3] > out[C_D4]
             and out[C_D2] >= MAP_STILL_DECAYING * out[C_D4])  # fmt: skip
    top = -1
    for b in range(NBINS - 1, -1, -1):
        if lt[j, b] >= 0.0:
            top = b
            break
    per_decade = LEVELS_PER_OCTAVE * math.log2(10.0) * MIN_DECADES
    for margin in (-1.0, MAP_MARGIN, FLOOR_MARGIN):
        if margin < 0.0:  # still decaying: the last fifth's largest norm is no floor
            if not still:
                continue
            cut = 0
        elif floor > 0.0:
            cut = ladder_level(margin * floor, base_j) + 1
        else:
            cut = 0
        if top - cut < per_decade:
            continue
        first = (cut + (1 << MAP_SHIFT) - 1) >> MAP_SHIFT  # bins wholly above the cut
        rho, pairs = _pooled_radius(S, j, first) if pm >= 0 else _map_radius(S, j, ng, first)
        if not (rho < 1.0 and rho > 0.0):
            return False
        beta = -math.log(rho) / tau
        gamma, t_end = _map_gamma(lt, lv, j, max(first << MAP_SHIFT, lowest), top, beta, ry)
        out[C_BETA] = beta
        out[C_GAMMA] = gamma
        out[C_FIT_START] = 0.0
        out[C_FIT_END] = t_end
        out[C_POINTS] = pairs
        out[C_KIND] = K_MAP
        out[C_SHIFT] = math.nan
        out[C_REASON] = R_FITTED
        return True
    return False


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


# --------------------------------------------------------------------- stored traces
@njit(nogil=True, cache=True)
def _measure_rows(norms, times, meas, R, alphas, lo, hi):
    lt, lv, base = ladders(1)
    rt, ry, a, b, lg = scratch()
    T = norms.shape[1]
    span = times[T - 1] - times[0]
    dt = times[1] - times[0] if T > 1 else 1.0
    g = np.empty(alphas.shape[1])
    gn = np.empty(alphas.shape[1])
    for r in range(lo, hi):
        begin(lt, lv, base, meas, 0, r, norms[r, 0], norms[r, 0])
        last = norms[r, 0]
        stopped = False
        for i in range(1, T):
            v = norms[r, i]
            if not math.isfinite(v):
                stopped = True
                break
            w = min(4, int(5.0 * (times[i] - times[0]) / span)) if span > 0.0 else 4
            observe(lt, lv, base, meas, 0, r, times[i] - times[0], v, v, w)
            last = v
        finish(lt, lv, meas, 0, r, last, stopped, dt, rt, ry, a, b, lg)
        if R.shape[0] > 0:
            predict(R, alphas[r], T - 1, dt, lt, lv, base, meas, 0, r, rt, ry, a, b, lg,
                    g, gn)  # fmt: skip


def measure_traces(norms, times, R=None, alpha0=None):
    """The measures of :data:`COLUMNS` for stored traces, each sample taken as a step.

    Parameters
    ----------
    norms : array (members, samples)
        ``‖g(t_i)‖``; a non-finite sample ends the trace (a stop).
    times : array (samples,)
        Uniformly spaced sample times.
    R, alpha0 : arrays (ng, ng) and (members, ng), optional
        The one-sample propagator of the linear prediction and each member's ``g(t_0)``:
        fills ``beta_predicted``.

    Returns
    -------
    array (members, len(COLUMNS))
    """
    norms = np.ascontiguousarray(np.atleast_2d(norms), dtype=np.float64)
    times = np.ascontiguousarray(times, dtype=np.float64)
    M = norms.shape[0]
    R = np.zeros((0, 0)) if R is None else np.ascontiguousarray(R, dtype=np.float64)
    alphas = (np.zeros((M, 1)) if alpha0 is None
              else np.ascontiguousarray(np.atleast_2d(alpha0), dtype=np.float64))  # fmt: skip
    meas = np.empty((M, NCOLS))
    run_chunks(lambda lo, hi: _measure_rows(norms, times, meas, R, alphas, lo, hi), M)
    return meas
