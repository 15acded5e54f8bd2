"""The exact residual law: along the exact flow of (3.1), g(t) = expm(Ã t) g(t0).

The paper's §3: by construction of the multiplier (3.11) every model's residual obeys ġ = Ã g,
whatever its mechanics.  Integrating with RK4 at a small step and comparing g(t) with the
matrix exponential checks every derivative function of every scene and the right-hand
side itself; a wrong f_accel, h_q or sign in (3.11) breaks it at order one.
"""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit
from scipy.linalg import expm

import stabdae
from conftest import KINEMATIC, SCENES, load_kinematic, load_scene, perturbed_state

TAU, T_END, SAVE = 5e-4, 2.0, 0.05


def coupled_matrix(model: stabdae.Model, seed: int = 3) -> np.ndarray:
    """A constant A (r × (m+r)) with every block coupled, and Ã stable."""
    rng = np.random.default_rng(seed)
    base = stabdae.baumgarte(omega=6.0, xi=0.8, k=4.0 if model.k else None).A(model)
    A = base + 0.5 * rng.standard_normal(base.shape)
    A_tilde = stabdae.matrix(A).A_tilde(model)
    assert np.linalg.eigvals(A_tilde).real.max() < 0
    return A


def constant_laws(model):
    return {
        "baumgarte": stabdae.baumgarte(
            omega=10.0 if model.m else None, xi=1.0, k=3.0 if model.k else None
        ),
        "matrix": stabdae.matrix(coupled_matrix(model)),
        "none": stabdae.none(),
    }


def relative_law_error(model, law, x0):
    ds = stabdae.integrate(model, x0, law, "rk4", TAU, T_END, SAVE)
    g = ds["residual"].values
    A_tilde = law.A_tilde(model)
    exact = np.stack([expm(A_tilde * t) @ g[0] for t in ds.time.values])
    return np.max(np.abs(g - exact)) / np.max(np.abs(exact))


@pytest.mark.parametrize("law_name", ["baumgarte", "matrix", "none"])
@pytest.mark.parametrize("name", SCENES)
def test_residual_follows_expm(name, law_name):
    model = load_scene(name)
    law = constant_laws(model)[law_name]
    x0 = perturbed_state(model, 1e-3, seed=7)
    assert np.max(np.abs(model.residual(x0))) > 1e-5  # a real perturbation
    assert relative_law_error(model, law, x0) <= 1e-6


@pytest.mark.parametrize("law_name", ["baumgarte", "matrix"])
@pytest.mark.parametrize("name", list(KINEMATIC))
def test_residual_follows_expm_with_a_kinematic_map(name, law_name):
    """The same law for quasi-velocities (q̇ = T v): the quaternion's norm and, for the
    rolling ball, constraints on the orientation and the angular velocity together."""
    model = load_kinematic(name)
    law = constant_laws(model)[law_name]
    x0 = perturbed_state(model, 1e-3, seed=7)
    assert np.max(np.abs(model.residual(x0))) > 1e-5
    assert relative_law_error(model, law, x0) <= 1e-6


def test_law_error_detects_a_wrong_law():
    """The comparison can fail: the same data against a different Ã is far off."""
    model = load_scene("pendulum")
    x0 = perturbed_state(model, 1e-3, seed=7)
    ds = stabdae.integrate(model, x0, stabdae.baumgarte(10.0, 1.0), "rk4", TAU, T_END, SAVE)
    wrong = stabdae.baumgarte(10.0, 0.9).A_tilde(model)
    g = ds["residual"].values
    exact = np.stack([expm(wrong * t) @ g[0] for t in ds.time.values])
    assert np.max(np.abs(g - exact)) / np.max(np.abs(exact)) > 1e-3


@pytest.mark.parametrize("name", ["chaplygin_sleigh", "knife_edge"])
def test_theorem5_law_closed_form(name):
    """ḣ = −k W L h with W = h_v h_vᵀ = s_h² (sleigh) or 1 (knife edge): h = h0 e^{−k W L t}."""
    model = load_scene(name)
    gain, L = 2.0, 1.5
    law = stabdae.theorem5(gain, [[L]])
    x0 = perturbed_state(model, 1e-3, seed=2)
    p = model.default_params()
    w = p[model.param_names.index("s_h")] ** 2 if "s_h" in model.params else 1.0
    ds = stabdae.integrate(model, x0, law, "rk4", TAU, T_END, SAVE)
    h = ds["residual"].values[:, 0]
    exact = h[0] * np.exp(-gain * w * L * ds.time.values)
    assert np.max(np.abs(h - exact)) <= 1e-6 * abs(h[0])
    np.testing.assert_allclose(law.A_tilde(model, x0), [[-gain * w * L]], rtol=1e-12)


