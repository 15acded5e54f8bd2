"""The ensemble kernel: blocks of members in lockstep, structure of arrays, member innermost.

Each work item (a block; ranges of blocks run on threads, :mod:`stabdae.engine.threads`)
holds a block of ``BLOCK`` members as arrays ``X[state, member]`` on the stack.  A step of
the block takes one of two forms, the same operations in the same order:

* for a scheme of ``STAGE_LOOP_MIN_STAGES`` stages or more on a model of
  ``STAGE_LOOP_MIN_N`` coordinates or more (of two stages, where the right-hand side's
  code is also ``STAGE_LOOP_MIN_SIZE`` or more), stage by stage (``block_step``): the stage's
  argument for every member (one loop over the block's entries), then one loop over the
  members whose body is a call of the stabilized right-hand side
  (:mod:`stabdae.engine.rhs`, the user's functions inside) on buffers that live on the
  stack (:func:`stack1`, :func:`stack2`), then the weighted sum.  The
  right-hand side is inlined once, whatever the number of stages: written out per stage,
  each stage added the right-hand side's compile time again (the Whipple bicycle's
  kernel: 9.3 s with Euler, 13.1 s with the midpoint rule, 19.6 s with RK4; stage by
  stage 10.2, 10.8 and 10.9 s).  Zero coefficients are skipped at run time, so one
  kernel serves every tableau of its number of stages;
* otherwise, one loop over the members whose body is the member's whole step
  (``member_loop_step``, :func:`stabdae.engine.rk.steps._member_step_source`): the stages
  written out for the scheme's pattern of zero / one / other coefficients
  (:func:`stabdae.engine.rk.steps.tableau_pattern`), zero terms left out, factors one
  dropped.  The stages stay in registers: stage by stage, through the block's buffers
  in memory, the pendulum's midpoint ensemble integrated 36 % slower and the rolling
  disk's 31 %; a small right-hand side compiles quickly once per stage.

The scheme's coefficients are run-time arrays in both.

The pieces of the step are compiled once and marked ``alwaysinline`` for LLVM
(``forceinline=True``) rather than inlined at the numba IR level (``inline="always"``):
numba re-types the whole caller for each IR-inlined call site, while LLVM inlines the
compiled bodies in a fraction of that.  The block step itself, called once, is inlined
by numba, so that its loops are optimized where LLVM sees the block's buffers as the
kernel's own allocas.  With no calls, no heap arrays and no branches left in the member
loop's body (the pivot tests of L D Lᵀ and the step's status are arithmetic: a chain of
branches on them kept LLVM from vectorizing), and every array the loop touches an alloca
that no other pointer reaches (the parameters, the law's numbers and the tableau are
copied to the stack first), LLVM keeps the buffers in registers and vectorizes the member
loop without run-time alias checks.

The library's own multiply-adds are fused (:mod:`stabdae.engine.fma`) at the same places as in
:func:`stabdae.integrate`'s step.  Members never interact, so results are bit-for-bit the
same for any thread count and any block size, and identical to :func:`stabdae.integrate`
for the same initial state (the same operations in the same order: zero coefficients
skipped in both, sums started from −0.0, ``1 · k`` is ``k``).

The block is updated in place: the step of member ``j`` reads and writes column ``j``
only, which LLVM sees without run-time alias checks.  (With two buffers swapped every
step it could not tell them apart and wanted a check per pair of rows, and for more than
a few state components it gave up vectorizing: the double pendulum's loop ran scalar.)
Failures are looked for at checks, not after every step: the loop's step only ORs its
right-hand sides' status into the slot's ``code``.  A check (:func:`block_failed`: a
status, or a non-finite state, which stays non-finite once it is) comes at every stored
sample, every ``CHECKPOINT`` steps and at the end; a block that passes is copied to
``Xc``.  A block that fails is rolled back to that copy and stepped again up to the
check, now one step at a time with a check and a copy after each: the members whose
step fails (singular ``S``, mass not SPD, non-finite state) are stopped with the state
before it, which the in-place update had overwritten; the others recompute the same
numbers.  Each rollback stops at least one member, so a block rolls back at most once
per member.  (Testing every step and reducing the test over the block cost a noticeable
share of the loop; a scalar replay of the failed member instead compiled a second copy of the
step.)  A member is also stopped when its residual exceeds the divergence threshold at
a stored sample (it keeps that sample's state).  A stopped member's slot goes on with a
copy of a running member (numbers nobody reads) so that it does not fail again at every
step; the other members are untouched.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..._codes import Status
from ..cache import Spec, keyed_cache, memo, tag
from ..decay import (
    MAP_MAX_NG,
    MAP_SHIFT,
    begin,
    block_levels,
    difference_norms,
    finish_with_map,
    finish_with_map_pooled,
    flushes_for,
    full_rows,
    ladder_base,
    ladder_level,
    ladders,
    map_begin,
    map_buffers,
    observe,
    pairs_full_for,
    pairs_pooled,
    predict,
    reference_logs,
    scratch,
    spectral_radius_of,
    window_flush,
    windows_flush,
)
from ..fma import fma
from ..jit import internal
from ..rhs import kernels_for
from ..rk.steps import _member_step, tableau_pattern
from ..workspace import copy_inputs, copy_tableau, stack1, stack2, stack_int1

BLOCK = 64
#: schemes of at least ``STAGE_LOOP_MIN_STAGES`` stages on models of at least
#: ``STAGE_LOOP_MIN_N`` coordinates step the block stage by stage (``block_step``: the
#: right-hand side inlined once, whatever the stages), and so do two-stage schemes where
#: the right-hand side's straight-line code (:func:`stabdae.engine.rhs.rhs_size`) is at
#: least ``STAGE_LOOP_MIN_SIZE``; the others step each member through its stages written
#: out (``member_loop_step``), whose copies of the right-hand side keep the stages in
#: registers.  Stage by stage, integrating took 36 % longer for the pendulum's midpoint
#: ensemble, 80 % for the double pendulum's (its RK4 23 %), 1–5 % for the bicycle's and
#: n_four_bar's RK4; with the midpoint rule 31 % for the rolling disk (size 135), 21 % for
#: n_four_bar (726), 2 % less for the bicycle (1959), 6 % less for Bricard (2661), 9 % less
#: for the 12-coordinate bicycle (3353).  Written out, each stage beyond the first adds
#: the right-hand side's compile time again (the bicycle's RK4 kernel: 19.6 s against
#: 10.9 s stage by stage)
STAGE_LOOP_MIN_N = 6
STAGE_LOOP_MIN_STAGES = 3
STAGE_LOOP_MIN_SIZE = 1000
#: the ensemble kernel checks the block at least this often (steps) and keeps a copy of it
CHECKPOINT = 32
_NONFINITE = int(Status.NONFINITE_STATE)
_DIVERGED = int(Status.DIVERGED)


def pooled_constraints(model, law) -> int:
    """The number of holonomic constraints when the constant law acts alike on every
    constraint (``Ã``'s blocks multiples of the identity, no coupling between f and h:
    Baumgarte's law), so that the decay measurement pools their pairs into one 2 × 2
    and one 1 × 1 map; −1 otherwise."""
    if not law.is_constant:
        return -1
    A = law.A_tilde(model)
    m, k = model.m, model.k
    f, fd, h = slice(0, m), slice(m, 2 * m), slice(2 * m, 2 * m + k)

    def scalar(block):
        return block.size == 0 or np.array_equal(block, block[0, 0] * np.eye(block.shape[0]))

    def zero(block):
        return not np.any(block)

    ok = (scalar(A[fd, f]) and scalar(A[fd, fd]) and scalar(A[h, h]) and zero(A[fd, h])
          and zero(A[h, f]) and zero(A[h, fd]))  # fmt: skip
    return m if ok else -1


#: Every buffer of the block kernel, declared once: its allocation (sizes: ``N2`` = 2n
#: state components, ``ng`` residual components, ``B`` slots, ``S_`` stages, ``NP``
#: parameters, ``LR × LC`` the law's matrix, ``NA`` rows of a bin visit's sums) and what
#: it holds.  ``stack*`` buffers live on the thread's stack, the others on the heap (once
#: per call).  A test checks the kernel allocates exactly these.
BUFFERS = {
    # the small run-time inputs, copied to the stack so that nothing aliases them
    "p_s": ("stack1(NP)", "the parameters"),
    "lm": ("stack2(LR, LC)", "the law's matrix"),
    "ls": ("stack1(1)", "the law's scalar"),
    "ta": ("stack2(S_, S_)", "the scheme's A"),
    "tb": ("stack1(S_)", "the scheme's b"),
    "tc": ("stack1(S_)", "the scheme's c"),
    # the block
    "X": ("stack2(N2, B)", "the states, updated in place (slot j: column j)"),
    "Xc": ("stack2(N2, B)", "X at the last check it passed, to roll back to"),
    "code": ("stack_int1(B)", "each slot's status since that check (ORed)"),
    "active": ("stack_int1(B)", "1 for a slot whose member (not padding) still runs"),
    # one member at a time, outside the member loop
    "ws_h": ("K_make_workspace()", "the right-hand side's workspace"),
    "xs_h": ("np.empty(N2)", "one member's state (energy, a stop's last state)"),
    "nrm_b": ("np.empty(B)", "‖g‖ of every slot at a stored sample"),
    "dn_b": ("np.empty(B)", "... its distance from the reference's residual"),
    "g_p": ("np.empty(alpha0s.shape[1])", "the linear prediction's g"),
    "gn_p": ("np.empty(alpha0s.shape[1])", "... and its next g"),
    "ref": ("reference_logs(R)", "the law's distinct ln |eigenvalue|: the groups a fitted "
            "map's eigenvalues are read in"),
    # the decay measurement (:mod:`..decay`)
    "gs": ("stack1(B)", "‖g‖ at a measured state"),
    "ds": ("stack1(B)", "... its distance from the reference's"),
    "gr": ("stack1(ng)", "the reference's residual at the current step"),
    "Gb": ("stack2(ng, B)", "the slots' residuals at a stored sample"),
    "lt, lv, base": ("ladders(B)", "each slot's ladder: times, norms, offset"),
    "clear_from": ("stack_int1(B)", "each slot's level below which its ladder holds no time"),
    "rt, ry, fa, fb, lg": ("scratch()", "the fits' scratch"),
    "S_map": ("map_buffers(B, ng, pooled)", "the one-step map's sums per slot and bin"),
    "Dv": ("stack2(ng, B)", "each slot's g (then g − g_ref) at a measured state"),
    "P": ("stack2(ng, B)", "... at the measured state before"),
    "Am": ("stack2(NA, B)", "the running sums of the current bin visit"),
    "base_s": ("stack_int1(B)", "each slot's ladder offset"),
    "low": ("stack_int1(B)", "the lowest map bin reached"),
    "nlev": ("stack_int1(B)", "the level at this state"),
    "wmax": ("stack1(B)", "the largest ‖g‖ of the fifth so far"),
    "dmax": ("stack1(B)", "... of the measured norm"),
    # the block step's
    "XS": ("stack2(N2, B)", "a stage's argument, then the weighted sum of the stages"),
    "KS": ("stack2(SN2, B)", "the stages' right-hand sides (stage s: rows s·N2 …)"),
    "GS": ("stack2(ng, B)", "the residual a stage's right-hand side evaluated"),
    "cm": ("stack_int1(B)", "each slot's worst stage status in the step"),
    # inside the member loop: per slot, on the stack (LLVM keeps them in registers)
    "ws": ("stack_workspace()", "the right-hand side's workspace"),
    "xs": ("stack1(N2)", "a stage's state (block_norms: the slot's state)"),
    "ks": ("stack1(N2)", "the stage's right-hand side"),
    "gj": ("stack1(ng)", "block_norms: the slot's residual"),
    "xk": ("stack1(N2)", "member_loop_step: the slot's state before the step"),
    "xn": ("stack1(N2)", "... after it"),
    "gv": ("stack1(ng)", "... the residual its first stage evaluated"),
}


def ensemble_kernel_for(model, bound, scheme, block: int = BLOCK):
    """The block-lockstep ensemble kernel of ``model`` (memoized per law kind, the scheme's
    number of stages (stepped stage by stage, see ``STAGE_LOOP_MIN_N``) or the kinds of
    its coefficients (written out), block, the shape of the law's matrix and whether the decay
    measurement pools the constraints, :func:`pooled_constraints`)."""
    K = kernels_for(model, bound)
    stages = len(scheme.b)
    by_stage = model.n >= STAGE_LOOP_MIN_N and (stages >= STAGE_LOOP_MIN_STAGES or (
        stages == 2 and K.size >= STAGE_LOOP_MIN_SIZE))  # fmt: skip
    spec = Spec("block", law=bound.code, law_fn=bound.fn,
                pattern=() if by_stage else tableau_pattern(scheme),
                stages=(len(scheme.b),) if by_stage else (),
                block=block, n_params=len(model.param_names), law_shape=bound.matrix.shape,
                pooled=pooled_constraints(model, bound.law))  # fmt: skip
    return memo(model, spec, lambda: build_block_kernel(K, spec))


# The block's bookkeeping at checks and stops: sizes from the arrays, so that these are
# compiled once (cached) for every model rather than as closures at each new model's first
# ensemble.


@njit(cache=True, error_model="numpy", _nrt=False)
def retire(X, j, row, active, code, x_final, x_last):
    """Stop slot ``j``.  Its member, output ``row`` (``-1``: padding, or a slot that
    was already stopped), gets ``x_last`` as its final state; the slot then takes the
    state of a running member whose last step succeeded, so that it computes harmless
    numbers from now on instead of failing at every step."""
    if row >= 0:
        for l in range(X.shape[0]):
            x_final[row, l] = x_last[l]
    active[j] = False
    for src in range(active.shape[0]):
        if active[src] and code[src] == 0:
            for l in range(X.shape[0]):
                X[l, j] = X[l, src]
            break


@njit(cache=True, error_model="numpy", _nrt=False)
def stop_failed(X, X_last, code, active, lo, cnt, step, status, fail_step, x_final,
                x_last):  # fmt: skip
    """Stop every slot with a status in ``code`` or a non-finite state: its member, if
    still running, gets that status (``NONFINITE_STATE`` for the state), ``step`` as
    its failing step and its column of ``X_last`` as final state; the slot is then
    recycled (:func:`retire`).  Clears ``code``; returns the number of members
    stopped."""
    for j in range(code.shape[0]):
        for l in range(X.shape[0]):
            if code[j] == 0 and not math.isfinite(X[l, j]):
                code[j] = _NONFINITE
    stopped = 0
    for j in range(code.shape[0]):
        if code[j] != 0:
            row = lo + j if (j < cnt and active[j]) else -1
            if row >= 0:
                status[row] = code[j]
                fail_step[row] = step
                stopped += 1
            for l in range(X.shape[0]):
                x_last[l] = X_last[l, j]
            retire(X, j, row, active, code, x_final, x_last)
    for j in range(code.shape[0]):
        code[j] = 0
    return stopped


@njit(cache=True, error_model="numpy", _nrt=False)
def block_failed(X, code):
    """Whether a slot's steps since the last check failed: a status in ``code`` or a
    non-finite state (which stays non-finite once it is).  (Slots innermost: the loops
    vectorize over any block size.)"""
    bad = False
    for j in range(code.shape[0]):
        bad |= code[j] != 0
    for l in range(X.shape[0]):
        for j in range(code.shape[0]):
            bad |= not math.isfinite(X[l, j])
    return bad


def build_block_kernel(K, spec: Spec):
    """The block-lockstep ensemble kernel for the kernels ``K`` and the compile spec
    ``spec``: an explicit scheme of ``spec.stages[0]`` stages stepped stage by stage, or
    one whose coefficients are of the kinds ``spec.pattern`` (:func:`tableau_pattern`)
    with each member's stages written out; blocks of ``spec.block`` members,
    ``spec.n_params`` parameters, a law matrix of shape ``spec.law_shape`` and the decay
    measurement's one-step map pooled over ``spec.pooled`` holonomic constraints (−1: the
    full map; :func:`.decay.map_width`), all fixed at compile time; the scheme's coefficients, the
    parameters and the law's numbers are run-time arrays (:mod:`.groups`)."""
    block, n_params, pattern = spec.block, spec.n_params, spec.pattern
    law_shape, pooled = spec.law_shape, spec.pooled
    rhs, residual, energy = K.rhs, K.residual, K.energy
    K_make_workspace = K.make_workspace
    N2, ng = 2 * K.n, K.ng
    B = block
    by_stage = not pattern  # (the spec names the stages, or the coefficients' kinds)
    S_ = spec.stages[0] if by_stage else len(pattern[1])
    SN2 = S_ * N2
    NB = N2 * B  # the entries of the block's state
    NP = max(n_params, 1)
    LR, LC = law_shape
    stack_workspace = K.stack_workspace
    ROWS_FULL = full_rows(ng)
    FULL = ng if ng <= MAP_MAX_NG else 0  # the full map's components (none: 0)
    pairs_full = pairs_full_for(B, FULL)
    bin_flush, end_flush = flushes_for(FULL if pooled < 0 else 0)
    NA = 10 if pooled >= 0 else ROWS_FULL  # rows of the current bin visit's sums
    # (a pooled map's end without reference counting: .decay.onestep, 'pooled ends')
    finish_member = finish_with_map_pooled if pooled >= 0 else finish_with_map

    @internal(error_model="numpy")
    def block_norms(X, t, p, gref, nrm, dnrm, G):
        """``‖g‖∞`` and ``‖g − gref‖∞`` of every slot of the block at time ``t`` into
        ``nrm`` and ``dnrm``, and ``g`` into the columns of ``G``: one loop over the
        slots, vectorized like the step's (cheaper than one scalar evaluation per running
        member)."""
        for j in range(B):
            ws = stack_workspace()
            xs = stack1(N2)
            gj = stack1(ng)
            for l in range(N2):
                xs[l] = X[l, j]
            residual(t, xs, p, ws, gj)
            s = 0.0
            d = 0.0
            for l in range(ng):
                s = max(s, abs(gj[l]))
                d = max(d, abs(gj[l] - gref[l]))
                G[l, j] = gj[l]
            nrm[j] = s
            dnrm[j] = d

    # inlined by numba (its one call): its loops are optimized where LLVM sees that the
    # block's buffers are distinct allocas (compiled on its own, the slot loop was
    # vectorized behind run-time alias checks, with a scalar copy of the right-hand side)
    @njit(inline="always", error_model="numpy")
    def block_step(X, t, tau, p, lm, ls, ta, tb, tc, XS, KS, GS, cm, code, Dv):
        """One explicit Runge–Kutta step of every slot of the block, stage by stage: each
        stage's argument, then its right-hand side for every slot (one loop over the
        slots: the right-hand side is inlined once, whatever the number of stages), then
        the weighted sum.  The operations of :func:`stabdae.integrate`'s step, in its
        order (zero coefficients skipped, sums from −0.0): the same bits.  Each slot's
        status, the worst of its stages, is ORed into ``code``; the residual at the
        step's start (the first stage's) goes to ``Dv``.  The sums run over the block's
        buffers as flat arrays: one loop each, which LLVM vectorizes without writing it
        out (over ``X[l, j]`` for each ``l``, it wrote out all ``N2 · B`` entries of each
        sum, more code than the right-hand side's)."""
        S = tb.shape[0]
        Xf = X.reshape(NB)
        XSf = XS.reshape(NB)
        KSf = KS.reshape(S_ * NB)
        for j in range(B):
            cm[j] = 0
        for s in range(S):
            for i in range(NB):
                XSf[i] = Xf[i]
            for q in range(s):
                if ta[s, q] != 0.0:
                    c = tau * ta[s, q]
                    for i in range(NB):
                        XSf[i] = fma(c, KSf[q * NB + i], XSf[i])
            ts = t + tc[s] * tau
            for j in range(B):  # the stage of every slot
                ws = stack_workspace()
                xs = stack1(N2)
                ks = stack1(N2)
                for l in range(N2):
                    xs[l] = XS[l, j]
                st = rhs(ts, xs, p, lm, ls, ws, ks)
                for l in range(N2):
                    KS[s * N2 + l, j] = ks[l]
                cm[j] = max(cm[j], st)
                for l in range(ng):
                    GS[l, j] = ws.g[l]
            if s == 0:
                for l in range(ng):
                    for j in range(B):
                        Dv[l, j] = GS[l, j]
        for i in range(NB):
            XSf[i] = -0.0
        for s in range(S):
            if tb[s] != 0.0:
                for i in range(NB):
                    XSf[i] = fma(tb[s], KSf[s * NB + i], XSf[i])
        for i in range(NB):
            Xf[i] = fma(tau, XSf[i], Xf[i])
        for j in range(B):
            code[j] |= cm[j]

    member_step = None if by_stage else _member_step(rhs, N2, ng, pattern)

    @njit(inline="always", error_model="numpy")
    def member_loop_step(X, t, tau, p, lm, ls, ta, tb, tc, XS, KS, GS, cm, code, Dv):
        """:func:`block_step`'s other form (below ``STAGE_LOOP_MIN_N`` coordinates, one
        stage, or two on a right-hand side smaller than ``STAGE_LOOP_MIN_SIZE``): one loop
        over the slots whose body is the
        member's whole step, its stages written out (:func:`.rk.steps._member_step`);
        ``XS``, ``KS``, ``GS`` and ``cm`` are not used."""
        for j in range(B):
            ws = stack_workspace()
            xk = stack1(N2)
            xs = stack1(N2)
            xn = stack1(N2)
            gv = stack1(ng)
            for l in range(N2):
                xk[l] = X[l, j]
            c = member_step(t, xk, tau, p, lm, ls, ta, tb, tc, ws, xs, xn, gv)
            for l in range(N2):
                X[l, j] = xn[l]
            code[j] |= c
            for l in range(ng):
                Dv[l, j] = gv[l]

    step = block_step if by_stage else member_loop_step

    @njit(nogil=True, error_model="numpy")
    def block_kernel(inputs, grid, tableau, measure, out, b_lo, b_hi):
        """Integrate the members of ``inputs`` (:mod:`.groups`) on ``grid`` with the
        scheme of ``tableau`` in blocks ``b_lo … b_hi − 1``; outputs as in
        :func:`stabdae.ensemble`.  Member ``i``'s stored samples go to row
        ``measure.trace_row[i]`` of ``out.norms`` (none when −1); its decay measures
        (:mod:`.decay`, from ``‖g‖`` at every measured step) to row ``i`` of ``out.meas``
        and ``out.codes``, with the linear prediction ``g_{k+1} = R g_k`` from
        ``alpha0[i]`` when ``measure.R`` is not empty (``R`` advances ``measure.stride``
        steps: the decay is measured at every ``stride``-th state,
        :func:`stabdae._ensemble.measure_stride`).  The decay is measured on
        ``‖g_k − g_ref[k]‖∞``, ``g_ref`` the residual of a reference trajectory at every
        step (none when it has no rows: ``‖g_k‖∞``).  When ``out.g_out`` has rows, the
        residual of the first member at every step goes to its rows (the reference
        trajectory is such a run of one member: the same step, compiled once).
        Every output row of the blocks is written here (``norms`` NaN after a stop,
        ``status`` 0 and ``fail_step`` −1 for a member that runs to the end), so the
        driver allocates them empty and the pages are first touched by the threads
        that fill them.  Releases the GIL (run by :func:`.threads.run_chunks`)."""
        x0s, alpha0s, p, law_mat, law_scal = inputs
        t0, tau, nsteps, save_every = grid
        tab_a, tab_b, tab_c = tableau
        threshold, g_ref, R, stride, trace_row, noise = measure
        out_norm, meas, mcodes, x_final = out.norms, out.meas, out.codes, out.x_final
        status, fail_step, e0, e1, g_out = out.status, out.fail_step, out.e0, out.e1, out.g_out
        M = x0s.shape[0]
        nsave = out_norm.shape[1]
        # the small run-time inputs on the stack (copy_inputs: no aliasing)
        p_s = stack1(NP)
        lm = stack2(LR, LC)
        ls = stack1(1)
        copy_inputs(p, law_mat, law_scal, p_s, lm, ls)
        ta = stack2(S_, S_)
        tb = stack1(S_)
        tc = stack1(S_)
        copy_tableau(tab_a, tab_b, tab_c, ta, tb, tc)
        # The block, updated in place (member j's step reads and writes column j only, so
        # the loop needs no run-time alias checks); its copy at the last check that it
        # passed (at most CHECKPOINT steps old), to roll back to; the status of each
        # slot's steps since then.
        X = stack2(N2, B)
        Xc = stack2(N2, B)
        XS = stack2(N2, B)  # a stage's argument, then the weighted sum of the stages
        KS = stack2(SN2, B)  # the stages' right-hand sides (stage s: rows s·N2 …)
        GS = stack2(ng, B)  # the residual a stage's right-hand side evaluated
        cm = stack_int1(B)  # each slot's worst stage status in the step
        code = stack_int1(B)
        active = stack_int1(B)  # members (not padding) still running: 1, else 0
        ws_h = K_make_workspace()
        xs_h = np.empty(N2)
        nrm_b = np.empty(B)  # the block's residual norms at a stored sample
        dn_b = np.empty(B)  # ... and their distances from the reference's
        gs = stack1(B)  # ‖g‖ at the start of the current step
        ds = stack1(B)  # ... and its distance from the reference's
        has_ref = g_ref.shape[0] > 0
        gr = stack1(ng)  # the reference's residual at the current step
        has_out = g_out.shape[0] > 0
        Gb = stack2(ng, B)  # the block's residuals at a stored sample
        for l in range(ng):
            gr[l] = 0.0
        lt, lv, base = ladders(B)  # the decay measurement's ladder per slot
        # per slot, a level below which its ladder holds no time (its members' starts
        # clear it from there up; 0 until a member has ended there: the rows are new)
        clear_from = stack_int1(B)
        for j in range(B):
            clear_from[j] = 0
        rt, ry, fa, fb, lg = scratch()
        # The measurement (the block functions of :mod:`.decay`): the one-step map's sums per
        # slot and bin, fed from the measured states' g − g_ref (Dv: each step's g, made
        # g − g_ref, with the norms gs, ds, at a measured one) through the previous one
        # (P) and the running sums (Am); each slot's ladder offset, the lowest of the
        # map's bins it reached and its level at this state; the largest norms of the
        # fifth.
        S_map = map_buffers(B, ng, pooled)
        # (as run-time integers: pairs_pooled and the pooled map's flushes are compiled once
        # for every model, and a literal argument would compile a copy per value)
        pm_ = np.int64(max(pooled, 0))
        pooled_ = np.int64(pooled)
        full_ = np.int64(FULL)
        Dv = stack2(ng, B)
        P = stack2(ng, B)
        Am = stack2(NA, B)
        base_s = stack_int1(B)
        low = stack_int1(B)
        nlev = stack_int1(B)
        wmax = stack1(B)
        dmax = stack1(B)
        rho_R = spectral_radius_of(R) if R.shape[0] > 0 else math.nan
        ref = reference_logs(R)
        g_p = np.empty(alpha0s.shape[1])
        gn_p = np.empty(alpha0s.shape[1])
        for b in range(b_lo, b_hi):
            lo = b * B
            cnt = min(B, M - lo)
            for j in range(B):  # a short last block repeats its first member
                src = lo + j if j < cnt else lo
                code[j] = 0
                active[j] = False
                for l in range(N2):
                    X[l, j] = x0s[src, l]
            for j in range(cnt):
                status[lo + j] = 0
                fail_step[lo + j] = -1
                r = trace_row[lo + j]
                if r >= 0:
                    for s in range(nsave):
                        out_norm[r, s] = math.nan
            alive = 0
            if has_ref:
                for l in range(ng):
                    gr[l] = g_ref[0, l]
            block_norms(X, t0, p_s, gr, nrm_b, dn_b, Gb)
            for j in range(B):
                base_s[j] = ladder_base(dn_b[j])
                low[j] = ladder_level(dn_b[j], base_s[j]) >> MAP_SHIFT
                wmax[j] = -math.inf
                dmax[j] = -math.inf
                for l in range(ng):
                    P[l, j] = 0.0
                for c in range(NA):
                    Am[c, j] = 0.0
            window = 0
            measured = 0  # steps up to this one have been through (a rollback redoes some)
            k_last = -1  # the last state measured
            k_next = 0  # the next state to measure (a multiple of stride: no division per step)
            for j in range(cnt):
                for l in range(N2):
                    xs_h[l] = X[l, j]
                e0[lo + j] = energy(t0, xs_h, p, ws_h)
                nrm = nrm_b[j]
                if trace_row[lo + j] >= 0:
                    out_norm[trace_row[lo + j], 0] = nrm
                begin(lt, lv, base, meas, mcodes, j, lo + j, nrm, dn_b[j], clear_from[j])
                map_begin(S_map, j, low[j])
                active[j] = True
                alive += 1
                if not (nrm <= threshold):
                    code[j] = _DIVERGED
            for j in range(cnt, B):  # padding repeats member lo: stopped with it
                code[j] = code[0]
            # (step 0 as an int64, not a literal: a literal argument compiles a second copy)
            alive -= stop_failed(X, X, code, active, lo, cnt, np.int64(0), status, fail_step,
                                 x_final, xs_h)  # fmt: skip
            checkpoint = 0  # the step after which Xc was taken
            for l in range(N2):
                for j in range(B):
                    Xc[l, j] = X[l, j]
            until_save = save_every  # steps to the next stored sample (no division per step)
            saved_until = until_save  # its value at the checkpoint
            careful_to = 0  # steps up to this one are checked one by one (after a rollback)
            i = 1
            while i <= nsteps:
                if alive == 0:
                    break
                t = t0 + (i - 1) * tau
                if has_ref:
                    for l in range(ng):
                        gr[l] = g_ref[i - 1, l]
                step(X, t, tau, p_s, lm, ls, ta, tb, tc, XS, KS, GS, cm, code, Dv)
                if has_out:  # g(x_{i-1}), evaluated by the step's first stage
                    for l in range(ng):
                        g_out[i - 1, l] = Dv[l, 0]
                k = i - 1
                if i > measured and k == k_next:  # state k measured (once: not in a replay)
                    k_next += stride
                    fifth = min(4, (5 * k) // nsteps)
                    if fifth != window:
                        windows_flush(meas, wmax, dmax, window, active, lo, cnt)
                        window = fifth
                    weight = 1.0 if k_last >= 0 else 0.0  # a pair with the state before
                    difference_norms(Dv, gr, gs, ds)
                    if pooled >= 0:
                        pairs_pooled(Dv, P, Am, weight, pm_)
                    elif ROWS_FULL > 1:
                        pairs_full(Dv, P, Am, weight)
                    changed = block_levels(gs, ds, base_s, low, nlev, wmax, dmax)
                    if changed != 0:
                        bin_flush(S_map, Am, nlev, low, changed, pooled_, full_)
                    for j in range(B):  # time and norm on each slot's level (a scatter)
                        lt[j, nlev[j]] = k * tau
                        lv[j, nlev[j]] = ds[j]
                    k_last = k
                measured = max(measured, i)
                until_save -= 1
                renew = True
                if i <= careful_to:  # stop the members whose step failed; Xc: the step before
                    windows_flush(meas, wmax, dmax, window, active, lo, cnt)
                    alive -= stop_failed(X, Xc, code, active, lo, cnt, i - 1, status,
                                         fail_step, x_final, xs_h)  # fmt: skip
                elif until_save == 0 or i - checkpoint == CHECKPOINT or i == nsteps:
                    if block_failed(X, code):  # roll back, then step by step up to here
                        for l in range(N2):
                            for j in range(B):
                                X[l, j] = Xc[l, j]
                        for j in range(B):
                            code[j] = 0
                        careful_to = i
                        until_save = saved_until
                        i = checkpoint + 1
                        continue
                else:
                    renew = False
                if until_save == 0:  # a stored sample, of the members whose steps succeeded
                    until_save = save_every
                    block_norms(X, t0 + i * tau, p_s, gr, nrm_b, dn_b, Gb)
                    sample = i // save_every  # (once: in the loop, a division per member)
                    for j in range(cnt):
                        if active[j]:
                            nrm = nrm_b[j]
                            if trace_row[lo + j] >= 0:
                                out_norm[trace_row[lo + j], sample] = nrm
                            if not (nrm <= threshold):
                                status[lo + j] = _DIVERGED
                                fail_step[lo + j] = i
                                alive -= 1
                                # its largest norms of the fifth (the others' wait for
                                # the fifth's end: a flush of the whole block at every
                                # stored sample was a loop over its members' rows each
                                # time)
                                window_flush(meas, wmax, dmax, window, j, lo + j)
                                for l in range(N2):
                                    xs_h[l] = X[l, j]
                                retire(X, j, lo + j, active, code, x_final, xs_h)
                if renew:  # the block after step i is good: the new checkpoint
                    checkpoint = i
                    saved_until = until_save
                    for l in range(N2):
                        for j in range(B):
                            Xc[l, j] = X[l, j]
                i += 1
            tf = t0 + nsteps * tau
            if has_ref:
                for l in range(ng):
                    gr[l] = g_ref[nsteps, l]
            block_norms(X, tf, p_s, gr, nrm_b, dn_b, Gb)
            if has_out:
                for l in range(ng):
                    g_out[nsteps, l] = Gb[l, 0]
            windows_flush(meas, wmax, dmax, window, active, lo, cnt)
            # the sums of the lowest bin reached (those below it are read from it)
            end_flush(S_map, Am, low, active, pooled_, full_)
            for j in range(cnt):
                final = math.nan
                if active[j]:
                    for l in range(N2):
                        x_final[lo + j, l] = X[l, j]
                    final = nrm_b[j]
                    observe(lt, lv, base, meas, j, lo + j, nsteps * tau, final, dn_b[j], 4)
                for l in range(N2):
                    xs_h[l] = x_final[lo + j, l]
                e1[lo + j] = energy(tf, xs_h, p, ws_h)
                # no level below the lowest bin measured or the final state's was visited
                lowest = min(low[j] << MAP_SHIFT, ladder_level(dn_b[j], base[j]))
                finish_member(lt, lv, S_map, meas, mcodes, j, lo + j, final, not active[j],
                              ng, pooled, base[j], lowest, stride * tau, rt, ry, fa, fb, lg,
                              ref, low_bin=low[j], noise=noise)  # fmt: skip
                written = lowest  # (a prediction clears the row and writes levels of its own)
                if R.shape[0] > 0:
                    written = predict(R, alpha0s, lo + j, nsteps // stride, stride * tau, lt,
                                      lv, base, meas, mcodes, j, lo + j, rt, ry, fa, fb, lg,
                                      g_p, gn_p, rho_R)  # fmt: skip
                clear_from[j] = min(lowest, written)
            for j in range(cnt, B):  # (padding: its ladder written, no end to say where)
                clear_from[j] = 0

    key = spec.key(K.key)
    tag(key, block_norms, step, *(() if by_stage else (member_step,)), pairs_full,
        *((bin_flush, end_flush) if FULL and pooled < 0 else ()))  # (closures only)
    kernel = keyed_cache(block_kernel, key)
    kernel.block_step = step  # (compiled inside the kernel; a test compiles it apart)
    return kernel
