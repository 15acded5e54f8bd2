"""The stabilized right-hand side (3.1), (3.11) compiled for one model and one law kind.

Per evaluation (the paper's §3)::

    γ      = forces(t, q, v)                    (3.3)
    F      = [f_q ; h_v]                        (r × n)
    g      = (f, f_q v + f_t, h)                (3.2)
    c      = (f_accel ; h_q v + h_t)            convective terms of (f̈, ḣ)
    M      = L D Lᵀ                            skipped for identity mass
    Y      = M⁻¹ Fᵀ,  z = M⁻¹ γ
    S      = F Y                                (r × r, SPD when F has full row rank)
    S λ    = A g − s,   s = c − F z             (3.11)
    v̇      = Y λ − z,   q̇ = v

so that ``(f̈; ḣ) = S λ + s = A g`` and the exact flow obeys ``ġ = Ã g`` (3.9).

A model with a kinematic map ``q̇ = T(q, t) v`` (quasi-velocities: a rigid body's angular
velocity beside its orientation's quaternion) takes F's holonomic rows along the map,
``f_q T``, its velocity products ``h_q T v``, and ``q̇ = T v``; every other line is the
same, so the residual obeys the same law.  Such a model takes the dense path (the map
fills the patterns the sparse and written-out paths are built on).

The kernel factory closes over the model's dispatchers and over compile-time flags (mass
present, m, k, time dependence, law kind).  Absent pieces are replaced by no-op stubs
behind branches on those constants, which LLVM removes: an identity-mass model compiles
no factorization of ``M``, a model with ``k = 0`` no nonholonomic block, a scleronomic
model no ``f_t`` call.  The constraint part takes one of three forms: the sparse path
(a diagonal or absent mass matrix and sparse constraints: index lists, :mod:`.sparsity`),
the dense path written out without the model's structural zeros (:func:`_structured`:
a mass matrix of blocks, few couplings), or the dense loops.  Every buffer lives in a
named workspace (:mod:`.workspace`) allocated once per integration; an evaluation
allocates nothing and returns a :class:`~stabdae.Status` code.

Sums start from ``-0.0``, the exact identity of IEEE addition, so LLVM drops the start
(``0.0 + x`` is not ``x`` for ``x = -0.0`` and would stay in the vectorized loop as one
addition per sum).
"""

from __future__ import annotations

import ast
import inspect
import math
import textwrap
from collections import namedtuple
from typing import NamedTuple

import numba
import numpy as np
from numba import njit

from .._codes import LawKind, Status
from .cache import Spec, fingerprint, memo, optional_fingerprint, tag
from .emit import emitted_source
from .fma import fma
from .jit import JIT, internal, python_function
from .linalg import (
    UNROLL_MAX_OPS,
    _written_out,
    factor_ops,
    ldl_factor_for,
    ldl_inplace,
    ldl_solve_columns,
    ldl_solve_columns_for,
    ldl_solve_for,
    ldl_solve_inplace,
    ldl_sparse_inplace,
    ldl_sparse_solve,
    pinv_solve_sym,
    pivot_tolerance,
    solve_pattern,
)
from .workspace import builders

# Compile-time law kinds of the right-hand side, as plain ints (the table, with what each
# means, is :class:`stabdae._codes.LawKind`; a law binds to one, :mod:`stabdae._laws`)
LAW_CONSTANT = int(LawKind.CONSTANT)
LAW_THEOREM5 = int(LawKind.THEOREM5)  # A22 = −k W(x) L,  W = h_v h_vᵀ  (m = 0)
LAW_USER = int(LawKind.USER)
LAW_ACPR = int(LawKind.ACPR)  # A = 0 plus the correction −γ_s D (G D)⁻¹ g
#: a constant A whose blocks are multiples of the identity (Baumgarte's), given by its three
#: factors (f, ḟ, h) as a 1 × 3 matrix: the same sums as LAW_CONSTANT without their zero
#: terms (2m + k products instead of r × (2m + k), in loops short enough for LLVM to
#: unroll inside the ensemble kernel's vectorized member loop)
LAW_SCALAR_BLOCKS = int(LawKind.SCALAR_BLOCKS)

# Relative pivot thresholds of the L D Lᵀ factorizations: a pivot below RTOL·max|diag|
# reports a singular matrix instead of producing huge or NaN multipliers.
MASS_RTOL = 1e-14
S_RTOL = 1e-12
#: eigenvalues of S below this fraction of the largest are zero for the least-squares
#: (pseudo-inverse) multiplier of redundant constraints
S_PINV_RTOL = 1e-10
#: the multiplier solves of (3.11): L D Lᵀ (a singular S stops with a status) or the
#: pseudo-inverse (redundant constraints: least-squares λ, integration goes on)
MULTIPLIERS = ("ldl", "lstsq")

_OK = int(Status.OK)
_SINGULAR_S = int(Status.SINGULAR_S)
_MASS_NOT_SPD = int(Status.MASS_NOT_SPD)


@njit(cache=True, forceinline=True)
def _noop3(a, b, out):  # stands in for an absent written-out piece
    pass


@njit(cache=True, forceinline=True)
def _noop4(a, b, c, out):  # stands in for an absent (t, q, p, out) piece
    pass


