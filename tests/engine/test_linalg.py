"""Small dense L D Lᵀ routines against NumPy, and their failure reports."""

from __future__ import annotations

import numpy as np
import pytest

from stabdae.engine.linalg import ldl_inplace, ldl_solve_columns, ldl_solve_inplace


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8])
def test_ldl_reconstructs_and_solves(n):
    rng = np.random.default_rng(n)
    B = rng.standard_normal((n, n))
    A = B @ B.T + n * np.eye(n)
    buf = np.full((n + 2, n + 2), 7.0)  # a larger buffer: only the leading block is used
    buf[:n, :n] = A
    assert ldl_inplace(buf, n, 1e-14) == 0
    L = np.tril(buf[:n, :n], -1) + np.eye(n)
    D = np.diag(1.0 / np.diag(buf[:n, :n]))
    np.testing.assert_allclose(L @ D @ L.T, A, rtol=1e-13, atol=1e-12)
    # the same factor as Cholesky: L D^½ = chol(A)
    np.testing.assert_allclose(L @ np.sqrt(D), np.linalg.cholesky(A), rtol=1e-12, atol=1e-12)
    assert np.all(buf[n:, :] == 7.0) and np.all(buf[:, n:] == 7.0)
    b = rng.standard_normal(n)
    x = b.copy()
    ldl_solve_inplace(buf, n, x)
    np.testing.assert_allclose(A @ x, b, rtol=1e-12, atol=1e-12)
    Bm = rng.standard_normal((n, 3))
    X = Bm.copy()
    ldl_solve_columns(buf, n, X, 3)
    np.testing.assert_allclose(A @ X, Bm, rtol=1e-12, atol=1e-12)


def test_singular_indefinite_and_nan_are_reported():
    singular = np.array([[1.0, 1.0], [1.0, 1.0]])
    assert ldl_inplace(singular.copy(), 2, 1e-12) == 2
    indefinite = np.array([[1.0, 0.0], [0.0, -1.0]])
    assert ldl_inplace(indefinite.copy(), 2, 0.0) == 2
    nan = np.array([[np.nan, 0.0], [0.0, 1.0]])
    assert ldl_inplace(nan.copy(), 2, 0.0) == 1
    # nearly singular beyond the relative threshold
    near = np.array([[1.0, 1.0], [1.0, 1.0 + 1e-14]])
    assert ldl_inplace(near.copy(), 2, 1e-12) == 2
    assert ldl_inplace(near.copy(), 2, 1e-16) == 0


@pytest.mark.parametrize("n,rank", [(1, 1), (3, 3), (4, 3), (5, 2), (6, 6)])
def test_pinv_solve_sym_matches_numpy_pinv(n, rank):
    """The least-squares multiplier: S⁺b against numpy.linalg.pinv, full and deficient rank."""
    from stabdae.engine.linalg import pinv_solve_sym

    rng = np.random.default_rng(n + rank)
    F = rng.standard_normal((n, rank)) @ rng.standard_normal((rank, n))
    S, b = F @ F.T, rng.standard_normal(n)
    want = np.linalg.pinv(S, rcond=1e-10) @ b
    a, got = np.tril(S).copy(), b.copy()
    r = pinv_solve_sym(a, n, got, 1e-10, np.empty((n, n)), np.empty(n), np.empty(n))
    assert r == rank
    assert np.max(np.abs(got - want)) <= 1e-12 * np.max(np.abs(want))


def test_fma_rounds_once_where_the_host_has_fma():
    """(1 + 2⁻³⁰)² − (1 + 2⁻²⁹) = 2⁻⁶⁰ exactly; multiply-then-add rounds the square to
    1 + 2⁻²⁹ and gives 0.  Without FMA hardware ``fma`` is that multiply-then-add."""
    from numba import njit

    from stabdae.engine.fma import HOST_FMA, fma

    @njit
    def f(a, b, c):
        return fma(a, b, c)

    a = 1.0 + 2.0**-30
    assert f(a, a, -(1.0 + 2.0**-29)) == (2.0**-60 if HOST_FMA else 0.0)
    assert f(3, 2.0, 1.0) == 7.0  # integers are converted


@pytest.mark.parametrize("scale", [1e-20, 1.0, 1e20])
def test_pivot_rule_is_relative_to_the_matrix_scale(scale):
    """The pivot test is relative to the largest diagonal entry, so a badly scaled matrix
    is judged as its unscaled self: a well-conditioned SPD matrix factors at any scale
    (an absolute 1e-12 would call it singular at 1e-20), and one singular to working
    precision is reported at any scale (an absolute threshold would pass it at 1e20)."""
    good = scale * np.array([[4.0, 1.0], [1.0, 3.0]])
    buf = good.copy()
    assert ldl_inplace(buf, 2, 1e-12) == 0
    L = np.array([[1.0, 0.0], [buf[1, 0], 1.0]])
    np.testing.assert_allclose(L @ np.diag(1.0 / np.diag(buf)) @ L.T, good, rtol=1e-14)
    near = scale * np.array([[1.0, 1.0], [1.0, 1.0 + 1e-14]])
    assert ldl_inplace(near.copy(), 2, 1e-12) == 2


