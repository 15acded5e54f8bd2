"""Mechanisms of the IFToMM multibody benchmark library against exact references.

The N-four-bar (problem A02): on its parallelogram branch every crank keeps the first
one's angle φ, and the motion reduces to I φ̈ = −k cos φ with I = m l² ((N + 1)/3 + N) and
k = m g l ((N + 1)/2 + N) (N + 1 cranks turning about their pivots, N couplers
translating).  That equation, solved by SciPy to 1e-13, is the reference; the mechanism
passes a singular position (every rod on the x-axis, F of rank N + 1 instead of 2N + 1)
each half turn.

The stiff flyball governor (problem A05): nothing turns it about the vertical from
outside, so its angular momentum about z, ξ(q)ᵀ M(q) v with ξ the generator of a turn of
the whole, is a first integral, off the constraint manifold too (the constraints, the
springs and the dampers are unchanged by the turn); its dampers only take energy out.

Bricard's mechanism (problem A04): 15 coordinates and 15 constraints, so Grübler's count
leaves no motion, yet it moves with one degree of freedom: the constraint Jacobian has
rank 14 all along the motion.  No dissipation: the energy is a first integral.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import stabdae
from conftest import load_scene

N = 4  # the shipped scene's windows
M, G, L = 1.0, 9.81, 1.0
INERTIA = M * L * L * ((N + 1) / 3 + N)
STIFF = M * G * L * ((N + 1) / 2 + N)


@pytest.fixture(scope="module")
def four_bar():
    model = load_scene("n_four_bar")
    assert (model.n, model.m, model.k) == (2 * N + 2, 2 * N + 1, 0)
    return model


@pytest.fixture(scope="module")
def reduced():
    """φ(t) from the reduced equation, from the benchmark's start: cranks upright, B_0
    moving along +x at 1 m/s (φ̇ = −1/l)."""
    sol = solve_ivp(lambda t, z: [z[1], -STIFF * np.cos(z[0]) / INERTIA], (0.0, 10.0),
                    [np.pi / 2, -1.0 / L], method="DOP853", rtol=1e-13, atol=1e-13,
                    dense_output=True)  # fmt: skip
    return lambda t: sol.sol(t)[0]


def branch_state(phi, rate):
    """Tips B_i = (i l + l cos φ, l sin φ) and their velocities."""
    i = np.arange(N + 1)
    q = np.concatenate([i * L + L * np.cos(phi), L * np.sin(phi) * np.ones(N + 1)])
    v = np.concatenate([-L * np.sin(phi) * rate * np.ones(N + 1),
                        L * np.cos(phi) * rate * np.ones(N + 1)])  # fmt: skip
    return np.concatenate([q, v])


def tip_error(ds, phi):
    x = ds["x"].values
    i = np.arange(N + 1)
    ex = x[:, : N + 1] - (i * L + L * np.cos(phi)[:, None])
    ey = x[:, N + 1 : 2 * N + 2] - L * np.sin(phi)[:, None]
    return max(np.max(np.abs(ex)), np.max(np.abs(ey)))


def test_accelerations_on_the_branch_are_the_reduced_equations(four_bar):
    """At states of the parallelogram branch (away from the singular positions φ = 0, π)
    the generated model's accelerations are those of I φ̈ = −k cos φ, to roundoff."""
    law, worst = stabdae.baumgarte(20.0, 1.0), 0.0
    for phi in (1.3, 0.7, -0.4, -2.0, 2.6, 3.6):
        for rate in (-1.0, 0.5, 4.0):
            acc = -STIFF * np.cos(phi) / INERTIA
            ax = -L * np.sin(phi) * acc - L * np.cos(phi) * rate**2
            ay = L * np.cos(phi) * acc - L * np.sin(phi) * rate**2
            want = np.concatenate([np.full(N + 1, ax), np.full(N + 1, ay)])
            ds = stabdae.integrate(four_bar, branch_state(phi, rate), law, "rk4", 1e-3, 1e-3,
                                   1e-3, with_multipliers=True)  # fmt: skip
            got = ds.acceleration.values[0]  # at the start, the given state
            worst = max(worst, np.max(np.abs(got - want)) / (1.0 + np.max(np.abs(want))))
    assert worst < 1e-12, worst