@njit(cache=True, forceinline=True)
def _noop5(a, b, c, d, out):  # stands in for an absent (t, q, v, p, out) piece
    pass


@njit(cache=True)
def _nan_energy(t, q, v, p):
    return math.nan


@njit(cache=True, forceinline=True)
def _load_Ft(fq, hv, Y, m, rows, n):
    """``Y[:, :rows] = Fᵀ`` for the first ``rows`` rows of ``F = [f_q ; h_v]``."""
    for i in range(rows):
        for j in range(n):
            Y[j, i] = fq[i, j] if i < m else hv[i - m, j]


@njit(cache=True, forceinline=True)
def _gram_lower(fq, hv, Y, S, m, rows, n):
    """The lower triangle of ``S = F Y`` for the first ``rows`` rows of ``F``."""
    for i in range(rows):
        for c in range(i + 1):
            s = -0.0
            for j in range(n):
                fij = fq[i, j] if i < m else hv[i - m, j]
                s = fma(fij, Y[j, c], s)
            S[i, c] = s


@njit(cache=True, forceinline=True, error_model="numpy")
def _diagonal_inverse(Mw, n):
    """``M[j, j] ← 1 / M[j, j]`` for a diagonal mass matrix; whether a pivot fails the test
    of :func:`.linalg.ldl_inplace` (the same numbers as its factor of a diagonal M)."""
    tol = pivot_tolerance(Mw, n, MASS_RTOL)
    bad = False
    for j in range(n):
        d = Mw[j, j]
        bad |= not (d > tol)
        Mw[j, j] = 1.0 / d
    return bad


_NO_INDEX = np.zeros(1, dtype=np.int64)

Kernels = namedtuple(
    "Kernels", "rhs residual energy project make_workspace stack_workspace n m k ng key size"
)
Kernels.__doc__ = """The compiled pieces of one (model, law kind); ``key`` identifies what they
were compiled from (:mod:`.cache`), ``None`` when a function has no source file; ``size``
the right-hand side's straight-line code (:func:`rhs_size`)."""

#: projection after each step: name -> (sweeps per level, tolerance); see ``project``
PROJECTIONS = {None: (0, 0.0), "post": (1, 0.0), "full": (8, 0.0)}


def _rejit(fn, absent):
    """The user's function recompiled from its ``py_func`` with the library's flags.

    ``error_model="numpy"`` drops the zero-division branches that a function compiled
    with the default error model keeps (they silently stop LLVM from vectorizing the
    ensemble kernel's member loop; a division by zero becomes inf/NaN and then a status),
    and ``forceinline=True`` marks it ``alwaysinline`` for LLVM, so that it disappears
    into its callers and the workspace buffers it writes can live in registers.  (Not
    ``inline="always"``: inlining at the numba IR level re-types the caller for every
    call site and multiplied the ensemble kernel's compile time, see :mod:`.ensemble`.)
    Straight-line code, such as ``stabdae generate`` writes, becomes an intrinsic of
    :func:`.emit.emitted_source` instead (the same numbers, a fraction of numba's compile
    time), callable from compiled code only.
    """
    if fn is None:
        return absent
    pyfunc = python_function(fn)
    if JIT and not numba.config.BOUNDSCHECK:
        # straight-line code (a generated model's) without numba's typing per statement,
        # written into its callers (no function of its own for numba and LLVM to compile);
        # its indices are constants, which construction ran in range, but checked kernels
        # asked for (NUMBA_BOUNDSCHECK=1) are numba's, every index checked
        try:
            return emitted_source(pyfunc, f"{pyfunc.__name__}_emitted")
        except NotImplementedError:
            pass  # numba compiles it as it is
    return njit(error_model="numpy", forceinline=True)(pyfunc)


def _inline(fn):
    """The written-out routine ``fn`` (:func:`.linalg._written_out`) as the intrinsic that
    writes it into its caller, where it has one; else ``fn``."""
    return getattr(fn, "emitted", fn)


def kernels_for(model, bound, multiplier: str = "ldl") -> Kernels:
    """Compiled ``rhs``, ``residual`` and ``energy`` for ``model`` under the law's kind.

    Memoized on the model, since every new closure is a new compilation.  Numeric law data
    (``A``, ``L``, gains) are runtime arguments, so sweeping them reuses the same kernels.
    ``acpr`` laws need ``multiplier="ldl"`` (the drivers check it).
    """
    spec = Spec("rhs", law=bound.code, law_fn=bound.fn, multiplier=multiplier)
    return memo(model, spec, lambda: _build(model, spec))


class Pieces(NamedTuple):
    """The compiled pieces of a model that no law touches (:func:`_pieces`): its sizes and
    which functions it has, its functions with the library's flags, ``residual``,
    ``project``, ``energy``, the workspace builders, the sparse path's helpers and index
    lists (unused, and typed placeholders, on the dense path), the dense path's ``h_q v``
    written out (:func:`_velocity_products`), and ``key``, the on-disk
    key of the model's part (None: a function without a source file)."""

    n: int
    m: int
    k: int
    r: int
    ng: int
    HAS_MASS: bool
    HAS_HT: bool
    HAS_KIN: bool
    SPARSE: bool
    mass: object
    forces: object
    f_accel: object
    h_t: object
    residual: object
    project: object
    energy: object
    make_workspace: object
    stack_workspace: object
    sparse_Y: object
    sparse_S: object
    hq_v: object
    FPTR: np.ndarray
    FCOL: np.ndarray
    CPTR: np.ndarray
    CROW: np.ndarray
    HQPTR: np.ndarray
    HQCOL: np.ndarray
    LPTR: np.ndarray
    LCOL: np.ndarray
    LTPTR: np.ndarray
    LROW: np.ndarray
    key: str | None


