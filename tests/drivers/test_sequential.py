"""Grid points run until decided: the sequential design's error guarantee (exact, by
dynamic programming over its looks), the common random numbers it rests on (member ``i``
a function of the seed and ``i``), and the sequential ensemble against the one-shot one
and against the truth of an affine system."""

from __future__ import annotations

import math

import numpy as np
import pytest
import xarray as xr
from scipy import stats

import stabdae
from conftest import load_scene
from models.affine import model as affine
from stabdae import theory
from stabdae._codes import DecisionReason, Status, Verdict
from stabdae._sequential import Sequential, bounds, decide
from stabdae.engine.sampler import draw_alphas
from stabdae.study.run import run_study

STABLE, UNSTABLE, UNDECIDED = int(Verdict.STABLE), int(Verdict.UNSTABLE), int(Verdict.UNDECIDED)


# --------------------------------------------------------------------- common random numbers
def test_a_members_target_depends_on_the_seed_and_its_index_alone():
    full = draw_alphas(5, 300, (1e-6, 1e-2), 7)
    for lo, hi in [(0, 1), (17, 64), (250, 300)]:
        assert np.array_equal(draw_alphas(5, hi - lo, (1e-6, 1e-2), 7, start=lo), full[lo:hi])
    assert not np.array_equal(draw_alphas(5, 300, (1e-6, 1e-2), 8), full)


def test_the_targets_have_the_documented_distribution():
    """‖α⁰‖∞ log-uniform in the radius; directions uniform on the sphere, whose first
    component is then uniform on [−1, 1] in three dimensions (Archimedes' hat-box
    theorem)."""
    low, high = 1e-6, 1e-2
    a = draw_alphas(3, 20_000, (low, high), 1)
    r = np.log(np.abs(a).max(axis=1))
    assert stats.kstest((r - math.log(low)) / math.log(high / low), "uniform").pvalue > 1e-3
    d = a / np.linalg.norm(a, axis=1, keepdims=True)
    for c in range(3):
        assert stats.kstest((d[:, c] + 1) / 2, "uniform").pvalue > 1e-3


# --------------------------------------------------------------------- the design's guarantee
@pytest.mark.parametrize("k, n", [(0, 64), (1, 64), (30, 1024), (64, 64), (500, 1000)])
def test_the_bounds_are_clopper_pearsons(k, n):
    """From the definition: the lower bound L has P(X ≥ k | L) = level, the upper U has
    P(X ≤ k | U) = level (X ~ Bin(n, ·)); and SciPy's exact interval agrees."""
    level = 0.004
    low, high = bounds(k, n, level)
    if k > 0:
        assert stats.binom.sf(k - 1, n, low) == pytest.approx(level, rel=1e-9)
    if k < n:
        assert stats.binom.cdf(k, n, high) == pytest.approx(level, rel=1e-9)
    ci = stats.binomtest(k, n).proportion_ci(1 - 2 * level, method="exact")
    assert (low, high) == pytest.approx((ci.low, ci.high), rel=1e-9, abs=1e-15)



def wrong_probability(plan: Sequential, p: float) -> tuple[float, float]:
    """Exactly: the probability that ``plan`` decides wrongly, and its expected members,
    when each member is unstable with probability ``p`` (every member judged)."""
    looks = plan.looks()
    alive = np.array([1.0])  # P(k unstable so far, not stopped yet)
    wrong = expected = 0.0
    before = 0
    for j, n in enumerate(looks):
        alive = np.convolve(alive, stats.binom.pmf(np.arange(n - before + 1), n - before, p))
        before = n
        for k in np.flatnonzero(alive > 1e-300):
            d = decide(plan, n, int(k), int(k), last=j == len(looks) - 1)
            if d.verdict is None:
                continue
            if (d.verdict == STABLE and p > plan.q) or (d.verdict == UNSTABLE and p <= plan.q):
                wrong += alive[k]
            expected += n * alive[k]
            alive[k] = 0.0
    return wrong, expected


@pytest.mark.parametrize("plan", [Sequential(), Sequential(q=0.2, batch=16, max=512)])
def test_a_wrong_decision_is_at_most_one_minus_the_confidence_however_the_looks_end(plan):
    """At the worst unstable fractions (``q`` itself, where *unstable* is wrong, and just
    above it, where *stable* is), and away from them."""
    for p in (plan.q, plan.q * (1 + 1e-9), 0.5 * plan.q, 2 * plan.q, 0.0, 1.0):
        wrong, _ = wrong_probability(plan, p)
        assert wrong <= 1 - plan.confidence, (p, wrong)


