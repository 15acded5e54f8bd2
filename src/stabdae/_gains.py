"""Gains that weigh the floor: what a constant law's residual settles on, and the gain that
reaches a requested residual soonest.

The gain that minimizes ``ρ(R(τÃ))`` (:func:`stabdae.theory.recommend_gain`, deadbeat
where the scheme allows) makes the transient vanish in a step or two, but the residual
does not go to zero: each step adds the scheme's local error on the constraints, and the
law propagates it, ``g_{k+1} = R g_k + e_k``.  A stiff gain both contracts harder and
makes ``e_k`` larger (the stages evaluate ``Ã g`` far from the manifold's tangent), so
its floor can be decades above a gentle gain's.

:func:`gain_floor` predicts the floor as the quasi-static forced response
``max_k ‖(I − R)⁻¹ e_k‖∞``: ``e_k`` is the residual one step of the scheme makes from a
state on the manifold, taken at states of the run from the reference state (its last
fifth, where a floor is read), each first put on the manifold by the Gauss–Newton
projection of the perturbation sampler (target ``g = 0``).  Beside it, a small ensemble
measures the floor its members settle on.  :func:`balanced_gain` then weighs transient
and floor: among critically damped Baumgarte gains it takes the one whose predicted
residual, ``‖R^k‖∞ · start + floor``, first stays below ``level`` soonest.
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
from .engine.sampler import sampler_for

__all__ = ["balanced_gain", "gain_floor"]

#: states of the reference run (its last fifth) the remainder is taken at
SAMPLES = 32
#: steps of the runs when no ``t_end`` is given
STEPS = 2000


def _on_manifold(model, x, t, p):
    """``x`` moved onto the constraint manifold at ``t`` (``g = 0``) by the sampler's
    Gauss–Newton steps from it; None where they do not get there."""
    sampler = sampler_for(model)
    ng = model.n_residual
    out = np.empty((1, x.size))
    alpha = np.empty((1, ng))
    status = np.zeros(1, dtype=np.int8)
    sampler(np.ascontiguousarray(x, dtype=float), float(t), p, np.zeros((1, ng)), True, out,
            alpha, status, 0, 1)  # fmt: skip
    return out[0] if status[0] == 0 and np.all(np.isfinite(out[0])) else None


def gain_floor(model, law, scheme, tau: float, t_end: float | None = None, *, params=None,
               samples: int = SAMPLES, members: int = 16) -> dict:  # fmt: skip
    """The residual floor a constant law settles on under ``scheme`` at step ``tau``:
    predicted from the scheme's one-step remainders, and measured.

    Returns
    -------
    dict
        ``predicted``: ``max_k ‖(I − R)⁻¹ e_k‖∞`` over ``samples`` states of the last fifth
        of the run from the reference state to ``t_end`` (default ``STEPS`` steps), each
        put on the manifold before its step (``inf`` where ``ρ(R) ≥ 1`` or the run does
        not stay finite); ``remainder``: the largest ``‖e_k‖∞``; ``measured``: the median
        ``residual_floor`` of an ensemble of ``members`` members with ``‖α⁰‖∞`` in
        ``[1e-10, 1e-9]`` (NaN with ``members=0``); ``rho``: ``ρ(R(τÃ))``.
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
            out["measured"] = float(np.nanmedian(ds.residual_floor.values))
        if not rho < 1.0:
            return out
        ref = integrate(model, None, law, scheme, tau, t0 + steps * tau, tau, params=p)
        xs, ts = ref.x.values, ref.time.values
        if not np.all(np.isfinite(xs)):
            return out
        pick = np.unique(np.linspace(int(0.8 * steps), steps - 1, samples).astype(int))
        worst = remainder = 0.0
        M = np.linalg.inv(np.eye(R.shape[0]) - R)
        for k in pick:
            x = _on_manifold(model, xs[k], ts[k], p)
            if x is None:
                return out
            g = integrate(model, x, law, scheme, tau, ts[k] + tau, tau, params=p,
                          t0=ts[k]).residual.values  # fmt: skip
            e = g[1] - R @ g[0]
            remainder = max(remainder, float(np.abs(e).max()))
            worst = max(worst, float(np.abs(M @ e).max()))
    out.update(predicted=worst, remainder=remainder)
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
