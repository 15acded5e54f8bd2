"""The other stabilizations of the toolkit: Ascher–Chin–Petzold–Reich (ACPR), post-
stabilization and coordinate projection (the end of the paper's §3).

References: on the affine system of tests/models/affine.py the ACPR residual obeys a linear law
whose matrix is derived by hand below, so one RK step maps g by the scheme's stability
polynomial exactly; a projection lands on the manifold (invariant g = 0), radially for the
pendulum (the closest point of the circle, closed form); projection does not change the
order of the scheme (convergence slope against a tight reference).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

import stabdae
from conftest import load_scene, perturbed_state
from models.affine import model as affine
from stabdae._laws import LawError, bind_law
from stabdae.engine.rhs import kernels_for
from stabdae.theory import step_matrix


def acpr_matrix(gamma: float) -> np.ndarray:
    """ġ = Ã g for ACPR on the affine system, g = (f, ḟ, h), M = I.

    δq = f_qᵀ f / (f_q f_qᵀ) with f_q = (1, 2, 0), so ḟ(f)/dt = ḟ − γ f; F δv = (ḟ, h)
    gives d ḟ/dt = −γ ḟ (ḟ = f_q v + f_t does not depend on q) and d h/dt = −γ h − γ h_q δq
    with h_q δq = 0.2 · 2/5 f = 0.08 f.
    """
    return np.array([[-gamma, 1.0, 0.0], [0.0, -gamma, 0.0], [-0.08 * gamma, 0.0, -gamma]])


@pytest.mark.parametrize("scheme", ["euler", "midpoint", "rk4"])
def test_acpr_residual_law_on_the_affine_system(scheme):
    gamma, tau = 7.0, 0.01
    x0 = affine.reference_state() + np.array([0.03, -0.02, 0.01, 0.02, -0.04, 0.05])
    ds = stabdae.integrate(affine, x0, stabdae.acpr(gamma), scheme, tau, 1.0)
    g = ds.residual.values
    R = step_matrix(acpr_matrix(gamma), scheme, tau)
    pred = g[:-1] @ R.T
    assert np.max(np.abs(g[1:] - pred)) < 1e-13 * np.max(np.abs(g[0])) + 1e-15
    # the continuous law to the scheme's accuracy
    exact = expm(acpr_matrix(gamma) * 1.0) @ g[0]
    tol = {"euler": 0.2, "midpoint": 5e-3, "rk4": 1e-6}[scheme]
    assert np.max(np.abs(g[-1] - exact)) <= tol * np.max(np.abs(g[0]))


def test_acpr_stabilizes_a_nonlinear_model():
    """Double pendulum: the index-1 equations drift, ACPR pulls the residual down."""
    model = load_scene("double_pendulum")
    x0 = perturbed_state(model, 1e-3)
    free = stabdae.integrate(model, x0, stabdae.none(), "rk4", 1e-3, 2.0, 0.5)
    acpr = stabdae.integrate(model, x0, stabdae.acpr(20.0), "rk4", 1e-3, 2.0, 0.5)
    g0 = acpr.residual_norm.values[0]
    assert free.residual_norm.values[-1] > 0.5 * g0  # no decay without stabilization
    # eigenvalue −γ (defective): below (1 + 2γt) e^{−γt} g0, down to the truncation floor
    # of RK4 at this step (2.8e-10 measured at t = 2)
    for t in (0.5, 1.0, 2.0):
        bound = (1 + 2 * 20.0 * t) * np.exp(-20.0 * t) * g0 + 1e-9
        assert acpr.residual_norm.sel(time=t).item() < bound


def test_acpr_needs_the_ldl_multiplier():
    model = load_scene("pendulum")
    with pytest.raises(LawError, match="multiplier must be 'ldl'"):
        stabdae.integrate(model, None, stabdae.acpr(10.0), "rk4", 1e-3, 0.01,
                          multiplier="lstsq")  # fmt: skip
    with pytest.raises(LawError, match="positive"):
        stabdae.acpr(-1.0)
    with pytest.raises(LawError, match="not a law"):
        stabdae.acpr(1.0).A_tilde(model)


def test_projection_lands_on_the_pendulum_circle_radially():
    """Pendulum: M = I, f = x² + y² − l²; the projection of q is l q/|q| (the closest
    point of the circle) and of v its tangential part (closed forms)."""
    model = load_scene("pendulum")
    K = kernels_for(model, bind_law(stabdae.none(), model))
    p = model.default_params()
    length = p[list(model.param_names).index("l")]
    x = np.array([0.9 * length, -0.5 * length, 0.3, 0.7])
    ws = K.make_workspace()
    y = x.copy()
    assert K.project(0.0, y, p, ws, 8, 0.0) == 0
    q = x[:2] * length / np.linalg.norm(x[:2])
    u = q / np.linalg.norm(q)
    v = x[2:] - (x[2:] @ u) * u
    np.testing.assert_allclose(y[:2], q, rtol=0, atol=1e-14)
    np.testing.assert_allclose(y[2:], v, rtol=0, atol=1e-14)
    # one sweep (post-stabilization) only reduces the position residual quadratically
    y = x.copy()
    K.project(0.0, y, p, ws, 1, 0.0)
    f0 = abs(x[0] ** 2 + x[1] ** 2 - length**2)
    f1 = abs(y[0] ** 2 + y[1] ** 2 - length**2)
    assert 0 < f1 < 0.2 * f0


def test_projection_full_goes_to_the_fixed_point():
    """integrate(projection="full") from a state far off the pendulum's circle: after one
    (negligible) step the state is the projection's fixed point, the closest point of the
    circle and the tangential velocity (closed forms), not one sweep's approximation."""
    model = load_scene("pendulum")
    length = model.default_params()[list(model.param_names).index("l")]
    x = np.array([0.9 * length, -0.5 * length, 0.3, 0.7])
    ds = stabdae.integrate(model, x, stabdae.none(), "euler", 1e-13, 1e-13,
                           projection="full")  # fmt: skip
    q = x[:2] * length / np.linalg.norm(x[:2])
    u = q / np.linalg.norm(q)
    np.testing.assert_allclose(ds.x.values[1, :2], q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ds.x.values[1, 2:], x[2:] - (x[2:] @ u) * u, rtol=0, atol=1e-12)
    assert float(ds.residual_norm[1]) < 1e-14


