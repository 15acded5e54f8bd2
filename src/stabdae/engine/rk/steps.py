"""The fixed-step explicit Runge–Kutta step, looped and generated, and the multipliers.

They must give the same bits for the same state (the tests
``test_block_step_and_looped_step_agree_bit_for_bit`` and its siblings pair them):

* the looped step (``step`` of :func:`stepper_for`) applies a tableau ``(A, b, c)`` given as
  run-time arrays (a new scheme never recompiles); ``integrate_kernel`` runs it over a
  trajectory, storing state, residual and energy every ``save_every`` steps, and
  projecting after each step when asked;
* the generated member step (:func:`_member_step_source`, :func:`_member_step`) is Python
  source written for the tableau's pattern of zero / one / other coefficients
  (:func:`tableau_pattern`), its sums over the state written out per component, for the
  ensemble kernel's member loop on small models (:mod:`stabdae.engine.ensemble.block`;
  on larger ones the kernel's block step goes stage by stage, its twin there).

The multiply-adds are fused (:mod:`stabdae.engine.fma`) at the same places in every form
(the looped step, the written-out and the looped member step, :func:`_looped_member_step`,
and the block kernel's stage-by-stage step),
zero coefficients are skipped, sums start from −0.0 and ``1 · k`` is ``k``.  Changing one
step, or adding a kind of coefficient to :func:`tableau_pattern` (today zero, one,
other), means changing all alike: the same terms skipped, the same products fused, in the
same order; the tests run every pattern of the built-in tableaus on both ensemble paths
and must stay bit-equal.
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
from ..source import exec_source
from ..workspace import stack1, stack2

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

#: the member step's sums over the state are written out per component while the state's
#: size times the stages is at most this (a loop left in the step keeps the member loop
#: around it from vectorizing; above it the code would grow with the model)
UNROLL_MAX_TERMS = 200


def _kind(value: float) -> int:
    return 0 if value == 0.0 else 1 if value == 1.0 else 2


def tableau_pattern(scheme) -> tuple:
    """The kind of each coefficient of an explicit scheme: ``(a, b)`` with ``a[s]`` the
    kinds of ``A[s, :s]`` and ``b`` those of the weights; 0 for zero, 1 for one, 2 for
    any other value.  The ensemble kernel is compiled for one pattern and leaves the
    zero terms out and the multiplications by one (exact) away; the values stay run-time
    arrays."""
    A, b = np.asarray(scheme.A), np.asarray(scheme.b)
    a = tuple(tuple(_kind(A[s, q]) for q in range(s)) for s in range(b.shape[0]))
    return a, tuple(_kind(w) for w in b)


def _member_step_source(pattern, n2: int | None = None) -> str:
    """Python source of one member's explicit Runge–Kutta step with the stages written
    out, the zero terms of ``pattern`` left out and the factors equal to one dropped.
    It returns the worst status of its right-hand sides and leaves the residual ``g`` at
    the step's start in ``gv`` (read from the first stage's evaluation, for the decay
    measurement); the new state's finiteness is left to the kernel's checks (a non-finite
    state stays non-finite).

    Written out rather than looped, so that the body has no inner loops left around the
    inlined right-hand sides and the member loop around it vectorizes for any number of
    stages (LLVM only vectorizes innermost loops and does not unroll a loop this large);
    with the state's size ``n2`` given, the sums over the state are written out per
    component too while ``n2`` times the stages is at most ``UNROLL_MAX_TERMS`` (Andrews'
    14 components with DOP853's 12 stages: the loops were left, and the member loop ran
    scalar), loops over ``N2`` otherwise.
    The results are those of the looped ``step`` (:func:`stepper_for`) bit for bit: it skips
    the same zero terms, starts its sums from −0.0 (exact), and ``1.0 * x`` is ``x``.
    """
    a_kind, b_kind = pattern
    stages = len(b_kind)

    def written(statement):  # per component where that stays small (see the docstring)
        if n2 is None or n2 * stages > UNROLL_MAX_TERMS:
            return ["    for l in range(N2):", f"        {statement}"]
        return [f"    {statement.replace('[l]', f'[{l}]')}" for l in range(n2)]

    def stage_arg(s):  # x + Σ (τ a_sq) k_q, fused, in the order of ``step``; τ · 1 is τ
        e = "xk[l]"
        for q in range(s):
            if a_kind[s][q]:
                c = "tau" if a_kind[s][q] == 1 else f"(tau * tab_a[{s}, {q}])"
                e = f"fma({c}, k{q}[l], {e})"
        return e

    def weights():  # Σ b_s k_s from −0.0 as ``step`` sums it: b k + (−0) is b k, 1 · k is k
        e = None
        for s in range(stages):
            if not b_kind[s]:
                continue
            if e is None:
                e = f"k{s}[l]" if b_kind[s] == 1 else f"tab_b[{s}] * k{s}[l]"
            else:
                e = f"({e} + k{s}[l])" if b_kind[s] == 1 else f"fma(tab_b[{s}], k{s}[l], {e})"
        return e or "-0.0"

    lines = ["def member_step(t, xk, tau, p, law_mat, law_scal, tab_a, tab_b, tab_c, ws, xs, xn,",
             "                gv):"]
    lines += [f"    k{s} = stack1(N2)" for s in range(stages)]
    for s in range(stages):
        arg = "xk"
        if any(a_kind[s][:s]):
            lines += written(f"xs[l] = {stage_arg(s)}")
            arg = "xs"
        lines.append(
            f"    c{s} = rhs(t + tab_c[{s}] * tau, {arg}, p, law_mat, law_scal, ws, k{s})"
        )
        if s == 0:  # g(x_k): the first stage has just evaluated it
            lines += ["    for l in range(NG):", "        gv[l] = ws.g[l]"]
    lines += written(f"xn[l] = fma(tau, {weights()}, xk[l])")
    lines += [
        "    return " + ("max(" + ", ".join(f"c{s}" for s in range(stages)) + ")"
                        if stages > 1 else "c0"),
    ]  # fmt: skip
    return "\n".join(lines) + "\n"


#: tableaus of more stages run the looped member step (:func:`_looped_member_step`): the
#: written-out step inlines the right-hand side once per stage and its compile time grows
#: with the square of the stages (the pendulum's first ensemble: 13 s at 4 stages, 26 s at
#: 16, 90 s at 32); the built-in schemes (DOP853: 12) stay written out
WRITTEN_MAX_STAGES = 16


def _member_step(rhs, N2: int, NG: int, pattern):
    if len(pattern[1]) > WRITTEN_MAX_STAGES:
        return _looped_member_step(rhs, N2, NG, len(pattern[1]))
    label = "member_step_" + "".join(map(str, sum(pattern[0], ()) + pattern[1]))
    ns = exec_source(_member_step_source(pattern, N2), label,
                     {"rhs": rhs, "stack1": stack1, "N2": N2, "NG": NG, "fma": fma})  # fmt: skip
    # inlined by numba into the kernel's member loop (its one call), not compiled on its
    # own and then again inside the kernel: half a second of a new model's first ensemble
    return njit(inline="always", error_model="numpy")(ns["member_step"])


def _looped_member_step(rhs, N2: int, NG: int, S: int):
    """The member step of :func:`_member_step_source` for a tableau of ``S`` stages as
    loops, with one inlined right-hand side: what ``step`` (:func:`stepper_for`) does,
    its zero terms skipped at run time, so the bits are the same; every stage is
    evaluated and the worst status returned, as in the written-out step.  The member
    loop around it does not vectorize; its compile time no longer grows with ``S``."""

    @njit(inline="always", error_model="numpy")
    def member_step(t, xk, tau, p, law_mat, law_scal, tab_a, tab_b, tab_c, ws, xs, xn, gv):
        k = stack2(S, N2)
        worst = 0
        for i in range(S):
            for l in range(N2):
                acc = xk[l]
                for j in range(i):
                    if tab_a[i, j] != 0.0:
                        acc = fma(tau * tab_a[i, j], k[j, l], acc)
                xs[l] = acc
            worst = max(worst, rhs(t + tab_c[i] * tau, xs, p, law_mat, law_scal, ws, k[i]))
            if i == 0:  # g(x_k): the first stage has just evaluated it
                for l in range(NG):
                    gv[l] = ws.g[l]
        for l in range(N2):
            acc = -0.0
            for i in range(S):
                if tab_b[i] != 0.0:
                    acc = fma(tab_b[i], k[i, l], acc)
            xn[l] = fma(tau, acc, xk[l])
        return worst

    return member_step