def test_the_guarantee_needs_the_budget_split_over_the_looks(monkeypatch):
    """The same looks, each spending the whole budget (an interval at 95 % at every look,
    as a fixed-size ensemble would report it): wrong more often than 5 % at ``p = q``.
    The test above can fail."""
    plan = Sequential(q=0.05, batch=16, max=4096)
    monkeypatch.setattr(Sequential, "side_level", property(lambda s: (1 - s.confidence) / 2))
    assert wrong_probability(plan, plan.q)[0] > 1 - plan.confidence


def test_a_grid_point_far_from_q_is_decided_at_the_first_look_that_can():
    """Every member stable: decided *stable* at the first look whose exact bound can reach
    ``q`` (1 − level^{1/n} ≤ q), and every member unstable at the first look."""
    plan = Sequential()
    level = plan.side_level
    first = next(n for n in plan.looks() if 1 - level ** (1 / n) <= plan.q)
    assert wrong_probability(plan, 0.0) == (0.0, first)
    assert wrong_probability(plan, 1.0) == (0.0, plan.batch)


def test_undecided_members_count_against_both_decisions():
    plan = Sequential()
    d = decide(plan, 1024, 0, 1024, last=False)  # every member undecided
    assert d.verdict == UNDECIDED and d.reason == int(DecisionReason.MEMBERS_UNDECIDED)
    d = decide(plan, 1024, 30, 60, last=True)  # unstable 3 %, not stable 6 %: q inside
    assert d.verdict == UNDECIDED and d.reason == int(DecisionReason.MAX_REACHED)
    assert d.low < plan.q < d.high
    d = decide(Sequential(tolerance=0.2), 64, 3, 3, last=False)
    assert d.verdict == UNDECIDED and d.reason == int(DecisionReason.WITHIN_TOLERANCE)


def test_members_not_run_are_left_out_of_the_decision_up_to_max_not_run():
    """The fractions are of the members that ran; a decision stands only where at most
    ``max_not_run`` did not run: above it the cell looks again, and stops undecided
    (``not_run``) once that share's lower bound is above the limit, or at the last look."""
    plan = Sequential()  # max_not_run 0.01
    level = plan.side_level
    # 127 ran, all stable, 1 of 128 not placed (0.8 % ≤ 1 %): decided on the 127 alone
    d = decide(plan, 127, 0, 0, last=False, not_run=1)
    assert d.verdict == STABLE and d.high == pytest.approx(bounds(0, 127, level)[1])
    # counted against stability (as one undecided of 128) it would not be decided
    assert decide(plan, 128, 0, 1, last=False).verdict is None
    # 3 of 256 not run (1.2 %): the ran members alone are stable, yet the cell looks again,
    # and at the last look it is undecided for the members not run
    d = decide(plan, 253, 0, 0, last=False, not_run=3)
    assert d.verdict is None and d.reason == int(DecisionReason.NOT_RUN)
    assert bounds(3, 256, level)[0] < plan.max_not_run
    d = decide(plan, 253, 0, 0, last=True, not_run=3)
    assert d.verdict == UNDECIDED and d.reason == int(DecisionReason.NOT_RUN)
    # 8 of 64: the share's lower bound is above 1 %: no look can decide, stop now
    assert bounds(8, 64, level)[0] > plan.max_not_run
    d = decide(plan, 56, 0, 0, last=False, not_run=8)
    assert d.verdict == UNDECIDED and d.reason == int(DecisionReason.NOT_RUN)
    assert d.low == 0.0 and d.high == pytest.approx(bounds(0, 56, level)[1])
    # a higher limit accepts them; nothing ran: undecided
    assert decide(Sequential(max_not_run=0.1), 120, 0, 0, last=False, not_run=8).verdict == STABLE
    assert decide(plan, 0, 0, 0, last=False, not_run=64).reason == int(DecisionReason.NOT_RUN)


