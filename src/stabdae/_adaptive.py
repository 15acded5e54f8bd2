"""Adaptive steps with an embedded Runge–Kutta pair (Dormand–Prince 5(4)): one trajectory
(:func:`integrate_adaptive`) and ensembles whose members each control their own step
(``stabdae.ensemble(rtol=...)``), both running the one loop of :func:`_adaptive_loop`.

For reference solutions and work–precision comparisons: the stabilized right-hand side
(3.1), (3.11) integrated with local error control, ``err = ‖e / (atol + rtol·max(|x|,
|x̃|))‖_RMS ≤ 1`` per step, ``e = τ Σ (b_i − b̂_i) k_i``, the step updated by
``0.9 err^{−1/5}`` within ``[0.2, 10]`` (no growth right after a rejection), the first
step chosen as in Hairer, Nørsett & Wanner (II.4).  Steps end exactly on the sample times.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from numba import njit

from ._cache import kernel_key, keyed_cache, tag
from ._integrate import (
    IntegrationWarning,
    _positive,
    _trajectory_dataset,
    check_multiplier,
    initial_state,
    projection_setting,
    sample_writer,
)
from ._laws import as_law, bind_law
from ._model import Model
from ._rhs import kernels_for
from ._schemes import dopri5, dopri5_embedded_weights
from ._status import Status

__all__ = ["integrate_adaptive"]

_STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
_MAX_STEPS = int(Status.MAX_STEPS)
_DIVERGED = int(Status.DIVERGED)


def adaptive_for(model: Model, bound, multiplier: str = "ldl"):
    """The compiled adaptive loop for ``model`` under the law's kind (memoized)."""
    key = ("adaptive", bound.code, bound.fn, multiplier)
    cache = model._kernel_cache
    if key not in cache:
        cache[key] = _build_adaptive(kernels_for(model, bound, multiplier))
    return cache[key]


def adaptive_ensemble_for(model: Model, bound):
    """The compiled per-member adaptive ensemble kernel (memoized)."""
    key = ("adaptive-ensemble", bound.code, bound.fn)
    cache = model._kernel_cache
    if key not in cache:
        cache[key] = _build_adaptive_ensemble(kernels_for(model, bound))
    return cache[key]


