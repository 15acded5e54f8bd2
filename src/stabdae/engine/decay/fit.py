"""Fits of the decay rate to the envelope points of a ladder: the transient's window,
the exponential fit, the fit with a polynomial prefactor (Brent's search for its shift),
the oscillating envelope, and the growth predicate."""

from __future__ import annotations

import math

from numba import njit

from .ladder import _TINY, log_normal
from .record import (
    C_BETA,
    C_D2,
    C_D3,
    C_D4,
    C_FIT_END,
    C_FIT_START,
    C_GAMMA,
    C_INITIAL,
    C_SHIFT,
    I_KIND,
    I_POINTS,
    I_REASON,
    K_EXPONENTIAL,
    K_NONE,
    K_OSCILLATING,
    K_POLYNOMIAL,
    R_FITTED,
    R_NO_TRANSIENT,
    R_NOT_DECAYING,
)

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
#: a point of the transient enters the fits only above this many times the run's roundoff
#: level, where the run ended still decaying (its last points may lie on that level)
ROUNDOFF_FLOOR = 30.0
#: γ is taken over the points above this many times the roundoff level (or, for a member
#: that starts within ten times that of it, over its first decade): a point carries
#: rounding errors of about that level, absolute, which move the product ``‖g‖ e^{βt}``
#: by their ratio to ``‖g‖``; on the roundoff level itself they would set γ
#: (``level · e^{βt}``, orders of magnitude above the transient's)
GAMMA_MARGIN = 1e6
N_SHIFTS = 16
#: Brent's search for the shift stops within this fraction of its bracket (two grid steps)
BRENT_TOL = 3e-5


# --------------------------------------------------------------------- fits
# (compiled without reference counting, as the member's functions: :mod:`.member`)
@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
def _fit_inverse(rt, ry, start, end):
    """Least squares ``t ≈ a + b y`` on [start, end); returns ``β = −1/b``."""
    _, _, _, sty, syy = _centered_sums(rt, ry, start, end)
    if sty == 0.0:
        return math.nan
    return -syy / sty


@njit(cache=True, _nrt=False)
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


@njit(cache=True, forceinline=True, _nrt=False)
def _residual2(rt, ry, lg, i, c0, c1, c2):
    """The squared residual of point ``i`` of the fit ``y ≈ c0 − c1 t + c2 log(t + s)``."""
    r = ry[i] - c0 + c1 * rt[i] - c2 * lg[i]
    return r * r


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
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


@njit(cache=True, _nrt=False)
def _window(rt, ry, n, floor, still_decaying, noise=0.0):
    """The fit window ``[start, end)`` of the envelope points: the transient (down to a
    margin above the floor, or all points when the run ended still decaying; above
    ``ROUNDOFF_FLOOR`` times the roundoff level ``noise`` in either case) after its
    first ``LEAD_FRACTION`` of decades.  ``end`` is 0 when no window spans
    ``MIN_DECADES`` with ``MIN_POINTS`` points."""
    lnfloor = math.log(floor) if floor > 0.0 else -math.inf
    lnnoise = math.log(ROUNDOFF_FLOOR * noise) if noise > 0.0 else -math.inf
    for margin in (1000.0, 100.0, FLOOR_MARGIN, -1.0):
        if margin < 0.0:
            if not still_decaying:
                break
            end = n
            for i in range(n):
                if ry[i] <= lnnoise:
                    end = i
                    break
        else:
            level = max(lnfloor + math.log(margin), lnnoise)
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


@njit(cache=True, _nrt=False)
def estimate(rt, ry, n, floor, still_decaying, dt, a, b, lg, out, code, noise=0.0):
    """β, γ and the fit's window, kind and shift from the ``n`` envelope points into
    ``out`` and ``code`` (a member's row of the record's floats and integers; ``reason``
    too).  ``noise``: the run's roundoff level (:func:`gamma_of`)."""
    out[C_BETA] = math.nan
    out[C_GAMMA] = math.nan
    out[C_FIT_START] = math.nan
    out[C_FIT_END] = math.nan
    code[I_POINTS] = 0
    code[I_KIND] = K_NONE
    out[C_SHIFT] = math.nan
    if n < 2 or not math.isfinite(ry[0]):
        code[I_REASON] = R_NOT_DECAYING if n < 2 else R_NO_TRANSIENT
        return
    start, end = _window(rt, ry, n, floor, still_decaying, noise)
    if end == 0:
        # no decade of decay above the floor: growing, or started near its floor
        code[I_REASON] = _without_rate(out)
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
    code[I_POINTS] = end - start
    code[I_KIND] = kind
    out[C_SHIFT] = shift
    if not (beta > 0.0):
        code[I_REASON] = _without_rate(out)
        return
    out[C_BETA] = beta
    # (the start is a point of the transient whose level a later visit may hold)
    out[C_GAMMA] = max(gamma_of(rt, ry, end, beta, noise), out[C_INITIAL])
    code[I_REASON] = R_FITTED


@njit(cache=True, _nrt=False)
def _without_rate(out):
    """Why a member's row ``out`` has no rate where its envelope gave none: not decaying
    where its deviation grew over the last three fifths (:func:`grows`) to end at or above
    its start; else no transient.  A deviation that ended below its start decayed (the
    verdicts' ``decayed``), also where it rose again late with its own floor (the
    scheme's coupling of the perturbation to the motion): its decay is what lay too
    close to that floor to be read."""
    if grows(out[C_D2], out[C_D3], out[C_D4]) and not (out[C_D4] < out[C_INITIAL]):
        return R_NOT_DECAYING
    return R_NO_TRANSIENT


@njit(cache=True, _nrt=False)
def gamma_of(rt, ry, end, beta, noise):
    """``γ = max ‖g(t)‖ e^{βt}`` over the envelope points ``[0, end)`` (``ry`` the log
    norms) that lie above ``GAMMA_MARGIN`` times the roundoff level ``noise``, or over
    the first decade (``MIN_DECADES``) of a member that starts within ten times that."""
    cut = -math.inf
    if noise > 0.0:
        cut = min(math.log(GAMMA_MARGIN * noise), ry[0] - MIN_DECADES * math.log(10.0))
    top = ry[0] + beta * rt[0]  # the exponential is monotone: one call, on the largest
    for i in range(1, end):
        if ry[i] >= cut:
            top = max(top, ry[i] + beta * rt[i])
    return math.exp(top)


@njit(cache=True, _nrt=False)
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
