"""Adaptive steps with an embedded Runge–Kutta pair (Dormand–Prince 5(4) or Hairer's
DOP853, :class:`stabdae._schemes.EmbeddedPair`): the loop of one trajectory
(:func:`adaptive_for`, behind :func:`stabdae.integrate_adaptive`, the loop of
:func:`_adaptive_loop`) and the ensemble kernel (:func:`adaptive_block_for`, behind
``stabdae.ensemble(rtol=...)``), which runs members on lanes side by side with the same
operations per member, so that each member is the single loop's trajectory bit for bit.

Local error control ``err ≤ 1`` per step with the error estimates ``e = τ Σ (b_i − b̂_i) k_i``
scaled by ``atol + rtol·max(|x|, |x̃|)``: ``err`` is their RMS norm for Dormand–Prince, and
``‖e₅‖² / √(‖e₅‖² + 0.01 ‖e₃‖²)`` of the fifth- and third-order estimates for DOP853 (as in
Hairer's code and SciPy's).  The step is updated by ``0.9 err^{−1/(q+1)}`` within
``[0.2, 10]`` (``q`` = 4 and 7: the estimate's order; no growth right after a rejection),
the first step chosen as in Hairer, Nørsett & Wanner (II.4).  Steps end exactly on the
sample times.  The pair's coefficients are run-time arrays: one compiled loop serves both.
"""

from __future__ import annotations

import hashlib
import math

import numpy as np
from numba import njit

from .._status import Status
from .cache import kernel_key, keyed_cache, memo, tag
from .decay import begin, finish, ladders, observe, predict, scratch
from .ensemble import UNROLL_MAX_TERMS
from .rhs import kernels_for
from .steps import sample_writer

__all__ = ["LANES", "adaptive_block_for", "adaptive_for"]

_STEP_TOO_SMALL = int(Status.STEP_TOO_SMALL)
_MAX_STEPS = int(Status.MAX_STEPS)
_DIVERGED = int(Status.DIVERGED)


def adaptive_for(model, bound, multiplier: str = "ldl"):
    """The compiled adaptive loop for ``model`` under the law's kind (memoized)."""
    return memo(model, ("adaptive", bound.code, bound.fn, multiplier),
                lambda: _build_adaptive(kernels_for(model, bound, multiplier)))


@njit(forceinline=True)
def _next_step(t, h, target, taken, max_steps):
    """The next attempted step from ``t`` with step size ``h``: ``(hh, hit, status)``, ``hh``
    cut to end on the sample time ``target`` when it reaches it (``hit``); status
    ``MAX_STEPS`` after ``taken ≥ max_steps`` steps, ``STEP_TOO_SMALL`` for a step below
    roundoff at ``t``."""
    if taken >= max_steps:
        return h, False, _MAX_STEPS
    hh = h
    hit = False
    if t + hh >= target - 1e-12 * abs(target):
        hh = target - t
        hit = True
    if hh <= 1e-14 * max(1.0, abs(t)):
        return hh, hit, _STEP_TOO_SMALL
    return hh, hit, 0


@njit(forceinline=True)
def _combined_norm(s5, s3, hh, N2):
    """DOP853's error norm ‖e₅‖² / √(‖e₅‖² + 0.01 ‖e₃‖²) from the sums of squares of the
    scaled estimates: 0 when both are 0 (a select, not a branch, so that the lanes'
    loop vectorizes; 0 for s5 = 0 and NaN for NaN or inf either way)."""
    den = (s5 + 0.01 * s3) * N2
    return abs(hh) * s5 / math.sqrt(den if den > 0.0 else 1.0)


