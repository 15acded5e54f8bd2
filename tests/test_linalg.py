"""Small dense Cholesky routines against NumPy, and their failure reports."""

from __future__ import annotations

import numpy as np
import pytest

from stabdae._linalg import cholesky_inplace, cholesky_solve_columns, cholesky_solve_inplace


@pytest.mark.parametrize("n", [1, 2, 3, 5, 8])
def test_cholesky_matches_numpy(n):
    rng = np.random.default_rng(n)
    B = rng.standard_normal((n, n))
    A = B @ B.T + n * np.eye(n)
    buf = np.full((n + 2, n + 2), 7.0)  # a larger buffer: only the leading block is used
    buf[:n, :n] = A
    assert cholesky_inplace(buf, n, 1e-14) == 0
    L = np.tril(buf[:n, :n])
    np.testing.assert_allclose(L, np.linalg.cholesky(A), rtol=1e-13, atol=1e-13)
    assert np.all(buf[n:, :] == 7.0) and np.all(buf[:, n:] == 7.0)
    b = rng.standard_normal(n)
    x = b.copy()
    cholesky_solve_inplace(buf, n, x)
    np.testing.assert_allclose(A @ x, b, rtol=1e-12, atol=1e-12)
    Bm = rng.standard_normal((n, 3))
    X = Bm.copy()
    cholesky_solve_columns(buf, n, X, 3)
    np.testing.assert_allclose(A @ X, Bm, rtol=1e-12, atol=1e-12)


def test_singular_indefinite_and_nan_are_reported():
    singular = np.array([[1.0, 1.0], [1.0, 1.0]])
    assert cholesky_inplace(singular.copy(), 2, 1e-12) == 2
    indefinite = np.array([[1.0, 0.0], [0.0, -1.0]])
    assert cholesky_inplace(indefinite.copy(), 2, 0.0) == 2
    nan = np.array([[np.nan, 0.0], [0.0, 1.0]])
    assert cholesky_inplace(nan.copy(), 2, 0.0) == 1
    # nearly singular beyond the relative threshold
    near = np.array([[1.0, 1.0], [1.0, 1.0 + 1e-14]])
    assert cholesky_inplace(near.copy(), 2, 1e-12) == 2
    assert cholesky_inplace(near.copy(), 2, 1e-16) == 0
