"""Decay-rate estimation from stored residual traces.

For each member, ``‖g(t)‖`` first decays at the rate of the law (continuous: ``−max Re λ(Ã)``;
discrete: ``−ln ρ(R(τÃ))/τ``) and then settles on a floor set by the scheme's local error
(the paper's §5).  The estimator

1. takes the floor as the median of the last fifth of the trace;
2. takes the upper envelope of the norm from the right (running maximum) and keeps only
   the samples that lie on it, so that the dips of an oscillating residual do not drag
   the fit down;
3. keeps the transient: the samples from the start until the envelope first comes within
   a factor 1000 of the floor (100, then ``FLOOR_MARGIN`` = 30 when that leaves fewer than
   8 samples; the whole trace if it never does): the floor is a forced response that
   bends the trace well above its own level.  An oscillating residual (under-damped laws:
   ``OSCILLATING_PEAKS`` peaks or more above 30× the floor) is fitted on its peaks only
   (the widest margin that leaves that many), which lie on ``c e^{−βt}``; the rest of its
   envelope is descending arcs, steeper than the decay;
4. the fit window is the later part of the transient (after ``LEAD_FRACTION`` of its
   decades), where faster modes have died out; it fits ``log ‖g‖ ≈ a − β t`` and (not for
   an oscillating residual) ``log ‖g‖ ≈ a − β t + ν log(t + s)`` by least squares,
   ``s`` found by a grid search refined by Brent's method, and keeps the fit with the
   smallest residual.  The ``ν log(t + s)`` term absorbs the
   polynomial prefactor of repeated eigenvalues: critically damped Baumgarte decays like
   ``|c0 + c1 t| e^{−ωt}`` (Euler's ``R(τÃ)`` is then a Jordan block, ``‖g_k‖ ~ |a + bk| ρ^k``),
   i.e. ``log ‖g‖ = log c1 − ωt + log(t + c0/c1)`` with a member-dependent shift, negative
   when ``c0 + c1 t`` crosses zero before the fit window (the grid covers both signs);
5. reports ``γ = max_t ‖g(t)‖ e^{βt}`` over the transient, the smallest prefactor with
   ``‖g(t)‖ ≤ γ e^{−βt}`` there.

Members with fewer than ``MIN_SAMPLES`` transient samples get ``β = γ = NaN``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .threads import run_chunks

FLOOR_MARGIN = 30.0
MIN_SAMPLES = 4
N_SHIFTS = 16
#: Brent's search for the shift stops within this fraction of its bracket (two grid steps)
BRENT_TOL = 3e-5
LEAD_FRACTION = 0.3
#: a transient with this many peaks is oscillating and fitted on its peaks (_peak_pass)
OSCILLATING_PEAKS = 3
#: a peak rises this many times above the trace's lowest sample since the previous peak
PEAK_RISE = 1.1


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
def _median(a, n):
    """Median of ``a[:n]`` (the mean of the middle two for even ``n``), reordering ``a``
    in place: Hoare's selection, O(n), the same value as sorting (a sort was a third of
    the fit's time)."""
    k = n // 2
    lo, hi = 0, n - 1
    while lo < hi:
        mid = (lo + hi) // 2  # median of three as the pivot
        if a[mid] < a[lo]:
            a[mid], a[lo] = a[lo], a[mid]
        if a[hi] < a[lo]:
            a[hi], a[lo] = a[lo], a[hi]
        if a[hi] < a[mid]:
            a[hi], a[mid] = a[mid], a[hi]
        pivot = a[mid]
        i, j = lo, hi
        while i <= j:
            while a[i] < pivot:
                i += 1
            while a[j] > pivot:
                j -= 1
            if i <= j:
                a[i], a[j] = a[j], a[i]
                i += 1
                j -= 1
        if k <= j:
            hi = j
        elif k >= i:
            lo = i
        else:
            break
    if n % 2 == 1:
        return a[k]
    below = a[0]  # a[:k] holds the k smallest: the lower middle is their largest
    for i in range(1, k):
        below = max(below, a[i])
    return 0.5 * (below + a[k])


