"""Ensembles: sampling, decay rates against the discrete prediction, determinism,
divergence isolation, NetCDF round trip."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest
import xarray as xr
from numba import njit

import stabdae
from conftest import ROOT, assert_schema, load_scene
from stabdae._schema import write_netcdf
from stabdae.engine import decay
from stabdae.engine.ensemble.block import CHECKPOINT
from stabdae.engine.fma import HOST_FMA

# ω = 1000 with τω = 0.1: the residual decays over several decades before the truncation
# floor, and the discrete rate −ln ρ(R(τÃ))/τ differs from the continuous ω (Euler: 5 %).
TAU, T_END, SAVE = 1e-4, 0.05, 2e-4


def baumgarte_ensemble(name, scheme, xi, **kw):
    model = load_scene(name)
    args = dict(members=64, radius=(1e-2, 1e-1), seed=3, save_dt=SAVE)
    args.update(kw)
    return stabdae.ensemble(model, stabdae.baumgarte(1000.0, xi), scheme, TAU, T_END, **args)


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


@pytest.mark.parametrize("radius", [(1e-6, 1e-2), (0.05, 0.5)])
def test_sampling_reaches_the_targets(radius):
    """Small targets are met with the reference state's Jacobian (a step or two), large
    ones, where that converges slowly or not at all, by Gauss–Newton at the current state:
    both to the same accuracy."""
    model = load_scene("double_pendulum")
    x0, alpha0, status = stabdae.sample_perturbations(model, 200, radius, seed=5)
    assert (status == 0).all()
    rng = np.random.default_rng(5)  # the same draws, to get the targets back
    from stabdae.engine.sampler import draw_alphas

    targets = draw_alphas(model.n_residual, 200, radius, rng)
    err = np.max(np.abs(alpha0 - targets), axis=1)
    size = np.max(np.abs(targets), axis=1)
    x_scale = np.max(np.abs(x0), axis=1)
    assert np.all(err <= 1e-12 * size + 64 * np.finfo(float).eps * x_scale**2)
    assert np.all((err / size)[size > 1e-3] <= 1e-12)  # relative where double allows it
    norms = np.max(np.abs(alpha0), axis=1)
    assert radius[0] * (1 - 1e-9) <= norms.min() and norms.max() <= radius[1] * (1 + 1e-9)
    # the achieved perturbation is g(x0): checked with the Python-side residual
    for x, a in zip(x0[:20], alpha0[:20]):
        np.testing.assert_allclose(model.residual(x), a, rtol=1e-9, atol=1e-15)


@pytest.mark.parametrize("scheme", ["midpoint", "rk4"])
@pytest.mark.parametrize("xi", [1.05, 3.0])
def test_beta_leaves_out_the_lead_of_the_transient(xi, scheme):
    """Over-damped laws: a second mode (nearly as slow at ξ = 1.05, much faster at ξ = 3)
    bends the start of the transient.  With the fit window after the first 30 % of its
    decades the median β is within 1 % of −ln ρ(R(τÃ))/τ (measured: within 0.1 %); a fit
    over the whole transient is 4–10 % off."""
    ds = baumgarte_ensemble("pendulum", scheme, xi)
    assert abs(float(ds.beta_median) / float(ds.beta_theory_discrete) - 1) <= 0.01


def test_radii_are_log_uniform_and_directions_of_unit_max_norm():
    """‖α⁰‖∞ of the placed members is log-uniform in the radius range: a Kolmogorov–Smirnov
    test of log ‖α⁰‖∞ against the uniform law on [log low, log high] (uniform radii put
    nine tenths of them in the top decade and fail it at p < 1e-100)."""
    from scipy.stats import kstest

    model = load_scene("pendulum")
    low, high = 1e-6, 1e-2
    _, alpha0, status = stabdae.sample_perturbations(model, 2000, (low, high), seed=11)
    assert (status == 0).all()
    logr = np.log(np.max(np.abs(alpha0), axis=1))
    assert math.log(low) * (1 + 1e-9) <= logr.min() and logr.max() <= math.log(high) + 1e-9
    test = kstest(logr, "uniform", args=(math.log(low), math.log(high / low)))
    assert test.pvalue > 1e-3, test
    # and not uniform in r itself
    assert kstest(np.exp(logr), "uniform", args=(low, high - low)).pvalue < 1e-10


def test_sampling_is_minimum_norm_to_first_order():
    """For small α⁰, x⁰ − x* ≈ G⁺α⁰ (G from finite differences at x*)."""
    model = load_scene("pendulum")
    x_ref = model.reference_state()
    x0, alpha0, _ = stabdae.sample_perturbations(model, 20, (1e-7, 1e-6), seed=1)
    h = 1e-6
    G = np.stack([(model.residual(x_ref + h * e) - model.residual(x_ref - h * e)) / (2 * h)
                  for e in np.eye(4)], axis=1)  # fmt: skip
    expected = np.linalg.pinv(G) @ alpha0.T
    np.testing.assert_allclose(x0 - x_ref, expected.T, rtol=1e-4, atol=1e-13)


def test_members_equal_single_integrations_bit_for_bit():
    model = load_scene("double_pendulum")
    law = stabdae.baumgarte(20.0, 1.0)
    ds = stabdae.ensemble(model, law, "heun", 1e-3, 0.5, members=5, seed=2, save_dt=0.05)
    for j in range(5):
        one = stabdae.integrate(model, ds.x0.values[j], law, "heun", 1e-3, 0.5, 0.05)
        np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[-1])
        np.testing.assert_array_equal(ds.residual_norm.values[j],
                                      one.residual_norm.values.astype(np.float32))  # fmt: skip


def test_block_size_does_not_change_any_number():
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0)
    runs = [stabdae.ensemble(model, law, "rk4", 1e-3, 0.2, members=37, seed=4, block=b)
            for b in (16, 64)]  # fmt: skip
    for other in runs[1:]:
        for name in ("residual_norm", "x_final", "beta", "alpha0"):
            np.testing.assert_array_equal(runs[0][name].values, other[name].values)


_THREADS_SCRIPT = """
import json, sys, numpy as np, numba, stabdae
model = stabdae.load_model(sys.argv[1])
ds = stabdae.ensemble(model, stabdae.baumgarte(10.0), "midpoint", 1e-3, 0.3,
                      members=300, seed=9, block=16)
print(json.dumps({"threads": numba.get_num_threads(),
                  "wide": ds.attrs["prefer_512_bit_vectors"],
                  "features": numba.config.CPU_FEATURES or "",
                  "x": ds.x_final.values.tobytes().hex(),
                  "r": ds.residual_norm.values.tobytes().hex()}))
