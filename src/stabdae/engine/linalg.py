"""Small dense linear algebra for the stabilized right-hand side.

The matrices met per right-hand-side evaluation are tiny (the mass matrix is n×n, the
constraint matrix ``S = F M⁻¹ Fᵀ`` is r×r with n, r of order 1–10), so a LAPACK call
costs more in dispatch than in arithmetic.  These routines work in place on caller-owned
buffers, allocate nothing and never raise: a failed factorization is reported through the
return value, which the caller turns into a status code.

The factorization is ``A = L D Lᵀ`` (L unit lower triangular) rather than Cholesky: no
square roots, and the reciprocal pivots are stored so that a solve is multiplications
only.  For the common ``r = 1`` constraint matrix, λ then costs one division — the same
arithmetic as a hand-written ``λ = rhs / S``.  Loops have no early exits, so the code
vectorizes when inlined into the ensemble kernel's member loop.

Only the leading ``n×n`` block of a buffer is touched, so one buffer can serve several sizes.

For the small sizes of a dense model the right-hand side uses the same routines written
out for its sizes (:func:`ldl_factor_for`, :func:`ldl_solve_for`,
:func:`ldl_solve_columns_for`): straight-line code with the same operations in the same
order, so the same numbers bit for bit.  LLVM vectorizes innermost loops only; a factor's
loop over its columns, which it does not unroll when the body is large, left the ensemble
kernel's member loop around it scalar.  The written-out code is compiled by
:mod:`.emit`, not statement by statement by numba.

Given a matrix's structural zeros (a model's patterns, :mod:`.sparsity`), the written-out
factor and solves leave out the terms that are structurally zero in the factor (its fill
included) and in the right sides: a block-diagonal mass matrix of 2 × 2 blocks factors in
a few operations instead of ``n³/6``.  The other operations keep their order, so the
numbers are the dense routines' up to the sign of a zero.
"""

from __future__ import annotations

import ast
import math
from functools import cache

import numpy as np
from numba import njit

from .emit import _index, emitted
from .fma import fma
from .jit import JIT
from .source import exec_source
from .sparsity import fill_pattern

#: the routines are written out when they take at most this many multiply-adds; larger ones
#: keep their loops, whose code does not grow with the size.  Written out, they integrate
#: several times as fast; the compile time grows with the multiply-adds, which this bounds
#: (the trade, measured: studies/README.md, ``bench_written_out.py``)
UNROLL_MAX_OPS = 2048


@njit(cache=True, error_model="numpy", forceinline=True)
def pivot_tolerance(a, n, rtol):
    """``rtol · max_i |a_ii|`` over the leading ``n × n`` block: the smallest pivot the
    factorizations accept."""
    dmax = abs(a[0, 0])  # (n = 0 reads a spare entry that is never used)
    for i in range(1, n):
        dmax = max(dmax, abs(a[i, i]))
    return rtol * dmax


@njit(cache=True, error_model="numpy", forceinline=True)
def ldl_inplace(a, n, rtol):
    """``a[:n, :n] = L D Lᵀ`` in place, for a symmetric positive definite matrix.

    On return the strict lower triangle of ``a[:n, :n]`` holds ``L`` (unit diagonal not
    stored) and the diagonal holds ``1/d_j``; the strict upper triangle is not touched and
    must not be read.

    Parameters
    ----------
    a : float64[:, :]
        Buffer whose leading ``n×n`` block holds a symmetric matrix (only the lower
        triangle is read).
    n : int
        Size of the block.
    rtol : float
        A pivot ``d_j ≤ rtol · max_i |a_ii|`` (or a non-finite pivot) counts as a failure:
        the matrix is singular, indefinite or not finite to working precision.

    Returns
    -------
    int
        ``0`` on success, otherwise ``j + 1`` for the first failing pivot ``j`` (the
        factor is then garbage and must not be used).
    """
    tol = pivot_tolerance(a, n, rtol)
    fail = 0
    for j in range(n):
        # row j: first w_p = L_jp d_p = a_jp − Σ_{q<p} w_q L_pq (rows p < j are final) …
        for p in range(j):
            s = a[j, p]
            for q in range(p):
                s = fma(-a[j, q], a[p, q], s)
            a[j, p] = s
        # … then L_jp = w_p / d_p and d_j = a_jj − Σ_p w_p L_jp
        d = a[j, j]
        for p in range(j):
            w = a[j, p]
            ljp = w * a[p, p]
            d = fma(-w, ljp, d)
            a[j, p] = ljp
        # Non-finite pivots fail this test too: while the earlier pivots passed (d_p > 0)
        # d ≤ a_jj, so d = +inf needs a_jj = +inf, and then tol = +inf; NaN and −inf
        # compare false.  (One comparison per pivot, and arithmetic instead of a branch to
        # keep the first failing pivot: this sits in the vectorized member loop, where a
        # chain of branches on ``fail`` stopped LLVM from vectorizing it for n ≥ 2.)
        bad = not (d > tol)
        fail += (j + 1) * (bad & (fail == 0))
        a[j, j] = 1.0 / d
    return fail