@pytest.mark.parametrize("rtol", [0.0, 1e-14, 1e-12, 0.5])
def test_written_out_pivot_of_size_one_fails_as_the_loop(rtol):
    """Of size 1 the written-out factor tests its pivot as ``min(d, 1/d) > 0``, with no
    product by the tolerance: for tolerances up to 1/2 it must fail the same pivots as
    the loops (d ≤ 0, ±inf, NaN, the signed zeros) and pass the same, the subnormal ones
    included, and store the same reciprocal."""
    from stabdae.engine.linalg import ldl_factor_for

    tiny = np.finfo(float).smallest_subnormal
    pivots = [np.nan, np.inf, -np.inf, 0.0, -0.0, -1.0, -tiny, tiny, 1e-300, 1.0, 1e300,
              np.finfo(float).max]  # fmt: skip
    for d in pivots:
        loops, out = np.full((2, 2), d), np.full((2, 2), d)
        code_loop = ldl_inplace(loops, 1, rtol)
        assert ldl_factor_for(1)(out, 1, rtol) == code_loop, d
        assert code_loop == (not 0.0 < d < np.inf), d
        assert np.array_equal(out, loops, equal_nan=True), d



@pytest.mark.parametrize("n", [1, 2, 3, 4, 8])  # each size is a compilation
def test_written_out_and_looped_ldl_agree_bit_for_bit(n):
    """The straight-line factor and solves that a dense right-hand side uses for its sizes
    (so that the ensemble kernel's member loop around them vectorizes) do the loops'
    operations in the loops' order: the same bits, the same failing pivot, the same
    untouched entries outside the leading block."""
    from stabdae.engine.linalg import (
        UNROLL_MAX_OPS,
        ldl_factor_for,
        ldl_solve_columns_for,
        ldl_solve_for,
    )

    assert ldl_factor_for(n) is not ldl_inplace  # written out at these sizes
    rng = np.random.default_rng(10 + n)
    B = rng.standard_normal((n, n))
    A = B @ B.T + 0.1 * np.eye(n)
    buf = np.full((n + 2, n + 2), 7.0)
    buf[:n, :n] = A
    buf[np.triu_indices(n, 1)] = 3.0  # the strict upper triangle is neither read nor written
    loops, out = buf.copy(), buf.copy()
    assert ldl_factor_for(n)(out, n, 1e-14) == ldl_inplace(loops, n, 1e-14) == 0
    assert np.array_equal(out, loops)
    b = rng.standard_normal(n)
    x_loop, x_out = b.copy(), b.copy()
    ldl_solve_inplace(loops, n, x_loop)
    ldl_solve_for(n)(out, n, x_out)
    assert np.array_equal(x_out, x_loop)
    for ncols in (1, 3, 6):
        Bm = rng.standard_normal((n + 1, ncols + 1))  # a larger buffer, leading block used
        X_loop, X_out = Bm.copy(), Bm.copy()
        ldl_solve_columns(loops, n, X_loop, ncols)
        ldl_solve_columns_for(n, ncols)(out, n, X_out, ncols)
        assert np.array_equal(X_out, X_loop)
    # a pivot that fails reports the same (first) failing column
    if n >= 2:
        bad = buf.copy()
        bad[n - 1, :n - 1] = bad[:n - 1, n - 1] = A[0, : n - 1]
        bad[n - 1, n - 1] = A[0, 0]  # row n−1 repeats row 0: singular
        bad_loop = bad.copy()
        code = ldl_inplace(bad_loop, n, 1e-12)
        assert code == n and ldl_factor_for(n)(bad, n, 1e-12) == code
    # beyond the size limit the loops themselves (their code does not grow with n)
    big = 1 + round((6 * UNROLL_MAX_OPS) ** (1 / 3))
    assert ldl_factor_for(big) is ldl_inplace
    assert ldl_solve_columns_for(n, UNROLL_MAX_OPS + 1) is ldl_solve_columns


def test_written_out_routines_of_size_zero_do_nothing():
    """A model without holonomic constraints (m = 0) gets the solves of size 0."""
    from stabdae.engine.linalg import ldl_solve_columns_for, ldl_solve_for

    b = np.arange(3.0)
    ldl_solve_for(0)(np.eye(3), 0, b)
    ldl_solve_columns_for(0, 2)(np.eye(3), 0, np.eye(3), 2)
    ldl_solve_columns_for(3, 0)(np.eye(3), 3, np.eye(3), 0)
    assert np.array_equal(b, np.arange(3.0))


def _nested(a):
    return tuple(tuple(bool(v) for v in row) for row in a)


