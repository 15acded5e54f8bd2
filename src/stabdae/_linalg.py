"""Small dense linear algebra for the stabilized right-hand side.

The matrices met per right-hand-side evaluation are tiny (the mass matrix is n×n, the
constraint matrix ``S = F M⁻¹ Fᵀ`` is r×r with n, r of order 1–10), so a LAPACK call
costs more in dispatch than in arithmetic.  These routines work in place on caller-owned
buffers, allocate nothing and never raise: a failed factorization is reported through the
return value, which the caller turns into a status code.

Only the leading ``n×n`` block of a buffer is touched, so one buffer can serve several sizes.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True, error_model="numpy", inline="always")
def cholesky_inplace(a, n, rtol):
    """Lower Cholesky factor of the SPD matrix ``a[:n, :n]``, in place.

    On return the lower triangle (diagonal included) of ``a[:n, :n]`` holds ``L`` with
    ``a = L Lᵀ``; the strict upper triangle is left as it was and must not be read.

    Parameters
    ----------
    a : float64[:, :]
        Buffer whose leading ``n×n`` block holds a symmetric matrix (only the lower
        triangle is read).
    n : int
        Size of the block.
    rtol : float
        A pivot ``d_j ≤ rtol · max_i |a_ii|`` (or a non-finite pivot) counts as a
        failure: the matrix is singular, indefinite or not finite to working precision.

    Returns
    -------
    int
        ``0`` on success, otherwise ``j + 1`` for the first failing pivot ``j``.
    """
    dmax = 0.0
    for i in range(n):
        d = abs(a[i, i])
        if d > dmax:
            dmax = d
    tol = rtol * dmax
    fail = 0
    for j in range(n):
        s = a[j, j]
        for p in range(j):
            s -= a[j, p] * a[j, p]
        # `not (s > tol)` is also true for NaN, so non-finite input fails here.  No early
        # return: the loop stays branch-free enough to vectorize across ensemble members;
        # after a failure the factor is garbage and the caller must not use it.
        if fail == 0 and (not (s > tol) or not math.isfinite(s)):
            fail = j + 1
        d = math.sqrt(s)
        a[j, j] = d
        for i in range(j + 1, n):
            s = a[i, j]
            for p in range(j):
                s -= a[i, p] * a[j, p]
            a[i, j] = s / d
    return fail


@njit(cache=True, error_model="numpy", inline="always")
def cholesky_solve_inplace(l, n, b):
    """Solve ``L Lᵀ x = b`` for one right-hand side, overwriting ``b[:n]`` with ``x``.

    ``l`` is the output of :func:`cholesky_inplace`. Nothing is checked.
    """
    for i in range(n):  # L y = b
        s = b[i]
        for p in range(i):
            s -= l[i, p] * b[p]
        b[i] = s / l[i, i]
    for i in range(n - 1, -1, -1):  # Lᵀ x = y
        s = b[i]
        for p in range(i + 1, n):
            s -= l[p, i] * b[p]
        b[i] = s / l[i, i]


@njit(cache=True, error_model="numpy", inline="always")
def cholesky_solve_columns(l, n, b, ncols):
    """Solve ``L Lᵀ X = B`` for the columns of ``b[:n, :ncols]``, in place.

    ``l`` is the output of :func:`cholesky_inplace`. Nothing is checked.
    """
    for c in range(ncols):
        for i in range(n):
            s = b[i, c]
            for p in range(i):
                s -= l[i, p] * b[p, c]
            b[i, c] = s / l[i, i]
        for i in range(n - 1, -1, -1):
            s = b[i, c]
            for p in range(i + 1, n):
                s -= l[p, i] * b[p, c]
            b[i, c] = s / l[i, i]
