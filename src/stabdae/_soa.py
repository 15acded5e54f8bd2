"""The ensemble kernel: blocks of members in lockstep, structure of arrays, member innermost.

Each work item (a block; ranges of blocks run on threads, :mod:`._threads`) holds a block
of ``BLOCK`` members as arrays ``X[state, member]`` and ``K[stage, state, member]``.  Every
stage is one loop over the members of the block; its body is the whole stabilized
right-hand side of one member (:mod:`._rhs`, the user's functions inlined) working on
buffers that live on the stack (:func:`stack1`, :func:`stack2`).  With no heap arrays, no
calls and no early exits left in the body, LLVM turns those buffers into registers and
vectorizes the loop across members.

Members never interact, so results are bit-for-bit the same for any thread count and any
block size, and identical to :func:`stabdae.integrate` for the same initial state (same
operations in the same order).  A member whose step fails (singular ``S``, mass not SPD,
non-finite state) or whose residual exceeds the divergence threshold at a stored sample is
frozen — its state no longer changes — and flagged; the other members are untouched.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from ._cache import kernel_key, keyed_cache, tag
from ._status import Status

BLOCK = 64
_NONFINITE = int(Status.NONFINITE_STATE)
_DIVERGED = int(Status.DIVERGED)


def _stack_array(context, builder, shape):
    arrty = types.Array(types.float64, len(shape), "C")
    ary = context.make_array(arrty)(context, builder)
    size = 1
    for s in shape:
        size *= s
    # alloca_once puts the buffer in the entry block of the function being compiled: one
    # buffer per call site, reused by every iteration of the loop around it.
    data = cgutils.alloca_once(builder, context.get_value_type(types.float64), size=max(size, 1))
    intp = lambda v: context.get_constant(types.intp, v)  # noqa: E731
    strides, acc = [], 8
    for s in reversed(shape):
        strides.insert(0, intp(acc))
        acc *= s
    context.populate_array(ary, data=data, shape=[intp(s) for s in shape], strides=strides,
                           itemsize=intp(8), meminfo=None)  # fmt: skip
    return ary._getvalue()


@intrinsic
def stack1(typingctx, n):
    """A float64 array of compile-time length ``n`` on the stack (no meminfo, no NRT).

    Only valid inside the function that calls it (inline the caller at the numba IR level
    if it is a helper).
    """
    if not isinstance(n, types.IntegerLiteral):
        return None
    size = n.literal_value

    def codegen(context, builder, sig, args):
        return _stack_array(context, builder, (size,))

    return types.Array(types.float64, 1, "C")(n), codegen


@intrinsic
def stack2(typingctx, n0, n1):
    """A C-ordered float64 array of compile-time shape ``(n0, n1)`` on the stack."""
    if not (isinstance(n0, types.IntegerLiteral) and isinstance(n1, types.IntegerLiteral)):
        return None
    shape = (n0.literal_value, n1.literal_value)

    def codegen(context, builder, sig, args):
        return _stack_array(context, builder, shape)

    return types.Array(types.float64, 2, "C")(n0, n1), codegen


def build_soa_kernel(K, stages: int, block: int = BLOCK):
    """The block-lockstep ensemble kernel for the kernels ``K``, an ``stages``-stage explicit
    scheme and blocks of ``block`` members (both fixed at compile time; the scheme's
    coefficients are run-time arrays)."""
    rhs, residual, energy = K.rhs, K.residual, K.energy
    K_make_workspace = K.make_workspace
    n, m, k, ng = K.n, K.m, K.k, K.ng
    N2, r = 2 * n, m + k
    mk, kk = max(m, 1), max(k, 1)
    S_ = stages
    B = block

    @njit(inline="always")
    def stack_workspace():
        """The workspace of ``K.make_workspace`` with every buffer on the stack."""
        return (
            stack1(n), stack1(n), stack2(n, n), stack1(n), stack2(mk, n), stack2(kk, n),
            stack2(kk, n), stack2(n, r), stack2(r, r), stack1(r), stack1(ng), stack1(mk),
            stack1(kk), stack2(r, ng), stack2(kk, kk), stack1(kk), stack2(r, r), stack1(r),
            stack1(r),
        )  # fmt: skip

    @njit(error_model="numpy")
    def save_sample(X, j, t, p, ws, g, xs):
        for l in range(N2):
            xs[l] = X[l, j]
        residual(t, xs, p, ws, g)
        nrm = 0.0
        for l in range(ng):
            nrm = max(nrm, abs(g[l]))
        return nrm

    @njit(nogil=True, error_model="numpy")
    def soa_kernel(x0s, t0, tau, nsteps, save_every, p, law_mat, law_scal, tab_a, tab_b, tab_c,
                   threshold, out_norm, x_final, status, fail_step, e0, e1,
                   b_lo, b_hi):  # fmt: skip
        """Integrate the rows of ``x0s`` in blocks ``b_lo … b_hi − 1``; outputs as in
        :func:`stabdae.ensemble`.  ``out_norm`` must be pre-filled (NaN): samples after a
        stop are not written.  Releases the GIL (run by :func:`._threads.run_chunks`)."""
        M = x0s.shape[0]
        for b in range(b_lo, b_hi):
            lo = b * B
            cnt = min(B, M - lo)
            X = np.empty((N2, B))
            Kst = np.empty((S_, N2, B))
            code = np.zeros(B, dtype=np.int64)  # status of the current step, per member
            active = np.ones(B, dtype=np.bool_)
            ws_h = K_make_workspace()
            g = np.empty(ng)
            xs_h = np.empty(N2)
            for j in range(B):  # a short last block repeats its first member
                src = lo + j if j < cnt else lo
                for l in range(N2):
                    X[l, j] = x0s[src, l]
            for j in range(cnt):
                for l in range(N2):
                    xs_h[l] = X[l, j]
                e0[lo + j] = energy(t0, xs_h, p, ws_h)
                nrm = save_sample(X, j, t0, p, ws_h, g, xs_h)
                out_norm[lo + j, 0] = nrm
                if not (nrm <= threshold):
                    active[j] = False
                    status[lo + j] = _DIVERGED
                    fail_step[lo + j] = 0
            for i in range(1, nsteps + 1):
                t = t0 + (i - 1) * tau
                for s in range(S_):
                    ts = t + tab_c[s] * tau
                    for j in range(B):
                        ws = stack_workspace()
                        xs = stack1(N2)
                        xd = stack1(N2)
                        for l in range(N2):
                            acc = X[l, j]
                            for q in range(s):
                                acc += tau * tab_a[s, q] * Kst[q, l, j]
                            xs[l] = acc
                        c = rhs(ts, xs, p, law_mat, law_scal, ws, xd)
                        code[j] = c if s == 0 else max(code[j], c)
                        for l in range(N2):
                            Kst[s, l, j] = xd[l]
                for j in range(B):
                    # x_{k+1} = x_k + τ Σ b_s k_s, kept only for an active member whose
                    # step succeeded and stayed finite (frozen members keep their state)
                    xn = stack1(N2)
                    finite = True
                    for l in range(N2):
                        acc = 0.0
                        for s in range(S_):
                            acc += tab_b[s] * Kst[s, l, j]
                        xn[l] = X[l, j] + tau * acc
                        finite &= math.isfinite(xn[l])
                    c = code[j]
                    c = _NONFINITE if (c == 0 and not finite) else c
                    code[j] = c
                    ok = active[j] and c == 0
                    for l in range(N2):
                        X[l, j] = xn[l] if ok else X[l, j]
                for j in range(cnt):
                    if active[j] and code[j] != 0:
                        active[j] = False
                        status[lo + j] = code[j]
                        fail_step[lo + j] = i - 1
                if i % save_every == 0:
                    tn = t0 + i * tau
                    for j in range(cnt):
                        if active[j]:
                            nrm = save_sample(X, j, tn, p, ws_h, g, xs_h)
                            out_norm[lo + j, i // save_every] = nrm
                            if not (nrm <= threshold):
                                active[j] = False
                                status[lo + j] = _DIVERGED
                                fail_step[lo + j] = i
            tf = t0 + nsteps * tau
            for j in range(cnt):
                for l in range(N2):
                    x_final[lo + j, l] = X[l, j]
                    xs_h[l] = X[l, j]
                e1[lo + j] = energy(tf, xs_h, p, ws_h)

    key = kernel_key(K.key, "soa", stages, block)
    tag(key, stack_workspace, save_sample)
    return keyed_cache(soa_kernel, key)
