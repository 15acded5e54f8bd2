"""A member's verdict, its stability class, the roundoff level and the measurement stride
in plain Python, one member (or one state) at a time, from their documented definitions
(the docstrings of ``stabdae._measures`` and ``stabdae._ensemble.measure_stride``).  The
constants are written out as documented, not imported, so that a changed constant in the
library shows.

*Growth* (the last three fifths' largest deviations ``d2, d3, d4``): ``d2 ≤ d3 ≤ d4`` and
``d4 > 1.5 d2``.  The noise level of fifth ``j``: ``10 · floor_j + 10 · roundoff``.

*Verdict*, in this order of precedence (the first that applies):

1. not run (status not 0 and not a blow-up): undecided, ``not run``; where the
   unperturbed run blew up (its status a blow-up) or its residual exceeded ε (a time at
   which it did) while ε lies above ``roundoff``, unless the theory has ``ρ ≥ 1``, every
   other member: unstable, ``motion unstable``;
2. blown up (diverged, non-finite, singular ``S``, mass not SPD): unstable, ``blew up``;
   except, with the theory and ``ρ < 1``, a member stopped by the divergence threshold
   when the threshold lies within the law's peak (``2 · max bound · d0`` + the largest
   noise): undecided, ``stopped in transient``;
3. with the theory and ``ρ < 1``, ``allowed = 2 · bound_4 · d0 + noise_4``:
   within it (``d4 ≤ allowed``): undecided, ``rose in floor band``, where it grew, past
   its start, past ``2 · bound_4 · d0 + 10 · roundoff`` and past ``1.5 · max(1,
   floor_4 / floor_2) · d2`` (the ratio 1 where either floor is 0); else stable,
   ``decayed`` if ``d4 < d0`` else ``within bound``;
   beyond it, ``beyond bound`` (unstable) if it grew (resolved, growth, ``d4 > noise_4``)
   past its start (``d4 > d0``), ``rose below start`` (undecided) if it grew but not past
   its start, else ``above bound`` (undecided);
4. with the theory and ``ρ ≥ 1``: grew (resolved, growth, ``d4 > d0`` or ``d4 >
   noise_4``): unstable, ``grew``; ended below its start: undecided, ``decayed though ρ
   ≥ 1``; else undecided, ``too short``;
5. without the theory: grew (resolved, growth, ``d4 > noise_4``) and ``d4 > d0``:
   unstable, ``grew``; ended below its start and did not grow: stable, ``decayed``; in
   the floor band (``d0 ≤ noise_0`` and ``d4 ≤ noise_4``): undecided, ``in floor band``;
   else undecided, ``too short``.

*Class*: not run → ``not run``; blown up → ``diverged``; undecided → ``undecided``;
unstable → ``growing``; stable: ``floor above epsilon`` where the raw residual is not
still falling by 3 per fifth (``w2 ≥ 3 w3 ≥ 9 w4`` fails) and ``w4 > ε``; else
``decayed`` (``w4 < initial``, largest ``≤ ε``), ``overshoot`` (``w4 < initial``, largest
``> ε``) or ``at floor``.
"""

from __future__ import annotations

import cmath
import math

import numpy as np

from stabdae._codes import StabilityClass as C
from stabdae._codes import Status
from stabdae._codes import Verdict as V
from stabdae._codes import VerdictReason as R

GROWTH, STILL_DECAYING = 1.5, 3.0
FLOOR_BAND, ROUNDOFF_MARGIN, TRANSIENT_SLACK = 10.0, 10.0, 2.0
MAX_STRIDE, STRIDE_CHANGE = 32, 0.2
BLOWN_UP = {Status.DIVERGED, Status.NONFINITE_STATE, Status.SINGULAR_S, Status.MASS_NOT_SPD}


def grows(d2: float, d3: float, d4: float) -> bool:
    return d2 <= d3 <= d4 and d4 > GROWTH * d2


