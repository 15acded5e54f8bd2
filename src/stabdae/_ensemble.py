"""Ensembles: many initial constraint perturbations of one model, integrated in parallel.

:func:`ensemble` is a thin driver: it validates its arguments (:mod:`._validate`), places
the initial states (:func:`sample_perturbations`, the compiled sampler of
:mod:`.kernels.sampler`), runs the block-lockstep kernel (:mod:`.kernels.ensemble`) or,
with ``rtol``, the per-member adaptive kernel (:mod:`.kernels.adaptive`) over chunks of
members on threads, each chunk's traces fitted (:mod:`.kernels.decay`) by the thread that
integrated them, and builds the dataset (:mod:`._schema`) beside the theorems'
predictions (:mod:`.theory`).
"""

from __future__ import annotations

import time
import warnings
from collections import Counter

import numpy as np
import xarray as xr

from . import _validate as check
from . import theory
from ._integrate import IntegrationWarning
from ._laws import Theorem5
from ._model import Model
from ._schema import model_coords, provenance, schema_variable, variable
from ._schemes import dopri5, dopri5_embedded_weights
from ._status import Status
from .kernels.adaptive import adaptive_ensemble_for
from .kernels.decay import Summary
from .kernels.ensemble import BLOCK, ensemble_kernel_for
from .kernels.sampler import (
    CHUNK,
    SAMPLING_RTOL,
    draw_alphas,
    residual_rows_for,
    sampler_for,
)
from .kernels.threads import default_threads, run_chunks

__all__ = ["ensemble", "sample_perturbations"]

#: a member "decayed" when it ended below max(‖α⁰‖, this × the ensemble's median floor)
DECAYED_FLOOR_FACTOR = 10.0
#: samples stored by default over a fixed-step run (the largest spacing that divides it)
DEFAULT_SAMPLES = 200

#: why members stopped, as the summary warning names it
_STOPPED = {
    Status.SINGULAR_S: "singular S",
    Status.MASS_NOT_SPD: "mass matrix not SPD",
    Status.NONFINITE_STATE: "non-finite state",
    Status.DIVERGED: "diverged",
    Status.SAMPLING_FAILED: "not placed (sampling failed)",
    Status.STEP_TOO_SMALL: "step too small",
    Status.MAX_STEPS: "max_steps used up",
}


# --------------------------------------------------------------------- sampling
def sample_perturbations(model: Model, members: int, radius=(1e-6, 1e-2), seed=0, *,
                         params=None, t0=None, threads=None):  # fmt: skip
    """Initial states ``x⁰`` with prescribed constraint perturbations ``g(x⁰, t0) = α⁰``.

    Parameters
    ----------
    members : int
    radius : float or (low, high)
        ``‖α⁰‖∞`` is log-uniform in ``[low, high]``; directions are uniform.
    seed : int or numpy.random.Generator
    params : mapping or array, optional
    t0 : float, optional
        Time of the initial states (default the model's ``t0``).
    threads : int, optional
        Threads to place the members on (default numba's thread count); no number depends
        on it.

    Returns
    -------
    x0 : array (members, 2n)
    alpha0 : array (members, 2m + k)
        The achieved perturbation ``g(x⁰, t0)``.
    status : array (members,) of int8
        ``Status.SAMPLING_FAILED`` where Gauss–Newton did not reach ``α⁰`` to
        ``1e-12·‖α⁰‖∞`` (or to roundoff, for tiny ``α⁰``).
    """
    who = "sample_perturbations"
    model = check.model(model, who)
    members = check.count(members, "members", who)
    low, high = check.radius(radius, who)
    if not isinstance(seed, np.random.Generator):
        seed = check.seed(seed, who)
    p = check.params(model, params, who)
    t0 = model.t0 if t0 is None else check.real(t0, "t0", who)
    threads = _threads(threads, who)
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    targets = draw_alphas(model.n_residual, members, (low, high), rng)
    return _place(model, targets, p, t0, threads)


