"""Every argument error names the function the user called."""

from __future__ import annotations

import numpy as np
import pytest

import stabdae
from conftest import pendulum_scene
from stabdae import theory


def _bad_calls():
    law = stabdae.baumgarte(10.0)
    m = pendulum_scene
    return [
        ("integrate", lambda: stabdae.integrate("pendulum", None, law)),
        ("integrate", lambda: stabdae.integrate(m(), None, None)),
        ("integrate", lambda: stabdae.integrate(m(), None, law, "rk9")),
        ("integrate", lambda: stabdae.integrate(m(), None, law, tau=-1.0)),
        ("integrate", lambda: stabdae.integrate(m(), None, law, tau=0.3, t_end=1.0)),
        ("integrate", lambda: stabdae.integrate(m(), None, law, save_dt=0.0015)),
        ("integrate", lambda: stabdae.integrate(m(), np.zeros(3), law)),
        ("integrate", lambda: stabdae.integrate(m(), m().reference_state() + 1e-3j, law)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, x0=np.zeros((2, 4), complex))),
        ("integrate", lambda: stabdae.integrate(m(), None, law, params={"nope": 1.0})),
        ("integrate", lambda: stabdae.integrate(m(), None, law, multiplier="qr")),
        ("integrate", lambda: stabdae.integrate(m(), None, law, projection="half")),
        ("integrate", lambda: stabdae.integrate(m(), None, stabdae.matrix(np.zeros((2, 2))))),
        ("integrate", lambda: stabdae.integrate(m(), None, law, t_end="soon")),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), None, None)),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), None, law, rtol=0.0)),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), None, law, t_end=-1)),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), None, law,
                                                                  max_steps=0)),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), np.ones(5), law)),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), None, law,
                                                                  params=[1.0])),
        ("ensemble", lambda: stabdae.ensemble(m(), None)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, tau=0.0)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, members=0)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, radius=(1.0, 0.1))),
        ("ensemble", lambda: stabdae.ensemble(m(), law, seed=np.random.default_rng(1))),
        ("ensemble", lambda: stabdae.ensemble(m(), law, seed=-1)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, x0=np.zeros((2, 3)))),
        ("ensemble", lambda: stabdae.ensemble(m(), law, block=0)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, block=10**6)),  # past the stack
        ("ensemble", lambda: stabdae.ensemble(m(), law, threads=0)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, residual_dtype="float16")),
        ("ensemble", lambda: stabdae.ensemble(m(), law, epsilon=-1.0)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, "rk4", rtol=1e-6)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, atol=1e-6)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, "nope")),
        ("ensemble", lambda: stabdae.ensemble(m(), law, params={"g": "x"})),
        ("ensemble", lambda: stabdae.ensemble(m(), law, progress=3)),
        ("sample_perturbations", lambda: stabdae.sample_perturbations(m(), 0)),
        ("sample_perturbations", lambda: stabdae.sample_perturbations(m(), 4, radius=-1.0)),
        ("sample_perturbations", lambda: stabdae.sample_perturbations(m(), 4, seed=1.5)),
        ("sample_perturbations", lambda: stabdae.sample_perturbations(m(), 4, threads=-2)),
        ("sample_perturbations", lambda: stabdae.sample_perturbations(m(), 4,
                                                                      params={"l": -np.inf})),
    ]  # fmt: skip


@pytest.mark.parametrize("index", range(len(_bad_calls())))
def test_every_argument_error_names_the_function_called(index):
    who, call = _bad_calls()[index]
    with pytest.raises((ValueError, TypeError)) as info:
        call()
    assert str(info.value).startswith(f"{who}: "), str(info.value)


def test_tau_limit_names_an_unknown_condition():
    with pytest.raises(ValueError, match=r"tau_limit: condition must be one of .*'spectral'"):
        theory.tau_limit(np.array([[-1.0]]), "euler", condition="spectal")


def test_an_ensemble_too_large_for_memory_is_refused_up_front(monkeypatch):
    """An ensemble that cannot fit is refused with its figures before anything is allocated
    or compiled (the operating system would kill the process part-way instead); the
    estimate is the documented per-member budget, checked here against a small budget."""
    from stabdae import _validate

    model = pendulum_scene()
    with pytest.raises(MemoryError, match=r"ensemble: members = 1000000000000 with 64 "
                                          r"traces of 11 samples needs about [\d.]+e\+05 "
                                          r"GiB, more than the"):
        stabdae.ensemble(model, stabdae.baumgarte(10.0), "midpoint", 0.1, 1.0,
                         members=10**12, save_dt=0.1)  # fmt: skip
    need = _validate.ensemble_bytes(model.n, model.n_residual, 1000, 1000, 11, 4)
    assert need == 8 * (8 * 2 + 4 * 2 + 48) * 1000 + 2 * 4 * 1000 * 11
    monkeypatch.setattr(_validate, "available_memory", lambda: need - 1)
    with pytest.raises(MemoryError, match="run fewer members"):
        stabdae.ensemble(model, stabdae.baumgarte(10.0), "midpoint", 0.1, 1.0, members=1000,
                         save_dt=0.1, traces="all")  # fmt: skip
    # no traces stored: none counted, and exactly what the members need is enough
    exact = _validate.ensemble_bytes(model.n, model.n_residual, 1000, 0, 11, 4)
    monkeypatch.setattr(_validate, "available_memory", lambda: exact)
    ds = stabdae.ensemble(model, stabdae.baumgarte(10.0), "midpoint", 0.1, 1.0, members=1000,
                          save_dt=0.1, traces="none")  # fmt: skip
    assert ds.sizes["member"] == 1000
    monkeypatch.setattr(_validate, "available_memory", lambda: need - 1)
    # the same members given as initial states: counted by rows, not by state components
    x0 = np.tile(model.reference_state(model.param_vector()), (1000, 1))
    with pytest.raises(MemoryError, match="members = 1000 with 1000 traces"):
        stabdae.ensemble(model, stabdae.baumgarte(10.0), "midpoint", 0.1, 1.0, x0=x0,
                         save_dt=0.1, traces="all")  # fmt: skip


def test_a_study_with_too_many_members_is_refused_when_loaded(tmp_path):
    from conftest import study_file
    from stabdae.study.spec import StudyError, load_study

    with pytest.raises(StudyError, match=r"\[ensemble\] members: 1000000000000 members per "
                                         r"grid point needs about .* GiB"):
        load_study(study_file(tmp_path), members=10**12)
