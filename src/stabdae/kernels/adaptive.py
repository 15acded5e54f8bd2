"""Adaptive steps with an embedded Runge–Kutta pair (Dormand–Prince 5(4) or Hairer's
DOP853, :class:`stabdae._schemes.EmbeddedPair`): the loop of one trajectory
(:func:`adaptive_for`, behind :func:`stabdae.integrate_adaptive`) and the per-member
ensemble kernel (:func:`adaptive_ensemble_for`, behind ``stabdae.ensemble(rtol=...)``),
both running the one loop of :func:`_adaptive_loop`.

Local error control ``err ≤ 1`` per step with the error estimates ``e = τ Σ (b_i − b̂_i) k_i``
scaled by ``atol + rtol·max(|x|, |x̃|)``: ``err`` is their RMS norm for Dormand–Prince, and
``‖e₅‖² / √(‖e₅‖² + 0.01 ‖e₃‖²)`` of the fifth- and third-order estimates for DOP853 (as in
Hairer's code and SciPy's).  The step is updated by ``0.9 err^{−1/(q+1)}`` within
``[0.2, 10]`` (``q`` = 4 and 7: the estimate's order; no growth right after a rejection),
the first step chosen as in Hairer, Nørsett & Wanner (II.4).  Steps end exactly on the
sample times.  The pair's coefficients are run-time arrays: one compiled loop serves both.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._status import Status
from .cache import kernel_key, keyed_cache, memo, tag
from .decay import begin, finish, ladders, observe, predict, scratch
from .rhs import kernels_for
from .steps import sample_writer

__all__ = ["adaptive_ensemble_for", "adaptive_for"]

_STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
_MAX_STEPS = int(Status.MAX_STEPS)
_DIVERGED = int(Status.DIVERGED)


def adaptive_for(model, bound, multiplier: str = "ldl"):
    """The compiled adaptive loop for ``model`` under the law's kind (memoized)."""
    return memo(model, ("adaptive", bound.code, bound.fn, multiplier),
                lambda: _build_adaptive(kernels_for(model, bound, multiplier)))


def adaptive_ensemble_for(model, bound):
    """The compiled per-member adaptive ensemble kernel (memoized)."""
    return memo(model, ("adaptive-ensemble", bound.code, bound.fn),
                lambda: _build_adaptive_ensemble(kernels_for(model, bound)))


