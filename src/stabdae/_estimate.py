"""Decay-rate estimation from stored residual traces.

For each member, ``‖g(t)‖`` first decays at the rate of the law (continuous: ``−max Re λ(Ã)``;
discrete: ``−ln ρ(R(τÃ))/τ``) and then settles on a floor set by the scheme's local error
(DESIGN §5).  The estimator

1. takes the floor as the median of the last fifth of the trace;
2. keeps the transient: the samples from the start until the trace first comes within a
   factor 1000 of the floor (100, then ``FLOOR_MARGIN`` = 30 when that leaves fewer than 8
   samples; the whole trace if it never does): the floor is a forced response that bends
   the trace well above its own level;
3. takes the upper envelope of the log-norm from the right (running maximum) and keeps
   only the samples that lie on it, so that the dips of an oscillating (under-damped)
   residual do not drag the fit down; the fit window is the later part of the transient
   (after ``LEAD_FRACTION`` of its decades), where faster modes have died out;
4. fits ``log ‖g‖ ≈ a − β t`` and ``log ‖g‖ ≈ a − β t + ν log(t + s)`` by least squares,
   ``s`` found by a grid search refined by golden sections, and keeps the fit with the
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
from numba import njit, prange

FLOOR_MARGIN = 30.0
MIN_SAMPLES = 4
N_SHIFTS = 16
GOLDEN_ITERATIONS = 20
LEAD_FRACTION = 0.3


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
def _fit_one(norm, nvalid, times, env, on_env, tail, lg, a, b, out):
    """Fit one trace; writes (β, γ, floor, transient samples) into ``out``.  ``env``,
    ``on_env``, ``tail``, ``lg`` (samples), ``a`` (3 × 3) and ``b`` (3) are scratch."""
    out[0] = math.nan
    out[1] = math.nan
    out[2] = math.nan
    out[3] = 0.0
    if nvalid < 2:
        return
    ntail = min(max(3, nvalid // 5), nvalid)
    for i in range(ntail):
        tail[i] = norm[nvalid - ntail + i]
    srt = tail[:ntail]
    srt.sort()
    floor = srt[ntail // 2] if ntail % 2 == 1 else 0.5 * (srt[ntail // 2 - 1] + srt[ntail // 2])
    out[2] = floor
    # upper envelope of log ‖g‖ from the right: non-increasing, blind to the dips of an
    # oscillating residual
    run = -math.inf
    for i in range(nvalid - 1, -1, -1):
        y = math.log(norm[i]) if norm[i] > 0.0 else -math.inf
        on_env[i] = y >= run  # a "record" from the right: on the upper hull of the trace
        if y > run:
            run = y
        env[i] = run
    # transient: until the envelope comes within a margin of the floor.  The floor is a
    # forced response, not noise, and bends the trace well above it: take the widest
    # margin (1000, 100, then FLOOR_MARGIN) that still leaves 8 samples.
    end = nvalid
    for margin in (1000.0, 100.0, FLOOR_MARGIN):
        level = math.log(margin * floor) if floor > 0.0 else -math.inf
        end = nvalid
        for i in range(1, nvalid):
            if env[i] <= level:
                end = i
                break
        if end >= 8:
            break
    out[3] = end
    if end < MIN_SAMPLES or not math.isfinite(env[end - 1]):
        return
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
        return
    dt = times[1] - times[0]
    span = times[end - 1] - times[0]
    # plain exponential (ν = 0), then ν log(t + s) over a log-spaced grid of shifts s
    beta, best = _fit_linear(env, on_env, times, start, end)
    if npts >= 6:
        # shifts s = e^u − t_w over (−t_w, ∞), t_w the window's first time: a negative s
        # puts a zero crossing of c0 + c1 t just before the window.  Grid in u, then a
        # golden-section refinement around the best grid point.
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
            for _ in range(GOLDEN_ITERATIONS):
                u1 = ub - 0.6180339887498949 * (ub - ua)
                u2 = ua + 0.6180339887498949 * (ub - ua)
                b1, s1 = _fit_with_log(env, on_env, times, start, end, math.exp(u1) - t_w, a, b, lg)
                b2, s2 = _fit_with_log(env, on_env, times, start, end, math.exp(u2) - t_w, a, b, lg)
                if s1 < best:
                    best, beta = s1, b1
                if s2 < best:
                    best, beta = s2, b2
                if s1 <= s2:
                    ub = u2
                else:
                    ua = u1
    gamma = 0.0
    for i in range(end):
        g = norm[i] * math.exp(beta * (times[i] - times[0]))
        if g > gamma:
            gamma = g
    out[0] = beta
    out[1] = gamma


@njit(parallel=True, cache=True)
def fit_decay_kernel(norms, nvalid, times, out):
    """Fit every row of ``norms`` (members × samples); ``out`` is (members, 4):
    β, γ, floor, number of transient samples."""
    M, T = norms.shape
    nchunks = (M + 255) // 256
    for c in prange(nchunks):
        env = np.empty(T)
        on_env = np.empty(T, dtype=np.bool_)
        tail = np.empty(T)
        row = np.empty(T)
        lg = np.empty(T)
        a = np.empty((3, 3))
        b = np.empty(3)
        for j in range(c * 256, min(M, (c + 1) * 256)):
            for i in range(T):
                row[i] = norms[j, i]
            _fit_one(row, nvalid[j], times, env, on_env, tail, lg, a, b, out[j])


@njit(parallel=True, cache=True)
def _trace_summary_kernel(norms, nvalid, largest, last):
    M, T = norms.shape
    for j in prange(M):
        n = T
        top = -math.inf
        for i in range(T):
            v = norms[j, i]
            if math.isfinite(v):
                top = max(top, v)
            elif n == T:
                n = i
        nvalid[j] = n
        largest[j] = top if n > 0 else math.nan
        last[j] = norms[j, max(n - 1, 0)]


def trace_summary(norms):
    """Per trace, in one pass: the number of leading finite samples, the largest finite
    sample (NaN when the first is not finite) and the last of the leading finite ones.

    The same numbers as ``isfinite`` / ``argmin`` / ``nanmax`` over the whole array, which
    made up most of the time spent after the integration of a large ensemble.
    """
    norms = np.ascontiguousarray(np.atleast_2d(norms))
    M = norms.shape[0]
    nvalid, largest, last = np.empty(M, dtype=np.int64), np.empty(M), np.empty(M)
    _trace_summary_kernel(norms, nvalid, largest, last)
    return nvalid, largest, last


def fit_decay(norms, times, nvalid=None):
    """β, γ, floor and transient length for each trace.

    Parameters
    ----------
    norms : array (members, samples)
        Residual norms ``‖g(t_i)‖`` (float32 or float64); NaN after a divergence.
    times : array (samples,)
        Uniformly spaced sample times.
    nvalid : array (members,), optional
        Number of valid leading samples per member (default: all non-NaN leading ones).

    Returns
    -------
    beta, gamma, floor, n_transient : arrays (members,)
    """
    norms = np.ascontiguousarray(np.atleast_2d(norms))
    times = np.ascontiguousarray(times, dtype=np.float64)
    if nvalid is None:
        nvalid = trace_summary(norms)[0]
    out = np.empty((norms.shape[0], 4))
    fit_decay_kernel(norms, np.ascontiguousarray(nvalid, dtype=np.int64), times, out)
    return out[:, 0], out[:, 1], out[:, 2], out[:, 3].astype(np.int64)