def test_a_grid_point_whose_members_cannot_be_placed_says_so():
    """Pendulum perturbations up to ‖α⁰‖∞ = 2: about a tenth cannot be placed (the
    sampler's Gauss–Newton does not reach them).  Every member that ran is stable, yet the
    point is undecided for the members not run, counted by their status in its summary."""
    model, law = load_scene("pendulum"), stabdae.baumgarte(10.0)
    with pytest.warns(stabdae.IntegrationWarning, match="not placed"):
        ds = stabdae.ensemble(model, law, "rk2", 0.01, 3.0, members={"max": 1024},
                              radius=(0.5, 2.0), seed=1, traces=4)  # fmt: skip
    unplaced = int((ds.status == int(Status.SAMPLING_FAILED)).sum())
    n = int(ds.members_used)
    assert 0 < unplaced and bounds(unplaced, n, Sequential().side_level)[0] > 0.01
    assert int(ds.members_run) == n - unplaced == int(ds.members_stable)
    assert int(ds.decision) == UNDECIDED
    assert int(ds.decision_reason) == int(DecisionReason.NOT_RUN)
    summary = ds.attrs["decision_summary"]
    assert f"{unplaced} not run: {unplaced} not placed (sampling failed)" in summary
    assert f"of the {n - unplaced} that ran" in summary
    assert ds.attrs["verdict_summary"].endswith(
        f"{unplaced} of {n} did not run ({unplaced} not placed (sampling failed))")
    # the same perturbations up to 1: all placed, decided stable
    ok = stabdae.ensemble(model, law, "rk2", 0.01, 3.0, members={"max": 1024},
                          radius=(0.1, 1.0), seed=1, traces=4)  # fmt: skip
    assert int(ok.decision) == STABLE and "not run" not in ok.attrs["decision_summary"]


@pytest.mark.parametrize("bad, words", [
    ({"max_not_run": 1.0}, "max_not_run must be a number in"),
    ({"confidence": 1.0}, "confidence must be a number between 0 and 1"),
    ({"q": 0}, "q must be a number between 0 and 1"),
    ({"batch": 8}, "batch must be an integer of at least 16"),
    ({"batch": 128, "max": 64}, "batch (128) must not exceed max (64)"),
    ({"tolerance": 2.0}, "tolerance must be a number in (0, 1]"),
    ({"maximum": 10}, "members has no key 'maximum'"),
])  # fmt: skip
def test_a_bad_plan_is_refused_by_name(bad, words):
    with pytest.raises(ValueError, match="ensemble: .*" + words.replace("(", r"\(")
                       .replace(")", r"\)")):  # fmt: skip
        stabdae.ensemble(load_scene("pendulum"), stabdae.baumgarte(10.0), tau=0.01, t_end=0.1,
                         members=bad)  # fmt: skip


# --------------------------------------------------------------------- the ensemble
def test_a_sequential_ensemble_is_the_one_shot_ensemble_of_as_many_members():
    """Each member the same, bit for bit, whatever the batches: the first 128 members of a
    plan with batches of 16 are those of one with batches of 64 and of a plain ensemble of
    128 (and the decision, its interval and the count are stored)."""
    model, law = load_scene("pendulum"), stabdae.baumgarte(10.0)
    kw = dict(tau=0.01, t_end=1.0, radius=(1e-8, 1e-3), seed=4, traces=8)
    a = stabdae.ensemble(model, law, members={"batch": 16, "max": 1024}, **kw)
    b = stabdae.ensemble(model, law, members={"batch": 64, "max": 1024}, **kw)
    n = int(a.members_used)
    assert int(a.decision) == STABLE and n == a.sizes["member"]
    assert float(a.decision_high) <= 0.05
    one = stabdae.ensemble(model, law, members=max(n, int(b.members_used)),
                           **{**kw, "traces": "all"})  # fmt: skip
    for name, var in one.data_vars.items():
        if "member" in var.dims:
            for ds in (a, b):
                m = ds.sizes["member"]
                assert np.array_equal(ds[name].values, var.values[:m], equal_nan=True), name
    assert a.trace.values.tolist() == list(range(8))  # the first members are traced
    assert np.array_equal(a.residual_norm.values, one.residual_norm.values[:8], equal_nan=True)
    assert a.attrs["sequential_looks"].tolist() == [16, 32, 64, 128][:len(a.sequential_looks)]


@pytest.mark.parametrize("scheme", ["euler", "rk4"])
def test_the_decisions_on_an_affine_system_are_the_spectral_radius(scheme):
    """The affine system's residual follows R(τÃ) exactly: a grid point is stable exactly
    where ρ(R) < 1.  Points with ρ ≤ 0.99 or ≥ 1.01 (a small version of the study in
    ``studies/certify_affine.py``), two seeds: each decided, and right."""
    seen = set()
    for omega in (2.0, 10.0, 40.0):
        law = stabdae.matrix([[-omega**2, -2 * omega, 0.0], [0.0, 0.0, -omega]])
        for tau_omega in (0.3, 1.5, 3.0):
            tau = tau_omega / omega
            rho = theory.discrete(law.A_tilde(affine), scheme, tau).spectral_radius
            if 0.99 < rho < 1.01:
                continue
            for seed in (1, 2):
                ds = stabdae.ensemble(affine, law, scheme, tau, 400 * tau, seed=seed,
                                      members={"batch": 32, "max": 512}, radius=(1e-6, 1e-2),
                                      traces="none", states=False)  # fmt: skip
                want = STABLE if rho < 1 else UNSTABLE
                assert int(ds.decision) == want, (omega, tau, rho, ds.decision_summary)
                seen.add(want)
    assert seen == {STABLE, UNSTABLE}