"""


def test_thread_count_and_vector_width_do_not_change_any_number():
    """One thread or two, 512-bit SIMD vectors (where the CPU has AVX-512) or the
    compiler's default width: the same bits."""
    from numba.core.codegen import get_host_cpu_features

    out = {}
    base = {k: v for k, v in os.environ.items()
            if k not in ("STABDAE_VECTOR_WIDTH", "NUMBA_CPU_FEATURES", "NUMBA_CPU_NAME")}
    for run, env in (("1", dict(base, NUMBA_NUM_THREADS="1")),
                     ("2", dict(base, NUMBA_NUM_THREADS="2")),
                     ("256", dict(base, NUMBA_NUM_THREADS="2", STABDAE_VECTOR_WIDTH="256"))):
        proc = subprocess.run([sys.executable, "-c", _THREADS_SCRIPT,
                               str(ROOT / "kernels" / "pendulum.py")],
                              capture_output=True, text=True, env=env, check=True)  # fmt: skip
        out[run] = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["1"]["threads"] == 1
    avx512 = "+avx512f" in get_host_cpu_features().split(",")
    assert out["2"]["wide"] == int(avx512) and out["256"]["wide"] == 0
    assert ("-prefer-256-bit" in out["2"]["features"]) == avx512
    assert "-prefer-256-bit" not in out["256"]["features"]
    for other in ("2", "256"):
        assert out["1"]["x"] == out[other]["x"] and out["1"]["r"] == out[other]["r"], other


def test_vector_width_is_chosen_only_where_numba_leaves_it_open(monkeypatch):
    from numba import config
    from numba.core.codegen import get_host_cpu_features

    from stabdae import _vector_width

    monkeypatch.setattr(config, "CPU_FEATURES", None)
    # this process has compiled: numba's features are fixed, nothing may change them
    assert _vector_width.choose({}) is False and config.CPU_FEATURES is None
    # a user's own features stand (here in a fresh process, where the choice is open)
    host = get_host_cpu_features()
    env = dict(os.environ, NUMBA_CPU_FEATURES=host)
    env.pop("STABDAE_VECTOR_WIDTH", None)
    proc = subprocess.run([sys.executable, "-c", "import numba, stabdae; "
                           "print(stabdae._vector_width.PREFER_512, numba.config.CPU_FEATURES)"],
                          capture_output=True, text=True, env=env, check=True)  # fmt: skip
    assert proc.stdout.split() == ["False", host]


def test_divergence_is_isolated():
    """Members that blow up (singular S at q = 0, a residual above the threshold, a NaN
    start) are flagged and frozen; the others give the same numbers as without them."""
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0)
    good, _, _ = stabdae.sample_perturbations(model, 6, (1e-4, 1e-3), seed=1)
    singular = np.array([0.0, 0.0, 0.1, 0.0])  # f_q = 0: S = F Fᵀ = 0
    far = model.reference_state() * np.array([3.0, 3.0, 1.0, 1.0])  # |f| = 8 > threshold
    nan = np.full(4, np.nan)
    mixed = np.vstack([good[:2], singular, good[2:4], far, nan, good[4:]])
    kw = dict(epsilon=1.0, divergence=5.0, save_dt=0.01)
    a = stabdae.ensemble(model, law, "rk4", 1e-3, 0.5, x0=mixed, **kw)
    b = stabdae.ensemble(model, law, "rk4", 1e-3, 0.5, x0=good, **kw)
    keep = [0, 1, 3, 4, 7, 8]
    for name in ("residual_norm", "x_final", "beta", "gamma", "bounded"):
        np.testing.assert_array_equal(a[name].values[keep], b[name].values)
    status = a.status.values
    assert status[2] == stabdae.Status.SINGULAR_S
    assert status[5] == stabdae.Status.DIVERGED and a.diverged_step.values[5] == 0
    assert status[6] == stabdae.Status.NONFINITE_STATE
    assert a.diverged.values[[2, 5, 6]].all() and not a.diverged.values[keep].any()
    assert not a.bounded.values[[2, 5, 6]].any() and b.bounded.values.all()


def test_dataset_schema_and_round_trip(tmp_path):
    ds = baumgarte_ensemble("double_pendulum", "midpoint", 1.0, members=16)
    assert_schema(ds)
    assert ds.residual_norm.dtype == np.float32
    for key in ("model", "law", "scheme", "tau", "seed", "stabdae_version", "created_at"):
        assert key in ds.attrs, key
    assert ds.attrs["residual_norm_dtype"] == "float32"
    assert ds.attrs["fused_multiply_add"] == int(HOST_FMA)
    path = write_netcdf(ds, tmp_path / "ens.nc")
    with xr.open_dataset(path) as back:
        xr.testing.assert_identical(back.load(), ds)
        for name in ("residual_norm", "x0", "beta"):  # zlib-compressed, shuffled
            enc = back[name].encoding
            assert enc.get("zlib") is True and enc.get("shuffle") is True, (name, enc)


def test_ensemble_errors():
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0)
    with pytest.raises(ValueError, match=r"^ensemble: radius must be a positive number or a pair"):
        stabdae.ensemble(model, law, "rk4", 1e-3, 0.1, radius=(-1.0, 1.0))
    with pytest.raises(ValueError, match=r"^ensemble: radius low = 1 exceeds high = 0.1"):
        stabdae.ensemble(model, law, "rk4", 1e-3, 0.1, radius=(1.0, 0.1))
    with pytest.raises(ValueError, match=r"^ensemble: members must be a positive integer, got 0"):
        stabdae.ensemble(model, law, "rk4", 1e-3, 0.1, members=0)
    with pytest.raises(
        ValueError, match=r"^ensemble: x0 must have shape \(members, 2n\) = \(M, 4\)"
    ):
        stabdae.ensemble(model, law, "rk4", 1e-3, 0.1, x0=np.zeros((3, 3)))


# ---------------------------------------------------------------- adaptive steps per member
@pytest.mark.parametrize("pair", ["dopri5", "dop853"])
def test_adaptive_members_control_their_own_steps(pair):
    """Pendulums swinging at different amplitudes need different numbers of steps; each
    member is bit-for-bit the single adaptive integration from its start, with either
    embedded pair."""
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    angles = np.array([0.1, 0.8, 1.6, 2.6])
    x0 = np.stack([[np.sin(a), -np.cos(a), 0.0, 0.0] for a in angles])
    kw = dict(rtol=1e-8, atol=1e-10, save_dt=0.5, residual_dtype="float64")
    ds = stabdae.ensemble(model, law, pair, tau=1e-3, t_end=2.0, x0=x0, **kw)
    assert ds.attrs["method"] == f"{pair}-adaptive" and ds.attrs["first_step"] == 1e-3
    steps = ds.steps_accepted.values
    assert len(set(steps.tolist())) == len(angles), steps  # every member its own count
    for j in range(len(angles)):
        one = stabdae.integrate_adaptive(model, x0[j], law, 2.0, scheme=pair, rtol=1e-8,
                                         atol=1e-10, save_dt=0.5, first_step=1e-3)  # fmt: skip
        assert one.attrs["method"] == pair and one.attrs["steps_accepted"] == steps[j]
        assert one.attrs["rhs_evaluations"] == ds.rhs_evaluations.values[j]
        np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[-1])
        np.testing.assert_array_equal(ds.residual_norm.values[j], one.residual_norm.values)


