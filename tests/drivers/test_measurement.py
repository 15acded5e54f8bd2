"""What an ensemble measures per member: β against the discrete prediction, the
one-step map's rate, the storage interval and the stride changing no rate, the
stability classes, the intervals, the stability radius and the roundoff level."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import stabdae
from conftest import baumgarte_ensemble, load_scene
from stabdae._codes import RadiusReason, VerdictReason
from stabdae._measures import V_STABLE, V_UNDECIDED, V_UNSTABLE
from stabdae.engine import decay


@pytest.mark.parametrize("xi", [0.5, 0.7, 1.0, 2.0])
@pytest.mark.parametrize(
    "name, scheme",
    [(name, scheme) for name in ("pendulum", "double_pendulum")
     for scheme in ("euler", "midpoint", "heun", "rk4")]
    # the generated spherical pendulum with one scheme (its other schemes, and a model of
    # n = 60, in studies/check_member_rates.py: each scheme is a kernel to compile)
    + [("spherical_pendulum", "midpoint")],
)  # fmt: skip
def test_beta_matches_discrete_prediction(name, scheme, xi):
    """Median β within 2 % of −ln ρ(R(τÃ))/τ (5 % under-damped) and each member's β within
    1 % of its linear prediction's (2 % at the largest perturbations): under-damped (an
    oscillating residual), critically damped (repeated eigenvalue, Euler's R(τÃ) a Jordan
    block) and over-damped."""
    ds = baumgarte_ensemble(name, scheme, xi)
    assert (ds.status == 0).all()
    predicted = float(ds.beta_theory_discrete)
    # an under-damped residual's fit window holds one or two of its periods here
    assert abs(float(ds.beta_median) / predicted - 1) <= (0.02 if xi >= 1 else 0.05)
    ratio = ds.beta_ratio.values
    # measured over the linear prediction; the largest perturbations (‖α⁰‖ near 0.1, a
    # tenth of the rods' length) leave the linear regime: Euler's quadratic terms move
    # the double pendulum's rate there by up to 1.4 %
    small = ds.alpha0_norm.values <= 0.05
    assert np.mean(np.abs(ratio[small] - 1) < 0.01) >= 0.95
    assert np.all(np.abs(ratio - 1) < 0.02)
    if scheme == "euler" and xi == 1.0:  # here discrete and continuous rates differ by 5 %
        assert abs(float(ds.beta_theory) / predicted - 1) > 0.04


def test_full_map_gives_the_discrete_rate_of_a_coupled_law():
    """A constant law that couples the constraints (every entry of A perturbed: no block a
    multiple of the identity) is measured by the full one-step map of the residual's four
    components, not the pooled one: on the double pendulum under the midpoint rule every
    member gets its β from that map, within 0.1 % of −ln ρ(R(τÃ))/τ."""
    from stabdae.engine.ensemble.block import pooled_constraints

    model = load_scene("double_pendulum")
    A = stabdae.baumgarte(omega=10.0, xi=0.8).A(model)
    A = A + 2.0 * np.random.default_rng(3).standard_normal(A.shape)
    law = stabdae.matrix(A)
    assert pooled_constraints(model, law) == -1
    ds = stabdae.ensemble(model, law, "midpoint", 1e-3, 2.0, members=32, radius=(1e-4, 1e-2),
                          seed=1)  # fmt: skip
    assert (ds.fit_kind.values == decay.K_MAP).all()
    np.testing.assert_allclose(ds.beta.values, float(ds.beta_theory_discrete), rtol=1e-3)


@pytest.mark.parametrize("scheme", ["midpoint", "rk4"])
@pytest.mark.parametrize("xi", [1.05, 3.0])
def test_beta_leaves_out_the_lead_of_the_transient(xi, scheme):
    """Over-damped laws: a second mode (nearly as slow at ξ = 1.05, much faster at ξ = 3)
    bends the start of the transient.  With the fit window after the first 30 % of its
    decades the median β is within 1 % of −ln ρ(R(τÃ))/τ (measured: within 0.1 %); a fit
    over the whole transient is 4–10 % off."""
    ds = baumgarte_ensemble("pendulum", scheme, xi)
    assert abs(float(ds.beta_median) / float(ds.beta_theory_discrete) - 1) <= 0.01


def test_stability_radius_is_bracketed():
    """Members at known radii 1e-5 … 2e-1 with ε = 1e-3: the three that start above ε are
    not bounded (but stable: they decay), the two below it are; with every member stable
    δ* is censored (NaN, above the largest radius, its low end).  A divergence threshold
    of 0.05 stops the two largest members inside the law's transient bound
    (2 sup‖R^k‖ ‖α⁰‖ > 0.05): no evidence either way, so they are undecided and δ* stays
    censored above the largest decided radius."""
    model = load_scene("pendulum")
    radii = (1e-5, 1e-4, 1e-2, 2e-1, 1e-1)
    x0 = np.concatenate([stabdae.sample_perturbations(model, 1, (r, r), seed=i)[0]
                         for i, r in enumerate(radii)])  # fmt: skip
    ds = stabdae.ensemble(model, stabdae.baumgarte(10.0, 1.0), "midpoint", 1e-3, 2.0, x0=x0,
                          epsilon=1e-3)  # fmt: skip
    np.testing.assert_allclose(ds.alpha0_norm.values, radii, rtol=1e-9)
    assert ds.bounded.values.tolist() == [1, 1, 0, 0, 0]
    assert ds.stable.values.tolist() == [1, 1, 1, 1, 1]
    assert np.isnan(float(ds.stability_radius))
    assert float(ds.stability_radius_low) == float(ds.alpha0_norm.values[3])
    with pytest.warns(stabdae.IntegrationWarning):
        cut = stabdae.ensemble(model, stabdae.baumgarte(10.0, 1.0), "midpoint", 1e-3, 2.0,
                               x0=x0, epsilon=1e-3, divergence=0.05)  # fmt: skip
    a = cut.alpha0_norm.values
    assert cut.stable.values.tolist() == [1, 1, 1, 0, 0]
    assert cut.verdict.values.tolist() == [V_STABLE] * 3 + [V_UNDECIDED] * 2
    assert cut.verdict_reason.values[3:].tolist() == [int(VerdictReason.STOPPED_IN_TRANSIENT)] * 2
    assert int(cut.stability_radius_reason) == int(RadiusReason.ABOVE_SAMPLE)
    assert np.isnan(float(cut.stability_radius)) and float(cut.stability_radius_low) == a[2]


def test_bounded_needs_the_residual_to_have_decayed():
    """An unstable law (f̈ = 5 f) over 1 s: a member that starts with ḟ = 1e-6 (and f = 0)
    grows as ḟ₀ cosh(√5 t), to about 4.7e-6, stays far below ε = 1 and is unstable, not
    bounded; members on the manifold (their residual stays at roundoff, which the law
    would grow too) are undecided: the run cannot tell, the theory says ρ > 1."""
    model = load_scene("pendulum")
    x_ref = model.reference_state()
    q = x_ref[:2]
    off = x_ref.copy()
    off[2:] += 1e-6 / (2 * q @ q) * q  # ḟ = 2 q·v grows by 1e-6; f unchanged
    x0 = np.concatenate([np.tile(x_ref, (7, 1)), off[None, :]])
    ds = stabdae.ensemble(model, stabdae.matrix([[5.0, 0.0]]), "rk4", 1e-3, 1.0, x0=x0,
                          epsilon=1.0)  # fmt: skip
    assert (ds.status.values == 0).all() and float(ds.max_residual[7]) < 1e-4
    assert float(ds.residual_norm[7, -1]) > 3 * float(ds.alpha0_norm[7])
    assert ds.bounded.values.tolist() == [0] * 8
    assert ds.verdict.values.tolist() == [V_UNDECIDED] * 7 + [V_UNSTABLE]
    assert int(ds.verdict_reason[7]) == int(VerdictReason.GREW)


def test_beta_does_not_depend_on_the_storage_interval():
    """Critically damped ω = 10, midpoint, τ = 1e-3: every member's β is the same number
    for save_dt = 0.025 (the default), 0.01 and 0.1 (it is measured at every step), the
    median within 1 % of ω = 10, and measured over predicted within 1 % for every member
    (the residual's floor, 7e-6 here, lies inside the sampled radii: the rate is read on
    the distance from the reference trajectory)."""
    model = load_scene("pendulum")
    run = lambda dt: stabdae.ensemble(model, stabdae.baumgarte(10, 1), "midpoint", 1e-3,  # noqa: E731
                                      5.0, members=128, radius=(1e-6, 1e-2), seed=1,
                                      save_dt=dt)  # fmt: skip
    ds = run(None)
    for dt in (0.01, 0.1):
        np.testing.assert_array_equal(run(dt).beta.values, ds.beta.values)
    assert int(ds.members_with_beta) == 128
    assert abs(float(ds.beta_median) / 10.0 - 1) < 0.01
    assert float(ds.beta_median_low) <= float(ds.beta_median) <= float(ds.beta_median_high)
    assert np.all(np.abs(ds.beta_ratio.values - 1) < 0.01)
    assert float(ds.residual_floor.median()) > 1e-6  # the floor is inside the radii


def test_stability_classes():
    """ω = 300 critically damped at τ = 1e-3 (ρ = 0.745): members overshoot ε by the
    law's own transient, yet every one is stable; the unstable law f̈ = 5f over 3 s: no
    member stable (over 1 s, a few started close to the decaying direction are still
    decaying at the end: e^{−√5 t} has not yet given way to e^{√5 t});
    radii 1e-12 … 1e-10: none diverges; ε below the floor: unstable on the motion itself;
    τ past the spectral limit: diverged."""
    from stabdae._measures import CLASSES

    model = load_scene("pendulum")
    kw = dict(members=64, seed=2, radius=(1e-6, 1e-2))
    ens = lambda law, tau, t_end, **k: stabdae.ensemble(model, law, "midpoint", tau,  # noqa: E731
                                                        t_end, **{**kw, **k})  # fmt: skip
    fast = ens(stabdae.baumgarte(300, 1), 1e-3, 1.0)
    classes = [CLASSES[c] for c in fast.stability_class.values]
    assert float(fast.fraction_stable) == 1.0 and "overshoot" in classes
    assert float(fast.overshoot.max()) <= 2 * float(fast.overshoot_theory)
    with warnings.catch_warnings():  # members that grow past the divergence threshold
        warnings.simplefilter("ignore", stabdae.IntegrationWarning)
        unstable = ens(stabdae.matrix([[5.0, 0.0]]), 1e-3, 3.0, members=256)
        short = ens(stabdae.matrix([[5.0, 0.0]]), 1e-3, 1.0, members=256)
    assert float(unstable.fraction_stable) == 0.0
    assert float(unstable.fraction_stable_high) < 0.02
    assert float(short.fraction_stable) <= 0.08
    tiny = ens(stabdae.baumgarte(10, 1), 1e-3, 2.0, radius=(1e-12, 1e-10), epsilon=1e-3)
    assert int(tiny.members_diverged) == 0 and float(tiny.fraction_stable) == 1.0
    # they start below the midpoint rule's floor (about 7e-6 here): they never decayed
    assert (tiny.stability_class.values == CLASSES.index("at_floor")).all()
    # ε below the midpoint rule's floor: the unperturbed run itself leaves ε, so no
    # member can stay within it (Definition 2): unstable on the motion, on its floor
    low = ens(stabdae.baumgarte(10, 1), 1e-3, 2.0, epsilon=1e-7)
    assert (low.verdict_reason.values == int(VerdictReason.MOTION_UNSTABLE)).all()
    assert 0.0 < float(low.reference_exceeds_epsilon_time) < 2.0
    assert (low.stability_class.values == CLASSES.index("growing")).all()
    with pytest.warns(stabdae.IntegrationWarning):
        bad = ens(stabdae.baumgarte(10, 1), 0.25, 20.0)
    assert (bad.stability_class.values == CLASSES.index("diverged")).all()
    assert float(bad.fraction_stable) == 0.0 and np.isnan(float(bad.stability_radius))


def test_wilson_and_median_intervals():
    """Wilson's 95 % interval at its textbook values (0 of 10: [0, 0.2775]; 5 of 10:
    [0.2366, 0.7634]).  The median's interval ``[v_(r), v_(n+1-r)]`` with the largest
    rank whose exact coverage ``1 − 2^{1−n} Σ_{i<r} C(n, i)`` (counted here with integer
    binomials) is at least 95 %: defined for every n ≥ 1 (``[min, max]`` below n = 6, with
    its lower coverage), and covering the true median of normal samples as often as it
    says, at small and large n."""
    from math import comb

    from stabdae._measures import median_interval, wilson

    np.testing.assert_allclose(wilson(0, 10), (0.0, 0.2775), atol=5e-5)
    np.testing.assert_allclose(wilson(5, 10), (0.2366, 0.7634), atol=5e-5)

    def exact(n):  # the largest rank r with coverage ≥ 0.95, and that coverage
        cov, tail = [], 0
        for r in range(1, n // 2 + 1):
            tail += comb(n, r - 1)  # Σ_{i<r} C(n, i), exactly
            cov.append(1 - 2 * tail / 2**n)
        ok = [r for r, c in zip(range(1, n // 2 + 1), cov) if c >= 0.95]
        r = ok[-1] if ok else 1
        return r, (cov[r - 1] if n > 1 else 0.0)

    rng = np.random.default_rng(0)
    for n in list(range(1, 41)) + [399, 400, 10_000]:
        x = rng.standard_normal(n)
        med, lo, hi, cover = median_interval(x)
        r, c = exact(n)
        v = np.sort(x)
        assert (med, lo, hi) == (np.median(x), v[r - 1], v[n - r]), n
        assert cover == pytest.approx(c, rel=1e-12, abs=1e-15), n
        assert (cover >= 0.95) == (n >= 6), n
    # over many samples the interval covers the true median (0) as often as stated
    for n in (7, 20, 400):
        _, _, _, stated = median_interval(rng.standard_normal(n))
        hits = [lo <= 0 <= hi for lo, hi in (median_interval(rng.standard_normal(n))[1:3]
                                             for _ in range(4000))]  # fmt: skip
        assert abs(np.mean(hits) - stated) < 4 * math.sqrt(stated * (1 - stated) / 4000), n


@pytest.mark.parametrize("scheme", ["euler", "midpoint", "rk4"])
@pytest.mark.parametrize("xi", [0.3, 1.0, 3.0])
def test_one_step_map_gives_the_discrete_rate_of_a_short_transient(scheme, xi):
    """On the affine system the residual follows ``g_{k+1} = R(τÃ) g_k`` exactly.  Over a
    short run (six time constants of the slowest mode: two decades or less, with the
    polynomial prefactor of a critically damped law, the beat of an under-damped one or
    the fast mode of an over-damped one) every member's β is ``−ln ρ(R)/τ`` to 1e-4: the
    one-step map fitted to its pairs is R (to roundoff, which moves a Jordan block's
    eigenvalue by its square root).  (A fit of the norm's envelope over such a
    window is off by up to half.)"""
    from models.affine import model as affine

    slowest = xi if xi < 1 else xi - math.sqrt(xi * xi - 1)  # ω = 1
    law = stabdae.matrix([[-1.0, -2 * xi, 0.0], [0.0, 0.0, -5.0]])
    ds = stabdae.ensemble(affine, law, scheme, 0.01, round(6 / slowest, 2), members=32,
                          radius=(1e-6, 1e-3), seed=2, traces="none")  # fmt: skip
    predicted = float(ds.beta_theory_discrete)
    assert abs(predicted / slowest - 1) < 0.05
    assert int(ds.members_with_beta) == 32
    np.testing.assert_allclose(ds.beta.values, predicted, rtol=1e-4)
    np.testing.assert_allclose(ds.beta_ratio.values, 1.0, rtol=1e-4)
    assert set(ds.fit_kind.values.tolist()) == {decay.K_MAP}


def test_measurement_stride_changes_no_rate(monkeypatch):
    """The fixed-step kernel measures every s-th step, s from the law's one-step map (ω = 10,
    ξ = 1, midpoint, τ = 1e-3: |ln λ| = 0.01 per step, s = 20; a law thirty times faster
    gets s = 1; not constant: 1).  β from pairs a stride apart is that of every step to
    1e-4 (the map fitted to them is R^s, whose radius is ρ(R)^s), the floor and the
    largest norm within the stride's resolution (a change of 0.2 in ln: a maximum of the
    law's modes read at most 0.2²/8 = 0.5 % low; the residual also carries the pendulum's
    motion, whose curvature adds to it: 0.51 % measured, twice the law's bound allowed),
    γ within 2 %."""
    from stabdae import _ensemble
    from stabdae._schemes import as_scheme
    from stabdae.theory import step_matrix

    model = load_scene("pendulum")
    law = stabdae.baumgarte(10, 1)
    A = law.A_tilde(model)
    mid = as_scheme("midpoint")
    assert _ensemble.measure_stride(step_matrix(A, mid, 1e-3)) == 20
    assert _ensemble.measure_stride(step_matrix(30 * A, mid, 1e-3)) == 1
    assert _ensemble.measure_stride(step_matrix(A, mid, 1e-5)) == _ensemble.MAX_STRIDE
    assert _ensemble.measure_stride(np.zeros((0, 0))) == 1

    run = lambda: stabdae.ensemble(model, law, "midpoint", 1e-3, 3.0, members=64,  # noqa: E731
                                   radius=(1e-6, 1e-2), seed=5, traces="none")  # fmt: skip
    strided = run()
    monkeypatch.setattr(_ensemble, "measure_stride", lambda R: 1)
    every = run()
    assert strided.attrs["measure_every"] == 20 and every.attrs["measure_every"] == 1
    assert int(every.members_with_beta) == int(strided.members_with_beta) == 64
    # both are the law's rate to what the fit promises on this linear law (1e-3; the
    # largest deviation over seeds 5–7 was 5.6e-4), and the stride moves β by a tenth of
    # that at most (measured: up to 3.9e-5 over those seeds)
    pred = float(every.beta_theory_discrete)
    for ds in (strided, every):
        np.testing.assert_allclose(ds.beta.values, pred, rtol=1e-3)
    np.testing.assert_allclose(strided.beta.values, every.beta.values, rtol=1e-4)
    # γ: the largest ‖g‖e^{βt} on the transient, for a Jordan block |c0 + c1 t| at the
    # end of γ's window, which a stride moves by up to one stride: ωsτ/(1 + ωt_w) of γ,
    # up to 4 % for the members whose window ends soonest (1e6 above roundoff)
    np.testing.assert_allclose(strided.gamma.values, every.gamma.values, rtol=0.05)
    for name in ("residual_floor", "max_residual"):
        np.testing.assert_allclose(strided[name].values, every[name].values,
                                   rtol=2 * 0.2**2 / 8, err_msg=name)  # fmt: skip
    for name in ("residual_floor", "max_residual"):  # maxima over a subset of the states
        assert (strided[name].values <= every[name].values).all(), name


def test_map_window_of_a_member_still_decaying_ends_at_the_run_end():
    """A member whose residual still falls when the run ends (ω = 10 over 2 s: no floor
    yet) has the whole run as its map's window; ``fit_end`` is where γ's levels end
    (``GAMMA_MARGIN`` times above the roundoff level), later the larger the member, and
    never past the final time."""
    model = load_scene("pendulum")
    ds = stabdae.ensemble(model, stabdae.baumgarte(10, 1), "midpoint", 1e-3, 2.0,
                          members=256, radius=(1e-6, 1e-2), seed=5, traces="none")  # fmt: skip
    still = ds.floor_reached.values == 0
    assert ds.attrs["measure_every"] == 20 and still.sum() > 200
    assert set(ds.fit_kind.values[still].tolist()) == {decay.K_MAP}
    end = ds.fit_end.values[still]
    assert (end > 0.0).all() and (end <= 2.0).all()
    # the larger the member, the later it comes within the cut (all decay alike)
    assert np.corrcoef(np.log(ds.alpha0_norm.values[still]), end)[0, 1] > 0.9


def test_members_whose_floor_rises_keep_the_map_rate():
    """Under-damped double pendulum (ω = 20, ξ = 0.75, midpoint, τ = 2/700, 4 s, radii
    1e-7 … 1e-3, as a point of the shipped τ × ξ study): most members start near the floor,
    whose largest norms rise over the last fifths with the pendulum's swing.  They are
    not growing (the envelope finds them decaying), so every member's β comes from the
    one-step map and the median is −ln ρ/τ to 1e-4.  (Skipping the map for every member
    whose largest norms rise left 236 of 256 to the envelope fit: median 12.9 for 15.0.)"""
    model = load_scene("double_pendulum")
    ds = stabdae.ensemble(model, stabdae.baumgarte(20.0, 0.75), "midpoint", 2 / 700, 4.0,
                          members=256, radius=(1e-7, 1e-3), seed=2, traces="none",
                          epsilon=1.0)  # fmt: skip
    assert (ds.fit_kind.values == decay.K_MAP).all()
    assert abs(float(ds.beta_median) / float(ds.beta_theory_discrete) - 1) < 1e-4


def test_roundoff_level_of_the_pendulum_is_its_closed_form():
    """The residual's roundoff level at a state is u · max_c Σ_i |∂g_c/∂x_i · x_i|; for the
    pendulum's f = x² + y² − l², ḟ = 2(x ẋ + y ẏ) the sums are 2(x² + y²) and
    4(|x ẋ| + |y ẏ|) (central differences are exact on quadratics up to rounding), and the
    level of several states is the median of theirs; all states are differenced in one
    call."""
    from stabdae import _ensemble, _measures

    model = load_scene("pendulum")
    p = model.param_vector(None)
    X = np.random.default_rng(3).normal(size=(5, 4))
    calls = []

    def rows(Y, at):
        calls.append(Y.shape[0])
        return _ensemble._residual_rows(model, np.ascontiguousarray(Y), p, at)

    u = np.finfo(float).eps / 2.0
    x, y, vx, vy = X.T
    each = np.maximum(2.0 * (x * x + y * y), 4.0 * (np.abs(x * vx) + np.abs(y * vy)))
    got = _measures.roundoff_level(rows, X, 0.7)
    # in units of u: pytest.approx's default absolute tolerance (1e-12) passes any level
    assert got / u == pytest.approx(np.median(each), rel=1e-6)
    assert calls == [5 * 9, 5]  # the differences of every state, then the time shifts
    for i in range(5):
        assert _measures.roundoff_level(rows, X[i : i + 1], 0.7) / u == pytest.approx(
            each[i], rel=1e-6)
    assert _measures.roundoff_level(rows, X[:0], 0.7) == 0.0


def test_the_ensembles_roundoff_level_is_the_reference_at_the_end_of_the_run():
    """The roundoff level an ensemble's verdicts allow for (its attribute
    ``roundoff_level``): on the affine system, whose constraints move with time
    (∂f/∂t = −1/2, ∂h/∂t = −1/10), the plain reference's level from the exact derivatives
    at the members' final states and the run's final time, times the law's
    ``Σ_k ‖R(τÃ)ᵏ‖∞`` over the run."""
    from models.affine import model as affine
    from reference.verdicts import roundoff_level
    from stabdae import theory

    law = stabdae.matrix([[-100.0, -20.0, 0.0], [0.0, 0.0, -10.0]])
    tau, nsteps = 0.01, 250
    ds = stabdae.ensemble(affine, law, "euler", tau, nsteps * tau, members=8, seed=2,
                          save_dt=0.1)  # fmt: skip
    grad_x = np.array([[1.0, 2.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0, 2.0, 0.0],
                       [0.0, 0.2, 0.0, 1.0, 0.0, -3.0]])  # fmt: skip
    grad_t = np.array([-0.5, 0.0, -0.1])
    t_end = float(ds.time.values[-1])
    assert t_end == pytest.approx(nsteps * tau, rel=1e-12)
    level = roundoff_level(lambda x, t: grad_x, lambda x, t: grad_t, ds.x_final.values,
                           t_end)  # fmt: skip
    gain = theory.forced_gain(np.eye(3) + tau * law.A_tilde(affine), nsteps)
    # (abs=0: pytest.approx would otherwise pass anything within 1e-12 of a level ~1e-13)
    assert ds.attrs["roundoff_level"] == pytest.approx(level * gain, rel=1e-6, abs=0.0)


def test_beta_of_velocity_and_position_constraints_together_matches_the_prediction():
    """The rolling disk (one holonomic constraint, two velocity constraints) under
    Baumgarte's law with ``k`` below ``ω``: the slowest mode is the velocity constraints'
    ``ḣ = −k h``, read from the pooled one-step map's ``h`` part (Σ h'h over Σ h²); the
    median and every member within 1e-3 of ``−ln ρ(R(τÃ))/τ``."""
    ds = stabdae.ensemble(load_scene("rolling_disk"), stabdae.baumgarte(10.0, 1.0, k=8.0),
                          "midpoint", 2e-3, 3.0, members=16, seed=1)  # fmt: skip
    predicted = float(ds.beta_theory_discrete)
    assert abs(predicted / 8.0 - 1) < 1e-3  # the h block sets the rate
    assert abs(float(ds.beta_median) / predicted - 1) < 1e-3
    assert np.all(np.abs(ds.beta.values / predicted - 1) < 1e-3)


@pytest.mark.parametrize("name, scheme, xi", [("four_bar", "euler", 1.0),
                                              ("four_bar", "dopri5", 2.0),
                                              ("bowl_particle", "midpoint", 0.5)])  # fmt: skip
def test_member_rates_on_models_the_project_does_not_ship(name, scheme, xi):
    """Two models written for the tests as a user writes one: a closed loop (a four-bar
    linkage in its three link angles, a mass matrix that couples crank and coupler) and a
    particle in a paraboloid bowl.  Baumgarte ω = 1000, τ = 1e-4 over 0.05 s (adaptive:
    ω = 10 over 5 s, rtol = 1e-8), 256 members from 1e-8 to 1e-1: none unstable, 99 %
    stable, and 98 % of those 10× above their floor with β within 1 % of their linear
    prediction.  (Under Euler the four-bar member knocked hardest, ‖α⁰‖ = 0.084, leaves
    the linear regime: its β is 1.1 % low, and, thrown into a motion five times as fast,
    its own floor rises below its start: undecided.  ``studies/check_member_rates.py``'s
    count with another seed: all 36 pairs of scheme and damping ratio 100 %.)"""
    import importlib

    model = importlib.import_module(f"models.{name}").model
    adaptive = scheme in ("dopri5", "dop853")
    omega, tau, t_end = (10.0, 1e-3, 5.0) if adaptive else (1000.0, 1e-4, 0.05)
    ds = stabdae.ensemble(model, stabdae.baumgarte(omega, xi), scheme, tau, t_end,
                          rtol=1e-8 if adaptive else None, members=256,
                          radius=(1e-8, 1e-1), seed=1, traces="none",
                          states=False)  # fmt: skip
    assert not (ds.verdict.values == V_UNSTABLE).any(), ds.attrs["verdict_summary"]
    assert (ds.verdict.values == V_STABLE).mean() >= 0.99, ds.attrs["verdict_summary"]
    above = ds.alpha0_norm.values >= 10.0 * ds.residual_floor.values
    ratio = ds.beta_ratio.values[above].astype(float)
    assert above.sum() >= 60, above.sum()
    assert np.mean(np.abs(ratio - 1.0) <= 0.01) >= 0.98


def test_a_member_that_rose_above_its_start_gets_its_rate_from_the_map():
    """Euler under critically damped Baumgarte (ω = 10, τ = 1e-3, 5 s) on the spherical
    pendulum: ``R(τÃ)`` is a Jordan block, and a member's deviation may rise to almost
    four times its start before it decays.  No bin of the one-step map above the start's
    holds a pair (the start is the first fall below them), so a window cut there read
    none and left the member to its envelope's fit or to a lower cut (13 of the 22 such
    members 10× above their floor read 0.9–2.5 % low); the start's bin holds the rise.
    Every one of them gets its β from the map, the law's rate −ln ρ(R)/τ to 1 %."""
    ds = stabdae.ensemble(load_scene("spherical_pendulum"), stabdae.baumgarte(10.0, 1.0),
                          "euler", 1e-3, 5.0, members=256, radius=(1e-4, 1e-1), seed=3,
                          traces="none", states=False)  # fmt: skip
    above = ds.alpha0_norm.values >= 10.0 * ds.residual_floor.values
    rose = above & (ds.max_residual.values > 2.8 * ds.alpha0_norm.values)
    assert rose.sum() >= 12
    assert (ds.fit_kind.values[rose] == decay.K_MAP).all()
    np.testing.assert_allclose(ds.beta_ratio.values[rose], 1.0, atol=0.01)