def _statements(fn) -> int:
    """The statements of ``fn``'s source (0 without a source)."""
    try:
        source = textwrap.dedent(inspect.getsource(python_function(fn)))
    except (OSError, TypeError):
        return 0
    return sum(isinstance(node, ast.stmt) for node in ast.walk(ast.parse(source))) - 1


def rhs_size(model, plan) -> int:
    """How much straight-line code the right-hand side inlines: the statements of the
    model's functions (a generated model's: about one operation each) and the
    multiply-adds of its written-out linear algebra (``plan``, or None).  The ensemble
    kernel steps the block stage by stage above a size (:mod:`.ensemble.block`)."""
    return sum(_statements(fn) for fn in model.functions.values()) + (plan.ops if plan else 0)


class Plan(NamedTuple):
    """The dense path's linear algebra written out for a model's structural zeros
    (:func:`_structured`); ``ops`` its operations (multiply-adds and copies), all pieces
    together."""

    factor_M: object
    solve_M: object
    solve_columns_M: object
    factor_S: object
    solve_S: object
    load_Ft: object
    gram: object
    add_Fz: object
    accel: object
    ops: int


def _pieces(model, sparse: bool) -> Pieces:
    """The compiled pieces of ``model`` that no law touches: its functions with the
    library's flags, the workspace, ``residual``, ``project``, ``energy`` (and the sparse
    path's helpers where ``sparse``), shared by the kernels of every law kind (the sampler
    and a run under Baumgarte's law compile them once)."""
    # These closures are inlined into the kernels that Python calls (integrate, sample,
    # ensemble); those get an explicit on-disk cache key from :mod:`._cache`.
    # Compile-time constants of the closures.
    n, m, k = model.n, model.m, model.k
    r, ng = m + k, 2 * m + k
    fns = model.functions
    HAS_MASS = "mass" in fns
    HAS_FT = "f_t" in fns
    HAS_HT = "h_t" in fns
    HAS_KIN = "kinematics" in fns
    mass = _rejit(fns.get("mass"), _noop4)
    forces = _rejit(fns["forces"], None)
    f_fn = _rejit(fns.get("f"), _noop4)
    f_q = _rejit(fns.get("f_q"), _noop4)
    f_t = _rejit(fns.get("f_t"), _noop4)
    f_accel = _rejit(fns.get("f_accel"), _noop5)
    h_fn = _rejit(fns.get("h"), _noop5)
    h_q = _rejit(fns.get("h_q"), _noop5)
    h_v = _rejit(fns.get("h_v"), _noop5)
    h_t = _rejit(fns.get("h_t"), _noop5)
    kinematics = _rejit(fns.get("kinematics"), _noop4)
    # inlined like the other pieces: a separately compiled user function would carry a
    # symbol name shared by every model's "energy" (see _cache.tag)
    energy_fn = _rejit(model.energy, _nan_energy)
    make_workspace, stack_workspace = builders(n, m, k, HAS_KIN)
    st = model.sparse_structure() if sparse else None
    SPARSE = st is not None
    # the dense path's products by F's velocity columns written out over the patterns' non-zeros
    fq_v, hq_v = (_noop4, _noop4) if SPARSE else _velocity_products(model, HAS_FT, HAS_HT)
    FQ_V, HQ_V = fq_v is not _noop4, hq_v is not _noop4
    if SPARSE:
        FPTR, FCOL, CPTR, CROW = st.fptr, st.fcol, st.cptr, st.crow
        HQPTR, HQCOL = st.hqptr, st.hqcol
        SI, SC, SPTR, SJ = st.si, st.sc, st.sptr, st.sj
        LPTR, LCOL, OPTR, OQ, LTPTR, LROW = st.lptr, st.lcol, st.optr, st.oq, st.ltptr, st.lrow
    else:  # never read (the branches on SPARSE are pruned), but typed
        FPTR = FCOL = CPTR = CROW = HQPTR = HQCOL = SI = SC = SPTR = SJ = _NO_INDEX
        LPTR = LCOL = OPTR = OQ = LTPTR = LROW = _NO_INDEX

    @internal(forceinline=True, error_model="numpy")
    def sparse_Y(t, q, p, ws, rows):
        """The sparse path's ``Y = M⁻¹ Fᵀ`` for the first ``rows`` rows of ``F`` (M
        diagonal, its inverse left on the diagonal of ``ws.M``, or absent); whether M's
        test failed."""
        fq, hv, Y, Mw = ws.fq, ws.hv, ws.Y, ws.M
        bad = False
        if HAS_MASS:
            mass(t, q, p, Mw)
            bad = _diagonal_inverse(Mw, n)
        for j in range(n):
            for e in range(CPTR[j], CPTR[j + 1]):
                i = CROW[e]
                if i < rows:
                    fij = fq[i, j] if i < m else hv[i - m, j]
                    Y[j, i] = fij * Mw[j, j] if HAS_MASS else fij
        return bad

    @internal(forceinline=True, error_model="numpy")
    def sparse_S(ws, rows):
        """The sparse path's ``S = F Y`` on its factor's pattern (the fill starts from
        zero) and its L D Lᵀ factor, for the first ``rows`` rows of F (the leading block's
        fill is the leading block of the fill); whether a pivot failed."""
        fq, hv, Y, S = ws.fq, ws.hv, ws.Y, ws.S
        for e in range(SI.shape[0]):
            i = SI[e]
            c = SC[e]
            if i < rows:
                s = -0.0
                for o in range(SPTR[e], SPTR[e + 1]):
                    j = SJ[o]
                    fij = fq[i, j] if i < m else hv[i - m, j]
                    s = fma(fij, Y[j, c], s)
                S[i, c] = s
        return ldl_sparse_inplace(S, rows, S_RTOL, LPTR, LCOL, OPTR, OQ) != 0

    @internal(forceinline=True)
    def residual(t, x, p, ws, g):
        """g = (f, f_q v + f_t, h) of (3.2) into ``g``; fills ws q, v, f_q, h_v, h_q (and,
        with a kinematic map, T, q̇ = T v and F's holonomic rows f_q T in ``fq``)."""
        q, v, fq, hv, hq, sm, sk = ws.q, ws.v, ws.fq, ws.hv, ws.hq, ws.sm, ws.sk
        for i in range(n):
            q[i] = x[i]
            v[i] = x[n + i]
        if HAS_KIN:
            Tw, qd, fr = ws.T, ws.qd, ws.fr
            kinematics(t, q, p, Tw)
            for i in range(n):
                s = -0.0
                for j in range(n):
                    s = fma(Tw[i, j], v[j], s)
                qd[i] = s
        if m > 0:
            f_fn(t, q, p, sm)
            for i in range(m):
                g[i] = sm[i]
            if HAS_KIN:  # F's holonomic rows along the map: ḟ = f_q T v + f_t
                f_q(t, q, p, fr)
                for i in range(m):
                    for j in range(n):
                        s = -0.0
                        for c in range(n):
                            s = fma(fr[i, c], Tw[c, j], s)
                        fq[i, j] = s
            else:
                f_q(t, q, p, fq)
            if HAS_FT:
                f_t(t, q, p, sm)
            if FQ_V:
                fq_v(fq, v, sm, g)
            else:
                for i in range(m):
                    s = sm[i] if HAS_FT else -0.0
                    if SPARSE:
                        for e in range(FPTR[i], FPTR[i + 1]):
                            j = FCOL[e]
                            s = fma(fq[i, j], v[j], s)
                    else:
                        for j in range(n):
                            s = fma(fq[i, j], v[j], s)
                    g[m + i] = s
        if k > 0:
            h_fn(t, q, v, p, sk)
            for i in range(k):
                g[2 * m + i] = sk[i]
            h_v(t, q, v, p, hv)
            h_q(t, q, v, p, hq)

    @internal(error_model="numpy")
    def project(t, x, p, ws, sweeps, tol):
        """Move ``x`` onto (towards) the manifold ``g = 0``, in place; return a status.

        Positions first, then velocities at the corrected positions (the block form of
        ``x ← x − D (G D)⁻¹ g`` of Ascher et al.), each level repeated until its residual
        max-norm is ``≤ tol``, stops halving (the roundoff level) or ``sweeps``
        corrections were made::

            q ← q − M⁻¹f_qᵀ (f_q M⁻¹f_qᵀ)⁻¹ f          (Gauss–Newton in the M metric)
            v ← v − M⁻¹Fᵀ S⁻¹ (ḟ, h)

        One sweep with ``tol = 0`` is post-stabilization; sweeps to a small tolerance are
        coordinate projection.
        """
        Mw, fq, hv, Y, S, g, sm, mu = ws.M, ws.fq, ws.hv, ws.Y, ws.S, ws.g, ws.sm, ws.mu
        q = ws.q
        for level in range(2):
            if (level == 0 and m == 0) or (level == 1 and r == 0):
                continue
            lo, cols = (0, m) if level == 0 else (m, r)
            prev = math.inf
            for _ in range(sweeps):
                residual(t, x, p, ws, g)
                err = 0.0
                for i in range(cols):
                    err = max(err, abs(g[lo + i]))
                if err <= tol or err > 0.5 * prev:  # converged, or at the roundoff level
                    break
                prev = err
                rhs_ = sm if level == 0 else mu
                for i in range(cols):
                    rhs_[i] = g[lo + i]
                if SPARSE:
                    if sparse_Y(t, q, p, ws, cols):
                        return _MASS_NOT_SPD
                    if sparse_S(ws, cols):
                        return _SINGULAR_S
                    ldl_sparse_solve(S, cols, rhs_, LPTR, LCOL, LTPTR, LROW)
                    for j in range(n):
                        s = -0.0
                        for e in range(CPTR[j], CPTR[j + 1]):
                            i = CROW[e]
                            if i < cols:
                                s = fma(Y[j, i], rhs_[i], s)
                        x[level * n + j] -= s
                    continue
                _load_Ft(fq, hv, Y, m, cols, n)
                if HAS_MASS:
                    mass(t, q, p, Mw)
                    if ldl_inplace(Mw, n, MASS_RTOL) != 0:
                        return _MASS_NOT_SPD
                    ldl_solve_columns(Mw, n, Y, cols)
                _gram_lower(fq, hv, Y, S, m, cols, n)
                if ldl_inplace(S, cols, S_RTOL) != 0:
                    return _SINGULAR_S
                ldl_solve_inplace(S, cols, rhs_)
                dx = ws.z  # (the projection evaluates no forces)
                for j in range(n):
                    s = -0.0
                    for i in range(cols):
                        s = fma(Y[j, i], rhs_[i], s)
                    dx[j] = s
                if HAS_KIN:
                    if level == 0:  # a step in v's coordinates moves q by T δv (into q̇'s
                        Tw, qd = ws.T, ws.qd  # buffer: the next sweep's residual refills it)
                        for j in range(n):
                            s = -0.0
                            for c in range(n):
                                s = fma(Tw[j, c], dx[c], s)
                            qd[j] = s
                        dx = qd
                for j in range(n):
                    x[level * n + j] -= dx[j]
        return _OK

    @internal(error_model="numpy")
    def energy(t, x, p, ws):
        q, v = ws.q, ws.v
        for i in range(n):
            q[i] = x[i]
            v[i] = x[n + i]
        return energy_fn(t, q, v, p)

    model_key = fingerprint(
        n, m, k, model.structure_key() if SPARSE or FQ_V or HQ_V else "dense",
        tuple((piece, optional_fingerprint(fn)) for piece, fn in sorted(fns.items())),
        optional_fingerprint(model.energy),
    )  # fmt: skip
    key = Spec("pieces", sparse=sparse).key(model_key)
    tag(key, residual, energy, project, make_workspace, stack_workspace)
    return Pieces(n, m, k, r, ng, HAS_MASS, HAS_HT, HAS_KIN, SPARSE, mass, forces, f_accel, h_t,
                  residual, project, energy, make_workspace, stack_workspace, sparse_Y, sparse_S,
                  hq_v, FPTR, FCOL, CPTR, CROW, HQPTR, HQCOL, LPTR, LCOL, LTPTR, LROW, key)


