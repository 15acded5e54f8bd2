"""Placing members at prescribed constraint perturbations: targets reached, radii
log-uniform, corrections of minimum norm, residual rows of the sampler's kernel."""

from __future__ import annotations

import math

import numpy as np
import pytest

import stabdae
from conftest import load_scene


@pytest.mark.parametrize("radius", [(1e-6, 1e-2), (0.05, 0.5)])
def test_sampling_reaches_the_targets(radius):
    """Small targets are met with the reference state's Jacobian (a step or two), large
    ones, where that converges slowly or not at all, by Gauss–Newton at the current state:
    both to the same accuracy."""
    model = load_scene("double_pendulum")
    x0, alpha0, status = stabdae.sample_perturbations(model, 200, radius, seed=5)
    assert (status == 0).all()
    from stabdae.engine.sampler import draw_alphas

    targets = draw_alphas(model.n_residual, 200, radius, 5)  # the seed's targets again
    err = np.max(np.abs(alpha0 - targets), axis=1)
    size = np.max(np.abs(targets), axis=1)
    x_scale = np.max(np.abs(x0), axis=1)
    assert np.all(err <= 1e-12 * size + 64 * np.finfo(float).eps * x_scale**2)
    assert np.all((err / size)[size > 1e-3] <= 1e-12)  # relative where double allows it
    norms = np.max(np.abs(alpha0), axis=1)
    assert radius[0] * (1 - 1e-9) <= norms.min() and norms.max() <= radius[1] * (1 + 1e-9)
    # the achieved perturbation is g(x0): checked with the Python-side residual
    for x, a in zip(x0[:20], alpha0[:20]):
        np.testing.assert_allclose(model.residual(x), a, rtol=1e-9, atol=1e-15)


def test_radii_are_log_uniform_and_directions_of_unit_max_norm():
    """‖α⁰‖∞ of the placed members is log-uniform in the radius range: a Kolmogorov–Smirnov
    test of log ‖α⁰‖∞ against the uniform law on [log low, log high] (uniform radii put
    nine tenths of them in the top decade and fail it at p < 1e-100)."""
    from scipy.stats import kstest

    model = load_scene("pendulum")
    low, high = 1e-6, 1e-2
    _, alpha0, status = stabdae.sample_perturbations(model, 2000, (low, high), seed=11)
    assert (status == 0).all()
    logr = np.log(np.max(np.abs(alpha0), axis=1))
    assert math.log(low) * (1 + 1e-9) <= logr.min() and logr.max() <= math.log(high) + 1e-9
    test = kstest(logr, "uniform", args=(math.log(low), math.log(high / low)))
    assert test.pvalue > 1e-3, test
    # and not uniform in r itself
    assert kstest(np.exp(logr), "uniform", args=(low, high - low)).pvalue < 1e-10


def test_sampling_is_minimum_norm_to_first_order():
    """For small α⁰, x⁰ − x* ≈ G⁺α⁰ (G from finite differences at x*)."""
    model = load_scene("pendulum")
    x_ref = model.reference_state()
    x0, alpha0, _ = stabdae.sample_perturbations(model, 20, (1e-7, 1e-6), seed=1)
    h = 1e-6
    G = np.stack([(model.residual(x_ref + h * e) - model.residual(x_ref - h * e)) / (2 * h)
                  for e in np.eye(4)], axis=1)  # fmt: skip
    expected = np.linalg.pinv(G) @ alpha0.T
    np.testing.assert_allclose(x0 - x_ref, expected.T, rtol=1e-4, atol=1e-13)


def test_residual_rows_by_the_sampler_are_those_of_their_kernel():
    """An ensemble that sampled its members evaluates the roundoff level's residual rows
    with the sampler it has compiled (placing skipped): the same numbers, bit for bit, as
    the kernel for residual rows, at a time of its own (a time-dependent model), through
    a non-finite row, on more rows than one chunk, and the caller's states untouched."""
    from stabdae import _ensemble

    model = load_scene("pendulum_varying_length")
    p = model.param_vector(None)
    X = np.random.default_rng(4).normal(size=(150, 2 * model.n))
    X[7, 1] = np.nan
    before = X.copy()
    by_kernel = _ensemble._residual_rows(model, X, p, 0.37)
    by_sampler = _ensemble._residual_rows(model, X, p, 0.37, sampler=True)
    np.testing.assert_array_equal(by_sampler, by_kernel)
    assert np.isnan(by_sampler[7]).any() and np.isfinite(np.delete(by_sampler, 7, 0)).all()
    np.testing.assert_array_equal(X, before)
    assert not np.array_equal(by_kernel, _ensemble._residual_rows(model, X, p, 0.0))
