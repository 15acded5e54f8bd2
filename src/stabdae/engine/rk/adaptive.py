"""Adaptive steps with an embedded Runge–Kutta pair (Dormand–Prince 5(4) or Hairer's
DOP853, :class:`stabdae._schemes.EmbeddedPair`) for one trajectory, and the attempted step
twice, side by side: looped (:func:`_adaptive_loop`, behind :func:`adaptive_for` and
:func:`stabdae.integrate_adaptive`) and generated (:func:`attempt_for`: its loops over the
state written out per component, for the lanes of the adaptive ensemble,
:mod:`stabdae.engine.ensemble.lanes`).  Both make the same operations per member, so that
each member of an adaptive ensemble is the single loop's trajectory bit for bit.

The step-size control is :mod:`stabdae.engine.rk.control`'s.  The pair's coefficients are
run-time arrays: one compiled loop serves both pairs.
"""

from __future__ import annotations

import hashlib
import math

import numpy as np
from numba import njit

from ..cache import Spec, fingerprint, keyed_cache, memo, tag
from ..rhs import kernels_for
from .control import _DIVERGED, _combined_norm, _f_eval, _first_step, _next_step, _settle
from .steps import UNROLL_MAX_TERMS, sample_writer

__all__ = ["adaptive_for", "attempt_for"]


def adaptive_for(model, bound, multiplier: str = "ldl"):
    """The compiled adaptive loop for ``model`` under the law's kind (memoized)."""
    spec = Spec("adaptive", law=bound.code, law_fn=bound.fn, multiplier=multiplier)
    return memo(model, spec, lambda: _build_adaptive(kernels_for(model, bound, multiplier), spec))