@pytest.mark.parametrize("pair", ["dopri5", "dop853"])
def test_adaptive_lanes_refill_and_stay_bit_identical(pair):
    """Members of very different step counts (at rest to spinning at 100 rad/s) on three
    lanes, five or so members per work item (so lanes are refilled): a lane whose member
    has ended takes the next waiting one, and every member is still the single adaptive
    integration bit for bit; a member that cannot start (singular S) stops alone; nothing
    depends on the lanes or the threads."""
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    angles = np.linspace(0.05, 3.0, 35)
    spins = np.random.default_rng(3).permutation(np.r_[0.0, np.geomspace(0.1, 100.0, 34)])
    x0 = np.stack([[np.sin(a), -np.cos(a), w * np.cos(a), w * np.sin(a)]
                   for a, w in zip(angles, spins)])  # fmt: skip
    x0 = np.insert(x0, 4, [0.0, 0.0, 0.1, 0.0], axis=0)  # the rod of length 0: S = 0
    kw = dict(tau=1e-3, t_end=2.0, x0=x0, rtol=1e-8, atol=1e-10, save_dt=0.25,
              residual_dtype="float64", traces="all")  # fmt: skip
    with pytest.warns(stabdae.IntegrationWarning, match="1 singular S"):
        ds = stabdae.ensemble(model, law, pair, block=3, threads=1, **kw)
    assert ds.status.values[4] == stabdae.Status.SINGULAR_S
    good = [j for j in range(len(x0)) if j != 4]
    steps = ds.steps_accepted.values[good]
    assert steps.max() >= 4 * steps.min(), steps
    for j in good:
        one = stabdae.integrate_adaptive(model, x0[j], law, 2.0, scheme=pair, rtol=1e-8,
                                         atol=1e-10, save_dt=0.25, first_step=1e-3)  # fmt: skip
        assert one.attrs["steps_accepted"] == ds.steps_accepted.values[j]
        assert one.attrs["rhs_evaluations"] == ds.rhs_evaluations.values[j]
        np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[-1])
        np.testing.assert_array_equal(ds.residual_norm.values[j], one.residual_norm.values)
    with pytest.warns(stabdae.IntegrationWarning):
        other = stabdae.ensemble(model, law, pair, block=8, threads=2, **kw)
    for name in ("residual_norm", "x_final", "steps_accepted", "rhs_evaluations", "beta",
                 "residual_floor", "status"):  # fmt: skip
        np.testing.assert_array_equal(ds[name].values, other[name].values)


def test_adaptive_prediction_wakes_no_lapack_solve(monkeypatch):
    """The adaptive ensemble's prediction propagator ``e^{Ãh}`` is formed by matrix
    products only: LAPACK's solves (``scipy.linalg.expm`` makes them) wake the BLAS
    library's threads, which then spin on the cores the ensemble's threads run on.
    Every member still gets a predicted β, at the law's rate ω = 10."""
    import scipy.linalg

    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)

    def refuse(*args, **kwargs):
        raise AssertionError("a LAPACK solve in the ensemble's own path")

    for mod, name in ((scipy.linalg, "expm"), (scipy.linalg, "solve"),
                      (scipy.linalg, "lu_factor"), (np.linalg, "solve"), (np.linalg, "inv")):
        monkeypatch.setattr(mod, name, refuse)
    ds = stabdae.ensemble(model, law, "dopri5", tau=1e-3, t_end=2.0, members=16,
                          radius=(1e-6, 1e-3), seed=2, rtol=1e-8, atol=1e-10)  # fmt: skip
    fitted = ds.beta_reason.values == decay.R_FITTED
    assert fitted.sum() >= 12
    np.testing.assert_allclose(ds.beta_predicted.values[fitted], 10.0, rtol=0.01)


def test_expm_by_products_is_scipys_to_roundoff():
    """``theory._expm`` (products only) against SciPy's Padé ``expm``: a critically
    damped law over one prediction step, a stiff one, a random 6 × 6 and zero."""
    import scipy.linalg

    from stabdae import theory

    rng = np.random.default_rng(4)
    cases = [np.array([[0.0, 1.0], [-100.0, -20.0]]) * 2.4e-3,
             np.array([[0.0, 7.3e-6], [-730.0, -0.146]]), 3.0 * rng.normal(size=(6, 6)),
             np.zeros((3, 3))]  # fmt: skip
    for A in cases:
        ref = scipy.linalg.expm(A)
        assert np.abs(theory._expm(A) - ref).max() <= 1e-13 * np.abs(ref).max()


def test_adaptive_ensemble_beta_and_determinism():
    """Continuous-time decay: at tight tolerance the median fitted β is the Theorem 3 rate
    (no discrete prediction is stored); one or two threads give the same numbers."""
    model = load_scene("double_pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    kw = dict(tau=1e-3, t_end=3.0, members=64, radius=(1e-6, 1e-3), seed=5, save_dt=0.01,
              rtol=1e-10, atol=1e-13)  # fmt: skip
    a = stabdae.ensemble(model, law, threads=1, **kw)
    b = stabdae.ensemble(model, law, threads=2, **kw)
    assert abs(float(a.beta_median) / float(a.beta_theory) - 1.0) < 0.02
    assert "beta_theory_discrete" not in a
    for name in ("residual_norm", "x_final", "steps_accepted"):
        np.testing.assert_array_equal(a[name].values, b[name].values)


def test_adaptive_ensemble_isolates_divergence():
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0)
    good, _, _ = stabdae.sample_perturbations(model, 3, (1e-4, 1e-3), seed=1)
    singular = np.array([0.0, 0.0, 0.1, 0.0])
    kw = dict(tau=1e-3, t_end=0.5, rtol=1e-8, save_dt=0.05, residual_dtype="float64")
    a = stabdae.ensemble(model, law, x0=np.vstack([good[:1], singular, good[1:]]), **kw)
    b = stabdae.ensemble(model, law, x0=good, **kw)
    np.testing.assert_array_equal(a.residual_norm.values[[0, 2, 3]], b.residual_norm.values)
    assert a.status.values[1] == stabdae.Status.SINGULAR_S and a.diverged.values[1] == 1