@njit(cache=True)
def _fit_linear(env, on_env, times, start, end):
    """Least squares ``env ≈ c − β t`` on samples [start, end); returns (β, SSE)."""
    st = sy = stt = sty = 0.0
    cnt = 0
    for i in range(start, end):
        if not on_env[i]:
            continue
        cnt += 1
        t = times[i] - times[0]
        st += t
        sy += env[i]
        stt += t * t
        sty += t * env[i]
    slope = (cnt * sty - st * sy) / (cnt * stt - st * st)
    icpt = (sy - slope * st) / cnt
    sse = 0.0
    for i in range(start, end):
        if not on_env[i]:
            continue
        r = env[i] - icpt - slope * (times[i] - times[0])
        sse += r * r
    return -slope, sse


@njit(cache=True)
def _fit_with_log(env, on_env, times, start, end, shift, a, b, lg):
    """Least squares ``env ≈ c − β t + ν log(t + shift)`` on [start, end); returns (β, SSE),
    SSE = inf when the normal equations are singular.  ``lg`` is scratch (the logarithms,
    taken once for both passes)."""
    a[:, :] = 0.0
    b[:] = 0.0
    for i in range(start, end):
        if not on_env[i]:
            continue
        t = times[i] - times[0]
        lg[i] = math.log(t + shift)
        r0, r1, r2 = 1.0, -t, lg[i]
        a[0, 0] += r0 * r0
        a[0, 1] += r0 * r1
        a[0, 2] += r0 * r2
        a[1, 1] += r1 * r1
        a[1, 2] += r1 * r2
        a[2, 2] += r2 * r2
        b[0] += r0 * env[i]
        b[1] += r1 * env[i]
        b[2] += r2 * env[i]
    a[1, 0] = a[0, 1]
    a[2, 0] = a[0, 2]
    a[2, 1] = a[1, 2]
    if not _solve3(a, b):
        return math.nan, math.inf
    sse = 0.0
    for i in range(start, end):
        if not on_env[i]:
            continue
        t = times[i] - times[0]
        r = env[i] - b[0] + b[1] * t - b[2] * lg[i]
        sse += r * r
    return b[1], sse


@njit(cache=True)
def _peak_pass(norm, on_env, end, apply):
    """Count the peaks of the transient ``norm[:end]``: samples on the upper envelope
    that the trace reaches by rising at least ``PEAK_RISE`` times above its lowest
    sample since the previous peak (not a wiggle of the floor).  With ``apply``, the
    other samples are taken off the envelope.

    The peaks of an oscillating residual lie on ``c e^{−βt}`` up to the sampling of the
    period; the rest of its envelope is descending arcs, steeper than ``e^{−βt}``, which
    pulled the fit off by up to a factor of several (under-damped Baumgarte, ξ = 0.7).
    A decay without oscillation has at most one such peak per component of ``g``."""
    count = 0
    low = math.inf
    for i in range(1, end):
        low = min(low, norm[i - 1])
        peak = on_env[i] and norm[i] >= norm[i - 1] and norm[i] >= PEAK_RISE * low
        if peak:
            count += 1
            low = math.inf
        if apply:
            on_env[i] = peak
    if apply:
        on_env[0] = False
    return count


@njit(cache=True)
def _transient_end(env, nvalid, level):
    """The first sample (from 1) at which the envelope is down to ``level``; ``nvalid``
    when it never is."""
    for i in range(1, nvalid):
        if env[i] <= level:
            return i
    return nvalid


@njit(cache=True)
def _brent(env, on_env, times, start, end, t_w, lo_u, hi_u, x, fx, bx, a, b, lg):
    """Brent's minimization (parabolic steps, golden sections when they fail) of the
    ``ν log(t + s)`` fit's SSE over ``u = log(s + t_w)`` in ``[lo_u, hi_u]``, from the
    grid's best point ``x`` (SSE ``fx``, β ``bx``), to ``BRENT_TOL`` of the bracket.
    Returns the smallest SSE seen and its β.  (Golden sections alone took 22 fits to a
    comparable bracket; the fit's time is mostly these fits' logarithms.)"""
    CG = 0.3819660112501051
    tol1 = BRENT_TOL * (hi_u - lo_u)
    tol2 = 2.0 * tol1
    lo, hi = lo_u, hi_u
    w = v = x
    fw = fv = fx
    d = e = 0.0
    best, beta = fx, bx
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
        bu, fu = _fit_with_log(env, on_env, times, start, end, math.exp(u) - t_w, a, b, lg)
        if fu < best:
            best, beta = fu, bu
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
    return best, beta


