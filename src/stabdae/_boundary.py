"""The stability boundary in τ, found by bisection rather than read off a grid.

:func:`boundary` brackets the largest step size at which an ensemble is still stable and
narrows the bracket by bisection in ``log τ`` with small classifier ensembles, then
confirms the result with the full ensemble.  Beside it stand the theory's limits for a
constant law: the spectral one (``ρ(R(τÃ)) = 1``), the weighted-norm one, and the step at
which Theorems 6/7 *with* condition 4 stop guaranteeing ``‖g‖ ≤ ε`` because the floor that
the scheme's local error forces, ``ε(τ) = ‖P⁻¹‖ max_k ‖P e_k‖ / (1 − ‖R‖_P)``, reaches ε.
"""

from __future__ import annotations

import math
import sys
import warnings

import numpy as np
import xarray as xr

from . import _validate as check
from . import theory
from ._ensemble import ensemble
from ._integrate import IntegrationWarning, integrate
from ._measures import (
    BISECTION,
    BRACKETED,
    CONFIRM,
    CONFIRM_FAILS,
    ENDS,
    GUIDED,
    BRACKETED_BY_MOTION,
    HIGH_END_STABLE,
    LOW_END_FAILS,
    LOW_END_MOTION,
    PROBE_UNDECIDED,
    STAGES,
    V_STABLE,
    V_UNDECIDED,
    VERDICTS,
    ensemble_verdict,
)
from ._codes import VerdictReason
from ._schema import cf_dataset, provenance, schema_variable, variable
from ._sequential import MIN_BATCH, Sequential
from .engine.ensemble.block import BLOCK

__all__ = ["boundary", "floor_limit"]

#: the first probes inside the bracket sit this far (relative) on either side of the
#: theory's spectral limit, when there is one: if the measured boundary is near it, the
#: bisection starts from a bracket of a few per cent instead of the user's decades
GUIDE = 0.02
#: steps per probe for a bracket of relative width ``rtol``: one member just outside a
#: limit where ``ρ ≈ 1 + c·rtol`` grows by ``e^{c·rtol·steps}`` over the run, which the
#: growth test must see (``c`` = ``τ dρ/dτ`` at the limit, of order 1)
STEPS_PER_RTOL = 10.0
MIN_STEPS = 2000
#: confirmation steps down from a bracket the full ensemble rejected, at most
MAX_CONFIRM = 40


