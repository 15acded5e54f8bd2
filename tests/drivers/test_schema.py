"""One dataset schema: valid units, history and time format on every dataset kind, and
the schema page generated from it."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import stabdae
from conftest import ROOT, assert_schema, load_scene, pendulum_scene
from stabdae import theory
from stabdae._schema import schema_markdown, udunits_ok


# ---------------------------------------------------------------- one schema
def test_udunits_check_accepts_units_and_refuses_prose():
    for good in ("1", "m", "m2", "m2 s-1", "m s-1", "s-1", "rad s-1", "J", "kg m^2",
                 "m/s", "m2 s-2"):  # fmt: skip
        assert udunits_ok(good), good
    for bad in ("", "model units", "mixed (see state_units)", "m2 per s", "meters"):
        assert not udunits_ok(bad), bad


def test_every_dataset_has_valid_units_history_and_one_time_format(tmp_path):
    """Trajectories (fixed and adaptive), ensembles (fixed and adaptive, with Theorem 5's
    columns), the theory over a study's grid and along a path: valid units or
    per-component units, a history, one created_at format; the pendulum's residual in m²
    and its velocity in m s-1."""
    from stabdae.study.spec import load_study
    from stabdae.study.theory import for_study

    pend = pendulum_scene()
    law = stabdae.baumgarte(10.0)
    traj = stabdae.integrate(pend, None, law, "rk4", 0.01, 0.2, 0.01)
    assert traj.residual.attrs.get("units_per_component") == "component_units"
    assert list(traj.component_units.values) == ["m2", "m2 s-1"]
    assert traj.attrs["history"].endswith("integrate: one trajectory (stabdae "
                                          f"{stabdae.__version__})")  # fmt: skip
    sleigh = load_scene("chaplygin_sleigh")
    datasets = [
        traj,
        stabdae.integrate_adaptive(pend, None, law, 0.2, rtol=1e-6, save_dt=0.1),
        stabdae.integrate(pend, None, law, "rk4", 0.01, 0.2, 0.1, with_multipliers=True),
        stabdae.ensemble(pend, law, "midpoint", 0.01, 0.2, members=8),
        stabdae.ensemble(pend, law, tau=0.01, t_end=0.2, rtol=1e-6, members=4),
        stabdae.ensemble(sleigh, stabdae.theorem5(2.0), "rk4", 0.01, 0.2, members=4),
        theory.along_path(pend, law, "euler", stabdae.integrate(pend, None, law, "euler",
                                                                0.01, 0.2, 0.01)),  # fmt: skip
    ]
    study = tmp_path / "s.toml"
    study.write_text('[model]\nfile = "pendulum"\n[law]\nkind = "baumgarte"\nomega = 10.0\n'
                     '[run]\nt_end = 0.2\ntau = 0.01\n[sweep]\ntau = [0.01, 0.02]\n')  # fmt: skip
    datasets.append(for_study(load_study(study)))
    for ds in datasets:
        assert_schema(ds)
    ens = datasets[3]
    assert ens.residual_norm.attrs["units"] == "1"  # f in m², ḟ in m² s-1: each divided
    assert ens.beta.attrs["units"] == "s-1"
    # a model whose constraints share one unit: the norms carry it
    sl = datasets[5]
    assert sl.residual_norm.attrs["units"] == "m s-1" and sl.gamma.attrs["units"] == "m s-1"


def test_schema_page_is_generated_from_the_schema():
    page = (ROOT / "docs" / "schema.md").read_text()
    assert page == schema_markdown(), (
        "docs/schema.md is stale: regenerate it with python -c \"from stabdae._schema import "
        "schema_markdown; open('docs/schema.md', 'w').write(schema_markdown())\""
    )


# ---------------------------------------------------------------- dimensional analysis
#: base dimensions of the unit symbols the scenes use
_BASE = {"m": {"m": 1}, "s": {"s": 1}, "kg": {"kg": 1}, "rad": {"rad": 1},
         "J": {"kg": 1, "m": 2, "s": -2}, "N": {"kg": 1, "m": 1, "s": -2}}  # fmt: skip


def _dims(units: str) -> dict:
    """``"J m-1 s"`` → ``{kg: 1, m: 1, s: -1}``: each factor's base dimensions to its power."""
    import re

    out: dict = {}
    for factor in units.split():
        if factor == "1":
            continue
        sym, power = re.fullmatch(r"([A-Za-z]+)(-?\d*)", factor).groups()
        for base, k in _BASE[sym].items():
            out[base] = out.get(base, 0) + k * int(power or 1)
    return {b: k for b, k in out.items() if k}


