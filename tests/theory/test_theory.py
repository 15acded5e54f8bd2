"""Theorems 3–7 as computations (stabdae.theory) against closed forms, and beside ensembles."""

from __future__ import annotations

import math

import numpy as np
import pytest

import stabdae
from conftest import load_scene
from stabdae import theory


def baumgarte_At(omega, xi):
    return np.array([[0.0, 1.0], [-(omega**2), -2.0 * xi * omega]])


# --------------------------------------------------------------------- closed forms
@pytest.mark.parametrize("k", [0.5, 3.0, 40.0])
def test_scalar_law_limits(k):
    A = np.array([[-k]])
    assert theory.continuous(A)["beta"] == pytest.approx(k, rel=1e-15)
    for scheme in ("euler", "midpoint", "heun"):
        for cond in theory.CONDITIONS:  # all norms coincide for a scalar
            assert theory.tau_limit(A, scheme, cond) == pytest.approx(2.0 / k, rel=1e-9)
    # RK4's real stability interval ends at −z4, the real root of z³ − 4z² + 12z − 24
    z4 = 2.785293563405282
    assert theory.tau_limit(A, "rk4") == pytest.approx(z4 / k, rel=1e-9)
    d = theory.discrete(A, "euler", 0.5 / k)
    assert d.spectral_radius == pytest.approx(0.5) and d.norm_max == pytest.approx(0.5)


@pytest.mark.parametrize("xi", [0.2, 0.5, 0.9])
def test_baumgarte_euler_limit_is_2xi_below_critical(xi):
    omega = 7.0
    A = baumgarte_At(omega, xi)
    assert theory.tau_limit(A, "euler") * omega == pytest.approx(2.0 * xi, rel=1e-8)
    assert theory.tau_limit(A, "euler", "weighted_norm") * omega == pytest.approx(
        2.0 * xi, rel=1e-6
    )
    assert theory.continuous(A)["beta"] == pytest.approx(xi * omega, rel=1e-12)


def test_baumgarte_critical_limit_is_2_for_euler_and_second_order_two_stage():
    omega = 10.0
    A = baumgarte_At(omega, 1.0)
    for scheme in ("euler", "midpoint", "heun", stabdae.two_stage(0.25, 2.0)):
        assert theory.tau_limit(A, scheme) * omega == pytest.approx(2.0, rel=1e-7), scheme
    # overdamped: eigenvalues −ω(ξ ± √(ξ²−1)); Euler limit 2/|λ|max
    xi = 2.0
    lam = omega * (xi + math.sqrt(xi * xi - 1.0))
    assert theory.tau_limit(baumgarte_At(omega, xi), "euler") == pytest.approx(2.0 / lam, 1e-9)


def test_max_norm_condition_fails_for_every_tau_when_m_positive():
    for model_name in ("pendulum", "double_pendulum", "hoop_bead"):
        model = load_scene(model_name)
        A = stabdae.baumgarte(10.0, 1.0).A_tilde(model)
        for scheme in ("euler", "midpoint", "rk4"):
            assert theory.tau_limit(A, scheme, "max_norm") == 0.0
            assert theory.tau_limit(A, scheme, "two_norm") == 0.0
            for tau in (1e-9, 1e-4, 1e-2):
                R = theory.step_matrix(A, scheme, tau)
                assert theory.CONDITIONS["max_norm"](R) >= 1.0 + tau * (1 - 1e-9)
            assert theory.tau_limit(A, scheme, "weighted_norm") > 0.0


def test_weighted_norm_condition_holds_exactly_when_spectral_radius_below_one():
    rng = np.random.default_rng(7)
    seen = {True: 0, False: 0}
    for _ in range(300):
        n = int(rng.integers(1, 5))
        A = rng.standard_normal((n, n)) - 0.5 * n * np.eye(n) * rng.uniform(0, 2)
        tau = 10 ** rng.uniform(-2, 0.5)
        R = theory.step_matrix(A, ["euler", "midpoint", "rk4"][int(rng.integers(3))], tau)
        rho = theory.spectral_radius(R)
        if abs(rho - 1.0) < 1e-6:
            continue
        assert (theory.weighted_norm(R) < 1.0) == (rho < 1.0), (A, tau, rho)
        if rho < 1.0:  # ‖R‖_P² = 1 − 1/λ_max(X)
            P = theory.lyapunov_weight(R)
            X = P @ P
            assert theory.weighted_norm(R) ** 2 == pytest.approx(
                1.0 - 1.0 / np.linalg.eigvalsh(X).max(), rel=1e-6
            )
        seen[rho < 1.0] += 1
    assert seen[True] > 50 and seen[False] > 50