def boundary(
    model,
    law,
    scheme=None,
    tau=None,
    *,
    rtol: float = 1e-3,
    q: float = 0.0,
    members: int = 1024,
    search_members: int = 64,
    steps: int | None = None,
    t_end: float | None = None,
    radius=(1e-6, 1e-2),
    seed: int = 0,
    params=None,
    epsilon: float | None = None,
    divergence: float | None = None,
    block: int = BLOCK,
    threads: int | None = None,
    progress=False,
    confidence: float | None = None,
) -> xr.Dataset:
    """The largest step size τ* at which an ensemble is stable, to a relative ``rtol``.

    Parameters
    ----------
    model, law, scheme
        As for :func:`stabdae.ensemble` (fixed steps; default scheme ``"rk2"``).
    tau : (low, high)
        The bracket to search: the ensemble must be stable at ``low`` and not at ``high``
        (otherwise τ* is NaN and ``tau_star_reason`` says which end failed).
    rtol : float
        Relative width of the final bracket: ``tau_star_high / tau_star_low ≤ 1 + rtol``.
    q : float
        Allowed fraction of members not stable: a probe is *stable* when the fraction of
        stable members (``verdict``) is at least ``1 − q``, *unstable* when more than
        ``q`` are unstable, and *undecided* otherwise; an undecided probe ends the search
        (``tau_star_reason`` says so; ``tau_star_low`` and ``tau_star_high`` keep the
        last decided bracket).  For a constant law no probe past the spectral limit is
        stable (a member is stable there never), so τ* never lies beyond it.
    members, search_members : int
        Ensemble sizes of the confirmation and of the bisection probes.
    steps : int, optional
        Steps every probe runs (``t_end = t0 + steps·τ``); default
        ``max(2000, 10/rtol)``, enough for a member just outside the limit to grow
        visibly.  A stable law near its limit decays as slowly as an unstable one grows:
        the run must be long in steps, not in time.
    t_end : float, optional
        Instead of ``steps``: every probe runs to this time (``τ`` is rounded down so that
        it divides the span).  For models whose motion the scheme does not keep bounded
        over long runs (an undamped oscillator gains energy at every step under Euler and
        the midpoint rule, and its residual floor grows with it), at the price of a
        coarser boundary: ``ρ(R) − 1`` is resolved to about ``1/steps``.
    radius, seed, params, epsilon, divergence, block, threads
        As for :func:`stabdae.ensemble`; every probe draws the same perturbations.
    progress : bool or callable ``(text)``
        ``True`` prints a line per probe on stderr; a callable receives that line.
    confidence : float, optional
        Decide every probe at a confidence instead (needs ``q > 0``): each probe runs
        members until it is decided, at most ``members`` (:class:`stabdae.Sequential`,
        first look ``search_members``, at least 16), with the error budget
        ``1 − confidence`` split evenly over the most probes the search can take (the
        bracket's ends, two beside the spectral limit, the bisection down to ``rtol``).
        With probability at least ``confidence`` every decision is right, and the
        unstable fraction crosses ``q`` between ``tau_star_low`` and ``tau_star_high``
        (``tau_star_confidence``); no confirmation stage follows (each probe already
        ran the members its decision needed).

    Returns
    -------
    xarray.Dataset
        ``tau_star`` (the bracket's geometric mean; for a constant law with the spectral
        limit as the bracket's top where it lies inside) with ``tau_star_low`` (stable, with
        the full ensemble) and ``tau_star_high`` (not stable), ``tau_star_reason``; the
        full ensemble's ``fraction_stable`` at ``tau_star_low`` with its Wilson interval
        and ``members_run``/``members_stable``; every probe (``probe_tau``,
        ``probe_members``, ``probe_fraction_stable``, ``probe_stable``,
        ``probe_verdict``, ``probe_stage``, ``probe_motion_unstable``: the scheme is
        unstable on the motion itself there, its unperturbed run diverges or leaves ε,
        and every member is unstable; where that holds at ``tau_star_high`` or at the
        bracket's low end, ``tau_star_reason`` says so); for a constant law the theory's ``tau_limit_spectral``,
        ``tau_limit_weighted_norm`` and ``tau_limit_floor`` (Theorems 6/7 with
        condition 4, see :func:`floor_limit`) and ``spectral_radius`` at τ*.

    Notes
    -----
    Stability is assumed to be lost once as τ grows (an interval ``(0, τ*]``); where it
    is not, the bisection finds one crossing and the probes show where it looked.
    """
    who = "boundary"
    model = check.model(model, who)
    law = check.law(law, who)
    scheme = check.scheme(scheme, who, default="rk2")
    p = check.params(model, params, who)
    if tau is None:
        raise TypeError(f"{who}: give the bracket to search, tau=(low, high)")
    try:
        lo, hi = (float(v) for v in tau)
    except (TypeError, ValueError):
        raise ValueError(f"{who}: tau must be a pair (low, high) of step sizes, got "
                         f"{tau!r}") from None  # fmt: skip
    if not (0 < lo < hi and math.isfinite(hi)):
        raise ValueError(f"{who}: tau needs 0 < low < high, got ({lo:g}, {hi:g})")
    rtol = check.positive(rtol, "rtol", who)
    if not 1e-9 <= rtol <= 1.0:
        raise ValueError(f"{who}: rtol must lie in [1e-9, 1], got {rtol:g}")
    q = check.real(q, "q", who)
    if not 0.0 <= q < 1.0:
        raise ValueError(f"{who}: q (the allowed unstable fraction) must lie in [0, 1), "
                         f"got {q:g}")  # fmt: skip
    members = check.count(members, "members", who)
    search_members = check.count(search_members, "search_members", who)
    if steps is not None and t_end is not None:
        raise ValueError(f"{who}: give steps or t_end, not both")
    if t_end is not None:
        span = check.span(model.t0, t_end, who)
    steps = (max(MIN_STEPS, math.ceil(STEPS_PER_RTOL / rtol)) if steps is None
             else check.count(steps, "steps", who))  # fmt: skip
    low_r, high_r = check.radius(radius, who)
    epsilon = 10.0 * high_r if epsilon is None else check.positive(epsilon, "epsilon", who)
    say = _reporter(progress, who)
    plan = None
    if confidence is not None:
        if not q > 0.0:
            raise ValueError(f"{who}: with confidence, q must be above 0 (no number of "
                             "members shows a fraction to be 0)")  # fmt: skip
        most = 4 + math.ceil(math.log2(max(2.0, math.log(hi / lo) / math.log1p(rtol)))) + 1
        confidence = check.real(confidence, "confidence", who)
        plan = Sequential.of({"confidence": 1.0 - (1.0 - confidence) / most
                              if 0.0 < confidence < 1.0 else confidence, "q": q,
                              "max": members,
                              "batch": min(members, max(MIN_BATCH, search_members))}, who)

    probes: list[tuple] = []

    def probe(t: float, n: int, stage: int) -> tuple[int, float]:
        """The verdict on the ensemble of ``n`` members at ``t`` (with ``t_end``, at the
        step ≤ ``t`` that divides the span, which it returns):
        :func:`._measures.ensemble_verdict` with the allowed fraction ``q``."""
        k = steps if t_end is None else max(1, math.ceil(span / t * (1.0 - 1e-12)))
        t = t if t_end is None else span / k
        with warnings.catch_warnings():  # stopped members are what the probe counts
            warnings.simplefilter("ignore", IntegrationWarning)
            ds = ensemble(model, law, scheme, t, model.t0 + k * t,
                          members=n if plan is None else plan,
                          radius=(low_r, high_r), seed=seed, save_dt=k * t, params=p,
                          epsilon=epsilon, divergence=divergence, block=block,
                          threads=threads, traces="none")  # fmt: skip
        frac = float(ds.fraction_stable)
        if plan is None:
            v = ensemble_verdict(int(ds.members_run), int(ds.members_stable),
                                 int(ds.members_unstable), q)  # fmt: skip
        else:  # the sequential decision; the members it took
            v, n = int(ds.decision), int(ds.members_used)
        probes.append((t, n, frac, v, stage, ds))
        say(f"{who}: tau = {t:.6g} {VERDICTS[v].upper() if v != V_STABLE else 'stable'} "
            f"({int(ds.members_stable)} stable, {int(ds.members_unstable)} unstable, "
            f"{int(ds.members_undecided)} undecided of {int(ds.members_run)} members; "
            f"{STAGES[stage]})")
        return v, t

    constant = law.is_constant
    A = law.A_tilde(model) if constant else None
    limits = _limits(A, scheme)

    # A probe that cannot decide ends the search: its reason says so, and tau_star_low
    # and tau_star_high keep the last bracket the probes decided (never a guess).
    reason = BRACKETED
    v_lo, lo = probe(lo, search_members, ENDS)
    if v_lo != V_STABLE:
        good, bad = math.nan, lo
        reason = (PROBE_UNDECIDED if v_lo == V_UNDECIDED
                  else LOW_END_MOTION if _on_motion(probes[-1][5])
                  else LOW_END_FAILS)  # fmt: skip
    elif (end := probe(hi, search_members, ENDS))[0] == V_STABLE:
        good, bad, reason = end[1], math.nan, HIGH_END_STABLE
    elif end[0] == V_UNDECIDED:
        good, bad, reason = lo, math.nan, PROBE_UNDECIDED
    else:
        good, bad = lo, end[1]
        spectral = limits["tau_limit_spectral"]
        if math.isfinite(spectral) and good < spectral < bad:
            for t in (spectral * (1.0 - GUIDE), spectral * (1.0 + GUIDE)):
                if not good < t < bad:
                    continue
                v, t = probe(t, search_members, GUIDED)
                if v == V_STABLE:
                    good = max(good, t)
                elif v == V_UNDECIDED:
                    break  # the bisection goes on from the decided bracket
                else:
                    bad = min(bad, t)
                    break
        good, bad, decided = _bisect(probe, good, bad, rtol, search_members)
        if not decided:
            reason = PROBE_UNDECIDED
        elif plan is not None:
            pass  # every probe was decided at the plan's confidence: nothing to confirm
        # the full ensemble at the largest stable step; where it fails, step down
        # (doubling the step, the last step down to the bracket's low end itself) until
        # it passes, then bisect again with the full ensemble
        elif (v := probe(good, members, CONFIRM)[0]) == V_UNDECIDED:
            reason = PROBE_UNDECIDED
        elif v != V_STABLE:
            bad, width = good, rtol
            for _ in range(MAX_CONFIRM):
                at_low_end = bad / (1.0 + width) <= lo
                v, t = probe(lo if at_low_end else bad / (1.0 + width), members, CONFIRM)
                if v == V_STABLE:
                    good = t
                    break
                if v == V_UNDECIDED:
                    good, reason = math.nan, PROBE_UNDECIDED
                    break
                if at_low_end:  # not stable down to the low end
                    good, reason = math.nan, CONFIRM_FAILS
                    break
                bad, width = t, 2.0 * width
            else:
                good, reason = math.nan, CONFIRM_FAILS
            if reason == BRACKETED:
                good, bad, decided = _bisect(probe, good, bad, rtol, members, stage=CONFIRM)
                if not decided:
                    reason = PROBE_UNDECIDED

    # a constant law is stable at no τ past the spectral limit: the bracket's top is the
    # limit where it lies inside, so τ* (the bracket's geometric mean) never lies beyond it
    top = min(bad, limits["tau_limit_spectral"]) if good <= limits["tau_limit_spectral"] \
        else bad  # fmt: skip
    star = math.sqrt(good * top) if reason == BRACKETED else math.nan
    high = _last(probes, bad, None)
    if reason == BRACKETED and high is not None and _on_motion(high):
        reason = BRACKETED_BY_MOTION
    at = _last(probes, good, None if plan is not None else members)
    floor = (floor_limit(model, law, scheme, epsilon, steps=steps if t_end is None else None,
                         t_end=t_end, params=p, rtol=rtol,
                         tau_max=limits["tau_limit_spectral"])
             if constant else math.nan)  # fmt: skip
    return _dataset(model, p, law, scheme, dict(
        tau_star=star, tau_star_low=good, tau_star_high=bad, reason=reason, probes=probes,
        at=at, floor=floor, limits=limits, A=A, rtol=rtol, q=q, steps=steps,
        members=members, search_members=search_members, seed=seed, radius=(low_r, high_r),
        epsilon=epsilon, bracket=(lo, hi),
        confidence=math.nan if plan is None else confidence,
        probe_confidence=math.nan if plan is None else plan.confidence))  # fmt: skip


