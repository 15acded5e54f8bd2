"""The compiled decay estimator against its NumPy/SciPy reference
(``tests/reference/decay.py``, written from the documented definition): the same fit
window and kind of fit, and β and γ to the shift searches' tolerance, on traces with a
known shape: a critically damped decay (a repeated eigenvalue's ``|c0 + c1 t| e^{−ωt}``),
an oscillating one, noisy exponentials, and runs that end while still decaying."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from reference import decay as ref
from stabdae.engine import decay

KINDS = {decay.K_EXPONENTIAL: "exponential", decay.K_POLYNOMIAL: "polynomial",
         decay.K_OSCILLATING: "oscillating", decay.K_NONE: None}  # fmt: skip


def _traces():
    t = np.linspace(0.0, 2.0, 2001)
    rng = np.random.default_rng(11)
    floor = 1e-13 * (1.0 + 0.5 * np.sin(37.0 * t))
    out = {
        "critically damped": 1e-3 * np.abs(1.0 + 10.0 * t) * np.exp(-10.0 * t) + floor,
        "critically damped, sign change": 1e-3 * np.abs(1.0 - 4.0 * t) * np.exp(-8.0 * t)
        + floor,
        "oscillating": 1e-3 * np.exp(-6.0 * t) * (1.2 + np.cos(40.0 * t)) + floor,
        "still decaying": 1e-2 * (1.0 + 5.0 * t) * np.exp(-9.0 * t),
    }
    for k in range(4):
        noise = np.exp(1e-3 * rng.standard_normal(t.size))
        out[f"noisy exponential {k}"] = 1e-4 * np.exp(-(5.0 + 3 * k) * t) * noise + floor
    return t, out


@pytest.fixture(scope="module")
def measured():
    t, traces = _traces()
    names = list(traces)
    rec = decay.measure_traces(np.stack([traces[n] for n in names]), t)
    return t, traces, names, rec


def test_window_and_kind_are_the_references(measured):
    """Every trace's fit window (first and last time, points) and kind of fit are the
    reference's, exactly; the polynomial and the oscillating fits both occur (the plain
    exponential loses to the polynomial on any trace that is not an exact exponential)."""
    t, traces, names, rec = measured
    kinds = set()
    for j, name in enumerate(names):
        want = ref.estimate(t, traces[name])
        got_kind = KINDS[int(rec["fit_kind"][j])]
        assert got_kind == want["kind"], name
        assert rec["fit_points"][j] == want["fit_points"], name
        assert rec["fit_start"][j] == want["fit_start"], name
        assert rec["fit_end"][j] == want["fit_end"], name
        kinds.add(got_kind)
    assert {"polynomial", "oscillating"} <= kinds


def test_beta_and_gamma_are_the_references(measured):
    """β and γ agree with the reference's: to 1e-10 for the closed-form fits (the straight
    line, the oscillating envelope's regression), to 2e-5 where the library's 16-point
    grid and Brent search of the shift stands beside the reference's dense grid and
    SciPy's minimizer."""
    t, traces, names, rec = measured
    for j, name in enumerate(names):
        want = ref.estimate(t, traces[name])
        tol = 2e-5 if want["kind"] == "polynomial" else 1e-10
        np.testing.assert_allclose(rec["beta"][j], want["beta"], rtol=tol, err_msg=name)
        np.testing.assert_allclose(rec["gamma"][j], want["gamma"], rtol=10 * tol,
                                   err_msg=name)  # fmt: skip
        assert rec["reason"][j] == decay.R_FITTED, name


def test_reference_window_follows_the_floor_margin():
    """A check of the reference itself on a closed form: a pure exponential onto a
    constant floor is cut where the envelope first comes within 1000 times the floor,
    and its fit is the exponential's rate."""
    t = np.linspace(0.0, 6.0, 6001)
    v = 1e-2 * np.exp(-10.0 * t) + 1e-14
    est = ref.estimate(t, v)
    # the floor (the last fifth's largest) is 1e-14: the window ends at the envelope's
    # last point above 1e-11, where 1e-2 e^{−10 t} = 1e-11
    assert est["fit_end"] < np.log(1e9) / 10.0 <= est["fit_end"] + 0.01
    assert abs(est["beta"] / 10.0 - 1.0) < 1e-3


