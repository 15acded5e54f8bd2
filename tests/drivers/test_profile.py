"""δ* as a profile (:func:`stabdae.radial_profile`): on members whose stability is a known
function of their perturbation's size, the bracket holds the true radius; the open and
censored cases say so; and on a pendulum it holds the sample's own δ*."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import xarray as xr

import stabdae
from conftest import load_scene
from stabdae._codes import ProfileReason, Verdict


def members(norms, verdicts, low=1e-4, high=1.0) -> xr.Dataset:
    return xr.Dataset({"alpha0_norm": ("member", norms), "verdict": ("member", verdicts)},
                      attrs={"radius_low": low, "radius_high": high})  # fmt: skip


def threshold(r0, n=4000, seed=0, undecided_above=None):
    """Members log-uniform in [1e-4, 1], stable below r0 and unstable above (undecided
    above ``undecided_above`` where given)."""
    r = np.exp(np.random.default_rng(seed).uniform(math.log(1e-4), 0.0, n))
    v = np.where(r < r0, int(Verdict.STABLE), int(Verdict.UNSTABLE)).astype(np.int8)
    if undecided_above is not None:
        v[r >= undecided_above] = int(Verdict.UNDECIDED)
    return members(r, v)


@pytest.mark.parametrize("r0", [5e-4, 0.0123, 0.2])
def test_the_bracket_holds_a_sharp_threshold(r0):
    p = stabdae.radial_profile(threshold(r0), bins=8)
    assert int(p.delta_star_reason) == int(ProfileReason.BRACKETED)
    assert float(p.delta_star_low) <= r0 <= float(p.delta_star_high)
    edges = np.geomspace(1e-4, 1.0, 9)
    k = np.searchsorted(edges, r0) - 1  # the bin holding r0: the bracket is at most it
    assert float(p.delta_star_low) >= edges[k] * (1 - 1e-12)
    assert float(p.delta_star_high) <= edges[k + 2] * (1 + 1e-12)
    assert int(p.members.sum()) == 4000


def test_censored_and_open_brackets_say_why():
    every = stabdae.radial_profile(threshold(2.0), bins=8)  # all stable
    assert int(every.delta_star_reason) == int(ProfileReason.ABOVE_SAMPLE)
    assert float(every.delta_star_low) == pytest.approx(1.0) and math.isnan(every.delta_star_high)
    none = stabdae.radial_profile(threshold(1e-5), bins=8)  # none stable
    assert int(none.delta_star_reason) == int(ProfileReason.BELOW_SAMPLE)
    assert math.isnan(none.delta_star_low)
    # undecided above 1e-2: the bins there are shown neither way
    open_ = stabdae.radial_profile(threshold(0.5, undecided_above=1e-2), bins=8)
    assert int(open_.delta_star_reason) == int(ProfileReason.OPEN_ABOVE)
    assert float(open_.delta_star_low) <= 1e-2 and math.isnan(open_.delta_star_high)
    # the threshold near the first bin's top: that bin is shown neither way
    below = stabdae.radial_profile(threshold(3e-4), bins=8)
    assert int(below.delta_star_reason) == int(ProfileReason.OPEN_BELOW)
    assert math.isnan(below.delta_star_low) and 3e-4 <= float(below.delta_star_high) <= 1e-3
    few = stabdae.radial_profile(threshold(0.05, n=40), bins=8)  # 5 per bin: too few
    assert int(few.delta_star_reason) in (int(ProfileReason.OPEN_ABOVE),
                                          int(ProfileReason.OPEN_BELOW))  # fmt: skip


def test_a_profile_is_refused_with_what_it_needs():
    with pytest.raises(ValueError, match="radial_profile: the dataset has no alpha0_norm"):
        stabdae.radial_profile(xr.Dataset({"verdict": ("member", [0])}))
    two = xr.Dataset({"alpha0_norm": (("tau", "member"), [[1e-3]]),
                      "verdict": (("tau", "member"), [[0]])})  # fmt: skip
    with pytest.raises(ValueError, match="select one grid point first"):
        stabdae.radial_profile(two)
    with pytest.raises(ValueError, match="give radius=\\(low, high\\)"):
        stabdae.radial_profile(xr.Dataset({"alpha0_norm": ("member", [1e-3]),
                                           "verdict": ("member", [0])}))  # fmt: skip
    with pytest.raises(ValueError, match="bins must be a positive integer"):
        stabdae.radial_profile(threshold(0.1), bins=0)


def test_on_a_pendulum_the_bracket_holds_the_samples_own_delta_star(tmp_path):
    """ω = 100, midpoint, τ = 0.015: perturbations above about 0.2 leave the step's reach.
    The profile's bracket holds the sample's δ* (and its picture draws)."""
    from stabdae.plots import profile_curve

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stabdae.IntegrationWarning)
        ds = stabdae.ensemble(load_scene("pendulum"), stabdae.baumgarte(100.0), "midpoint",
                              0.015, 1.5, members=2048, radius=(1e-4, 1.0), seed=1,
                              traces="none", states=False)  # fmt: skip
    p = stabdae.radial_profile(ds, bins=10)
    assert int(p.delta_star_reason) == int(ProfileReason.BRACKETED)
    assert float(p.delta_star_low) <= float(ds.stability_radius) <= float(p.delta_star_high)
    assert profile_curve(p, tmp_path / "p.png").stat().st_size > 10_000


# --------------------------------------------------------------------- paired differences
def verdicts(codes) -> xr.Dataset:
    return xr.Dataset({"verdict": ("member", np.asarray(codes, dtype=np.int8))},
                      attrs={"seed": 1, "radius_low": 1e-4, "radius_high": 1.0})  # fmt: skip


def test_a_paired_difference_reads_the_discordant_members():
    """From the definition: 30 members unstable at a only, 5 at b only, of 200 judged (10
    undecided left out): the difference 25/200, and its interval the Clopper–Pearson one
    of π = 30/35 mapped by (d/n)(2π − 1)."""
    from scipy import stats

    S, U, X = int(Verdict.STABLE), int(Verdict.UNSTABLE), int(Verdict.UNDECIDED)
    a = [U] * 30 + [S] * 5 + [U] * 40 + [S] * 125 + [X] * 10
    b = [S] * 30 + [U] * 5 + [U] * 40 + [S] * 125 + [S] * 10
    out = stabdae.paired_difference(verdicts(a), verdicts(b))
    assert (out["members"], out["a_only"], out["b_only"]) == (200, 30, 5)
    assert out["difference"] == pytest.approx(25 / 200)
    ci = stats.binomtest(30, 35).proportion_ci(0.95, method="exact")
    assert out["low"] == pytest.approx(35 / 200 * (2 * ci.low - 1), rel=1e-9)
    assert out["high"] == pytest.approx(35 / 200 * (2 * ci.high - 1), rel=1e-9)
    assert 0 < out["low"] < out["difference"] < out["high"]
    same = stabdae.paired_difference(verdicts(a), verdicts(a))  # none differs: at most
    assert same["difference"] == 0.0  # the discordant share, 1 − 0.05^{1/200}
    assert same["high"] == -same["low"] == pytest.approx(1 - 0.05 ** (1 / 200), rel=1e-9)
    other = verdicts(b)
    other.attrs["seed"] = 2
    with pytest.raises(ValueError, match="paired_difference: the two ran different members"):
        stabdae.paired_difference(verdicts(a), other)
