"""Adaptive ensembles: members on lanes with their own steps, bit-identical to
integrate_adaptive, refilled lanes, divergence isolated, errors."""

from __future__ import annotations

import numpy as np
import pytest

import stabdae
from conftest import load_scene
from stabdae.engine import decay


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
                                         atol=1e-10, save_dt=2.0, first_step=1e-3)  # fmt: skip
        assert one.attrs["method"] == pair and one.attrs["steps_accepted"] == steps[j]
        assert one.attrs["rhs_evaluations"] == ds.rhs_evaluations.values[j]
        np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[-1])
        np.testing.assert_array_equal(ds.residual_norm.values[j, [0, -1]],
                                      one.residual_norm.values)  # fmt: skip


@pytest.mark.parametrize("pair", ["dopri5", "dop853"])
def test_lanes_attempt_and_adaptive_loop_agree_bit_for_bit(pair):
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
                                         atol=1e-10, save_dt=2.0, first_step=1e-3)  # fmt: skip
        assert one.attrs["steps_accepted"] == ds.steps_accepted.values[j]
        assert one.attrs["rhs_evaluations"] == ds.rhs_evaluations.values[j]
        np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[-1])
        np.testing.assert_array_equal(ds.residual_norm.values[j, [0, -1]],
                                      one.residual_norm.values)  # fmt: skip
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


def test_adaptive_samples_change_no_step():
    """The steps are not cut to the sample times: with ``save_dt`` left out, 0.01 and
    0.001 every member takes the same steps and every measure has the same bits.  The
    stored samples are the residual of the dense output between the steps: within 0.5 % of the
    residual of states integrated to the sample times (``integrate_adaptive``, whose steps
    end there) wherever it lies far above the floor, or within the two runs' own
    integration errors (the smallest member, ‖α⁰‖ = 1e-4, differs by 1.2e-6 at 1.1e-4)."""
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    radius = (1e-4, 1e-2)
    kw = dict(tau=1e-3, t_end=2.0, members=16, radius=radius, seed=1, rtol=1e-8,
              residual_dtype="float64", traces="all")  # fmt: skip
    runs = [stabdae.ensemble(model, law, "dopri5", save_dt=dt, **kw)
            for dt in (None, 0.01, 0.001)]  # fmt: skip
    assert [r.sizes["time"] for r in runs] == [201, 201, 2001]
    for name in ("beta", "beta_reason", "verdict", "residual_floor", "max_residual",
                 "steps_accepted", "rhs_evaluations", "x_final", "beta_median"):  # fmt: skip
        for other in runs[1:]:
            np.testing.assert_array_equal(runs[0][name].values, other[name].values, name)
    # every member's β is the law's rate (ξ = 1: a double eigenvalue, ω = 10)
    assert (runs[0].beta_reason.values == decay.R_FITTED).all()
    np.testing.assert_allclose(runs[0].beta.values, 10.0, rtol=0.01)
    ds = runs[2]
    x0, _, _ = stabdae.sample_perturbations(model, 16, radius, seed=1)
    for j in range(4):
        one = stabdae.integrate_adaptive(model, x0[j], law, 2.0, scheme="dopri5", rtol=1e-8,
                                         atol=1e-8, save_dt=0.001, first_step=1e-3)  # fmt: skip
        ref, got = one.residual_norm.values, ds.residual_norm.values[j]
        far = ref > 1e3 * float(ds.residual_floor[j])
        assert far.sum() >= 100, far.sum()
        # beside the interpolation: the two runs' own errors (different steps), each up to
        # rtol per accepted step on states of size 1, seen in g through ‖∂g/∂x‖ ≤ 2|x| ≈ 2
        # (the unit pendulum's ḟ = 2 q·v)
        own = 4.0 * 1e-8 * int(ds.steps_accepted[j])
        np.testing.assert_allclose(got[far], ref[far], rtol=5e-3, atol=own)


@pytest.mark.parametrize("pair, xi, rtol, share", [("dopri5", 0.5, 1e-8, 0.99),
                                                   ("dopri5", 1.0, 1e-8, 0.99),
                                                   ("dop853", 1.0, 1e-8, 0.99),
                                                   ("dop853", 2.0, 1e-8, 0.99),
                                                   ("dopri5", 1.0, 1e-6, 0.95)])  # fmt: skip