def _place(model, targets, p, t0, threads=None):
    sampler = sampler_for(model)
    M = targets.shape[0]
    x0 = np.empty((M, 2 * model.n))
    alpha0 = np.empty_like(targets)
    status = np.zeros(M, dtype=np.int8)
    x_ref = model.reference_state(p)
    run_chunks(
        lambda lo, hi: sampler(x_ref, t0, p, targets, x0, alpha0, status, lo, hi),
        -(-M // CHUNK), threads=threads,
    )  # fmt: skip
    return x0, alpha0, status


def _residual_rows(model, x, p, t0, threads=None):
    """``g(x_i, t0)`` for every row of ``x`` (compiled; NaN rows give NaN)."""
    kernel = residual_rows_for(model)
    out = np.empty((x.shape[0], model.n_residual))
    run_chunks(lambda lo, hi: kernel(x, t0, p, out, lo, hi), -(-x.shape[0] // CHUNK),
               threads=threads)  # fmt: skip
    return out


def _threads(threads, who: str):
    return None if threads is None else check.count(threads, "threads", who)


# --------------------------------------------------------------------- driver
def ensemble(
    model: Model,
    law,
    scheme=None,
    tau: float = 1e-3,
    t_end: float = 1.0,
    *,
    rtol: float | None = None,
    atol: float | None = None,
    members: int = 1024,
    radius=(1e-6, 1e-2),
    seed: int = 0,
    save_dt: float | None = None,
    x0=None,
    params=None,
    epsilon: float | None = None,
    divergence: float | None = None,
    block: int = BLOCK,
    threads: int | None = None,
    progress=None,
    residual_dtype="float32",
) -> xr.Dataset:
    """Integrate an ensemble of initial constraint perturbations in parallel.

    Parameters
    ----------
    model : Model
    law : Law or @njit function
    scheme : Scheme or str, default "rk2" (the midpoint rule; "dopri5" with ``rtol``)
    tau, t_end, save_dt : float
        Fixed step, final time, spacing of stored residual norms (as in :func:`integrate`;
        default ``save_dt``: about 200 samples).  With ``rtol``, ``tau`` is every member's
        first step and ``save_dt`` need not be a multiple of it.
    rtol, atol : float, optional
        Adaptive steps: each member controls its own step with the embedded Dormand–Prince
        5(4) pair (as :func:`integrate_adaptive`) to these tolerances (``atol`` defaults
        to ``rtol``).  The dataset then also has ``steps_accepted`` and
        ``rhs_evaluations`` per member, and only the continuous-time prediction
        ``beta_theory``.
    members : int
        Ensemble size (ignored when ``x0`` is given).
    radius : float or (low, high)
        Range of ``‖α⁰‖∞``, log-uniform; directions uniform.
    seed : int
        Seed (a non-negative integer, stored in the dataset) of the
        ``numpy.random.Generator`` that draws the perturbations.
    x0 : array (members, 2n), optional
        The user's own initial states instead of sampled ones.
    params : mapping or array, optional
        Physical parameters.
    epsilon : float, optional
        The ε of Definition 2: a member is *bounded* when ``max_t ‖g‖ ≤ ε`` and it decayed
        (ended below ``max(‖α⁰‖, 10 × the ensemble's median floor)``).  Default
        ``10 × radius high``.
    divergence : float, optional
        Residual norm above which a member is frozen and flagged ``diverged``
        (default ``1e3 × epsilon``).
    block : int
        Members integrated in lockstep per parallel work item (compile-time: a new value
        compiles a new kernel).  Does not change any number.
    threads : int, optional
        Threads to run the blocks on (default numba's thread count, ``NUMBA_NUM_THREADS``).
        Does not change any number.
    progress : callable ``(members_done, members)``, optional
        Called after each chunk of members has been integrated.
    residual_dtype : "float32" or "float64"
        Storage of ``residual_norm``: float32 (default) halves the memory of large
        ensembles (10⁶ members × 200 samples: 0.8 GB); float64 keeps every digit.

    Returns
    -------
    xarray.Dataset
        See ``docs/api.md``: ``residual_norm(member, time)`` (float32), ``alpha0``, ``x0``,
        ``x_final``, ``beta``, ``gamma``, ``residual_floor``, ``bounded``, ``diverged`` and
        ``diverged_step``, ``energy_drift``, ``status`` per member; ``fraction_bounded``,
        ``stability_radius``, ``beta_median`` and, for constant laws, ``beta_theory``,
        ``beta_theory_discrete``, ``spectral_radius``.

    Warns
    -----
    IntegrationWarning
        When members stopped (diverged, singular ``S``, …), with their count per reason;
        their rows are kept up to the stop, and ``status`` says why per member.
    """
    who = "ensemble"
    model = check.model(model, who)
    law = check.law(law, who)
    adaptive = rtol is not None
    if adaptive:
        given = None if scheme is None else check.scheme(scheme, who).name
        if given not in (None, "dopri5"):
            raise ValueError(
                f"{who}: adaptive steps (rtol given) use the Dormand–Prince 5(4) pair; scheme "
                f"must be 'dopri5' or left out, got {given!r}"
            )
        scheme = dopri5()
        rtol = check.positive(rtol, "rtol", who)
        atol = rtol if atol is None else check.positive(atol, "atol", who)
    elif atol is not None:
        raise ValueError(f"{who}: atol is for adaptive steps; give rtol as well")
    scheme = check.scheme(scheme, who, default="rk2")
    p = check.params(model, params, who)
    t0 = model.t0
    tau = check.positive(tau, "tau", who)
    span = check.span(t0, t_end, who)
    if adaptive:
        save_dt = (span / DEFAULT_SAMPLES if save_dt is None
                   else check.positive(save_dt, "save_dt", who))  # fmt: skip
        save_times = check.sample_times(t0, float(t_end), save_dt, who)
    else:
        nsteps, save_every = check.fixed_time_grid(span, tau, save_dt, who,
                                                   default_samples=DEFAULT_SAMPLES)  # fmt: skip
    block = check.block(block, model.n, who)
    rdtype = check.dtype(residual_dtype, "residual_dtype", ("float32", "float64"), who)
    low, high = check.radius(radius, who)
    seed = check.seed(seed, who)
    epsilon = 10.0 * high if epsilon is None else check.positive(epsilon, "epsilon", who)
    divergence = (1e3 * epsilon if divergence is None
                  else check.positive(divergence, "divergence", who))  # fmt: skip
    threads = _threads(threads, who)
    if progress is not None and not callable(progress):
        raise TypeError(f"{who}: progress must be a callable (done, total), got "
                        f"{type(progress).__name__}")  # fmt: skip
    if x0 is None:
        members = check.count(members, "members", who)
    else:
        x0 = check.initial_states(model, x0, who)
    bound = check.bound_law(law, model, who)

    clock = time.perf_counter()
    if x0 is None:
        targets = draw_alphas(model.n_residual, members, (low, high),
                              np.random.default_rng(seed))  # fmt: skip
        x0, alpha0, status = _place(model, targets, p, t0, threads)
    else:
        alpha0 = _residual_rows(model, x0, p, t0, threads)
        status = np.where(np.isfinite(x0).all(axis=1), 0, int(Status.NONFINITE_STATE))
        status = status.astype(np.int8)
    wall_sample = time.perf_counter() - clock

    M = x0.shape[0]
    clock = time.perf_counter()
    if adaptive:
        out = _run_adaptive(model, bound, x0, status, p, t0, save_times, rtol, atol, tau,
                            divergence, rdtype, threads, progress)  # fmt: skip
        run = dict(method="dopri5-adaptive", rtol=rtol, atol=atol, first_step=tau, t0=t0,
                   t_end=float(t_end), save_dt=save_dt)  # fmt: skip
    else:
        out = _run_fixed(model, bound, scheme, x0, p, t0, tau, nsteps, save_every, block,
                         divergence, rdtype, threads, progress)  # fmt: skip
        run = dict(tau=tau, t0=t0, t_end=t0 + nsteps * tau, save_dt=tau * save_every,
                   steps=nsteps)  # fmt: skip
    wall_integrate = time.perf_counter() - clock
    status = np.where(status != 0, status, out["status"]).astype(np.int8)
    clock = time.perf_counter()
    ds = _ensemble_dataset(
        model, p, law, scheme, bound, out["times"], x0, alpha0, out["norms"], out["x_final"],
        status, out["fail_step"], out["e0"], out["e1"], epsilon, out["summary"],
        dict(**run, members=M, seed=seed, radius_low=low, radius_high=high, epsilon=epsilon,
             divergence=divergence, sampling_rtol=SAMPLING_RTOL,
             threads=threads if threads is not None else default_threads()),
        extra=out.get("extra"),
    )  # fmt: skip
    # wall times (compilation included on a first call) for benchmarks; not part of the data
    ds.attrs.update(wall_sample_s=wall_sample, wall_integrate_s=wall_integrate,
                    wall_dataset_s=time.perf_counter() - clock)  # fmt: skip
    _warn_stopped(model, status)
    return ds


def _outputs(x0, nsave, rdtype):
    """The per-member outputs, allocated empty: the kernels write every element (the
    fixed-step kernel on its own threads, so that the pages are first touched there)."""
    M = x0.shape[0]
    return {"norms": np.empty((M, nsave), dtype=rdtype), "x_final": np.empty_like(x0),
            "status": np.empty(M, dtype=np.int8), "fail_step": np.empty(M, dtype=np.int64),
            "e0": np.empty(M), "e1": np.empty(M), "summary": Summary(M)}  # fmt: skip


def _run_fixed(model, bound, scheme, x0, p, t0, tau, nsteps, save_every, block, divergence,
               rdtype, threads, progress) -> dict:  # fmt: skip
    """The block-lockstep kernel over chunks of blocks on threads; each chunk's traces
    summarized and fitted by the thread that integrated them, while they are in its
    cache."""
    M = x0.shape[0]
    out = _outputs(x0, nsteps // save_every + 1, rdtype)
    out["times"] = times = t0 + tau * save_every * np.arange(nsteps // save_every + 1)
    kernel = ensemble_kernel_for(model, bound, scheme, block)
    norms, summary = out["norms"], out["summary"]

    def chunk(lo, hi):
        kernel(x0, t0, tau, nsteps, save_every, p, bound.matrix, bound.scalars, scheme.A,
               scheme.b, scheme.c, divergence, norms, out["x_final"], out["status"],
               out["fail_step"], out["e0"], out["e1"], lo, hi)  # fmt: skip
        summary.rows(norms, times, min(lo * block, M), min(hi * block, M))

    run_chunks(
        chunk, -(-M // block), threads=threads,
        progress=None if progress is None
        else lambda done, _: progress(min(M, done * block), M),
    )  # fmt: skip
    return out


def _run_adaptive(model, bound, x0, status, p, t0, save_times, rtol, atol, first_step,
                  divergence, rdtype, threads, progress) -> dict:  # fmt: skip
    """The per-member adaptive kernel over chunks of members on threads."""
    M = x0.shape[0]
    out = _outputs(x0, save_times.shape[0] + 1, rdtype)
    out["times"] = times = np.concatenate([[t0], save_times])
    out["norms"].fill(np.nan)
    out["fail_step"].fill(-1)
    out["e0"].fill(np.nan)
    out["e1"].fill(np.nan)
    out["status"][:] = status  # members that could not be placed stay out
    steps = np.zeros(M, dtype=np.int64)
    nfev = np.zeros(M, dtype=np.int64)
    kernel = adaptive_ensemble_for(model, bound)
    scheme = dopri5()
    norms, summary = out["norms"], out["summary"]

    def chunk(lo, hi):
        kernel(x0, t0, save_times, p, bound.matrix, bound.scalars, scheme.A, scheme.b,
               dopri5_embedded_weights(), scheme.c, rtol, atol, first_step, 10_000_000,
               divergence, norms, out["x_final"], out["status"], out["fail_step"], out["e0"],
               out["e1"], steps, nfev, lo, hi)  # fmt: skip
        summary.rows(norms, times, lo, hi)

    run_chunks(chunk, M, threads=threads, progress=progress)
    out["extra"] = {"steps_accepted": steps, "rhs_evaluations": nfev}
    return out


def _warn_stopped(model, status) -> None:
    """One warning for the members that stopped, counted by reason (as :func:`integrate`
    warns for one trajectory)."""
    stopped = Counter(int(s) for s in status[status != 0])
    if not stopped:
        return
    reasons = ", ".join(f"{n} {_STOPPED[Status(s)]}" for s, n in sorted(stopped.items()))
    total = sum(stopped.values())
    warnings.warn(
        f"ensemble({model.name}): {total} of {status.shape[0]} members stopped: {reasons}; "
        "their samples up to the stop are kept (see the status variable)",
        IntegrationWarning,
        stacklevel=3,
    )


def _ensemble_dataset(model, p, law, scheme, bound, times, x0, alpha0, norms, x_final,
                      status, fail_step, e0, e1, epsilon, summary, run, extra=None):  # fmt: skip
    ok = status == 0
    max_res, final = summary.largest, summary.last
    beta, gamma, floor = summary.beta, summary.gamma, summary.floor
    alpha_norm = np.max(np.abs(alpha0), axis=1)
    floor_ref = float(np.nanmedian(np.where(ok, floor, np.nan))) if ok.any() else np.nan
    decayed = ok & (final <= np.maximum(alpha_norm, DECAYED_FLOOR_FACTOR * floor_ref))
    bounded = ok & (max_res <= epsilon) & decayed
    diverged = status == int(Status.DIVERGED)
    diverged |= status == int(Status.NONFINITE_STATE)
    diverged |= status == int(Status.SINGULAR_S)

    coords = {
        "member": variable("member", np.arange(x0.shape[0]), "ensemble member", "1"),
        **model_coords(model, times),
    }
    values = {
        "residual_norm": norms,
        "alpha0": alpha0,
        "alpha0_norm": alpha_norm,
        "x0": x0,
        "x_final": x_final,
        "beta": beta,
        "gamma": gamma,
        "residual_floor": floor,
        "max_residual": max_res,
        "bounded": bounded.astype(np.int8),
        "diverged": diverged.astype(np.int8),
        "diverged_step": fail_step,
        "status": status,
        "fraction_bounded": float(bounded.mean()),
        "stability_radius": _stability_radius(alpha_norm, bounded),
        "beta_median": float(np.nanmedian(beta)) if np.isfinite(beta).any() else np.nan,
    }
    if model.energy is not None:
        values["energy_drift"] = e1 - e0
    values.update(extra or {})
    values.update(_theory_values(law, model, p, scheme, run.get("tau"), x0, x_final, times,
                                 norms, alpha0, floor))  # fmt: skip
    data = {name: schema_variable(name, val, model) for name, val in values.items()}
    data["residual_norm"].attrs["comment"] = (
        f"stored as {norms.dtype}; " + data["residual_norm"].attrs["comment"]
    )
    attrs = provenance(model, p, law, scheme, f"ensemble of {x0.shape[0]} members", **run)
    attrs["residual_norm_dtype"] = str(norms.dtype)
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _stability_radius(alpha_norm, bounded) -> float:
    """Largest δ with every sampled ‖α⁰‖ ≤ δ bounded: just below the smallest failure."""
    if bounded.all():
        return float(alpha_norm.max())
    return float(alpha_norm[~bounded].min())


def _theory_values(law, model, p, scheme, tau, x0, x_final, times, norms, alpha0,
                   floor) -> dict:  # fmt: skip
    """The theorems' predictions stored beside the measurements (:mod:`stabdae.theory`)."""
    if law.is_constant and tau is None:  # adaptive steps: only the continuous rate
        return {"beta_theory": theory.continuous(law.A_tilde(model))["beta"]}
    if law.is_constant:
        return theory.predictions(model, law, scheme, tau)
    if not isinstance(law, Theorem5):
        return {}
    # Theorem 5 over the states the ensemble visited (its initial and final states)
    states = np.concatenate([x0, x_final])
    c = theory.theorem5(model, law, states, params=p)
    out = {"lambda_min_W": c["lambda_min_W"], "beta_theorem5_proven": c["beta_proven"],
           "beta_theorem5_printed": c["beta_printed"]}  # fmt: skip
    # the Lyapunov argument bounds the 2-norm: γ = √(l_m/l₁)‖α⁰‖₂ also bounds ‖α(t)‖∞
    alpha2 = np.linalg.norm(alpha0, axis=1)
    for which in ("proven", "printed"):
        out[f"bound_{which}_held"] = theory.bound_held(
            times, norms, alpha2, c[f"beta_{which}"], c["gamma_factor"], floor
        ).astype(np.int8)
    out["gamma_theorem5"] = c["gamma_factor"] * alpha2
    return out
