"""Ensembles: many initial constraint perturbations of one model, integrated in parallel.

:func:`ensemble` is a thin driver: it validates its arguments (:mod:`._validate`), places
the initial states (:func:`sample_perturbations`, the compiled sampler of
:mod:`.engine.sampler`), runs the block-lockstep kernel (:mod:`.engine.ensemble.block`) or,
with ``rtol``, the per-member adaptive kernel (:mod:`.engine.ensemble.lanes`) over chunks of
members on threads, each chunk's traces fitted (:mod:`.engine.decay`) by the thread that
integrated them, and builds the dataset (:mod:`._ensemble_dataset`) beside the theorems'
predictions (:mod:`.theory`).  Each member's verdict (:func:`._measures.verdict`) is read
against the unperturbed run (``α⁰ = 0``): its residual per fifth of the run is the floor
band, and how it went against ε (:class:`._measures.Motion`) says whether the scheme is
unstable on the motion itself; that run is one more member of the same kernel call where
it can be, a run of its own otherwise.  With a decision plan (``confidence``) the members
run in looks of growing size until the grid point is decided (:mod:`._sequential`).
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace

import numpy as np
import xarray as xr

from . import _measures, theory
from . import _validate as check
from ._codes import DecisionReason, Status, VerdictReason, messages
from ._measures import Motion
from ._ensemble_dataset import Table, _warn_stopped
from ._ensemble_dataset import ensemble_table as _table
from ._model import Model
from ._raised import first_raising_member, model_raised, stage_finder
from ._schema import schema_entry
from ._sequential import Sequential, decide
from .engine.ahead import sampler_ahead, wait_share
from .engine.crash import guard
from .engine.decay import Record
from .engine.ensemble.block import BLOCK, ensemble_kernel_for
from .engine.ensemble.groups import (
    AdaptiveGrid,
    AdaptiveMeasurement,
    FixedGrid,
    FixedMeasurement,
    Outputs,
    PairTableau,
    Tableau,
    inputs,
    outputs,
)
from .engine.ensemble.lanes import LANES, adaptive_block_for
from .engine.jit import compile_seconds, compiling_elsewhere
from .engine.rk.steps import integrator_for
from .engine.sampler import CHUNK, SAMPLING_RTOL, draw_alphas, residual_rows_for, sampler_for
from .engine.threads import default_threads, run_chunks

__all__ = ["ensemble", "sample_perturbations"]

#: samples stored by default over a fixed-step run (the largest spacing that divides it)
DEFAULT_SAMPLES = 200
#: members whose residual traces are stored by default (enough for the pictures)
DEFAULT_TRACES = 64
#: steps of the linear prediction e^{Ãh} of an adaptive ensemble over its run
PREDICTION_STEPS = 4096
#: the most steps (accepted and rejected) an adaptive member may take
MAX_STEPS = 10_000_000
#: the default divergence threshold lies this many times above the law's transient bound
#: for the largest member (:func:`default_divergence`)
DIVERGENCE_OVER_BOUND = 1e3
#: the largest reference residual history kept (steps × components; 128 MB)
REFERENCE_MAX_ENTRIES = 16_000_000
#: rows first allotted to an adaptive reference trajectory's steps (more on a second run)
REFERENCE_ROWS = 4096
#: the fixed-step kernel measures the residual at every ``s``-th step, ``s`` at most this
#: many, over which no mode of the law changes by more than ``STRIDE_CHANGE`` in ``ln``
#: (:func:`measure_stride`)
MAX_STRIDE = 32
STRIDE_CHANGE = 0.2


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
        Member ``i``'s target is a function of the seed and ``i`` alone (a counter-based
        generator): the first ``k`` members of a larger sample are those of a sample of
        ``k``.  A generator gives the key (two draws from it).
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
        ``Status.SAMPLING_FAILED`` where the corrections did not reach ``α⁰`` to
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
    targets = draw_alphas(model.n_residual, members, (low, high), seed)
    return _place(model, targets, p, t0, threads)


def _place(model, targets, p, t0, threads=None, beside=None):
    """The members placed at the targets ``α⁰`` (:mod:`.engine.sampler`):
    ``(x0, alpha0, status)``.  With ``beside`` (a function of no arguments) the placing
    runs on a thread of its own while ``beside()`` runs on this one, and its result comes
    fourth: the ensemble's reference trajectory, whose first call for a new model compiles
    the ensemble kernel, seconds during which the placing costs nothing.  (numba compiles
    under a process-wide lock, so the sampler is compiled first, here.)"""
    sampler = sampler_for(model)
    M = targets.shape[0]
    x0 = np.empty((M, 2 * model.n))
    alpha0 = np.empty_like(targets)
    status = np.zeros(M, dtype=np.int8)
    x_ref = model.reference_state(p)

    def chunk(lo, hi):
        sampler(x_ref, t0, p, targets, True, x0, alpha0, status, lo, hi)

    items = -(-M // CHUNK)
    if beside is None:
        run_chunks(chunk, items, threads=threads)
        return x0, alpha0, status
    chunk(0, 0)
    with ThreadPoolExecutor(1, thread_name_prefix="stabdae-place") as pool:
        placing = pool.submit(run_chunks, chunk, items, threads=threads)
        other = beside()
        placing.result()
    return x0, alpha0, status, other


#: up to this many rows, :func:`_residual_rows` runs on the calling thread (a roundoff
#: level's 16 states × (4n + 1) rows take microseconds; a trip to the pool about a
#: millisecond)
SMALL_ROWS = 1024


def _residual_rows(model, x, p, t0, threads=None, sampler=False):
    """``g(x_i, t0)`` for every row of ``x`` (compiled; NaN rows give NaN); by the
    model's sampler when ``sampler`` (an ensemble that sampled its members has it
    compiled: the same numbers, without compiling a kernel for them)."""
    out = np.empty((x.shape[0], model.n_residual))
    if x.shape[0] <= SMALL_ROWS:  # a few rows: the trip to the threads costs more than they
        threads = 1
    if sampler:
        kernel = sampler_for(model)
        x = np.ascontiguousarray(x, dtype=float)  # (only read: the sampler writes no state)
        none = np.empty((x.shape[0], 0))
        status = np.empty(x.shape[0], dtype=np.int8)
        unused = np.zeros(x.shape[1])  # (the state placing starts from)
        run_chunks(lambda lo, hi: kernel(unused, t0, p, none, False, x, out, status, lo, hi),
                   -(-x.shape[0] // CHUNK), threads=threads)  # fmt: skip
        return out
    kernel = residual_rows_for(model)
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
    block: int | None = None,
    threads: int | None = None,
    progress=None,
    residual_dtype="float32",
    traces=DEFAULT_TRACES,
    states: bool = True,
) -> xr.Dataset:
    """Integrate an ensemble of initial constraint perturbations in parallel.

    Parameters
    ----------
    model : Model
    law : Law or @njit function
    scheme : Scheme or str, default "rk2" (the midpoint rule; with ``rtol``: "dopri5", or
        "dop853")
    tau, t_end, save_dt : float
        Fixed step, final time, spacing of stored residual norms (as in :func:`integrate`;
        default ``save_dt``: about 200 samples).  With ``rtol``, ``tau`` is every member's
        first step and ``save_dt`` need not be a multiple of it; the steps are not cut to
        the sample times, so nothing measured depends on ``save_dt`` (a stored sample
        is the residual of the state's cubic Hermite interpolant between the accepted steps
        around it).
    rtol, atol : float, optional
        Adaptive steps: each member controls its own step with the scheme's embedded pair
        (Dormand–Prince 5(4) by default, or DOP853; as :func:`integrate_adaptive`) to
        these tolerances (``atol`` defaults to ``rtol``; a number, one per state
        component, shape ``(2n,)``, or ``"scales"``: ``rtol`` times the model's
        ``scales``).  The dataset then also has
        ``steps_accepted`` and ``rhs_evaluations`` per member, and only the
        continuous-time prediction ``beta_theory``.
    members : int, Sequential or dict
        Ensemble size (ignored when ``x0`` is given).  A :class:`stabdae.Sequential` plan
        (or a dict of its keys) runs members in batches until the ensemble is decided:
        stable (at most ``q`` of the members unstable) or unstable at the plan's
        confidence, or undecided (said why); the dataset then has the members run, and
        ``decision``, ``decision_reason``, ``decision_low``, ``decision_high``,
        ``members_used``; its traced members are the first ones.  An ensemble whose estimated memory
        (about ``8 (8n + 4(2m + k) + 48)`` bytes per member, plus the traces) exceeds the
        memory available is refused with the figures before anything is allocated.
    radius : float or (low, high)
        Range of ``‖α⁰‖∞``, log-uniform; directions uniform.
    seed : int
        Seed (a non-negative integer, stored in the dataset) of the perturbations: member
        ``i``'s is a function of the seed and ``i`` alone (a counter-based generator), so
        the first ``k`` members of any ensemble with this seed are the same.
    x0 : array (members, 2n), optional
        The user's own initial states instead of sampled ones.  Their decay is measured
        on their raw residual norm (there is no reference trajectory to measure their
        distance from: they need not lie near the model's reference state), whose floor
        is set by the scheme's local errors along each one's motion.
    params : mapping or array, optional
        Physical parameters.
    epsilon : float, optional
        The ε of Definition 2: a member is *bounded* when it is stable (see
        ``stability_class``) and ``max_t ‖g‖ ≤ ε``.  Default ``10 × radius high``.
    divergence : float, optional
        Residual norm above which a member is frozen and flagged ``diverged``
        (default ``1e3 × epsilon``, at least 1, a residual of the model's own size, and,
        for a constant ``Ã``, at least ``1e3`` times the law's transient bound
        ``sup_k ‖R(τÃ)^k‖∞ · radius high``: a stable law's own transient is not stopped).
        A member the threshold stops inside the law's transient bound is *undecided*.
    block : int, optional
        Members integrated in lockstep per parallel work item (default 64), or with
        ``rtol`` the lanes that run members side by side, each with its own steps
        (default 8).  Compile-time: a new value compiles a new kernel.  Does not change
        any number.
    threads : int, optional
        Threads to run the blocks on (default numba's thread count, ``NUMBA_NUM_THREADS``).
        Does not change any number.
    progress : callable ``(members_done, members)``, optional
        Called after each chunk of members has been integrated.
    residual_dtype : "float32" or "float64"
        Storage of ``residual_norm``: float32 (default) halves its memory; float64 keeps
        every digit.
    traces : int, "all" or "none"
        The members whose residual norms are stored (``residual_norm(trace, time)``, the
        coordinate ``trace`` naming each stored member): this many, evenly spaced over the
        members (default 64), all of them, or none.  No measurement depends on it: the
        decay rate, floor and class of every member are measured at every step inside
        the kernels.
    states : bool
        Store every member's initial and final state (``x0``, ``x_final``: 4n numbers per
        member, most of the bytes of a large model's ensemble).  ``False`` leaves them
        out; the members are the same (``alpha0`` and the seed give them again).

    Returns
    -------
    xarray.Dataset
        See ``docs/schema.md``: per member ``alpha0``, ``x0``, ``x_final``, ``beta`` with
        ``beta_reason``, ``gamma``, ``residual_floor``, ``verdict`` (stable, unstable or
        undecided) with ``verdict_reason`` (:func:`._measures.verdict`; the attribute
        ``verdict_summary`` counts them), ``stability_class``, ``stable``,
        ``bounded``, ``diverged``, ``status``, ``energy_drift`` and, for constant laws,
        ``beta_predicted`` and ``beta_ratio``; ``residual_norm(trace, time)`` for the
        traced members; the summaries ``fraction_stable``, ``fraction_unstable``,
        ``fraction_undecided``, ``fraction_bounded`` (with Wilson 95 % intervals),
        ``beta_median`` (with an exact order-statistics interval and its coverage),
        ``stability_radius`` with its bracket and ``stability_radius_reason``, the counts
        behind them and, for constant laws, the theory's ``beta_theory``,
        ``beta_theory_discrete``, ``spectral_radius``.

    Warns
    -----
    IntegrationWarning
        When members stopped (diverged, singular ``S``, …), with their count per reason;
        their rows are kept up to the stop, and ``status`` says why per member.
    """
    table = ensemble_table(model, law, scheme, tau, t_end, rtol=rtol, atol=atol,
                           members=members, radius=radius, seed=seed, save_dt=save_dt, x0=x0,
                           params=params, epsilon=epsilon, divergence=divergence, block=block,
                           threads=threads, progress=progress, residual_dtype=residual_dtype,
                           traces=traces, states=states)  # fmt: skip
    _warn_stopped(table.attrs["model"], table.data["status"][1])
    return table.to_dataset()


def ensemble_table(model, law, scheme=None, tau=1e-3, t_end=1.0, *, rtol=None, atol=None,
                   members=1024, radius=(1e-6, 1e-2), seed=0, save_dt=None, x0=None,
                   params=None, epsilon=None, divergence=None, block=None, threads=None,
                   progress=None, residual_dtype="float32", traces=DEFAULT_TRACES,
                   states=True) -> Table:  # fmt: skip
    """:func:`ensemble`'s dataset as a :class:`~._ensemble_dataset.Table` (what a study
    keeps per grid point), without the warning for stopped members."""
    plan = None
    if isinstance(members, (Sequential, Mapping)):
        plan = Sequential.of(members, "ensemble")
        if x0 is not None:
            raise ValueError("ensemble: members as a sequential plan runs sampled members; "
                             "with x0 give no members")  # fmt: skip
        members = plan.max
    run = _run_spec("ensemble", model, law, scheme, tau, t_end, rtol, atol, members, radius,
                    seed, save_dt, x0, params, epsilon, divergence, block, threads, progress,
                    residual_dtype, traces, states, first=plan is not None)  # fmt: skip
    # the law's transient and the accumulation of per-step errors over this run (R over the
    # run's steps, or the prediction's), from one walk over R's powers
    peak, gain = (theory.power_norms(run.R, run.mode.prediction_steps)
                  if run.R.shape[0] > 0 else (math.nan, math.inf))  # fmt: skip
    times = run.mode.times(run.t0)
    if plan is not None:
        return _sequential_table(run, plan, peak, gain, times)
    walls = _Walls()
    placed = None
    try:
        with walls("sample"):
            x0, alpha0, status, g_ref = placed = _members(run, x0)
            run = replace(run, noise=_noise(run, x0, status, gain))
        with walls("integrate"):
            out, band, motion = _integrate(run, x0, alpha0, status, g_ref)
    except Exception as exc:  # a model function raised: say which, when and where
        raise _raised_in(run, "ensemble", exc, None if placed is None else x0) from exc
    status = np.where(status != 0, status, out.status).astype(np.int8)
    with walls("dataset"):
        referee = _referee(run, g_ref, band, motion)
        roundoff = _roundoff(run.model, out.x_final, status, run.p, float(times[-1]), gain,
                             run.threads, run.sampled)  # fmt: skip
        table = _build(run, times, x0, alpha0, out, status, referee, peak, roundoff)
    table.attrs.update(walls.attrs())
    return table


class _Walls:
    """Wall times of an ensemble's phases (``with walls("integrate"): ...``), each without
    the compiling (or loading of compiled kernels) inside it, which is counted apart: for
    benchmarks and a study's account of its time; not part of the data."""

    def __init__(self):
        self.seconds = {"sample": 0.0, "integrate": 0.0, "dataset": 0.0, "compile": 0.0}

    @contextlib.contextmanager
    def __call__(self, phase: str):
        clock, compiling = time.perf_counter(), compile_seconds()
        try:
            yield
        finally:
            compiled = compile_seconds() - compiling
            self.seconds["compile"] += compiled
            self.seconds[phase] += time.perf_counter() - clock - compiled

    def attrs(self) -> dict:
        return {f"wall_{k}_s": v for k, v in self.seconds.items()}


def _build(run, times, x0, alpha0, out, status, referee, peak, roundoff, verdicts=None
           ) -> Table:  # fmt: skip
    """The ensemble's table from its members' outputs (``verdicts``: theirs, where
    known)."""
    table = _table(
        run.model, run.p, run.law, run.scheme, run.bound, times, x0, alpha0, out.norms,
        run.traced, out.x_final, status, out.fail_step, out.e0, out.e1, run.epsilon,
        Record(out.meas, out.codes), run.R,
        dict(**run.mode.attrs(run), members=x0.shape[0], seed=run.seed, radius_low=run.low,
             radius_high=run.high, epsilon=run.epsilon, divergence=run.divergence,
             sampling_rtol=SAMPLING_RTOL,
             threads=run.threads if run.threads is not None else default_threads()),
        extra=run.mode.extra(out), overshoot_theory=peak, adaptive=run.adaptive,
        roundoff=roundoff, referee=referee, verdicts=verdicts,
    )  # fmt: skip
    table.attrs["fit_roundoff_level"] = float(run.noise)
    if not run.states:
        del table.data["x0"], table.data["x_final"]
    return table


def _sequential_table(run: _RunSpec, plan: Sequential, peak, gain, times) -> Table:
    """The ensemble run look by look until its decision (:mod:`._sequential`): the
    members ``0 … n − 1`` of the last look, each as the one-shot ensemble of ``n``
    members would give it, with the decision, its reason and interval."""
    looks = plan.looks()
    parts, g_ref, referee, roundoff = [], None, None, 0.0
    walls = _Walls()
    lo = 0
    progress = run.progress
    for j, hi in enumerate(looks):
        sub = replace(run, members=hi - lo, start=lo, trace_row=run.trace_row[lo:hi],
                      progress=None if progress is None
                      else (lambda done, _, lo=lo: progress(lo + done, plan.max)))  # fmt: skip
        placed = None
        try:
            with walls("sample"):
                x0, alpha0, status, g = placed = _members(sub, None, reference=g_ref is None)
                if lo == 0:  # from the first members, as the one-shot ensemble's
                    run = replace(run, noise=_noise(run, x0, status, gain))
                sub = replace(sub, noise=run.noise)
            with walls("integrate"):
                if g_ref is None:
                    g_ref, referee = g, _referee(run, g)
                out = run.mode.integrate(sub, x0, alpha0, status, g_ref)
        except Exception as exc:
            raise _raised_in(sub, "ensemble", exc, None if placed is None else x0) from exc
        status = np.where(status != 0, status, out.status).astype(np.int8)
        parts.append((x0, alpha0, out, status))
        if lo == 0:  # the roundoff level from the first members: the same at any batch
            k = min(ROUNDOFF_SAMPLE, hi)
            roundoff = _roundoff(run.model, out.x_final[:k], status[:k], run.p,
                                 float(times[-1]), gain, run.threads, run.sampled)  # fmt: skip
        x0, alpha0, out, status = _joined(parts, run.trace_row[:hi])
        judged = _measures.verdict(Record(out.meas.copy(), out.codes.copy()), status,
                                   roundoff=roundoff, **referee)  # fmt: skip
        verdicts = judged[0]
        unstable = int((verdicts == _measures.V_UNSTABLE).sum())
        stable = int((verdicts == _measures.V_STABLE).sum())
        ran = judged[1] != int(VerdictReason.NOT_RUN)
        not_run = int(hi - ran.sum())
        decision = decide(plan, hi - not_run, unstable, hi - not_run - stable,
                          last=j == len(looks) - 1, not_run=not_run)  # fmt: skip
        if decision.verdict is not None:
            break
        lo = hi
    clock = time.perf_counter()
    traced = run.traced[run.traced < hi]
    out = out._replace(norms=out.norms[:traced.size])
    table = _build(replace(run, members=hi, traced=traced, trace_row=run.trace_row[:hi]),
                   times, x0, alpha0, out, status, referee, peak, roundoff,
                   judged)  # fmt: skip
    for name, value in (("decision", np.int8(decision.verdict)),
                        ("decision_reason", np.int8(decision.reason)),
                        ("decision_low", decision.low), ("decision_high", decision.high),
                        ("members_used", np.int32(hi))):  # fmt: skip
        table.data[name] = schema_entry(name, value, run.model)
    table.attrs.update({f"sequential_{k}": v for k, v in plan.as_dict().items()})
    table.attrs["sequential_looks"] = np.asarray(looks[:j + 1], dtype=np.int64)
    not_run_text = f", {not_run} not run: {_measures.not_run_text(status, ran)}" if not_run else ""
    table.attrs["decision_summary"] = (
        f"{_measures.VERDICTS[decision.verdict]} after {hi} members ({unstable} unstable, "
        f"{hi - not_run - stable - unstable} undecided{not_run_text}): the unstable "
        f"fraction of the {hi - not_run} that ran in "
        f"[{decision.low:.3g}, {decision.high:.3g}] at confidence {plan.confidence:g}, "
        f"q = {plan.q:g}; {DECISION_REASONS[decision.reason]}")  # fmt: skip
    walls.seconds["dataset"] = time.perf_counter() - clock
    table.attrs.update(walls.attrs())
    return table


def _joined(parts, trace_row):
    """One set of members' ``(x0, alpha0, outputs, status)`` from the looks' parts, in
    order; the traced members' rows from the part that ran them."""
    if len(parts) == 1:
        return parts[0]
    x0 = np.concatenate([p[0] for p in parts])
    alpha0 = np.concatenate([p[1] for p in parts])
    status = np.concatenate([p[3] for p in parts])
    outs = [p[2] for p in parts]
    norms = np.empty_like(outs[0].norms)
    lo = 0
    for o in outs:
        hi = lo + o.status.shape[0]
        rows = trace_row[lo:hi]
        rows = rows[rows >= 0]
        norms[rows] = o.norms[rows]
        lo = hi
    cat = {f: np.concatenate([getattr(o, f) for o in outs])
           for f in ("meas", "codes", "x_final", "status", "fail_step", "e0", "e1", "steps",
                     "nfev")}  # fmt: skip
    return x0, alpha0, outs[0]._replace(norms=norms, **cat), status


# --------------------------------------------------------------------- the run spec
@dataclass(frozen=True)
class _Fixed:
    """Fixed steps: the block-lockstep kernel (:mod:`.engine.ensemble.block`)."""

    grid: FixedGrid
    tableau: Tableau
    kernel: object
    stride: int  # the decay is measured at every stride-th state (:func:`measure_stride`)

    @property
    def prediction_steps(self) -> int:
        return int(self.grid.nsteps)

    def times(self, t0):
        g = self.grid
        return t0 + g.tau * g.save_every * np.arange(g.nsteps // g.save_every + 1)

    def attrs(self, run) -> dict:
        g = self.grid
        return dict(tau=g.tau, t0=g.t0, t_end=g.t0 + g.nsteps * g.tau,
                    save_dt=g.tau * g.save_every, steps=int(g.nsteps),
                    measure_every=self.stride)  # fmt: skip

    def extra(self, out) -> dict:
        return {}

    def reference(self, run):
        """The reference trajectory's residuals (:func:`_reference_residuals`)."""
        return _reference_residuals(run.model, run.bound, run.scheme, run.p, run.t0,
                                    self.grid.tau, int(self.grid.nsteps), run.block,
                                    run.rdtype, kernel=self.kernel)  # fmt: skip

    def integrate(self, run, x0, alpha0, status, g_ref) -> Outputs:
        """The kernel over chunks of blocks on threads."""
        M = x0.shape[0]
        g = self.grid
        out = outputs(M, x0.shape[1], run.model.n_residual, run.traced.size,
                      g.nsteps // g.save_every + 1, run.rdtype)  # fmt: skip
        R_stride = (np.linalg.matrix_power(run.R, self.stride) if run.R.size else run.R)
        measure = FixedMeasurement.of(run.divergence, g_ref, R_stride, self.stride,
                                      run.trace_row, run.noise)  # fmt: skip
        args = (inputs(x0, alpha0, run.p, run.bound), self.grid, self.tableau, measure, out)
        progress, block = run.progress, run.block
        run_chunks(lambda lo, hi: self.kernel(*args, lo, hi), -(-M // block),
                   threads=run.threads,
                   progress=None if progress is None
                   else lambda done, _: progress(min(M, done * block), M))  # fmt: skip
        return out


@dataclass(frozen=True)
class _Lanes:
    """Adaptive steps: members on lanes, each with its own steps
    (:mod:`.engine.ensemble.lanes`)."""

    grid: AdaptiveGrid
    tableau: PairTableau
    kernel: object
    name: str

    prediction_steps = PREDICTION_STEPS

    def times(self, t0):
        return np.concatenate([[t0], self.grid.save_times])

    def attrs(self, run) -> dict:
        g = self.grid
        # one number where every component has the same (as it was given, or alike)
        atol = float(g.atol[0]) if (g.atol == g.atol[0]).all() else g.atol
        return dict(method=f"{self.name}-adaptive", rtol=g.rtol, atol=atol, first_step=g.h0,
                    t0=g.t0, t_end=run.t_end, save_dt=run.save_dt)  # fmt: skip

    def extra(self, out) -> dict:
        return {"steps_accepted": out.steps, "rhs_evaluations": out.nfev}

    def reference(self, run):
        """The reference trajectory's ``(t, g)`` at its start and every accepted step: a
        run of the lanes kernel with this one member, which records them (no rows where
        it does not run to the end or would take more than ``REFERENCE_MAX_ENTRIES``
        numbers).  Each member's steps are its own, but a member whose steps the motion
        sets (rather than its transient: every member near its floor) takes nearly the
        reference's, and with them nearly its local errors: its decay is measured on its
        distance from this residual, linear in time between the reference's steps."""
        model = run.model
        cols = 1 + model.n_residual
        x0 = model.reference_state(run.p)[None, :]
        rows = REFERENCE_ROWS
        while True:
            out = self._outputs(run, x0, np.zeros(1, dtype=np.int8), rows, cols)
            measure = AdaptiveMeasurement.of(math.inf, run.R, run.h_pred, np.full(1, -1),
                                             np.zeros((0, cols)))  # fmt: skip
            with guard("ensemble"):
                self.kernel(inputs(x0, np.zeros((1, cols - 1)), run.p, run.bound), self.grid,
                            self.tableau, measure, out, 0, 1)  # fmt: skip
            need = int(out.steps[0]) + 1
            if out.status[0] != 0 or need * cols > REFERENCE_MAX_ENTRIES:
                return np.zeros((0, cols))
            if need <= rows:
                table = out.g_out[:need]
                return table if np.isfinite(table).all() else np.zeros((0, cols))
            rows = need

    def _outputs(self, run, x0, status, rows=0, columns=0) -> Outputs:
        """Outputs for the members ``x0`` (the reference alone: ``rows`` of ``(t, g)``,
        ``columns`` wide, and no traces)."""
        out = outputs(x0.shape[0], x0.shape[1], run.model.n_residual,
                      0 if rows else run.traced.size, self.grid.save_times.size + 1,
                      run.rdtype, residuals=rows, columns=columns, counts=True)  # fmt: skip
        out.status[:] = status  # members that could not be placed stay out
        out.fail_step.fill(-1)  # (the lanes write these only where a member stops or ends)
        out.e0.fill(np.nan)
        out.e1.fill(np.nan)
        return out

    def integrate(self, run, x0, alpha0, status, g_ref) -> Outputs:
        """The kernel over chunks of members on threads."""
        M = x0.shape[0]
        out = self._outputs(run, x0, status)
        measure = AdaptiveMeasurement.of(run.divergence, run.R, run.h_pred, run.trace_row,
                                         g_ref, run.noise)  # fmt: skip
        args = (inputs(x0, alpha0, run.p, run.bound), self.grid, self.tableau, measure, out)
        run_chunks(lambda lo, hi: self.kernel(*args, lo, hi), M, threads=run.threads,
                   progress=run.progress)  # fmt: skip
        return out


@dataclass(frozen=True)
class _RunSpec:
    """An ensemble run, validated: the model, law and scheme, the members' placing, and
    the mode (:class:`_Fixed` or :class:`_Lanes`) with its grid, tableau and kernel."""

    model: Model
    law: object
    bound: object
    scheme: object
    mode: _Fixed | _Lanes
    p: np.ndarray
    t0: float
    t_end: float
    save_dt: float | None
    block: int
    members: int
    low: float
    high: float
    seed: int
    epsilon: float
    divergence: float
    threads: int | None
    progress: object
    rdtype: object
    trace_row: np.ndarray
    traced: np.ndarray
    states: bool
    sampled: bool
    R: np.ndarray  # the linear prediction's one-step propagator (empty: none)
    h_pred: float  # ... and its step
    start: int = 0  # the index of the first member (of a sequential ensemble's look)
    noise: float = 0.0  # the roundoff level the fits keep their distance from (_noise)

    @property
    def adaptive(self) -> bool:
        return isinstance(self.mode, _Lanes)


def _run_spec(who, model, law, scheme, tau, t_end, rtol, atol, members, radius, seed,
              save_dt, x0, params, epsilon, divergence, block, threads, progress,
              residual_dtype, traces, states, first=False) -> _RunSpec:  # fmt: skip
    """Every argument of :func:`ensemble` checked, in the order of its signature, and
    the run spec they make (the kernel compiled or loaded once, here); ``first``: the
    traced members are the first ones (a sequential ensemble's, whose size is not known
    yet), not spread over ``members``."""
    model = check.model(model, who)
    law = check.law(law, who)
    adaptive = rtol is not None
    pair = None
    if adaptive:
        pair = check.pair(None if scheme is None else check.scheme(scheme, who), who)
        scheme = pair.scheme
        rtol, atol, _ = check.tolerances(rtol, rtol if atol is None else atol, who,
                                         2 * model.n, model.scales)  # fmt: skip
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
    if block is None:
        block = LANES if adaptive else BLOCK
    block = check.block(block, model.n, who, copies=4 if adaptive else 2)
    rdtype = check.dtype(residual_dtype, "residual_dtype", ("float32", "float64"), who)
    low, high = check.radius(radius, who)
    seed = check.seed(seed, who)
    epsilon = 10.0 * high if epsilon is None else check.positive(epsilon, "epsilon", who)
    divergence = None if divergence is None else check.positive(divergence, "divergence", who)
    threads = _threads(threads, who)
    if progress is not None and not callable(progress):
        raise TypeError(f"{who}: progress must be a callable (done, total), got "
                        f"{type(progress).__name__}")  # fmt: skip
    if x0 is None:
        members = check.count(members, "members", who)
    else:
        x0 = check.initial_states(model, x0, who)
        members = x0.shape[0]
    samples = save_times.size + 1 if adaptive else nsteps // save_every + 1
    traced_count = members if traces == "all" else 0 if traces == "none" else \
        min(traces, members) if isinstance(traces, (int, np.integer)) else 0  # fmt: skip
    check.fits_in_memory(
        check.ensemble_bytes(model.n, model.n_residual, members, traced_count, samples,
                             np.dtype(rdtype).itemsize),
        f"members = {members} with {traced_count} traces of {samples} samples", who,
        "run fewer members (several ensembles with other seeds), or store fewer traces")
    trace_row, traced = _trace_rows(traces, members, who, first)
    if not isinstance(states, (bool, np.bool_)):
        raise TypeError(f"{who}: states must be True or False, got {states!r}")
    bound = check.bound_law(law, model, who)
    if adaptive:
        R, h_pred = _prediction(law, model, span=float(t_end) - t0)
        mode = _Lanes(AdaptiveGrid.of(t0, save_times, tau, rtol, atol, MAX_STEPS),
                      PairTableau.of(pair), adaptive_block_for(model, bound, pair, block),
                      pair.name)  # fmt: skip
    else:
        R, h_pred = _prediction(law, model, scheme, tau=tau)
        mode = _Fixed(FixedGrid.of(t0, tau, nsteps, save_every), Tableau.of(scheme),
                      ensemble_kernel_for(model, bound, scheme, block),
                      measure_stride(R))  # fmt: skip
    if divergence is None:
        divergence = default_divergence(epsilon, high, R, mode.prediction_steps)
    return _RunSpec(model, law, bound, scheme, mode, p, t0, float(t_end), save_dt, block,
                    members, low, high, seed, epsilon, divergence, threads, progress, rdtype,
                    trace_row, traced, bool(states), x0 is None, R, h_pred)  # fmt: skip


def _raised_in(run: _RunSpec, who: str, exc: BaseException, x0):
    """The error for an exception out of the kernels: with fixed steps, the first member
    whose trajectory raises alone (the reference trajectory where the members were not
    placed yet: ``x0`` None), replayed to the step, and the model function that raises
    there."""
    if isinstance(exc, MemoryError) or type(exc).__module__.split(".")[0] == "stabdae":
        return exc  # the library's own error, already clear
    where = find = None
    if not run.adaptive:
        g = run.mode.grid
        kernel = integrator_for(run.model, run.bound)
        sweeps, tol = check.projection(None, who)

        def one(x_start, t_start, steps, every, ox, og, oe):
            return kernel(x_start, t_start, g.tau, steps, every, run.p, run.bound.matrix,
                          run.bound.scalars, run.scheme.A, run.scheme.b, run.scheme.c, sweeps,
                          tol, ox, og, oe)  # fmt: skip

        if x0 is None:  # raised while placing the members: the reference trajectory
            starts, label = run.model.reference_state(run.p)[None, :], "the reference trajectory"
        else:
            starts, label = x0, "member {}"
        where = first_raising_member(one, starts, run.t0, g.tau, int(g.nsteps),
                                     run.model.n_residual)  # fmt: skip
        if where is not None:
            where = (*where[:2], label.format(where[2]))
        find = stage_finder(run.model, run.bound, "ldl", run.scheme, g.tau, run.p)
    return model_raised(who, run.model, run.p, exc, where, find)


def default_divergence(epsilon, high, R, steps) -> float:
    """The default divergence threshold: ``1e3 ε``, at least 1 (a residual of the
    model's own size), and, where ``Ã`` is constant with a bounded transient, at least
    ``DIVERGENCE_OVER_BOUND`` times what the law's transient allows the largest member
    (``sup_k ‖R^k‖∞ · radius high``, :func:`.theory.power_norms`): a stable law's own
    transient is never stopped as a divergence."""
    level = max(1e3 * epsilon, 1.0)
    if R.shape[0] > 0:
        peak = theory.power_norms(R, steps)[0]
        if math.isfinite(peak):
            level = max(level, DIVERGENCE_OVER_BOUND * peak * high)
    return level


def _members(run: _RunSpec, x0, reference: bool = True):
    """``(x0, alpha0, status, g_ref)``: the members, sampled at the seed's targets or the
    user's own, with the reference trajectory's residuals (:meth:`_Fixed.reference`; no
    rows: none; without ``reference``: None).  The reference runs beside the placing only
    while the kernel is still to be compiled or loaded (its run alone is too short to pay
    for a thread)."""
    model, p, t0 = run.model, run.p, run.t0
    none = np.zeros((0, model.n_residual))
    if x0 is not None:
        alpha0 = _residual_rows(model, x0, p, t0, run.threads)
        status = np.where(_measures.rows_finite(x0), 0, int(Status.NONFINITE_STATE))
        return x0, alpha0, status.astype(np.int8), none
    targets = draw_alphas(model.n_residual, run.members, (run.low, run.high), run.seed,
                          run.start)  # fmt: skip
    if not reference:
        return (*_place(model, targets, p, t0, run.threads), None)
    ahead = sampler_ahead(model, sampler_for(model), run.mode.kernel)
    if ahead is not None:
        # a helper process compiles the sampler while this one compiles the kernel (in
        # the reference's first call); the placing then loads the sampler from the cache
        try:
            clock = time.perf_counter()
            g_ref = run.mode.reference(run)
            # the sampler is the smaller kernel: a helper not done a share of the kernel's
            # time later is stopped (the placing then compiles the sampler here); the wait
            # is compile time
            with compiling_elsewhere():
                ahead.join(wait_share() * (time.perf_counter() - clock))
        finally:
            ahead.stop()
        x0, alpha0, status = _place(model, targets, p, t0, run.threads)
    elif run.adaptive or run.mode.kernel.signatures:
        x0, alpha0, status = _place(model, targets, p, t0, run.threads)
        g_ref = run.mode.reference(run)
    else:
        x0, alpha0, status, g_ref = _place(model, targets, p, t0, run.threads,
                                           beside=lambda: run.mode.reference(run))  # fmt: skip
    return x0, alpha0, status, none if g_ref is None else g_ref


def _reference_residuals(model, bound, scheme, p, t0, tau, nsteps, block=BLOCK,
                         rdtype=np.float32, kernel=None):  # fmt: skip
    """The residual ``g`` at every step of the trajectory from the model's reference state
    (``α⁰ = 0``): the truncation error's forced response, the same for every member of a
    sampled ensemble up to ``O(‖α⁰‖)``.  Each member's decay is measured on its distance
    from it, so that the rate is read far below the floor the raw residual settles on.
    None (an empty array: the raw residual is measured) when it would take more than
    ``REFERENCE_MAX_ENTRIES`` numbers or does not run to the end.  (A run of the ensemble
    kernel itself with this one member, which records its residual at every step: a
    kernel of its own cost a new model's first ensemble seconds of compilation, more
    than the block of identical slots this run steps costs at any ensemble size; its
    storage type ``rdtype`` is the ensemble's, for the same compiled kernel.)"""
    ng = model.n_residual
    if (nsteps + 1) * ng > REFERENCE_MAX_ENTRIES:
        return np.zeros((0, ng))
    if kernel is None:
        kernel = ensemble_kernel_for(model, bound, scheme, block)
    x0 = model.reference_state(p)[None, :]
    out = outputs(1, x0.shape[1], ng, 0, 2, rdtype, residuals=nsteps + 1)
    with guard("ensemble"):
        kernel(inputs(x0, np.zeros((1, ng)), p, bound), FixedGrid.of(t0, tau, nsteps, nsteps),
               Tableau.of(scheme),
               FixedMeasurement.of(math.inf, np.zeros((0, ng)), np.zeros((0, 0)), nsteps + 1,
                                   np.full(1, -1)),
               out, 0, 1)  # fmt: skip
    if out.status[0] != 0 or not np.isfinite(out.g_out).all():
        return np.zeros((0, ng))
    return out.g_out


def _integrate(run: _RunSpec, x0, alpha0, status, g_ref):
    """``(out, band, motion)``: the members' outputs, and the floor band and the motion
    (:class:`._measures.Motion`) :func:`_reference_floor`
    would give where the verdicts are judged against it (no reference residuals to read
    it from; fixed steps), read from the reference state run as one more member of the
    same kernel call: members never interact, so its numbers are those of its run alone,
    without that run's own pass over a whole block of slots.  ``band`` is None otherwise,
    and where that member stopped (then its run alone, without the divergence
    threshold, gives the band as before)."""
    if run.adaptive or (g_ref is not None and g_ref.shape[0] > 1):
        return run.mode.integrate(run, x0, alpha0, status, g_ref), None, None
    M, ng = x0.shape[0], run.model.n_residual
    ref = np.asarray(run.model.reference_state(run.p), dtype=float)[None, :]
    progress = run.progress
    more = replace(run, trace_row=np.append(run.trace_row, -1),
                   progress=None if progress is None
                   else lambda done, _: progress(min(done, M), M))  # fmt: skip
    out = run.mode.integrate(more, np.concatenate([x0, ref]),
                             np.concatenate([alpha0, np.zeros((1, ng))]),
                             np.append(status, np.int8(0)), g_ref)  # fmt: skip
    band = motion = None
    if out.status[M] == 0:
        rec = Record(out.meas[M:], out.codes[M:])
        band = np.array([rec[f"w{w}"][0] for w in range(5)], dtype=float)
        if not np.isfinite(band).all():
            band = np.zeros(5)  # as :func:`_reference_floor` gives it
        motion = Motion.of_run(0, math.nan, band, run.t0, run.t_end, run.epsilon)
    per_member = ("meas", "codes", "x_final", "status", "fail_step", "e0", "e1")
    return (out._replace(**{name: getattr(out, name)[:M] for name in per_member}), band,
            motion)


def _referee(run: _RunSpec, g_ref, band=None, motion=None) -> dict:
    """What a member's verdict is judged against (:func:`._measures.verdict`): the
    reference trajectory's largest residual per fifth of the run (its truncation floor:
    from its stored residuals, or from a run of the mode's kernel on the reference state
    alone, or ``band`` where that run was read from the members' own, :func:`_integrate`),
    how that run went against ε (``motion``, :class:`._measures.Motion`, from the same
    source), and, where ``Ã`` is constant, ``ρ`` of the one-step propagator and
    ``sup ‖R^k‖∞`` per fifth (:func:`.theory.fifth_bounds`)."""
    if band is None or motion is None:
        band, motion = _floor_band(run, g_ref)
    if run.R.shape[0] == 0:
        return dict(floor_band=band, bounds=None, rho=math.nan, divergence=run.divergence,
                    motion=motion)  # fmt: skip
    rho = float(np.max(np.abs(np.linalg.eigvals(run.R))))
    return dict(floor_band=band, bounds=theory.fifth_bounds(run.R, run.mode.prediction_steps),
                rho=rho, divergence=run.divergence, motion=motion)  # fmt: skip


def _floor_band(run: _RunSpec, g_ref) -> tuple[np.ndarray, Motion]:
    """The reference trajectory's largest residual per fifth of the run and how it went
    against ε (:class:`._measures.Motion`): from its stored residuals ``g_ref``, or where
    there are none from a run of the reference state alone (:func:`_reference_floor`)."""
    if g_ref is None or g_ref.shape[0] <= 1:
        return _reference_floor(run)
    if run.adaptive:  # rows (t, g) at the reference's accepted steps, fifths by time
        t = g_ref[:, 0]
        fifth = np.minimum(4, (5.0 * (t - run.t0) / (run.t_end - run.t0)).astype(int))
        norms = np.abs(g_ref[:, 1:]).max(axis=1)
    else:
        nsteps = g_ref.shape[0] - 1
        t = run.t0 + run.mode.grid.tau * np.arange(nsteps + 1)
        fifth = np.minimum(4, (5 * np.arange(nsteps + 1)) // nsteps)
        norms = np.abs(np.asarray(g_ref, dtype=float)).max(axis=1)
    band = np.array([norms[fifth == w].max(initial=0.0) for w in range(5)])
    return band, Motion.of_rows(t, norms, run.epsilon)


def _reference_floor(run: _RunSpec) -> tuple[np.ndarray, Motion]:
    """The largest residual per fifth of the run of the model's reference state alone
    (``α⁰ = 0``), measured as the members' (5 numbers; zeros where it did not run to the
    end), and how that run went against ε (:class:`._measures.Motion`: with no
    divergence threshold, it stops only where it blew up)."""
    x0 = run.model.reference_state(run.p)[None, :]
    one = replace(run, trace_row=np.full(1, -1), traced=np.zeros(0, dtype=np.int64),
                  progress=None, divergence=math.inf, threads=1)  # fmt: skip
    out = run.mode.integrate(one, x0, np.zeros((1, run.model.n_residual)),
                             np.zeros(1, dtype=np.int8), np.zeros((0, run.model.n_residual)))
    rec = Record(out.meas, out.codes)
    band = np.array([rec[f"w{w}"][0] for w in range(5)], dtype=float)
    status = int(out.status[0])
    if status == 0 and not np.isfinite(band).all():
        status = int(Status.NONFINITE_STATE)
    stopped = (run.t0 + run.mode.grid.tau * int(out.fail_step[0])
               if status and not run.adaptive and out.fail_step[0] >= 0 else math.nan)
    if status != 0:
        band = np.zeros(5)
    return band, Motion.of_run(status, stopped, band, run.t0, run.t_end, run.epsilon)


def _trace_rows(traces, members: int, who: str, first: bool = False):
    """``(trace_row, traced)``: each member's row of the stored traces (−1: none) and the
    traced members, evenly spaced over the ensemble (``first``: the first ones)."""
    if isinstance(traces, str):
        if traces not in ("all", "none"):
            raise ValueError(f"{who}: traces must be a number of members, 'all' or 'none', "
                             f"got {traces!r}")  # fmt: skip
        count = members if traces == "all" else 0
    elif isinstance(traces, (bool, np.bool_)) or not isinstance(traces, (int, np.integer)):
        raise TypeError(f"{who}: traces must be a number of members, 'all' or 'none', got "
                        f"{type(traces).__name__}")  # fmt: skip
    elif traces < 0:
        raise ValueError(f"{who}: traces must be >= 0, got {traces}")
    else:
        count = min(int(traces), members)
    if first:
        traced = np.arange(count, dtype=np.int64)
    else:
        # evenly spaced and rounded: non-decreasing, so the distinct ones are those unlike
        # the one before (np.unique's sort took 1 ms for 10⁴ members traced)
        traced = np.linspace(0, members - 1, count).round().astype(np.int64)
        distinct = np.ones(traced.size, dtype=bool)
        distinct[1:] = traced[1:] != traced[:-1]
        traced = traced[distinct]
    trace_row = np.full(members, -1, dtype=np.int64)
    trace_row[traced] = np.arange(traced.size)
    return trace_row, traced


def _prediction(law, model, scheme=None, tau=None, span=None):
    """The one-step propagator of each member's linear prediction and its step: ``R(τÃ)``
    for fixed steps of ``tau`` with ``scheme``, or ``e^{Ãh}`` over ``PREDICTION_STEPS``
    steps of an adaptive run over ``span``; an empty matrix for laws that are not
    constant."""
    if not law.is_constant:
        return np.zeros((0, 0)), 1.0
    A = np.asarray(law.A_tilde(model), dtype=float)
    if span is not None:
        h = span / PREDICTION_STEPS
        return np.ascontiguousarray(theory._expm(A * h)), h
    return np.ascontiguousarray(theory.step_matrix(A, scheme, tau)), tau


def measure_stride(R) -> int:
    """Every how many steps the fixed-step kernel measures each member's residual: the
    most steps, up to ``MAX_STRIDE``, over which every mode of the law's one-step map
    ``R = R(τÃ)`` changes by at most ``STRIDE_CHANGE`` (``|ln λ|`` for each eigenvalue
    λ: decay and rotation together); 1 for a law that is not constant (no ``R``).

    The measurement's cost is memory traffic beside a step that may cost less (a
    pendulum's step is a few nanoseconds); over such a stride a mode moves by at most a
    fifth, so the envelope, the peak (read low by at most about ``STRIDE_CHANGE²/8``, half
    a per cent) and the floor are read as from every step, and the one-step map fitted to
    pairs a stride apart is ``R^s``, whose spectral radius is ``ρ(R)^s`` exactly."""
    if R.size == 0:
        return 1
    lam = np.linalg.eigvals(np.asarray(R, dtype=float)).astype(complex)
    with np.errstate(divide="ignore"):
        change = np.abs(np.log(lam)).max()
    if not np.isfinite(change):  # an eigenvalue 0 (ln = −inf): every step
        return 1
    if change == 0.0:  # every mode on the unit circle at angle 0: nothing moves
        return MAX_STRIDE
    return int(min(MAX_STRIDE, max(1, math.floor(STRIDE_CHANGE / change))))


#: members whose final states set the roundoff level the growth test compares with
ROUNDOFF_SAMPLE = 16
DECISION_REASONS = messages(DecisionReason)


def _noise(run, x0, status, gain) -> float:
    """The roundoff level the fits keep their distance from (γ's window ends
    ``GAMMA_MARGIN`` times above it, :func:`.engine.decay.fit.gamma_of`): as
    :func:`_roundoff`, at the initial states of the first ``ROUNDOFF_SAMPLE`` members
    (the same for any ensemble or look that holds them) and the run's end time (the
    largest ``|∂g/∂t · t|``).  Known before the members run, as the kernel needs it."""
    k = min(ROUNDOFF_SAMPLE, x0.shape[0])
    return _roundoff(run.model, x0[:k], status[:k], run.p, float(run.t_end), gain,
                     run.threads, run.sampled)  # fmt: skip


def _roundoff(model, x_final, status, p, t, gain, threads, sampled=False):
    """What roundoff can build up in the residual by the end of the run: its level at the
    final states of up to ``ROUNDOFF_SAMPLE`` members that ran to the end, evenly spaced
    (:func:`._measures.roundoff_level`), accumulated by the law's recursion (``gain``,
    :func:`.theory.forced_gain`; once where it is unknown or unbounded).  ``sampled``:
    the members were sampled (:func:`_residual_rows` by the sampler)."""
    ran = np.flatnonzero(status == 0)
    if ran.size == 0:
        return 0.0
    pick = ran[np.unique(np.linspace(0, ran.size - 1, min(ROUNDOFF_SAMPLE, ran.size))
                         .astype(int))]  # fmt: skip
    level = _measures.roundoff_level(
        lambda X, at: _residual_rows(model, np.ascontiguousarray(X), p, at, threads, sampled),
        x_final[pick], t)  # fmt: skip
    return level * (gain if math.isfinite(gain) else 1.0)