def test_rk4_passes_ten_singular_positions_on_the_branch(four_bar, reduced):
    """Ten seconds of the benchmark (ten passages through the horizontal) with RK4 at
    τ = 1e-4: the tips follow the reduced solution (measured 5.0e-10) and the energy is
    kept; at τ = 1e-3 the error is four decades larger (measured 1.6e-7), as a fourth-order
    method's should be."""
    fine = stabdae.integrate(four_bar, None, stabdae.baumgarte(20.0, 1.0), "rk4", 1e-4, 10.0,
                             0.01)  # fmt: skip
    assert fine.attrs["status"] == 0
    phi = reduced(fine.time.values)
    assert np.count_nonzero(np.diff(np.sign(np.sin(phi)))) >= 10  # singular passages
    assert tip_error(fine, phi) < 1e-8
    energy = fine.energy.values
    assert np.max(np.abs(energy - energy[0])) < 1e-8 * abs(energy[0])
    coarse = stabdae.integrate(four_bar, None, stabdae.baumgarte(20.0, 1.0), "rk4", 1e-3,
                               10.0, 0.01)  # fmt: skip
    assert 1e-8 < tip_error(coarse, phi) < 1e-5


def test_adaptive_steps_stall_at_a_singular_position_unless_least_squares(four_bar, reduced):
    """At rtol 1e-12 the adaptive pair shrinks its step to roundoff at the first passage
    (t ≈ 0.71 s) with the LDLᵀ multiplier, and the warning points to the pseudo-inverse;
    with ``multiplier="lstsq"`` it passes the singular positions and follows the reduced
    solution (measured 4.9e-8 over 10 s)."""
    law = stabdae.baumgarte(20.0, 1.0)
    with pytest.warns(stabdae.IntegrationWarning, match=r"step size fell below.*lstsq"):
        stalled = stabdae.integrate_adaptive(four_bar, None, law, 3.0, rtol=1e-12,
                                             atol=1e-12, save_dt=0.01)  # fmt: skip
    assert stalled.attrs["status"] == int(stabdae.Status.STEP_TOO_SMALL)
    y0 = stalled["x"].values[:, N + 1]
    last = np.flatnonzero(np.isfinite(y0))[-1]
    assert 0.5 < stalled.time.values[last] < 0.8 and abs(y0[last]) < 0.05  # near φ = 0
    with warnings.catch_warnings():
        warnings.simplefilter("error", stabdae.IntegrationWarning)
        passed = stabdae.integrate_adaptive(four_bar, None, law, 3.0, rtol=1e-12, atol=1e-12,
                                            save_dt=0.01, multiplier="lstsq")  # fmt: skip
    assert passed.attrs["status"] == 0
    assert tip_error(passed, reduced(passed.time.values)) < 1e-6


# ----------------------------------------------------------------- the flyball governor
@pytest.fixture(scope="module")
def governor():
    model = load_scene("flyball_governor")
    assert (model.n, model.m, model.k) == (8, 4, 0)
    return model


def angular_momentum(model, x):
    """ξ(q)ᵀ M(q) v at each state (rows of ``x``), ξ = (1, 0, −y1, x1, 0, −y2, x2, 0)."""
    p, mass, M = model.param_vector(), model.functions["mass"], np.zeros((8, 8))
    out = []
    for row in x:
        q, v = row[:8], row[8:]
        mass(0.0, q, p, M)  # (the generated function writes both triangles)
        xi = np.array([1.0, 0.0, -q[3], q[2], 0.0, -q[6], q[5], 0.0])
        out.append(xi @ M @ v)
    return np.array(out)


def test_governor_keeps_its_angular_momentum_and_loses_energy(governor):
    """From the benchmark's start and from a start off the manifold, the angular momentum
    about z holds to the integration's accuracy (measured 8e-15 and 6e-15 relative over 2 s
    at rtol 1e-10).
    On the manifold the energy never rises: the dampers only dissipate (off it, the law's
    correcting forces do work until the residual has decayed)."""
    law = stabdae.baumgarte(200.0, 1.0)
    rng = np.random.default_rng(4)
    start = governor.reference_state()
    off = start + 1e-4 * rng.standard_normal(16)  # off the constraint manifold
    for x0 in (start, off):
        ds = stabdae.integrate_adaptive(governor, x0, law, 2.0, rtol=1e-10, atol=1e-10,
                                        save_dt=0.01)  # fmt: skip
        assert ds.attrs["status"] == 0
        L = angular_momentum(governor, ds["x"].values)
        assert abs(L[0]) > 50.0  # 53.9 kg m²/s from the benchmark's start
        assert np.max(np.abs(L - L[0])) < 1e-10 * abs(L[0])
        energy = ds.energy.values
        if x0 is start:
            assert np.max(np.diff(energy)) < 1e-9 * abs(energy[0])
            assert energy[-1] < energy[0] - 1e-4  # the dampers took some out
    assert ds.residual_norm.values[0] > 1e-5 > 1e-9 > ds.residual_norm.values[-1]