def _times(*dims, power=1):
    out: dict = {}
    for d in dims:
        for b, k in d.items():
            out[b] = out.get(b, 0) + k
    return {b: power * k for b, k in out.items() if k}


RATES = {"beta", "beta_predicted", "beta_median", "beta_median_low", "beta_median_high",
         "beta_theory", "beta_theory_discrete", "beta_lyapunov", "beta_theorem5_proven",
         "beta_theorem5_printed", "theorem5_beta_proven", "theorem5_beta_printed"}  # fmt: skip
TIMES = {"fit_start", "fit_end", "tau_star", "tau_star_low", "tau_star_high", "probe_tau",
         "tau_limit_spectral", "tau_limit_max_norm", "tau_limit_two_norm",
         "tau_limit_weighted_norm", "tau_limit_floor", "reference_stop_time",
         "reference_exceeds_epsilon_time"}  # fmt: skip
RESIDUALS = {"residual_norm", "alpha0_norm", "gamma", "residual_floor", "max_residual",
             "final_residual", "stability_radius", "stability_radius_low",
             "stability_radius_high", "gamma_theorem5", "path_epsilon", "path_remainder",
             "path_residual_norm", "path_bound_start"}  # fmt: skip
ENERGIES = {"energy", "energy_drift"}
PER_ENTRY = {"x": "state", "x0": "state", "x_final": "state", "residual": "component",
             "alpha0": "component", "multiplier": "multiplier",
             "acceleration": "acceleration"}  # fmt: skip


def test_units_follow_from_the_models_declared_units():
    """Dimensional analysis of every schema variable for the Chaplygin sleigh (a velocity
    constraint in m s-1, coordinates in m and rad, energy in J) and the pendulum (a
    position constraint in m², energy per mass in m² s-2): rates are per second, times
    in seconds, residual norms in the unit of g's components (where f and ḟ differ, the
    norm of g with each component divided by its unit: 1), energies in the energy's, the
    rest pure numbers; per entry, a velocity is its coordinate per second, ḟ is f per
    second, an acceleration its coordinate per second squared, and a multiplier makes
    ``Fᵀλ`` a generalized force: energy per unit of f, or per unit of h and second (a
    velocity constraint's row of F is ∂h/∂v)."""
    from stabdae._schema import SCHEMA, schema_variable

    for scene in ("chaplygin_sleigh", "pendulum"):
        model = load_scene(scene)
        q = [_dims(u) for u in model.coordinate_units]
        c = [_dims(u) for u in model.constraint_units]
        energy = _dims(model.energy_units)
        per_s = {"s": -1}
        f, h = c[: model.m], c[model.m:]
        want_entry = {
            "state": q + [_times(d, per_s) for d in q],
            "component": f + [_times(d, per_s) for d in f] + h,
            "multiplier": [_times(energy, _times(d, power=-1)) for d in f]
            + [_times(energy, _times(d, {"s": 1}, power=-1)) for d in h],
            "acceleration": [_times(d, {"s": -2}) for d in q],
        }
        got_entry = {"state": model.state_units, "component": model.component_units,
                     "multiplier": model.multiplier_units,
                     "acceleration": model.acceleration_units}  # fmt: skip
        for kind, units in got_entry.items():
            assert [_dims(u) for u in units] == want_entry[kind], (scene, kind, units)
        comp = want_entry["component"]  # a norm over g = (f, ḟ, h) has one unit or none
        common = comp[0] if all(d == comp[0] for d in comp) else None
        for name in SCHEMA:
            attrs = schema_variable(name, 0.0, model, dims=()).attrs
            if name in PER_ENTRY:
                assert "units_per_component" in attrs or "units" in attrs, name
                continue
            units = attrs.get("units")
            if name in RESIDUALS and common is None:
                assert units == "1" and "units_per_component" not in attrs, name
                continue
            want = (per_s if name in RATES else {"s": 1} if name in TIMES
                    else common if name in RESIDUALS else energy if name in ENERGIES
                    else {})  # fmt: skip
            assert _dims(units) == want, (scene, name, units)
    assert model.name == "pendulum" and _dims(model.multiplier_units[0]) == {"s": -2}