def test_adaptive_ensemble_errors():
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0)
    with pytest.raises(ValueError, match=r"^ensemble: adaptive steps need an embedded pair, "
                       r"'dopri5' \(Dormand–Prince 5\(4\)\) or 'dop853' .*; got 'rk4'"):
        stabdae.ensemble(model, law, "rk4", 1e-3, 0.1, members=4, rtol=1e-6)
    with pytest.raises(ValueError, match="^ensemble: atol is for adaptive steps; give rtol"):
        stabdae.ensemble(model, law, "rk4", 1e-3, 0.1, members=4, atol=1e-6)


def _scheme(spec):
    if isinstance(spec, str):
        return spec
    with warnings.catch_warnings():  # σ = 0 and σ = 2 are first order, and say so
        warnings.simplefilter("ignore", UserWarning)
        return stabdae.two_stage(*spec)


@pytest.mark.parametrize("spec", ["euler", "midpoint", "rk4", "dop853", (0.3, 0.0), (0.25, 2.0)])
def test_every_tableau_pattern_equals_single_integrations(spec):
    """The ensemble kernel is compiled per pattern of zero / one / other coefficients and
    writes the stages out; its numbers are still those of ``integrate`` bit for bit
    (σ = 0 has a zero weight, σ = 2 two general ones, DOP853 twelve stages and zeros
    inside A and b; dopri5's pattern is covered below)."""
    scheme = _scheme(spec)
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    ds = stabdae.ensemble(model, law, scheme, 2e-3, 0.2, members=3, seed=5, save_dt=0.02)
    for j in range(3):
        one = stabdae.integrate(model, ds.x0.values[j], law, scheme, 2e-3, 0.2, 0.02)
        np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[-1])
        np.testing.assert_array_equal(ds.residual_norm.values[j],
                                      one.residual_norm.values.astype(np.float32))  # fmt: skip


@pytest.mark.parametrize("spec", ["rk4", "dopri5"])
def test_time_dependent_model_stage_times_equal_single_integrations(spec):
    """On time-dependent constraints (the pendulum of prescribed length, the car axis) the
    stage times t + c·τ matter: the ensemble kernel's generated step gives the numbers of
    ``integrate`` bit for bit.  The stage times are formed alike for every pattern of
    coefficients (the patterns themselves are covered on the pendulum above); RK4 repeats
    a stage time, dopri5 has seven distinct ones and zeros inside A."""
    scheme = _scheme(spec)
    cases = [("pendulum_varying_length", stabdae.baumgarte(10.0, 1.0), 2e-3)]
    if spec == "rk4":  # (one pattern on the car axis: each pattern is a compilation)
        cases.append(("car_axis", stabdae.baumgarte(50.0, 1.0), 1e-3))
    for name, law, tau in cases:
        model = load_scene(name)
        ds = stabdae.ensemble(model, law, scheme, tau, 0.1, members=3, seed=5,
                              radius=(1e-6, 1e-4), save_dt=0.02)  # fmt: skip
        assert (ds.status.values == 0).all()
        for j in range(3):
            one = stabdae.integrate(model, ds.x0.values[j], law, scheme, tau, 0.1, 0.02)
            np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[-1])
            np.testing.assert_array_equal(ds.residual_norm.values[j],
                                          one.residual_norm.values.astype(np.float32))  # fmt: skip


def test_reference_residuals_are_those_of_integrate():
    """Each member's decay is measured on its distance from the residual of the trajectory
    from the reference state.  Its run (the ensemble kernel with that one member) gives
    ``integrate``'s residual at every step bit for bit, sample and stage times included
    (a time-dependent model: a residual at the wrong time differs at once)."""
    from stabdae._ensemble import _reference_residuals
    from stabdae._laws import bind_law

    model = load_scene("pendulum_varying_length")
    law = stabdae.baumgarte(10.0, 1.0)
    p, tau, nsteps = model.param_vector(), 2e-3, 50
    g = _reference_residuals(model, bind_law(law, model), stabdae.rk4(), p, model.t0, tau,
                             nsteps)  # fmt: skip
    one = stabdae.integrate(model, model.reference_state(p), law, "rk4", tau,
                            model.t0 + nsteps * tau, tau)  # fmt: skip
    assert g.shape == (nsteps + 1, model.n_residual) and np.abs(g[-1]).max() > 0
    np.testing.assert_array_equal(g, one.residual.values)


def test_stability_radius_is_bracketed():
    """Members at known radii 1e-5 … 2e-1 with ε = 1e-3: the three that start above ε are
    not bounded (but stable: they decay), the two below it are; with every member stable
    δ* is not bracketed (NaN, its low end the largest radius); with a divergence threshold
    that stops the two largest members, δ* lies between 1e-2 and 1e-1."""
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
    # two members stop: δ*'s upper end is the smaller of their radii
    assert cut.stable.values.tolist() == [1, 1, 1, 0, 0]
    assert float(cut.stability_radius_low) == a[2] and float(cut.stability_radius_high) == a[4]
    assert a[2] < float(cut.stability_radius) < a[4]


def test_bounded_needs_the_residual_to_have_decayed():
    """An unstable law (f̈ = 5 f) over 1 s: a member that starts with ḟ = 1e-6 (and f = 0)
    grows as ḟ₀ cosh(√5 t), to about 4.7e-6, stays far below ε = 1 and is still not
    bounded, since it did not decay; members on the manifold (their residual stays at
    roundoff) are bounded."""
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
    assert ds.bounded.values.tolist() == [1] * 7 + [0]


def test_members_stopped_mid_run_keep_their_last_good_state():
    """Euler at τ = 0.25 with ω = 10 is unstable: every member grows until it stops, at a
    step of its own, so the block loses its members one by one and ends with none running.
    A member stopped at a stored sample (residual above the threshold) keeps that state;
    one whose step overflowed keeps the state before that step.  Both equal ``integrate``
    run up to that step, bit for bit."""
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    tau = 0.25
    x0, _, _ = stabdae.sample_perturbations(model, 5, (1e-3, 1e-1), seed=3)
    runs = {
        stabdae.Status.DIVERGED: stabdae.ensemble(
            model, law, "euler", tau, 250.0, x0=x0, save_dt=tau, epsilon=1.0, divergence=1e250
        ),
        stabdae.Status.NONFINITE_STATE: stabdae.ensemble(
            model, law, "euler", tau, 250.0, x0=x0, save_dt=250.0, epsilon=1.0, divergence=1e300
        ),
    }
    for status, ds in runs.items():
        assert (ds.status.values == status).all(), status
        steps = ds.diverged_step.values
        assert len(set(steps.tolist())) > 1 and (steps > 0).all()
        if status == stabdae.Status.NONFINITE_STATE:  # the block was rolled back
            assert ((steps > CHECKPOINT) & (steps % CHECKPOINT > 1)).any(), steps
        for j in range(5):
            span = steps[j] * tau
            one = stabdae.integrate(model, x0[j], law, "euler", tau, span, span)
            np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[-1])
            # the stored samples up to the stop are the trajectory's, NaN after it
            every = round(float(ds.attrs["save_dt"]) / tau)
            full = stabdae.integrate(model, x0[j], law, "euler", tau, span, tau)
            ref = full.residual_norm.values[::every].astype(np.float32)
            row = ds.residual_norm.values[j]
            np.testing.assert_array_equal(row[: len(ref)], ref)
            assert np.isnan(row[len(ref):]).all()


