"""Datasets: CF-style attributes, provenance, atomic NetCDF writing.

Every variable and coordinate built here carries ``long_name`` and ``units``; provenance
attributes are stamped by one function (:func:`provenance`) so that every dataset the
library writes says what produced it.
"""

from __future__ import annotations

import datetime as _dt
import os
import tempfile
from pathlib import Path

import numpy as np
import xarray as xr

from ._fma import HOST_FMA
from ._version import __version__


def variable(dims, data, long_name: str, units: str, **attrs) -> xr.Variable:
    """An ``xr.Variable`` with the CF attributes every stabdae variable has."""
    return xr.Variable(dims, data, attrs={"long_name": long_name, "units": units, **attrs})


def model_coords(model, times) -> dict:
    """Coordinates every stabdae dataset of a model shares: time, state, component."""
    return {
        "time": variable("time", times, "time", "s"),
        "state": variable("state", model.state_names, "state component x = (q, v)", "1"),
        "component": variable(
            "component", model.component_names, "residual component g = (f, fdot, h) (3.2)", "1"
        ),
        "state_units": variable("state", model.state_units, "units of each state component", "1"),
    }


def flat_attrs(prefix: str, values: dict) -> dict:
    """Flatten a mapping into NetCDF-storable attributes ``<prefix><key>``."""
    out = {}
    for key, val in values.items():
        if isinstance(val, (bool, np.bool_)):
            val = int(val)
        elif isinstance(val, (list, tuple, np.ndarray)):
            val = np.asarray(val, dtype=np.float64)
        elif val is None:
            continue
        out[f"{prefix}{key}"] = val
    return out


def provenance(model, p: np.ndarray, law, scheme, **run) -> dict:
    """Global attributes: what produced a dataset (model, parameters, law, scheme, run)."""
    attrs = {
        "Conventions": "CF-1.10",
        "title": f"stabdae: {model.name}",
        "source": f"stabdae {__version__}",
        "stabdae_version": __version__,
        "created_at": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "model": model.name,
        "model_n": model.n,
        "model_m": model.m,
        "model_k": model.k,
        "model_param_names": " ".join(model.param_names),
        # 1: the library's multiply-adds were fused (._fma); results differ at roundoff
        # from a machine without FMA, which computes them with two roundings
        "fused_multiply_add": int(HOST_FMA),
    }
    attrs.update(flat_attrs("model_param_", dict(zip(model.param_names, p.tolist()))))
    law_attrs = law.attrs()
    attrs["law"] = law_attrs.pop("law")
    attrs.update(flat_attrs("law_", law_attrs))
    attrs.update(flat_attrs("", scheme.attrs()))
    attrs.update(flat_attrs("", run))
    attrs["history"] = f"{attrs['created_at']}: created by stabdae {__version__}"
    return attrs


def write_netcdf(ds: xr.Dataset, path, *, compress: int = 4, overwrite: bool = True) -> Path:
    """Write ``ds`` to ``path`` atomically: a temporary file in the same folder, then rename.

    A reader never sees a half-written file, and a failure leaves any previous file intact.
    Floating-point and integer variables are zlib-compressed at level ``compress``.
    """
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass overwrite=True (or --force) to replace it")
    path.parent.mkdir(parents=True, exist_ok=True)
    encoding = {}
    for name, var in ds.data_vars.items():
        if var.dtype.kind in "fiu" and var.ndim > 0:
            encoding[name] = {"zlib": True, "complevel": compress, "shuffle": True}
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        ds.to_netcdf(tmp, engine="netcdf4", encoding=encoding)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the file ordinary modes
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