def test_gamma_of_a_run_that_ends_on_its_roundoff_level_is_the_transients():
    """A pure exponential that falls onto a roundoff plateau in the run's last fifth
    (each fifth still below the one before, so the run reads as still decaying): with
    the roundoff level given, γ is the exponential's prefactor ``a`` (to the plateau's
    share at the lowest point used, 1e-6 of it), the window ends above the plateau, and
    both are the reference's."""
    t = np.linspace(0.0, 3.0, 3001)
    a, rate, level = 1e-3, 10.0, 1e-15
    wobble = 1.0 + 0.5 * np.sin(41.0 * t)
    v = a * np.exp(-rate * t) + level * wobble
    rec = decay.measure_traces(v[None, :], t, noise=level)
    assert rec["reason"][0] == decay.R_FITTED
    assert abs(rec["gamma"][0] / a - 1.0) < 2e-6
    assert a * np.exp(-rate * rec["fit_end"][0]) > ref.ROUNDOFF_FLOOR * level
    assert abs(rec["beta"][0] / rate - 1.0) < 1e-3
    want = ref.estimate(t, v, level)
    assert rec["fit_end"][0] == want["fit_end"]
    np.testing.assert_allclose(rec["gamma"][0], want["gamma"], rtol=1e-9)


# ------------------------------------------------------------------ random traces
def _shape(kind, a, rate, c, omega, floor, t):
    wobble = 1.0 + 0.3 * np.sin(omega * t + 1.0)
    if kind == "exponential":
        return a * np.exp(-rate * t) + floor * wobble
    if kind == "critically damped":
        return a * np.abs(1.0 + c * t) * np.exp(-rate * t) + floor * wobble
    if kind == "oscillating":
        return a * np.exp(-rate * t) * (1.2 + np.cos(omega * t)) + floor * wobble
    if kind == "flat":
        return a * wobble
    if kind == "rising":
        return a * np.exp(rate * t) + floor
    if kind == "on its floor":
        return floor * wobble
    return a * (1.0 + c * t) * np.exp(-0.3 * rate * t)  # still decaying at the end


@given(kind=st.sampled_from(["exponential", "critically damped", "oscillating", "flat",
                             "rising", "on its floor", "still decaying"]),
       a=st.floats(1e-8, 1.0), rate=st.floats(0.5, 40.0), c=st.floats(-8.0, 20.0),
       omega=st.floats(5.0, 80.0), floor=st.floats(1e-16, 1e-9),
       samples=st.sampled_from([201, 600, 1001]),
       noise=st.sampled_from([0.0, 1e-17, 1e-15, 1e-13]))  # fmt: skip
@settings(max_examples=120)
def test_random_traces_follow_the_reference(kind, a, rate, c, omega, floor, samples, noise):
    """Random traces of every shape (decaying onto a varying floor, a repeated
    eigenvalue's ``|1 + ct| e^{−βt}``, oscillating, flat, rising, sitting on the floor,
    still decaying at the end): the fifths' largest norms, the start and the largest
    exactly; the window and the kind of fit exactly, except where the reference's own
    choice is a tie (the two fits' sums of squares, or the RMS against ``SMOOTH_RMS``,
    within 1e-6); β to the shift searches' tolerance, and γ; no fit, no β.  With a
    roundoff level given (``noise``), the window and γ keep their documented distance
    from it."""
    t = np.linspace(0.0, 2.0, samples)
    v = _shape(kind, a, rate, c, omega, floor, t)
    assume(np.all(v > 0) and np.all(np.isfinite(v)))
    rec = decay.measure_traces(v[None, :], t, noise=noise)
    want = ref.estimate(t, v, noise)
    np.testing.assert_array_equal([rec[f"w{k}"][0] for k in range(5)], ref.fifths(t, v))
    assert rec["initial"][0] == v[0] and rec["largest"][0] == v.max()
    got_kind = KINDS[int(rec["fit_kind"][0])]
    if want["kind"] is None:
        assert got_kind is None and np.isnan(rec["beta"][0])
        assert rec["reason"][0] != decay.R_FITTED
        return
    assert rec["fit_points"][0] == want["fit_points"]
    assert rec["fit_start"][0] == want["fit_start"] and rec["fit_end"][0] == want["fit_end"]
    if got_kind != want["kind"]:
        # (both fits exact to roundoff, as for a pure exponential, is a tie too)
        tie_fit = (abs(want["sse_polynomial"] - want["sse_exponential"])
                   <= 1e-6 * want["sse_exponential"] + 1e-16 * want["fit_points"])  # fmt: skip
        tie_rms = abs(want["rms"] / ref.SMOOTH_RMS - 1.0) <= 1e-6
        assert tie_fit or tie_rms, (got_kind, want)
        return
    tol = 2e-5 if want["kind"] == "polynomial" else 1e-10
    np.testing.assert_allclose(rec["beta"][0], want["beta"], rtol=tol)
    if rec["reason"][0] == decay.R_FITTED:
        np.testing.assert_allclose(rec["gamma"][0], want["gamma"], rtol=10 * tol)
