"""The adaptive ensemble kernel (:func:`adaptive_block_for`, behind
``stabdae.ensemble(rtol=...)``): members run on ``LANES`` lanes side by side, each with its
own step size, with the same operations per member as the loop of one trajectory
(:mod:`stabdae.engine.rk.adaptive`, whose generated attempted step it runs), so that each
member is that loop's trajectory bit for bit.  A lane whose member ends takes the next
member of its block.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..cache import Spec, keyed_cache, memo, tag
from ..decay import (
    LOW_MARGIN,
    MAP_BINS,
    MAP_SHIFT,
    begin,
    finish,
    finish_with_map,
    generator_add,
    generator_store,
    generator_width,
    ladder_level,
    ladders,
    observe,
    predict,
    reference_logs,
    scratch,
    spectral_radius_of,
)
from ..rhs import kernels_for
from ..rk.adaptive import _pattern, attempt_for
from ..rk.control import _DIVERGED, _f_eval, _first_step, _next_step, _settle
from .block import pooled_constraints


# ------------------------------------------------------------------- samples
@njit(cache=True)
def _max_norm(g, ng):
    """``‖g‖∞`` of a sample, ``inf`` where it is not finite (so that it fails every test
    against the divergence threshold)."""
    r = 0.0
    for l in range(ng):
        r = max(r, abs(g[l]))
    return r if math.isfinite(r) else math.inf


@njit(cache=True)
def _hermite(x0, f0, x1, f1, h, theta, out):
    """The cubic Hermite interpolant at ``t0 + θ h`` of an accepted step from ``x0`` (with
    ``ẋ = f0``) to ``x1`` (``f1``), in ``out``.

    The ensemble's steps are not cut to the sample times, so that the steps taken, and
    with them the residual's floor and every measure of the decay, do not depend on
    ``save_dt``; a stored sample is the residual of this dense output of the state.  Its
    error is ``O(h⁴)``, and between steps it can lie above the residual's floor: the
    decay is measured on the accepted steps only, never on the samples."""
    for l in range(x0.shape[0]):
        d = x1[l] - x0[l]
        out[l] = (x0[l] + theta * d
                  + theta * (theta - 1.0) * ((1.0 - 2.0 * theta) * d
                                             + (theta - 1.0) * h * f0[l]
                                             + theta * h * f1[l]))  # fmt: skip


@njit(cache=True)
def _deviation(G, lane, g_ref, kp, t):
    """Lane ``lane``'s residual ``G[:, lane]`` at time ``t`` made its distance from the
    reference trajectory's, ``g − g_ref(t)``, linear in ``t`` between the rows ``(t, g)``
    of ``g_ref`` around ``t`` (``kp[lane]``: the row at or before the lane's last time,
    advanced here; the members' times only increase); returns ``‖g − g_ref(t)‖∞``
    (``inf`` where it is not finite).

    The reference trajectory's residual is its integrator's local errors, forced through
    the law: a floor that moves with the motion and that a member's steps reproduce while
    the motion sets them.  Linear between the reference's steps, it is a smooth function
    of time read to well within its own size (a member near its floor and the reference
    take nearly the same steps)."""
    nr = g_ref.shape[0]
    k = kp[lane]
    while k + 2 < nr and g_ref[k + 1, 0] <= t:
        k += 1
    kp[lane] = k
    w = 0.0
    if k + 1 < nr and g_ref[k + 1, 0] > g_ref[k, 0]:
        w = min(1.0, max(0.0, (t - g_ref[k, 0]) / (g_ref[k + 1, 0] - g_ref[k, 0])))
    k1 = min(k + 1, nr - 1)
    d = 0.0
    for l in range(G.shape[0]):
        a = g_ref[k, 1 + l]
        G[l, lane] -= a + w * (g_ref[k1, 1 + l] - a)
        d = max(d, abs(G[l, lane]))
    return d if math.isfinite(d) else math.inf


@njit(cache=True)
def _record(g_out, row, t, G, lane):
    """Row ``row`` of ``g_out`` (while it has one): ``(t, G[:, lane])``."""
    if row < g_out.shape[0]:
        g_out[row, 0] = t
        for l in range(G.shape[0]):
            g_out[row, 1 + l] = G[l, lane]


# ------------------------------------------------------------------- lanes in lockstep
#: members integrated side by side (lanes) in the block adaptive ensemble kernel
LANES = 8


#: Every buffer of the lanes kernel, declared once (as :data:`.block.BUFFERS`; ``s`` and
#: ``s_e`` the pair's stage counts); a test checks the kernel allocates exactly these.
BUFFERS = {
    "p_s": ("stack1(NP)", "the parameters"),
    "lm": ("stack2(LR, LC)", "the law's matrix"),
    "ls": ("stack1(1)", "the law's scalar"),
    "at": ("stack1(N2)", "atol, one per state component"),
    "ta": ("stack2(s, s)", "the pair's A"),
    "tb": ("stack1(s)", "the pair's b"),
    "tc": ("stack1(s)", "the pair's c"),
    "te": ("stack2(2, s_e)", "the error estimate's weights"),
    # per lane
    "X": ("stack2(N2, B)", "the state"),
    "K0": ("stack2(N2, B)", "the first stage (FSAL: the last accepted step's last)"),
    "XN": ("stack2(N2, B)", "the attempt's new state"),
    "KL": ("stack2(N2, B)", "... and its last stage"),
    "T": ("stack1(B)", "the time"),
    "HH": ("stack1(B)", "the attempted step (0: none yet)"),
    "E": ("stack1(B)", "the attempt's error norm"),
    "RN": ("stack1(B)", "the attempt's ‖g‖ at the new state"),
    "GN": ("stack2(ng, B)", "... and g itself"),
    "GOOD": ("stack_int1(B)", "whether the attempt's right-hand sides succeeded"),
    "NEV": ("stack_int1(B)", "the attempt's evaluations"),
    "H": ("np.empty(B)", "the next step the control proposes"),
    "hit": ("np.zeros(B, dtype=np.bool_)", "the attempt ends on t_end"),
    "after": ("np.zeros(B, dtype=np.bool_)", "the last step was rejected (no growth)"),
    "jj": ("np.zeros(B, dtype=np.int64)", "the next sample"),
    "mem": ("np.full(B, -1, dtype=np.int64)", "the lane's member (−1: none)"),
    "acc_n": ("np.zeros(B, dtype=np.int64)", "accepted steps"),
    "rej_n": ("np.zeros(B, dtype=np.int64)", "rejected steps"),
    "fev_n": ("np.zeros(B, dtype=np.int64)", "right-hand-side evaluations"),
    # one member at a time, in the scalar pass
    "ws_h": ("make_workspace()", "the right-hand side's workspace"),
    "x_h": ("np.empty(N2)", "a member's state"),
    "k0_h": ("np.empty(N2)", "its first stage"),
    "k1_h": ("np.empty(N2)", "the first step's trial stage; ẋ at a step's end"),
    "xs_h": ("np.empty(N2)", "the first step's trial state; a sample's state"),
    "g_h": ("np.empty(ng)", "a member's residual"),
    "x_o": ("np.empty(N2)", "the state at the start of a step with samples inside"),
    "k_o": ("np.empty(N2)", "... and its ẋ"),
    "lt, lv, base": ("ladders(B)", "each lane's ladder"),
    "rt, ry, fa, fb, lg": ("scratch()", "the fits' scratch"),
    "G0": ("np.empty((B, ng))", "each lane's g − g_ref at its last accepted state"),
    "kp": ("np.zeros(B, dtype=np.int64)", "each lane's row of the reference's steps"),
    "dp": ("np.zeros(B)", "each lane's distance at its last accepted state"),
    "Ag": ("np.zeros((B, GW))", "each lane's running sums of its generator's pairs"),
    "S_g": ("np.zeros((B, MAP_BINS, GW))", "... per bin (as the one-step map's)"),
    "low": ("np.zeros(B, dtype=np.int64)", "the lowest bin reached"),
    "ref": ("reference_logs(R)", "the law's distinct ln |eigenvalue| of e^{h Ã}"),
    "g_p": ("np.empty(alpha0s.shape[1])", "the linear prediction's g"),
    "gn_p": ("np.empty(alpha0s.shape[1])", "... and its next g"),
    # inside the lane loop: per lane, on the stack
    "ws": ("stack_workspace()", "the attempt's workspace"),
    "x": ("stack1(N2)", "the lane's state"),
    "k0": ("stack1(N2)", "its first stage"),
    "xs": ("stack1(N2)", "a stage's state"),
    "xn": ("stack1(N2)", "the attempt's new state"),
    "kl": ("stack1(N2)", "... and its last stage"),
}


def adaptive_block_for(model, bound, pair, lanes: int = LANES):
    """The compiled block adaptive ensemble kernel (memoized per law kind, the pair's
    stage counts and norm, the number of lanes, the shape of the law's matrix)."""
    spec = Spec("lanes", law=bound.code, law_fn=bound.fn, pattern=_pattern(pair),
                stages=(pair.scheme.stages, pair.error.shape[1]), combined=pair.combined,
                block=lanes, n_params=len(model.param_names), law_shape=bound.matrix.shape,
                pooled=pooled_constraints(model, bound.law))  # fmt: skip
    return memo(model, spec, lambda: _build_adaptive_block(kernels_for(model, bound), spec))


def _build_adaptive_block(K, spec: Spec):
    from ..workspace import copy_inputs, copy_tableau, stack1, stack2, stack_int1

    rhs, residual, energy = K.rhs, K.residual, K.energy
    make_workspace, stack_workspace = K.make_workspace, K.stack_workspace
    N2, ng = 2 * K.n, K.ng
    (s, s_e), combined, pattern, B = spec.stages, spec.combined, spec.pattern, spec.block
    NP = max(spec.n_params, 1)
    LR, LC = spec.law_shape
    PM = spec.pooled
    GW = generator_width(ng, PM)
    attempt = attempt_for(rhs, s, s_e, combined, pattern, N2, ng)

    f_eval = _f_eval(rhs)
    first_step = _first_step(f_eval, N2)

    @njit(nogil=True, error_model="numpy")
    def block_kernel(inputs, grid, tableau, measure, out, lo, hi):
        """Members ``lo … hi − 1`` of ``inputs`` (:mod:`.groups`) on ``B`` lanes: each
        lane runs one member with its own step size, error norm and accept/reject; the
        attempted steps of all lanes are one loop over the lanes (vectorized), the
        step-size control, samples and decay measurement a scalar pass after it; a lane
        whose member has finished (or stopped) takes the next waiting member.  Outputs as
        the block kernel's (:mod:`.block`), with ``out.steps`` and ``out.nfev``."""
        x0, alpha0s, p, law_mat, law_scal = inputs
        t0, save_times, h0, rtol, atol, max_steps = grid
        tab_a, tab_b, tab_e, tab_c, q = tableau
        divergence, R, h_pred, trace_row, g_ref, noise = measure
        NR = g_ref.shape[0]
        # the least floor of the distance from the reference, whose steps' local errors
        # differ from a member's by a share of their own size that a member's last fifth
        # need not show: a hundredth of the reference's largest residual (the generator's
        # last margin then cuts at a tenth of it).  With the last fifth alone, a member
        # that started below the reference's floor read half the rate (dopri5, rtol 1e-6)
        floor_min = 0.0
        for k in range(NR):
            for l in range(1, g_ref.shape[1]):
                floor_min = max(floor_min, abs(g_ref[k, l]) / (10.0 * LOW_MARGIN))
        # no window is cut below this (the generator's last margin over floor_min): a
        # pair wholly below it is never read (its bins are filled before it, and a run
        # that ended still decaying fits the pairs above it), and is not summed
        cut_min = LOW_MARGIN * floor_min
        rec = out.g_out.shape[0] > 0  # the first member's (t, g) at every accepted step
        norms, meas, mcodes, x_final = out.norms, out.meas, out.codes, out.x_final
        status, fail_step, e0, e1 = out.status, out.fail_step, out.e0, out.e1
        steps, nfev = out.steps, out.nfev
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
        at = stack1(N2)  # atol per component, on the stack for the same reason
        for l in range(N2):
            at[l] = atol[l]
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
        GN = stack2(ng, B)
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
        x_o = np.empty(N2)
        k_o = np.empty(N2)
        lt, lv, base = ladders(B)
        rt, ry, fa, fb, lg = scratch()
        G0 = np.empty((B, ng))
        kp = np.zeros(B, dtype=np.int64)
        dp = np.zeros(B)
        Ag = np.zeros((B, GW))
        S_g = np.zeros((B, MAP_BINS, GW))
        low = np.zeros(B, dtype=np.int64)
        ref = reference_logs(R)
        rho_R = spectral_radius_of(R) if R.shape[0] > 0 else math.nan
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
                        t_old = T[lane]
                        t = tend if hit[lane] else t_old + hh
                        inside = jj[lane] < nsave - 1 and save_times[jj[lane]] <= t
                        if inside:  # samples inside the step: keep its start
                            for l in range(N2):
                                x_o[l] = X[l, lane]
                                k_o[l] = K0[l, lane]
                        T[lane] = t
                        for l in range(N2):
                            X[l, lane] = XN[l, lane]
                            K0[l, lane] = KL[l, lane]
                        window = min(4, int(5.0 * (t - t0) / span))
                        if rec and i == lo:
                            _record(out.g_out, acc_n[lane], t, GN, lane)
                        d = _deviation(GN, lane, g_ref, kp, t) if NR > 0 else RN[lane]
                        observe(lt, lv, base, meas, lane, i, t - t0, RN[lane], d, window)
                        if d < math.inf:  # the generator's pair, binned by when
                            if d >= cut_min or dp[lane] >= cut_min:
                                generator_add(Ag, lane, G0, GN, hh, PM)
                            else:  # below every window: the state carried, no sums
                                for l in range(ng):
                                    G0[lane, l] = GN[l, lane]
                            dp[lane] = d
                            nb = ladder_level(d, base[lane]) >> MAP_SHIFT
                            if nb < low[lane]:
                                generator_store(S_g, Ag, lane, nb + 1, low[lane])
                                low[lane] = nb
                        if inside:  # ... its end
                            for l in range(N2):
                                x_h[l] = X[l, lane]
                                k1_h[l] = K0[l, lane]
                        while inside and jj[lane] < nsave - 1 and save_times[jj[lane]] <= t:
                            ts = save_times[jj[lane]]
                            _hermite(x_o, k_o, x_h, k1_h, hh, (ts - t_old) / hh, xs_h)
                            residual(ts, xs_h, p, ws_h, g_h)
                            r = _max_norm(g_h, ng)
                            jj[lane] += 1
                            if trace_row[i] >= 0:
                                norms[trace_row[i], jj[lane]] = r
                            if not (r <= divergence):
                                st = _DIVERGED
                                break
                        if hit[lane] and st == 0:
                            jj[lane] += 1
                            for l in range(N2):
                                x_h[l] = X[l, lane]
                            residual(t, x_h, p, ws_h, g_h)
                            r = _max_norm(g_h, ng)
                            if trace_row[i] >= 0:
                                norms[trace_row[i], jj[lane]] = r
                            if not (r <= divergence):
                                st = _DIVERGED
                            elif jj[lane] == nsave:
                                st = -1  # done
                    else:
                        rej_n[lane] += 1
                if i >= 0 and st == 0:  # the next attempt: its step, or a stop
                    HH[lane], hit[lane], st = _next_step(T[lane], H[lane], tend,
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
                    generator_store(S_g, Ag, lane, 0, low[lane])
                    finish_with_map(lt, lv, S_g, meas, mcodes, lane, i, final, st != 0, ng, PM,
                                    base[lane], 0, span / max(acc_n[lane], 1), rt, ry, fa,
                                    fb, lg, ref, h_pred, floor_min, NR == 0, 0, noise)  # fmt: skip
                    if R.shape[0] > 0:
                        predict(R, alpha0s, i, int(round(span / h_pred)), h_pred, lt, lv,
                                base, meas, mcodes, lane, i, rt, ry, fa, fb, lg, g_p,
                                gn_p, rho_R)  # fmt: skip
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
                        begin(lt, lv, base, meas, mcodes, lane, i, math.nan, math.nan)
                        finish(lt, lv, meas, mcodes, lane, i, math.nan, True, 1.0, rt, ry, fa,
                               fb, lg)  # fmt: skip
                        continue
                    e0[i] = energy(t0, x_h, p, ws_h)
                    residual(t0, x_h, p, ws_h, g_h)
                    r0 = 0.0
                    for l in range(ng):
                        r0 = max(r0, abs(g_h[l]))
                    d0 = 0.0
                    kp[lane] = 0
                    for l in range(ng):
                        if rec and i == lo:
                            out.g_out[0, 1 + l] = g_h[l]
                        G0[lane, l] = g_h[l] - (g_ref[0, 1 + l] if NR > 0 else 0.0)
                        d0 = max(d0, abs(G0[lane, l]))
                    if rec and i == lo:
                        out.g_out[0, 0] = t0
                    begin(lt, lv, base, meas, mcodes, lane, i, r0, d0)
                    dp[lane] = d0
                    for c in range(GW):
                        Ag[lane, c] = 0.0
                    low[lane] = ladder_level(d0, base[lane]) >> MAP_SHIFT
                    # the bins at and below the start are all written before they are
                    # read (as the level falls past them, or at the end); those above it
                    # never are: cleared
                    for b_ in range(low[lane] + 1, MAP_BINS):
                        for c in range(GW):
                            S_g[lane, b_, c] = 0.0
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
                                           ws_h, rtol, at, h0, tend, expo)  # fmt: skip
                        fev_n[lane] += nf
                        hh, hit[lane], st = _next_step(t0, h, tend, 0, max_steps)
                    if st != 0:
                        for l in range(N2):
                            x_final[i, l] = x_h[l]
                        status[i] = st
                        steps[i] = 0
                        nfev[i] = fev_n[lane]
                        fail_step[i] = 0
                        finish(lt, lv, meas, mcodes, lane, i, math.nan, True, span, rt, ry, fa, fb,
                               lg)  # fmt: skip
                        if R.shape[0] > 0:
                            predict(R, alpha0s, i, int(round(span / h_pred)), h_pred, lt,
                                    lv, base, meas, mcodes, lane, i, rt, ry, fa, fb, lg, g_p,
                                    gn_p, rho_R)  # fmt: skip
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
                                          tc, rtol, at, ws, xs, xn, kl)  # fmt: skip
                for l in range(N2):
                    XN[l, lane] = xn[l]
                    KL[l, lane] = kl[l]
                GOOD[lane] = good
                NEV[lane] = nev
                E[lane] = e
                RN[lane] = r
                for l in range(ng):
                    GN[l, lane] = ws.g[l]

    key = spec.key(K.key)
    tag(key, attempt, f_eval, first_step)
    keyed_cache(block_kernel, key)
    return block_kernel