@pytest.mark.parametrize("name", ["double_pendulum", "affine", "chaplygin_sleigh"])
def test_projection_keeps_the_residual_at_roundoff(name):
    model = affine if name == "affine" else load_scene(name)
    x0 = perturbed_state(model, 1e-3)
    law = stabdae.none()
    post = stabdae.integrate(model, x0, law, "rk4", 1e-3, 1.0, 0.1, projection="post")
    full = stabdae.integrate(model, x0, law, "rk4", 1e-3, 1.0, 0.1, projection="full")
    drift = stabdae.integrate(model, x0, law, "rk4", 1e-3, 1.0, 0.1)
    assert post.attrs["projection"] == "post" and drift.attrs["projection"] == "none"
    assert np.max(post.residual_norm.values[1:]) < 1e-12
    assert np.max(full.residual_norm.values[1:]) < 1e-13
    assert drift.residual_norm.values[-1] > 1e-6


def test_projection_keeps_the_order_of_the_scheme():
    """RK4 with coordinate projection on the index-1 equations converges with order 4."""
    model = load_scene("double_pendulum")
    ref = stabdae.integrate_adaptive(model, None, stabdae.baumgarte(10.0), 1.0,
                                     rtol=1e-13, atol=1e-13).x.values[-1]  # fmt: skip
    errs = []
    taus = [2e-2, 1e-2, 5e-3]
    for tau in taus:
        x = stabdae.integrate(model, None, stabdae.none(), "rk4", tau, 1.0, 1.0,
                              projection="full").x.values[-1]  # fmt: skip
        errs.append(np.max(np.abs(x - ref)))
    slope = np.polyfit(np.log(taus), np.log(errs), 1)[0]
    assert 3.6 < slope < 4.6, (slope, errs)


def test_adaptive_with_projection_and_acpr():
    model = load_scene("double_pendulum")
    x0 = perturbed_state(model, 1e-3)
    post = stabdae.integrate_adaptive(model, x0, stabdae.none(), 2.0, rtol=1e-8, atol=1e-8,
                                      save_dt=0.5, projection="post")  # fmt: skip
    plain = stabdae.integrate_adaptive(model, x0, stabdae.none(), 2.0, rtol=1e-8, atol=1e-8,
                                       save_dt=0.5)  # fmt: skip
    assert np.max(post.residual_norm.values[1:]) < 1e-12
    assert plain.residual_norm.values[-1] > 1e-4
    # the projection costs one evaluation per accepted step (first-same-as-last is lost)
    a = post.attrs
    assert a["rhs_evaluations"] >= 7 * a["steps_accepted"]
    acpr = stabdae.integrate_adaptive(model, x0, stabdae.acpr(20.0), 2.0, rtol=1e-8,
                                      atol=1e-8, save_dt=0.5)  # fmt: skip
    assert acpr.residual_norm.values[-1] < 1e-6


def test_bad_projection_argument():
    model = load_scene("pendulum")
    with pytest.raises(ValueError, match="projection must be None, 'post' or 'full'"):
        stabdae.integrate(model, None, stabdae.none(), "rk4", 1e-3, 0.01, projection="yes")
