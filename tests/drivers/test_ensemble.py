"""Ensembles: members equal to single integrations bit for bit for any block, thread
count and tableau pattern, divergence isolated, stopped members, the dataset and its
NetCDF round trip, optional traces and states."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import warnings
from dataclasses import replace

import numpy as np
import pytest
import xarray as xr
from numba import njit

import stabdae
from conftest import ROOT, assert_schema, baumgarte_ensemble, load_scene
from stabdae._schema import write_netcdf
from stabdae.engine.ensemble.block import CHECKPOINT
from stabdae.engine.fma import HOST_FMA


def test_block_step_and_looped_step_agree_bit_for_bit():
    model = load_scene("double_pendulum")
    law = stabdae.baumgarte(20.0, 1.0)
    ds = stabdae.ensemble(model, law, "heun", 1e-3, 0.5, members=5, seed=2, save_dt=0.05)
    for j in range(5):
        one = stabdae.integrate(model, ds.x0.values[j], law, "heun", 1e-3, 0.5, 0.05)
        np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[-1])
        np.testing.assert_array_equal(ds.residual_norm.values[j],
                                      one.residual_norm.values.astype(np.float32))  # fmt: skip


@pytest.mark.parametrize("scheme, tau, t_end", [("rk4", 1e-3, 0.2), ("midpoint", 0.025, 4.0)])
def test_block_size_does_not_change_any_number(scheme, tau, t_end):
    """Blocks of 16 members or 64: every variable the same bits.  Members of one slot of
    a block follow each other in it, whose ladder each member's start clears from the
    lowest level the one before reached; at the longer step a member's distance from the
    reference falls past several levels at a step, down to roundoff (a level left from
    the member before would be read as its own)."""
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0)
    runs = [stabdae.ensemble(model, law, scheme, tau, t_end, members=137, seed=4, block=b,
                             threads=1)
            for b in (16, 64)]  # fmt: skip
    for other in runs[1:]:
        assert set(other.data_vars) == set(runs[0].data_vars)
        for name in runs[0].data_vars:
            np.testing.assert_array_equal(runs[0][name].values, other[name].values, name)


_WIDTH_SCRIPT = """
import json, sys, numpy as np, numba, stabdae
model = stabdae.load_model(sys.argv[1])
ds = stabdae.ensemble(model, stabdae.baumgarte(10.0), "midpoint", 1e-3, 0.3,
                      members=300, seed=9, block=16)
print(json.dumps({"wide": ds.attrs["prefer_512_bit_vectors"],
                  "features": numba.config.CPU_FEATURES or "",
                  "x": ds.x_final.values.tobytes().hex(),
                  "r": ds.residual_norm.values.tobytes().hex()}))