def _on_motion(ds) -> bool:
    """Whether a probe's scheme is unstable on the motion itself, as its members' verdicts
    say (:func:`._measures.verdict`: the unperturbed run blew up or left ε beyond
    roundoff, where the law's linear part is stable)."""
    return "verdict_reason" in ds and bool(
        (ds["verdict_reason"] == int(VerdictReason.MOTION_UNSTABLE)).any())


def _bisect(probe, good, bad, rtol, n, stage=BISECTION):
    """Geometric bisection of ``[good, bad]`` until ``bad/good ≤ 1 + rtol`` (or until the
    probes' steps cannot come closer: with ``t_end``, steps that divide the span):
    ``(good, bad, decided)``, ``decided`` false where a probe was undecided (the bracket
    is then the last decided one)."""
    while bad > good * (1.0 + rtol):
        v, t = probe(math.sqrt(good * bad), n, stage)
        if t <= good or t >= bad:
            break
        if v == V_UNDECIDED:
            return good, bad, False
        if v == V_STABLE:
            good = t
        else:
            bad = t
    return good, bad, True


def _last(probes, t, n):
    """The full-ensemble probe at step ``t`` (``n`` None: any probe at ``t``; None when
    there is none)."""
    for pt, pn, _, _, _, ds in reversed(probes):
        if pt == t and (n is None or pn == n):
            return ds
    return None


