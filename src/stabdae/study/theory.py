"""The theorems' predictions at every point of a study's grid (``stabdae theory``, and the
path conditions of a study with a state-dependent law).

Built on :mod:`stabdae.theory`, which computes on matrices and given trajectories; the
sampling and integrating that state-dependent laws need happen here.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from .._ensemble import sample_perturbations
from .._integrate import integrate
from .._schema import cf_dataset, component_coords, provenance, schema_variable, variable
from ..theory import (
    CONDITIONS,
    along_path,
    continuous,
    discrete,
    lyapunov,
    tau_limit,
    theorem5,
)
from .spec import most_members

__all__ = ["axis_units", "for_study"]


def axis_units(canon: str) -> str:
    """Units of a sweep axis by its canonical name (``run.tau``: s)."""
    return {"run.tau": "s", "law.omega": "s-1", "law.k": "s-1"}.get(canon, "1")


def for_study(study, *, path_steps: int = 2000) -> xr.Dataset:
    """The theorems' predictions at every grid point of a study (``stabdae theory``).

    Constant laws: Theorems 3, 4, 6/7 from ``Ã`` alone, nothing integrated.  Theorem 5
    laws: ``λ_min(W)`` over a sampled neighbourhood of the manifold (the study's
    perturbations placed around ``x*``, and the reference trajectory) and the discrete
    conditions along the reference trajectory (its first ``path_steps`` steps).
    """
    model = study.model
    names = list(study.axes)
    shape = study.shape
    cols: dict[str, np.ndarray] = {}

    def put(name, idx, value):
        if name not in cols:
            cols[name] = np.full(shape, np.nan)
        cols[name][idx] = value

    neighbourhood = None
    per_law: dict = {}
    for idx, values in study.points():
        s = study.setup(values)
        law, scheme, tau = s["law"], s["scheme"], s["tau"]
        p = model.param_vector(s["params"])
        if law.is_constant:
            A = law.A_tilde(model)
            # what depends on Ã (and the scheme) alone is computed once per distinct law,
            # not at every τ of the grid: the τ limits are four bisections each
            key = (A.tobytes(), A.shape, scheme.stability_polynomial().tobytes())
            if key not in per_law:
                c, ly = continuous(A), lyapunov(A)
                per_law[key] = {
                    "beta_theory": c["beta"], "lyapunov_holds": float(ly["holds"]),
                    "beta_lyapunov": ly["beta"],
                    **{f"tau_limit_{k}": tau_limit(A, scheme, k) for k in CONDITIONS},
                }  # fmt: skip
            for k, v in per_law[key].items():
                put(k, idx, v)
            d = discrete(A, scheme, tau, limits=False)
            rho = d.spectral_radius
            put("beta_theory_discrete", idx, -math.log(rho) / tau if rho > 0 else math.inf)
            for k, v in d.as_dict().items():
                put(k, idx, v)
            put("norm_condition", idx, float(d.norm_weighted < 1.0))
        else:
            if neighbourhood is None or any(n.startswith("model.") for n in names):
                x_ref = model.reference_state(p)
                ens = sample_perturbations(model, most_members(study.ensemble["members"]),
                                           study.ensemble["radius"], study.ensemble["seed"],
                                           params=p)[0]  # fmt: skip
                traj = integrate(model, x_ref, law, scheme, tau, s["t_end"], s["save_dt"],
                                 params=p).x.values  # fmt: skip
                neighbourhood = np.concatenate([ens, traj])
            c5 = theorem5(model, law, neighbourhood, params=p)
            for k in ("lambda_min_W", "beta_proven", "beta_printed", "gamma_factor"):
                put(f"theorem5_{k}", idx, c5[k])
            t_path = min(s["t_end"], model.t0 + path_steps * tau)
            t_path = model.t0 + tau * max(2, round((t_path - model.t0) / tau))
            trajectory = integrate(model, None, law, scheme, tau, t_path, tau, params=p)
            path = along_path(model, law, scheme, trajectory, params=p)
            put("path_spectral_radius_max", idx, float(path.spectral_radius.max()))
            put("path_norm_weighted_max", idx, float(path.q))
            put("path_epsilon", idx, float(path.epsilon))
    data = {k: schema_variable(k, v, model, dims=names) for k, v in cols.items()}
    coords = {n: variable(n, v, f"swept {n}", axis_units(n)) for n, v in study.axes.items()}
    coords.update(component_coords(model))
    setup = study.setup()
    attrs = provenance(model, None, setup["law"], setup["scheme"],
                       f"stabdae theory {study.path.name}: the theorems over the grid")
    attrs["study"] = str(study.path)
    return cf_dataset(data, coords=coords, attrs=attrs)