def test_a_member_whose_deviation_ended_below_its_start_is_never_not_decaying():
    """The four-bar linkage under the midpoint rule at a gentle over-damped gain
    (ω = 10, ξ = 2, τ = 1e-3, 5 s): each member's distance from the reference falls two
    to three decades, then follows a floor of its own (the scheme's coupling of its
    perturbation to the motion) that rises over the run.  A member whose decay lies too
    close to that floor is withheld as "no transient", as its verdict (decayed) agrees;
    never "not decaying" (14 of 71 members 10× above their floor were).  Every β given is
    the law's rate to 1 %, and more than half of those members get one."""
    from models.four_bar import model as four_bar
    from stabdae._codes import BetaReason

    ds = stabdae.ensemble(four_bar, stabdae.baumgarte(10.0, 2.0), "midpoint", 1e-3, 5.0,
                          members=256, radius=(1e-8, 1e-1), seed=3, traces="none",
                          states=False)  # fmt: skip
    above = ds.alpha0_norm.values >= 10.0 * ds.residual_floor.values
    decayed = ds.verdict_reason.values == int(VerdictReason.DECAYED)
    assert above.sum() >= 60 and decayed[above].all()
    assert not (ds.beta_reason.values[decayed] == int(BetaReason.NOT_DECAYING)).any()
    ratio = ds.beta_ratio.values[above]
    given = np.isfinite(ratio)
    assert given.mean() >= 0.55, given.mean()
    np.testing.assert_allclose(ratio[given], 1.0, atol=0.01)