@njit(forceinline=True)
def _settle(good, e, hh, h, hit, after_reject, expo):
    """The step control after an attempt of size ``hh`` (``h``: the step before a cut to a
    sample time, ``hit``): ``(accepted, next h, after_reject)``.  A failed or non-finite
    attempt shrinks hard; ``e ≤ 1`` accepts and grows by ``0.9 e^{−1/(q+1)}`` within
    ``[0.2, 10]``, not at all right after a rejection; ``e > 1`` shrinks by that factor."""
    if not good:
        return False, 0.25 * hh, True
    if e <= 1.0:
        fac = 10.0 if e == 0.0 else min(10.0, max(0.2, 0.9 * e**-expo))
        if after_reject:
            fac = min(fac, 1.0)
        return True, (hh * fac if not hit else max(h, hh * fac)), False
    return False, hh * max(0.2, 0.9 * e**-expo), True


def _f_eval(rhs):
    """One out-of-line copy of the (inlined) right-hand side, for the places that call it
    once per step or per member: compiling the inlined body once instead of at each of
    them halves the compile time."""

    @njit(error_model="numpy")
    def f_eval(t, x, p, law_mat, law_scal, ws, xdot):
        return rhs(t, x, p, law_mat, law_scal, ws, xdot)

    return f_eval


def _first_step(f_eval, N2: int):
    """``first_step(t, x, k0, k1, xs, p, law_mat, law_scal, ws, rtol, atol, h0, tend, expo)``:
    ``h0`` when positive, otherwise the first step of Hairer, Nørsett & Wanner (II.4), from
    ‖x‖/‖ẋ‖ and then from ‖ẍ‖ (one evaluation, into ``k1``, at ``x + h ẋ`` in ``xs``);
    returns the step and the evaluations it took."""

    @njit(error_model="numpy")
    def first_step(t, x, k0, k1, xs, p, law_mat, law_scal, ws, rtol, atol, h0, tend, expo):
        if h0 > 0.0:
            return h0, 0
        d0 = d1 = 0.0
        for l in range(N2):
            sc = atol + rtol * abs(x[l])
            d0 += (x[l] / sc) ** 2
            d1 += (k0[l] / sc) ** 2
        d0, d1 = math.sqrt(d0 / N2), math.sqrt(d1 / N2)
        h = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
        h = min(h, tend - t)
        for l in range(N2):
            xs[l] = x[l] + h * k0[l]
        st = f_eval(t + h, xs, p, law_mat, law_scal, ws, k1)
        if st == 0:
            d2 = 0.0
            for l in range(N2):
                sc = atol + rtol * abs(x[l])
                d2 += ((k1[l] - k0[l]) / sc) ** 2
            d2 = math.sqrt(d2 / N2) / h
            if max(d1, d2) <= 1e-15:
                h1 = max(1e-6, h * 1e-3)
            else:
                h1 = (0.01 / max(d1, d2)) ** expo
            h = min(100.0 * h, h1)
        return h, 1

    return first_step


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
                # ‖·‖ over (atol + rtol max(|x|, |x_new|)): the RMS of τ Σ e_i k_i, or for
                # DOP853 Hairer's ‖e₅‖² / √(‖e₅‖² + 0.01 ‖e₃‖²) from the two estimates
                s5 = s3 = 0.0
                for l in range(N2):
                    sc = atol + rtol * max(abs(x[l]), abs(xnew[l]))
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

    tag(kernel_key(K.key, f"adaptive-loop-{label}"), f_eval, first_step, run)
    return run


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


# ------------------------------------------------------------------- lanes in lockstep
#: members integrated side by side (lanes) in the block adaptive ensemble kernel
LANES = 8