def _adaptive_loop(K, save, label: str, accepted_step=None):
    """The adaptive loop of one trajectory, with ``save(j, t, x, p, ws, g, out)``
    storing sample ``j`` (it returns True to stop the trajectory: status DIVERGED) and
    ``accepted_step(t, ws, out)`` called after every accepted step, with ``ws.g`` the
    residual at the new state (the last evaluation is there: first same as last).

    ``run(x, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_e, tab_c, combined, q,
    rtol, atol, h0, max_steps, sweeps, tol, ws, k, xs, xnew, g, out, counts)`` integrates
    ``x`` with the pair's tableau, error weights ``tab_e`` (2 × s_e), norm (``combined``)
    and estimate order ``q`` (:class:`stabdae._schemes.EmbeddedPair`; ``k`` has s_e rows) in
    place from ``t0`` through every time in ``save_times`` (increasing, after ``t0``);
    sample ``j + 1`` is saved at ``save_times[j]`` (sample 0 at ``t0``).  ``sweeps > 0``
    projects the state after each accepted step (``K.project``; the first stage of the
    next step is then evaluated anew).  ``counts`` receives (accepted, rejected, rhs
    evaluations).  Returns ``(status, samples written)``; on a failure ``x`` is the last
    accepted state.  It allocates nothing: the buffers are the caller's.  ``label`` keeps
    the symbol names of loops with different ``save`` functions apart (:func:`.cache.tag`).
    """
    rhs, project = K.rhs, K.project
    N2 = 2 * K.n
    if accepted_step is None:
        accepted_step = _no_hook

    @njit(error_model="numpy")
    def f_eval(t, x, p, law_mat, law_scal, ws, xdot):
        # one out-of-line copy of the (inlined) right-hand side, called from three places:
        # compiling the inlined body once instead of three times halves the compile time
        return rhs(t, x, p, law_mat, law_scal, ws, xdot)

    @njit(error_model="numpy")
    def run(x, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_e, tab_c, combined, q,
            rtol, atol, h0, max_steps, sweeps, tol, ws, k, xs, xnew, g, out, counts):  # fmt: skip
        s = tab_b.shape[0]
        s_e = tab_e.shape[1]  # s, or s + 1 with ẋ at the new state evaluated for the estimate
        expo = 1.0 / (q + 1)
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
                    h1 = (0.01 / max(d1, d2)) ** expo
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
                    for i in range(s):
                        acc += tab_b[i] * k[i, l]
                    xnew[l] = x[l] + hh * acc
                    if not math.isfinite(xnew[l]):
                        finite = False
            if finite and s_e > s:  # ẋ at the new state, for the estimate and the next step
                st = f_eval(t + hh, xnew, p, law_mat, law_scal, ws, k[s])
                nfev += 1
                finite = st == 0
            e = 0.0
            if finite:
                # ‖·‖ over (atol + rtol max(|x|, |x_new|)): the RMS of τ Σ e_i k_i, or for
                # DOP853 Hairer's ‖e₅‖² / √(‖e₅‖² + 0.01 ‖e₃‖²) from the two estimates
                s5 = s3 = 0.0
                for l in range(N2):
                    sc = atol + rtol * max(abs(x[l]), abs(xnew[l]))
                    acc5 = 0.0
                    for i in range(s_e):
                        acc5 += tab_e[0, i] * k[i, l]
                    if combined:
                        acc3 = 0.0
                        for i in range(s_e):
                            acc3 += tab_e[1, i] * k[i, l]
                        e5, e3 = acc5 / sc, acc3 / sc
                        s5 += e5 * e5
                        s3 += e3 * e3
                    else:
                        e5 = hh * acc5 / sc
                        s5 += e5 * e5
                if combined:
                    if s5 != 0.0 or s3 != 0.0:
                        e = abs(hh) * s5 / math.sqrt((s5 + 0.01 * s3) * N2)
                else:
                    e = math.sqrt(s5 / N2)
                finite = math.isfinite(e)
            if not finite:  # a failed evaluation or overflow: shrink hard and retry
                rejected += 1
                h = 0.25 * hh
                after_reject = True
                continue
            if e <= 1.0:
                accepted += 1
                t = target if hit else t + hh
                for l in range(N2):
                    x[l] = xnew[l]
                    k[0, l] = k[s_e - 1, l]  # first same as last: ẋ at the new point
                if sweeps > 0:
                    st = project(t, x, p, ws, sweeps, tol)
                    if st == 0:
                        st = f_eval(t, x, p, law_mat, law_scal, ws, k[0])
                        nfev += 1
                    if st != 0:
                        counts[0], counts[1], counts[2] = accepted, rejected, nfev
                        return st, j + 1
                accepted_step(t, ws, out)
                fac = 10.0 if e == 0.0 else min(10.0, max(0.2, 0.9 * e ** -expo))
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
                h = hh * max(0.2, 0.9 * e ** -expo)
                after_reject = True
        counts[0], counts[1], counts[2] = accepted, rejected, nfev
        return 0, nsave + 1

    tag(kernel_key(K.key, f"adaptive-loop-{label}"), f_eval, run)
    return run


@njit(forceinline=True)
def _no_hook(t, ws, out):
    pass


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
    def adaptive_kernel(x0, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_e,
                        tab_c, combined, q, rtol, atol, h0, max_steps, sweeps, tol, out_x,
                        out_g, out_e, counts):  # fmt: skip
        """One trajectory from ``x0``: the loop of :func:`_adaptive_loop` writing state,
        residual and energy samples into ``out_x``, ``out_g``, ``out_e``."""
        ws = make_workspace()
        k = np.empty((tab_e.shape[1], N2))
        xs, xnew, g = np.empty(N2), np.empty(N2), np.empty(ng)
        x = x0.copy()
        return run(x, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_e, tab_c,
                   combined, q, rtol, atol, h0, max_steps, sweeps, tol, ws, k, xs, xnew, g,
                   (out_x, out_g, out_e), counts)  # fmt: skip

    keyed_cache(adaptive_kernel, kernel_key(K.key, "adaptive-dopri5"))
    return adaptive_kernel


