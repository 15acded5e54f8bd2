"""Gains that weigh the floor: what a constant law's residual settles on, and the gain that
reaches a requested residual soonest.

The gain that minimizes ``ρ(R(τÃ))`` (:func:`stabdae.theory.recommend_gain`, deadbeat
where the scheme allows) makes the transient vanish in a step or two, but the residual
does not go to zero: each step adds the scheme's local error on the constraints, and the
law propagates it, ``g_{k+1} = R g_k + e_k``.  A stiff gain both contracts harder and
makes ``e_k`` larger (the stages evaluate ``Ã g`` far from the manifold's tangent), so
its floor can be decades above a gentle gain's.

:func:`gain_floor` takes the floor from the run from the reference state itself: its
residual is that recursion from ``g_0 = 0`` driven by the remainders ``e_k`` of the
motion, step after step, so that what the law does to a forcing that moves with the
motion is in it.  (The quasi-static response ``(I − R)⁻¹ e_k`` of one remainder holds for a
forcing slower than the law; at a gentle gain, whose rate lies below the motion's
frequencies, the law averages the remainders over a period, and that response
over-predicts the floor several times.)  Beside it, a small ensemble measures the floor its
members settle on.  :func:`balanced_gain` then weighs transient and floor: among
critically damped Baumgarte gains it takes the one whose predicted residual,
``‖R^k‖∞ · start + floor``, first stays below ``level`` soonest.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from . import _validate as check
from . import theory
from ._ensemble import ensemble
from ._integrate import IntegrationWarning, integrate
from ._laws import baumgarte

__all__ = ["balanced_gain", "gain_floor"]

#: steps of the runs when no ``t_end`` is given
STEPS = 2000


def gain_floor(model, law, scheme, tau: float, t_end: float | None = None, *, params=None,
               members: int = 16) -> dict:  # fmt: skip
    """The residual floor a constant law settles on under ``scheme`` at step ``tau``:
    the forced response of the scheme's one-step remainders along the motion, and
    measured.

    Returns
    -------
    dict
        ``predicted``: ``max_k ‖g_k‖∞`` over the last fifth of the run from the reference
        state to ``t_end`` (default ``STEPS`` steps), ``g_{k+1} = R g_k + e_k`` from
        ``g_0 = 0`` (``inf`` where ``ρ(R) ≥ 1`` or the run does not stay finite);
        ``remainder``: the largest ``‖e_k‖∞ = ‖g_{k+1} − R g_k‖∞`` there; ``measured``:
        the median ``residual_floor`` of an ensemble of ``members`` members with
        ``‖α⁰‖∞`` in ``[1e-10, 1e-9]`` (NaN with ``members=0``); ``rho``: ``ρ(R(τÃ))``.
    """
    who = "gain_floor"
    model = check.model(model, who)
    law = check.law(law, who)
    if not law.is_constant:
        raise ValueError(f"{who}: needs a constant law (Ã independent of the state)")
    scheme = check.scheme(scheme, who)
    tau = check.positive(tau, "tau", who)
    p = check.params(model, params, who)
    t0 = model.t0
    steps = STEPS if t_end is None else max(5, round((float(t_end) - t0) / tau))
    R = theory.step_matrix(law.A_tilde(model), scheme, tau)
    rho = theory.spectral_radius(R)
    out = {"predicted": math.inf, "remainder": math.nan, "measured": math.nan, "rho": rho}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        if members:
            ds = ensemble(model, law, scheme, tau, t0 + steps * tau, members=members,
                          radius=(1e-10, 1e-9), seed=0, params=p, traces="none",
                          states=False)  # fmt: skip
            floors = ds.residual_floor.values  # (NaN where a member did not run through)
            out["measured"] = float(np.nanmedian(floors)) if np.isfinite(floors).any() \
                else math.nan  # fmt: skip
        if not rho < 1.0:
            return out
        g = integrate(model, None, law, scheme, tau, t0 + steps * tau, tau,
                      params=p).residual.values  # fmt: skip
    if not np.all(np.isfinite(g)):
        return out
    last = g[int(0.8 * steps):]
    remainders = last[1:] - last[:-1] @ R.T
    out.update(predicted=float(np.abs(last).max()),
               remainder=float(np.abs(remainders).max()))
    return out


def balanced_gain(model, scheme, tau: float, level: float, start: float, *, xi: float = 1.0,
                  t_end: float | None = None, params=None, omegas=None) -> dict:  # fmt: skip
    """The Baumgarte gain (damping ``xi``) whose residual reaches ``level`` soonest from a
    perturbation of size ``start``, transient and floor together.

    For each ``ω`` of ``omegas`` (default 32 values geometric from the minimal-ρ gain of
    :func:`stabdae.theory.recommend_gain` down to a thousandth of it) the predicted
    residual after ``k`` steps is ``‖R^k‖∞ · start + floor`` (:func:`gain_floor`'s
    prediction, without the ensemble); the time to ``level`` is the first ``kτ`` from which
    it stays below (``inf`` where the floor alone is above ``level``).

    Returns ``omega`` (NaN where no gain reaches ``level``), ``time``, and per candidate
    ``omegas``, ``floors``, ``times``; ``deadbeat`` (the minimal-ρ gain) with its
    ``deadbeat_floor`` and ``deadbeat_time``."""
    who = "balanced_gain"
    scheme = check.scheme(scheme, who)
    tau = check.positive(tau, "tau", who)
    level = check.positive(level, "level", who)
    start = check.positive(start, "start", who)
    rec = theory.recommend_gain(scheme, tau)
    if omegas is None:
        omegas = rec["omega"] * np.geomspace(1.0, 1e-3, 32)
    omegas = np.asarray(omegas, dtype=float)
    steps = STEPS if t_end is None else max(5, round((float(t_end) - model.t0) / tau))
    floors, times = [], []
    for w in omegas:
        law = baumgarte(float(w), xi)
        f = gain_floor(model, law, scheme, tau, t_end, params=params, members=0)["predicted"]
        floors.append(f)
        times.append(_time_to(theory.step_matrix(law.A_tilde(model), scheme, tau), f, start,
                              level, steps) * tau)  # fmt: skip
    times = np.asarray(times)
    best = int(np.argmin(times)) if np.isfinite(times).any() else None
    dead_law = baumgarte(rec["omega"], rec["xi"])
    dead = gain_floor(model, dead_law, scheme, tau, t_end, params=params,
                      members=0)["predicted"]  # fmt: skip
    dead_R = theory.step_matrix(dead_law.A_tilde(model), scheme, tau)
    return {"omega": math.nan if best is None else float(omegas[best]),
            "time": math.inf if best is None else float(times[best]),
            "omegas": omegas, "floors": np.asarray(floors), "times": times,
            "deadbeat": rec["omega"], "deadbeat_xi": rec["xi"], "deadbeat_floor": dead,
            "deadbeat_time": _time_to(dead_R, dead, start, level, steps) * tau}  # fmt: skip


def _time_to(R, floor, start, level, steps) -> float:
    """The first step from which ``‖R^k‖∞ · start + floor`` stays below ``level`` (within
    ``steps``; inf where it does not)."""
    if not floor < level:
        return math.inf
    P = np.eye(R.shape[0])
    below = None
    for k in range(steps + 1):
        ok = float(np.abs(P).sum(axis=1).max()) * start + floor <= level
        if ok and below is None:
            below = k
        elif not ok:
            below = None
        P = R @ P
    return math.inf if below is None else float(below)
