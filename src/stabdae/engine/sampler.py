"""Initial constraint perturbations α⁰ (Monte Carlo studies of the manifold's stability).

From the consistent reference state ``x*`` (``g(x*) = 0``) each member is displaced by the
minimum-norm step ``x⁰ = x* + G⁺α⁰``, ``G = ∂g/∂x`` ((2m + k) × 2n), ``G⁺ = Gᵀ(GGᵀ)⁻¹``
(the paper's (2.9) idea), then corrected by steps ``x ← x + G⁺(α⁰ − g(x))`` until
``g(x⁰) = α⁰``: with ``G`` at ``x*`` (formed once for every member) while each step at
least quarters the error, which for small α⁰ takes a step or two, and with ``G`` at the
current state (Gauss–Newton) from the first step that does not.  ``G`` is formed by
central differences of the compiled residual; an approximate Jacobian changes the path,
not the target, since the residual itself is exact.  Random numbers come from a
counter-based generator in Python (:func:`draw_alphas`: member ``i``'s from the seed and
``i`` alone) and enter the compiled code as arrays, so the result depends on neither the
thread count nor the members run beside it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.special import ndtri

from .._codes import Status
from .cache import Spec, keyed_cache, memo, tag
from .jit import internal
from .linalg import ldl_inplace, ldl_solve_inplace
from .rhs import LAW_CONSTANT, kernels_for

#: relative accuracy asked of ``g(x⁰) = α⁰``.  Below ``‖α⁰‖ ≈ 1e-4`` it cannot be met in
#: double precision (evaluating g near x* cancels terms of size |x|²), so a member whose
#: Newton steps stall at roundoff is accepted when ``|g − α⁰| ≤ 1e-12|α⁰| + ROUNDOFF·ε·|x|²``
#: (ε the machine epsilon); otherwise it gets ``Status.SAMPLING_FAILED``.
SAMPLING_RTOL = 1e-12
ROUNDOFF = 64.0
MAX_NEWTON = 25
#: members per work item of the sampler
CHUNK = 64

_FAILED = int(Status.SAMPLING_FAILED)


class _Unstabilized:
    """The bound form of the law ``A = 0``: the sampler evaluates only the residual, which
    does not depend on the law (the same compiled kernels as any constant law)."""

    code = LAW_CONSTANT
    fn = None


def sampler_for(model):
    """The compiled perturbation sampler of ``model`` (memoized)."""
    spec = Spec("sampler")
    return memo(model, spec, lambda: build_sampler(kernels_for(model, _Unstabilized), spec))


def residual_rows_for(model):
    """The compiled ``g(x_i, t0)`` of rows of states of ``model`` (memoized)."""
    spec = Spec("residual_rows")
    return memo(model, spec,
                lambda: build_residual_rows(kernels_for(model, _Unstabilized), spec))


def build_sampler(K, spec: Spec):
    """Compiled Gauss–Newton placement for the kernels ``K``, over chunks of 64 members
