"""The fixed-step explicit Runge–Kutta step of one trajectory, and the multipliers.

The step (``step`` of :func:`stepper_for`) applies a tableau ``(A, b, c)`` given as
run-time arrays (a new scheme never recompiles); ``integrate_kernel`` runs it over a
trajectory, storing state, residual and energy every ``save_every`` steps, and projecting
after each step when asked.  The ensemble kernel's block step
(:mod:`stabdae.engine.ensemble.block`) is its twin for a block of members: the same
operations in the same order (zero coefficients skipped, multiply-adds fused at the same
places, sums from −0.0, ``1 · k`` is ``k``), so an ensemble member is ``integrate``'s
trajectory bit for bit (``test_block_step_and_looped_step_agree_bit_for_bit`` and its
siblings pair them).  Changing either means changing both alike.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit

from ..._codes import Status
from ..cache import Spec, keyed_cache, memo
from ..fma import fma
from ..jit import internal
from ..rhs import kernels_for

__all__ = ["Stepper", "integrator_for", "multipliers_for", "sample_writer", "stepper_for"]

_NONFINITE = int(Status.NONFINITE_STATE)


Stepper = namedtuple("Stepper", "step integrate")


def stepper_for(model, bound, multiplier: str = "ldl") -> Stepper:
    """The compiled RK step and single-trajectory loop for ``model`` under the law's kind
    (memoized on the model)."""
    spec = Spec("stepper", law=bound.code, law_fn=bound.fn, multiplier=multiplier)
    return memo(model, spec, lambda: _build_stepper(kernels_for(model, bound, multiplier), spec))


def integrator_for(model, bound, multiplier: str = "ldl"):
    """The compiled single-trajectory loop for ``model`` under the law's kind."""
    return stepper_for(model, bound, multiplier).integrate


def sample_writer(K):
    """``save(j, t, x, p, ws, g, out_x, out_g, out_e)``: state, residual and energy at ``t``
    into row ``j`` of the outputs (inlined into the single-trajectory loops)."""
    residual, energy = K.residual, K.energy
    N2, ng = 2 * K.n, K.ng

    @internal(forceinline=True)
    def save(j, t, x, p, ws, g, out_x, out_g, out_e):
        residual(t, x, p, ws, g)
        for l in range(N2):
            out_x[j, l] = x[l]
        for l in range(ng):
            out_g[j, l] = g[l]
        out_e[j] = energy(t, x, p, ws)

    return save


def _build_stepper(K, spec: Spec):
    rhs, make_workspace, project = K.rhs, K.make_workspace, K.project
    save = sample_writer(K)
    N2, ng = 2 * K.n, K.ng

    @njit(error_model="numpy")
    def step(x, t, tau, p, law_mat, law_scal, tab_a, tab_b, tab_c, ws, stages, xs):
        """One explicit RK step, ``x`` updated in place; returns a status code.

        ``stages`` (s × 2n) and ``xs`` (2n) are scratch.  On a non-zero status ``x`` is
        left as it was before the step.
        """
        s = tab_b.shape[0]
        for i in range(s):
            for l in range(N2):
                acc = x[l]
                for j in range(i):
                    if tab_a[i, j] != 0.0:  # skipped, as in the ensemble's block step
                        acc = fma(tau * tab_a[i, j], stages[j, l], acc)
                xs[l] = acc
            st = rhs(t + tab_c[i] * tau, xs, p, law_mat, law_scal, ws, stages[i])
            if st != 0:
                return st
        for l in range(N2):
            acc = -0.0  # the exact identity of +, so the first term is taken as it is
            for i in range(s):
                if tab_b[i] != 0.0:
                    acc = fma(tab_b[i], stages[i, l], acc)
            xs[l] = fma(tau, acc, x[l])
            if not math.isfinite(xs[l]):
                return _NONFINITE
        for l in range(N2):
            x[l] = xs[l]
        return 0

    @njit(error_model="numpy")
    def integrate_kernel(x0, t0, tau, nsteps, save_every, p, law_mat, law_scal,
                         tab_a, tab_b, tab_c, sweeps, tol, out_x, out_g, out_e):  # fmt: skip
        """Integrate from ``x0`` for ``nsteps`` steps, saving every ``save_every`` steps;
        after each step, ``sweeps > 0`` projects the state (``K.project``).

        Writes sample ``j`` (time ``t0 + j·save_every·τ``) into ``out_x[j]``, ``out_g[j]``
        and ``out_e[j]``; samples after a failure are left untouched.  Returns
        ``(status, steps completed)``.
        """
        ws = make_workspace()
        stages = np.empty((tab_b.shape[0], N2))
        xs = np.empty(N2)
        g = np.empty(ng)
        x = x0.copy()
        j = 0
        t = t0
        for i in range(nsteps + 1):
            if i > 0:
                st = step(x, t, tau, p, law_mat, law_scal, tab_a, tab_b, tab_c, ws, stages, xs)
                if st != 0:
                    return st, i - 1
                t = t0 + i * tau  # from the step count, not accumulated
                if sweeps > 0:
                    st = project(t, x, p, ws, sweeps, tol)
                    if st != 0:
                        return st, i - 1
            if i % save_every == 0:
                save(j, t, x, p, ws, g, out_x, out_g, out_e)
                j += 1
        return 0, nsteps

    keyed_cache(step, spec.key(K.key, "step"))
    keyed_cache(integrate_kernel, spec.key(K.key, "integrate"))
    return Stepper(step, integrate_kernel)


def multipliers_for(model, bound, multiplier: str = "ldl"):
    """``kernel(times, xs, p, law_mat, law_scal, out_lam, out_acc)``: the multipliers λ of
    (3.11) and the accelerations v̇ at stored states (memoized on the model)."""
    spec = Spec("multipliers", law=bound.code, law_fn=bound.fn, multiplier=multiplier)
    return memo(model, spec,
                lambda: _build_multipliers(kernels_for(model, bound, multiplier), spec))


def _build_multipliers(K, spec: Spec):
    rhs, make_workspace = K.rhs, K.make_workspace
    n, r, N2 = K.n, K.m + K.k, 2 * K.n

    @njit(error_model="numpy")
    def multipliers(times, xs, p, law_mat, law_scal, out_lam, out_acc):
        """Row ``j``: λ (the right side of (3.11) after the solve) and v̇ at state
        ``xs[j]``, time ``times[j]``; rows of non-finite states are left as they are."""
        ws = make_workspace()
        x = np.empty(N2)
        xdot = np.empty(N2)
        for j in range(xs.shape[0]):
            finite = True
            for l in range(N2):
                x[l] = xs[j, l]
                finite &= math.isfinite(x[l])
            if not finite:
                continue
            if rhs(times[j], x, p, law_mat, law_scal, ws, xdot) != 0:
                continue
            for i in range(r):
                out_lam[j, i] = ws.rl[i]
            for i in range(n):
                out_acc[j, i] = xdot[n + i]

    return keyed_cache(multipliers, spec.key(K.key))

#: the adaptive attempt's sums over the state are written out per component while the
#: state's size times the stages is at most this (a loop left in the attempt keeps the lane
#: loop around it from vectorizing; above it the code would grow with the model)
UNROLL_MAX_TERMS = 200
