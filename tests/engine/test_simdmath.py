"""The vectorizing sine and cosine against 50-digit values, and what makes them worth having:
they vectorize, and the vector lanes give the scalar function's bits."""

from __future__ import annotations

import math
import re

import mpmath
import numpy as np
import pytest
from numba import njit

from conftest import compiled_only
from stabdae import simdmath


@njit(error_model="numpy")
def _both(x, s, c):
    for i in range(x.size):
        s[i] = simdmath.sin(x[i])
        c[i] = simdmath.cos(x[i])


def _evaluate(x):
    s, c = np.empty_like(x), np.empty_like(x)
    _both(x, s, c)
    return s, c


def _arguments(limit, seed):
    """Uniform arguments, and the doubles nearest to multiples of π/2 (where the reduced
    argument cancels most)."""
    rng = np.random.default_rng(seed)
    k = rng.integers(-int(limit / 1.6), int(limit / 1.6) + 1, 500, dtype=np.int64)
    return np.concatenate([rng.uniform(-limit, limit, 3000), k * (math.pi / 2),
                           [0.0, -0.0, math.pi / 4, -math.pi / 4, 5e-324]])  # fmt: skip


def _exact(fn, x):
    with mpmath.workdps(50):
        return [fn(mpmath.mpf(float(v))) for v in x]


@pytest.mark.parametrize("limit", [math.pi / 4, 10.0, 1e3, 1.6e6])
def test_within_one_ulp_where_the_reduction_is_exact(limit):
    x = _arguments(limit, seed=int(limit))
    s, c = _evaluate(x)
    for got, fn in ((s, mpmath.sin), (c, mpmath.cos)):
        exact = _exact(fn, x)
        ulps = [float(abs(g - e)) / math.ulp(float(e)) if float(e) != 0 else float(abs(g - e))
                for g, e in zip(got, exact)]  # fmt: skip
        assert max(ulps) <= 1.0, (fn.__name__, limit, max(ulps), x[int(np.argmax(ulps))])


@pytest.mark.parametrize("limit, bound", [(1e10, 2.5e-16), (1e12, 1e-14)])
def test_absolute_error_beyond_the_exact_reduction(limit, bound):
    x = _arguments(limit, seed=7)
    s, c = _evaluate(x)
    for got, fn in ((s, mpmath.sin), (c, mpmath.cos)):
        err = max(float(abs(g - e)) for g, e in zip(got, _exact(fn, x)))
        assert err <= bound, (fn.__name__, limit, err)


def test_not_finite_and_huge_arguments_give_nan():
    s, c = _evaluate(np.array([np.inf, -np.inf, np.nan, 2.0**50, -(2.0**60)]))
    assert np.isnan(s).all() and np.isnan(c).all()
    s, c = _evaluate(np.array([2.0**49]))  # the largest handled range still reduces
    assert np.isfinite(s).all() and abs(s[0] ** 2 + c[0] ** 2 - 1.0) < 1e-12


@compiled_only
def test_the_loop_vectorizes_and_its_lanes_give_the_scalar_bits():
    x = _arguments(100.0, seed=3)
    s, c = _evaluate(x)  # compiles the loop (this test may run alone)
    ir = _both.inspect_llvm(_both.signatures[0])
    assert re.search(r"<\d+ x double>", ir), "the loop around simdmath.sin/cos stayed scalar"
    # a loop over math.sin also has vector types, with llvm.sin.v4f64 split back into
    # scalar library calls by the backend: no call to any sine or cosine may be left
    calls = re.findall(r"call [^\n]*@([\w.]*(?:sin|cos)[\w.]*)\(", ir)
    assert not calls, calls
    scalar_s = np.array([simdmath.sin(v) for v in x])  # one compiled call per argument
    scalar_c = np.array([simdmath.cos(v) for v in x])
    np.testing.assert_array_equal(s, scalar_s)
    np.testing.assert_array_equal(c, scalar_c)