@pytest.mark.parametrize("shape", ["blocks", "arrow"])
def test_written_out_routines_for_a_pattern_skip_its_zeros_only(shape):
    """With the matrix's structural zeros given, the written-out factor and solves do the
    dense routines' operations minus the structurally zero terms: the same numbers up to
    the sign of a zero on the factor's pattern (its fill included: an arrow matrix whose
    first row is full fills in completely), the entries off it neither read nor written,
    and the solution's non-zeros where :func:`solve_pattern` says."""
    from stabdae.engine.linalg import (
        factor_ops,
        ldl_factor_for,
        ldl_solve_columns_for,
        ldl_solve_for,
        solve_pattern,
    )
    from stabdae.engine.sparsity import fill_pattern

    n = 7
    if shape == "blocks":  # Andrews' mass matrix: pairs of coupled angles and a single one
        pat = np.zeros((n, n), dtype=bool)
        for lo, hi in ((0, 2), (2, 3), (3, 5), (5, 7)):
            pat[lo:hi, lo:hi] = True
    else:  # arrow: every entry of row and column 0 and the diagonal
        pat = np.eye(n, dtype=bool)
        pat[0, :] = pat[:, 0] = True
    fill = fill_pattern(np.tril(pat))
    assert shape == "blocks" or fill.sum() == n * (n + 1) // 2  # the arrow fills in
    rng = np.random.default_rng(3)
    B = rng.standard_normal((n, n)) * pat
    A = (B @ B.T + np.eye(n)) * pat  # SPD with exactly that pattern
    key = _nested(np.tril(pat))
    assert factor_ops(n, key) < factor_ops(n, None) or shape == "arrow"
    dense = A.copy()
    assert ldl_inplace(dense, n, 1e-14) == 0
    buf = np.where(fill, A, 5.0)  # off the factor's pattern: a value no sum may read
    buf[np.triu_indices(n, 1)] = 3.0
    assert ldl_factor_for(n, key)(buf, n, 1e-14) == 0
    np.testing.assert_array_equal(buf[fill], dense[fill])
    assert np.all(buf[np.tril(~fill)] == 5.0) and np.all(buf[np.triu_indices(n, 1)] == 3.0)
    b = rng.standard_normal(n)
    x, xd = b.copy(), b.copy()
    ldl_solve_for(n, key)(buf, n, x)
    ldl_solve_inplace(dense, n, xd)
    np.testing.assert_array_equal(x, xd)
    # right sides with structural zeros: column c has non-zeros in rows c and c + 3 only
    cols = np.zeros((n, 3), dtype=bool)
    for c in range(3):
        cols[[c, c + 3], c] = True
    Xpat, ops = solve_pattern(np.tril(pat), cols)
    Bm = np.where(cols, rng.standard_normal((n, 3)), 0.0)
    Xd = Bm.copy()
    ldl_solve_columns(dense, n, Xd, 3)
    X = np.where(cols, Bm, 9.0)  # 9: entries the solve must not read (it writes Xpat's)
    ldl_solve_columns_for(n, 3, key, _nested(cols))(buf, n, X, 3)
    np.testing.assert_array_equal(X[Xpat], Xd[Xpat])
    assert np.all(Xd[~Xpat] == 0.0) and np.all(X[~Xpat] == 9.0)
    if shape == "blocks":  # a column's non-zeros fill their blocks, no more
        assert Xpat.sum() == 4 + 4 + 3 and ops < n * n * 3


def test_written_out_code_reads_and_writes_each_entry_once():
    """The written-out factor and solves keep every entry in a local: each array entry is
    read at most once (at the start) and written at most once (before the return), where
    the operations read and write them a cubic number of times; indexing that is not by
    constants is left as it is."""
    import inspect
    import re

    from stabdae.engine import linalg

    n = 8
    for fn in (linalg.ldl_factor_for(n), linalg.ldl_solve_for(n),
               linalg.ldl_solve_columns_for(n, 3)):  # fmt: skip
        line = getattr(fn, "straight_line", None)  # the code it compiles, where the JIT runs
        source = linalg._unparsed(line()) if line is not None else inspect.getsource(fn)
        reads = re.findall(r"_at\d\((\w+), ([\d, ]+)\)", source)
        writes = re.findall(r"_set\d\((\w+), ([\d, ]+), ", source)
        assert reads and writes
        assert len(reads) == len(set(reads)) and len(writes) == len(set(writes))
        assert "[" not in source.split(":", 1)[1]  # no subscript left in the body
    source = linalg._scalarized("def f(a, b, k):\n    s = a[0, 1]\n    s = s + a[k, 1]\n"
                                "    b[1] *= s\n    b[0] = s\n    b[0] *= 2.0\n"
                                "    return s\n")  # fmt: skip
    assert "a[k, 1]" in source and "a[0, 1]" in source  # a has a dynamic index: kept
    assert source.index("_at1(b, 1)") < source.index("_b_1 *= s")  # read, then scaled
    assert "_at1(b, 0)" not in source  # written before it is read: never loaded
    assert source.index("_set1(b, 1, _b_1)") < source.index("return s")
    assert source.index("_set1(b, 0, _b_0)") < source.index("return s")