def test_lyapunov_uses_the_symmetric_part():
    # −LÃ has positive leading minors (the paper's test passes) but its symmetric part is
    # indefinite: V grows along α = (1, 1), so the theorem must not be claimed.
    # (leading minors of −LÃ: 1 and 1; αᵀLÃα = 8 > 0 at α = (1, 1))
    A = np.array([[-1.0, 10.0], [0.0, -1.0]])
    L = np.eye(2)
    out = theory.lyapunov(A, L)
    assert not out["holds"]
    assert out["minors_Q"][1] < 0  # the symmetric part −(LÃ + ÃᵀL)/2 = [[1, −5], [−5, 1]]
    # with L from the Lyapunov equation the same Ã is proven stable
    out = theory.lyapunov(A)
    assert out["holds"] and out["beta"] > 0
    # the proven rate never exceeds the true one, and is exact for symmetric Ã with L = I
    assert out["beta"] <= theory.continuous(A)["beta"] + 1e-12
    S = np.array([[-3.0, 1.0], [1.0, -2.0]])
    assert theory.lyapunov(S, np.eye(2))["beta"] == pytest.approx(
        np.linalg.eigvalsh(-S).min(), rel=1e-12
    )


# --------------------------------------------------------------------- with ensembles
def test_affine_constraints_follow_R_power_exactly():
    """Constraints affine in (q, v, t): the residual recursion is exactly g ← R(τÃ) g."""
    from models import affine

    model = affine.model
    law = stabdae.baumgarte(100.0, 1.0, k=50.0)
    At = law.A_tilde(model)
    scheme = stabdae.midpoint()
    limit = theory.tau_limit(At, scheme)
    assert limit * 100.0 == pytest.approx(2.0, rel=1e-7)  # ξ = 1: τω < 2
    for factor in (0.95, 1.05):
        tau = factor * limit
        nsteps = 200
        ds = stabdae.ensemble(model, law, scheme, tau, nsteps * tau, members=16,
                              radius=(1e-3, 1e-2), seed=5, save_dt=10 * tau,
                              divergence=1e30, epsilon=1e30,
                              residual_dtype="float64")  # fmt: skip
        assert ds.residual_norm.dtype == np.float64
        assert (ds.status == 0).all()
        R = theory.step_matrix(At, scheme, tau)
        Rs = np.linalg.matrix_power(R, 10)
        g = ds.alpha0.values.T.copy()
        pred = [np.abs(g).max(axis=0)]
        for _ in range(nsteps // 10):
            g = Rs @ g
            pred.append(np.abs(g).max(axis=0))
        pred = np.array(pred).T
        got = ds.residual_norm.values
        # relative to each member's largest residual: the sequence first grows ~ω·f (the
        # velocity residual picks up the position residual), and roundoff in g(x) is
        # absolute, at the level of that peak.  Measured: ~1e-11 absolute, up to 1.3e-10 of
        # the peak for the member with the smallest one (0.99e-10 before the library's
        # multiply-adds were fused); a wrong rate or step shows at 1e-4 and above.
        scale = pred.max(axis=1, keepdims=True)
        err = np.abs(got - pred) / scale
        assert err.max() <= 5e-10, err.max()
        rho = theory.spectral_radius(R)
        if factor < 1:
            assert rho < 1 and (got[:, -1] < got[:, 0]).all()
        else:
            assert rho > 1 and (got[:, -1] > 10 * got[:, 0]).all()


def test_theorem5_printed_bound_fails_where_proven_bound_holds():
    """The sleigh with its constraint row scaled by s_h = 0.5: W = 1/4 < 1, so the printed
    rate k₀w₀ = k/2 is faster than the true decay e^{−kWt} = e^{−kt/4}, which the proven
    rate k₀λ_min(W) = k/4 matches."""
    model = load_scene("chaplygin_sleigh")
    params = dict(model.params, s_h=0.5)
    law = stabdae.theorem5(4.0)
    ds = stabdae.ensemble(model, law, "rk4", 1e-2, 12.0, members=64, radius=(1e-3, 1e-2),
                          seed=2, params=params, save_dt=0.1)  # fmt: skip
    assert float(ds.lambda_min_W) == pytest.approx(0.25, rel=1e-12)
    assert float(ds.beta_theorem5_proven) == pytest.approx(1.0, rel=1e-12)
    assert float(ds.beta_theorem5_printed) == pytest.approx(2.0, rel=1e-12)
    assert ds.bound_proven_held.values.all()
    assert (ds.bound_printed_held.values == 0).sum() >= 32
    # the measured rate sits at the proven one
    assert float(ds.beta_median) == pytest.approx(1.0, rel=0.02)


def test_theorem5_constants_and_law_with_two_constraints_and_L_not_identity():
    """Two nonholonomic constraints, W = diag(9, 4), L with eigenvalues 1/2 and 2: Theorem
    5's rates in closed form (proven k·λ_min(W)·l₁²/l_m = k/2, printed k·w₀·l₁²/l_m = k/4),
    and the residual following ḣ = −k W L h, i.e. expm(−k W L t) h(0)."""
    from scipy.linalg import expm

    from models.linear_nonholonomic import W
    from models.linear_nonholonomic import model as lin

    c, s = math.cos(0.4), math.sin(0.4)
    Q = np.array([[c, -s], [s, c]])
    L = Q @ np.diag([0.5, 2.0]) @ Q.T
    k = 3.0
    law = stabdae.theorem5(k, L)
    c5 = theory.theorem5(lin, law, lin.reference_state()[None, :])
    assert c5["lambda_min_W"] == pytest.approx(4.0, rel=1e-14)
    assert (c5["l1"], c5["lm"]) == (pytest.approx(0.5, rel=1e-14), pytest.approx(2.0, rel=1e-14))
    assert c5["beta_proven"] == pytest.approx(k * 4.0 * 0.25 / 2.0, rel=1e-13)
    assert c5["beta_printed"] == pytest.approx(k * 2.0 * 0.25 / 2.0, rel=1e-13)
    assert c5["gamma_factor"] == pytest.approx(2.0, rel=1e-14)
    x0 = lin.reference_state() + np.array([0, 0, 0, 0.01, -0.02, 0.0])
    ds = stabdae.integrate(lin, x0, law, "rk4", 5e-4, 1.0, 0.1)
    h0 = ds.residual.values[0]
    for i in (3, 10):
        t = float(ds.time[i])
        np.testing.assert_allclose(ds.residual.values[i], expm(-k * W @ L * t) @ h0,
                                   rtol=1e-9, atol=1e-15)  # fmt: skip


@pytest.mark.parametrize("scheme", ["euler", "midpoint", "heun", "rk4"])
def test_tau_limit_lies_just_on_the_stable_side_of_the_exact_limit(scheme):
    """Scalar law ġ = −k g: the spectral limit is z*/k with z* the real stability boundary
    (2 for Euler and second-order two-stage schemes, the positive root of
    z³ − 4z² + 12z − 24 for RK4).  The answer is within rtol below it, never above (where
    ρ ≥ 1), and ``inf`` when the condition holds up to ``tau_max``."""
    k = 3.0
    A = np.array([[-k]])
    z = 2.785293563405282 if scheme == "rk4" else 2.0
    exact = z / k
    for condition in ("spectral", "max_norm", "two_norm", "weighted_norm"):  # equal: scalar
        lim = theory.tau_limit(A, scheme, condition, rtol=1e-10)
        assert exact * (1 - 2e-10) <= lim < exact, condition
        assert theory.tau_limit(A, scheme, condition, tau_max=0.5 * exact) == math.inf
    assert theory.spectral_radius(theory.step_matrix(A, scheme, lim)) < 1.0
    assert theory.spectral_radius(theory.step_matrix(A, scheme, exact * (1 + 1e-9))) > 1.0


@pytest.mark.parametrize("scene", ["pendulum", "double_pendulum"])
def test_tau_sweep_boundary_matches_the_spectral_radius(scene):
    """Sweeping τ: every member stays bounded wherever the weighted-norm condition holds,
    and the empirical boundary is within one grid cell of ρ(R(τÃ)) = 1."""
    model = load_scene(scene)
    # ω large against the pendulum's own frequency (~3 s⁻¹): Euler's slow energy growth
    # of the free swing stays small over the run, and the constraint law sets the limit
    law = stabdae.baumgarte(200.0, 0.5)
    At = law.A_tilde(model)
    limit = theory.tau_limit(At, "euler")
    assert limit * 200.0 == pytest.approx(1.0, rel=1e-8)  # 2ξ/ω
    taus = limit * np.array([0.5, 0.7, 0.85, 0.95, 1.05, 1.2, 1.5])
    empirical, predicted = [], []
    for tau in taus:
        # ε = 1: Euler's truncation floor near the limit, τ²/2·‖g⁽²⁾‖/(1 − ρ), is far above
        # the perturbations, so a smaller ε would count stable runs as unbounded
        ds = stabdae.ensemble(model, law, "euler", tau, 400 * tau, members=32,
                              radius=(1e-6, 1e-4), seed=1, save_dt=20 * tau,
                              epsilon=1.0)  # fmt: skip
        holds = bool(ds.norm_condition)
        if holds:
            assert float(ds.fraction_bounded) == 1.0, tau
        empirical.append(float(ds.fraction_bounded) == 1.0)
        predicted.append(float(ds.spectral_radius) < 1.0)
    # the first τ that is not stable: empirical and predicted within one grid cell
    first_bad = lambda flags: flags.index(False) if False in flags else len(flags)  # noqa: E731
    assert abs(first_bad(empirical) - first_bad(predicted)) <= 1
    assert first_bad(predicted) == 4


@pytest.mark.parametrize("m", [1, 2, 5, 40])
def test_power_norms_stop_at_max_steps_in_closed_form(m):
    """``R = 1.1`` (powers grow, never below a millionth of the peak): the peak is
    ``sup_{0 ≤ k ≤ m} 1.1^k = 1.1^m`` and the forced gain ``Σ_{k < m} 1.1^k``; a 2 × 2
    rotation scaled by 1.1 the same in the max-norm of its powers."""
    peak, total = theory.power_norms(np.array([[1.1]]), m)
    assert peak == pytest.approx(1.1**m, rel=1e-14)
    assert total == pytest.approx(sum(1.1**k for k in range(m)), rel=1e-14)
    c, s = math.cos(0.3), math.sin(0.3)
    R = 1.1 * np.array([[c, -s], [s, c]])
    norms = [np.abs(np.linalg.matrix_power(R, k)).sum(axis=1).max() for k in range(m + 1)]
    peak, total = theory.power_norms(R, m)
    assert peak == pytest.approx(max(norms), rel=1e-12)
    assert total == pytest.approx(sum(norms[:m]), rel=1e-12)
    assert theory.transient_peak(R, m) == peak and theory.forced_gain(R, m) == total


def test_along_path_floor_bounds_the_residual():
    """Theorem 6 along a nonlinear path: ‖g_k‖ ≤ max(‖P⁻¹‖‖Pg₀‖, ε) with ε from the
    measured one-step remainders."""
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    x0 = stabdae.sample_perturbations(model, 1, (1e-3, 1e-3), seed=4)[0][0]
    for scheme, tau in (("euler", 0.01), ("midpoint", 0.02)):
        path = stabdae.integrate(model, x0, law, scheme, tau, 5.0, tau)
        out = theory.along_path(model, law, scheme, path)
        assert float(out.q) < 1.0
        bound = max(float(out.bound_start), float(out.epsilon))
        assert (out.residual_norm.values <= bound * (1 + 1e-9)).all()
        # the floor is a real bound, not a vacuous one: within 100x of what is reached
        late = out.residual_norm.values[len(out.step) // 2 :]
        assert float(out.epsilon) < 100 * late.max()
        # constant law: every R_k is the same and its max-norm exceeds 1 (m > 0)
        assert np.ptp(out.spectral_radius.values) < 1e-15
        assert (out.norm_max.values > 1.0).all()


def test_along_path_with_a_non_symmetric_map_and_constant_forcing():
    """Theorem 6 in closed form: the forced affine system under Euler makes the remainder
    ``e = (c τ²/2, 0, 0)`` at every step, with the non-symmetric ``R = I + τÃ`` of a
    Jordan block (ρ = 0.8, ‖R‖₂ > 1).  ``along_path`` must report that remainder, ``q``
    and ``ε`` from the weight's definition (``RᵀXR − X = −I`` as a Kronecker system,
    ``P = X^{1/2}``), and the orbit must settle on the fixed point ``(I − R)⁻¹ e`` below
    the bound."""
    from scipy.linalg import sqrtm

    from models.affine import FORCING, forced

    law = stabdae.matrix([[-100.0, -20.0, 0.0], [0.0, 0.0, -10.0]])
    tau = 0.02
    x0 = stabdae.sample_perturbations(forced, 1, (1e-3, 1e-3), seed=4)[0][0]
    path = stabdae.integrate(forced, x0, law, "euler", tau, 4.0, tau)
    out = theory.along_path(forced, law, "euler", path)
    R = np.eye(3) + tau * law.A_tilde(forced)
    e = np.array([0.5 * FORCING * tau**2, 0.0, 0.0])
    X = np.linalg.solve(np.kron(R.T, R.T) - np.eye(9), -np.eye(3).ravel()).reshape(3, 3)
    P = np.real(sqrtm(0.5 * (X + X.T)))
    Pinv = np.linalg.inv(P)
    q = np.linalg.norm(P @ R @ Pinv, 2)
    assert np.linalg.norm(R, 2) > 1.0 > q
    assert np.allclose(out.spectral_radius.values, 0.8, rtol=1e-12, atol=0.0)
    assert np.allclose(out.remainder.values[:-1], e[0], rtol=1e-6, atol=0.0)
    assert float(out.q) == pytest.approx(q, rel=1e-9)
    eps = np.linalg.norm(Pinv, 2) * np.linalg.norm(P @ e) / (1.0 - q)
    assert float(out.epsilon) == pytest.approx(eps, rel=1e-6)
    g0 = path.residual.values[0]
    assert float(out.bound_start) == pytest.approx(np.linalg.norm(Pinv, 2) *
                                                   np.linalg.norm(P @ g0), rel=1e-9)  # fmt: skip
    bound = max(float(out.bound_start), float(out.epsilon))
    assert (out.residual_norm.values <= bound).all()
    fixed = np.linalg.solve(np.eye(3) - R, e)
    np.testing.assert_allclose(path.residual.values[-1], fixed, rtol=1e-6, atol=1e-15)


def test_predictions_memo_gives_the_computed_values_per_tau_and_law():
    """The ensemble's predictions are memoized by (Ã, tableau, τ): a repeated call returns
    what a fresh computation gives, a new τ or gain is a new entry, and a caller that
    edits the returned dict does not change the next one."""
    model = stabdae.load_model("pendulum")
    law, scheme = stabdae.baumgarte(10.0, 0.5), stabdae.midpoint()
    theory._PREDICTIONS.clear()
    first = theory.predictions(model, law, scheme, 0.05)
    first["spectral_radius"] = -1.0
    again = theory.predictions(model, law, scheme, 0.05)
    fresh = theory._predictions(law.A_tilde(model), scheme, 0.05, False)
    assert again == fresh and again["spectral_radius"] > 0
    # R(τÃ) of the midpoint rule for Baumgarte's 2×2 block: the closed form of ρ
    z = 0.05 * np.linalg.eigvals(baumgarte_At(10.0, 0.5)).astype(complex)
    assert again["spectral_radius"] == pytest.approx(np.max(np.abs(1 + z + z**2 / 2)), rel=1e-12)
    other_tau = theory.predictions(model, law, scheme, 0.02)
    other_law = theory.predictions(model, stabdae.baumgarte(10.0, 1.0), scheme, 0.05)
    assert other_tau["spectral_radius"] != again["spectral_radius"]
    assert other_law["spectral_radius"] != again["spectral_radius"]
    assert theory.predictions(model, law, scheme, 0.02) == other_tau  # the entries stay apart


def _exact_spectral_limit(omega, xi, coeffs):
    """The spectral τ limit of Baumgarte's 2×2 block from its analytic eigenvalues
    ω(−ξ ± √(ξ² − 1)), to 40 digits: the smallest positive root of |R(τλ)|² − 1
    (mpmath, independent of the library's eigenvalue computation)."""
    import mpmath as mp

    mp.mp.dps = 40
    best = mp.inf
    root = mp.sqrt(mp.mpf(xi) ** 2 - 1)
    for lam in (omega * (-mp.mpf(xi) + root), omega * (-mp.mpf(xi) - root)):
        a = [mp.mpf(c) * lam**k for k, c in enumerate(coeffs)]
        b = [mp.mpf(0)] * (2 * len(a) - 1)
        for j, aj in enumerate(a):
            for k, ak in enumerate(a):
                b[j + k] += mp.re(aj * mp.conj(ak))
        b[0] -= 1
        nonzero = [i for i, v in enumerate(b) if abs(v) > mp.mpf(10) ** -30]
        low, high = nonzero[0], nonzero[-1]
        if b[low] > 0:
            return 0.0
        roots = mp.polyroots(b[low : high + 1][::-1], maxsteps=200, extraprec=200)
        pos = [mp.re(r) for r in roots if abs(mp.im(r)) < 1e-25 and mp.re(r) > 0]
        if pos:
            best = min(best, min(pos))
    return float(best)


@pytest.mark.parametrize("xi", [0.0, 1e-9, 0.25, 0.5, 1 / math.sqrt(2), 1.0, 2.0])
@pytest.mark.parametrize("scheme", ["euler", "midpoint", "heun", "rk3", "heun3", "rk4",
                                    "dopri5"])  # fmt: skip
def test_spectral_tau_limit_exact_for_every_damping(scheme, xi):
    """τ limits against the exact limits of the damped oscillator for undamped, nearly
    undamped, under-, critically and over-damped Baumgarte laws (RK4's 2√2/ω at ξ = 0,
    none for Euler and the two-stage schemes there), to the rtol asked; ρ(R(τÃ)) exact at
    the Jordan block of ξ = 1.  (ω = 7.3: its critically damped Ã has eigenvalues that
    LAPACK returns spread by 1.6e-8 relative, where ω = 10's come out exact.)"""
    omega = 7.3
    A = baumgarte_At(omega, xi)
    coeffs = stabdae.theory.as_scheme(scheme).stability_polynomial()
    exact = _exact_spectral_limit(omega, xi, coeffs)
    got = theory.tau_limit(A, scheme, rtol=1e-10)
    if exact == 0.0:
        assert got == 0.0
    else:
        assert exact * (1 - 2e-10) <= got < exact, (got, exact)
        assert theory.tau_limit(A, scheme, "weighted_norm", rtol=1e-10) == got
    if scheme == "rk4" and xi == 0.0:
        assert got == pytest.approx(2 * math.sqrt(2) / omega, rel=1e-9)
    if scheme in ("rk3", "heun3") and xi == 0.0:  # both have R(z) = 1 + z + z²/2 + z³/6
        assert got == pytest.approx(math.sqrt(3) / omega, rel=1e-9)
    if xi == 1.0:  # R(τÃ) for Euler at τω = 0.9 and ω = 12.62: a Jordan block of 0.1
        # (from the matrix R's own eigenvalues it reads 0.1000000098)
        A_j = baumgarte_At(12.62, 1.0)
        rho = theory.discrete(A_j, "euler", 0.9 / 12.62, limits=False).spectral_radius
        assert rho == pytest.approx(0.1, rel=1e-14)
