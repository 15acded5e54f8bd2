"""The compiled code as LLVM sees it: no factorization compiled for an identity mass,
member and lane loops that vectorize, a step loop that allocates nothing."""

from __future__ import annotations

import re

import numpy as np
import pytest
from numba import njit

import stabdae
from conftest import compiled_only, load_scene
from models.toy import unit_pendulum
from stabdae._laws import bind_law
from stabdae.engine.rhs import kernels_for
from stabdae.engine.rk.steps import stepper_for


@njit
def mass_identity(t, q, p, out):
    out[0, 0] = 1.0
    out[0, 1] = 0.0
    out[1, 0] = 0.0
    out[1, 1] = 1.0


def _divisions(model) -> int:
    """Divisions in the compiled RK step, where the rhs is inlined (Euler: once); the
    L D Lᵀ factorizations divide once per pivot and nothing else in the rhs divides.
    The caller switches the kernel cache off: a kernel loaded from disk brings no LLVM IR."""
    stabdae.integrate(model, None, stabdae.baumgarte(10.0), "euler", 0.1, 0.1)  # compile
    step = stepper_for(model, bind_law(stabdae.baumgarte(10.0), model)).step
    ir = next(iter(step.inspect_llvm().values()))
    return len(re.findall(r"= fdiv (?:[a-z]+ )*double ", ir))


def _arithmetic_counts(fn) -> tuple[int, int]:
    """Arithmetic instructions (and fused multiply-adds) on vectors of doubles and on
    scalar doubles in the LLVM IR of the compiled ``fn``."""
    ir = "\n".join(fn.inspect_llvm().values())
    vector = len(re.findall(r"= (?:fadd|fsub|fmul|fdiv|fneg)[a-z ]* <\d+ x double>", ir))
    vector += len(re.findall(r"call[a-z ]* <\d+ x double> @llvm\.fma\.", ir))
    scalar = len(re.findall(r"= (?:fadd|fsub|fmul|fdiv|fneg)[a-z ]* double ", ir))
    scalar += len(re.findall(r"call[a-z ]* double @llvm\.fma\.f64", ir))
    return vector, scalar


@compiled_only
def test_identity_mass_compiles_no_factorization(monkeypatch):
    """One division (the 1×1 pivot of S) without a mass matrix; with an explicit 2×2
    identity the mass factorization adds its pivots' (LLVM may fold the first, the
    reciprocal of a constant 1.0, when it sees the entry's value through the factor's
    locals: one or two more)."""
    monkeypatch.setenv("STABDAE_CACHE_DIR", "off")
    plain = unit_pendulum("no_mass")
    explicit = unit_pendulum("with_mass", mass=mass_identity)
    assert _divisions(plain) == 1
    assert _divisions(explicit) in (2, 3)


@compiled_only
@pytest.mark.parametrize("scene, scheme_name", [("andrews", "rk4"),
                                                ("bricard_independent", "midpoint")])