def test_governor_rk4_converges_below_its_springs_step_limit(governor):
    """The springs and dampers set a step limit of their own: RK4 stops at τ = 5e-4
    whatever the law; below it, fourth order (measured errors 4.2e-10 and 2.4e-11 at
    τ = 2e-4 and 1e-4 over 2 s)."""
    law = stabdae.baumgarte(200.0, 1.0)
    ref = stabdae.integrate_adaptive(governor, None, law, 2.0, rtol=1e-12, atol=1e-12,
                                     save_dt=0.01)  # fmt: skip
    errors = []
    for tau in (2e-4, 1e-4):
        ds = stabdae.integrate(governor, None, law, "rk4", tau, 2.0, 0.01)
        assert ds.attrs["status"] == 0
        errors.append(np.max(np.abs(ds["x"].values[:, :8] - ref["x"].values[:, :8])))
    assert errors[1] < 1e-9 and 8.0 < errors[0] / errors[1] < 32.0, errors
    with pytest.warns(stabdae.IntegrationWarning):
        coarse = stabdae.integrate(governor, None, law, "rk4", 5e-4, 2.0, 0.01)
    assert coarse.attrs["status"] != 0


# ----------------------------------------------------------------- Bricard's mechanism
def test_bricard_moves_with_one_degree_of_freedom_where_its_count_gives_none():
    """With the pseudo-inverse multiplier the mechanism swings (the joint J2 between
    y = −1 and −0.87), F has rank 14 of 15 at every sample (one redundant constraint,
    S singular throughout), the residual stays at the integration's error, and the energy
    is kept to fourth order in τ (measured 4.6e-9 and 2.9e-10 over 10 s at τ = 2e-3 and
    1e-3)."""
    model = load_scene("bricard")
    assert (model.n, model.m, model.k) == (15, 15, 0)
    law, drift = stabdae.baumgarte(20.0, 1.0), []
    for tau in (2e-3, 1e-3):
        ds = stabdae.integrate(model, None, law, "rk4", tau, 4.0, 0.02, multiplier="lstsq")
        assert ds.attrs["status"] == 0
        energy = ds.energy.values
        drift.append(np.max(np.abs(energy - energy[0])))
    assert drift[1] < 1e-8 and drift[0] / drift[1] > 8.0, drift
    assert ds.residual_norm.max() < 1e-7
    x = ds["x"].values
    j2_y = x[:, 1] + x[:, 4]  # J2 = r1 + r2
    assert j2_y.max() - j2_y.min() > 0.1
    p, f_q, F = model.param_vector(), model.functions["f_q"], np.zeros((15, 15))
    for row in x[::10]:
        f_q(0.0, row[:15], p, F)
        sv = np.linalg.svd(F, compute_uv=False)
        assert sv[-1] < 1e-10 * sv[0] and sv[-2] > 1e-3 * sv[0], sv[-3:]


def test_bricard_without_its_redundant_row_is_the_same_mechanism():
    """The 14 independent rows give the full set's motion: RK4 with L D Lᵀ against RK4
    with the pseudo-inverse on all 15 rows, over 2 s, differ by the steps' own error
    (measured 1.4e-9 at τ = 2e-3 and 8.9e-11 at 1e-3: fourth order, so the two models
    agree and only their off-manifold dynamics, where the step's error puts the state,
    differ); from a perturbed start the dropped row's residual (the closure along x)
    decays with the kept ones."""
    law = stabdae.baumgarte(20.0, 1.0)
    kept = load_scene("bricard_independent")
    assert (kept.n, kept.m) == (15, 14)
    apart = []
    for tau in (2e-3, 1e-3):
        ds = stabdae.integrate(kept, None, law, "rk4", tau, 2.0, 0.02)
        full = stabdae.integrate(load_scene("bricard"), None, law, "rk4", tau, 2.0, 0.02,
                                 multiplier="lstsq")  # fmt: skip
        assert ds.attrs["status"] == 0 and full.attrs["status"] == 0
        apart.append(np.max(np.abs(ds["x"].values - full["x"].values)))
    assert apart[0] < 1e-8 and apart[0] / apart[1] > 8.0, apart
    x0, _, _ = stabdae.sample_perturbations(kept, 1, (1e-3, 1e-3), seed=3)
    off = stabdae.integrate(kept, x0[0], law, "rk4", 2e-3, 2.0, 0.02)
    closure_x = off["x"].values[:, 0:15:3].sum(axis=1)  # Σ r_i,x: the dropped row
    kept_norm = off.residual_norm.values
    assert abs(closure_x[0]) > 1e-5 and kept_norm[0] > 1e-4
    assert abs(closure_x[-1]) < 1e-3 * abs(closure_x[0])
    assert kept_norm[-1] < 1e-3 * kept_norm[0]