SEQUENTIAL_STUDY = """
[model]
file = "pendulum"
[law]
kind = "baumgarte"
omega = 50.0
[run]
t_end = 1.0
tau = 0.01
[ensemble]
members = { batch = 32, max = 256 }
radius = [1e-8, 1e-3]
[sweep]
tau = [0.01, 0.05]
"""


def run_sequential_study(folder, batch=32, stop_at=None):
    """The study above with ``batch``, written to ``folder/s.nc`` (``stop_at``: Ctrl-C
    before that grid point, each point's chunk written as it finishes)."""
    from stabdae.study import run as run_module

    folder.mkdir(exist_ok=True)
    (folder / "s.toml").write_text(SEQUENTIAL_STUDY.replace("batch = 32", f"batch = {batch}"))
    real, calls = run_module.run_point, []

    def point(*args, **kwargs):
        calls.append(1)
        if len(calls) == stop_at:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    run_module.run_point = point
    try:
        return run_study(folder / "s.toml", folder / "s.nc", progress=False,
                         log=lambda *a, **k: None)  # fmt: skip
    finally:
        run_module.run_point = real


def test_a_study_runs_its_grid_points_until_decided(tmp_path):
    """Points take different numbers of members; the dataset pads the others with
    not-run members, its summary and pictures show the decisions."""
    from stabdae.study.report import summary

    ds = xr.open_dataset(run_sequential_study(tmp_path)).load()
    used = ds.members_used.values
    assert ds.decision.values.tolist() == [STABLE, UNSTABLE] and used[1] < used[0]
    assert ds.sizes["member"] == used.max()
    pad = ds.status.isel(tau=1).values[used[1]:]
    assert (pad == int(Status.NOT_NEEDED)).all() and np.isnan(ds.beta.isel(tau=1)[used[1]:]).all()
    assert (ds.status.isel(tau=1).values[:used[1]] != int(Status.NOT_NEEDED)).all()
    text = summary(ds)
    assert "decision" in text and "unstable" in text and "stable" in text


def test_a_sequential_study_resumes_and_rebatches_to_the_same_members(tmp_path, monkeypatch):
    """Interrupted after its first grid point and run again: the dataset of a clean run.
    With batches of 16 instead of 32: the same decisions, and every member run by both
    the same, bit for bit."""
    from conftest import same_data

    monkeypatch.setenv("STABDAE_FLUSH_SECONDS", "0")
    clean = xr.open_dataset(run_sequential_study(tmp_path / "clean")).load()
    with pytest.raises(KeyboardInterrupt):
        run_sequential_study(tmp_path / "cut", stop_at=2)
    assert (tmp_path / "cut" / "s.nc.parts").is_dir()
    same_data(xr.open_dataset(run_sequential_study(tmp_path / "cut")).load(), clean)
    other = xr.open_dataset(run_sequential_study(tmp_path / "b16", batch=16)).load()
    assert other.decision.values.tolist() == clean.decision.values.tolist()
    for k in range(2):
        n = min(int(other.members_used[k]), int(clean.members_used[k]))
        for name, var in clean.data_vars.items():
            if "member" in var.dims:
                a, b = var.isel(tau=k, member=slice(0, n)), other[name].isel(tau=k)[:n]
                assert np.array_equal(a.values, b.values, equal_nan=True), name


def test_a_bad_plan_in_a_study_file_is_refused_by_its_key(tmp_path):
    from stabdae.study.spec import StudyError, load_study

    (tmp_path / "s.toml").write_text(SEQUENTIAL_STUDY.replace("batch = 32", "batch = 8"))
    with pytest.raises(StudyError, match=r"\[ensemble\] members: batch must be an integer "
                                         r"of at least 16, got 8"):  # fmt: skip
        load_study(tmp_path / "s.toml")
    text = SEQUENTIAL_STUDY.replace("batch = 32", "batch = 32, maximum = 5")
    (tmp_path / "s.toml").write_text(text)
    with pytest.raises(StudyError, match=r"\[ensemble\] members: .*has no key 'maximum'"):
        load_study(tmp_path / "s.toml")