def test_a_law_whose_step_is_a_multiple_of_the_identity():
    """The midpoint rule at ``τω = 1`` with ``ξ = 1`` (ω = 300, τ = 1/300, a point of the
    main study's grid): ``R(τÃ) = I/2``, so every member's distance from the reference
    keeps the direction of its ``α⁰`` and its pairs span one direction.  The map is then
    fitted as ``ĉ I`` and every member's β is ``ln 2/τ`` to 1 % (the general 2 × 2 fit
    read the floor's motion across that direction as a second mode: ratios 0.30 … 2.76,
    median 1.50).  The law's map of a scalar is recognized, a Jordan block of the same
    modulus is not.  (Members up to 1e-4: the scheme's remainder at τω = 1 is large, the
    reference's floor 6e-3, and couples a larger perturbation to the motion: measured
    1.5 % at 7e-4, 3 % at 1e-3, growing with ‖α⁰‖.)"""
    from stabdae._schemes import as_scheme
    from stabdae.engine.decay import reference_logs
    from stabdae.theory import step_matrix

    model = load_scene("pendulum")
    law = stabdae.baumgarte(300, 1)
    R = step_matrix(law.A_tilde(model), as_scheme("midpoint"), 1 / 300)
    np.testing.assert_allclose(R, np.eye(2) / 2, atol=1e-12)
    ds = stabdae.ensemble(model, law, "midpoint", 1 / 300, 2.0, members=64,
                          radius=(1e-8, 1e-4), seed=1, traces="none")  # fmt: skip
    assert float(ds.beta_theory_discrete) == pytest.approx(300 * math.log(2), rel=1e-12)
    ratio = ds.beta_ratio.values[np.isfinite(ds.beta_ratio.values)]
    assert ratio.size >= 16
    assert np.all(np.abs(ratio - 1) < 0.01), np.sort(ratio)
    assert reference_logs(R).shape == (1,)
    assert reference_logs(np.array([[0.5, 1e-3], [0.0, 0.5]])).shape == (2,)