"""


def test_thread_count_and_vector_width_do_not_change_any_number():
    """One thread or two, 512-bit SIMD vectors (where the CPU has AVX-512) or the
    compiler's default width: the same bits.  The thread counts run in this process (the
    kernel's thread count is an argument); the vector width is fixed when a process
    first compiles, so the default width runs in a fresh one."""
    import numba
    from numba.core.codegen import get_host_cpu_features

    model = load_scene("pendulum")
    kw = dict(members=300, seed=9, block=16)
    law = stabdae.baumgarte(10.0)
    runs = {t: stabdae.ensemble(model, law, "midpoint", 1e-3, 0.3, threads=t, **kw)
            for t in sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)})}  # fmt: skip
    here = runs[max(runs)]
    assert [int(ds.attrs["threads"]) for ds in runs.values()] == sorted(runs)
    env = {k: v for k, v in os.environ.items()
           if k not in ("STABDAE_VECTOR_WIDTH", "NUMBA_CPU_FEATURES", "NUMBA_CPU_NAME")}
    env["STABDAE_VECTOR_WIDTH"] = "256"
    proc = subprocess.run([sys.executable, "-c", _WIDTH_SCRIPT,
                           str(ROOT / "kernels" / "pendulum.py")], capture_output=True,
                          text=True, env=env, check=True)  # fmt: skip
    narrow = json.loads(proc.stdout.strip().splitlines()[-1])
    avx512 = "+avx512f" in get_host_cpu_features().split(",")
    wide_here = ("-prefer-256-bit" in (numba.config.CPU_FEATURES or ""))
    assert here.attrs["prefer_512_bit_vectors"] == int(wide_here) and narrow["wide"] == 0
    assert "-prefer-256-bit" not in narrow["features"]
    if "STABDAE_VECTOR_WIDTH" not in os.environ and "NUMBA_CPU_FEATURES" not in os.environ:
        assert wide_here == avx512  # this process chose the width as a user's would
    for ds in runs.values():
        assert ds.x_final.values.tobytes().hex() == narrow["x"]
        assert ds.residual_norm.values.tobytes().hex() == narrow["r"]


def test_vector_width_is_chosen_only_where_numba_leaves_it_open(monkeypatch):
    from numba import config
    from numba.core.codegen import get_host_cpu_features

    from stabdae.engine import vector_width as _vector_width

    monkeypatch.setattr(config, "CPU_FEATURES", None)
    # this process has compiled: numba's features are fixed, nothing may change them
    assert _vector_width.choose({}) is False and config.CPU_FEATURES is None
    # a user's own features stand (here in a fresh process, where the choice is open)
    host = get_host_cpu_features()
    env = dict(os.environ, NUMBA_CPU_FEATURES=host)
    env.pop("STABDAE_VECTOR_WIDTH", None)
    proc = subprocess.run([sys.executable, "-c", "import numba, stabdae.engine as e; "
                           "print(e.vector_width.PREFER_512, numba.config.CPU_FEATURES)"],
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
    with stabdae.open_dataset(path) as back:
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


def _scheme(spec):
    if isinstance(spec, str):
        return spec
    with warnings.catch_warnings():  # σ = 0 and σ = 2 are first order, and say so
        warnings.simplefilter("ignore", UserWarning)
        return stabdae.two_stage(*spec)


@pytest.fixture(params=["written out", "by stage"])
def step_form(request, monkeypatch):
    """Both forms of the ensemble kernel's block step on the same small model: each
    member's stages written out (the pendulum's own) and stage by stage (the form of
    larger models under schemes of three stages or more, forced here)."""
    from stabdae.engine.ensemble import block

    if request.param == "by stage":
        monkeypatch.setattr(block, "STAGE_LOOP_MIN_N", 0)
        monkeypatch.setattr(block, "STAGE_LOOP_MIN_STAGES", 0)
    return request.param


def test_two_stage_schemes_step_stage_by_stage_where_the_right_hand_side_is_large():
    """A two-stage scheme steps the block stage by stage where the right-hand side's
    straight-line code is large (the bicycle's: its midpoint kernel compiles in a fraction
    of the time, and integrates as fast), and with its stages written out where it is
    small (the N-four-bar's, which integrates 21 % faster so); three or more stages go
    stage by stage on both, one stage on neither.  No kernel is compiled here."""
    from stabdae._laws import bind_law
    from stabdae._schemes import as_scheme
    from stabdae.engine.ensemble import block
    from stabdae.engine.rhs import kernels_for

    forms = {}
    for name in ("bicycle", "n_four_bar"):
        model = load_scene(name)
        bound = bind_law(stabdae.baumgarte(10.0, 1.0, 10.0 if model.k else None), model)
        assert model.n >= block.STAGE_LOOP_MIN_N
        forms[name] = (kernels_for(model, bound).size,
                       [block.ensemble_kernel_for(model, bound, as_scheme(s)).block_step.__name__
                        for s in ("euler", "midpoint", "rk4")])  # fmt: skip
    assert forms["bicycle"][0] >= block.STAGE_LOOP_MIN_SIZE > forms["n_four_bar"][0] > 0
    assert forms["bicycle"][1] == ["member_loop_step", "block_step", "block_step"]
    assert forms["n_four_bar"][1] == ["member_loop_step", "member_loop_step", "block_step"]


@pytest.mark.parametrize("spec", ["euler", "midpoint", "rk4", "dop853", (0.3, 0.0), (0.25, 2.0)])
def test_block_step_and_looped_step_agree_for_every_tableau_pattern(spec, step_form):
    """The ensemble kernel's step, with each member's stages written out for the pattern
    of the coefficients or stage by stage (zero coefficients skipped at run time): its
    numbers are those of ``integrate`` bit for bit
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


def test_a_tableau_of_many_stages_runs_bit_for_bit(step_form):
    """A tableau of 40 stages (written out per stage it compiled for 14 minutes: above
    ``WRITTEN_MAX_STAGES`` a member's stages are looped, and stage by stage the block's
    are): the numbers are still ``integrate``'s bit for bit, with zeros, ones and other
    values in A and b (skipped, exact, fused)."""
    from stabdae._schemes import from_tableau, tableau_order
    from stabdae.engine.rk.steps import WRITTEN_MAX_STAGES

    s = 40
    assert s > WRITTEN_MAX_STAGES
    rng = np.random.default_rng(3)
    A = np.tril(rng.uniform(0.0, 0.05, (s, s)), -1)
    A[rng.random((s, s)) < 0.3] = 0.0
    A = np.tril(A, -1)
    A[5, 2] = 1.0
    b = rng.uniform(0.5, 1.0, s)
    b[[3, 17]] = 0.0
    b /= b.sum()
    tableau = {"A": A, "b": b, "c": A.sum(axis=1), "name": "many_stages",
               "order": tableau_order(A, b)}
    scheme = from_tableau(tableau)
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    ds = stabdae.ensemble(model, law, scheme, 2e-3, 0.1, members=3, seed=5, save_dt=0.02)
    assert (ds.status.values == 0).all()
    for j in range(3):
        one = stabdae.integrate(model, ds.x0.values[j], law, scheme, 2e-3, 0.1, 0.02)
        np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[-1])
        np.testing.assert_array_equal(ds.residual_norm.values[j],
                                      one.residual_norm.values.astype(np.float32))  # fmt: skip


