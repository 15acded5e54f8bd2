"""A member's verdict (stable, unstable, undecided) and its reason: the rule on records
where the truth is known by construction, the law's transient bound in closed form, and
ensembles whose truth is known (an exact affine system, stable laws over irregular or
growing motions, an unstable law)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import stabdae
from conftest import load_scene
from models.affine import model as affine
from stabdae import theory
from stabdae._codes import StabilityClass, Status, VerdictReason
from stabdae._measures import V_STABLE, V_UNDECIDED, V_UNSTABLE, verdict, verdict_summary
from stabdae.engine.decay import Record

R_ = VerdictReason


def _record(initial, d2, d3, d4):
    """A measurement record of members with these initial norms and deviations over the
    last three fifths (every other column NaN: the verdict reads only these)."""
    rec = Record.empty(len(initial))
    rec.values[:] = np.nan
    rec.codes[:] = 0
    for name, col in (("initial", initial), ("d2", d2), ("d3", d3), ("d4", d4)):
        rec[name][:] = col
    return rec


def test_verdict_rule_with_the_theory():
    """ρ < 1, bound 2 per unit ‖α⁰‖ over the last fifth (slack 2: 4 ‖α⁰‖), floor band
    10 × 1e-6: each case decided by the documented rule, and the unstable ones only with
    evidence (left the bound and grew, or blew up past what the bound allows)."""
    bounds = np.array([1.0, 3.0, 3.0, 2.0, 2.0])
    band = np.full(5, 1e-6)
    #                decayed  within  beyond+grew  above,flat  below band
    initial = np.array([1e-3, 1e-3, 1e-3, 1e-3, 1e-9])
    d2 = np.array([1e-4, 2e-3, 2e-3, 9e-3, 1e-9])
    d3 = np.array([1e-5, 2e-3, 4e-3, 9e-3, 2e-9])
    d4 = np.array([1e-6, 3e-3, 8e-3, 9e-3, 4e-9])  # allowed: 4e-3 + 1e-5
    status = np.zeros(5, dtype=np.int8)
    v, r = verdict(_record(initial, d2, d3, d4), status, band, bounds, rho=0.9)
    assert v.tolist() == [V_STABLE, V_STABLE, V_UNSTABLE, V_UNDECIDED, V_STABLE]
    assert r.tolist() == [R_.DECAYED, R_.WITHIN_BOUND, R_.BEYOND_BOUND, R_.ABOVE_BOUND,
                          R_.WITHIN_BOUND]  # fmt: skip
    # the law's transient over by the last fifth (bound 1e-12): a deviation that left the
    # bound and grew, past its start (unstable) or staying 25× below it (undecided: the
    # floor of a motion that has left the reference's)
    late = np.array([1.0, 3.0, 3.0, 2.0, 1e-12])
    v, r = verdict(_record(np.array([1e-3, 1e-1]), np.array([1e-3, 1e-3]),
                           np.array([2e-3, 2e-3]), np.array([4e-3, 4e-3])),
                   np.zeros(2, dtype=np.int8), band, late, rho=0.9)  # fmt: skip
    assert v.tolist() == [V_UNSTABLE, V_UNDECIDED]
    assert r.tolist() == [R_.BEYOND_BOUND, R_.ROSE_BELOW_START]
    # stopped by the divergence threshold: inside the bound (2·3·1e-3 + 1e-5 ≥ 5e-3) no
    # evidence; past it, blown up; a non-finite state is always unstable; not placed: not run
    status = np.array([4, 4, 3, 5, 0], dtype=np.int8)
    for div, expect in ((5e-3, R_.STOPPED_IN_TRANSIENT), (1e-2, R_.BLEW_UP)):
        v, r = verdict(_record(initial, d2, d3, d4), status, band, bounds, rho=0.9,
                       divergence=div)  # fmt: skip
        assert r[:4].tolist() == [expect, expect, R_.BLEW_UP, R_.NOT_RUN]
        assert v[:4].tolist() == [V_UNDECIDED if expect == R_.STOPPED_IN_TRANSIENT
                                  else V_UNSTABLE] * 2 + [V_UNSTABLE, V_UNDECIDED]  # fmt: skip


def test_a_member_that_grew_inside_the_floor_band_is_never_stable():
    """ρ < 1, the law's transient over (bound 1e-12 by the last fifth), floor band 10 ×
    1e-2: a deviation that rose 4× over the last three fifths, past its start, while the
    reference's floor stayed flat, has grown inside the band: undecided, never stable.
    The same rise beside a floor that rose 4× too is the floor's variation (stable); a
    rise that stays below its start is no growth past it (stable); twice the floor's rise
    is growth again."""
    bounds = np.array([1.0, 1e-3, 1e-6, 1e-9, 1e-12])
    flat, rising = np.full(5, 1e-2), np.array([1e-2, 1e-2, 1e-2, 2e-2, 4e-2])
    rec = _record(np.array([1e-4, 1e-3]), np.array([1e-4, 1e-4]), np.array([2e-4, 2e-4]),
                  np.array([4e-4, 4e-4]))  # fmt: skip
    status = np.zeros(2, dtype=np.int8)
    v, r = verdict(rec, status, flat, bounds, rho=0.9)
    assert v.tolist() == [V_UNDECIDED, V_STABLE]
    assert r.tolist() == [R_.ROSE_IN_FLOOR_BAND, R_.DECAYED]
    v, r = verdict(rec, status, rising, bounds, rho=0.9)
    assert v.tolist() == [V_STABLE, V_STABLE]
    faster = _record(np.array([1e-4]), np.array([1e-4]), np.array([4e-4]), np.array([8e-4]))
    v, r = verdict(faster, status[:1], rising, bounds, rho=0.9)
    assert (v[0], r[0]) == (V_UNDECIDED, R_.ROSE_IN_FLOOR_BAND)


def test_every_member_is_unstable_where_the_unperturbed_run_is():
    """Where the unperturbed run blew up or left ε, every member that ran is unstable on
    the motion itself, whatever its deviation did (decayed, stopped in the law's
    transient); members not placed stay not run; a run that only ran out of steps is no
    evidence."""
    from stabdae._measures import Motion

    bounds = np.full(5, 2.0)
    rec = _record(np.array([1e-3, 1e-3, 1e-3]), np.array([1e-4, 1e-4, 1e-4]),
                  np.array([1e-5, 1e-5, 1e-5]), np.array([1e-6, 1e-6, 1e-6]))  # fmt: skip
    status = np.array([0, 4, 5], dtype=np.int8)
    kw = dict(floor_band=np.zeros(5), bounds=bounds, rho=0.9, divergence=1e-3)
    v, r = verdict(rec, status, **kw)
    assert r.tolist() == [R_.DECAYED, R_.STOPPED_IN_TRANSIENT, R_.NOT_RUN]
    for motion in (Motion(int(Status.NONFINITE_STATE), 3.64), Motion(exceeds_at=0.83)):
        v, r = verdict(rec, status, motion=motion, **kw)
        assert v.tolist() == [V_UNSTABLE, V_UNSTABLE, V_UNDECIDED]
        assert r.tolist() == [R_.MOTION_UNSTABLE, R_.MOTION_UNSTABLE, R_.NOT_RUN]
    v, r = verdict(rec, status, motion=Motion(int(Status.MAX_STEPS)), **kw)
    assert r.tolist() == [R_.DECAYED, R_.STOPPED_IN_TRANSIENT, R_.NOT_RUN]
    line = verdict_summary(np.full(3, V_UNSTABLE, dtype=np.int8),
                           np.full(3, int(R_.MOTION_UNSTABLE), dtype=np.int8),
                           np.ones(3, dtype=bool),
                           Motion(int(Status.NONFINITE_STATE), 3.64).describe(0.1))
    assert "3 unstable on the motion itself: the unperturbed run diverges at t = 3.64" in line
    assert (Motion(exceeds_at=1.0, by_fifth=True).describe(0.1)
            == "the unperturbed run's residual exceeds epsilon = 0.1 by t = 1")


def test_verdict_rule_at_rho_above_one_and_without_theory():
    """ρ ≥ 1: growth past the start is unstable (the reference's own residual grows too,
    so the floor band is no bar), a member that decayed is undecided, never stable.
    Without the theory: decayed is stable, growth above the floor band and the start is
    unstable, a member that never left the floor band is undecided, and one that did
    neither is undecided (too short)."""
    band = np.full(5, 1e-3)
    initial = np.array([1e-6, 1e-2, 1e-2, 1e-6, 1e-2])
    d2 = np.array([1e-6, 1e-3, 1e-1, 1e-6, 1e-2])
    d3 = np.array([2e-6, 1e-4, 2e-1, 1e-6, 1e-2])
    d4 = np.array([4e-6, 1e-5, 4e-1, 1e-6, 1.1e-2])
    status = np.zeros(5, dtype=np.int8)
    v, r = verdict(_record(initial, d2, d3, d4), status, band, np.full(5, np.inf), rho=1.01)
    assert v.tolist() == [V_UNSTABLE, V_UNDECIDED, V_UNSTABLE, V_UNDECIDED, V_UNDECIDED]
    assert r.tolist() == [R_.GREW, R_.DECAYED_RHO_ABOVE_ONE, R_.GREW, R_.TOO_SHORT,
                          R_.TOO_SHORT]  # fmt: skip
    v, r = verdict(_record(initial, d2, d3, d4), status, band)
    assert v.tolist() == [V_UNDECIDED, V_STABLE, V_UNSTABLE, V_UNDECIDED, V_UNDECIDED]
    assert r.tolist() == [R_.IN_FLOOR_BAND, R_.DECAYED, R_.GREW, R_.IN_FLOOR_BAND,
                          R_.TOO_SHORT]  # fmt: skip
    line = verdict_summary(v, r, np.ones(5, dtype=bool))
    assert line.startswith("of 5 members that ran: 1 stable, 1 unstable (1 grew), 3 undecided")
    assert "2 in the floor band" in line and "1 too short" in line


def test_fifth_bounds_in_closed_form():
    """``sup ‖R^k‖∞`` per fifth of ``k = 0 … N``: a Jordan block ``[[λ, 1], [0, λ]]`` has
    ``‖R^k‖∞ = |λ|^k + k |λ|^{k−1}``; a rotation's, its powers' norms by NumPy; a
    nilpotent matrix's fifths after its last power are 0 and a growing one's inf once it
    overflows."""
    lam, N = 0.97, 200
    norms = np.array([lam**k + k * lam ** (k - 1) if k else 1.0 for k in range(N + 1)])
    fifth = np.minimum(4, 5 * np.arange(N + 1) // N)
    expect = [norms[fifth == w].max() for w in range(5)]
    got = theory.fifth_bounds(np.array([[lam, 1.0], [0.0, lam]]), N)
    np.testing.assert_allclose(got, expect, rtol=1e-12)
    c, s = math.cos(0.3), math.sin(0.3)
    got = theory.fifth_bounds(np.array([[c, -s], [s, c]]), 50)
    powers = [np.abs(np.linalg.matrix_power(np.array([[c, -s], [s, c]]), k)).sum(1).max()
              for k in range(51)]  # fmt: skip
    fifth = np.minimum(4, 5 * np.arange(51) // 50)
    np.testing.assert_allclose(got, [max(powers[k] for k in range(51) if fifth[k] == w)
                                     for w in range(5)], rtol=1e-12)  # fmt: skip
    assert theory.fifth_bounds(np.array([[0.0, 1.0], [0.0, 0.0]]), 100).tolist() == \
        [1.0, 0.0, 0.0, 0.0, 0.0]  # fmt: skip
    grow = theory.fifth_bounds(np.array([[1e3]]), 500)
    assert math.isfinite(grow[0]) and grow[-1] == math.inf


@pytest.mark.parametrize("scheme", ["euler", "midpoint", "heun", "rk4"])
def test_double_pendulum_is_stable_over_its_irregular_motion(scheme):
    """The double pendulum under critically damped Baumgarte over 5 s: its truncation
    floor moves with the irregular motion (the reference's fifths rise), which is no
    instability: at least 99 % of members stable, none unstable."""
    ds = stabdae.ensemble(load_scene("double_pendulum"), stabdae.baumgarte(10, 1), scheme,
                          1e-3, 5.0, members=256, seed=1, traces="none")  # fmt: skip
    assert float(ds.fraction_stable) >= 0.99, ds.attrs["verdict_summary"]
    assert int(ds.members_unstable) == 0


def test_affine_system_decays_exactly_and_its_transient_is_no_divergence():
    """The affine system follows ``g_{k+1} = R(τÃ) g_k`` exactly (no floor).  Euler at
    ρ = 0.9 over 50 steps: every member decayed.  At ρ = 1 − 4e-4 with ω = 3e4 (a
    critically damped law's transient peaks near ω/e, so ``sup ‖R^k‖ ‖α⁰‖`` reaches
    about 110 for ‖α⁰‖ = 1e-2) over 1e4 steps: the default threshold lies above the
    transient, so no member stops and none is unstable; with a threshold of 100 the
    members it stops are undecided, stopped inside the law's bound."""
    law = stabdae.baumgarte(10, 1, k=10)
    ds = stabdae.ensemble(affine, law, "euler", 0.01, 0.5, members=256, seed=1,
                          traces="none")  # fmt: skip
    assert (ds.stability_class.values == int(StabilityClass.DECAYED)).all()
    assert (ds.verdict_reason.values == int(R_.DECAYED)).all()
    om = 3e4
    tau = 4e-4 / om
    big = stabdae.baumgarte(om, 1, k=om)
    ds = stabdae.ensemble(affine, big, "euler", tau, 1e4 * tau, members=256, seed=1,
                          traces="none")  # fmt: skip
    assert abs(float(ds.spectral_radius) - (1 - 4e-4)) < 1e-12
    peak = float(ds.overshoot_theory)
    assert 1e4 < peak < 1.2e4  # ω/e ≈ 1.1e4
    assert ds.attrs["divergence"] >= 1e3 * peak * 1e-2
    assert (ds.status.values == 0).all() and int(ds.members_unstable) == 0
    assert float(ds.fraction_stable) == 1.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stabdae.IntegrationWarning)
        cut = stabdae.ensemble(affine, big, "euler", tau, 1e4 * tau, members=256, seed=1,
                               traces="none", divergence=100.0)  # fmt: skip
    stopped = cut.status.values != 0
    assert stopped.any() and int(cut.members_unstable) == 0
    assert (cut.verdict_reason.values[stopped] == int(R_.STOPPED_IN_TRANSIENT)).all()
    assert "stopped by the divergence threshold" in cut.attrs["verdict_summary"]