@pytest.mark.parametrize("tau", [1e-3, 0.025])
def test_a_members_measures_do_not_depend_on_its_place_in_the_ensemble(tau):
    """Each member's measures, its linear prediction included, are its own: the same
    members given in reverse order get the same values, member by member.  Among them
    members fitted by their one-step map, with their predictions; members whose residual
    rises from far below its floor beside members whose residual falls (a level one of
    them left in a slot of the block would be read as the next one's); and, at the
    longer step, members whose norm falls past several levels of their ladder at a
    step.  (A prediction stepped from a member's own row of ``α⁰``, for a member fitted
    by its envelope: ``tests/engine/test_decay.py``.)"""
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    x0 = stabdae.sample_perturbations(model, 400, (1e-6, 1e-2), seed=1)[0]
    # every fifth member starts far below its floor, to which its residual then rises
    # (the levels of its ladder above its start: the next member in its slot has none)
    x0[::5] = stabdae.sample_perturbations(model, 80, (1e-13, 1e-13), seed=2)[0]
    # blocks of 16 on one thread: 25 blocks, four to a chunk, each slot's ladder used by
    # four members in turn
    runs = [stabdae.ensemble(model, law, "midpoint", tau, 2.0, x0=x, save_dt=0.5, block=16,
                             threads=1)
            for x in (x0, x0[::-1])]  # fmt: skip
    forward, backward = runs[0], runs[1].isel(member=slice(None, None, -1))
    if tau == 1e-3:
        assert int(np.isfinite(forward["beta_predicted"]).sum()) >= 3
    for name in ("beta", "gamma", "beta_predicted", "fit_kind", "beta_reason", "x_final"):
        np.testing.assert_array_equal(forward[name].values, backward[name].values, name)