def test_measures_of_stored_traces_match_numpy():
    """Initial, largest and final norm of traces with stops (inf, NaN) are NumPy's over
    the leading finite samples; a stopped trace gets no β and the reason "stopped"."""
    from stabdae.engine import decay

    norms = np.random.default_rng(0).random((40, 30))
    norms[3, 10:] = np.nan
    norms[5, 7], norms[5, 8:] = np.inf, np.nan
    meas = decay.measure_traces(norms, np.linspace(0.0, 1.0, 30))
    for j in range(40):
        row = norms[j]
        n = int(np.argmin(np.isfinite(row))) if not np.isfinite(row).all() else row.size
        assert meas[j, decay.C_INITIAL] == row[0]
        assert meas[j, decay.C_LARGEST] == row[:n].max()
        assert meas[j, decay.C_FINAL] == row[n - 1]
    assert meas[3, decay.C_REASON] == decay.R_STOPPED and np.isnan(meas[3, decay.C_BETA])


def test_ladder_records_are_the_right_envelope():
    """The ladder's points are, level by level, the last sample on that level, and exactly
    those of them that no later sample exceeds (the right envelope), in time order."""
    import struct

    from stabdae.engine import decay

    rng = np.random.default_rng(4)
    v = np.exp(-np.linspace(0, 12, 700) + 2.0 * rng.standard_normal(700))
    lt, lv, base = decay.ladders(1)
    rt, ry = np.empty(decay.NBINS), np.empty(decay.NBINS)
    decay.ladder_clear(lt, 0)
    base[0] = decay.ladder_base(v[0])
    bits = lambda x: struct.unpack("<q", struct.pack("<d", x))[0]  # noqa: E731
    level = [min(max((bits(x) >> 49) - base[0], 0), decay.NBINS - 1) for x in v]
    for i, x in enumerate(v):
        lt[0, level[i]], lv[0, level[i]] = float(i), x
    n = decay.records(lt, lv, 0, rt, ry)
    last_on_level = {lev: i for i, lev in enumerate(level)}
    expect = sorted(i for i in last_on_level.values() if i == v.size - 1 or v[i] > v[i + 1:].max())
    assert rt[:n].tolist() == [float(i) for i in expect]
    np.testing.assert_array_equal(ry[:n], np.log(v[expect]))


def test_map_gamma_is_the_largest_product_on_the_envelope():
    """γ of a member measured by its one-step map, taken over every visited level in one
    branch-free pass, is ``max ‖g‖e^{βt}`` over the right envelope's points on the levels
    from the cut up (:func:`decay.records`, the definition), and the latest time is that
    of the envelope: on a noisy decay with rises (points that are not on the envelope) and
    a zero norm (none), at rates below, at and above the decay's; from a cut below the
    ladder (none of it left out), and over fewer levels than the pass takes at a time."""
    import struct

    rng = np.random.default_rng(11)
    t = np.linspace(0.0, 6.0, 900)
    v = np.exp(-2.0 * t + 0.7 * rng.standard_normal(t.size))
    v[450] = 0.0
    lt, lv, base = decay.ladders(1)
    decay.ladder_clear(lt, 0)
    base[0] = decay.ladder_base(v[0])
    bits = lambda x: struct.unpack("<q", struct.pack("<d", x))[0]  # noqa: E731
    level = [min(max((bits(x) >> 49) - base[0], 0), decay.NBINS - 1) for x in v]
    for i, x in enumerate(v):
        lt[0, level[i]], lv[0, level[i]] = t[i], x
    top = max(level)
    u = np.empty(decay.NBINS)
    for lo in (-3, 0, min(level) + 40, top - 60, top - 5, top):  # runs of 8 levels, a tail
        above = {lev: i for i, lev in enumerate(level) if lev >= lo}  # last visit per level
        later_max = np.maximum.accumulate(v[::-1])[::-1]  # the largest from each sample on
        env = [i for i in above.values()
               if v[i] > 0 and (i == v.size - 1 or later_max[i + 1] < v[i])]  # fmt: skip
        for beta in (0.5, 2.0, 7.0):
            gamma, t_end = decay.onestep._map_gamma(lt, lv, 0, lo, top, beta, u)
            expect = max(v[i] * math.exp(beta * t[i]) for i in env)
            assert gamma == pytest.approx(expect, rel=1e-14), (lo, beta)
            assert t_end == max(t[i] for i in above.values())