def _build_adaptive_ensemble(K):
    make_workspace, residual, energy = K.make_workspace, K.residual, K.energy
    N2, ng = 2 * K.n, K.ng

    @njit(forceinline=True)
    def save(j, t, x, p, ws, g, out):
        norms, i, divergence, trace_row = out[0], out[1], out[2], out[3]
        residual(t, x, p, ws, g)
        r = 0.0
        for l in range(ng):
            r = max(r, abs(g[l]))
        if not math.isfinite(r):
            r = math.inf
        if trace_row[i] >= 0:
            norms[trace_row[i], j] = r
        return not (r <= divergence)

    @njit(forceinline=True)
    def accepted_step(t, ws, out):
        i, lt, lv, base, meas, t0, span = out[1], out[4], out[5], out[6], out[7], out[8], out[9]
        r = 0.0
        for l in range(ng):
            r = max(r, abs(ws.g[l]))
        window = min(4, int(5.0 * (t - t0) / span))
        observe(lt, lv, base, meas, 0, i, t - t0, r, r, window)

    run = _adaptive_loop(K, save, "ensemble", accepted_step)

    @njit(nogil=True, error_model="numpy")
    def ensemble_kernel(x0, alpha0s, t0, save_times, p, law_mat, law_scal, tab_a, tab_b,
                        tab_e, tab_c, combined, q, rtol, atol, h0, max_steps, divergence, R,
                        h_pred, trace_row, norms, meas, x_final, status, fail_step, e0, e1,
                        steps, nfev, lo, hi):  # fmt: skip
        """Members ``lo … hi − 1``, each with its own step control; the buffers are
        allocated once per call (a chunk of members), not per member.  Stored samples
        and decay measures as in the fixed-step kernel (:mod:`.ensemble`); the linear
        prediction steps ``g`` by ``R = e^{Ã h_pred}``."""
        ws = make_workspace()
        k = np.empty((tab_e.shape[1], N2))
        xs, xnew, g = np.empty(N2), np.empty(N2), np.empty(ng)
        x = np.empty(N2)
        counts = np.zeros(3, dtype=np.int64)
        tend = save_times[save_times.shape[0] - 1]
        span = tend - t0
        lt, lv, base = ladders(1)
        rt, ry, fa, fb, lg = scratch()
        g_p = np.empty(alpha0s.shape[1])
        gn_p = np.empty(alpha0s.shape[1])
        for i in range(lo, hi):
            for l in range(N2):
                x[l] = x0[i, l]
            if trace_row[i] >= 0:
                for s in range(norms.shape[1]):
                    norms[trace_row[i], s] = math.nan
            if status[i] != 0:  # not placed: keep it out
                for l in range(N2):
                    x_final[i, l] = x[l]
                begin(lt, lv, base, meas, 0, i, math.nan, math.nan)
                finish(lt, lv, meas, 0, i, math.nan, True, 1.0, rt, ry, fa, fb, lg)
                continue
            e0[i] = energy(t0, x, p, ws)
            residual(t0, x, p, ws, g)
            r0 = 0.0
            for l in range(ng):
                r0 = max(r0, abs(g[l]))
            begin(lt, lv, base, meas, 0, i, r0, r0)
            st, written = run(x, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_e,
                              tab_c, combined, q, rtol, atol, h0, max_steps, 0, 0.0, ws, k,
                              xs, xnew, g, (norms, i, divergence, trace_row, lt, lv, base, meas,
                                       t0, span), counts)  # fmt: skip
            for l in range(N2):
                x_final[i, l] = x[l]
            status[i] = st
            steps[i] = counts[0]
            nfev[i] = counts[2]
            final = math.nan
            if st != 0:
                fail_step[i] = counts[0]
            else:
                e1[i] = energy(tend, x, p, ws)
                residual(tend, x, p, ws, g)
                final = 0.0
                for l in range(ng):
                    final = max(final, abs(g[l]))
            finish(lt, lv, meas, 0, i, final, st != 0, span / max(counts[0], 1), rt, ry, fa,
                   fb, lg)  # fmt: skip
            if R.shape[0] > 0:
                predict(R, alpha0s[i], int(round(span / h_pred)), h_pred, lt, lv, base, meas,
                        0, i, rt, ry, fa, fb, lg, g_p, gn_p)  # fmt: skip

    keyed_cache(ensemble_kernel, kernel_key(K.key, "adaptive-ensemble-dopri5"))
    return ensemble_kernel