def test_gamma_and_beta_bound_every_saved_norm_of_their_window():
    """γ's definition: ``‖g(t)‖ ≤ γ e^{−β (t − t_start)}`` over the fit window.  Under
    Baumgarte's law at ξ = 1 the affine system's residual is a Jordan block's,
    ``‖g‖ ∝ (1 + ωt) e^{−ωt}``, so ``‖g‖ e^{βt}`` grows over the window and γ lies above
    the largest norm (a prefactor read as the largest norm would not bound the rest)."""
    from models.affine import model

    ds = stabdae.ensemble(model, stabdae.baumgarte(10.0, 1.0, k=10.0), "rk4", 1e-3, 3.0,
                          members=16, seed=0, save_dt=0.01)  # fmt: skip
    t = ds.time.values - float(ds.time.values[0])
    norms = ds.residual_norm.values.astype(float)
    checked = 0
    for j in range(ds.sizes["member"]):
        gamma, beta = float(ds.gamma.values[j]), float(ds.beta.values[j])
        lo = float(ds.fit_start.values[j]) - float(ds.time.values[0])
        hi = float(ds.fit_end.values[j]) - float(ds.time.values[0])
        inside = (t >= lo) & (t <= hi)
        bound = gamma * np.exp(-beta * (t[inside] - lo))
        assert (norms[j, inside] <= bound * (1 + 1e-5)).all(), j
        assert gamma > 2.0 * norms[j, inside].max(), j
        checked += int(inside.sum())
    assert checked > 16 * 20


