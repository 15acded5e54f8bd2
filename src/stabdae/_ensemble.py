"""Ensembles: many initial constraint perturbations of one model, integrated in parallel.

Layering (STYLE: driver over kernel): :func:`ensemble` validates, samples the
perturbations (:mod:`._sampling`), calls the compiled block-lockstep kernel
(:mod:`._soa`) — or, with ``rtol``, the per-member adaptive kernel (:mod:`._adaptive`) —
fits decay rates (:mod:`._estimate`) and builds the dataset.
"""

from __future__ import annotations

import math
import time

import numpy as np
import xarray as xr

from ._adaptive import adaptive_ensemble_for, save_grid
from ._dataset import model_coords, provenance, variable
from ._estimate import Summary
from ._integrate import _positive, _whole_multiple
from ._laws import as_law, bind_law
from ._model import Model
from ._rhs import kernels_for
from ._sampling import CHUNK, SAMPLING_RTOL, build_residual_rows, build_sampler, draw_alphas
from ._schemes import as_scheme, dopri5, dopri5_embedded_weights
from ._soa import BLOCK, build_soa_kernel, tableau_pattern
from ._status import Status, status_flag_attrs
from ._threads import default_threads, run_chunks

__all__ = ["ensemble", "sample_perturbations"]

_DIVERGED = int(Status.DIVERGED)
#: a member "decayed" when it ended below max(‖α⁰‖, this × the ensemble's median floor)
DECAYED_FLOOR_FACTOR = 10.0


def _memo(model: Model, key: tuple, build):
    """``build()`` once per model and key (every new closure is a new compilation)."""
    cache = model._kernel_cache
    if key not in cache:
        cache[key] = build()
    return cache[key]


def _unstabilized(model: Model):
    from ._laws import none

    return kernels_for(model, bind_law(none(), model))


def sampler_for(model: Model):
    """The compiled perturbation sampler of ``model`` (memoized)."""
    return _memo(model, ("sampler",), lambda: build_sampler(_unstabilized(model)))