def _adaptive_loop(K, save, label: str):
    """The Dormand–Prince loop of one trajectory, with ``save(j, t, x, p, ws, g, out)``
    storing sample ``j`` (it returns True to stop the trajectory: status DIVERGED).

    ``run(x, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_bh, tab_c, rtol, atol,
    h0, max_steps, sweeps, tol, ws, k, xs, xnew, err, g, out, counts)`` integrates ``x`` in
    place from ``t0`` through every time in ``save_times`` (increasing, after ``t0``);
    sample ``j + 1`` is saved at ``save_times[j]`` (sample 0 at ``t0``).  ``sweeps > 0``
    projects the state after each accepted step (``K.project``; the first stage of the
    next step is then evaluated anew).  ``counts`` receives (accepted, rejected, rhs
    evaluations).  Returns ``(status, samples written)``; on a failure ``x`` is the last
    accepted state.  It allocates nothing: the buffers are the caller's.  ``label`` keeps
    the symbol names of loops with different ``save`` functions apart (:func:`._cache.tag`).
    """
    rhs, project = K.rhs, K.project
    N2 = 2 * K.n

    @njit(error_model="numpy")
    def f_eval(t, x, p, law_mat, law_scal, ws, xdot):
        # one out-of-line copy of the (inlined) right-hand side, called from three places:
        # compiling the inlined body once instead of three times halves the compile time
        return rhs(t, x, p, law_mat, law_scal, ws, xdot)

    @njit(error_model="numpy")
    def rms_error(x, xnew, err, rtol, atol):
        s = 0.0
        for l in range(N2):
            sc = atol + rtol * max(abs(x[l]), abs(xnew[l]))
            e = err[l] / sc
            s += e * e
        return math.sqrt(s / N2)

    @njit(error_model="numpy")
    def run(x, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_bh, tab_c, rtol,
            atol, h0, max_steps, sweeps, tol, ws, k, xs, xnew, err, g, out, counts):  # fmt: skip
        s = tab_b.shape[0]
        t = t0
        nfev = 0
        counts[0], counts[1], counts[2] = 0, 0, 0
        if save(0, t, x, p, ws, g, out):
            return _DIVERGED, 1
        st = f_eval(t, x, p, law_mat, law_scal, ws, k[0])
        nfev += 1
        if st != 0:
            counts[2] = nfev
            return st, 1
        # first step (Hairer–Nørsett–Wanner II.4): h from ‖x‖/‖ẋ‖, then from ‖ẍ‖
        h = h0
        if h <= 0.0:
            d0 = d1 = 0.0
            for l in range(N2):
                sc = atol + rtol * abs(x[l])
                d0 += (x[l] / sc) ** 2
                d1 += (k[0, l] / sc) ** 2
            d0, d1 = math.sqrt(d0 / N2), math.sqrt(d1 / N2)
            h = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
            h = min(h, save_times[save_times.shape[0] - 1] - t0)
            for l in range(N2):
                xs[l] = x[l] + h * k[0, l]
            st = f_eval(t + h, xs, p, law_mat, law_scal, ws, k[1])
            nfev += 1
            if st == 0:
                d2 = 0.0
                for l in range(N2):
                    sc = atol + rtol * abs(x[l])
                    d2 += ((k[1, l] - k[0, l]) / sc) ** 2
                d2 = math.sqrt(d2 / N2) / h
                if max(d1, d2) <= 1e-15:
                    h1 = max(1e-6, h * 1e-3)
                else:
                    h1 = (0.01 / max(d1, d2)) ** 0.2
                h = min(100.0 * h, h1)
        accepted = rejected = 0
        j = 0
        nsave = save_times.shape[0]
        after_reject = False
        while j < nsave:
            target = save_times[j]
            if accepted + rejected >= max_steps:
                counts[0], counts[1], counts[2] = accepted, rejected, nfev
                return _MAX_STEPS, j + 1
            hit = False
            hh = h
            if t + hh >= target - 1e-12 * abs(target):
                hh = target - t
                hit = True
            if hh <= 1e-14 * max(1.0, abs(t)):
                counts[0], counts[1], counts[2] = accepted, rejected, nfev
                return _STEP_TOO_SMALL, j + 1
            # stages 1 … s−1 (stage 0 is ẋ at (t, x): first same as last)
            st = 0
            for i in range(1, s):
                for l in range(N2):
                    acc = 0.0
                    for m_ in range(i):
                        acc += tab_a[i, m_] * k[m_, l]
                    xs[l] = x[l] + hh * acc
                st = f_eval(t + tab_c[i] * hh, xs, p, law_mat, law_scal, ws, k[i])
                nfev += 1
                if st != 0:
                    break
            finite = st == 0
            if finite:
                for l in range(N2):
                    acc = 0.0
                    acc_e = 0.0
                    for i in range(s):
                        acc += tab_b[i] * k[i, l]
                        acc_e += (tab_b[i] - tab_bh[i]) * k[i, l]
                    xnew[l] = x[l] + hh * acc
                    err[l] = hh * acc_e
                    if not (math.isfinite(xnew[l]) and math.isfinite(err[l])):
                        finite = False
            if not finite:  # a failed evaluation or overflow: shrink hard and retry
                rejected += 1
                h = 0.25 * hh
                after_reject = True
                continue
            e = rms_error(x, xnew, err, rtol, atol)
            if e <= 1.0:
                accepted += 1
                t = target if hit else t + hh
                for l in range(N2):
                    x[l] = xnew[l]
                    k[0, l] = k[s - 1, l]  # FSAL: the last stage is ẋ at the new point
                if sweeps > 0:
                    st = project(t, x, p, ws, sweeps, tol)
                    if st == 0:
                        st = f_eval(t, x, p, law_mat, law_scal, ws, k[0])
                        nfev += 1
                    if st != 0:
                        counts[0], counts[1], counts[2] = accepted, rejected, nfev
                        return st, j + 1
                fac = 10.0 if e == 0.0 else min(10.0, max(0.2, 0.9 * e ** -0.2))
                if after_reject:
                    fac = min(fac, 1.0)
                after_reject = False
                h = hh * fac if not hit else max(h, hh * fac)
                if hit:
                    j += 1
                    if save(j, t, x, p, ws, g, out):
                        counts[0], counts[1], counts[2] = accepted, rejected, nfev
                        return _DIVERGED, j + 1
            else:
                rejected += 1
                h = hh * max(0.2, 0.9 * e ** -0.2)
                after_reject = True
        counts[0], counts[1], counts[2] = accepted, rejected, nfev
        return 0, nsave + 1

    tag(kernel_key(K.key, f"adaptive-loop-{label}"), f_eval, rms_error, run)
    return run


