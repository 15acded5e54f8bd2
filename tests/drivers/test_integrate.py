"""One trajectory: the dataset and its units, the NetCDF round trip, parameters changed
without recompiling, failures as statuses that keep the finite part."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from numba import njit

import stabdae
from conftest import assert_schema, compiled_only, load_scene, perturbed_state
from models.toy import X_REF, unit_pendulum
from stabdae._laws import bind_law
from stabdae._schema import write_netcdf
from stabdae.engine.rk.steps import integrator_for


def test_dataset_schema_and_units():
    model = load_scene("double_pendulum")
    ds = stabdae.integrate(model, perturbed_state(model, 1e-3), stabdae.baumgarte(10.0), "heun",
                           1e-3, 0.5, 0.05)  # fmt: skip
    assert ds.sizes == {"time": 11, "state": 8, "component": 4}
    np.testing.assert_allclose(ds.time.values, np.arange(11) * 0.05, atol=1e-15)
    assert_schema(ds)
    assert list(ds.component.values) == ["f_0", "f_1", "fdot_0", "fdot_1"]
    assert list(ds.state_units.values[:2]) == ["m", "m"] and ds.state_units.values[4] == "m s-1"
    np.testing.assert_allclose(ds.residual_norm, np.abs(ds.residual).max("component"))
    attrs = ds.attrs
    assert attrs["Conventions"] == "CF-1.10"
    assert attrs["model"] == "double_pendulum" and attrs["law"] == "baumgarte"
    assert attrs["law_omega"] == 10.0 and attrs["scheme"] == "heun" and attrs["tau"] == 1e-3
    assert attrs["model_param_g"] == 9.81 and attrs["status"] == 0
    # the stored residual is g(x) of the stored state
    for i in (0, 5, 10):
        np.testing.assert_allclose(
            ds.residual.values[i], model.residual(ds.x.values[i]), rtol=1e-12, atol=1e-15
        )


def test_netcdf_round_trip(tmp_path):
    model = load_scene("chaplygin_sleigh")
    ds = stabdae.integrate(model, perturbed_state(model, 1e-3), stabdae.theorem5(2.0), "rk4",
                           1e-3, 0.5, 0.01)  # fmt: skip
    path = write_netcdf(ds, tmp_path / "sub" / "sleigh.nc")
    assert sorted(p.name for p in path.parent.iterdir()) == ["sleigh.nc"]  # no temporary left
    with stabdae.open_dataset(path) as back:
        xr.testing.assert_identical(back.load(), ds)
        assert back.x.encoding.get("zlib") is True and back.residual.encoding.get("zlib") is True
    with pytest.raises(FileExistsError, match="exists"):
        write_netcdf(ds, path, overwrite=False)


@compiled_only
def test_params_change_without_recompiling():
    model = load_scene("pendulum")
    law = stabdae.baumgarte(10.0)
    a = stabdae.integrate(model, None, law, "rk4", 1e-3, 0.5, 0.5, params={"g": 9.81, "l": 1.0})
    kernel = integrator_for(model, bind_law(law, model))
    before = len(kernel.signatures)
    b = stabdae.integrate(model, model.reference_state(model.param_vector({"l": 2.0})),
                          stabdae.baumgarte(3.0, 0.5), "euler", 1e-3, 0.5, 0.5,
                          params={"l": 2.0})  # fmt: skip
    assert len(kernel.signatures) == before
    # each run stays on the circle of its own length: the parameter reached the kernel
    assert abs(np.hypot(*a.x.values[-1, :2]) - 1.0) < 1e-6
    assert abs(np.hypot(*b.x.values[-1, :2]) - 2.0) < 1e-3


# ---------------------------------------------------------------- failures are statuses


@njit
def f_twice(t, q, p, out):
    r = q[0] * q[0] + q[1] * q[1] - 1.0
    out[0] = r
    out[1] = 2.0 * r  # the same constraint again: F has rank 1, S is singular


@njit
def f_q_twice(t, q, p, out):
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]
    out[1, 0] = 4.0 * q[0]
    out[1, 1] = 4.0 * q[1]


@njit
def f_accel_twice(t, q, v, p, out):
    s = 2.0 * (v[0] * v[0] + v[1] * v[1])
    out[0] = s
    out[1] = 2.0 * s


@njit
def mass_param(t, q, p, out):
    out[0, 0] = 1.0
    out[0, 1] = 0.0
    out[1, 0] = 0.0
    out[1, 1] = p[0]


def test_singular_S_is_a_status_not_nan():
    model = unit_pendulum("redundant", m=2, f=f_twice, f_q=f_q_twice, f_accel=f_accel_twice)
    with pytest.warns(stabdae.IntegrationWarning, match=r"stopped at step 0 .*singular constraint"):
        ds = stabdae.integrate(model, None, stabdae.baumgarte(10.0), "rk4", 0.01, 1.0, 0.1)
    assert ds.attrs["status"] == stabdae.Status.SINGULAR_S
    assert ds.attrs["status_name"] == "singular_s"
    np.testing.assert_array_equal(ds.x.values[0], X_REF)  # the initial sample is kept
    assert np.isnan(ds.x.values[1:]).all()


def test_mass_not_spd_is_a_status():
    model = unit_pendulum("negative_mass", params={"m2": 1.0}, mass=mass_param)
    with pytest.warns(stabdae.IntegrationWarning, match="mass matrix is not symmetric positive"):
        ds = stabdae.integrate(model, None, stabdae.baumgarte(10.0), "rk4", 0.01, 1.0,
                               params={"m2": -1.0})  # fmt: skip
    assert ds.attrs["status"] == stabdae.Status.MASS_NOT_SPD


def test_blow_up_stops_with_a_status_and_keeps_the_finite_part():
    """Euler far outside its stability region (τω = 10 > 2ξ) grows until it overflows."""
    model = load_scene("pendulum")
    x0 = perturbed_state(model, 1e-3)
    with pytest.warns(stabdae.IntegrationWarning, match=r"stopped at step \d+"):
        ds = stabdae.integrate(model, x0, stabdae.baumgarte(100.0), "euler", 0.1, 100.0)
    assert ds.attrs["status"] == stabdae.Status.NONFINITE_STATE  # it overflows
    done = ds.attrs["steps_completed"]
    assert 0 < done < 1000
    assert np.isfinite(ds.x.values[: done + 1]).all() and np.isnan(ds.x.values[done + 1 :]).all()


# ---------------------------------------------------------------- what the kernels compile


def test_a_failed_write_names_the_file_and_the_free_space(tmp_path, monkeypatch):
    """The HDF5 library reports a full disk as "NetCDF: HDF error": the message names the
    file and the free space, and no temporary file is left."""
    ds = stabdae.integrate(load_scene("pendulum"), None, stabdae.baumgarte(10.0), "rk4", 0.1,
                           0.2)  # fmt: skip

    def full_disk(*args, **kwargs):
        raise RuntimeError("NetCDF: HDF error")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", full_disk)
    with pytest.raises(OSError, match=r"could not write .*out\.nc: NetCDF: HDF error \(\d+ MiB "
                                      r"free in .*a full disk reads like this\)"):  # fmt: skip
        write_netcdf(ds, tmp_path / "out.nc")
    assert list(tmp_path.iterdir()) == []