def _limits(A, scheme) -> dict:
    if A is None:
        return {"tau_limit_spectral": math.nan, "tau_limit_weighted_norm": math.nan}
    return {f"tau_limit_{c}": theory.tau_limit(A, scheme, c)
            for c in ("spectral", "weighted_norm")}  # fmt: skip


def floor_limit(model, law, scheme, epsilon: float, *, steps: int | None = MIN_STEPS,
                t_end: float | None = None, params=None, rtol: float = 1e-3,
                tau_max: float | None = None) -> float:  # fmt: skip
    """The largest τ at which Theorems 6/7 with condition 4 still guarantee
    ``‖g_k‖∞ ≤ epsilon`` from the model's reference state, for a constant law.

    At each τ the trajectory from the reference state (``α⁰ = 0``) is integrated for
    ``steps`` steps, every step kept; its one-step remainders ``e_k = g_{k+1} − R g_k``
    (or up to ``t_end``, τ rounded down to divide the span) give the floor
    :func:`stabdae.theory.condition4` (``ε(τ)``), which grows with τ
    (the local error) and without bound as ``ρ(R) → 1``.  The limit is where ``ε(τ)``
    reaches ``epsilon``, by bisection in ``log τ`` to ``rtol`` below ``tau_max`` (default
    the spectral limit); 0 when the floor is above ``epsilon`` already at
    ``1e-4 tau_max``.
    """
    who = "floor_limit"
    law = check.law(law, who)
    if not law.is_constant:
        raise ValueError(f"{who}: needs a constant law (Ã independent of the state)")
    scheme = check.scheme(scheme, who)
    p = check.params(model, params, who)
    A = law.A_tilde(model)
    if tau_max is None:
        tau_max = theory.tau_limit(A, scheme, "spectral")
    if not math.isfinite(tau_max) or tau_max <= 0:
        return math.nan

    def floor_at(t):
        k = steps if t_end is None else max(1, math.ceil((t_end - model.t0) / t * (1 - 1e-12)))
        t = t if t_end is None else (t_end - model.t0) / k
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", IntegrationWarning)
            traj = integrate(model, None, law, scheme, t, model.t0 + k * t, t, params=p)
        g = traj.residual.values
        if not np.all(np.isfinite(g)):
            return math.inf
        return theory.condition4(theory.step_matrix(A, scheme, t), g)["epsilon"]

    good, bad = 1e-4 * tau_max, tau_max
    if not floor_at(good) <= epsilon:
        return 0.0
    while bad > good * (1.0 + rtol):
        mid = math.sqrt(good * bad)
        if floor_at(mid) <= epsilon:
            good = mid
        else:
            bad = mid
    return good


