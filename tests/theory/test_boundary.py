"""The stability boundary found by bisection (stabdae.boundary), the theory's limits beside
it, and the growth test it rests on."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest

import stabdae
from conftest import assert_schema, load_scene
from models.affine import model as affine
from stabdae import theory
from stabdae._measures import (
    BRACKETED,
    BRACKETED_BY_MOTION,
    CLASSES,
    CONFIRM_FAILS,
    HIGH_END_STABLE,
    LOW_END_FAILS,
)
from stabdae._schemes import as_scheme

#: f̈ = −100 f − 20 ḟ (ω = 10, ξ = 1: a Jordan block) and ḣ = −10 h
AFFINE_LAW = stabdae.matrix([[-100.0, -20.0, 0.0], [0.0, 0.0, -10.0]])


@pytest.mark.parametrize("scheme", ["euler", "midpoint", "rk4"])
def test_boundary_of_the_affine_system_is_the_spectral_limit(scheme):
    """No remainder: g_{k+1} = R(τÃ) g_k exactly, so the measured boundary is ρ = 1.  Its
    states grow without bound (the forces do not vanish), and with them the roundoff in
    the residual, which the stable side must not mistake for growth; the divergence
    threshold is raised so that the roundoff floor near ρ = 1 (accumulated over
    ~1/(1 − ρ)² steps of a Jordan block) does not stop members either."""
    ds = stabdae.boundary(affine, AFFINE_LAW, scheme, tau=(0.02, 1.0), rtol=1e-3,
                          members=32, search_members=16, divergence=1e12)  # fmt: skip
    spectral = theory.tau_limit(AFFINE_LAW.A_tilde(affine), scheme)
    assert int(ds.tau_star_reason) == BRACKETED
    assert float(ds.tau_star_low) < float(ds.tau_star_high) <= float(ds.tau_star_low) * 1.001
    assert float(ds.tau_star) == pytest.approx(spectral, rel=1e-3)
    assert float(ds.tau_limit_spectral) == spectral
    assert float(ds.fraction_stable) == 1.0 and int(ds.members_run) == 32
    confirm = ds.probe_members.values == 32
    assert confirm.any() and (ds.probe_stable.values[confirm] == 1).all()
    assert_schema(ds)


def test_boundary_of_the_pendulum_lies_between_the_floor_and_the_spectral_limit():
    """The pendulum's remainder (its quadratic constraint, and the local error of the stiff
    stabilization term) loses stability before ρ = 1; Theorems 6/7 with condition 4
    guarantee ‖g‖ ≤ ε only up to where the floor the local error forces reaches ε.  RK4
    (which damps the pendulum's own swing) over long runs.  Just past τ* the unperturbed
    run's own residual leaves ε (or the run blows up): the search says its bracket ends
    on the motion, and no stable probe was unstable on it."""
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    ds = stabdae.boundary(model, law, "rk4", tau=(1e-3, 0.3), rtol=1e-2, members=64,
                          search_members=16, radius=(1e-8, 1e-3), epsilon=1.0)  # fmt: skip
    star, floor = float(ds.tau_star), float(ds.tau_limit_floor)
    spectral = float(ds.tau_limit_spectral)
    assert int(ds.tau_star_reason) == BRACKETED_BY_MOTION
    probe_tau, on_motion = ds.probe_tau.values, ds.probe_motion_unstable.values == 1
    assert on_motion[probe_tau == float(ds.tau_star_high)].all()
    assert not on_motion[ds.probe_stable.values == 1].any()
    assert 0 < floor < float(ds.tau_star_low) and float(ds.tau_star_high) < spectral
    assert float(ds.tau_star_high) <= float(ds.tau_star_low) * 1.01
    assert 0.5 * spectral < star
    # the floor limit is where the condition-4 floor along the reference path reaches ε
    for tau, below in ((0.97 * floor, True), (1.03 * floor, False)):
        path = stabdae.integrate(model, None, law, "rk4", tau, 2000 * tau, tau)
        eps = theory.condition4(theory.step_matrix(law.A_tilde(model), "rk4", tau),
                                path.residual.values)["epsilon"]  # fmt: skip
        assert (eps <= 1.0) == below


def test_boundary_says_when_the_bracket_does_not_hold_it():
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    kw = dict(members=16, search_members=8, steps=400, rtol=0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stabdae.IntegrationWarning)
        high = stabdae.boundary(model, law, "midpoint", tau=(0.3, 0.5), **kw)
    low = stabdae.boundary(model, law, "midpoint", tau=(1e-3, 2e-3), **kw)
    assert int(high.tau_star_reason) == LOW_END_FAILS and math.isnan(float(high.tau_star))
    assert float(high.tau_star_high) == 0.3
    assert int(low.tau_star_reason) == HIGH_END_STABLE and math.isnan(float(low.tau_star))
    assert float(low.tau_star_low) == 2e-3 and low.sizes["probe"] == 2


def _stand_in(unstable):
    """A stand-in for the ensemble a probe runs: of its ``members``,
    ``unstable(tau, members)`` unstable and the rest stable."""
    import xarray as xr

    def fake(model, law, scheme, tau, t_end, *, members, **kw):
        u = unstable(tau, members)
        return xr.Dataset({"fraction_stable": (members - u) / members,
                           "fraction_stable_low": 0.0, "fraction_stable_high": 1.0,
                           "members_run": members, "members_stable": members - u,
                           "members_unstable": u, "members_undecided": 0,
                           "members_diverged": 0, "members_growing": u})  # fmt: skip
    return fake


@pytest.mark.parametrize("q", [0.0, 0.25])
def test_boundary_allows_the_unstable_fraction_q(q, monkeypatch):
    """Probes whose unstable count rises linearly with τ (``⌊n (τ − 0.1)/0.4⌋`` of ``n``):
    each probe is stable exactly where its fraction stable is at least ``1 − q``, and the
    boundary is where the full ensemble's unstable count first exceeds ``q n``,
    ``τ = 0.1 + 0.4 (⌊q n⌋ + 1)/n``."""
    from stabdae import _boundary

    # of n members, ⌊n x⌋ unstable, x = (τ − 0.1)/0.4 clipped to [0, 1]
    rising = _stand_in(lambda tau, n: math.floor(n * min(1.0, max(0.0, (tau - 0.1) / 0.4))))
    monkeypatch.setattr(_boundary, "ensemble", rising)
    n = 40
    ds = stabdae.boundary(affine, AFFINE_LAW, "euler", tau=(0.01, 1.0), rtol=1e-4,
                          members=n, search_members=20, q=q, steps=50)  # fmt: skip
    frac = ds.probe_fraction_stable.values
    assert (ds.probe_stable.values == (frac >= 1.0 - q)).all()
    assert int(ds.tau_star_reason) == BRACKETED
    edge = 0.1 + 0.4 * (math.floor(q * n) + 1) / n
    assert float(ds.tau_star_low) < edge <= float(ds.tau_star_high)
    assert float(ds.tau_star_high) <= float(ds.tau_star_low) * (1 + 1e-4)
    if q > 0:  # a stable probe with unstable members: q decided it
        assert ((frac < 1.0) & (ds.probe_stable.values == 1)).any()


@pytest.mark.parametrize("full_edge, reason", [(0.12, BRACKETED), (0.09, CONFIRM_FAILS)])
def test_the_full_ensemble_steps_down_to_the_brackets_low_end(full_edge, reason,
                                                               monkeypatch):
    """The search's members are stable up to τ = 0.3, the full ensemble only up to
    ``full_edge``: the confirmation steps down from the search's bracket (doubling its
    step) to the low end τ = 0.1 and no further; above it, the full ensemble's edge is
    bisected; below it, the search ends with ``CONFIRM_FAILS`` and no τ*."""
    from stabdae import _boundary

    # every member stable up to one step with the search's 20 members, up to another with
    # the full ensemble's 40 (a larger ensemble meets rarer failures)
    edges = _stand_in(lambda tau, n: n if tau > (0.3 if n == 20 else full_edge) else 0)
    monkeypatch.setattr(_boundary, "ensemble", edges)
    ds = stabdae.boundary(affine, AFFINE_LAW, "euler", tau=(0.1, 1.0), rtol=1e-3,
                          members=40, search_members=20, steps=50)  # fmt: skip
    assert int(ds.tau_star_reason) == reason
    confirm = ds.probe_members.values == 40
    assert ds.probe_tau.values[confirm].min() >= 0.1
    # the step-down's schedule: from the search's bracket, each failed τ divided by
    # 1 + rtol, 1 + 2 rtol, 1 + 4 rtol, … until that passes below the low end, which is
    # then probed itself
    taus = ds.probe_tau.values[confirm]
    passed = np.flatnonzero(ds.probe_stable.values[confirm] == 1)
    down = taus[: passed[0] + 1] if reason == BRACKETED else taus
    assert down[-1] == 0.1 and down[-2] / (1 + 1e-3 * 2 ** (len(down) - 2)) <= 0.1
    for j, (before, after) in enumerate(zip(down[:-2], down[1:-1])):
        assert after == pytest.approx(before / (1 + 1e-3 * 2**j), rel=1e-12)
    if reason == BRACKETED:
        assert float(ds.tau_star_low) <= full_edge < float(ds.tau_star_high)
        assert float(ds.tau_star_high) <= float(ds.tau_star_low) * (1 + 1e-3)
    else:
        assert math.isnan(float(ds.tau_star))


def test_boundary_errors():
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    for kw, text in [({}, "tau=(low, high)"), ({"tau": 0.1}, "a pair"),
                     ({"tau": (0.2, 0.1)}, "0 < low < high"),
                     ({"tau": (0.1, 0.2), "q": 1.0}, "q (the allowed"),
                     ({"tau": (0.1, 0.2), "rtol": 2.0}, "rtol must lie"),
                     ({"tau": (0.1, 0.2), "steps": 10, "t_end": 1.0}, "not both")]:  # fmt: skip
        with pytest.raises((TypeError, ValueError), match=r"^boundary: .*" + re.escape(text)):
            stabdae.boundary(model, law, "midpoint", **kw)


def test_condition4_and_forced_gain_against_closed_forms():
    """A scalar recursion g_{k+1} = r g_k + e: P = 1, q = |r|, ε = |e|/(1 − |r|); the forced
    gain Σ r^k = 1/(1 − r)."""
    r, e = 0.6, 1e-3
    g = [0.5]
    for _ in range(200):
        g.append(r * g[-1] + e)
    out = theory.condition4(np.array([[r]]), np.array(g)[:, None])
    assert out["q"] == pytest.approx(r, rel=1e-12)
    assert out["epsilon"] == pytest.approx(e / (1 - r), rel=1e-9)
    assert out["start"] == pytest.approx(0.5, rel=1e-12)
    assert theory.forced_gain(np.array([[r]])) == pytest.approx(1 / (1 - r), rel=1e-5)
    assert theory.forced_gain(np.array([[1.01]])) == math.inf
    assert theory.condition4(np.array([[1.01]]), np.array(g)[:, None])["epsilon"] == math.inf


def test_condition4_with_a_non_symmetric_map_and_constant_forcing():
    """``g_{k+1} = R g_k + e`` with ``R`` non-symmetric (a rotation and a shear, ρ < 1 but
    ``‖R‖₂ > 1``) and a constant ``e``: the remainders are ``e`` itself; the weight from
    the definition (``RᵀXR − X = −I`` solved as a Kronecker system, ``P = X^{1/2}``) gives
    ``q = ‖P R P⁻¹‖₂ < 1`` and ``ε = ‖P⁻¹‖₂ ‖P e‖₂ / (1 − q)``; and the orbit keeps
    the bound ``‖g_k‖∞ ≤ max(start, ε)`` (the theorems' claim)."""
    from scipy.linalg import sqrtm

    R = np.array([[0.5, 0.9, 0.0], [-0.3, 0.4, 0.2], [0.0, 0.1, -0.6]])
    e = np.array([2e-3, -1e-3, 5e-4])
    g = [np.array([0.3, -0.2, 0.1])]
    for _ in range(400):
        g.append(R @ g[-1] + e)
    g = np.array(g)
    out = theory.condition4(R, g, weight="lyapunov")
    n = R.shape[0]
    X = np.linalg.solve(np.kron(R.T, R.T) - np.eye(n * n), -np.eye(n).ravel()).reshape(n, n)
    P = np.real(sqrtm(0.5 * (X + X.T)))
    Pinv = np.linalg.inv(P)
    q = np.linalg.norm(P @ R @ Pinv, 2)
    assert np.linalg.norm(R, 2) > 1.0 > q
    assert out["q"] == pytest.approx(q, rel=1e-10)
    assert out["remainder"] == pytest.approx(np.abs(e).max(), rel=1e-9)
    eps = np.linalg.norm(Pinv, 2) * np.linalg.norm(P @ e) / (1.0 - q)
    assert out["epsilon"] == pytest.approx(eps, rel=1e-8)
    start = np.linalg.norm(Pinv, 2) * np.linalg.norm(P @ g[0])
    assert out["start"] == pytest.approx(start, rel=1e-10)
    assert np.abs(g).max(axis=1).max() <= max(out["start"], out["epsilon"])
    # the weight chosen for the smallest floor: no larger, and its bound holds too
    best = theory.condition4(R, g)
    assert best["epsilon"] <= out["epsilon"] and best["q"] < 1.0
    assert np.abs(g).max(axis=1).max() <= max(best["start"], best["epsilon"])
    P = best["weight"]
    assert best["q"] == pytest.approx(np.linalg.norm(P @ R @ np.linalg.inv(P), 2), rel=1e-12)


def test_the_floor_weight_follows_the_contraction_not_the_components_sizes():
    """The pendulum under ω = 300 (ξ = 1), midpoint, τω = 1.5: ρ(R) = 0.625, but the
    weight of RᵀXR − X = −I weighs ḟ (of size ω f) like f and has q = 0.999998, so its
    floor is 20,000 times the residual.  The chosen weight contracts at q < 0.9 and
    bounds the floor four decades lower; both bounds hold along the reference path (the
    theorems' claim: ‖g_k‖∞ ≤ max(start, ε) for g_{k+1} = R g_k + e_k)."""
    model, law, tau = load_scene("pendulum"), stabdae.baumgarte(300.0, 1.0), 0.005
    R = theory.step_matrix(law.A_tilde(model), "midpoint", tau)
    g = stabdae.integrate(model, None, law, "midpoint", tau, 2000 * tau, tau).residual.values
    plain, best = theory.condition4(R, g, weight="lyapunov"), theory.condition4(R, g)
    assert theory.spectral_radius(R) == pytest.approx(0.625)
    assert plain["q"] > 0.99999 and best["q"] < 0.9
    assert best["epsilon"] < 1e-4 * plain["epsilon"]
    for out in (plain, best):
        assert np.abs(g).max(axis=1).max() <= max(out["start"], out["epsilon"])
    with pytest.raises(ValueError, match="condition4: weight must be 'best' or 'lyapunov'"):
        theory.condition4(R, g, weight="identity")


def test_roundoff_growing_with_the_state_is_not_growth():
    """The affine system's coordinates drift like t², and the residual's roundoff with
    them: stable members at τ = 0.1 over 10⁴ steps; an unstable step is still caught."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stabdae.IntegrationWarning)
        ds = stabdae.ensemble(affine, AFFINE_LAW, "euler", 0.1, 1000.0, members=16,
                              traces="all", save_dt=10.0)  # fmt: skip
        bad = stabdae.ensemble(affine, AFFINE_LAW, "euler", 0.201, 201.0, members=16,
                               traces="none")  # fmt: skip
    fifths = ds.residual_norm.values[:, 1:].reshape(16, 5, 20).max(axis=2)
    assert (fifths[:, 4] > 1.5 * fifths[:, 2]).all()  # it rises, at the roundoff level
    size = np.abs(ds.x_final.values).max(axis=1)
    assert (size > 1e6).all() and (fifths[:, 4] < 1e3 * np.finfo(float).eps * size).all()
    assert float(ds.fraction_stable) == 1.0
    assert float(bad.fraction_stable) == 0.0
    assert set(bad.stability_class.values) <= {CLASSES.index("growing"),
                                               CLASSES.index("diverged")}


@pytest.mark.parametrize("scheme", ["euler", "midpoint", "heun", "rk3", "rk4"])
def test_recommended_gain_annihilates_the_residual_of_the_affine_system(scheme):
    """The recommended law on the affine system (whose residual follows R(τÃ) exactly):
    the holonomic block's residual is gone after the promised steps (to roundoff), and the
    first-order block's too where a real root allows it; elsewhere its |R(−kτ)| is the
    smallest on a fine grid of k."""
    tau = 0.01
    rec = theory.recommend_gain(scheme, tau)
    w, xi, k = rec["omega"], rec["xi"], rec["k"]
    assert rec["rho_holonomic"] < 1e-12 and rec["steps_holonomic"] in (1, 2)
    law = stabdae.matrix([[-w * w, -2 * xi * w, 0.0], [0.0, 0.0, -k]])
    x0 = stabdae.sample_perturbations(affine, 1, (1e-3, 1e-3), seed=4)[0]
    steps = max(rec["steps_holonomic"], rec["steps_first_order"])
    g = stabdae.integrate(affine, x0[0], law, scheme, tau, affine.t0 + steps * tau,
                          tau).residual.values  # fmt: skip
    start = np.abs(g[0]).max()
    assert np.abs(g[steps, :2]).max() < 1e-9 * start  # f and ḟ, to roundoff
    if rec["steps_first_order"]:
        assert rec["rho_first_order"] < 1e-12 and abs(g[1, 2]) < 1e-9 * start
    else:
        R = np.polynomial.Polynomial(stabdae.theory.as_scheme(scheme).stability_polynomial())
        grid = np.linspace(0.0, 5.0, 50001)
        assert rec["rho_first_order"] <= np.abs(R(-grid)).min() + 1e-12
        assert abs(g[1, 2]) == pytest.approx(rec["rho_first_order"] * abs(g[0, 2]), rel=1e-6)
    # no (ω, ξ) on a grid does better than deadbeat, and the next best are not deadbeat
    A = lambda w_, x_: stabdae.matrix([[-w_ * w_, -2 * x_ * w_, 0.0],  # noqa: E731
                                       [0.0, 0.0, -k]]).A_tilde(affine)  # fmt: skip
    near = [theory.spectral_radius_of(A(w * f, xi * e), scheme, tau)
            for f in (0.9, 1.1) for e in (0.9, 1.1)]  # fmt: skip
    assert min(near) > 1e-3


def test_recommended_gains_in_closed_form():
    """Euler: ω = 1/τ, ξ = 1 (a double root at −1: nilpotent in 2 steps), k = 1/τ; the
    midpoint rule: roots −1 ± i, so ω = √2/τ, ξ = 1/√2, and min |1 − x + x²/2| = 1/2 at
    x = 1."""
    e = theory.recommend_gain("euler", 0.02)
    assert (e["omega"], e["xi"], e["steps_holonomic"], e["k"]) == pytest.approx((50, 1, 2, 50))
    m = theory.recommend_gain("midpoint", 0.02)
    assert m["omega"] == pytest.approx(math.sqrt(2) / 0.02, rel=1e-12)
    assert m["xi"] == pytest.approx(1 / math.sqrt(2), rel=1e-12)
    assert m["k"] == pytest.approx(50, rel=1e-8) and m["rho_first_order"] == pytest.approx(0.5)
    with pytest.raises(ValueError, match="recommend_gain: tau must be positive"):
        theory.recommend_gain("rk4", 0.0)


@pytest.mark.parametrize("steps", [1, 500, "0.5 s"])
def test_short_probes_never_pass_the_spectral_limit(steps):
    """Probes of one step cannot resolve growth: the search says a probe could not decide
    instead of a bracket.  On the affine system (exact: no floor) 500 steps decide every
    probe and τ* is the spectral limit, to rtol, never beyond it (the bracket's top is
    the limit for a constant law); on the pendulum τ* never lies beyond it either (a
    member is never stable at ρ ≥ 1).  Probes of 0.5 s (5 steps at τ = 0.1) are too short
    to decide near the limit on either: undecided, said so."""
    from stabdae._codes import TauStarReason

    length = dict(t_end=0.5) if steps == "0.5 s" else dict(steps=steps)
    for model, law in ((affine, stabdae.baumgarte(10, 1, k=10)),
                       (load_scene("pendulum"), stabdae.baumgarte(10, 1))):  # fmt: skip
        ds = stabdae.boundary(model, law, "midpoint", tau=(1e-3, 1.0), rtol=1e-2, members=64,
                              search_members=32, **length)  # fmt: skip
        limit = float(ds.tau_limit_spectral)
        if steps != 500:
            assert int(ds.tau_star_reason) == int(TauStarReason.UNDECIDED)
            assert math.isnan(float(ds.tau_star))
        elif model is affine:
            assert int(ds.tau_star_reason) == int(TauStarReason.BRACKETED)
            assert float(ds.tau_star_low) <= limit <= float(ds.tau_star_high)
            assert float(ds.tau_star_high) <= limit * 1.011
        assert not float(ds.tau_star_low) > limit
        assert not float(ds.tau_star) > limit


#: docs/theory.md's table: ωτ, ξ, kτ and, where not deadbeat, the first-order ρ
_PUBLISHED_GAINS = {
    "euler": (1.0, 1.0, 1.0, 0.0), "midpoint": (math.sqrt(2), 1 / math.sqrt(2), 1.0, 0.5),
    "heun": (math.sqrt(2), 1 / math.sqrt(2), 1.0, 0.5), "rk3": (1.939, 0.362, 1.596, None),
    "rk4": (1.945, 0.889, 1.596, 0.27),
}  # fmt: skip


@pytest.mark.parametrize("scheme", list(_PUBLISHED_GAINS))
def test_recommended_gain_is_the_published_value_and_the_brute_force_minimum(scheme):
    """``recommend_gain`` gives the published gains (to the table's digits), and no gain
    of a dense grid (ωτ in (0, 4], ξ in (0, 2]; kτ in [0, 6]) has a smaller spectral
    radius, each radius computed from the definition: ``R(τÃ) = Σ c_j (τÃ)^j`` with
    ``Ã = [[0, 1], [−ω², −2ξω]]`` (or ``−k``) and its eigenvalues."""
    tau = 0.1
    rec = theory.recommend_gain(scheme, tau)
    wt, xi, kt, rho1 = _PUBLISHED_GAINS[scheme]
    assert rec["omega"] * tau == pytest.approx(wt, abs=6e-4)
    assert rec["xi"] == pytest.approx(xi, abs=6e-4)
    assert rec["k"] * tau == pytest.approx(kt, abs=6e-4)
    if rho1 is not None:
        assert rec["rho_first_order"] == pytest.approx(rho1, abs=6e-3)
    tab = as_scheme(scheme)

    def step(Z):
        """One step of the tableau on y' = Z y (unit step) from every unit vector."""
        stages = []
        for i in range(tab.stages):
            Y = np.eye(len(Z)) + sum(tab.A[i, j] * stages[j] for j in range(i))
            stages.append(Z @ Y)
        return np.eye(len(Z)) + sum(b * K for b, K in zip(tab.b, stages))

    def rho_block(w, x):
        return float(np.abs(np.linalg.eigvals(step(np.array([[0.0, 1.0],
                                                             [-w * w, -2.0 * x * w]])))).max())

    assert rho_block(rec["omega"] * tau, rec["xi"]) == pytest.approx(rec["rho_holonomic"],
                                                                     abs=1e-6)  # fmt: skip
    grid = min(rho_block(w, x) for w in np.linspace(0.02, 4.0, 200)
               for x in np.linspace(0.01, 2.0, 100))  # fmt: skip
    assert rec["rho_holonomic"] <= grid + 1e-9
    first = min(abs(step(np.array([[-x]]))[0, 0]) for x in np.linspace(0.0, 6.0, 6001))
    assert rec["rho_first_order"] <= first + 1e-9


@pytest.mark.parametrize("scheme", ["euler", "rk4"])
def test_a_search_decided_at_a_confidence_brackets_the_affine_limit(scheme):
    """Every probe run until decided, the budget split over the probes the search can
    take: the bracket holds the spectral limit (exact for the affine system), the
    confidence is stored, and no probe ran more members than it needed (stable probes
    stop at the first look that can show it, unstable ones at the first)."""
    ds = stabdae.boundary(affine, AFFINE_LAW, scheme, tau=(0.02, 1.0), rtol=1e-3,
                          members=1024, search_members=32, q=0.05, confidence=0.95)
    spectral = theory.tau_limit(AFFINE_LAW.A_tilde(affine), scheme)
    assert int(ds.tau_star_reason) == BRACKETED
    assert float(ds.tau_star_low) <= spectral <= float(ds.tau_star_high)
    assert float(ds.tau_star_high) <= float(ds.tau_star_low) * 1.001
    assert float(ds.tau_star_confidence) == 0.95 and ds.attrs["probe_confidence"] > 0.99
    used = ds.probe_members.values
    assert set(used[ds.probe_stable.values == 0]) == {32}
    assert used.max() < 1024 and (ds.probe_stage.values != 3).all()  # no confirmation
    with pytest.raises(ValueError, match="boundary: with confidence, q must be above 0"):
        stabdae.boundary(affine, AFFINE_LAW, scheme, tau=(0.02, 1.0), confidence=0.95)
