"""The ensemble kernels' arguments, in named groups.

A kernel takes a few groups instead of two dozen positionals: what the members start from
and run under (:class:`Inputs`), the time grid (:class:`FixedGrid` or
:class:`AdaptiveGrid`), the scheme's coefficients (:class:`Tableau`, :class:`PairTableau`),
what is measured (:class:`FixedMeasurement`, :class:`AdaptiveMeasurement`) and where the
results go (:class:`Outputs`), then the range of work items.  Each group is a
``NamedTuple``, which numba passes as a tuple of its fields: a field is read by name in
the kernel at no cost, and a kernel is compiled once per combination of the fields'
types.  The constructors below fix those types (floats as floats, counts as int64), so
that a caller's ``0`` for ``0.0`` does not compile a second kernel.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..decay.record import Record

__all__ = ["AdaptiveGrid", "AdaptiveMeasurement", "FixedGrid", "FixedMeasurement", "Inputs",
           "Outputs", "PairTableau", "Tableau", "inputs", "outputs"]  # fmt: skip


class Inputs(NamedTuple):
    """The members' initial states ``x0`` (members, 2n) and perturbations ``alpha0``
    (members, 2m + k); the parameters ``p`` and the law's run-time numbers
    (``law_mat``, ``law_scal``)."""

    x0: np.ndarray
    alpha0: np.ndarray
    p: np.ndarray
    law_mat: np.ndarray
    law_scal: np.ndarray


def inputs(x0, alpha0, p, bound) -> Inputs:
    """:class:`Inputs` of these members under the bound law ``bound``."""
    return Inputs(np.ascontiguousarray(x0, dtype=float), np.ascontiguousarray(alpha0, dtype=float),
                  p, bound.matrix, bound.scalars)  # fmt: skip


class FixedGrid(NamedTuple):
    """Fixed steps: ``nsteps`` steps of ``tau`` from ``t0``, a sample stored every
    ``save_every`` steps."""

    t0: float
    tau: float
    nsteps: int
    save_every: int

    @classmethod
    def of(cls, t0, tau, nsteps, save_every) -> FixedGrid:
        return cls(float(t0), float(tau), np.int64(nsteps), np.int64(save_every))


class AdaptiveGrid(NamedTuple):
    """Adaptive steps from ``t0`` through the sample times ``save_times`` (the last is
    the end), the first step ``h0``, the tolerances and the most steps per member."""

    t0: float
    save_times: np.ndarray
    h0: float
    rtol: float
    atol: np.ndarray  #: one per state component
    max_steps: int

    @classmethod
    def of(cls, t0, save_times, h0, rtol, atol, max_steps) -> AdaptiveGrid:
        return cls(float(t0), np.ascontiguousarray(save_times, dtype=float), float(h0),
                   float(rtol), np.ascontiguousarray(atol, dtype=float),
                   np.int64(max_steps))  # fmt: skip


class Tableau(NamedTuple):
    """An explicit scheme's Butcher coefficients."""

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray

    @classmethod
    def of(cls, scheme) -> Tableau:
        return cls(scheme.A, scheme.b, scheme.c)


class PairTableau(NamedTuple):
    """An embedded pair's coefficients: the scheme's, the error weights ``e`` and the
    error estimate's order ``q``."""

    a: np.ndarray
    b: np.ndarray
    e: np.ndarray
    c: np.ndarray
    q: int

    @classmethod
    def of(cls, pair) -> PairTableau:
        sc = pair.scheme
        return cls(sc.A, sc.b, pair.error, sc.c, np.int64(pair.error_order))


class FixedMeasurement(NamedTuple):
    """What the fixed-step kernel measures: members whose residual exceeds
    ``divergence`` at a stored sample stop; the decay on ``‖g_k − g_ref[k]‖∞`` (``g_ref``
    with no rows: ``‖g_k‖∞``) at every ``stride``-th state, with the linear prediction
    ``g_{k+1} = R g_k`` over ``stride`` steps (``R`` empty: none); member ``i``'s
    samples go to row ``trace_row[i]`` of the stored norms (−1: none); ``noise``: the
    run's roundoff level, from which the fits' windows keep their distance
    (:func:`stabdae.engine.decay.fit.gamma_of`; 0: none known)."""

    divergence: float
    g_ref: np.ndarray
    R: np.ndarray
    stride: int
    trace_row: np.ndarray
    noise: float

    @classmethod
    def of(cls, divergence, g_ref, R, stride, trace_row, noise=0.0) -> FixedMeasurement:
        return cls(float(divergence), np.ascontiguousarray(g_ref, dtype=float),
                   np.ascontiguousarray(R, dtype=float), np.int64(stride),
                   np.ascontiguousarray(trace_row, dtype=np.int64), float(noise))  # fmt: skip


class AdaptiveMeasurement(NamedTuple):
    """What the adaptive kernel measures: as :class:`FixedMeasurement`, at every accepted
    step, on ``‖g − g_ref(t)‖∞``: ``g_ref`` the reference trajectory's accepted steps, a
    row ``(t, g)`` each, linear in ``t`` between them (no rows: ``‖g‖∞``); with the
    prediction ``R = e^{Ã h_pred}``."""

    divergence: float
    R: np.ndarray
    h_pred: float
    trace_row: np.ndarray
    g_ref: np.ndarray
    noise: float

    @classmethod
    def of(cls, divergence, R, h_pred, trace_row, g_ref, noise=0.0) -> AdaptiveMeasurement:
        return cls(float(divergence), np.ascontiguousarray(R, dtype=float), float(h_pred),
                   np.ascontiguousarray(trace_row, dtype=np.int64),
                   np.ascontiguousarray(g_ref, dtype=float), float(noise))  # fmt: skip


class Outputs(NamedTuple):
    """Where the results go, one row per member (``norms``: per traced member and stored
    sample; ``meas``, ``codes``: the measurement record's float and integer columns,
    :mod:`stabdae.engine.decay.record`).  ``g_out``: the first member's residual at every
    step (fixed steps; adaptive steps: ``(t, g)`` at its start and every accepted step, as
    many as fit; no rows: not kept); ``steps``, ``nfev``: accepted steps and
    right-hand-side evaluations per member (adaptive steps; empty otherwise)."""

    norms: np.ndarray
    meas: np.ndarray
    codes: np.ndarray
    x_final: np.ndarray
    status: np.ndarray
    fail_step: np.ndarray
    e0: np.ndarray
    e1: np.ndarray
    g_out: np.ndarray
    steps: np.ndarray
    nfev: np.ndarray


def outputs(members: int, n2: int, ng: int, ntraced: int, nsave: int, rdtype, *,
            residuals: int = 0, columns: int = 0, counts: bool = False) -> Outputs:  # fmt: skip
    """:class:`Outputs` for ``members`` members of state size ``n2``, allocated empty (the
    kernels write every element: the fixed-step kernel on its own threads, so that the
    pages are first touched there); ``residuals`` rows of ``g_out`` (of ``columns``
    columns, ``ng`` by default); ``counts``: the adaptive kernel's step counts."""
    rec = Record.empty(members)
    per = members if counts else 0
    return Outputs(np.empty((ntraced, nsave), dtype=rdtype), rec.values, rec.codes,
                   np.empty((members, n2)), np.empty(members, dtype=np.int8),
                   np.empty(members, dtype=np.int64), np.empty(members), np.empty(members),
                   np.full((residuals, columns or ng), np.nan), np.zeros(per, dtype=np.int64),
                   np.zeros(per, dtype=np.int64))  # fmt: skip