def test_theorem5_with_scaled_row():
    """With the sleigh's row scaled by s_h = 0.5, W = 0.25 and the decay slows by 4."""
    model = load_scene("chaplygin_sleigh")
    law = stabdae.theorem5(2.0)
    x0 = perturbed_state(model, 1e-3, seed=2)
    ds = stabdae.integrate(model, x0, law, "rk4", TAU, T_END, SAVE, params={"s_h": 0.5})
    h = ds["residual"].values[:, 0]
    exact = h[0] * np.exp(-2.0 * 0.25 * ds.time.values)
    assert np.max(np.abs(h - exact)) <= 1e-6 * abs(h[0])


@njit
def baumgarte_as_user_law(t, x, p, out):
    out[0, 0] = -100.0
    out[0, 1] = -20.0


@njit
def state_dependent_law(t, x, p, out):
    # ω²(x) = 25 (1 + x²): a gain that changes along the path
    w2 = 25.0 * (1.0 + x[0] * x[0])
    out[0, 0] = -w2
    out[0, 1] = -2.0 * np.sqrt(w2)


def test_user_law_constant_matches_expm():
    model = load_scene("pendulum")
    law = stabdae.user(baumgarte_as_user_law)
    x0 = perturbed_state(model, 1e-3, seed=7)
    assert relative_law_error(model, law, x0) <= 1e-6


def test_user_law_state_dependent_obeys_gdot():
    """ġ(t) = Ã(x(t)) g(t) along the path, checked with a central difference in time."""
    model = load_scene("pendulum")
    law = stabdae.user(state_dependent_law)
    x0 = perturbed_state(model, 1e-3, seed=7)
    dt = 1e-3
    ds = stabdae.integrate(model, x0, law, "rk4", 1e-4, 0.5, dt)
    g = ds["residual"].values
    xs = ds["x"].values
    gdot = (g[2:] - g[:-2]) / (2 * dt)
    predicted = np.stack([law.A_tilde(model, x) @ gi for x, gi in zip(xs[1:-1], g[1:-1])])
    scale = np.max(np.abs(predicted))
    assert np.max(np.abs(gdot - predicted)) <= 1e-4 * scale


@pytest.mark.parametrize("xi", [0.5, 1.0])
def test_baumgarte_residual_is_the_damped_oscillator(xi):
    """Baumgarte's law is f̈ + 2ξω ḟ + ω² f = 0 for each holonomic constraint: the
    pendulum's residual follows the damped oscillator's closed form,
    f(t) = e^{−ξωt}(f₀ cos ω_d t + (ḟ₀ + ξω f₀) sin(ω_d t)/ω_d), ω_d = ω√(1 − ξ²)
    (and (f₀ + (ḟ₀ + ω f₀) t) e^{−ωt} at ξ = 1), and ḟ its derivative."""
    model = load_scene("pendulum")
    omega = 10.0
    ds = stabdae.integrate(model, perturbed_state(model, 1e-3), stabdae.baumgarte(omega, xi),
                           "rk4", 5e-4, 0.5, 0.05)  # fmt: skip
    f0, fd0 = ds.residual.values[0]
    t = ds.time.values
    decay = np.exp(-xi * omega * t)
    if xi < 1:
        wd = omega * np.sqrt(1 - xi**2)
        c, s = np.cos(wd * t), np.sin(wd * t)
        b = (fd0 + xi * omega * f0) / wd
        f = decay * (f0 * c + b * s)
        fd = decay * (-xi * omega * (f0 * c + b * s) + wd * (-f0 * s + b * c))
    else:
        b = fd0 + omega * f0
        f = decay * (f0 + b * t)
        fd = decay * (b - omega * (f0 + b * t))
    scale = np.abs(ds.residual.values[0]).max()
    np.testing.assert_allclose(ds.residual.values[:, 0], f, rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(ds.residual.values[:, 1], fd, rtol=0, atol=1e-7 * scale)