def adaptive_block_for(model, bound, pair, lanes: int = LANES):
    """The compiled block adaptive ensemble kernel (memoized per law kind, the pair's
    stage counts and norm, the number of lanes, the shape of the law's matrix)."""
    s, s_e = pair.scheme.stages, pair.error.shape[1]
    shape = bound.matrix.shape
    n_params = len(model.param_names)
    pattern = _pattern(pair)
    return memo(model, ("adaptive-block", bound.code, bound.fn, s, s_e, pair.combined, pattern,
                        lanes, shape),
                lambda: _build_adaptive_block(kernels_for(model, bound), s, s_e,
                                              pair.combined, pattern, lanes, n_params,
                                              shape))  # fmt: skip


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
    lines += over_state(["sc[l] = atol + rtol * max(abs(x[l]), abs(xn[l]))"])
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
    from .source import exec_source
    from .workspace import stack1

    ns = exec_source(_attempt_source(s, s_e, combined, pattern, N2),
                     f"adaptive_attempt_{_label(s, s_e, combined, pattern)}",
                     {"rhs": rhs, "stack1": stack1, "N2": N2, "NG": ng, "math": math,
                      "combined_norm": _combined_norm})  # fmt: skip
    return njit(forceinline=True, error_model="numpy")(ns["attempt"])


