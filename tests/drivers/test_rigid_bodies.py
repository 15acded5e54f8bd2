"""Rigid bodies in unit quaternions with body angular velocities (a kinematic map
``q̇ = T(q) v``) against references with a source: the heavy symmetric top's closed-form
steady precession and first integrals, the torque-free body's Jacobi elliptic solution,
and the model interface's own rules for a map."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

import stabdae
from conftest import load_kinematic, perturbed_state, scene_module
from stabdae import rigid

LAW = stabdae.baumgarte(omega=10.0, xi=1.0)


def _precession_error(model, top, tau):
    ds = stabdae.integrate(model, None, LAW, "rk4", tau, 10.0, 0.5)
    axis = rigid.rotations(ds.x.values)[:, :, 2]  # R(p/|p|) e₃
    exact = top.exact_axis(ds.time.values, model.default_params())
    return float(np.abs(axis - exact).max()), ds


def test_heavy_top_precesses_at_the_closed_form_rate_with_its_first_integrals():
    """Steady precession: the axis at θ₀ from the vertical turning at the root Ω of
    ``A Ω² cos θ₀ − C ωz Ω + mgl = 0``, for 10 s (a third of a turn); energy, vertical and
    axial momenta constant; RK4's error falls 16-fold when the step halves."""
    model, top = load_kinematic("heavy_top"), scene_module("heavy_top")
    err, ds = _precession_error(model, top, 1e-3)
    err2, _ = _precession_error(model, top, 2e-3)
    assert err < 1e-9
    assert 12.0 < err2 / err < 20.0  # fourth order: the reference is the exact motion
    p = model.default_params()
    X = ds.x.values
    A, C = p[0], p[1]
    E = ds.energy.values
    L = rigid.angular_momentum(X, np.diag([A, A, C]))
    assert np.abs(E - E[0]).max() < 1e-11 * abs(E[0])
    assert np.abs(L[:, 2] - L[0, 2]).max() < 1e-11
    assert np.abs(C * X[:, 7] - C * X[0, 7]).max() < 1e-12
    # the norm constraint held by the law, not by renormalization
    assert np.abs(np.linalg.norm(X[:, :4], axis=1) - 1.0).max() < 1e-9


def test_free_body_follows_the_elliptic_function_solution_through_its_flips():
    """Near the intermediate axis: ω(t) = (a cn, b sn, c dn)(ν t + K) (Landau & Lifshitz
    §37), two flips of the spin axis in 10 s at t = K/ν and 3K/ν; energy and the world
    angular momentum constant."""
    model, body = load_kinematic("free_body"), scene_module("free_body")
    p = model.default_params()
    ds = stabdae.integrate(model, None, LAW, "rk4", 1e-3, 10.0, 0.01)
    t, X = ds.time.values, ds.x.values
    exact, half = body.exact_omega(t, p)
    assert np.abs(X[:, 5:8] - exact).max() < 1e-10
    wy = X[:, 6]
    cross = np.flatnonzero(np.sign(wy[1:]) != np.sign(wy[:-1]))
    times = t[cross] - wy[cross] * (t[cross + 1] - t[cross]) / (wy[cross + 1] - wy[cross])
    np.testing.assert_allclose(times, [0.5 * half, 1.5 * half], atol=1e-4)
    L = rigid.angular_momentum(X, np.diag(p[:3]))
    assert np.abs(L - L[0]).max() < 1e-11
    E = ds.energy.values
    assert np.abs(E - E[0]).max() < 1e-12 * E[0]


def test_rotations_are_the_quaternions_rotations():
    """The compiled rotation (and its third row, :func:`rigid.vertical`) against SciPy's
    (the NumPy-side :func:`rigid.rotations` is SciPy's), and a turn about an axis by an
    angle against Rodrigues' formula: for unit and non-unit quaternions."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(3)
    for _ in range(5):
        quat = rng.standard_normal(4) * rng.uniform(0.5, 2.0)
        R = np.empty((3, 3))
        rigid.rotation(quat, 0, R)
        want = Rotation.from_quat(quat[[1, 2, 3, 0]]).as_matrix()
        np.testing.assert_allclose(R, want, rtol=0, atol=1e-14)
        np.testing.assert_allclose(rigid.vertical(quat, 0), want[2], rtol=0, atol=1e-14)
        state = np.concatenate([quat, np.zeros(4)])
        np.testing.assert_allclose(rigid.rotations(state), want, rtol=0, atol=1e-14)
    axis, angle = np.array([1.0, 2.0, 2.0]) / 3.0, 0.7
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rodrigues = np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K
    R = np.empty((3, 3))
    rigid.rotation(rigid.quaternion_about(axis, angle), 0, R)
    np.testing.assert_allclose(R, rodrigues, rtol=0, atol=1e-15)


@pytest.mark.parametrize("name", ["heavy_top", "free_body", "quaternion_ball"])
def test_check_passes_on_the_quaternion_models(name):
    report = load_kinematic(name).check()
    assert report.ok, report
    assert any(row.piece == "kinematics" for row in report.rows)


def test_check_finds_an_f_accel_written_as_if_the_velocities_were_the_derivatives():
    """The common slip with quasi-velocities: ``(d/dt f_q) v`` with ``q̇ = v`` assumed
    (``2 |v|²`` for the norm) instead of ``(d/dt (f_q T)) v = |p|² w²``."""

    @njit
    def f_accel_as_if(t, q, v, p, out):
        out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3])

    model = load_kinematic("free_body").replace(f_accel=f_accel_as_if)
    report = model.check()
    assert not report.ok
    assert {row.piece for row in report.rows if not row.ok} == {"f_accel"}


def test_an_identity_map_gives_the_numbers_of_the_model_without_one():
    """T = I takes the same sums as q̇ = v (products by one, additions of zeros, all
    exact): the map's plumbing changes nothing bit for bit where it is the identity."""

    @njit
    def identity(t, q, p, out):
        out[:, :] = 0.0
        for i in range(q.shape[0]):
            out[i, i] = 1.0

    base = stabdae.load_model("double_pendulum").replace(sparsity="dense")
    mapped = base.replace(kinematics=identity)
    x0 = perturbed_state(base, 1e-3, seed=2)
    for scheme in ("euler", "rk4"):
        a = stabdae.integrate(base, x0, LAW, scheme, 1e-3, 0.5, 0.05)
        b = stabdae.integrate(mapped, x0, LAW, scheme, 1e-3, 0.5, 0.05)
        np.testing.assert_array_equal(a.x.values, b.x.values)
        np.testing.assert_array_equal(a.residual.values, b.residual.values)


