"""Step-size control of the embedded pairs, shared by the loop of one trajectory
(:mod:`stabdae.engine.rk.adaptive`) and the lanes of the adaptive ensemble
(:mod:`stabdae.engine.ensemble.lanes`), so that both take the same steps.

Local error control ``err ≤ 1`` per step with the error estimates ``e = τ Σ (b_i − b̂_i) k_i``
scaled by ``atol_l + rtol·max(|x_l|, |x̃_l|)`` (``atol`` one per state component): ``err``
is their RMS norm for Dormand–Prince, and
``‖e₅‖² / √(‖e₅‖² + 0.01 ‖e₃‖²)`` of the fifth- and third-order estimates for DOP853 (as in
Hairer's code and SciPy's).  The step is updated by ``SAFETY · err^{−1/(q+1)}`` within
``[MIN_FACTOR, MAX_FACTOR]`` (``q`` = 4 and 7: the estimate's order; no growth right after a
rejection), the first step chosen as in Hairer, Nørsett & Wanner (II.4).  Steps end exactly
on the sample times.
"""

from __future__ import annotations

import math

from numba import njit

from ..._codes import Status

#: the step-size update ``SAFETY · err^{−1/(q+1)}``, kept within ``[MIN_FACTOR, MAX_FACTOR]``
SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
#: the factor of an attempt whose right-hand side failed or whose error is not finite
FAIL_FACTOR = 0.25

_STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
_MAX_STEPS = int(Status.MAX_STEPS)
_DIVERGED = int(Status.DIVERGED)


@njit(forceinline=True)
def _next_step(t, h, target, taken, max_steps):
    """The next attempted step from ``t`` with step size ``h``: ``(hh, hit, status)``, ``hh``
    cut to end on the sample time ``target`` when it reaches it (``hit``); status
    ``MAX_STEPS`` after ``taken ≥ max_steps`` steps, ``STEP_TOO_SMALL`` for a step below
    roundoff at ``t``."""
    if taken >= max_steps:
        return h, False, _MAX_STEPS
    hh = h
    hit = False
    if t + hh >= target - 1e-12 * abs(target):
        hh = target - t
        hit = True
    if hh <= 1e-14 * max(1.0, abs(t)):
        return hh, hit, _STEP_TOO_SMALL
    return hh, hit, 0


@njit(forceinline=True)
def _combined_norm(s5, s3, hh, N2):
    """DOP853's error norm ‖e₅‖² / √(‖e₅‖² + 0.01 ‖e₃‖²) from the sums of squares of the
    scaled estimates: 0 when both are 0 (a select, not a branch, so that the lanes'
    loop vectorizes; 0 for s5 = 0 and NaN for NaN or inf either way)."""
    den = (s5 + 0.01 * s3) * N2
    return abs(hh) * s5 / math.sqrt(den if den > 0.0 else 1.0)


@njit(forceinline=True)
def _settle(good, e, hh, h, hit, after_reject, expo):
    """The step control after an attempt of size ``hh`` (``h``: the step before a cut to a
    sample time, ``hit``): ``(accepted, next h, after_reject)``.  A failed or non-finite
    attempt shrinks by ``FAIL_FACTOR``; ``e ≤ 1`` accepts and grows by
    ``SAFETY e^{−1/(q+1)}`` within ``[MIN_FACTOR, MAX_FACTOR]``, not at all right after a
    rejection; ``e > 1`` shrinks by that factor."""
    if not good:
        return False, FAIL_FACTOR * hh, True
    if e <= 1.0:
        fac = MAX_FACTOR if e == 0.0 else min(MAX_FACTOR, max(MIN_FACTOR, SAFETY * e**-expo))
        if after_reject:
            fac = min(fac, 1.0)
        return True, (hh * fac if not hit else max(h, hh * fac)), False
    return False, hh * max(MIN_FACTOR, SAFETY * e**-expo), True


def _f_eval(rhs):
    """One out-of-line copy of the (inlined) right-hand side, for the places that call it
    once per step or per member: compiling the inlined body once instead of at each of
    them halves the compile time."""

    @njit(error_model="numpy")
    def f_eval(t, x, p, law_mat, law_scal, ws, xdot):
        return rhs(t, x, p, law_mat, law_scal, ws, xdot)

    return f_eval


def _first_step(f_eval, N2: int):
    """``first_step(t, x, k0, k1, xs, p, law_mat, law_scal, ws, rtol, atol, h0, tend, expo)``:
    ``h0`` when positive, otherwise the first step of Hairer, Nørsett & Wanner (II.4), from
    ‖x‖/‖ẋ‖ and then from ‖ẍ‖ (one evaluation, into ``k1``, at ``x + h ẋ`` in ``xs``);
    returns the step and the evaluations it took."""

    @njit(error_model="numpy")
    def first_step(t, x, k0, k1, xs, p, law_mat, law_scal, ws, rtol, atol, h0, tend, expo):
        if h0 > 0.0:
            return h0, 0
        d0 = d1 = 0.0
        for l in range(N2):
            sc = atol[l] + rtol * abs(x[l])
            d0 += (x[l] / sc) ** 2
            d1 += (k0[l] / sc) ** 2
        d0, d1 = math.sqrt(d0 / N2), math.sqrt(d1 / N2)
        h = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
        h = min(h, tend - t)
        for l in range(N2):
            xs[l] = x[l] + h * k0[l]
        st = f_eval(t + h, xs, p, law_mat, law_scal, ws, k1)
        if st == 0:
            d2 = 0.0
            for l in range(N2):
                sc = atol[l] + rtol * abs(x[l])
                d2 += ((k1[l] - k0[l]) / sc) ** 2
            d2 = math.sqrt(d2 / N2) / h
            if max(d1, d2) <= 1e-15:
                h1 = max(1e-6, h * 1e-3)
            else:
                h1 = (0.01 / max(d1, d2)) ** expo
            h = min(100.0 * h, h1)
        return h, 1

    return first_step
