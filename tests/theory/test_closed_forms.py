"""Scenes against their exact solutions."""

from __future__ import annotations

import numpy as np
from scipy.integrate import quad

import stabdae
from conftest import load_scene, scene_module


def test_knife_edge_exact_solution():
    model = load_scene("knife_edge")
    law = stabdae.baumgarte(k=5.0)
    ds = stabdae.integrate(model, None, law, "rk4", 1e-3, 4.0, 0.1)
    exact = scene_module("knife_edge").exact_solution(model.default_params(), ds.time.values)
    np.testing.assert_allclose(ds["x"].values, exact, rtol=0, atol=1e-10)


def test_knife_edge_exact_solution_general_start():
    """Closed form from a start with φ0 ≠ 0 and the slope pulling sideways."""
    model = load_scene("knife_edge")
    mod = scene_module("knife_edge")
    p = model.default_params()
    phi0, u0, om = 0.7, -0.3, -2.0
    x0 = np.array([0.2, -0.1, phi0, u0 * np.cos(phi0), u0 * np.sin(phi0), om])
    ds = stabdae.integrate(model, x0, stabdae.baumgarte(k=5.0), "rk4", 1e-3, 3.0, 0.1)
    exact = mod.exact_solution(p, ds.time.values, u0=u0, omega=om, x0=0.2, y0=-0.1, phi0=phi0)
    np.testing.assert_allclose(ds["x"].values, exact, rtol=0, atol=1e-10)


def test_chaplygin_sleigh_exact_solution():
    model = load_scene("chaplygin_sleigh")
    mod = scene_module("chaplygin_sleigh")
    p = model.default_params()
    ds = stabdae.integrate(model, None, stabdae.baumgarte(k=5.0), "rk4", 1e-3, 4.0, 0.1)
    x = ds["x"].values
    t = ds.time.values
    u_ex, om_ex, phi_ex = mod.exact_solution(p, t)
    u = np.cos(x[:, 2]) * x[:, 3] + np.sin(x[:, 2]) * x[:, 4]
    np.testing.assert_allclose(x[:, 2], phi_ex, rtol=0, atol=1e-10)
    np.testing.assert_allclose(x[:, 5], om_ex, rtol=0, atol=1e-10)
    np.testing.assert_allclose(u, u_ex, rtol=0, atol=1e-10)
    # the contact point's path: x(t) = ∫ u cos φ, y(t) = ∫ u sin φ (adaptive quadrature)
    for i in (10, 25, 40):
        xq = quad(lambda s: _vx(mod, p, s), 0, t[i], epsabs=1e-13, epsrel=1e-13)[0]
        yq = quad(lambda s: _vy(mod, p, s), 0, t[i], epsabs=1e-13, epsrel=1e-13)[0]
        assert abs(x[i, 0] - xq) < 1e-9 and abs(x[i, 1] - yq) < 1e-9


def _vx(mod, p, s):
    u, _, phi = mod.exact_solution(p, s)
    return float(u * np.cos(phi))


def _vy(mod, p, s):
    u, _, phi = mod.exact_solution(p, s)
    return float(u * np.sin(phi))


def test_hoop_bead_relative_equilibrium():
    """Started at the relative equilibrium, the bead turns with the hoop at fixed θ*."""
    model = load_scene("hoop_bead")
    mod = scene_module("hoop_bead")
    p = model.default_params()
    assert 0.5 < mod.relative_equilibrium_angle(p) < 1.5  # off the bottom: Ω²R > g
    ds = stabdae.integrate(model, None, stabdae.baumgarte(10.0, 1.0), "rk4", 1e-3, 5.0, 0.1)
    exact = np.stack([mod.relative_equilibrium(p, t) for t in ds.time.values])
    np.testing.assert_allclose(ds["x"].values, exact, rtol=0, atol=1e-9)


def test_hoop_bead_off_equilibrium_is_not_fixed():
    """The comparison above can fail: a bead started below θ* oscillates away from it."""
    model = load_scene("hoop_bead")
    mod = scene_module("hoop_bead")
    p = model.default_params()
    th = mod.relative_equilibrium_angle(p) - 0.2
    R, om = p[1], p[2]
    x0 = np.array([R * np.sin(th), 0, -R * np.cos(th), 0, R * np.sin(th) * om, 0])
    ds = stabdae.integrate(model, x0, stabdae.baumgarte(10.0, 1.0), "rk4", 1e-3, 2.0, 0.1)
    exact = np.stack([mod.relative_equilibrium(p, t) for t in ds.time.values])
    assert np.max(np.abs(ds["x"].values - exact)) > 0.05