def _reporter(progress, who):
    if progress is True:
        return lambda text: print(text, file=sys.stderr, flush=True)
    if progress is False or progress is None:
        return lambda text: None
    if callable(progress):
        return progress
    raise TypeError(f"{who}: progress must be True, False or a callable (text), got "
                    f"{type(progress).__name__}")  # fmt: skip


def _dataset(model, p, law, scheme, r) -> xr.Dataset:
    probes = r["probes"]
    at = r["at"]
    scalars = {
        "tau_star": r["tau_star"], "tau_star_low": r["tau_star_low"],
        "tau_star_high": r["tau_star_high"], "tau_limit_floor": r["floor"], **r["limits"],
    }  # fmt: skip
    if at is not None:
        for name in ("fraction_stable", "fraction_stable_low", "fraction_stable_high",
                     "members_run", "members_stable", "members_unstable", "members_undecided",
                     "members_diverged", "members_growing"):  # fmt: skip
            scalars[name] = at[name].values[()]
    else:
        scalars.update(fraction_stable=math.nan, fraction_stable_low=math.nan,
                       fraction_stable_high=math.nan, members_run=0, members_stable=0,
                       members_unstable=0, members_undecided=0, members_diverged=0,
                       members_growing=0)  # fmt: skip
    if r["A"] is not None and math.isfinite(r["tau_star"]):
        scalars["spectral_radius"] = theory.spectral_radius_of(r["A"], scheme, r["tau_star"])
    else:
        scalars["spectral_radius"] = math.nan
    data = {name: schema_variable(name, val, model, dims=())
            for name, val in scalars.items()}  # fmt: skip
    data["tau_star_reason"] = schema_variable("tau_star_reason", np.int8(r["reason"]), model)
    data["tau_star_confidence"] = schema_variable("tau_star_confidence", r["confidence"], model)
    columns = {
        "probe_tau": [x[0] for x in probes], "probe_members": [x[1] for x in probes],
        "probe_fraction_stable": [x[2] for x in probes],
        "probe_stable": [np.int8(x[3] == V_STABLE) for x in probes],
        "probe_verdict": [np.int8(x[3]) for x in probes],
        "probe_stage": [np.int8(x[4]) for x in probes],
        "probe_motion_unstable": [np.int8(_on_motion(x[5])) for x in probes],
    }  # fmt: skip
    for name, vals in columns.items():
        data[name] = schema_variable(name, np.asarray(vals), model, dims=("probe",))
    attrs = provenance(model, p, law, scheme, "stabdae.boundary: the largest stable step "
                       "size, bisected", tau=r["tau_star"])  # fmt: skip
    attrs.update(rtol=r["rtol"], q=r["q"], steps=r["steps"], members=r["members"],
                 search_members=r["search_members"], seed=r["seed"],
                 radius_low=r["radius"][0], radius_high=r["radius"][1],
                 epsilon=r["epsilon"], bracket_low=r["bracket"][0],
                 bracket_high=r["bracket"][1])  # fmt: skip
    if math.isfinite(r["probe_confidence"]):
        attrs["probe_confidence"] = r["probe_confidence"]
    coords = {"probe": variable("probe", np.arange(len(probes)), "probe index", "1")}
    return cf_dataset(data, coords=coords, attrs=attrs)