def test_a_norm_over_components_of_different_units_says_so():
    """The pendulum's residual norm runs over f (m²) and ḟ (m² s-1): it is the norm of g
    with each component divided by its unit, a pure number (units "1"), and its comment
    says so, kept beside a comment the variable already has; the sleigh's (one unit)
    has the constraints' unit and no such comment."""
    from stabdae._schema import MIXED_NORM, schema_variable

    pend, sleigh = load_scene("pendulum"), load_scene("chaplygin_sleigh")
    norm = schema_variable("residual_norm", 0.0, pend, dims=()).attrs
    gamma = schema_variable("gamma", 0.0, pend, dims=()).attrs
    assert norm["units"] == "1" and "units_per_component" not in norm
    assert norm["comment"] == f"NaN after a member stopped; {MIXED_NORM}"
    assert gamma["units"] == "1" and gamma["comment"] == MIXED_NORM
    one = schema_variable("residual_norm", 0.0, sleigh, dims=()).attrs
    assert one["units"] == "m s-1" and MIXED_NORM not in one.get("comment", "")


def test_write_netcdf_compresses_the_numeric_arrays_at_the_level_asked(tmp_path):
    """``write_netcdf``: floating-point and integer arrays zlib-compressed (with the
    shuffle filter) at level ``compress``, scalars and strings as they are; the values
    read back equal."""
    import netCDF4
    import xarray as xr

    from stabdae._schema import write_netcdf

    ds = xr.Dataset({"rate": ("member", np.linspace(0.0, 1.0, 50)),
                     "count": ("member", np.arange(50, dtype=np.int32)),
                     "label": ("member", np.array([f"m{i}" for i in range(50)])),
                     "scalar": ((), 2.5)})  # fmt: skip
    path = write_netcdf(ds, tmp_path / "a.nc", compress=7)
    with netCDF4.Dataset(path) as nc:
        for name in ("rate", "count"):
            filters = nc[name].filters()
            assert filters["zlib"] and filters["shuffle"] and filters["complevel"] == 7, name
        for name in ("label", "scalar"):
            assert not nc[name].filters()["zlib"], name
    back = xr.open_dataset(path).load()
    xr.testing.assert_identical(back.drop_attrs(), ds.drop_attrs())