def test_member_loop_of_a_dense_model_vectorizes(monkeypatch, scene, scheme_name):
    """Andrews' mechanism (n = 7, dense 7 × 7 mass matrix, 6 constraints) and Bricard's
    (n = 15, 14 constraints, a mass matrix of blocks) take the dense path, written out for
    their patterns.  The ensemble kernel's step of a block (stage by stage for Andrews
    under RK4, its stages written out for Bricard under the midpoint rule; compiled here
    as the kernel compiles it: inlined, with the block's buffers on the stack) vectorizes:
    its arithmetic is on vectors of doubles.  Any loop inside the right-hand side that
    LLVM leaves rolled keeps the member loop around it from being innermost, and it runs
    one member at a time:

    * Andrews: the mass factor's loop over its columns (49 vector arithmetic instructions
      against 917 scalar ones; written out, 1098 against 62);
    * Bricard: the loop of ``ḟ = f_q v`` over the 14 rows of ``f_q`` and that of the law's
      ``A g`` over its 14 × 28 entries (60 against 7773; with ``f_q v`` written out over
      its pattern and Baumgarte's ``A`` as its three factors, 6740 against 207, and a
      member's step about a sixth of the time).

    Compiled on its own rather than inlined, the member loop was vectorized behind
    run-time alias checks with a scalar copy of the right-hand side beside it."""
    from stabdae._schemes import as_scheme
    from stabdae.engine.ensemble.block import BLOCK, ensemble_kernel_for
    from stabdae.engine.workspace import copy_inputs, stack1, stack2, stack_int1

    monkeypatch.setenv("STABDAE_CACHE_DIR", "off")
    model = load_scene(scene)
    assert model.sparse_structure() is None
    bound = bind_law(stabdae.baumgarte(1e3, 1.0), model)
    scheme = as_scheme(scheme_name)
    step = ensemble_kernel_for(model, bound, scheme, BLOCK).block_step
    N2, ng, B, S = 2 * model.n, model.n_residual, BLOCK, len(scheme.b)
    SN2 = S * N2
    NP = len(model.param_names)
    LR, LC = bound.matrix.shape

    @njit(error_model="numpy")
    def block_step(Xa, t, tau, p, law_mat, law_scal, tab_a, tab_b, tab_c, code):
        p_s, lm, ls = stack1(NP), stack2(LR, LC), stack1(1)
        copy_inputs(p, law_mat, law_scal, p_s, lm, ls)
        ta, tb, tc = stack2(S, S), stack1(S), stack1(S)
        for i in range(S):
            tb[i], tc[i] = tab_b[i], tab_c[i]
            for q in range(S):
                ta[i, q] = tab_a[i, q]
        X, XS, KS = stack2(N2, B), stack2(N2, B), stack2(SN2, B)
        GS, Dv, cm, cs = stack2(ng, B), stack2(ng, B), stack_int1(B), stack_int1(B)
        for l in range(N2):
            for j in range(B):
                X[l, j] = Xa[l, j]
        for j in range(B):
            cs[j] = 0
        step(X, t, tau, p_s, lm, ls, ta, tb, tc, XS, KS, GS, cm, cs, Dv)
        for l in range(N2):
            for j in range(B):
                Xa[l, j] = X[l, j]
        for j in range(B):
            code[j] = cs[j]

    X = np.repeat(model.reference_state()[:, None], B, axis=1)
    code = np.zeros(B, dtype=np.int64)
    block_step(X, model.t0, 1e-6, model.param_vector(), bound.matrix, bound.scalars,
               np.asarray(scheme.A, float), np.asarray(scheme.b, float),
               np.asarray(scheme.c, float), code)  # fmt: skip
    assert (code == 0).all() and np.isfinite(X).all()
    # every member starts from the same state: the same step as one trajectory's
    one = stabdae.integrate(model, model.reference_state(), stabdae.baumgarte(1e3, 1.0),
                            scheme, 1e-6, model.t0 + 1e-6, 1e-6)  # fmt: skip
    np.testing.assert_array_equal(X[:, 0], one.x.values[-1])
    vector, scalar = _arithmetic_counts(block_step)
    assert vector > 100 and vector > scalar, (vector, scalar)