@njit(cache=True, error_model="numpy", forceinline=True)
def ldl_solve_inplace(l, n, b):
    """Solve ``L D Lᵀ x = b`` for one right-hand side, overwriting ``b[:n]`` with ``x``.

    ``l`` is the output of :func:`ldl_inplace`. Nothing is checked.
    """
    for i in range(n):  # L y = b
        s = b[i]
        for p in range(i):
            s = fma(-l[i, p], b[p], s)
        b[i] = s
    for i in range(n):  # D z = y
        b[i] *= l[i, i]
    for i in range(n - 1, -1, -1):  # Lᵀ x = z
        s = b[i]
        for p in range(i + 1, n):
            s = fma(-l[p, i], b[p], s)
        b[i] = s


@njit(cache=True, error_model="numpy", forceinline=True)
def ldl_solve_columns(l, n, b, ncols):
    """Solve ``L D Lᵀ X = B`` for the columns of ``b[:n, :ncols]``, in place."""
    for c in range(ncols):
        for i in range(n):
            s = b[i, c]
            for p in range(i):
                s = fma(-l[i, p], b[p, c], s)
            b[i, c] = s
        for i in range(n):
            b[i, c] *= l[i, i]
        for i in range(n - 1, -1, -1):
            s = b[i, c]
            for p in range(i + 1, n):
                s = fma(-l[p, i], b[p, c], s)
            b[i, c] = s


@njit(cache=True, error_model="numpy")
def pinv_solve_sym(a, n, b, rtol, V, w, tmp):
    """``b[:n] ← S⁺ b`` for the symmetric ``S`` whose lower triangle is in ``a[:n, :n]``.

    The least-squares multiplier of a redundant constraint set: ``S = F M⁻¹ Fᵀ`` is then
    singular, and the minimum-norm solution of ``min ‖S λ − b‖`` gives the same
    acceleration ``Y λ`` as any exact solution when one exists.  Cyclic Jacobi rotations
    diagonalize ``S = V diag(w) Vᵀ`` (``a`` is overwritten); eigenvalues with
    ``|w_i| ≤ rtol · max |w|`` are treated as zero.  ``V`` (n×n), ``w`` and ``tmp`` (n)
    are scratch.  Returns the numerical rank (0 for a zero or non-finite matrix).
    """
    for i in range(n):
        for j in range(i):
            a[j, i] = a[i, j]
        for j in range(n):
            V[i, j] = 1.0 if i == j else 0.0
    for _sweep in range(64):
        off = 0.0
        diag = 0.0
        for i in range(n):
            diag += a[i, i] * a[i, i]
            for j in range(i):
                off += a[i, j] * a[i, j]
        if not (off > 1e-32 * diag):  # converged (or NaN: handled below)
            break
        for p in range(n):
            for q in range(p + 1, n):
                apq = a[p, q]
                if apq == 0.0:
                    continue
                # rotation in the (p, q) plane that zeroes a[p, q]
                theta = (a[q, q] - a[p, p]) / (2.0 * apq)
                t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
                if theta < 0.0:
                    t = -t
                c = 1.0 / math.sqrt(t * t + 1.0)
                s = t * c
                for k in range(n):  # A ← A J
                    akp, akq = a[k, p], a[k, q]
                    a[k, p] = c * akp - s * akq
                    a[k, q] = s * akp + c * akq
                for k in range(n):  # A ← Jᵀ A
                    apk, aqk = a[p, k], a[q, k]
                    a[p, k] = c * apk - s * aqk
                    a[q, k] = s * apk + c * aqk
                for k in range(n):  # V ← V J
                    vkp, vkq = V[k, p], V[k, q]
                    V[k, p] = c * vkp - s * vkq
                    V[k, q] = s * vkp + c * vkq
    wmax = 0.0
    for i in range(n):
        w[i] = a[i, i]
        wmax = max(wmax, abs(w[i]))
    if not (wmax > 0.0 and math.isfinite(wmax)):
        for i in range(n):
            b[i] = 0.0 if wmax == 0.0 else math.nan
        return 0
    rank = 0
    for i in range(n):  # tmp = diag(w)⁺ Vᵀ b
        s = 0.0
        for k in range(n):
            s += V[k, i] * b[k]
        if abs(w[i]) > rtol * wmax:
            tmp[i] = s / w[i]
            rank += 1
        else:
            tmp[i] = 0.0
    for k in range(n):  # b = V tmp
        s = 0.0
        for i in range(n):
            s += V[k, i] * tmp[i]
        b[k] = s
    return rank