@njit(cache=True)
def _fit_one(norm, nvalid, times, env, on_env, tail, lg, a, b, out):
    """Fit one trace; writes (β, γ, floor, transient samples) into ``out``.  ``env``,
    ``on_env``, ``tail``, ``lg`` (samples), ``a`` (3 × 3) and ``b`` (3) are scratch.
    Returns the largest of ``norm[:nvalid]`` (−inf when ``nvalid`` is 0)."""
    out[0] = math.nan
    out[1] = math.nan
    out[2] = math.nan
    out[3] = 0.0
    if nvalid < 2:
        return norm[0] if nvalid == 1 else -math.inf
    ntail = min(max(3, nvalid // 5), nvalid)
    for i in range(ntail):
        tail[i] = norm[nvalid - ntail + i]
    floor = _median(tail, ntail)
    out[2] = floor
    # upper envelope of ‖g‖ from the right: non-increasing, blind to the dips of an
    # oscillating residual; its logarithm is taken below, on the transient only
    top = -math.inf  # the largest sample so far
    for i in range(nvalid - 1, -1, -1):
        y = norm[i]
        on_env[i] = y >= top  # a "record" from the right: on the upper hull of the trace
        top = max(top, y)
        env[i] = top
    largest = top
    # transient: until the envelope comes within a margin of the floor.  The floor is a
    # forced response, not noise, and bends the trace well above it: take the widest
    # margin (1000, 100, then FLOOR_MARGIN) that still leaves 8 samples, or for an
    # oscillating residual (OSCILLATING_PEAKS peaks above the narrowest) that many peaks,
    # and fit an oscillating one on its peaks only (_peak_pass).
    oscillating = _peak_pass(norm, on_env, _transient_end(env, nvalid, FLOOR_MARGIN * floor),
                             False) >= OSCILLATING_PEAKS  # fmt: skip
    end = nvalid
    for margin in (1000.0, 100.0, FLOOR_MARGIN):
        end = _transient_end(env, nvalid, margin * floor)
        if oscillating:
            if _peak_pass(norm, on_env, end, False) >= OSCILLATING_PEAKS:
                break
        elif end >= 8:
            break
    out[3] = end
    if oscillating:
        _peak_pass(norm, on_env, end, True)
    for i in range(end):  # the fits work on log ‖g‖
        env[i] = math.log(env[i]) if env[i] > 0.0 else -math.inf
    if end < MIN_SAMPLES or not math.isfinite(env[end - 1]):
        return largest
    # fit window: the later part of the transient, after LEAD_FRACTION of its decades,
    # where faster modes have died out and the decay runs at the asymptotic rate
    cut = env[0] - LEAD_FRACTION * (env[0] - env[end - 1])
    start = 0
    for i in range(end):
        if env[i] <= cut:
            start = i
            break
    npts = 0
    for i in range(start, end):
        npts += on_env[i]
    while npts < MIN_SAMPLES and start > 0:
        start -= 1
        npts += on_env[start]
    if npts < 2:
        return largest
    dt = times[1] - times[0]
    span = times[end - 1] - times[0]
    # plain exponential (ν = 0), then ν log(t + s) over a log-spaced grid of shifts s
    beta, best = _fit_linear(env, on_env, times, start, end)
    if npts >= 6 and not oscillating:  # (the peaks lie on e^{−βt}: ν log would fit jitter)
        # shifts s = e^u − t_w over (−t_w, ∞), t_w the window's first time: a negative s
        # puts a zero crossing of c0 + c1 t just before the window.  Grid in u, then a
        # refinement by Brent's method around the best grid point.
        t_w = times[start] - times[0]
        lo = math.log(0.25 * dt)
        hi = math.log(t_w + 4.0 * span + dt)
        step_u = (hi - lo) / (N_SHIFTS - 1)
        k_best = -1
        for k in range(N_SHIFTS):
            u = lo + k * step_u
            bk, sse = _fit_with_log(env, on_env, times, start, end, math.exp(u) - t_w, a, b, lg)
            if sse < best:
                best, beta, k_best = sse, bk, k
        if k_best >= 0:
            ua = lo + max(k_best - 1, 0) * step_u
            ub = lo + min(k_best + 1, N_SHIFTS - 1) * step_u
            best, beta = _brent(env, on_env, times, start, end, t_w, ua, ub,
                                lo + k_best * step_u, best, beta, a, b, lg)
    gamma = 0.0
    for i in range(end):
        g = norm[i] * math.exp(beta * (times[i] - times[0]))
        if g > gamma:
            gamma = g
    out[0] = beta
    out[1] = gamma
    return largest


@njit(nogil=True, cache=True)
def summarize_rows(norms, times, r0, r1, nvalid, largest, last, fit, do_fit):
    """Rows ``r0 … r1 − 1`` of the stored traces ``norms`` (members × samples): the
    number of leading finite samples, the largest finite sample (NaN when the first is
    not finite), the last of the leading finite ones, and with ``do_fit`` the decay fit
    into ``fit[j]`` (β, γ, floor, transient samples).  One thread; the ensemble runs it
    on each chunk of members right after integrating it (:mod:`.threads`)."""
    T = norms.shape[1]
    row = np.empty(T)
    env = np.empty(T)
    on_env = np.empty(T, dtype=np.bool_)
    tail = np.empty(T)
    lg = np.empty(T)
    a = np.empty((3, 3))
    b = np.empty(3)
    for j in range(r0, r1):
        bad = False  # a non-finite sample (one vectorized pass; most traces have none)
        for i in range(T):
            v = norms[j, i]
            row[i] = v
            bad |= not math.isfinite(v)
        n = T
        top = -math.inf
        if bad or not do_fit:
            for i in range(T):
                v = row[i]
                if math.isfinite(v):
                    top = max(top, v)
                elif n == T:
                    n = i
        if do_fit:  # (the fit's envelope gives the largest sample of a finite trace)
            top_fit = _fit_one(row, n, times, env, on_env, tail, lg, a, b, fit[j])
            if not bad:
                top = top_fit
        nvalid[j] = n
        largest[j] = top if n > 0 else math.nan
        last[j] = row[max(n - 1, 0)]


class Summary:
    """Output arrays of :func:`summarize_rows` for ``members`` traces."""

    def __init__(self, members: int):
        self.nvalid = np.empty(members, dtype=np.int64)
        self.largest = np.empty(members)
        self.last = np.empty(members)
        self.fit = np.empty((members, 4))

    def rows(self, norms, times, r0: int, r1: int, do_fit: bool = True) -> None:
        """Summarize (and fit) rows ``r0 … r1 − 1``; releases the GIL."""
        summarize_rows(norms, times, r0, r1, self.nvalid, self.largest, self.last, self.fit,
                       do_fit)  # fmt: skip

    @property
    def beta(self):
        return self.fit[:, 0]

    @property
    def gamma(self):
        return self.fit[:, 1]

    @property
    def floor(self):
        return self.fit[:, 2]


def _summarize(norms, times, do_fit: bool) -> Summary:
    norms = np.ascontiguousarray(np.atleast_2d(norms))
    times = np.ascontiguousarray(times, dtype=np.float64)
    out = Summary(norms.shape[0])
    run_chunks(lambda lo, hi: out.rows(norms, times, lo, hi, do_fit), norms.shape[0])
    return out


def trace_summary(norms):
    """Per trace, in one compiled call: the number of leading finite samples, the largest
    finite sample (NaN when the first is not finite) and the last of the leading finite
    ones.  (Two passes over each row: :func:`summarize_rows` copies it first, for the fit
    it runs without here.)

    The same numbers as ``isfinite`` / ``argmin`` / ``nanmax`` over the whole array, which
    made up most of the time spent after the integration of a large ensemble.
    """
    out = _summarize(norms, np.zeros(1), False)
    return out.nvalid, out.largest, out.last


def fit_decay(norms, times):
    """β, γ, floor and transient length for each trace.

    Parameters
    ----------
    norms : array (members, samples)
        Residual norms ``‖g(t_i)‖`` (float32 or float64); NaN after a divergence (the
        fit uses the leading finite samples).
    times : array (samples,)
        Uniformly spaced sample times.

    Returns
    -------
    beta, gamma, floor, n_transient : arrays (members,)
    """
    fit = _summarize(norms, times, True).fit
    return fit[:, 0], fit[:, 1], fit[:, 2], fit[:, 3].astype(np.int64)