@pytest.mark.parametrize("scheme", ["euler", "rk4"])
def test_gamma_of_an_exact_decay_is_the_initial_norm_down_to_roundoff(scheme):
    """On the affine system without its holonomic constraint the residual is h alone, and
    one step maps it by the scalar ``R(−τk)`` exactly, so ``‖g_k‖ e^{βt_k} = ‖α⁰‖`` at
    every step: γ, the largest such product over the transient, is ``‖α⁰‖`` for every
    member, to 1e-6 (the rounding a point carries ``GAMMA_MARGIN`` times above the
    roundoff level), though the members decay to that level within the run (the points
    on it once set γ to ``level · e^{βt}``, 10³–10⁵ times ``‖α⁰‖``)."""
    from models.affine import nonholonomic

    ds = stabdae.ensemble(nonholonomic, stabdae.baumgarte(k=10.0), scheme, 1e-3, 3.0,
                          members=64, seed=0)  # fmt: skip
    ratio = ds.gamma.values / ds.alpha0_norm.values
    assert np.isfinite(ratio).all()
    assert np.abs(ratio - 1.0).max() < 1e-6
    beta = ds.beta.values / ds.beta_theory_discrete.values
    assert np.abs(beta - 1.0).max() < 1e-6
    # the members reach the roundoff level before the end: γ's window ends above it
    assert (ds.final_residual.values < 1e3 * ds.attrs["fit_roundoff_level"]).all()
    t_end = ds.fit_end.values - float(ds.time.values[0])
    assert (ds.alpha0_norm.values * np.exp(-10.0 * t_end)
            > 0.9 * decay.fit.GAMMA_MARGIN * ds.attrs["fit_roundoff_level"]).all()  # fmt: skip