def save_grid(t0: float, t_end: float, save_dt) -> np.ndarray:
    """Sample times after ``t0``: every ``save_dt``, the last one at ``t_end`` (only
    ``t_end`` when ``save_dt`` is None)."""
    if save_dt is None:
        return np.array([t_end])
    save_dt = _positive(save_dt, "save_dt")
    count = max(1, int(math.ceil((t_end - t0) / save_dt - 1e-9)))
    out = np.minimum(t0 + save_dt * np.arange(1, count + 1), t_end)
    out[-1] = t_end
    return out


def _build_adaptive(K):
    make_workspace = K.make_workspace
    write = sample_writer(K)
    N2, ng = 2 * K.n, K.ng

    @njit(forceinline=True)
    def save(j, t, x, p, ws, g, out):
        write(j, t, x, p, ws, g, out[0], out[1], out[2])
        return False

    run = _adaptive_loop(K, save, "trajectory")

    @njit(error_model="numpy")
    def adaptive_kernel(x0, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_bh,
                        tab_c, rtol, atol, h0, max_steps, sweeps, tol, out_x, out_g, out_e,
                        counts):  # fmt: skip
        """One trajectory from ``x0``: the loop of :func:`_adaptive_loop` writing state,
        residual and energy samples into ``out_x``, ``out_g``, ``out_e``."""
        ws = make_workspace()
        k = np.empty((tab_b.shape[0], N2))
        xs, xnew, err, g = np.empty(N2), np.empty(N2), np.empty(N2), np.empty(ng)
        x = x0.copy()
        return run(x, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_bh, tab_c,
                   rtol, atol, h0, max_steps, sweeps, tol, ws, k, xs, xnew, err, g,
                   (out_x, out_g, out_e), counts)  # fmt: skip

    keyed_cache(adaptive_kernel, kernel_key(K.key, "adaptive-dopri5"))
    return adaptive_kernel


def _build_adaptive_ensemble(K):
    make_workspace, residual, energy = K.make_workspace, K.residual, K.energy
    N2, ng = 2 * K.n, K.ng

    @njit(forceinline=True)
    def save(j, t, x, p, ws, g, out):
        norms, i, divergence = out
        residual(t, x, p, ws, g)
        r = 0.0
        for l in range(ng):
            r = max(r, abs(g[l]))
        if not math.isfinite(r):
            r = math.inf
        norms[i, j] = r
        return not (r <= divergence)

    run = _adaptive_loop(K, save, "ensemble")

    @njit(nogil=True, error_model="numpy")
    def ensemble_kernel(x0, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_bh,
                        tab_c, rtol, atol, h0, max_steps, divergence, norms, x_final, status,
                        fail_step, e0, e1, steps, nfev, lo, hi):  # fmt: skip
        """Members ``lo … hi − 1``, each with its own step control; the buffers are
        allocated once per call (a chunk of members), not per member."""
        ws = make_workspace()
        k = np.empty((tab_b.shape[0], N2))
        xs, xnew, err, g = np.empty(N2), np.empty(N2), np.empty(N2), np.empty(ng)
        x = np.empty(N2)
        counts = np.zeros(3, dtype=np.int64)
        tend = save_times[save_times.shape[0] - 1]
        for i in range(lo, hi):
            for l in range(N2):
                x[l] = x0[i, l]
            if status[i] != 0:  # not placed: keep it out
                for l in range(N2):
                    x_final[i, l] = x[l]
                continue
            e0[i] = energy(t0, x, p, ws)
            st, written = run(x, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_bh,
                              tab_c, rtol, atol, h0, max_steps, 0, 0.0, ws, k, xs, xnew,
                              err, g, (norms, i, divergence), counts)  # fmt: skip
            for l in range(N2):
                x_final[i, l] = x[l]
            status[i] = st
            steps[i] = counts[0]
            nfev[i] = counts[2]
            if st != 0:
                fail_step[i] = counts[0]
            else:
                e1[i] = energy(tend, x, p, ws)

    keyed_cache(ensemble_kernel, kernel_key(K.key, "adaptive-ensemble-dopri5"))
    return ensemble_kernel