@njit(cache=True, error_model="numpy", forceinline=True)
def ldl_sparse_inplace(a, n, rtol, lptr, lcol, optr, oq):
    """:func:`ldl_inplace` on the factor's pattern only (:func:`.sparsity.structure`): the
    strict lower entries of row ``j`` are ``lcol[lptr[j]:lptr[j+1]]``, and for the ``e``-th
    of them, ``(j, p)``, the ``q < p`` with both ``L[j, q]`` and ``L[p, q]`` non-zero are
    ``oq[optr[e]:optr[e+1]]``.  The same operations in the same order as the dense
    factorization without its structurally zero terms; entries off the pattern are neither
    read nor written (the fill must hold zeros on entry)."""
    tol = pivot_tolerance(a, n, rtol)
    fail = 0
    for j in range(n):
        for e in range(lptr[j], lptr[j + 1]):
            p = lcol[e]
            s = a[j, p]
            for o in range(optr[e], optr[e + 1]):
                q = oq[o]
                s = fma(-a[j, q], a[p, q], s)
            a[j, p] = s
        d = a[j, j]
        for e in range(lptr[j], lptr[j + 1]):
            p = lcol[e]
            w = a[j, p]
            ljp = w * a[p, p]
            d = fma(-w, ljp, d)
            a[j, p] = ljp
        bad = not (d > tol)
        fail += (j + 1) * (bad & (fail == 0))
        a[j, j] = 1.0 / d
    return fail


@njit(cache=True, error_model="numpy", forceinline=True)
def ldl_sparse_solve(l, n, b, lptr, lcol, ltptr, lrow):
    """:func:`ldl_solve_inplace` for a factor of :func:`ldl_sparse_inplace`; ``lrow[
    ltptr[i]:ltptr[i+1]]`` are the rows of column ``i``'s strict lower entries.  With ``n``
    smaller than the factor, the leading ``n × n`` block's system is solved."""
    for i in range(n):
        s = b[i]
        for e in range(lptr[i], lptr[i + 1]):
            p = lcol[e]
            s = fma(-l[i, p], b[p], s)
        b[i] = s
    for i in range(n):
        b[i] *= l[i, i]
    for i in range(n - 1, -1, -1):
        s = b[i]
        for e in range(ltptr[i], ltptr[i + 1]):
            p = lrow[e]
            if p < n:  # (a leading block of the factor: rows below it left out)
                s = fma(-l[p, i], b[p], s)
        b[i] = s


# --------------------------------------------------------------------- written out
def _pattern(n: int, pattern) -> tuple:
    """The factor's pattern as a tuple of rows of booleans (lower triangle, diagonal
    included, closed under the fill of the elimination): every entry for ``None``."""
    if pattern is None:
        return tuple(tuple(p <= j for p in range(n)) for j in range(n))
    fill = fill_pattern(np.asarray(pattern, dtype=bool)[:n, :n])
    return tuple(tuple(bool(fill[j, p]) for p in range(n)) for j in range(n))