def test_map_bins_hold_the_pairs_before_the_first_fall_below_each():
    """The one-step map's sums of bin ``b`` are those of the pairs whose first state came
    before the member's level first fell below bin ``b`` (the transient above it; their
    number exactly, since the sums of the last pairs are below the others' roundoff), also
    when the residual comes back above it (a floor's jitter): on a block of two members,
    one decaying with rises and one that jumps several bins at once, against the sums
    taken pair by pair."""
    B, ng = 2, 2

    @njit
    def run(G):  # G[k, l, j]: the residual of member j at measured state k
        S = decay.map_buffers(B, ng, 1)
        lt, lv, base = decay.ladders(B)
        Dv, P, A = np.zeros((ng, B)), np.zeros((ng, B)), np.zeros((10, B))
        gn, dn, gr = np.zeros(B), np.zeros(B), np.zeros(ng)
        low, nlev = np.zeros(B, np.int64), np.zeros(B, np.int64)
        wmax, dmax = np.full(B, -np.inf), np.full(B, -np.inf)
        active = np.ones(B, np.bool_)
        for k in range(G.shape[0]):
            Dv[:, :] = G[k]
            decay.difference_norms(Dv, gr, gn, dn)
            if k == 0:
                for j in range(B):
                    base[j] = decay.ladder_base(dn[j])
                    low[j] = decay.ladder_level(dn[j], base[j]) >> decay.MAP_SHIFT
            decay.pairs_pooled(Dv, P, A, 1.0 if k > 0 else 0.0, 1)
            changed = decay.block_levels(gn, dn, base, low, nlev, wmax, dmax)
            if changed != 0:
                decay.bin_flush(S, A, nlev, low, changed, 1, 0)
            for j in range(B):
                lt[j, nlev[j]] = float(k)
                lv[j, nlev[j]] = dn[j]
        decay.end_flush(S, A, low, active, 1, 0)
        return S, base

    rng = np.random.default_rng(2)
    K = 400
    decay_ = np.exp(-np.linspace(0.0, 40.0, K))
    decay_[300:] = decay_[299] * np.exp(3.0 * rng.standard_normal(100))  # a jittering floor
    jump = np.exp(-np.linspace(0.0, 30.0, K))
    jump[200:] *= 1e-6  # six decades at once: several bins crossed by one state
    phase = rng.uniform(0, 2 * np.pi, (K, 1))
    G = np.empty((K, ng, B))
    for j, amp in enumerate((decay_, jump)):
        G[:, 0, j] = amp * np.cos(phase[:, 0] + j)
        G[:, 1, j] = amp * np.sin(phase[:, 0] + j)
    S, base = run(G)
    bits = lambda x: np.frombuffer(np.float64(x).tobytes(), np.int64)[0]  # noqa: E731
    for j in range(B):
        norm = np.abs(G[:, :, j]).max(axis=1)
        level = np.array([min(max((bits(x) >> 49) - base[j], 0), decay.NBINS - 1) for x in norm])
        bins = level >> decay.MAP_SHIFT
        crossed = 0
        for b in range(decay.MAP_BINS):
            below = np.nonzero(bins < b)[0]
            first_below = below[0] if below.size else K
            if b <= bins[0]:
                crossed += first_below < K
            # pairs (g_k, g_k+1) with k < first_below (the last one ends below the bin)
            n = min(first_below, K - 1)
            p, q = G[:n, :, j], G[1:n + 1, :, j]
            if first_below == 0 or b > bins[0]:  # the member started below bin b: none
                p, q = p[:0], q[:0]
            expect = [p[:, 0] @ p[:, 0], p[:, 0] @ p[:, 1], p[:, 0] @ p[:, 1], p[:, 1] @ p[:, 1],
                      q[:, 0] @ p[:, 0], q[:, 0] @ p[:, 1], q[:, 1] @ p[:, 0], q[:, 1] @ p[:, 1],
                      0.0, 0.0, float(len(p))]  # fmt: skip
            np.testing.assert_allclose(S[j, b], expect, rtol=1e-12, atol=0,
                                       err_msg=f"member {j}, bin {b}")  # fmt: skip
        assert crossed >= 8  # the test crosses bins, several at once for member 1


@pytest.mark.parametrize("c0", [1.0, 0.1, -0.3])
def test_fitted_rate_of_exact_decays(c0):
    """β of exact traces ``|c0 + c1 t| e^{−βt}`` (a repeated eigenvalue's prefactor, its
    zero crossing before the window for c0 < 0), ``e^{−βt}`` and ``e^{−βt}`` times an
    oscillation, each on a floor of seeded noise: the true β within 1 %; γ the smallest
    prefactor of ``e^{−βt}`` over the transient."""
    from stabdae.engine import decay

    beta, c1 = 10.0, 10.0
    t = np.arange(4001) * 0.001  # the floor from t ≈ 2: the last fifth lies on it
    rng = np.random.default_rng(2)
    floor = 1e-9 * (1.0 + 0.5 * rng.random((3, t.size)))
    traces = np.stack([
        np.abs(c0 + c1 * t) * np.exp(-beta * t),
        np.exp(-beta * t),
        np.exp(-beta * t) * (1.2 + np.cos(15.0 * t)),
    ]) + floor  # fmt: skip
    meas = decay.measure_traces(traces, t)
    got, gamma = meas[:, decay.C_BETA], meas[:, decay.C_GAMMA]
    np.testing.assert_allclose(got, beta, rtol=0.01)
    assert meas[2, decay.C_KIND] == decay.K_OSCILLATING
    assert np.all(meas[:, decay.C_FLOOR] < 1.5e-9) and np.all(meas[:, decay.C_FLOOR] > 1e-9)
    for j in range(3):  # γ e^{−βt} bounds the trace where it lies above 1000 × its floor
        above = traces[j] > 1000 * meas[j, decay.C_FLOOR]
        assert np.all(traces[j, above] <= gamma[j] * np.exp(-got[j] * t[above]) * 1.2)
        assert np.any(traces[j, above] >= gamma[j] * np.exp(-got[j] * t[above]) / 1.2)


@pytest.mark.parametrize("c0", [1.0, 0.1, -0.3])
def test_refined_shift_gives_the_repeated_eigenvalue_rate(c0):
    """On ``|c0 + c1 t| e^{−βt}`` with a floor at 1e-13, the ``ν log(t + s)`` fit with its
    shift refined (Brent's method) recovers β to 0.2 %."""
    from stabdae.engine import decay

    t = np.arange(4001) * 0.001
    floor = 1e-13 * (1.0 + 0.5 * np.random.default_rng(2).random(t.size))
    trace = np.abs(c0 + 10.0 * t) * np.exp(-10.0 * t) + floor
    meas = decay.measure_traces(trace[None, :], t)
    assert meas[0, decay.C_KIND] == decay.K_POLYNOMIAL
    assert abs(meas[0, decay.C_BETA] / 10.0 - 1) < 0.002


def test_log_normal_is_the_library_logarithm_to_an_ulp():
    """The branch-free logarithm the fits use (so that their loops vectorize) agrees with
    the C library's to one unit in the last place over the whole normal range, and is
    exact at 1."""
    from numba import njit

    from stabdae.engine import decay

    @njit
    def logs(x, out):
        for i in range(x.shape[0]):
            out[i] = decay.log_normal(x[i])

    rng = np.random.default_rng(7)
    x = np.concatenate([np.exp(rng.uniform(-708.0, 709.0, 200_000)),
                        rng.uniform(0.5, 2.0, 200_000), 1.0 + rng.uniform(-1e-6, 1e-6, 10_000),
                        [1.0, 2.0, 0.5, np.sqrt(0.5), np.sqrt(2.0), 2.2250738585072014e-308,
                         1.7976931348623157e308]])  # fmt: skip
    got = np.empty_like(x)
    logs(x, got)
    ref = np.log(x)
    assert (got[x == 1.0] == 0.0).all()
    nz = ref != 0.0
    assert (np.abs(got - ref)[nz] <= np.spacing(np.abs(ref[nz]))).all()


