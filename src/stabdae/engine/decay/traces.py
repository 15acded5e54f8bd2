"""The estimator run over stored residual traces (for tests and for traces computed
elsewhere), on threads."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..threads import run_chunks
from .ladder import ladders, scratch
from .member import begin, finish, observe, predict
from .onestep import spectral_radius_of
from .record import Record


# --------------------------------------------------------------------- stored traces
@njit(nogil=True, cache=True)
def _measure_rows(norms, times, meas, codes, R, alphas, noise, lo, hi):
    lt, lv, base = ladders(1)
    rt, ry, a, b, lg = scratch()
    T = norms.shape[1]
    span = times[T - 1] - times[0]
    dt = times[1] - times[0] if T > 1 else 1.0
    g = np.empty(alphas.shape[1])
    gn = np.empty(alphas.shape[1])
    rho_R = spectral_radius_of(R) if R.shape[0] > 0 else math.nan
    for r in range(lo, hi):
        begin(lt, lv, base, meas, codes, 0, r, norms[r, 0], norms[r, 0])
        last = norms[r, 0]
        stopped = False
        for i in range(1, T):
            v = norms[r, i]
            if not math.isfinite(v):
                stopped = True
                break
            w = min(4, int(5.0 * (times[i] - times[0]) / span)) if span > 0.0 else 4
            observe(lt, lv, base, meas, 0, r, times[i] - times[0], v, v, w)
            last = v
        finish(lt, lv, meas, codes, 0, r, last, stopped, dt, rt, ry, a, b, lg, noise)
        if R.shape[0] > 0:
            predict(R, alphas, r, T - 1, dt, lt, lv, base, meas, codes, 0, r, rt, ry, a, b, lg,
                    g, gn, rho_R)  # fmt: skip


def measure_traces(norms, times, R=None, alpha0=None, noise=0.0):
    """The measurement record (:data:`COLUMNS`) of stored traces, each sample taken as a
    step.

    Parameters
    ----------
    norms : array (members, samples)
        ``‖g(t_i)‖``; a non-finite sample ends the trace (a stop).
    times : array (samples,)
        Uniformly spaced sample times.
    R, alpha0 : arrays (ng, ng) and (members, ng), optional
        The one-sample propagator of the linear prediction and each member's ``g(t_0)``:
        fills ``beta_predicted``.
    noise : float, optional
        The traces' roundoff level: the fits keep their distance from it (the window
        ends ``ROUNDOFF_FLOOR`` times above it where a trace ends still decaying; γ is
        taken ``GAMMA_MARGIN`` times above it, :func:`.fit.gamma_of`).

    Returns
    -------
    Record
        ``record["beta"]`` etc.: a column by name, one row per member.
    """
    norms = np.ascontiguousarray(np.atleast_2d(norms), dtype=np.float64)
    times = np.ascontiguousarray(times, dtype=np.float64)
    M = norms.shape[0]
    R = np.zeros((0, 0)) if R is None else np.ascontiguousarray(R, dtype=np.float64)
    alphas = (np.zeros((M, 1)) if alpha0 is None
              else np.ascontiguousarray(np.atleast_2d(alpha0), dtype=np.float64))  # fmt: skip
    out = Record.empty(M)
    run_chunks(lambda lo, hi: _measure_rows(norms, times, *out, R, alphas, float(noise), lo, hi), M)
    return out