def _adaptive_loop(K, save, label: str):
    """The adaptive loop of one trajectory, with ``save(j, t, x, p, ws, g, out)``
    storing sample ``j`` (it returns True to stop the trajectory: status DIVERGED).

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

    f_eval = _f_eval(rhs)
    first_step = _first_step(f_eval, N2)

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
        h, nf = first_step(t, x, k[0], k[1], xs, p, law_mat, law_scal, ws, rtol, atol, h0,
                           save_times[save_times.shape[0] - 1], expo)  # fmt: skip
        nfev += nf
        accepted = rejected = 0
        j = 0
        nsave = save_times.shape[0]
        after_reject = False
        while j < nsave:
            target = save_times[j]
            hh, hit, st = _next_step(t, h, target, accepted + rejected, max_steps)
            if st != 0:
                counts[0], counts[1], counts[2] = accepted, rejected, nfev
                return st, j + 1
            # stages 1 … s−1 (stage 0 is ẋ at (t, x): first same as last)
            st = 0
            for i in range(1, s):
                for l in range(N2):
                    acc = 0.0
                    for m_ in range(i):
                        if tab_a[i, m_] != 0.0:  # zeros skipped, as the lanes skip them
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
                        if tab_b[i] != 0.0:
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
                # ‖·‖ over (atol_l + rtol max(|x_l|, |x_new,l|)): the RMS of τ Σ e_i k_i, or for
                # DOP853 Hairer's ‖e₅‖² / √(‖e₅‖² + 0.01 ‖e₃‖²) from the two estimates
                s5 = s3 = 0.0
                for l in range(N2):
                    sc = atol[l] + rtol * max(abs(x[l]), abs(xnew[l]))
                    acc5 = 0.0
                    for i in range(s_e):
                        if tab_e[0, i] != 0.0:
                            acc5 += tab_e[0, i] * k[i, l]
                    if combined:
                        acc3 = 0.0
                        for i in range(s_e):
                            if tab_e[1, i] != 0.0:
                                acc3 += tab_e[1, i] * k[i, l]
                        e5, e3 = acc5 / sc, acc3 / sc
                        s5 += e5 * e5
                        s3 += e3 * e3
                    else:
                        e5 = hh * acc5 / sc
                        s5 += e5 * e5
                e = _combined_norm(s5, s3, hh, N2) if combined else math.sqrt(s5 / N2)
                finite = math.isfinite(e)
            # (a failed evaluation or overflow: shrink hard and retry)
            ok, h, after_reject = _settle(finite, e, hh, h, hit, after_reject, expo)
            if ok:
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
                if hit:
                    j += 1
                    if save(j, t, x, p, ws, g, out):
                        counts[0], counts[1], counts[2] = accepted, rejected, nfev
                        return _DIVERGED, j + 1
            else:
                rejected += 1
        counts[0], counts[1], counts[2] = accepted, rejected, nfev
        return 0, nsave + 1

    # (the loop is part of other kernels: its names need only differ per model and label)
    tag(K.key and fingerprint(K.key, "adaptive-loop", label), f_eval, first_step, run)
    return run


def _build_adaptive(K, spec: Spec):
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

    keyed_cache(adaptive_kernel, spec.key(K.key))
    return adaptive_kernel


def _pattern(pair) -> tuple:
    """Which coefficients of a pair are not zero: (A's rows, b, the error weights' rows)."""
    nz = lambda a: tuple(bool(v != 0.0) for v in a)  # noqa: E731
    return (tuple(nz(row) for row in pair.scheme.A), nz(pair.scheme.b),
            tuple(nz(row) for row in pair.error))  # fmt: skip


def _attempt_source(s: int, s_e: int, combined: bool, pattern: tuple, n2: int) -> str:
    """Python source of one lane's attempted step of an embedded pair with ``s`` stages
    and error weights over ``s_e`` stages (``s + 1``: ẋ at the new state evaluated too),
    the stages written out (no inner loop around the inlined right-hand sides, so the lane
    loop around it vectorizes).  The sums run over the coefficients that are not zero
    (``pattern``, :func:`_pattern`), in the order of :func:`_adaptive_loop`'s loops, which
    skip the same zeros, so that each lane's numbers are those of the single-trajectory
    loop bit for bit.  (With DOP853's zeros in, LLVM left the lane loop scalar.)  The loops
    over the state's ``n2`` components are written out too while ``n2`` times the stages
    is at most ``UNROLL_MAX_TERMS``, as in the fixed-step kernel (Andrews' 14 components
    with DOP853: LLVM did not unroll the loops, and the lane loop ran scalar), in the same
    order.  Every stage is evaluated (lanes do not branch);
    ``nev`` counts those the single loop evaluates (up to the first failing one).
    Returns ``(good, nev, err, r)``: all evaluations succeeded and the new state and the
    error norm are finite; the error norm; ``‖g‖∞`` at the last evaluation (the new
    state)."""
    a_nz, b_nz, e_nz = pattern
    unrolled = n2 * s_e <= UNROLL_MAX_TERMS

    def over_state(body):  # a loop over l, or its body once per component
        if not unrolled:
            return ["    for l in range(N2):"] + [f"        {line}" for line in body]
        return [f"    {line.replace('[l]', f'[{c}]')}" for c in range(n2) for line in body]

    lines = ["def attempt(t, hh, x, k0, p, law_mat, law_scal, tab_a, tab_b, tab_e, tab_c, rtol,",
             "            atol, ws, xs, xn, kl):"]
    lines += [f"    k{i} = stack1(N2)" for i in range(1, s_e)]
    lines += ["    ok = True", "    nev = 0"]
    for i in range(1, s):
        lines += over_state(["acc = 0.0"]
                            + [f"acc += tab_a[{i}, {m}] * k{m}[l]" for m in range(i)
                               if a_nz[i][m]]
                            + ["xs[l] = x[l] + hh * acc"])  # fmt: skip
        lines += [f"    c = rhs(t + tab_c[{i}] * hh, xs, p, law_mat, law_scal, ws, k{i})",
                  "    nev += ok", "    ok &= c == 0"]  # fmt: skip
    lines += ["    fin = True"]
    lines += over_state(["acc = 0.0"]
                        + [f"acc += tab_b[{i}] * k{i}[l]" for i in range(s) if b_nz[i]]
                        + ["xn[l] = x[l] + hh * acc", "fin &= math.isfinite(xn[l])"])
    if s_e > s:
        lines += [f"    c = rhs(t + hh, xn, p, law_mat, law_scal, ws, k{s})",
                  "    nev += ok & fin", "    ok &= c == 0"]  # fmt: skip
    # the scale, then each estimate in a loop of its own: one loop over l with both
    # estimates in it is too large for LLVM to unroll at n = 4 (the double pendulum), and
    # the lane loop around a loop left rolled stays scalar.  Each sum still runs over l
    # in order, as the single loop's.
    lines += ["    sc = stack1(N2)"]
    lines += over_state(["sc[l] = atol[l] + rtol * max(abs(x[l]), abs(xn[l]))"])
    lines += ["    s5 = 0.0"]
    est5 = ["acc5 = 0.0"] + [f"acc5 += tab_e[0, {i}] * k{i}[l]" for i in range(s_e)
                             if e_nz[0][i]]  # fmt: skip
    if combined:
        lines += over_state(est5 + ["e5 = acc5 / sc[l]", "s5 += e5 * e5"])
        lines += ["    s3 = 0.0"]
        lines += over_state(["acc3 = 0.0"]
                            + [f"acc3 += tab_e[1, {i}] * k{i}[l]" for i in range(s_e)
                               if e_nz[1][i]]
                            + ["e3 = acc3 / sc[l]", "s3 += e3 * e3"])  # fmt: skip
        lines += ["    e = combined_norm(s5, s3, hh, N2)"]
    else:
        lines += over_state(est5 + ["e5 = hh * acc5 / sc[l]", "s5 += e5 * e5"])
        lines += ["    e = math.sqrt(s5 / N2)"]
    lines += over_state([f"kl[l] = k{s_e - 1}[l]"])
    lines += ["    r = 0.0", "    for l in range(NG):", "        r = max(r, abs(ws.g[l]))",
              "    return ok & fin & math.isfinite(e), nev, e, r"]  # fmt: skip
    return "\n".join(lines) + "\n"


def _label(s, s_e, combined, pattern) -> str:
    return f"{s}-{s_e}-{int(combined)}-{hashlib.sha1(repr(pattern).encode()).hexdigest()[:10]}"


def attempt_for(rhs, s: int, s_e: int, combined: bool, pattern: tuple, N2: int, ng: int):
    """The compiled attempt of :func:`_attempt_source` on the right-hand side ``rhs`` of
    a model with ``N2`` state components and ``ng`` residual components (marked
    ``alwaysinline``: the block kernel's lane loop inlines it)."""
    from ..source import exec_source
    from ..workspace import stack1

    ns = exec_source(_attempt_source(s, s_e, combined, pattern, N2),
                     f"adaptive_attempt_{_label(s, s_e, combined, pattern)}",
                     {"rhs": rhs, "stack1": stack1, "N2": N2, "NG": ng, "math": math,
                      "combined_norm": _combined_norm})  # fmt: skip
    return njit(forceinline=True, error_model="numpy")(ns["attempt"])