def test_files_carry_cf_flags_and_coordinates(tmp_path):
    """On disk, as CF 1.10 and its compliance checker want: a code variable's
    ``flag_values`` have the variable's own type (CF 3.5; they were int64 beside int8
    codes), and no coordinate variable has a ``_FillValue`` (CF 2.5.1).  Read with
    netCDF4 itself, not through xarray, which hides both."""
    import netCDF4

    from stabdae._schema import write_netcdf

    model = pendulum_scene()
    law = stabdae.baumgarte(10.0)
    datasets = {
        "trajectory": stabdae.integrate(model, None, law, "rk4", 1e-3, 0.1, 0.01),
        "ensemble": stabdae.ensemble(model, law, "rk4", 1e-3, 0.1, members=8, save_dt=0.01),
    }
    for kind, ds in datasets.items():
        path = write_netcdf(ds, tmp_path / f"{kind}.nc")
        with netCDF4.Dataset(path) as nc:
            flagged = [v for v in nc.variables.values() if "flag_values" in v.ncattrs()]
            assert flagged or kind == "trajectory"
            for var in flagged:
                assert np.asarray(var.flag_values).dtype == var.dtype, (kind, var.name)
            coords = [v for name, v in nc.variables.items() if v.dimensions == (name,)]
            assert coords, kind
            for var in coords:
                assert "_FillValue" not in var.ncattrs(), (kind, var.name)
    # in memory as on disk (what reading the file back gives), and so written by the
    # dataset's own to_netcdf too
    flags = datasets["ensemble"].status.attrs["flag_values"]
    assert flags.dtype == np.int8 and flags.tolist() == [int(c) for c in stabdae.Status]
    datasets["ensemble"].to_netcdf(tmp_path / "own.nc")
    with netCDF4.Dataset(tmp_path / "own.nc") as nc:
        assert nc["status"].flag_values.dtype == np.int8
        assert "_FillValue" not in nc["time"].ncattrs()


#: what the CF checker says of every stabdae dataset, on purpose: ``time`` is simulated
#: time in seconds from the run's start, with no epoch; CF's time coordinate
#: (standard_name "time") needs units "s since <date>", and xarray then decodes it into
#: dates for every reader (with calendar "none" it cannot open the file at all)
CF_ACCEPTED = {("§5.1 Independent Latitude, Longitude, Vertical, and Time Axes",
                "Coordinate variable 'time' should have standard_name='time', found: 'None'")}


def cf_findings(path) -> set:
    """The IOOS compliance checker's (CF 1.10) failed checks of high and medium priority
    on the file ``path``: ``(section, message)``."""
    import json

    from compliance_checker.runner import CheckSuite, ComplianceChecker

    CheckSuite.load_all_available_checkers()
    report = path.with_suffix(".cf.json")
    ComplianceChecker.run_checker(str(path), ["cf:1.10"], 0, "normal",
                                  output_filename=str(report), output_format="json")  # fmt: skip
    result = json.loads(report.read_text())["cf:1.10"]
    return {(item["name"], msg) for level in ("high_priorities", "medium_priorities")
            for item in result[level] if item["value"][0] < item["value"][1]
            for msg in item["msgs"]}  # fmt: skip


def numeric_without_one_unit(path) -> list[str]:
    """The numeric variables of the file ``path`` (read with netCDF4, as a CF tool reads
    it) that have no ``units``, or carry ``units_per_component``."""
    import netCDF4

    with netCDF4.Dataset(path) as nc:
        return [v.name for v in nc.variables.values() if v.dtype != str
                and np.dtype(v.dtype).kind in "fiu"
                and ("units" not in v.ncattrs() or "units_per_component" in v.ncattrs())]