def verdict(d0, d2, d3, d4, status, floor_band=None, bounds=None, rho=math.nan,
            divergence=math.inf, roundoff=0.0, motion_status=0,
            motion_exceeds=math.nan, epsilon=math.inf) -> tuple[int, int]:  # fmt: skip
    """One member's ``(verdict, reason)``; ``motion_status`` and ``motion_exceeds``: the
    unperturbed run's status and the time its residual exceeded ``epsilon`` (NaN:
    never)."""
    band = [0.0] * 5 if floor_band is None else [0.0 if math.isnan(b) else b
                                                  for b in floor_band]  # fmt: skip
    noise = [FLOOR_BAND * b + ROUNDOFF_MARGIN * roundoff for b in band]
    theory = bounds is not None and math.isfinite(rho)
    status = int(status)
    blown = status in {int(s) for s in BLOWN_UP}
    if status != 0 and not blown:
        return V.UNDECIDED, R.NOT_RUN
    law_grows = bounds is not None and math.isfinite(rho) and rho >= 1.0
    left = not math.isnan(motion_exceeds) and roundoff < epsilon
    if (int(motion_status) in {int(s) for s in BLOWN_UP} or left) and not law_grows:
        return V.UNSTABLE, R.MOTION_UNSTABLE
    if blown:
        if theory and rho < 1.0 and status == Status.DIVERGED:
            peak = TRANSIENT_SLACK * max(bounds) * d0 + max(noise)
            if divergence <= peak:
                return V.UNDECIDED, R.STOPPED_IN_TRANSIENT
        return V.UNSTABLE, R.BLEW_UP
    resolved = math.isfinite(d2) and math.isfinite(d3) and math.isfinite(d4)
    rising = resolved and grows(d2, d3, d4)
    if theory and rho < 1.0:
        if d4 <= TRANSIENT_SLACK * bounds[4] * d0 + noise[4]:
            floor_rise = band[4] / band[2] if band[2] > 0 and band[4] > 0 else 1.0
            if (rising and d4 > d0 and d4 > TRANSIENT_SLACK * bounds[4] * d0
                    + ROUNDOFF_MARGIN * roundoff
                    and d4 > GROWTH * max(1.0, floor_rise) * d2):  # fmt: skip
                return V.UNDECIDED, R.ROSE_IN_FLOOR_BAND
            return V.STABLE, (R.DECAYED if d4 < d0 else R.WITHIN_BOUND)
        if rising and d4 > noise[4]:
            return (V.UNSTABLE, R.BEYOND_BOUND) if d4 > d0 else (V.UNDECIDED,
                                                                 R.ROSE_BELOW_START)
        return V.UNDECIDED, R.ABOVE_BOUND
    if theory:
        if rising and (d4 > d0 or d4 > noise[4]):
            return V.UNSTABLE, R.GREW
        if d4 < d0:
            return V.UNDECIDED, R.DECAYED_RHO_ABOVE_ONE
        return V.UNDECIDED, R.TOO_SHORT
    grew = rising and d4 > noise[4]
    if grew and d4 > d0:
        return V.UNSTABLE, R.GREW
    if d4 < d0 and not grew:
        return V.STABLE, R.DECAYED
    if d0 <= noise[0] and d4 <= noise[4]:
        return V.UNDECIDED, R.IN_FLOOR_BAND
    return V.UNDECIDED, R.TOO_SHORT


def stability_class(initial, largest, w2, w3, w4, status, epsilon, verdict_) -> int:
    """One member's stability class."""
    status = int(status)
    if status != 0:
        return C.DIVERGED if status in {int(s) for s in BLOWN_UP} else C.NOT_RUN
    if verdict_ == V.UNDECIDED:
        return C.UNDECIDED
    if verdict_ == V.UNSTABLE:
        return C.GROWING
    still = w2 >= STILL_DECAYING * w3 and w3 >= STILL_DECAYING * w4
    if not still and w4 > epsilon:
        return C.FLOOR_ABOVE_EPSILON
    if w4 < initial:
        return C.DECAYED if largest <= epsilon else C.OVERSHOOT
    return C.AT_FLOOR


def ensemble_verdict(n_run: int, n_stable: int, n_unstable: int, q: float) -> int:
    """Stable where at least ``1 − q`` of the members that ran are stable, unstable where
    more than ``q`` are unstable, undecided otherwise or where none ran."""
    if n_run == 0:
        return V.UNDECIDED
    if n_stable >= (1 - q) * n_run:
        return V.STABLE
    return V.UNSTABLE if n_unstable > q * n_run else V.UNDECIDED


def roundoff_level(grad_x, grad_t, states, t: float) -> float:
    """``u · median over the states of max_c (Σ_i |∂g_c/∂x_i · x_i| + |∂g_c/∂t · t|)``
    from exact derivatives: ``grad_x(x, t)`` (ng, n), ``grad_t(x, t)`` (ng,); states whose
    terms are not finite are left out (0 where none is left)."""
    u = np.finfo(float).eps / 2.0
    levels = []
    for x in np.atleast_2d(states):
        terms = np.abs(grad_x(x, t) * x).sum(axis=1) + np.abs(grad_t(x, t) * t)
        if np.all(np.isfinite(terms)):
            levels.append(terms.max() if terms.size else 0.0)
    return u * float(np.median(levels)) if levels else 0.0


def measure_stride(eigenvalues) -> int:
    """The most steps, up to 32, over which ``|ln λ|`` (decay and rotation) of every
    eigenvalue of ``R`` moves by at most 0.2: ``⌊0.2 / max |ln λ|⌋``, at least 1; 1 where
    an eigenvalue is 0, 32 where every ``ln λ`` is 0."""
    change = 0.0
    for lam in eigenvalues:
        if lam == 0:
            return 1
        change = max(change, abs(cmath.log(complex(lam))))
    if change == 0.0:
        return MAX_STRIDE
    return min(MAX_STRIDE, max(1, math.floor(STRIDE_CHANGE / change)))