@pytest.mark.parametrize("shift", [0.05, 2.0])
def test_log_prefactor_fit_recovers_an_exact_model(shift):
    """``log ‖g‖ = c − βt + ν log(t + s)`` sampled without noise: the fit at that shift
    returns its β to 1e-9 and a zero sum of squares."""
    from stabdae.engine import decay

    t = np.linspace(0.3, 1.5, 40)
    y = 0.7 - 9.5 * t + 1.0 * np.log(t + shift)
    rt, ry, a, b, lg = decay.scratch()
    rt[:40], ry[:40] = t, y
    beta, sse = decay.fit._fit_with_log(rt, ry, 0, 40, shift, a, b, lg,
                                    decay.fit._shift_free_sums(rt, ry, 0, 40))
    assert abs(beta - 9.5) < 1e-9 and sse < 1e-20


@pytest.mark.parametrize("hint", [2.0, 2.3, 1e-3, 40.0, math.nan])
def test_log_prefactor_search_from_a_hint_finds_the_grids_minimum(hint):
    """The prediction's shift search starts at the measured member's shift: from a hint
    near the true shift (2.0) it finds the exact model's β; from a hint far off (the
    minimum on its bracket's edge) it falls back to the whole grid, as with no hint."""
    from stabdae.engine import decay

    t = np.linspace(0.3, 1.5, 40)
    y = 0.7 - 9.5 * t + 1.0 * np.log(t + 2.0)
    rt, ry, a, b, lg = decay.scratch()
    rt[:40], ry[:40] = t, y
    beta, sse, shift = decay.fit._fit_polynomial(rt, ry, 0, 40, 0.03, a, b, lg, hint)
    grid = decay.fit._fit_polynomial(rt, ry, 0, 40, 0.03, a, b, lg)
    assert abs(beta - 9.5) < 1e-6 and abs(shift - 2.0) < 1e-3
    assert abs(beta - grid[0]) < 1e-6


def test_envelope_logarithms_are_the_librarys():
    """The envelope's log norms (a vectorized logarithm over the row): within an ulp of
    numpy's on normal norms; a row with a zero norm (−inf) or one below the normal floats
    takes the library's log for every point."""
    from stabdae.engine import decay

    lt, lv, _ = decay.ladders(3)
    rt, ry = np.empty(decay.NBINS), np.empty(decay.NBINS)
    k = np.arange(40)
    for j, last in enumerate([None, 0.0, 1e-310]):
        v = np.geomspace(1e3, 1e-200, 40)  # a decay: level 139 - k visited last at time k
        if last is not None:
            v[-1] = last
        lt[j, :] = -1.0
        lt[j, 139 - k] = k
        lv[j, 139 - k] = v
        n = decay.records(lt, lv, j, rt, ry)
        assert n == 40 and (rt[:n] == k).all()
        with np.errstate(divide="ignore"):
            ref = np.log(v)
        if last is None:
            assert (np.abs(ry[:n] - ref) <= np.spacing(np.abs(ref))).all()
        else:
            assert (ry[:n] == ref).all()
            assert ry[n - 1] == (-np.inf if last == 0.0 else math.log(1e-310))


def test_log_prefactor_fit_outside_the_normal_range_is_least_squares():
    """A shift that puts t + s below the normal floats (t from 0, s = 1e-310) takes the
    library's logarithm: the fit is then numpy's least squares on the same columns."""
    from stabdae.engine import decay

    t = np.linspace(0.0, 1.0, 30)
    y = 0.3 - 4.0 * t + 0.01 * np.sin(7.0 * t)
    rt, ry, a, b, lg = decay.scratch()
    rt[:30], ry[:30] = t, y
    beta, sse = decay.fit._fit_with_log(rt, ry, 0, 30, 1e-310, a, b, lg,
                                    decay.fit._shift_free_sums(rt, ry, 0, 30))
    X = np.column_stack([np.ones(30), -t, np.log(t + 1e-310)])
    coef, res = np.linalg.lstsq(X, y, rcond=None)[:2]
    assert abs(beta - coef[1]) < 1e-9 * abs(coef[1])
    assert abs(sse - res[0]) < 1e-6 * res[0]