def test_adaptive_member_rates_down_to_their_floor(pair, xi, rtol, share):
    """Each member's β from the generator fitted to its accepted steps, on its distance
    from the reference trajectory's residual, against the law's rate: at rtol = 1e-8,
    99 % of the members 10× above their floor (α⁰ from 1e-8 to 1e-1) within 1 %, and
    every β given within 1 % (read from the raw residual's envelope, 39 % were, and the
    fits were off by up to 18 %).  At rtol = 1e-6 a few members have fewer than a dozen
    steps above their floor: they get no β rather than one from a handful of pairs (one
    of 8 pairs was 1.75 % off), and a member that starts below the reference's floor
    gets none (one read half the rate)."""
    ds = stabdae.ensemble(load_scene("pendulum"), stabdae.baumgarte(10.0, xi), pair, 1e-3,
                          5.0, rtol=rtol, members=256, seed=1, radius=(1e-8, 1e-1),
                          traces="none", states=False)  # fmt: skip
    ratio = ds.beta_ratio.values.astype(float)
    above = ds.alpha0_norm.values >= 10.0 * ds.residual_floor.values
    assert above.sum() >= 120, above.sum()
    assert np.mean(np.abs(ratio[above] - 1.0) <= 0.01) >= share
    given = np.isfinite(ratio)
    np.testing.assert_allclose(ratio[given], 1.0, atol=0.01)
    assert (ds.beta_predicted.values[given] == float(ds.beta_theory)).all()


def test_adaptive_reference_records_every_accepted_step():
    """The reference trajectory an adaptive ensemble measures its members against: a row
    ``(t, g)`` at its start and at each of its accepted steps, times increasing to
    ``t_end``, the first and last rows its residuals at the ends; per fifth of the run
    its largest residual is what the reference member's own measurement gives (the
    floor band of the verdicts)."""
    from stabdae import _ensemble

    model = load_scene("pendulum")
    run = _ensemble._run_spec("ensemble", model, stabdae.baumgarte(10.0, 2.0), "dopri5", 1e-3,
                              2.0, 1e-8, None, 8, (1e-6, 1e-2), 1, None, None, None, None,
                              None, None, None, None, "float64", "none", True)  # fmt: skip
    table = run.mode.reference(run)
    t = table[:, 0]
    assert t[0] == 0.0 and t[-1] == 2.0 and (np.diff(t) > 0).all()
    one = stabdae.integrate_adaptive(model, model.reference_state(), stabdae.baumgarte(10.0, 2.0),
                                     2.0, scheme="dopri5", rtol=1e-8, atol=1e-8, save_dt=2.0,
                                     first_step=1e-3)  # fmt: skip
    assert table.shape == (one.attrs["steps_accepted"] + 1, 1 + model.n_residual)
    np.testing.assert_array_equal(np.abs(table[[0, -1], 1:]).max(axis=1),
                                  one.residual_norm.values)
    referee = _ensemble._referee(run, table)
    band, motion = _ensemble._reference_floor(run)
    np.testing.assert_array_equal(referee["floor_band"], band)
    # the same run, read from its rows or from its fifths: within ε, ran to the end
    assert not referee["motion"].unstable and referee["motion"] == motion


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


@pytest.mark.parametrize("pair, stages", [("dopri5", 7), ("dop853", 13)])
def test_adaptive_counts_in_closed_form_at_every_stop(pair, stages):
    """The counts ``integrate_adaptive`` reports on every way out of its loop: stopped by
    ``max_steps``, accepted plus rejected steps are ``max_steps`` and the right-hand side
    was evaluated once at the start, once for the first step's estimate and ``s − 1``
    times per step tried (first same as last); stopped at the start (a singular ``S``),
    no step and the one evaluation that failed."""
    import warnings

    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stabdae.IntegrationWarning)
        for cap in (1, 2, 9):
            ds = stabdae.integrate_adaptive(model, None, law, 2.0, scheme=pair, rtol=1e-10,
                                            atol=1e-12, max_steps=cap)  # fmt: skip
            tried = ds.attrs["steps_accepted"] + ds.attrs["steps_rejected"]
            assert int(ds.attrs["status"]) == stabdae.Status.MAX_STEPS and tried == cap
            assert ds.attrs["rhs_evaluations"] == 2 + (stages - 1) * cap
        ds = stabdae.integrate_adaptive(model, np.array([0.0, 0.0, 0.1, 0.0]), law, 2.0,
                                        scheme=pair, rtol=1e-8)  # fmt: skip
    assert int(ds.attrs["status"]) == stabdae.Status.SINGULAR_S
    assert (ds.attrs["steps_accepted"], ds.attrs["steps_rejected"],
            ds.attrs["rhs_evaluations"]) == (0, 0, 1)  # fmt: skip


def test_adaptive_ensemble_errors():
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0)
    with pytest.raises(ValueError, match=r"^ensemble: adaptive steps need an embedded pair, "
                       r"'dopri5' \(Dormand–Prince 5\(4\)\) or 'dop853' .*; got 'rk4'"):
        stabdae.ensemble(model, law, "rk4", 1e-3, 0.1, members=4, rtol=1e-6)
    with pytest.raises(ValueError, match="^ensemble: atol is for adaptive steps; give rtol"):
        stabdae.ensemble(model, law, "rk4", 1e-3, 0.1, members=4, atol=1e-6)