def _factor_lines(n: int, L: tuple) -> tuple[list[str], int]:
    """:func:`ldl_inplace`'s operations for size ``n`` in its order, without the terms
    that are structurally zero in the factor's pattern ``L``; and their multiply-adds."""
    # Of size 1 the pivot is the entry itself, and ``d > rtol·|d|`` holds exactly for
    # 0 < d < inf when 0 ≤ rtol ≤ 1/2 (the callers' tolerances; above 1/2, rtol times the
    # smallest subnormal rounds to itself, which fails).  That is ``min(d, 1/d) > 0``
    # (+inf has the reciprocal +0, ±0 the infinite ones, NaN its own), read from the
    # reciprocal the factor stores anyway: no product and no abs, and the pendulum's
    # ensemble steps 7 % faster
    out = [] if n == 1 else ["dmax = abs(a[0, 0])"]
    out += [f"dmax = max(dmax, abs(a[{i}, {i}]))" for i in range(1, n)]
    out += ([] if n == 1 else ["tol = rtol * dmax"]) + ["fail = 0"]
    ops = 0
    for j in range(n):
        row = [p for p in range(j) if L[j][p]]
        for p in row:
            out.append(f"s = a[{j}, {p}]")
            terms = [q for q in range(p) if L[j][q] and L[p][q]]
            out += [f"s = fnma(a[{j}, {q}], a[{p}, {q}], s)" for q in terms]
            out.append(f"a[{j}, {p}] = s")
            ops += len(terms) + 1
        out.append(f"d = a[{j}, {j}]")
        for p in row:
            out += [f"w = a[{j}, {p}]", f"ljp = w * a[{p}, {p}]", "d = fnma(w, ljp, d)",
                    f"a[{j}, {p}] = ljp"]  # fmt: skip
        if n == 1:
            out += ["inv = 1.0 / d", "bad = not (min(d, inv) > 0.0)", "fail += bad",
                    "a[0, 0] = inv"]  # fmt: skip
            continue
        out += ["bad = not (d > tol)", f"fail += {j + 1} * (bad & (fail == 0))",
                f"a[{j}, {j}] = 1.0 / d"]  # fmt: skip
    return out + ["return fail"], ops


def _solve_lines(n: int, at, L: tuple, b: tuple) -> tuple[list[str], tuple, int]:
    """:func:`ldl_solve_inplace`'s operations for size ``n`` on the entries ``at(i)``,
    for a factor of pattern ``L`` and a right side whose structurally non-zero entries are
    ``b``: the lines, the solution's pattern and the multiply-adds.  A structurally zero
    entry is neither read nor written; where terms make it non-zero, its sum starts from
    ``-0.0`` (the dense sum starts from the entry's zero: the two differ in the sign of a
    zero at most)."""
    out, ops = [], 0

    def substitute(i, known, terms):
        nonlocal ops
        if not (known[i] or terms):
            return False
        out.append(f"s = {at(i)}" if known[i] else "s = -0.0")
        out.extend(f"s = fnma({l_}, {at(p)}, s)" for p, l_ in terms)
        out.append(f"{at(i)} = s")
        ops += len(terms)
        return True

    y = list(b)
    for i in range(n):  # L y = b
        y[i] = substitute(i, y, [(p, f"l[{i}, {p}]") for p in range(i) if L[i][p] and y[p]])
    out += [f"{at(i)} *= l[{i}, {i}]" for i in range(n) if y[i]]  # D z = y
    ops += sum(y)
    for i in range(n - 1, -1, -1):  # Lᵀ x = z
        y[i] = substitute(i, y, [(p, f"l[{p}, {i}]") for p in range(i + 1, n)
                                 if L[p][i] and y[p]])  # fmt: skip
    return out, tuple(y), ops