@pytest.mark.parametrize("spec", ["rk4", "dopri5"])
def test_block_step_and_looped_step_agree_on_stage_times(spec, step_form):
    """On time-dependent constraints (the pendulum of prescribed length) the
    stage times t + c·τ matter: the ensemble kernel's block step gives the numbers of
    ``integrate`` bit for bit.  The stage times are formed alike for every pattern of
    coefficients (the patterns themselves are covered on the pendulum above); RK4 repeats
    a stage time, dopri5 has seven distinct ones and zeros inside A."""
    scheme = _scheme(spec)
    for name, law, tau in [("pendulum_varying_length", stabdae.baumgarte(10.0, 1.0), 2e-3)]:
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


def test_a_reference_over_the_size_cap_is_left_out_and_the_raw_residual_measured(
        monkeypatch):  # fmt: skip
    """Above ``REFERENCE_MAX_ENTRIES`` numbers (steps × components) the reference is not
    kept: no rows, and each member's decay is read on its raw residual.  On the affine
    system, whose reference residual is zero to roundoff, the rates are those measured
    against the reference."""
    from models.affine import model as affine
    from stabdae import _ensemble
    from stabdae._laws import bind_law

    law = stabdae.matrix([[-100.0, -20.0, 0.0], [0.0, 0.0, -10.0]])
    p, tau, nsteps = affine.param_vector(), 0.01, 300
    size = (nsteps + 1) * affine.n_residual
    for cap, rows in ((size, nsteps + 1), (size - 1, 0)):
        monkeypatch.setattr(_ensemble, "REFERENCE_MAX_ENTRIES", cap)
        g = _ensemble._reference_residuals(affine, bind_law(law, affine), stabdae.euler(), p,
                                           affine.t0, tau, nsteps)  # fmt: skip
        assert g.shape == (rows, affine.n_residual)
    kw = dict(members=16, seed=3, radius=(1e-4, 1e-2))
    raw = stabdae.ensemble(affine, law, "euler", tau, nsteps * tau, **kw)
    monkeypatch.setattr(_ensemble, "REFERENCE_MAX_ENTRIES", 10**9)
    ref = stabdae.ensemble(affine, law, "euler", tau, nsteps * tau, **kw)
    assert np.isfinite(ref.beta.values).all()
    np.testing.assert_allclose(raw.beta.values, ref.beta.values, rtol=1e-6)
    assert (raw.verdict.values == ref.verdict.values).all()


def test_members_stopped_mid_run_keep_their_last_good_state():
    """Euler at τ = 0.25 with ω = 10 is unstable: every member grows until it stops, at a
    step of its own, so the block loses its members one by one and ends with none running.
    A member stopped at a stored sample (residual above the threshold) keeps that state;
    one whose step overflowed keeps the state before that step.  Both equal ``integrate``
    run up to that step, bit for bit; and a member stopped at a stored sample keeps the
    largest residual norm of the states measured before it (every step's here), those
    of the fifth of the run it stopped in included."""
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    tau = 0.25
    x0, _, _ = stabdae.sample_perturbations(model, 5, (1e-3, 1e-1), seed=3)
    threshold = {stabdae.Status.DIVERGED: 1e250, stabdae.Status.NONFINITE_STATE: 1e300}
    runs = {
        stabdae.Status.DIVERGED: stabdae.ensemble(
            model, law, "euler", tau, 250.0, x0=x0, save_dt=tau, epsilon=1.0, divergence=1e250
        ),
        stabdae.Status.NONFINITE_STATE: stabdae.ensemble(
            model, law, "euler", tau, 250.0, x0=x0, save_dt=250.0, epsilon=1.0, divergence=1e300
        ),
    }
    for status, ds in runs.items():
        # integrate under the ensemble's threshold: its own default would stop earlier
        level = threshold[status]
        assert (ds.status.values == status).all(), status
        steps = ds.diverged_step.values
        assert len(set(steps.tolist())) > 1 and (steps > 0).all()
        if status == stabdae.Status.NONFINITE_STATE:  # the block was rolled back
            assert ((steps > CHECKPOINT) & (steps % CHECKPOINT > 1)).any(), steps
        for j in range(5):
            span = steps[j] * tau
            one = stabdae.integrate(model, x0[j], law, "euler", tau, span, span,
                                    divergence=level)  # fmt: skip
            np.testing.assert_array_equal(ds.x_final.values[j], one.x.values[-1])
            # the stored samples up to the stop are the trajectory's, NaN after it
            every = round(float(ds.attrs["save_dt"]) / tau)
            full = stabdae.integrate(model, x0[j], law, "euler", tau, span, tau,
                                     divergence=level)  # fmt: skip
            ref = full.residual_norm.values[::every].astype(np.float32)
            row = ds.residual_norm.values[j]
            np.testing.assert_array_equal(row[: len(ref)], ref)
            assert np.isnan(row[len(ref):]).all()
            if status == stabdae.Status.DIVERGED:  # (the last state is the one not measured)
                np.testing.assert_allclose(ds.max_residual.values[j],
                                           full.residual_norm.values[:-1].max(), rtol=1e-12)


