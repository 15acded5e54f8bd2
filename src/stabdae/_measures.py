"""What an ensemble reports: each member's class with its reason, and the summaries with
their uncertainty.

Per member (from the measures of :mod:`.engine.decay`: its initial norm, the largest norm
over each fifth of the run ``W0 … W4``, the floor ``W4``) a *stability class*:

``decayed``
    fell below where it started and stayed within ε;
``overshoot``
    as ``decayed``, but above ε on the way: the law's own transient (a critically damped
    law's ``‖e^{Ãt}‖∞`` peaks near ``ω/e``); ``overshoot`` (largest / initial norm) is
    stored beside the law's ``sup_k ‖R(τÃ)^k‖∞``;
``at floor``
    started within reach of the scheme's floor and stayed there, within ε;
``floor above epsilon``
    not growing, but the floor itself (the scheme's local error at this step) lies above
    ε: a property of the step size, not an instability;
``growing``
    the largest norm of each of the last three fifths grows, and the last is at least
    ``decay.GROWTH`` times the third, above what roundoff can build up: unstable over this
    run, though not yet diverged;
``diverged``
    stopped by the divergence threshold, a non-finite state or a singular ``S``;
``not run``
    not placed, or an adaptive member that ran out of steps.

*Stable* is one of the first four; *bounded* (Definition 2 of the paper) is stable with
the largest norm within ε.  The fractions come with Wilson 95 % intervals, the median
decay rate with an order-statistics interval, and every summary with the counts behind it.
"""

from __future__ import annotations

import math

import numpy as np

from ._codes import ProbeStage, StabilityClass, Status, TauStarReason, messages
from .engine import decay

#: class codes of ``stability_class`` (:class:`stabdae._codes.StabilityClass`)
DECAYED, OVERSHOOT, AT_FLOOR, FLOOR_ABOVE_EPSILON, GROWING, DIVERGED, NOT_RUN = (
    int(c) for c in StabilityClass)
CLASSES = tuple(c.message for c in StabilityClass)
STABLE = (DECAYED, OVERSHOOT, AT_FLOOR, FLOOR_ABOVE_EPSILON)
#: the normal quantile of the 95 % intervals
Z95 = 1.959963984540054

#: codes of a boundary search's ``tau_star_reason`` (:class:`stabdae._codes.TauStarReason`)
BRACKETED, LOW_END_FAILS, HIGH_END_STABLE, CONFIRM_FAILS = (int(c) for c in TauStarReason)
TAU_STAR_REASONS = messages(TauStarReason)
#: a boundary search's probe stages (``probe_stage``, :class:`stabdae._codes.ProbeStage`)
ENDS, GUIDED, BISECTION, CONFIRM = (int(c) for c in ProbeStage)
STAGES = messages(ProbeStage)

#: how far above the roundoff it can build up a rising residual must be to be growth
ROUNDOFF_MARGIN = 10.0

_BLOWN_UP = (Status.DIVERGED, Status.NONFINITE_STATE, Status.SINGULAR_S, Status.MASS_NOT_SPD)


def classify(meas: decay.Record, status: np.ndarray, epsilon: float,
             roundoff: float = 0.0) -> np.ndarray:  # fmt: skip
    """The stability class of each member (int8, codes of :data:`CLASSES`) from its
    measurement record ``meas``.

    ``roundoff``: the size of the residual that roundoff alone can build up by the end of
    the run (:func:`roundoff_level` at the final states, times the law's
    :func:`stabdae.theory.forced_gain` where it is known).  A member grows only where its
    last fifth rises above ``ROUNDOFF_MARGIN`` times that: below it, a residual that
    rises is roundoff growing with the size of the state (a model whose coordinates
    drift), not an instability."""
    initial, largest = meas["initial"], meas["largest"]
    w2, w3, w4 = meas["w2"], meas["w3"], meas["w4"]
    with np.errstate(invalid="ignore"):
        growing = decay.grows(w2, w3, w4) & (w4 > ROUNDOFF_MARGIN * roundoff)
        fell = w4 < initial
        within = largest <= epsilon
        floor_ok = w4 <= epsilon
    cls = np.full(status.shape, AT_FLOOR, dtype=np.int8)
    cls[~floor_ok] = FLOOR_ABOVE_EPSILON
    cls[fell & floor_ok & within] = DECAYED
    cls[fell & floor_ok & ~within] = OVERSHOOT
    cls[growing] = GROWING
    blown = np.isin(status, [int(s) for s in _BLOWN_UP])
    cls[blown] = DIVERGED
    cls[(status != 0) & ~blown] = NOT_RUN
    return cls