def test_unstable_law_is_never_stable():
    """``f̈ = 5 f`` (ρ > 1) over 3 s: no member stable, and every unstable one with its
    reason (grew or blew up)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stabdae.IntegrationWarning)
        ds = stabdae.ensemble(load_scene("pendulum"), stabdae.matrix([[5.0, 0.0]]),
                              "midpoint", 1e-3, 3.0, members=256, seed=1,
                              traces="none")  # fmt: skip
    assert float(ds.spectral_radius) > 1 and int(ds.members_stable) == 0
    unstable = ds.verdict.values == V_UNSTABLE
    assert unstable.mean() > 0.9
    assert set(ds.verdict_reason.values[unstable].tolist()) <= {int(R_.GREW), int(R_.BLEW_UP)}


def test_where_the_unperturbed_run_diverges_every_member_says_so():
    """The pendulum under the midpoint rule and Baumgarte's law at two points where
    ρ(R) < 1 but the scheme does not keep the motion itself: (τ, ω) = (0.04, 44.81),
    where the unperturbed run becomes non-finite before 5 s, and (0.25, 6.694), where its
    residual leaves ε = 1 within the run.  Every member is unstable with the one reason,
    the dataset says when, and the summary line says it too; a grid point run until
    decided is decided unstable at its first look.  A boundary search over ω = 44.81
    brackets τ* below a step where the motion diverges, and says so."""
    from stabdae._measures import Motion

    pendulum = load_scene("pendulum")
    kw = dict(members=32, radius=(1e-8, 1e-3), epsilon=1.0, seed=1, traces="none")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stabdae.IntegrationWarning)
        blown = stabdae.ensemble(pendulum, stabdae.baumgarte(44.81), "midpoint", 0.04, 5.0,
                                 **kw)  # fmt: skip
        left = stabdae.ensemble(pendulum, stabdae.baumgarte(6.694), "midpoint", 0.25, 5.0,
                                **{**kw, "members": {"q": 0.05, "batch": 16, "max": 64}})
    for ds in (blown, left):
        assert float(ds.spectral_radius) < 1.0
        assert (ds.verdict.values == V_UNSTABLE).all()
        assert (ds.verdict_reason.values == int(R_.MOTION_UNSTABLE)).all()
        assert Motion.of_dataset(ds).unstable
        assert "unstable on the motion itself: the unperturbed run" in ds.attrs["verdict_summary"]
    assert int(blown.reference_status) == int(Status.NONFINITE_STATE)
    stop = float(blown.reference_stop_time)
    assert 0.0 < stop < 5.0 and abs(stop / 0.04 - round(stop / 0.04)) < 1e-9
    assert f"diverges at t = {stop:.6g}" in blown.attrs["verdict_summary"]
    # the residual the run stored leaves ε where the dataset says it does
    assert int(left.reference_status) == 0 and int(left.decision) == V_UNSTABLE
    assert int(left.members_used) == 16
    out = float(left.reference_exceeds_epsilon_time)
    ref = stabdae.integrate(pendulum, law=stabdae.baumgarte(6.694), scheme="midpoint",
                            tau=0.25, t_end=5.0)  # fmt: skip
    first = np.flatnonzero(ref.residual_norm.values > 1.0)[0]
    assert out == pytest.approx(float(ref.time[first]), abs=1e-12)
    b = stabdae.boundary(pendulum, stabdae.baumgarte(44.81), "midpoint", tau=(1e-3, 0.3),
                         t_end=5.0, members=32, search_members=16, radius=(1e-8, 1e-3),
                         epsilon=1.0, seed=1, rtol=0.05)  # fmt: skip
    assert int(b.tau_star_reason) == int(stabdae._codes.TauStarReason.BRACKETED_BY_MOTION)
    assert float(b.tau_star_low) < float(b.tau_star) < float(b.tau_star_high)
    high = np.flatnonzero(b.probe_tau.values == float(b.tau_star_high))
    assert b.probe_motion_unstable.values[high].all()
    motion = b.probe_motion_unstable.values == 1
    assert (b.probe_verdict.values[motion] == V_UNSTABLE).all()


@pytest.mark.parametrize("scheme", ["euler", "midpoint", "heun", "rk4"])
def test_bead_on_a_turning_wire_is_not_unstable(scheme):
    """A bead flung out along a turning wire: its distance from the axis grows as
    cosh(Ω t), and with it the floor; the law (ρ < 1) is stable, so no member is
    unstable and at least 99 % are stable."""
    from models.wire_bead import model as wire

    ds = stabdae.ensemble(wire, stabdae.baumgarte(10, 1), scheme, 1e-3, 5.0, members=128,
                          seed=1, traces="none")  # fmt: skip
    assert int(ds.members_unstable) == 0
    assert float(ds.fraction_stable) >= 0.99, ds.attrs["verdict_summary"]
    assert ds.attrs["reference_floor"][4] > 10 * ds.attrs["reference_floor"][0]


def test_bead_on_a_helix_with_drag_is_stable():
    """A user's bead sliding down a helix with drag under ω = 20 critically damped:
    every member stable, β of the members within 1 % of the prediction."""
    from models.helix_bead import model as helix

    ds = stabdae.ensemble(helix, stabdae.baumgarte(20, 1), "midpoint", 1e-3, 5.0,
                          members=128, seed=1, traces="none")  # fmt: skip
    assert float(ds.fraction_stable) == 1.0, ds.attrs["verdict_summary"]
    assert abs(float(ds.beta_median) / float(ds.beta_theory_discrete) - 1) < 0.01


def test_integrate_reports_a_diverged_trajectory():
    """One trajectory of the unstable law ``f̈ = 5 f`` from ``‖g(x0)‖ = 1e-3`` over 20 s
    grows as ``e^{√5 t}`` to about 1e16: reported diverged (status and warning) at the
    first sample past the default threshold, NaN after it; the stable law from the same
    state is ok, and a user's threshold is honoured."""
    model = load_scene("pendulum")
    x0 = model.reference_state() + 1e-3
    with pytest.warns(stabdae.IntegrationWarning, match="divergence threshold"):
        ds = stabdae.integrate(model, x0, stabdae.matrix([[5.0, 0.0]]), "rk4", 1e-3, 20.0, 0.01)
    assert ds.attrs["status"] == int(Status.DIVERGED)
    norms = ds.residual_norm.values
    first = int(np.flatnonzero(~(norms <= max(1.0, 1e3 * norms[0])))[0])
    assert np.isfinite(norms[: first + 1]).all() and np.isnan(norms[first + 1:]).all()
    ok = stabdae.integrate(model, x0, stabdae.baumgarte(10, 1), "rk4", 1e-3, 20.0, 0.01)
    assert np.isfinite(ok.residual_norm.values).all()
    with pytest.warns(stabdae.IntegrationWarning):
        cut = stabdae.integrate(model, x0, stabdae.baumgarte(10, 1), "rk4", 1e-3, 1.0, 0.01,
                                divergence=1e-4)  # fmt: skip
    assert np.isnan(cut.residual_norm.values[-1])