def _build_adaptive_block(K, s: int, s_e: int, combined: bool, pattern: tuple, B: int,
                          n_params: int, law_shape):  # fmt: skip
    from .workspace import copy_inputs, copy_tableau, stack1, stack2, stack_int1

    rhs, residual, energy = K.rhs, K.residual, K.energy
    make_workspace, stack_workspace = K.make_workspace, K.stack_workspace
    N2, ng = 2 * K.n, K.ng
    NP = max(n_params, 1)
    LR, LC = law_shape
    label = _label(s, s_e, combined, pattern)
    attempt = attempt_for(rhs, s, s_e, combined, pattern, N2, ng)

    f_eval = _f_eval(rhs)
    first_step = _first_step(f_eval, N2)

    @njit(nogil=True, error_model="numpy")
    def block_kernel(x0, alpha0s, t0, save_times, p, law_mat, law_scal, tab_a, tab_b, tab_e,
                     tab_c, q, rtol, atol, h0, max_steps, divergence, R, h_pred, trace_row,
                     norms, meas, x_final, status, fail_step, e0, e1, steps, nfev, lo,
                     hi):  # fmt: skip
        """Members ``lo … hi − 1`` on ``B`` lanes: each lane runs one member with its own
        step size, error norm and accept/reject; the attempted steps of all lanes are one
        loop over the lanes (vectorized), the step-size control, samples and decay
        measurement a scalar pass after it; a lane whose member has finished (or
        stopped) takes the next waiting member.  Outputs as the per-member kernel's."""
        if hi <= lo:
            return
        expo = 1.0 / (q + 1)
        nsave = save_times.shape[0]
        tend = save_times[nsave - 1]
        span = tend - t0
        # the small run-time inputs on the stack (copy_inputs: no aliasing)
        p_s = stack1(NP)
        lm = stack2(LR, LC)
        ls = stack1(1)
        copy_inputs(p, law_mat, law_scal, p_s, lm, ls)
        ta = stack2(s, s)
        tb = stack1(s)
        tc = stack1(s)
        te = stack2(2, s_e)
        copy_tableau(tab_a, tab_b, tab_c, ta, tb, tc)
        for i in range(2):
            for j in range(s_e):
                te[i, j] = tab_e[i, j]
        # per lane: state, first stage, attempt's new state and last stage; time, step
        X = stack2(N2, B)
        K0 = stack2(N2, B)
        XN = stack2(N2, B)
        KL = stack2(N2, B)
        T = stack1(B)
        HH = stack1(B)
        E = stack1(B)
        RN = stack1(B)
        GOOD = stack_int1(B)
        NEV = stack_int1(B)
        H = np.empty(B)
        hit = np.zeros(B, dtype=np.bool_)
        after = np.zeros(B, dtype=np.bool_)
        jj = np.zeros(B, dtype=np.int64)  # the next sample
        mem = np.full(B, -1, dtype=np.int64)  # the lane's member, −1: none
        acc_n = np.zeros(B, dtype=np.int64)
        rej_n = np.zeros(B, dtype=np.int64)
        fev_n = np.zeros(B, dtype=np.int64)
        ws_h = make_workspace()
        x_h = np.empty(N2)
        k0_h = np.empty(N2)
        k1_h = np.empty(N2)
        xs_h = np.empty(N2)
        g_h = np.empty(ng)
        lt, lv, base = ladders(B)
        rt, ry, fa, fb, lg = scratch()
        g_p = np.empty(alpha0s.shape[1])
        gn_p = np.empty(alpha0s.shape[1])
        nxt = lo
        alive = 0
        for lane in range(B):
            for l in range(N2):
                X[l, lane] = 0.0
                K0[l, lane] = 0.0
            T[lane] = t0
            HH[lane] = 0.0
        while True:
            # ---- scalar pass: settle each lane's attempt, then fill empty lanes
            for lane in range(B):
                i = mem[lane]
                st = 0
                if i >= 0 and HH[lane] > 0.0:  # an attempt was made
                    fev_n[lane] += NEV[lane]
                    hh = HH[lane]
                    ok, H[lane], after[lane] = _settle(GOOD[lane] != 0, E[lane], hh, H[lane],
                                                       hit[lane], after[lane], expo)
                    if ok:
                        acc_n[lane] += 1
                        t = save_times[jj[lane]] if hit[lane] else T[lane] + hh
                        T[lane] = t
                        for l in range(N2):
                            X[l, lane] = XN[l, lane]
                            K0[l, lane] = KL[l, lane]
                        window = min(4, int(5.0 * (t - t0) / span))
                        observe(lt, lv, base, meas, lane, i, t - t0, RN[lane], RN[lane],
                                window)  # fmt: skip
                        if hit[lane]:
                            jj[lane] += 1
                            for l in range(N2):
                                x_h[l] = X[l, lane]
                            residual(t, x_h, p, ws_h, g_h)
                            r = 0.0
                            for l in range(ng):
                                r = max(r, abs(g_h[l]))
                            if not math.isfinite(r):
                                r = math.inf
                            if trace_row[i] >= 0:
                                norms[trace_row[i], jj[lane]] = r
                            if not (r <= divergence):
                                st = _DIVERGED
                            elif jj[lane] == nsave:
                                st = -1  # done
                    else:
                        rej_n[lane] += 1
                if i >= 0 and st == 0:  # the next attempt: its step, or a stop
                    HH[lane], hit[lane], st = _next_step(T[lane], H[lane],
                                                         save_times[jj[lane]],
                                                         acc_n[lane] + rej_n[lane],
                                                         max_steps)  # fmt: skip
                if i >= 0 and st != 0:  # the member's end: its outputs
                    st = 0 if st == -1 else st
                    for l in range(N2):
                        x_h[l] = X[l, lane]
                        x_final[i, l] = x_h[l]
                    status[i] = st
                    steps[i] = acc_n[lane]
                    nfev[i] = fev_n[lane]
                    final = math.nan
                    if st != 0:
                        fail_step[i] = acc_n[lane]
                    else:
                        e1[i] = energy(tend, x_h, p, ws_h)
                        residual(tend, x_h, p, ws_h, g_h)
                        final = 0.0
                        for l in range(ng):
                            final = max(final, abs(g_h[l]))
                    finish(lt, lv, meas, lane, i, final, st != 0,
                           span / max(acc_n[lane], 1), rt, ry, fa, fb, lg)  # fmt: skip
                    if R.shape[0] > 0:
                        predict(R, alpha0s[i], int(round(span / h_pred)), h_pred, lt, lv,
                                base, meas, lane, i, rt, ry, fa, fb, lg, g_p,
                                gn_p)  # fmt: skip
                    mem[lane] = -1
                    alive -= 1
                while mem[lane] < 0 and nxt < hi:  # the next waiting member
                    i = nxt
                    nxt += 1
                    for l in range(N2):
                        x_h[l] = x0[i, l]
                    if trace_row[i] >= 0:
                        for c in range(norms.shape[1]):
                            norms[trace_row[i], c] = math.nan
                    if status[i] != 0:  # not placed: keep it out
                        for l in range(N2):
                            x_final[i, l] = x_h[l]
                        begin(lt, lv, base, meas, lane, i, math.nan, math.nan)
                        finish(lt, lv, meas, lane, i, math.nan, True, 1.0, rt, ry, fa, fb, lg)
                        continue
                    e0[i] = energy(t0, x_h, p, ws_h)
                    residual(t0, x_h, p, ws_h, g_h)
                    r0 = 0.0
                    for l in range(ng):
                        r0 = max(r0, abs(g_h[l]))
                    begin(lt, lv, base, meas, lane, i, r0, r0)
                    acc_n[lane] = rej_n[lane] = fev_n[lane] = 0
                    # sample 0 (as the single loop's save: ‖g‖ at t0, checked)
                    r = r0 if math.isfinite(r0) else math.inf
                    if trace_row[i] >= 0:
                        norms[trace_row[i], 0] = r
                    st = 0 if r <= divergence else _DIVERGED
                    if st == 0:
                        st = f_eval(t0, x_h, p, law_mat, law_scal, ws_h, k0_h)
                        fev_n[lane] = 1
                    h = h0
                    if st == 0:
                        h, nf = first_step(t0, x_h, k0_h, k1_h, xs_h, p, law_mat, law_scal,
                                           ws_h, rtol, atol, h0, tend, expo)  # fmt: skip
                        fev_n[lane] += nf
                        hh, hit[lane], st = _next_step(t0, h, save_times[0], 0, max_steps)
                    if st != 0:
                        for l in range(N2):
                            x_final[i, l] = x_h[l]
                        status[i] = st
                        steps[i] = 0
                        nfev[i] = fev_n[lane]
                        fail_step[i] = 0
                        finish(lt, lv, meas, lane, i, math.nan, True, span, rt, ry, fa, fb,
                               lg)  # fmt: skip
                        if R.shape[0] > 0:
                            predict(R, alpha0s[i], int(round(span / h_pred)), h_pred, lt,
                                    lv, base, meas, lane, i, rt, ry, fa, fb, lg, g_p,
                                    gn_p)  # fmt: skip
                        continue
                    mem[lane] = i
                    alive += 1
                    jj[lane] = 0
                    after[lane] = False
                    H[lane] = h
                    HH[lane] = hh
                    T[lane] = t0
                    for l in range(N2):
                        X[l, lane] = x_h[l]
                        K0[l, lane] = k0_h[l]
            if alive == 0:
                break
            # an idle lane repeats a running one (numbers nobody reads, none failing)
            src = 0
            while mem[src] < 0:
                src += 1
            for lane in range(B):
                if mem[lane] < 0:
                    T[lane] = T[src]
                    HH[lane] = HH[src]
                    for l in range(N2):
                        X[l, lane] = X[l, src]
                        K0[l, lane] = K0[l, src]
            # ---- vector pass: every lane's attempted step
            for lane in range(B):
                ws = stack_workspace()
                x = stack1(N2)
                k0 = stack1(N2)
                xs = stack1(N2)
                xn = stack1(N2)
                kl = stack1(N2)
                for l in range(N2):
                    x[l] = X[l, lane]
                    k0[l] = K0[l, lane]
                good, nev, e, r = attempt(T[lane], HH[lane], x, k0, p_s, lm, ls, ta, tb, te,
                                          tc, rtol, atol, ws, xs, xn, kl)  # fmt: skip
                for l in range(N2):
                    XN[l, lane] = xn[l]
                    KL[l, lane] = kl[l]
                GOOD[lane] = good
                NEV[lane] = nev
                E[lane] = e
                RN[lane] = r

    tag(kernel_key(K.key, f"adaptive-block-{label}-{B}"), attempt, f_eval, first_step)
    keyed_cache(block_kernel, kernel_key(K.key, f"adaptive-block-{label}-{B}-{NP}-{LR}x{LC}"))
    return block_kernel