def test_atol_per_state_component():
    """``atol`` one per component of ``x = (q, v)``, as SciPy's ``solve_ivp`` takes it:
    every entry alike gives the numbers of the one number bit for bit (the error norm is
    the same sum), in ``integrate_adaptive`` and in an adaptive ensemble; a looser
    ``atol`` on the velocities alone takes fewer steps than the same tight one on all;
    a wrong shape, or a component not positive and finite, is refused naming the
    function, the shape expected and the components."""
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    one = stabdae.integrate_adaptive(model, None, law, 1.0, rtol=1e-8, atol=1e-10)
    alike = stabdae.integrate_adaptive(model, None, law, 1.0, rtol=1e-8, atol=np.full(4, 1e-10))
    np.testing.assert_array_equal(one.x.values, alike.x.values)
    assert one.attrs["steps_accepted"] == alike.attrs["steps_accepted"]
    loose = stabdae.integrate_adaptive(model, None, law, 1.0, rtol=1e-12,
                                       atol=[1e-14, 1e-14, 1e-6, 1e-6])  # fmt: skip
    tight = stabdae.integrate_adaptive(model, None, law, 1.0, rtol=1e-12, atol=1e-14)
    assert loose.attrs["steps_accepted"] < tight.attrs["steps_accepted"]
    np.testing.assert_array_equal(loose.attrs["atol"], [1e-14, 1e-14, 1e-6, 1e-6])
    kw = dict(tau=1e-3, t_end=0.5, members=6, seed=2, rtol=1e-8)
    ens = stabdae.ensemble(model, law, "dopri5", atol=1e-10, **kw)
    ens_alike = stabdae.ensemble(model, law, "dopri5", atol=np.full(4, 1e-10), **kw)
    for name in ("x_final", "steps_accepted", "beta", "residual_norm"):
        np.testing.assert_array_equal(ens[name].values, ens_alike[name].values)
    assert ens_alike.attrs["atol"] == 1e-10
    with pytest.raises(ValueError, match=r"^integrate_adaptive: atol must be a number or one "
                                         r"per state component, shape \(2n,\) = \(4,\); got "
                                         r"shape \(3,\)"):
        stabdae.integrate_adaptive(model, None, law, 1.0, atol=np.ones(3))
    with pytest.raises(ValueError, match=r"^ensemble: atol must be positive and finite in "
                                         r"every component; components \[1, 3\] are "
                                         r"\[0.0, nan\]"):
        stabdae.ensemble(model, law, "dopri5", atol=[1e-9, 0.0, 1e-9, np.nan], **kw)


def test_atol_from_the_models_scales():
    """``Model(..., scales=...)`` declares each state component's size (or each
    coordinate's, the velocities alike per second); ``atol="scales"`` is then ``rtol``
    times them, bit for bit the explicit vector, in ``integrate_adaptive`` and the
    adaptive ensemble.  Without declared scales, or with another string, it is refused;
    scales of the wrong shape or not positive are refused by the model, by name."""
    base = load_scene("pendulum")
    model = base.replace(scales=[1.0, 1.0, 3.0, 3.0])
    np.testing.assert_array_equal(base.replace(scales=[2.0, 0.5]).scales, [2.0, 0.5, 2.0, 0.5])
    law = stabdae.baumgarte(10.0, 1.0)
    vector = 1e-8 * np.array([1.0, 1.0, 3.0, 3.0])
    by_scales = stabdae.integrate_adaptive(model, None, law, 1.0, rtol=1e-8, atol="scales")
    explicit = stabdae.integrate_adaptive(model, None, law, 1.0, rtol=1e-8, atol=vector)
    np.testing.assert_array_equal(by_scales.x.values, explicit.x.values)
    np.testing.assert_array_equal(by_scales.attrs["atol"], vector)
    kw = dict(tau=1e-3, t_end=0.5, members=6, seed=2, rtol=1e-8)
    a = stabdae.ensemble(model, law, "dopri5", atol="scales", **kw)
    b = stabdae.ensemble(model, law, "dopri5", atol=vector, **kw)
    np.testing.assert_array_equal(a.x_final.values, b.x_final.values)
    with pytest.raises(ValueError, match=r"^integrate_adaptive: atol='scales' takes rtol times "
                                         r"the model's scales, and the model declares none"):
        stabdae.integrate_adaptive(base, None, law, 1.0, atol="scales")
    with pytest.raises(ValueError, match=r"^ensemble: atol must be a number, one per state "
                                         r"component, or 'scales'; got 'scale'"):
        stabdae.ensemble(model, law, "dopri5", atol="scale", **kw)
    with pytest.raises(stabdae.ModelError, match=r"scales must have shape \(2n,\) = \(4,\) or "
                                                 r"\(n,\) = \(2,\); got \(3,\)"):
        base.replace(scales=[1.0, 1.0, 1.0])
    with pytest.raises(stabdae.ModelError, match=r"scales must be positive and finite; y, "
                                                 r"y_dot are \[0.0, 0.0\]"):
        base.replace(scales=[1.0, 0.0])