def roundoff_level(residual_rows, states, t: float) -> float:
    """The size roundoff gives the residual at these states: the median over the states of
    ``u · max_c (Σ_i |∂g_c/∂x_i · x_i| + |∂g_c/∂t · t|)`` (``u`` the unit roundoff), each
    term the change of ``g`` when one entry of the state (or the time) moves by one
    rounding, by central differences.  ``residual_rows(X, t)`` evaluates ``g`` at every row
    of ``X``."""
    states = np.asarray(states, dtype=float)
    if states.size == 0:
        return 0.0
    h = 1e-6
    u = np.finfo(float).eps / 2.0
    states = np.atleast_2d(states)
    S, n2 = states.shape
    rows = 2 * n2 + 1  # per state: ± each entry, then the state itself
    X = np.repeat(states, rows, axis=0).reshape(S, rows, n2)
    idx = np.arange(n2)
    X[:, 2 * idx, idx] += h * states
    X[:, 2 * idx + 1, idx] -= h * states
    # every state's rows in one call (each call is a trip to the threads)
    G = residual_rows(X.reshape(S * rows, n2), t).reshape(S, rows, -1)
    if t != 0.0:
        Gt = residual_rows(np.ascontiguousarray(X[:, -1]), t * (1.0 + h))
    levels = []
    for i in range(S):
        terms = np.abs(G[i, 0:-1:2] - G[i, 1:-1:2]).sum(axis=0) / (2.0 * h)
        if t != 0.0:
            terms = terms + np.abs(Gt[i] - G[i, -1]) / h
        if np.all(np.isfinite(terms)):
            levels.append(float(terms.max()) if terms.size else 0.0)
    return u * float(np.median(levels)) if levels else 0.0


def wilson(successes: int, n: int) -> tuple[float, float]:
    """Wilson's 95 % score interval of a fraction (NaN for ``n = 0``)."""
    if n == 0:
        return math.nan, math.nan
    p = successes / n
    z2 = Z95 * Z95
    centre = (p + z2 / (2 * n)) / (1 + z2 / n)
    half = Z95 * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / (1 + z2 / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def median_interval(values) -> tuple[float, float, float]:
    """The median of the finite values with a distribution-free 95 % interval from order
    statistics (ranks ``n/2 ∓ 1.96 √n / 2``); NaN where there are too few values."""
    v = np.sort(np.asarray(values, dtype=float)[np.isfinite(values)])
    n = v.size
    if n == 0:
        return math.nan, math.nan, math.nan
    med = float(np.median(v))
    half = Z95 * math.sqrt(n) / 2.0
    lo, hi = int(math.floor(n / 2.0 - half)), int(math.ceil(n / 2.0 + half))
    if lo < 0 or hi > n - 1:
        return med, math.nan, math.nan
    return med, float(v[lo]), float(v[hi])


def stability_radius(alpha_norm, stable, ran) -> tuple[float, float, float, str]:
    """δ* with its bracket: ``(δ*, low, high, reason)``.  ``high`` is the smallest
    ``‖α⁰‖`` of a member that was not stable, ``low`` the largest below it (every member
    up to ``low`` was stable); δ* is their geometric mean, NaN with a reason when the
    sample does not bracket it."""
    a, ok = np.asarray(alpha_norm)[ran], np.asarray(stable)[ran]
    if a.size == 0:
        return math.nan, math.nan, math.nan, "no member ran"
    if ok.all():
        return math.nan, float(a.max()), math.nan, "every member stable: delta* is above the sample"
    high = float(a[~ok].min())
    below = a[a < high]
    if below.size == 0:
        return math.nan, math.nan, high, "no member stable below the smallest failure"
    low = float(below.max())
    return math.sqrt(low * high), low, high, "bracketed"


def flags(meas, cls, epsilon):
    """Per member: ``(stable, bounded)``, bounded being stable and within ε at every step
    (Definition 2)."""
    stable = np.isin(cls, STABLE)
    with np.errstate(invalid="ignore"):
        return stable, stable & (meas["largest"] <= epsilon)


def summaries(meas, cls, alpha_norm, epsilon) -> dict:
    """The ensemble's scalar summaries with their intervals and counts."""
    ran = cls != NOT_RUN
    stable, bounded = flags(meas, cls, epsilon)
    n = int(ran.sum())
    beta = meas["beta"]
    out = {"members_run": n, "members_stable": int((stable & ran).sum()),
           "members_bounded": int((bounded & ran).sum()),
           "members_diverged": int((cls == DIVERGED).sum()),
           "members_growing": int((cls == GROWING).sum()),
           "members_with_beta": int(np.isfinite(beta).sum())}  # fmt: skip
    for name, k in (("fraction_stable", out["members_stable"]),
                    ("fraction_bounded", out["members_bounded"])):  # fmt: skip
        out[name] = k / n if n else math.nan
        out[name + "_low"], out[name + "_high"] = wilson(k, n)
    out["beta_median"], out["beta_median_low"], out["beta_median_high"] = median_interval(beta)
    delta, low, high, why = stability_radius(alpha_norm, stable, ran)
    out.update(stability_radius=delta, stability_radius_low=low, stability_radius_high=high)
    return out, why