def test_consistent_state_solves_the_norm_and_its_rate():
    """Held orientation components and angular velocities: p0 from |p| = 1, w from
    ḟ = |p|² w = 0; the rolling ball's translational velocities from rolling."""
    top = load_kinematic("heavy_top")
    x = top.reference_state()
    guess = x.copy()
    guess[0] *= 1.01
    guess[4] = 0.3  # w
    fixed = {name: x[i] for i, name in enumerate(top.state_names) if name not in ("p0", "w")}
    got = top.consistent_state(fixed, guess=guess)
    np.testing.assert_allclose(got, x, rtol=0, atol=1e-13)
    ball = load_kinematic("quaternion_ball")
    xb = ball.reference_state()
    guess = xb.copy()
    guess[6:9] += (0.1, -0.2, 0.05)  # x_dot, y_dot, w
    free = ("x_dot", "y_dot", "w")
    fixed = {nm: xb[i] for i, nm in enumerate(ball.state_names) if nm not in free}
    got = ball.consistent_state(fixed, guess=guess)
    assert np.abs(ball.residual(got)).max() < 1e-13
    np.testing.assert_allclose(got, xb, rtol=0, atol=1e-13)


def test_projection_and_the_correction_of_ascher_et_al_follow_the_map():
    """Coordinate projection moves q by T δv (a step in v's coordinates): under the law
    A = 0 it holds the residual at roundoff; the correction −γ D (G D)⁻¹ g decays it."""
    model = load_kinematic("heavy_top")
    ds = stabdae.integrate(model, None, stabdae.none(), "rk4", 1e-2, 5.0, 0.5,
                           projection="full")  # fmt: skip
    assert ds.residual_norm.values.max() < 1e-13
    x0 = perturbed_state(model, 1e-3, seed=4)
    ds = stabdae.integrate(model, x0, stabdae.acpr(5.0), "rk4", 1e-3, 3.0, 0.5)
    g = ds.residual_norm.values
    assert g[-1] < 1e-5 * g[0]


def test_model_rules_for_a_kinematic_map():
    model = load_kinematic("free_body")

    @njit
    def too_small(t, q, p, out):
        out[:, :] = 0.0

    with pytest.raises(stabdae.ModelError, match=r"kinematics\(t, q, p, out\).*\(4, 4\)"):
        model.replace(kinematics=njit(lambda t, q, p, out: None))
    with pytest.raises(stabdae.ModelError, match="sparsity='sparse' is not available"):
        model.replace(sparsity="sparse")
    with pytest.raises(stabdae.ModelError, match="velocities must name the n=4"):
        model.replace(velocities=["w", "omega_x"])
    with pytest.raises(stabdae.ModelError, match="velocity names repeat coordinate"):
        model.replace(velocities=["p0", "a", "b", "c"])
    assert model.state_names[4:] == ["w", "omega_x", "omega_y", "omega_z"]
    assert model.state_units[4:] == ["s-1"] * 4
    report = model.replace(kinematics=too_small).check()  # a singular T is named
    assert [row.piece for row in report.rows if not row.ok][:1] == ["kinematics"]


def test_the_norm_residual_decays_at_the_predicted_rate_per_member():
    """Every member above its floor: β within 1 % of −ln ρ(R(τÃ))/τ applied to its own
    α⁰, the quaternion's norm residual (f, ḟ) stabilized like any constraint."""
    model = load_kinematic("heavy_top")
    ds = stabdae.ensemble(model, stabdae.baumgarte(1000.0, 1.0), "rk4", 1e-4, 0.05,
                          members=64, radius=(1e-8, 1e-1), seed=3, save_dt=2e-4,
                          traces="none", states=False)  # fmt: skip
    above = ds.alpha0_norm.values > 10 * ds.residual_floor.values
    assert above.sum() >= 30
    ratio = ds.beta_ratio.values[above].astype(float)
    assert np.all(np.abs(ratio - 1.0) < 0.01), ratio