def _written_out(header: str, lines: list[str], label: str):
    """The straight-line function ``header`` + ``lines``, its entries held in locals
    (:func:`_scalarized`), compiled: lowered by :func:`.emit.emitted` (no numba typing of
    its statements) behind a one-line function that numba inlines where it is called
    (callable from Python), whose ``emitted`` attribute is the intrinsic itself.

    The code is parsed, rewritten and checked only when a compilation first reads it
    (``straight_line()``): a process whose kernels come from the cache skips that (a
    second of Python on a 12-coordinate bicycle's written-out linear algebra)."""
    source = header + "\n" + "".join(f"    {line}\n" for line in lines or ["pass"])
    fn_def = cache(lambda: _scalarized_tree(source))
    name, params = header[4:header.index("(")], header[header.index("(") + 1:header.index(")")]
    if not JIT:
        return exec_source(_unparsed(fn_def()), label,
                           {"fma": fma, "fnma": _fnma, **_PY_ENTRY})[name]  # fmt: skip
    wrapper = f"def {name}({params}):\n    return _emitted({params})\n"
    emitted_ = emitted(fn_def, {}, label, params=[a.strip() for a in params.split(",")])
    call = exec_source(wrapper, label + "_call", {"_emitted": emitted_})[name]
    out = njit(error_model="numpy", forceinline=True)(call)
    out.straight_line = fn_def  # the code it does, on demand (:func:`_unparsed` reads it)
    out.emitted = emitted_  # for compiled callers: no function of its own to compile
    return out


def _py_at(a, *index):
    return a[index]


def _py_set(a, *rest):
    a[rest[:-1]] = rest[-1]


#: the written-out Python code's entry reads and writes (what :func:`.emit.emitted` lowers
#: to a load or a store at the entry's address)
_PY_ENTRY = {"_at1": _py_at, "_at2": _py_at, "_set1": _py_set, "_set2": _py_set}


def _fnma(a, b, c):
    return fma(-a, b, c)


def _entry(node) -> tuple | None:
    """``(array, (i, j, ...))`` of a subscript by integer constants, else None."""
    if not (isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name)):
        return None
    index = _index(node.slice)
    if not all(isinstance(i, ast.Constant) and type(i.value) is int for i in index):
        return None
    return node.value.id, tuple(i.value for i in index)


def _scalarized(source: str) -> str:
    """:func:`_scalarized_tree`'s function as source."""
    return _unparsed(_scalarized_tree(source))


def _unparsed(fn_def: ast.FunctionDef) -> str:
    return ast.unparse(ast.fix_missing_locations(fn_def)) + "\n"


def _scalarized_tree(source: str) -> ast.FunctionDef:
    """The straight-line function ``source`` with each array entry it indexes by constants
    held in a local variable: read from its array once, before the first statement,
    where the code reads it before writing it, and written back once, before the
    ``return`` (or at the end), where the code writes it.  The same operations on the same
    values in the same order, so the same bits (the arguments are distinct buffers: no
    entry is reached through two names).  The operations read each entry many times (a
    cubic number in a factor); held in a local, it is loaded once, where LLVM, told
    nothing of whether the arrays overlap, may load it again after a store to another
    array, and each access is code to generate and optimize."""
    fn = ast.parse(source).body[0]
    dynamic = {n.value.id for n in ast.walk(fn) if isinstance(n, ast.Subscript)
               and isinstance(n.value, ast.Name) and _entry(n) is None}  # fmt: skip
    local: dict = {}  # entry -> its local's name
    loads: list = []  # entries read before they are written
    stores: list = []  # entries written

    def name(key, ctx, read):
        if key not in local:
            local[key] = "_" + key[0] + "".join(f"_{i}" for i in key[1])
            if read:
                loads.append(key)
        if isinstance(ctx, ast.Store) and key not in stores:
            stores.append(key)
        return ast.Name(id=local[key], ctx=ctx)

    class Locals(ast.NodeTransformer):
        def visit_Subscript(self, node):
            key = _entry(node)
            if key is None or key[0] in dynamic:
                return self.generic_visit(node)
            return name(key, node.ctx, read=not isinstance(node.ctx, ast.Store))

        def visit_Assign(self, node):  # the value is evaluated before the targets
            node.value = self.visit(node.value)
            node.targets = [self.visit(t) for t in node.targets]
            return node

        def visit_AugAssign(self, node):  # ``a[i] *= x`` reads a[i] first
            node.value = self.visit(node.value)
            key = _entry(node.target)
            if key is not None and key[0] not in dynamic:
                name(key, ast.Load(), read=True)
            node.target = self.visit(node.target)
            return node

    body = [Locals().visit(stmt) for stmt in fn.body]

    def call(fn, key, *more):
        args = [ast.Name(key[0], ast.Load()), *(ast.Constant(i) for i in key[1]), *more]
        return ast.Call(ast.Name(f"{fn}{len(key[1])}", ast.Load()), args, [])

    head = [ast.Assign([ast.Name(local[k], ast.Store())], call("_at", k)) for k in loads]
    tail = [ast.Expr(call("_set", k, ast.Name(local[k], ast.Load()))) for k in stores]
    ret = [i for i, stmt in enumerate(body) if isinstance(stmt, ast.Return)]
    if any(isinstance(n, ast.Return) for stmt in body for n in ast.walk(stmt)
           if not isinstance(stmt, ast.Return)) or ret[:-1]:  # fmt: skip
        return ast.parse(source).body[0]  # (only straight-line code with one return at
        # its end is rewritten)
    at = ret[0] if ret else len(body)
    fn.body = head + body[:at] + tail + body[at:] or [ast.Pass()]
    return fn