def test_no_transient_or_growth_gives_no_rate_and_says_why():
    """A trace that sits on its floor, and one that grows, get β = NaN with their
    reasons, never a fitted number."""
    from stabdae.engine import decay

    t = np.arange(2001) * 1e-3
    flat = 1e-6 * (1.0 + 0.5 * np.random.default_rng(3).random(t.size))
    growing = 1e-6 * np.exp(3.0 * t)
    meas = decay.measure_traces(np.stack([flat, growing]), t)
    assert np.isnan(meas[:, decay.C_BETA]).all()
    assert meas[0, decay.C_REASON] == decay.R_NO_TRANSIENT
    assert meas[1, decay.C_REASON] == decay.R_NOT_DECAYING


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
    radii 1e-12 … 1e-10: none diverges; ε below the floor: floor above ε; τ past the
    spectral limit: diverged."""
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
    low = ens(stabdae.baumgarte(10, 1), 1e-3, 2.0, epsilon=1e-7)
    assert CLASSES.index("floor_above_epsilon") in low.stability_class.values
    with pytest.warns(stabdae.IntegrationWarning):
        bad = ens(stabdae.baumgarte(10, 1), 0.25, 20.0)
    assert (bad.stability_class.values == CLASSES.index("diverged")).all()
    assert float(bad.fraction_stable) == 0.0 and np.isnan(float(bad.stability_radius))


def test_wilson_and_median_intervals():
    """Wilson's 95 % interval at its textbook values (0 of 10: [0, 0.2775]; 5 of 10:
    [0.2366, 0.7634]); the median's interval at its ranks, covering the true median of
    normal samples about 95 % of the time."""
    from stabdae._measures import median_interval, wilson

    np.testing.assert_allclose(wilson(0, 10), (0.0, 0.2775), atol=5e-5)
    np.testing.assert_allclose(wilson(5, 10), (0.2366, 0.7634), atol=5e-5)
    x = np.random.default_rng(0).standard_normal(10_000)
    med, lo, hi = median_interval(x)
    v = np.sort(x)  # ranks n/2 ∓ 1.96 √n / 2 = 5000 ∓ 98
    assert (med, lo, hi) == (np.median(x), v[4902], v[5098])
    # over many samples the interval covers the true median (0) about 95 % of the time
    rng = np.random.default_rng(1)
    cover = [lo <= 0 <= hi for lo, hi in (median_interval(rng.standard_normal(400))[1:]
                                          for _ in range(2000))]  # fmt: skip
    assert 0.93 < np.mean(cover) < 0.97


def test_traces_and_states_are_optional_and_change_no_measurement():
    """traces='none', a number, 'all', and states=False: the same β, classes and
    summaries; the stored traces are those of the named members; the measurements are
    stored in single precision, the summaries computed in double."""
    model = load_scene("pendulum")
    run = lambda tr, st=True: stabdae.ensemble(model, stabdae.baumgarte(10, 1), "midpoint",  # noqa: E731
                                               1e-3, 1.0, members=40, seed=1, traces=tr,
                                               states=st)  # fmt: skip
    every, none, some, bare = run("all"), run("none"), run(7), run(7, False)
    assert none.sizes["trace"] == 0 and every.sizes["trace"] == 40 and some.sizes["trace"] == 7
    for ds in (none, some, bare):
        np.testing.assert_array_equal(ds.beta.values, every.beta.values)
        np.testing.assert_array_equal(ds.stability_class.values, every.stability_class.values)
    np.testing.assert_array_equal(some.residual_norm.values,
                                  every.residual_norm.sel(trace=some.trace).values)
    assert "x0" not in bare and "x_final" not in bare and "x_final" in some
    # the floor is the largest norm of the last fifth of the run: against the stored norms
    # there (the kernel measures every s-th step, the samples are every 50th)
    tail = every.residual_norm.sel(time=slice(0.8, None)).max("time").values
    ratio = every.residual_floor.values / tail
    assert np.all((ratio >= 1 / 1.5) & (ratio <= 1.5)), ratio
    xr.testing.assert_identical(bare, some.drop_vars(["x0", "x_final"]).assign_attrs(bare.attrs))
    for name in ("beta", "gamma", "beta_ratio", "fit_start"):
        assert every[name].dtype == np.float32, name
    for name in ("max_residual", "residual_floor", "overshoot", "alpha0", "alpha0_norm",
                 "beta_median"):
        assert every[name].dtype == np.float64, name
    assert every.fit_points.dtype == np.int32 and every.diverged_step.dtype == np.int32
    # the median of the double-precision rates, not of their single-precision copies
    assert float(every.beta_median) != float(np.median(every.beta.values.astype(float)))
    with pytest.raises(ValueError, match="ensemble: traces must be"):
        run("some")
    with pytest.raises(TypeError, match=r"ensemble: states must be True or False, got 'no'"):
        run(7, "no")


@njit
def _mass_swing(t, q, p, out):
    """SPD only while q0 > −1/2: the members below stop when their swing gets there."""
    out[0, 0] = 1.0
    out[0, 1] = 0.0
    out[1, 0] = 0.0
    out[1, 1] = q[0] + 0.5


def test_members_stopped_by_a_status_keep_their_last_good_state():
    """A step that fails with a status (mass not SPD) leaves finite numbers, which the
    block's check after 32 steps or at a sample still sees: each member stops at its own
    step, keeps the state before it and reports the status, as ``integrate`` does."""
    from toy import unit_pendulum

    model = unit_pendulum("swing_mass", mass=_mass_swing)
    x0 = np.array([[0.0, -1.0, -v, 0.0] for v in (2.0, 2.5, 3.0, 3.5, 4.0)])
    law = stabdae.baumgarte(10.0)
    ds = stabdae.ensemble(model, law, "rk4", 1e-3, 1.0, x0=x0, save_dt=0.1)
    steps = ds.diverged_step.values
    assert (ds.status.values == stabdae.Status.MASS_NOT_SPD).all()
    assert len(set(steps.tolist())) == 5 and (steps % CHECKPOINT > 1).any(), steps
    for j in range(5):
        with pytest.warns(stabdae.IntegrationWarning, match="not symmetric positive"):
            one = stabdae.integrate(model, x0[j], law, "rk4", 1e-3, 1.0, 1e-3)
        assert one.attrs["steps_completed"] == steps[j]
        np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[steps[j]])


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
    from affine import model as affine

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
    1e-5 (the map fitted to them is R^s, whose radius is ρ(R)^s), the floor and the
    largest norm within the stride's resolution (a change of 0.2 in ln: a maximum read at
    most 0.2²/8 = 0.5 % low), γ within 2 %."""
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
    np.testing.assert_allclose(strided.beta.values, every.beta.values, rtol=1e-5)
    # γ: the largest ‖g‖e^{βt} on the transient, for a Jordan block |c0 + c1 t| at the
    # transient's end, which a stride moves by up to one stride (2 % of the window here)
    np.testing.assert_allclose(strided.gamma.values, every.gamma.values, rtol=0.02)
    for name in ("residual_floor", "max_residual"):
        np.testing.assert_allclose(strided[name].values, every[name].values, rtol=0.005,
                                   err_msg=name)  # fmt: skip
    for name in ("residual_floor", "max_residual"):  # maxima over a subset of the states
        assert (strided[name].values <= every[name].values).all(), name


def test_map_window_of_a_member_still_decaying_ends_at_the_run_end():
    """A member whose residual still falls when the run ends (ω = 10 over 2 s: no floor
    yet) has the whole run as its map's window: ``fit_end`` is the final time, whose
    state is on the ladder though the stride does not measure it (s = 20 ends at step
    1980), and γ covers it."""
    model = load_scene("pendulum")
    ds = stabdae.ensemble(model, stabdae.baumgarte(10, 1), "midpoint", 1e-3, 2.0,
                          members=256, radius=(1e-6, 1e-2), seed=5, traces="none")  # fmt: skip
    still = ds.floor_reached.values == 0
    assert ds.attrs["measure_every"] == 20 and still.sum() > 200
    assert set(ds.fit_kind.values[still].tolist()) == {decay.K_MAP}
    np.testing.assert_array_equal(ds.fit_end.values[still], 2.0)


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
    assert got == pytest.approx(u * np.median(each), rel=1e-6)
    assert calls == [5 * 9, 5]  # the differences of every state, then the time shifts
    for i in range(5):
        assert _measures.roundoff_level(rows, X[i : i + 1], 0.7) == pytest.approx(
            u * each[i], rel=1e-6)
    assert _measures.roundoff_level(rows, X[:0], 0.7) == 0.0


def test_residual_rows_by_the_sampler_are_those_of_their_kernel():
    """An ensemble that sampled its members evaluates the roundoff level's residual rows
    with the sampler it has compiled (placing skipped): the same numbers, bit for bit, as
    the kernel for residual rows, at a time of its own (a time-dependent model), through
    a non-finite row, on more rows than one chunk, and the caller's states untouched."""
    from stabdae import _ensemble

    model = load_scene("pendulum_varying_length")
    p = model.param_vector(None)
    X = np.random.default_rng(4).normal(size=(150, 2 * model.n))
    X[7, 1] = np.nan
    before = X.copy()
    by_kernel = _ensemble._residual_rows(model, X, p, 0.37)
    by_sampler = _ensemble._residual_rows(model, X, p, 0.37, sampler=True)
    np.testing.assert_array_equal(by_sampler, by_kernel)
    assert np.isnan(by_sampler[7]).any() and np.isfinite(np.delete(by_sampler, 7, 0)).all()
    np.testing.assert_array_equal(X, before)
    assert not np.array_equal(by_kernel, _ensemble._residual_rows(model, X, p, 0.0))