@pytest.mark.parametrize(("members", "divergence"), [(64, None), (70, None), (20, 1e-30)])
def test_reference_floor_read_beside_the_members_is_its_run_alone(members, divergence):
    """An ensemble given ``x0`` has no reference residuals: its verdicts' floor band is
    the reference state's own run, which runs as one more member of the members' kernel
    call.  The band must be that of its run alone bit for bit, the members' outputs
    those of their run without it, and progress must count the user's members only (64:
    the extra member opens a block of its own).  Where that member stops (a divergence
    threshold below every residual), the band comes from its run alone, without the
    threshold, as before."""
    from stabdae import _ensemble as E

    model = load_scene("pendulum")
    x0, _, _ = stabdae.sample_perturbations(model, members, (1e-6, 1e-2), seed=4)
    seen = []
    run = E._run_spec("ensemble", model, stabdae.baumgarte(10.0, 1.0), "midpoint", 1e-3, 0.5,
                      None, None, members, (1e-6, 1e-2), 0, 0.05, x0, None, None, divergence,
                      None, None, lambda done, total: seen.append((done, total)), "float32",
                      3, True)  # fmt: skip
    x0, alpha0, status, g_ref = E._members(run, x0)
    assert g_ref.shape[0] == 0
    out, band, motion = E._integrate(run, x0, alpha0, status, g_ref)
    alone, alone_motion = E._reference_floor(run)
    if divergence is None:
        assert band is not None and (band > 0).all()
        np.testing.assert_array_equal(band, alone)
        assert motion == alone_motion and not motion.unstable
    else:
        assert band is None and motion is None and (out.status != 0).all()
    referee = E._referee(run, g_ref, band, motion)
    np.testing.assert_array_equal(referee["floor_band"], alone)
    assert referee["motion"] == alone_motion
    plain = run.mode.integrate(replace(run, progress=None), x0, alpha0, status, g_ref)
    for name in plain._fields:
        np.testing.assert_array_equal(getattr(out, name), getattr(plain, name), err_msg=name)
    assert seen and all(total == members and done <= members for done, total in seen)
    assert seen[-1][0] == members


@pytest.mark.parametrize("members", [1, 2, 7, 40, 10_000])
def test_traced_members_are_evenly_spaced_and_distinct(members):
    """The traced members for each count (none, one, a few, all but one, all, more than
    all): the rounded points of ``linspace(0, members − 1, count)``, each once (NumPy's
    ``unique`` of them), and each trace row the member's place among them."""
    from stabdae._ensemble import _trace_rows

    for traces in (0, 1, 2, 3, members - 1, members, members + 5, "all", "none"):
        count = min({"all": members, "none": 0}.get(traces, traces), members)
        row, traced = _trace_rows(traces, members, "ensemble")
        expect = np.unique(np.linspace(0, members - 1, count).round().astype(np.int64))
        np.testing.assert_array_equal(traced, expect)
        assert traced.dtype == np.int64
        np.testing.assert_array_equal(row[traced], np.arange(traced.size))
        assert (np.delete(row, traced) == -1).all()


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
    for name in ("beta", "beta_ratio", "fit_start"):
        assert every[name].dtype == np.float32, name
    # γ = max ‖g‖ e^{βt} can pass float32's range (a member that starts near its floor)
    for name in ("gamma", "max_residual", "residual_floor", "overshoot", "alpha0",
                 "alpha0_norm", "beta_median"):
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
    from models.toy import unit_pendulum

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