def ensemble_kernel_for(model: Model, bound, scheme, block: int):
    """The block-lockstep ensemble kernel (memoized per law kind, the kinds of the scheme's
    coefficients, block and the shape of the law's matrix)."""
    pattern = tableau_pattern(scheme)
    shape = bound.matrix.shape
    return _memo(model, ("ensemble", bound.code, bound.fn, pattern, block, shape),
                 lambda: build_soa_kernel(kernels_for(model, bound), pattern, block,
                                          len(model.param_vector(None)), shape))  # fmt: skip


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
    p = model.param_vector(params)
    t0 = model.t0 if t0 is None else float(t0)
    low, high = _radius(radius)
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    targets = draw_alphas(model.n_residual, _count(members, "members"), (low, high), rng)
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
    kernel = _memo(model, ("residual_rows",),
                   lambda: build_residual_rows(_unstabilized(model)))  # fmt: skip
    out = np.empty((x.shape[0], model.n_residual))
    run_chunks(lambda lo, hi: kernel(x, t0, p, out, lo, hi), -(-x.shape[0] // CHUNK),
               threads=threads)  # fmt: skip
    return out


def _radius(radius) -> tuple[float, float]:
    vals = np.atleast_1d(np.asarray(radius, dtype=np.float64))
    if vals.shape not in ((1,), (2,)) or not np.all(np.isfinite(vals)) or np.any(vals <= 0):
        raise ValueError(
            f"ensemble: radius must be a positive number or a pair (low, high) of positive "
            f"numbers, got {radius!r}"
        )
    low, high = float(vals[0]), float(vals[-1])
    if low > high:
        raise ValueError(f"ensemble: radius low = {low:g} exceeds high = {high:g}")
    return low, high


def _count(value, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"ensemble: {name} must be a positive integer, got {value!r}")
    return int(value)


def _fixed_step_grid(span: float, tau: float, save_dt) -> tuple[int, int]:
    """(steps, steps between stored samples); default about 200 samples."""
    nsteps = _whole_multiple(span, tau, "t_end - t0", "tau")
    if save_dt is None:
        save_every = max(1, nsteps // 200)
        while nsteps % save_every:
            save_every -= 1
        return nsteps, save_every
    save_every = _whole_multiple(_positive(save_dt, "save_dt"), tau, "save_dt", "tau")
    if nsteps % save_every:
        raise ValueError(
            f"ensemble: t_end - t0 = {span:g} must be a whole multiple of save_dt = {save_dt:g}"
        )
    return nsteps, save_every


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
        Range of ``‖α⁰‖∞``, log-uniform (DESIGN §6).
    seed : int
        Seed of the ``numpy.random.Generator`` that draws the perturbations.
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
    """
    if not isinstance(model, Model):
        raise TypeError(f"ensemble: model must be a stabdae.Model, got {type(model).__name__}")
    law = as_law(law)
    adaptive = rtol is not None
    if adaptive:
        if scheme is not None and as_scheme(scheme).name != "dopri5":
            raise ValueError(
                f"ensemble: adaptive steps (rtol given) use the Dormand–Prince 5(4) pair; "
                f"scheme must be 'dopri5' or left out, got {as_scheme(scheme).name!r}"
            )
        scheme = dopri5()
        rtol = _positive(rtol, "rtol")
        atol = rtol if atol is None else _positive(atol, "atol")
    elif atol is not None:
        raise ValueError("ensemble: atol is for adaptive steps; give rtol as well")
    scheme = as_scheme("rk2" if scheme is None else scheme)
    p = model.param_vector(params)
    t0 = model.t0
    tau = _positive(tau, "tau")
    span = float(t_end) - t0
    if not (math.isfinite(span) and span > 0):
        raise ValueError(f"ensemble: t_end must be after t0 = {t0}, got t_end = {t_end!r}")
    if adaptive:
        save_dt = span / 200 if save_dt is None else _positive(save_dt, "save_dt")
        save_times = save_grid(t0, float(t_end), save_dt)
    else:
        nsteps, save_every = _fixed_step_grid(span, tau, save_dt)
    block = _count(block, "block")
    rdtype = np.dtype(residual_dtype) if str(residual_dtype) in ("float32", "float64") else None
    if rdtype is None:
        raise ValueError(
            f"ensemble: residual_dtype must be 'float32' or 'float64', got {residual_dtype!r}"
        )
    low, high = _radius(radius)
    epsilon = 10.0 * high if epsilon is None else _positive(epsilon, "epsilon")
    divergence = 1e3 * epsilon if divergence is None else _positive(divergence, "divergence")

    bound = bind_law(law, model)
    clock = time.perf_counter()
    if x0 is None:
        x0, alpha0, status = sample_perturbations(
            model, _count(members, "members"), (low, high), seed, params=p, threads=threads
        )
    else:
        x0 = np.array(x0, dtype=np.float64)
        if x0.ndim != 2 or x0.shape[1] != 2 * model.n:
            raise ValueError(
                f"ensemble: x0 must have shape (members, 2n) = (M, {2 * model.n}), got {x0.shape}"
            )
        alpha0 = _residual_rows(model, x0, p, t0, threads)
        status = np.where(np.isfinite(x0).all(axis=1), 0, int(Status.NONFINITE_STATE))
        status = status.astype(np.int8)
    M = x0.shape[0]
    wall_sample = time.perf_counter() - clock

    nsave = save_times.shape[0] + 1 if adaptive else nsteps // save_every + 1
    # the fixed-step kernel writes every element of these (first touch on its threads)
    norms = np.empty((M, nsave), dtype=rdtype)
    x_final = np.empty_like(x0)
    run_status = np.empty(M, dtype=np.int8)
    fail_step = np.empty(M, dtype=np.int64)
    e0 = np.empty(M)
    e1 = np.empty(M)
    x0c = np.ascontiguousarray(x0)
    extra = None
    # each chunk's traces are summarized and fitted by the thread that integrated them,
    # while they are still in its cache
    summary = Summary(M)
    clock = time.perf_counter()
    if adaptive:
        steps = np.zeros(M, dtype=np.int64)
        nfev = np.zeros(M, dtype=np.int64)
        kernel = adaptive_ensemble_for(model, bound)
        norms.fill(np.nan)
        fail_step.fill(-1)
        e0.fill(np.nan)
        e1.fill(np.nan)
        run_status[:] = status  # members that could not be placed stay out
        times = np.concatenate([[t0], save_times])

        def chunk(lo, hi):
            kernel(x0c, t0, save_times, p, bound.matrix, bound.scalars, scheme.A, scheme.b,
                   dopri5_embedded_weights(), scheme.c, rtol, atol, tau, 10_000_000,
                   divergence, norms, x_final, run_status, fail_step, e0, e1, steps, nfev,
                   lo, hi)  # fmt: skip
            summary.rows(norms, times, lo, hi)

        run_chunks(chunk, M, threads=threads, progress=progress)
        extra = {"steps_accepted": steps, "rhs_evaluations": nfev}
        run = dict(method="dopri5-adaptive", rtol=rtol, atol=atol, first_step=tau, t0=t0,
                   t_end=float(t_end), save_dt=save_dt)  # fmt: skip
    else:
        kernel = ensemble_kernel_for(model, bound, scheme, block)
        times = t0 + tau * save_every * np.arange(nsave)

        def chunk(lo, hi):
            kernel(x0c, t0, tau, nsteps, save_every, p, bound.matrix, bound.scalars, scheme.A,
                   scheme.b, scheme.c, divergence, norms, x_final, run_status, fail_step, e0,
                   e1, lo, hi)  # fmt: skip
            summary.rows(norms, times, min(lo * block, M), min(hi * block, M))

        run_chunks(
            chunk, -(-M // block), threads=threads,
            progress=None if progress is None
            else lambda done, _: progress(min(M, done * block), M),
        )  # fmt: skip
        run = dict(tau=tau, t0=t0, t_end=t0 + nsteps * tau, save_dt=tau * save_every,
                   steps=nsteps)  # fmt: skip
    wall_integrate = time.perf_counter() - clock
    status = np.where(status != 0, status, run_status).astype(np.int8)
    clock = time.perf_counter()
    ds = _ensemble_dataset(
        model, p, law, scheme, bound, times, x0, alpha0, norms, x_final, status, fail_step,
        e0, e1, epsilon, summary,
        dict(**run, members=M, seed=seed, radius_low=low, radius_high=high, epsilon=epsilon,
             divergence=divergence, sampling_rtol=SAMPLING_RTOL,
             threads=threads if threads is not None else default_threads()),
        extra=extra,
    )  # fmt: skip
    # wall times (compilation included on a first call) for benchmarks; not part of the data
    ds.attrs.update(wall_sample_s=wall_sample, wall_integrate_s=wall_integrate,
                    wall_dataset_s=time.perf_counter() - clock)  # fmt: skip
    return ds


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
    data = {name: schema_variable(name, val) for name, val in values.items()}
    data["status"].attrs.update(status_flag_attrs())
    data["residual_norm"].attrs["comment"] = (
        f"stored as {norms.dtype}; " + data["residual_norm"].attrs["comment"]
    )
    attrs = provenance(model, p, law, scheme, **run)
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
    from . import theory
    from ._laws import Theorem5

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


#: name -> (dims, long_name, units, extra attributes): the ensemble dataset's schema
ENSEMBLE_SCHEMA = {
    "residual_norm": (("member", "time"), "max-norm of the constraint residual", "1",
                      {"comment": "NaN after a member stopped"}),
    "alpha0": (("member", "component"), "initial perturbation g(x0, t0) achieved", "1", {}),
    "alpha0_norm": ("member", "max-norm of alpha0", "1", {}),
    "x0": (("member", "state"), "initial state", "mixed (see state_units)", {}),
    "x_final": (("member", "state"), "final state (last state before a stop)",
                "mixed (see state_units)", {}),
    "beta": ("member", "fitted decay rate of the residual norm", "s-1",
             {"comment": "fit on the transient above the floor, see stabdae._estimate"}),
    "gamma": ("member", "prefactor: max over the transient of |g| exp(beta t)", "1", {}),
    "residual_floor": ("member", "residual level at the end (truncation floor)", "1", {}),
    "max_residual": ("member", "largest residual norm reached", "1", {}),
    "bounded": ("member", "stayed within epsilon and decayed (Definition 2)", "1",
                {"flag_values": [0, 1], "flag_meanings": "no yes"}),
    "diverged": ("member", "stopped: blew up (diverged, non-finite or singular S)", "1",
                 {"flag_values": [0, 1], "flag_meanings": "no yes"}),
    "diverged_step": ("member", "step at which the member stopped (-1: ran to the end)", "1",
                      {}),
    "status": ("member", "member status", "1", {}),
    "steps_accepted": ("member", "accepted steps (adaptive steps)", "1", {}),
    "rhs_evaluations": ("member", "right-hand-side evaluations (adaptive steps)", "1", {}),
    "energy_drift": ("member", "energy change E(final) - E(x0)", "model units", {}),
    "fraction_bounded": ((), "fraction of bounded members", "1", {}),
    "stability_radius": ((), "largest |alpha0| below which every member is bounded", "1", {}),
    "beta_median": ((), "median fitted decay rate", "s-1", {}),
    "beta_theory": ((), "continuous decay rate -max Re eig(A~) (Theorem 3)", "s-1", {}),
    "beta_theory_discrete": ((), "discrete decay rate -ln rho(R(tau A~))/tau", "s-1", {}),
    "spectral_radius": ((), "spectral radius of R(tau A~)", "1", {}),
    "norm_max": ((), "max-norm of R(tau A~) (the paper's norm; Theorems 6, 7)", "1", {}),
    "norm_weighted": ((), "norm of R(tau A~) in the discrete-Lyapunov weight", "1",
                      {"comment": "inf when no weight exists (spectral radius >= 1)"}),
    "norm_condition": ((), "weighted-norm condition of Theorems 6/7 holds", "1",
                       {"flag_values": [0, 1], "flag_meanings": "no yes"}),
    "lambda_min_W": ((), "min eigenvalue of W = h_v h_v^T over x0 and x_final", "1", {}),
    "beta_theorem5_proven": ((), "Theorem 5 rate k0 lambda_min(W) l1^2/lm (proven)", "s-1",
                             {}),
    "beta_theorem5_printed": ((), "Theorem 5 rate k0 w0 l1^2/lm as printed, w0^2 = "
                              "lambda_min(W)", "s-1", {}),
    "gamma_theorem5": ("member", "Theorem 5 prefactor |alpha0|_2 sqrt(lm/l1)", "1", {}),
    "bound_proven_held": ("member", "|alpha(t)| <= gamma exp(-beta t) held, proven beta",
                          "1", {"flag_values": [0, 1], "flag_meanings": "no yes",
                                "comment": "judged above 10x the member's residual floor, "
                                "that floor added to the bound"}),
    "bound_printed_held": ("member", "|alpha(t)| <= gamma exp(-beta t) held, printed beta",
                           "1", {"flag_values": [0, 1], "flag_meanings": "no yes",
                                 "comment": "judged above 10x the member's residual floor, "
                                "that floor added to the bound"}),
}  # fmt: skip


def schema_variable(name: str, data) -> xr.Variable:
    dims, long_name, units, extra = ENSEMBLE_SCHEMA[name]
    return variable(dims, data, long_name, units, **extra)