(:data:`CHUNK`; run on threads by :func:`.threads.run_chunks`)."""
    residual, make_workspace = K.residual, K.make_workspace
    N2, ng = 2 * K.n, K.ng
    eps3 = np.finfo(np.float64).eps ** (1.0 / 3.0)
    eps = np.finfo(np.float64).eps

    @internal(error_model="numpy")
    def g_at(t0, x, p, ws, g):
        """``g(x, t0)`` into ``g``: the residual in a function of its own, which LLVM
        compiles once for the sampler's three calls (inlined at each, as it is into the
        ensemble kernel's steps, it went through LLVM three times; a call costs nothing
        beside the Newton steps)."""
        residual(t0, x, p, ws, g)

    @internal(error_model="numpy")
    def jacobian(x, t0, p, ws, xp, gpm, G, GGt):
        """``G = ∂g/∂x`` at ``x`` by central differences and the L D Lᵀ factor of
        ``G Gᵀ`` into ``GGt``; whether the factorization failed."""
        for l in range(N2):
            h = eps3 * max(1.0, abs(x[l]))
            for k in range(N2):
                xp[k] = x[k]
            xp[l] = x[l] + h
            g_at(t0, xp, p, ws, gpm[0])
            xp[l] = x[l] - h
            g_at(t0, xp, p, ws, gpm[1])
            for i in range(ng):
                G[i, l] = (gpm[0, i] - gpm[1, i]) / (2.0 * h)
        for i in range(ng):
            for k in range(i + 1):
                s = 0.0
                for l in range(N2):
                    s += G[i, l] * G[k, l]
                GGt[i, k] = s
        return ldl_inplace(GGt, ng, 1e-14) != 0

    @njit(inline="always")
    def place(x_start, t0, p, alpha, newton, ws, G0, GGt0, bad0, G, GGt, r, y, xp, gp, gpm,
              x):  # fmt: skip
        """Place one member from ``x_start`` (the reference state, whose Jacobian ``G0``
        and factor ``GGt0`` are given, ``bad0`` when that factorization failed); returns
        its status, with ``gp = g(x)`` at the state ``x`` it leaves (without ``newton``:
        ``x_start`` itself, evaluated).  The steps use the reference state's Jacobian
        (the same for every member: the first step is the minimum-norm one) while each
        at least quarters the error, then the Jacobian at the current state (Gauss–Newton
        proper) at every step.
        (The residual is called from one place here and two in :func:`jacobian`, each a
        call of :func:`g_at`.)"""
        for l in range(N2):
            x[l] = x_start[l]
        amax = 0.0
        if newton:
            for i in range(ng):
                amax = max(amax, abs(alpha[i]))
        stalled = False  # the last step was roundoff-limited
        own = False  # Jacobian at the current state (else the reference state's)
        prev = math.inf
        xnorm = 0.0
        it = 0
        while True:
            g_at(t0, x, p, ws, gp)
            if not newton:
                return 0
            err = 0.0
            for i in range(ng):
                r[i] = alpha[i] - gp[i]
                err = max(err, abs(r[i]))
            if err <= SAMPLING_RTOL * amax:
                return 0
            if stalled:  # accept what evaluating g allows
                if err <= SAMPLING_RTOL * amax + ROUNDOFF * eps * max(1.0, xnorm) ** 2:
                    return 0
                return _FAILED
            if it == MAX_NEWTON:
                return _FAILED
            it += 1
            if not own and err > 0.25 * prev:  # the fixed Jacobian converges too slowly
                own = True
            prev = err
            if own:
                if jacobian(x, t0, p, ws, xp, gpm, G, GGt):
                    return _FAILED
            elif bad0:
                return _FAILED
            Gu = G if own else G0
            Fu = GGt if own else GGt0
            for i in range(ng):
                y[i] = r[i]
            ldl_solve_inplace(Fu, ng, y)
            step = 0.0
            xnorm = 0.0
            for l in range(N2):
                s = 0.0
                for i in range(ng):
                    s += Gu[i, l] * y[i]
                x[l] += s
                step = max(step, abs(s))
                xnorm = max(xnorm, abs(x[l]))
            stalled = step <= 4.0 * eps * max(1.0, xnorm)

    @njit(nogil=True, error_model="numpy")
    def sample_kernel(x_ref, t0, p, alphas, newton, x_out, alpha_out, status, c_lo, c_hi):
        """Place the members of chunks ``c_lo … c_hi − 1`` (64 members each) from
        ``x_ref`` at the targets ``alphas``; without ``newton``, only evaluate ``g`` at the
        rows of ``x_out`` (``alphas`` not read: the residual rows of a model whose
        sampler is compiled, without a kernel of their own)."""
        M = x_out.shape[0]
        for c in range(c_lo, c_hi):
            ws = make_workspace()
            nn = ng if newton else 0  # (the Newton steps' matrices: none to evaluate)
            G0 = np.empty((nn, N2))
            GGt0 = np.empty((nn, nn))
            G = np.empty((nn, N2))
            GGt = np.empty((nn, nn))
            r = np.empty(ng)
            y = np.empty(ng)
            xp = np.empty(N2)
            gp = np.empty(ng)
            gpm = np.empty((2, ng))
            x = np.empty(N2)
            bad0 = False
            if newton:  # the reference state's Jacobian, shared by the chunk's members
                for l in range(N2):
                    x[l] = x_ref[l]
                bad0 = jacobian(x, t0, p, ws, xp, gpm, G0, GGt0)
            for j in range(c * CHUNK, min(M, (c + 1) * CHUNK)):
                x_start = x_ref if newton else x_out[j]
                status[j] = place(x_start, t0, p, alphas[j], newton, ws, G0, GGt0, bad0, G,
                                  GGt, r, y, xp, gp, gpm, x)  # fmt: skip
                if newton:
                    for l in range(N2):
                        x_out[j, l] = x[l]
                for i in range(ng):
                    alpha_out[j, i] = gp[i]

    key = spec.key(K.key)
    tag(key, place, jacobian, g_at)
    return keyed_cache(sample_kernel, key)


def build_residual_rows(K, spec: Spec):
    """Compiled ``g(x_i, t0)`` for the rows of an array of states, over chunks of
    :data:`CHUNK` rows."""
    residual, make_workspace = K.residual, K.make_workspace
    N2, ng = 2 * K.n, K.ng

    @njit(nogil=True, error_model="numpy")
    def residual_rows(x, t0, p, out, c_lo, c_hi):
        ws = make_workspace()
        g = np.empty(ng)
        xs = np.empty(N2)
        for j in range(c_lo * CHUNK, min(x.shape[0], c_hi * CHUNK)):
            for l in range(N2):
                xs[l] = x[j, l]
            residual(t0, xs, p, ws, g)
            for i in range(ng):
                out[j, i] = g[i]

    return keyed_cache(residual_rows, spec.key(K.key))


def member_key(seed) -> np.ndarray:
    """The Philox key (two 64-bit words) of ``seed``: a non-negative integer (through
    :class:`numpy.random.SeedSequence`) or a ``numpy.random.Generator`` (two words drawn
    from it)."""
    if isinstance(seed, np.random.Generator):
        return seed.integers(0, 2**64, size=2, dtype=np.uint64, endpoint=False)
    return np.random.SeedSequence(int(seed)).generate_state(2, np.uint64)


def draw_alphas(ng: int, members: int, radius, seed, start: int = 0) -> np.ndarray:
    """Targets α⁰ of the members ``start … start + members − 1`` (members × ng): directions
    uniform on the unit sphere, scaled so that the max-norm ``‖α⁰‖∞`` (the paper's norm)
    is log-uniform in ``radius = (low, high)``.

    Member ``i``'s target is a function of ``(seed, i)`` alone (common random numbers):
    its ``ng + 1`` uniforms are the outputs of the counter-based Philox4x64 generator
    (Salmon, Moraes, Dror and Shaw, "Parallel random numbers: as easy as 1, 2, 3", SC
    2011; :class:`numpy.random.Philox`) at its own counters ``i·B … (i + 1)·B − 1``
    (``B = ⌈(ng + 1)/4⌉``), turned into normals by the inverse normal distribution
    function.  So member ``i`` is the same at every grid point of a study, in any batch
    of members, at any thread count, and an ensemble extended by more members keeps the
    ones it had."""
    low, high = radius
    per = ng + 1
    blocks = -(-per // 4)
    raw = np.random.Philox(key=member_key(seed), counter=int(start) * blocks).random_raw(
        4 * blocks * members).reshape(members, 4 * blocks)[:, :per]  # fmt: skip
    # the 53 high bits, centred in their interval: uniforms in the open interval (0, 1)
    u = ((raw >> np.uint64(11)).astype(np.float64) + 0.5) * 2.0**-53
    d = ndtri(u[:, :ng])
    d /= np.max(np.abs(d), axis=1, keepdims=True)
    if low == high:
        r = np.full(members, float(low))
    else:
        r = np.exp(math.log(low) + (math.log(high) - math.log(low)) * u[:, ng])
    return d * r[:, None]