def integrate_adaptive(
    model: Model,
    x0=None,
    law=None,
    t_end: float = 1.0,
    *,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    save_dt: float | None = None,
    first_step: float | None = None,
    max_steps: int = 10_000_000,
    params=None,
    t0: float | None = None,
    multiplier: str = "ldl",
    projection: str | None = None,
):
    """Integrate one trajectory of the stabilized equations with Dormand–Prince 5(4).

    Parameters
    ----------
    model : Model
    x0 : array (2n,), optional
        Initial state (default the model's reference state).
    law : Law
        Constraint-perturbation law, as for :func:`stabdae.integrate` (``none()`` gives the
        index-1 equations).
    t_end : float
        Final time.
    rtol, atol : float
        Relative and absolute local error tolerances (per state component, RMS norm).
    save_dt : float, optional
        Spacing of the stored samples (the last one at ``t_end``); steps end exactly on
        them.  Default: only ``t0`` and ``t_end``.
    first_step : float, optional
        Initial step (default: chosen from the tolerances and ``ẋ``, ``ẍ``).
    max_steps : int
        Accepted plus rejected steps before giving up (status ``MAX_STEPS``).
    params : mapping or array, optional
    t0 : float, optional
    multiplier : {"ldl", "lstsq"}
        As for :func:`stabdae.integrate`: ``"lstsq"`` integrates redundant constraints.
    projection : {None, "post", "full"}
        As for :func:`stabdae.integrate`, after each accepted step (costs one more
        right-hand-side evaluation per step: the first-same-as-last stage is lost).

    Returns
    -------
    xarray.Dataset
        As :func:`stabdae.integrate`, with attributes ``method = "dopri5"``, ``rtol``,
        ``atol``, ``steps_accepted``, ``steps_rejected`` and ``rhs_evaluations``.

    Examples
    --------
    >>> import stabdae
    >>> model = stabdae.load_model("pendulum")
    >>> ds = stabdae.integrate_adaptive(model, None, stabdae.none(), 1.0, rtol=1e-10,
    ...                                 atol=1e-12)
    """
    if not isinstance(model, Model):
        raise TypeError(
            f"integrate_adaptive: model must be a stabdae.Model, got {type(model).__name__}"
        )
    if law is None:
        raise ValueError("integrate_adaptive: give a law, e.g. stabdae.none() or "
                         "stabdae.baumgarte(omega=10.0, xi=1.0)")  # fmt: skip
    law = as_law(law)
    rtol, atol = _positive(rtol, "rtol"), _positive(atol, "atol")
    if rtol < 100 * np.finfo(float).eps:
        raise ValueError(
            f"integrate_adaptive: rtol = {rtol:g} is below 100 machine epsilons "
            f"({100 * np.finfo(float).eps:.1e}); the error estimate is roundoff"
        )
    p = model.param_vector(params)
    t0 = model.t0 if t0 is None else float(t0)
    span = float(t_end) - t0
    if not (math.isfinite(span) and span > 0):
        raise ValueError(f"integrate_adaptive: t_end must be after t0 = {t0}, got {t_end!r}")
    save_times = save_grid(t0, float(t_end), save_dt)
    h0 = -1.0 if first_step is None else _positive(first_step, "first_step")
    x0 = initial_state(model, x0, p, "integrate_adaptive")

    scheme = dopri5()
    multiplier = check_multiplier(multiplier, "integrate_adaptive")
    sweeps, tol = projection_setting(projection, "integrate_adaptive")
    bound = bind_law(law, model)
    kernel = adaptive_for(model, bound, multiplier)
    nsave = save_times.shape[0] + 1
    out_x = np.full((nsave, 2 * model.n), np.nan)
    out_g = np.full((nsave, model.n_residual), np.nan)
    out_e = np.full(nsave, np.nan)
    counts = np.zeros(3, dtype=np.int64)
    status, written = kernel(
        x0, t0, save_times, p, bound.matrix, bound.scalars, scheme.A, scheme.b,
        dopri5_embedded_weights(), scheme.c, rtol, atol, h0, int(max_steps), sweeps, tol,
        out_x, out_g, out_e, counts,
    )  # fmt: skip
    status = Status(status)
    if status != Status.OK:
        warnings.warn(
            f"integrate_adaptive({model.name}): stopped after {int(counts[0])} accepted steps "
            f"({written - 1} of {nsave - 1} samples): {status.description}; samples up to "
            "there are kept, later ones are NaN",
            IntegrationWarning,
            stacklevel=2,
        )
    times = np.concatenate([[t0], save_times])
    ds = _trajectory_dataset(
        model, p, law, scheme, times, out_x, out_g, out_e, status, int(counts[0]),
        dict(method="dopri5", rtol=rtol, atol=atol, t0=t0, t_end=float(t_end),
             steps=int(counts[0]), multiplier=multiplier,
             projection=str(projection).lower()),
    )  # fmt: skip
    ds.attrs.update(
        steps_accepted=int(counts[0]), steps_rejected=int(counts[1]),
        rhs_evaluations=int(counts[2]),
    )  # fmt: skip
    return ds