def _label(base: str, pattern) -> str:
    return base if pattern is None else base + "_pattern"


@cache
def ldl_factor_for(n: int, pattern=None):
    """:func:`ldl_inplace` for matrices of size ``n`` (its ``n`` argument is then ignored):
    written out while it takes at most ``UNROLL_MAX_OPS`` multiply-adds, else itself.

    ``pattern`` (``n × n`` nested tuples of booleans, hashable) marks the matrix's
    structural non-zeros; their lower triangle and its fill are factored, the other
    entries are neither read nor written, and the code is written out whatever its size
    (the caller bounds it with :func:`factor_ops`)."""
    if pattern is None and n * n * n // 6 > UNROLL_MAX_OPS:
        return ldl_inplace
    return _written_out("def ldl_factor(a, n, rtol):", _factor_lines(n, _pattern(n, pattern))[0],
                        _label(f"ldl_factor_{n}", pattern))  # fmt: skip


@cache
def ldl_solve_for(n: int, pattern=None):
    """:func:`ldl_solve_inplace` for size ``n`` (and a factor of :func:`ldl_factor_for`
    with the same ``pattern``), written out as :func:`ldl_factor_for`."""
    if pattern is None and n * n > UNROLL_MAX_OPS:
        return ldl_solve_inplace
    lines = _solve_lines(n, lambda i: f"b[{i}]", _pattern(n, pattern), (True,) * n)[0]
    return _written_out("def ldl_solve(l, n, b):", lines, _label(f"ldl_solve_{n}", pattern))


@cache
def ldl_solve_columns_for(n: int, ncols: int, pattern=None, columns=None):
    """:func:`ldl_solve_columns` for size ``n`` and ``ncols`` columns, written out as
    :func:`ldl_factor_for`.  ``columns`` (``n × ncols`` nested tuples of booleans) marks
    the right sides' structural non-zeros: the others are neither read nor written, and
    the solution's are :func:`solve_pattern`'s."""
    if pattern is None and columns is None and n * n * ncols > UNROLL_MAX_OPS:
        return ldl_solve_columns
    L = _pattern(n, pattern)
    lines = []
    for c in range(ncols):
        b = (True,) * n if columns is None else tuple(columns[i][c] for i in range(n))
        lines += _solve_lines(n, lambda i, c=c: f"b[{i}, {c}]", L, b)[0]
    return _written_out("def ldl_solve_columns(l, n, b, ncols):", lines,
                        _label(f"ldl_solve_columns_{n}x{ncols}", pattern))  # fmt: skip


def factor_ops(n: int, pattern) -> int:
    """Multiply-adds of :func:`ldl_factor_for` ``(n, pattern)``."""
    return _factor_lines(n, _pattern(n, pattern))[1]


def solve_pattern(pattern, columns) -> tuple[np.ndarray, int]:
    """The structural non-zeros of ``X`` in ``A X = B`` for ``A`` of pattern ``pattern``
    (``n × n``, None for dense) and ``B`` of pattern ``columns`` (``n × ncols``), as
    :func:`ldl_solve_columns_for` computes it; and its multiply-adds."""
    B = np.asarray(columns, dtype=bool)
    n = B.shape[0]
    L = _pattern(n, pattern)
    X, ops = np.zeros_like(B), 0
    for c in range(B.shape[1]):
        _, x, o = _solve_lines(n, str, L, tuple(bool(v) for v in B[:, c]))
        X[:, c] = x
        ops += o
    return X, ops