def test_stability_radius_is_censored_or_bracketed():
    """δ* over the decided members (undecided ones left out), from its definition: the
    smallest unstable ‖α⁰‖ above, the largest below it, their geometric mean; censored
    with the side the sample bounds it from where it does not bracket it."""
    from stabdae._codes import RadiusReason
    from stabdae._measures import stability_radius

    a = np.array([1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 3e-5])
    stable = np.array([True, True, True, False, False, False])
    decided = np.array([True, True, True, True, True, False])  # 3e-5: undecided
    delta, low, high, why = stability_radius(a, stable, decided)
    assert (low, high, why) == (1e-3, 1e-2, int(RadiusReason.BRACKETED))
    assert delta == pytest.approx(math.sqrt(1e-5))
    # the undecided member at 3e-5, were it unstable, would set the upper end
    assert stability_radius(a, stable, np.ones(6, dtype=bool))[2] == 3e-5
    d, lo, hi, why = stability_radius(a, np.ones(6, dtype=bool), decided)
    assert math.isnan(d) and lo == 1e-1 and math.isnan(hi)
    assert why == int(RadiusReason.ABOVE_SAMPLE)
    d, lo, hi, why = stability_radius(a, np.zeros(6, dtype=bool), decided)
    assert math.isnan(d) and math.isnan(lo) and hi == 1e-5
    assert why == int(RadiusReason.BELOW_SAMPLE)
    assert stability_radius(a, stable, np.zeros(6, dtype=bool))[3] == int(RadiusReason.NO_MEMBER)
