"""A model's derived outputs: stored at every sample of a trajectory and at every member's
final state of an ensemble, each a variable of its own name and units."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

import stabdae
from conftest import load_scene


@njit
def angle_and_speed(t, q, v, p, out):
    out[0] = math.atan2(q[0], -q[1])  # from the downward vertical
    out[1] = math.sqrt(v[0] * v[0] + v[1] * v[1])


@njit
def writes_three(t, q, v, p, out):
    out[0] = 0.0
    out[1] = 0.0
    out[2] = 0.0


def pendulum_with_outputs(**overrides):
    kw = dict(outputs=angle_and_speed, output_names=["theta", "speed"],
              output_units=["rad", "m s-1"])  # fmt: skip
    kw.update(overrides)
    return load_scene("pendulum").replace(**kw)


def _plain(x):
    """The outputs written from their definition with NumPy."""
    return np.arctan2(x[..., 0], -x[..., 1]), np.hypot(x[..., 2], x[..., 3])


def test_outputs_in_a_trajectory_and_an_ensemble():
    model = pendulum_with_outputs()
    law = stabdae.baumgarte(10.0)
    ds = stabdae.integrate(model, None, law, "rk4", 1e-3, 1.0, 0.01)
    theta, speed = _plain(ds.x.values)
    np.testing.assert_allclose(ds.theta.values, theta, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(ds.speed.values, speed, rtol=1e-15)
    assert ds.theta.dims == ("time",) and ds.theta.attrs["units"] == "rad"
    assert ds.speed.attrs["units"] == "m s-1"
    ens = stabdae.ensemble(model, law, "rk4", 1e-3, 0.2, members=16, seed=1)
    theta, speed = _plain(ens.x_final.values)
    np.testing.assert_allclose(ens.theta_final.values, theta, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(ens.speed_final.values, speed, rtol=1e-15)
    assert ens.theta_final.dims == ("member",)
    # the model without outputs gives the same numbers otherwise
    plain = stabdae.ensemble(load_scene("pendulum"), law, "rk4", 1e-3, 0.2, members=16, seed=1)
    np.testing.assert_array_equal(plain.x_final.values, ens.x_final.values)
    assert "theta_final" not in plain


def test_outputs_are_refused_by_name():
    with pytest.raises(stabdae.ModelError, match=r"outputs needs output_names"):
        pendulum_with_outputs(output_names=None, output_units=None)
    with pytest.raises(stabdae.ModelError, match=r"output name 'beta' is a dataset's own "
                                                 r"variable or coordinate"):
        pendulum_with_outputs(output_names=["beta", "speed"])
    with pytest.raises(stabdae.ModelError, match=r"output name 'x' is a dataset's own"):
        pendulum_with_outputs(output_names=["x", "speed"])
    with pytest.raises(stabdae.ModelError, match=r"output_units must have "
                                                 r"len\(output_names\)=2 entries, got 3"):
        pendulum_with_outputs(output_units=["rad", "m", "s"])
    with pytest.raises(stabdae.ModelError, match=r"outputs\(t, q, v, p, out\)"):
        pendulum_with_outputs(outputs=writes_three)
    with pytest.raises(stabdae.ModelError, match=r"output_names and output_units go with "
                                                 r"outputs="):
        load_scene("pendulum").replace(output_names=["theta"])
    with pytest.raises(stabdae.ModelError, match=r"declares no outputs"):
        load_scene("pendulum").derived(np.zeros(4))


def test_output_and_parameter_names_the_dataset_cannot_hold_are_refused():
    """``output_names = ["theta", None]`` made a variable ``None_final``; a 300-character
    output or parameter name was accepted and failed at the NetCDF write."""
    with pytest.raises(stabdae.ModelError, match=r"output_names must be strings, got None"):
        pendulum_with_outputs(output_names=["theta", None])
    with pytest.raises(stabdae.ModelError, match=r"output name .* has 300 characters: at most"):
        pendulum_with_outputs(output_names=["theta", "s" * 300])
    with pytest.raises(stabdae.ModelError, match=r"parameter name .* has 300 characters"):
        load_scene("pendulum").replace(params={"g" * 300: 9.81})
    assert pendulum_with_outputs(output_names=["theta", "s" * 200]).output_names[1] == "s" * 200