@compiled_only
@pytest.mark.parametrize("pair", ["dopri5"])
def test_adaptive_lane_loop_of_a_dense_model_vectorizes(monkeypatch, pair):
    """The adaptive ensemble kernel's loop over its lanes, around one attempted step of
    each (compiled as the kernel compiles it), vectorizes for Andrews' mechanism too:
    the attempt's loops over the 14 state components are written out.  (Left as loops,
    LLVM did not unroll them and the lane loop ran scalar: Andrews' DOP853 ensemble at
    rtol 1e-5 cost 911 core-µs per member, 143 written out, the same bits.)"""
    from stabdae._schemes import embedded_pair
    from stabdae.engine.ensemble.lanes import LANES
    from stabdae.engine.rk.adaptive import _pattern, attempt_for
    from stabdae.engine.workspace import copy_inputs, copy_tableau, stack1, stack2

    monkeypatch.setenv("STABDAE_CACHE_DIR", "off")
    model = load_scene("andrews")
    bound = bind_law(stabdae.baumgarte(1e3, 1.0), model)
    K = kernels_for(model, bound)
    ep = embedded_pair(pair)
    S, S_E = ep.scheme.stages, ep.error.shape[1]
    N2, ng, B = 2 * K.n, K.ng, LANES
    attempt = attempt_for(K.rhs, S, S_E, ep.combined, _pattern(ep), N2, ng)
    stack_workspace = K.stack_workspace
    NP = len(model.param_names)
    LR, LC = bound.matrix.shape

    @njit(error_model="numpy")
    def lanes(Xa, hh, p, law_mat, law_scal, tab_a, tab_b, tab_e, tab_c, Ea):
        # the inputs on the stack, as the kernel has them (no aliasing)
        p_s, lm, ls = stack1(NP), stack2(LR, LC), stack1(1)
        copy_inputs(p, law_mat, law_scal, p_s, lm, ls)
        ta, tb, tc, te = stack2(S, S), stack1(S), stack1(S), stack2(2, S_E)
        copy_tableau(tab_a, tab_b, tab_c, ta, tb, tc)
        for i in range(2):
            for j in range(S_E):
                te[i, j] = tab_e[i, j]
        X, XN, E = stack2(N2, B), stack2(N2, B), stack1(B)
        at = stack1(N2)  # atol, one per state component
        for l in range(N2):
            at[l] = 1e-6
            for lane in range(B):
                X[l, lane] = Xa[l, lane]
        for lane in range(B):  # the kernel's vector pass
            ws = stack_workspace()
            x, k0, xs, xn, kl = stack1(N2), stack1(N2), stack1(N2), stack1(N2), stack1(N2)
            for l in range(N2):
                x[l] = X[l, lane]
                k0[l] = 0.0
            good, nev, e, r = attempt(0.0, hh, x, k0, p_s, lm, ls, ta, tb, te, tc, 1e-6,
                                      at, ws, xs, xn, kl)  # fmt: skip
            for l in range(N2):
                XN[l, lane] = xn[l]
            E[lane] = e if good else -1.0
        for lane in range(B):
            Ea[lane] = E[lane]
            for l in range(N2):
                Xa[l, lane] = XN[l, lane]

    X = np.repeat(model.reference_state()[:, None], B, axis=1)
    E = np.zeros(B)
    tab_e = np.zeros((2, S_E))
    tab_e[: ep.error.shape[0]] = ep.error
    lanes(X, 1e-7, model.param_vector(), bound.matrix, bound.scalars,
          np.asarray(ep.scheme.A, float), np.asarray(ep.scheme.b, float), tab_e,
          np.asarray(ep.scheme.c, float), E)  # fmt: skip
    assert (E >= 0).all() and np.isfinite(X).all()
    vector, scalar = _arithmetic_counts(lanes)
    assert vector > 100 and vector > scalar, (vector, scalar)


@compiled_only
def test_step_loop_allocates_nothing():
    """NRT allocation count is the same for 10 and 10 000 steps: the loop allocates nothing."""
    from numba.core.runtime import _nrt_python, rtsys

    model = load_scene("double_pendulum")
    law = stabdae.baumgarte(10.0)
    for t_end in (0.01, 10.0):  # compile, and fill what the driver caches per run length
        stabdae.integrate(model, None, law, "rk4", 1e-3, t_end, t_end)
    _nrt_python.memsys_enable_stats()
    try:
        counts = []
        for t_end in (0.01, 10.0):
            before = rtsys.get_allocation_stats().alloc
            stabdae.integrate(model, None, law, "rk4", 1e-3, t_end, t_end)
            counts.append(rtsys.get_allocation_stats().alloc - before)
    finally:
        _nrt_python.memsys_disable_stats()
    assert counts[0] == counts[1] and counts[0] > 0


def test_the_kernels_per_member_and_per_state_calls_take_no_reference_counts():
    """The functions the ensemble kernel calls once per member, per measured state or per
    check are compiled without numba's reference counting: each call of one compiled with
    it takes and drops a reference to every heap array it is given, two atomic operations
    on a cache line that every thread writes (the members' outputs are one array for all
    threads): 16 % of a 100-step kernel call of 10⁴ pendulums in ``perf``.  (A member's
    ``α⁰`` goes to its prediction as the shared array and its row, not as a view, for the
    same reason.)"""
    from stabdae.engine import decay
    from stabdae.engine.decay import member, onestep
    from stabdae.engine.ensemble import block

    called = [member.begin, member.finish, member.finish_with_map_pooled, member.predict,
              member.fit_envelope, member.summarize, onestep.map_begin, onestep.bin_flush,
              onestep.end_flush, onestep.windows_flush, onestep.window_flush,
              onestep._store, onestep.map_estimate_pooled, onestep._map_gamma,
              decay.ladder_top, decay.records, block.retire, block.stop_failed,
              block.block_failed]  # fmt: skip
    counted = [f.py_func.__name__ for f in called if f.targetoptions.get("_nrt", True)]
    assert not counted, f"compiled with reference counting: {counted}"
