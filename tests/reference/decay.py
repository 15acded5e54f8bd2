"""The decay estimator over a stored trace in plain NumPy/SciPy, from its documented
definition (the docstring of ``stabdae.engine.decay``), each sample taken as a step:

* levels: ``LEVELS_PER_OCTAVE = 8`` per octave, read from a float's exponent and three
  leading mantissa bits; the first sample's level is ``NBINS − 1 − ABOVE``; clamped to
  ``[0, NBINS − 1]``;
* envelope points: the last sample on each level that no later sample's level exceeds,
  in time order, with their logarithms;
* the largest norm per fifth of the run; the floor is the last fifth's; the run "ended
  still decaying" when each of the last three fifths' largest norms is at least
  ``STILL_DECAYING`` times below the one before;
* the transient: the envelope points before the first within a margin (1000, 100, then
  ``FLOOR_MARGIN``) of the floor, or all of them when the run ended still decaying; the
  fit window: the transient after its first ``LEAD_FRACTION`` of decades, with at least
  ``MIN_POINTS`` points over at least ``MIN_DECADES``; where the roundoff level is
  given, no point at or below ``ROUNDOFF_FLOOR`` times it (the margins' levels are at
  least that, and a run that ended still decaying is cut there);
* fits: ``log‖g‖ ≈ a − βt`` and, with six points or more, ``log‖g‖ ≈ a − βt + ν log(t +
  s)`` with the best shift ``s = e^u − t_w`` over ``u ∈ [log(dt/4), log(t_w + 4·span +
  dt)]`` (``t_w``, ``span``: the window's first time and length; here a dense grid
  refined by SciPy's bounded minimizer, not the library's grid and Brent), the better
  kept; when neither fits to ``SMOOTH_RMS`` (RMS in the logarithm), ``t ≈ a + b log‖g‖``
  and ``β = −1/b``;
* ``γ = max ‖g(t)‖ e^{βt}`` over the first sample and the envelope points up to the
  window's end that lie above ``GAMMA_MARGIN`` times the roundoff level (or within the
  first decade below the first envelope point, whichever reaches lower).

A different computation of the same definitions: the window and the kind of fit are the
same, β agrees to the shift searches' tolerance.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import minimize_scalar

NBINS, ABOVE, SHIFT = 512, 80, 49
FLOOR_MARGIN, LEAD_FRACTION, MIN_POINTS, MIN_DECADES = 30.0, 0.3, 12, 1.0
SMOOTH_RMS, STILL_DECAYING = 0.01, 3.0
ROUNDOFF_FLOOR, GAMMA_MARGIN = 30.0, 1e6


def _levels(v: np.ndarray) -> np.ndarray:
    bits = v.astype(np.float64).view(np.int64) >> SHIFT
    base = bits[0] - (NBINS - 1 - ABOVE)
    return np.clip(bits - base, 0, NBINS - 1)


def envelope(t: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The right-envelope points ``(times, log norms)`` of a finite, positive trace."""
    level = _levels(v)
    last = {lev: i for i, lev in enumerate(level)}
    keep = sorted(i for i in last.values() if i == v.size - 1 or level[i] > level[i + 1:].max())
    return t[keep] - t[0], np.log(v[keep])


def fifths(t: np.ndarray, v: np.ndarray) -> np.ndarray:
    span = t[-1] - t[0]
    w = np.minimum(4, (5.0 * (t - t[0]) / span).astype(int))
    return np.array([v[w == k].max() if (w == k).any() else np.nan for k in range(5)])


def window(rt, ry, floor: float, still: bool, noise: float = 0.0) -> tuple[int, int]:
    """The documented window; no point at or below ``ROUNDOFF_FLOOR`` times the roundoff
    level ``noise`` belongs to it."""
    n = ry.size
    lnnoise = math.log(ROUNDOFF_FLOOR * noise) if noise > 0 else -math.inf
    for margin in (1000.0, 100.0, FLOOR_MARGIN, None):
        if margin is None:
            if not still:
                break
            level = lnnoise
        else:
            level = max(math.log(floor) + math.log(margin), lnnoise)
        below = np.flatnonzero(ry <= level)
        end = int(below[0]) if below.size else n
        if end < 2:
            continue
        cut = ry[0] - LEAD_FRACTION * (ry[0] - ry[end - 1])
        start = int(np.flatnonzero(ry[:end] <= cut)[0])
        if end - start >= MIN_POINTS and ry[start] - ry[end - 1] >= MIN_DECADES * math.log(10):
            return start, end
    return 0, 0


def _fit_log(t, y, shift):
    X = np.column_stack([np.ones_like(t), -t, np.log(t + shift)])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    return coef[1], float(np.sum((y - X @ coef) ** 2))


def fit_polynomial(t, y, dt: float) -> tuple[float, float]:
    """β and SSE of the ``ν log(t + s)`` fit at its best shift."""
    t_w, span = t[0], t[-1] - t[0]
    lo, hi = math.log(0.25 * dt), math.log(t_w + 4.0 * span + dt)
    grid = np.linspace(lo, hi, 801)
    sse = [_fit_log(t, y, math.exp(u) - t_w)[1] for u in grid]
    k = int(np.argmin(sse))
    a, b = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    res = minimize_scalar(lambda u: _fit_log(t, y, math.exp(u) - t_w)[1], bounds=(a, b),
                          method="bounded", options={"xatol": 1e-10 * (hi - lo)})  # fmt: skip
    u = res.x if res.fun <= sse[k] else grid[k]
    return _fit_log(t, y, math.exp(u) - t_w)


def estimate(t: np.ndarray, v: np.ndarray, noise: float = 0.0) -> dict:
    """β, γ, the window's first and last time and its number of points, the kind of fit
    ("exponential", "polynomial", "oscillating"; None: no window) of one trace, and what
    chose the kind: the two fits' sums of squares and the kept one's RMS."""
    rt, ry = envelope(t, v)
    w = fifths(t, v)
    still = w[2] >= STILL_DECAYING * w[3] and w[3] >= STILL_DECAYING * w[4]
    start, end = window(rt, ry, w[4], still, noise)
    if end == 0:
        return {"beta": math.nan, "kind": None}
    tt, yy = rt[start:end], ry[start:end]
    slope, intercept = np.polyfit(tt, yy, 1)
    beta, kind = -slope, "exponential"
    sse = sse_exp = float(np.sum((yy - (intercept + slope * tt)) ** 2))
    sse_poly = math.nan
    if end - start >= 6:
        bp, sse_poly = fit_polynomial(tt, yy, t[1] - t[0])
        if sse_poly < sse:
            beta, sse, kind = bp, sse_poly, "polynomial"
    rms = math.sqrt(sse / (end - start))
    if rms > SMOOTH_RMS:
        b = np.polyfit(yy, tt, 1)[0]
        beta, kind = -1.0 / b, "oscillating"
    # γ: the start, and the window's points above GAMMA_MARGIN times the roundoff level
    # (all of the first decade below the start)
    cut = -math.inf
    if noise > 0:
        cut = min(math.log(GAMMA_MARGIN * noise), ry[0] - math.log(10.0))
    keep = ry[:end] >= cut
    keep[0] = True
    gamma = max(math.exp(np.max(ry[:end][keep] + beta * rt[:end][keep])), v[0])
    return {"beta": beta, "gamma": gamma, "fit_start": rt[start], "fit_end": rt[end - 1],
            "fit_points": end - start, "kind": kind, "sse_exponential": sse_exp,
            "sse_polynomial": sse_poly, "rms": rms}