def test_files_have_one_unit_per_variable_and_open_as_written(tmp_path):
    """CF gives a variable one unit and reads one without units as a pure number: in a
    file ``stabdae.write_netcdf`` wrote, every numeric variable has ``units``, a variable
    whose entries mix units (the pendulum's x in m and m s-1, its residual, alpha0, x0,
    x_final; the sleigh's accelerations in m s-2 and rad s-2) stored one entry per
    variable with that entry's unit and values; ``stabdae.open_dataset`` gives back the
    dataset that was written, identical.  Before: ``x``, ``residual``, ``alpha0`` and
    every mixed norm had no ``units``."""
    import netCDF4

    model = pendulum_scene()
    law = stabdae.baumgarte(10.0)
    datasets = {
        "trajectory": stabdae.integrate(model, None, law, "rk4", 1e-3, 0.1, 0.01,
                                        with_multipliers=True),
        "ensemble": stabdae.ensemble(model, law, "rk4", 1e-3, 0.1, members=8, save_dt=0.01,
                                     states=True),
        "sleigh": stabdae.integrate(load_scene("chaplygin_sleigh"), None,
                                    stabdae.theorem5(2.0), "rk4", 1e-3, 0.1, 0.01,
                                    with_multipliers=True),
    }  # fmt: skip
    for kind, ds in datasets.items():
        path = stabdae.write_netcdf(ds, tmp_path / f"{kind}.nc")
        assert numeric_without_one_unit(path) == [], kind
        stacked = [n for n, v in ds.data_vars.items() if "units_per_component" in v.attrs]
        assert set(stacked) == {"trajectory": {"x", "residual"},
                                "ensemble": {"alpha0", "x0", "x_final"},
                                "sleigh": {"x", "acceleration"}}[kind]  # fmt: skip
        with netCDF4.Dataset(path) as nc:
            for name in stacked:
                var = ds[name]
                dim = ds[var.attrs["units_per_component"]].dims[0]
                units = ds[var.attrs["units_per_component"]].values
                assert name not in nc.variables
                for i, label in enumerate(ds[dim].values):
                    entry = nc[f"{name}__{label}"]
                    assert entry.units == units[i] and entry.stacked_from == name
                    np.testing.assert_array_equal(entry[:].filled(np.nan),
                                                  var.isel({dim: i}).values)  # fmt: skip
        xr.testing.assert_identical(stabdae.open_dataset(path).load(), ds)
        # a file of another writer opens as xarray opens it
        other = tmp_path / f"{kind}-xarray.nc"
        ds.to_netcdf(other)
        xr.testing.assert_identical(stabdae.open_dataset(other).load(),
                                    xr.open_dataset(other).load())  # fmt: skip


def test_every_kind_of_dataset_passes_the_cf_checker(tmp_path):
    """The IOOS compliance checker (CF 1.10) on a trajectory and an ensemble written by
    their own ``to_netcdf`` (as a user writes them) and on a study's dataset: no finding
    but the time coordinate's missing epoch (:data:`CF_ACCEPTED`).  Before the flags and
    coordinates were fixed: ``_FillValue`` on ``time``, ``tau``, ``omega`` (2.5.1) and
    ``flag_values`` as int64 on int8 variables (3.5)."""
    pytest.importorskip("compliance_checker")
    from conftest import study_file
    from stabdae.study.run import run_study

    model = pendulum_scene()
    law = stabdae.baumgarte(10.0)
    traj = tmp_path / "trajectory.nc"
    stabdae.integrate(model, None, law, "rk4", 1e-3, 0.1, 0.01).to_netcdf(traj)
    ens = tmp_path / "ensemble.nc"
    stabdae.ensemble(model, law, "rk4", 1e-3, 0.1, members=8, save_dt=0.01).to_netcdf(ens)
    study = run_study(study_file(tmp_path, members=8, t_end=0.2, omegas="5.0"),
                      progress=False, log=lambda *a: None)  # fmt: skip
    # grid points run until decided: the decision's codes, and members padded as not run
    (tmp_path / "seq.toml").write_text(
        '[model]\nfile = "pendulum"\n[law]\nkind = "baumgarte"\nomega = 50.0\n[run]\n'
        't_end = 0.5\ntau = 0.01\n[ensemble]\nmembers = { batch = 16, max = 64 }\n'
        '[sweep]\ntau = [0.01, 0.05]\n')  # fmt: skip
    seq = run_study(tmp_path / "seq.toml", tmp_path / "seq.nc", progress=False,
                    log=lambda *a: None)  # fmt: skip
    with xr.open_dataset(seq) as ds:
        assert ds.members_used.values.tolist() != [64, 64]  # (the padding is checked too)
    for path in (traj, ens, study, seq):
        assert cf_findings(path) == CF_ACCEPTED, path.name
    # a study's file has one unit per variable (its alpha0 one variable per entry)
    for path in (study, seq):
        assert numeric_without_one_unit(path) == [], path.name
        with xr.open_dataset(path) as ds:
            assert "alpha0__f_0" in ds and "alpha0" not in ds
        with stabdae.open_dataset(path) as ds:
            assert ds.alpha0.dims[-1] == "component"