def _velocity_products(model, has_ft: bool, has_ht: bool):
    """The dense path's ``ḟ = f_q v + f_t`` (into ``g[m:2m]``) and ``−h_q v − h_t`` (into
    ``rl[m:]``) written out over the non-zeros of ``f_q``'s and ``h_q``'s patterns, in the
    loops' order (the same sums without their structurally zero terms, as on the sparse
    path); :func:`_noop4` for a piece without patterns, or with more than
    ``UNROLL_MAX_OPS`` non-zeros.

    Written out, not looped: a loop over the rows that LLVM does not unroll (Bricard's
    14 × 15 ``f_q``) stays inside the ensemble kernel's loop over the members, which is
    then no longer innermost and runs one member at a time."""
    pats, n, m, k = model.patterns, model.n, model.m, model.k
    if "kinematics" in model.functions:  # the map fills f_q T; h_q multiplies T v
        return _noop4, _noop4
    tag_ = model.structure_key()[:8] if pats is not None else ""
    out = []
    for rows, piece, has_t, header, start, term, dst in (
        (m, "f_q", has_ft, "def fq_v(fq, v, sm, g):", "sm[{i}]",
         "s = fma(fq[{i}, {j}], v[{j}], s)", "g[{r}] = s"),
        (k, "h_q", has_ht, "def hq_v(hq, v, sk, rl):", "-sk[{i}]",
         "s = fnma(hq[{i}, {j}], v[{j}], s)", "rl[{r}] = s"),
    ):  # fmt: skip
        pat = None if pats is None or not rows else pats.get(piece)
        if pat is None or int(pat.sum()) > UNROLL_MAX_OPS:
            out.append(_noop4)
            continue
        lines = []
        for i in range(rows):
            lines.append("s = " + (start.format(i=i) if has_t else "-0.0"))
            lines += [term.format(i=i, j=j) for j in range(n) if pat[i, j]]
            lines.append(dst.format(r=m + i))
        out.append(_inline(_written_out(header, lines, f"{piece}_v_{tag_}")))
    return tuple(out)


def _nested(a) -> tuple:
    return tuple(tuple(bool(v) for v in row) for row in a)


def _structured(model, n: int, m: int, k: int) -> Plan | None:
    """The dense path's linear algebra written out for the model's structural zeros.

    A mass matrix that is not diagonal rules out the sparse path (:mod:`.sparsity`), but
    it is often block diagonal (a body's coordinates couple among themselves only), and
    each constraint touches a few coordinates.  Here ``M``'s factor, ``Y = M⁻¹ Fᵀ``,
    ``z = M⁻¹ γ``, ``S = F Y`` and its factor, ``F z`` and ``Y λ`` are written out for the
    sizes and patterns of the model (:mod:`.linalg`): the dense path's operations in its
    order without the terms that are structurally zero, so the two agree to the sign of a
    zero.  None where the model has no patterns, where they save nothing, or where a
    piece would exceed ``UNROLL_MAX_OPS`` multiply-adds (its code grows with them).
    """
    pats = model.patterns
    r = m + k
    if pats is None or r == 0 or "kinematics" in model.functions:
        return None
    F = np.zeros((r, n), dtype=bool)
    if m:
        F[:m] = pats["f_q"]
    if k:
        F[m:] = pats["h_v"]
    has_mass = "mass" in model.functions
    M = np.tril(pats["mass"]) if has_mass else None  # the factor reads the lower triangle
    if has_mass:
        Ypat, y_ops = solve_pattern(M, F.T)
        m_ops = factor_ops(n, M)
    else:
        Ypat, y_ops, m_ops = F.T.copy(), 0, 0
    S = np.tril((F.astype(np.int64) @ Ypat.astype(np.int64)) > 0)
    gram_ops = int(sum((F[i] & Ypat[:, c]).sum() for i in range(r) for c in range(i + 1)))
    s_ops = factor_ops(r, S)
    ops = (m_ops, y_ops, gram_ops, s_ops)
    dense = (n**3 // 6 if has_mass else 0, n * n * r if has_mass else 0,
             n * r * (r + 1) // 2, r**3 // 6)  # fmt: skip
    total = int(sum(ops) + F.sum() + Ypat.sum())
    if max(ops) > UNROLL_MAX_OPS or total >= sum(dense) + 2 * n * r:
        return None

    def entry(i, j):
        return f"fq[{i}, {j}]" if i < m else f"hv[{i - m}, {j}]"

    load = [f"Y[{j}, {i}] = {entry(i, j)}" for i in range(r) for j in range(n) if F[i, j]]
    gram = []
    for i in range(r):
        for c in range(i + 1):
            gram.append("s = -0.0")
            gram += [f"s = fma({entry(i, j)}, Y[{j}, {c}], s)" for j in range(n)
                     if F[i, j] and Ypat[j, c]]  # fmt: skip
            gram.append(f"S[{i}, {c}] = s")  # every entry: the factor's fill reads zeros
    add_fz = []
    for i in range(r):
        add_fz.append(f"s = rl[{i}]")
        add_fz += [f"s = fma({entry(i, j)}, z[{j}], s)" for j in range(n) if F[i, j]]
        add_fz.append(f"rl[{i}] = s")
    accel = []
    for j in range(n):
        accel.append(f"s = -z[{j}]")
        accel += [f"s = fma(Y[{j}, {i}], rl[{i}], s)" for i in range(r) if Ypat[j, i]]
        accel += [f"xdot[{j}] = v[{j}]", f"xdot[{n + j}] = s"]
    tag_ = model.structure_key()[:8]
    mkey = _nested(M) if has_mass else None
    return Plan(
        factor_M=ldl_factor_for(n, mkey) if has_mass else None,
        solve_M=ldl_solve_for(n, mkey) if has_mass else None,
        solve_columns_M=ldl_solve_columns_for(n, r, mkey, _nested(F.T)) if has_mass else None,
        factor_S=ldl_factor_for(r, _nested(S)),
        solve_S=ldl_solve_for(r, _nested(S)),
        load_Ft=_written_out("def load_Ft(fq, hv, Y):", load, f"load_Ft_{tag_}"),
        gram=_written_out("def gram(fq, hv, Y, S):", gram, f"gram_{tag_}"),
        add_Fz=_written_out("def add_Fz(fq, hv, z, rl):", add_fz, f"add_Fz_{tag_}"),
        accel=_written_out("def accel(Y, z, rl, v, xdot):", accel, f"accel_{tag_}"),
        ops=total,
    )


def _build(model, spec: Spec) -> Kernels:
    law_code, law_fn, lstsq = spec.law, spec.law_fn, spec.multiplier == "lstsq"
    # The sparse path (:mod:`.sparsity`) where the model's structure pays for it; not for
    # the least-squares multiplier or the correction of Ascher et al., which stay dense.
    sparse = not (lstsq or law_code == LAW_ACPR) and model.sparse_structure() is not None
    P = memo(model, Spec("pieces", sparse=sparse), lambda: _pieces(model, sparse))
    # compile-time constants of the right-hand side's closure
    n, m, k, r, ng = P.n, P.m, P.k, P.r, P.ng
    HAS_MASS, HAS_HT, HAS_KIN, SPARSE = P.HAS_MASS, P.HAS_HT, P.HAS_KIN, P.SPARSE
    mass, forces, f_accel, h_t = P.mass, P.forces, P.f_accel, P.h_t
    residual, project, energy = P.residual, P.project, P.energy
    make_workspace, stack_workspace = P.make_workspace, P.stack_workspace
    sparse_Y, sparse_S = P.sparse_Y, P.sparse_S
    hq_v = P.hq_v
    HQ_V = hq_v is not _noop4
    FPTR, FCOL, CPTR, CROW, HQPTR, HQCOL = P.FPTR, P.FCOL, P.CPTR, P.CROW, P.HQPTR, P.HQCOL
    LPTR, LCOL, LTPTR, LROW = P.LPTR, P.LCOL, P.LTPTR, P.LROW
    LAW = law_code
    LSTSQ = lstsq
    law_A = _rejit(law_fn, _noop4)
    # the dense path's factorizations written out for these sizes (same numbers as the
    # loops; see :mod:`.linalg`)
    factor_M, solve_M, solve_columns_M = (ldl_factor_for(n), ldl_solve_for(n),
                                          ldl_solve_columns_for(n, r))  # fmt: skip
    factor_S, solve_S, solve_Sm = ldl_factor_for(r), ldl_solve_for(r), ldl_solve_for(m)
    factor_M, solve_M, solve_columns_M = map(_inline, (factor_M, solve_M, solve_columns_M))
    factor_S, solve_S, solve_Sm = map(_inline, (factor_S, solve_S, solve_Sm))
    # the same, written out for the model's structural zeros where they pay (not for the
    # least-squares multiplier or the correction of Ascher et al., which read all of S)
    plan = None
    if not (SPARSE or lstsq or law_code == LAW_ACPR):
        plan = memo(model, Spec("structured"), lambda: _structured(model, n, m, k))
    STRUCTURED = plan is not None
    if STRUCTURED:
        factor_S, solve_S = _inline(plan.factor_S), _inline(plan.solve_S)
        if HAS_MASS:
            factor_M, solve_M = _inline(plan.factor_M), _inline(plan.solve_M)
            solve_columns_M = _inline(plan.solve_columns_M)
        load_Ft, gram = _inline(plan.load_Ft), _inline(plan.gram)
        add_Fz, accel = _inline(plan.add_Fz), _inline(plan.accel)
    else:  # never called (the branches on STRUCTURED are pruned), but typed
        load_Ft, gram, add_Fz, accel = _noop3, _noop4, _noop4, _noop5

    @internal(forceinline=True, error_model="numpy")
    def rhs(t, x, p, law_mat, law_scal, ws, xdot):
        """Write ẋ of the stabilized system (3.1) into ``xdot``; return a status code.

        ``law_mat``/``law_scal`` carry the law's runtime data (``A``; or ``L`` and the gain
        of Theorem 5).  On a non-zero status ``xdot`` is undefined.  Nothing is checked:
        shapes are fixed by the workspace.
        """
        q, v, Mw, z, fq, hv, hq = ws.q, ws.v, ws.M, ws.z, ws.fq, ws.hv, ws.hq
        Y, S, rl, g, sm, sk = ws.Y, ws.S, ws.rl, ws.g, ws.sm, ws.sk
        Aw, W, Lh = ws.Aw, ws.W, ws.Lh
        if HAS_KIN:  # q̇ (a model without a map has no buffer for it: branch pruned)
            vq = ws.qd
        else:
            vq = v
        residual(t, x, p, ws, g)
        forces(t, q, v, p, z)

        # Right side of (3.11): A g − c + F z.  First −c, the convective terms; then the
        # law's A g is added (fused multiply-adds), and F z below, once z = M⁻¹γ is known.
        if m > 0:
            f_accel(t, q, v, p, sm)
            for i in range(m):
                rl[i] = -sm[i]
        if k > 0:
            if HAS_HT:
                h_t(t, q, v, p, sk)
            if HQ_V:
                hq_v(hq, v, sk, rl)
            else:
                for i in range(k):
                    s = -sk[i] if HAS_HT else -0.0
                    if SPARSE:
                        for e in range(HQPTR[i], HQPTR[i + 1]):
                            j = HQCOL[e]
                            s = fma(-hq[i, j], vq[j], s)
                    else:
                        for j in range(n):
                            s = fma(-hq[i, j], vq[j], s)
                    rl[m + i] = s
        if LAW == LAW_CONSTANT:
            for i in range(r):
                s = rl[i]
                for j in range(ng):
                    s = fma(law_mat[i, j], g[j], s)
                rl[i] = s
        elif LAW == LAW_SCALAR_BLOCKS:
            # −(c − a₀ f − a₁ ḟ): the same sums as a₁ ḟ + (a₀ f + (−c)), each rounded once
            # and negated exactly (they differ only in the sign of a sum that cancels to
            # zero exactly), with c left positive.  A user's c is often 2·(…), which LLVM
            # then adds to itself instead of multiplying by −2, and the negation goes into
            # the multiply-adds that follow: one product less per evaluation (the
            # pendulum's ensemble stepped 4–5 % faster)
            for i in range(m):
                s = fma(-law_mat[0, 0], g[i], sm[i])
                rl[i] = -fma(-law_mat[0, 1], g[m + i], s)
            for i in range(k):
                rl[m + i] = fma(law_mat[0, 2], g[2 * m + i], rl[m + i])
        elif LAW == LAW_USER:
            law_A(t, x, p, Aw)
            for i in range(r):
                s = rl[i]
                for j in range(ng):
                    s = fma(Aw[i, j], g[j], s)
                rl[i] = s
        elif LAW == LAW_THEOREM5:  # m = 0: A22 g = −k W L g with W = h_v h_vᵀ
            for i in range(k):
                s = -0.0
                for j in range(k):
                    s = fma(law_mat[i, j], g[j], s)
                Lh[i] = s
            for i in range(k):
                for j in range(k):
                    s = -0.0
                    for l in range(n):
                        s = fma(hv[i, l], hv[j, l], s)
                    W[i, j] = s
            for i in range(k):
                s = -0.0
                for j in range(k):
                    s = fma(W[i, j], Lh[j], s)
                rl[i] = fma(-law_scal[0], s, rl[i])
        # (LAW_ACPR: the index-1 equations, A g = 0; its correction is added at the end)

        # Y = M⁻¹ Fᵀ and z = M⁻¹ γ
        # No early returns below: a failed factorization is remembered and reported at the
        # end, so that the ensemble kernel can inline this body into a vectorized loop.
        bad_mass = False
        if SPARSE:
            # M diagonal or absent: Y has Fᵀ's pattern; only its non-zeros are written,
            # and only they are read
            bad_mass = sparse_Y(t, q, p, ws, r)
            if HAS_MASS:
                for j in range(n):
                    z[j] *= Mw[j, j]
            for i in range(r):  # rl += F z
                s = rl[i]
                for e in range(FPTR[i], FPTR[i + 1]):
                    j = FCOL[e]
                    fij = fq[i, j] if i < m else hv[i - m, j]
                    s = fma(fij, z[j], s)
                rl[i] = s
            bad_S = sparse_S(ws, r)
            ldl_sparse_solve(S, r, rl, LPTR, LCOL, LTPTR, LROW)  # rl is now λ
            for j in range(n):
                s = -z[j]
                for e in range(CPTR[j], CPTR[j + 1]):
                    i = CROW[e]
                    s = fma(Y[j, i], rl[i], s)
                xdot[j] = vq[j]
                xdot[n + j] = s
        elif STRUCTURED:
            load_Ft(fq, hv, Y)
            if HAS_MASS:
                mass(t, q, p, Mw)
                bad_mass = factor_M(Mw, n, MASS_RTOL) != 0
                solve_columns_M(Mw, n, Y, r)
                solve_M(Mw, n, z)
            add_Fz(fq, hv, z, rl)
            gram(fq, hv, Y, S)
            bad_S = factor_S(S, r, S_RTOL) != 0
            solve_S(S, r, rl)  # rl is now λ
            accel(Y, z, rl, vq, xdot)
        else:
            _load_Ft(fq, hv, Y, m, r, n)
            if HAS_MASS:
                mass(t, q, p, Mw)
                bad_mass = factor_M(Mw, n, MASS_RTOL) != 0
                solve_columns_M(Mw, n, Y, r)
                solve_M(Mw, n, z)

            # rl += F z, and S = F Y (symmetric; the lower triangle suffices for L D Lᵀ)
            for i in range(r):
                s = rl[i]
                for j in range(n):
                    fij = fq[i, j] if i < m else hv[i - m, j]
                    s = fma(fij, z[j], s)
                rl[i] = s
            _gram_lower(fq, hv, Y, S, m, r, n)
            if LSTSQ:  # redundant constraints: the minimum-norm least-squares λ
                bad_S = pinv_solve_sym(S, r, rl, S_PINV_RTOL, ws.V, ws.ev, ws.mu) == 0
            else:
                bad_S = factor_S(S, r, S_RTOL) != 0
                solve_S(S, r, rl)  # rl is now λ

            for j in range(n):
                s = -z[j]
                for i in range(r):
                    s = fma(Y[j, i], rl[i], s)
                xdot[j] = vq[j]
                xdot[n + j] = s
        if LAW == LAW_ACPR:
            # − γ_s (δq, δv): δv = Y S⁻¹ (ḟ, h); δq = Y₁ P⁻¹ f with P = f_q M⁻¹ f_qᵀ the
            # leading m × m block of S, whose L D Lᵀ factor is the leading block of S's
            mu = ws.mu
            for i in range(m):
                mu[i] = g[m + i]
                sm[i] = g[i]
            for i in range(k):
                mu[m + i] = g[2 * m + i]
            solve_S(S, r, mu)
            solve_Sm(S, m, sm)
            gam = law_scal[0]
            for j in range(n):
                dq = -0.0
                for i in range(m):
                    dq = fma(Y[j, i], sm[i], dq)
                dv = -0.0
                for i in range(r):
                    dv = fma(Y[j, i], mu[i], dv)
                if HAS_KIN:
                    z[j] = dq  # (z is spent): δq in v's coordinates, moved by T below
                else:
                    xdot[j] = fma(-gam, dq, xdot[j])
                xdot[n + j] = fma(-gam, dv, xdot[n + j])
            if HAS_KIN:
                Tw = ws.T
                for j in range(n):
                    s = -0.0
                    for c in range(n):
                        s = fma(Tw[j, c], z[c], s)
                    xdot[j] = fma(-gam, s, xdot[j])
        # the mass matrix's failure first (MASS_NOT_SPD > SINGULAR_S > OK = 0); arithmetic,
        # not branches, which LLVM sank the S test into and then could not vectorize
        return max(_MASS_NOT_SPD * bad_mass, _SINGULAR_S * bad_S)

    # the model's part of the key is the pieces' (its functions, energy and structure);
    # None (no cache) where that is
    flags = (("lstsq",) if lstsq else ()) + (
        ("structured", model.structure_key()) if STRUCTURED else ())
    key = spec.key(P.key, *flags)
    tag(key, rhs)
    return Kernels(rhs, residual, energy, project, make_workspace, stack_workspace, n, m, k,
                   ng, key, rhs_size(model, plan))
