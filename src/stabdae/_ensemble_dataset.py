"""The dataset of an ensemble, built from what its kernel returned: the measurement
record read by column name, the per-member classes and summaries (:mod:`._measures`),
the theorems' predictions (:mod:`.theory`), the schema's variables and the provenance
(:mod:`._schema`); and the one warning for the members that stopped.

It is built as a :class:`Table` of plain arrays first, which :meth:`Table.to_dataset`
turns into an ``xarray.Dataset``: a study keeps its grid points' tables and makes one
dataset of them all (building an ``xarray.Dataset`` per grid point cost more than the
ensemble's integration on small studies)."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from . import _measures, theory
from ._codes import BetaReason, StabilityClass, Status, Verdict, VerdictReason
from ._integrate import IntegrationWarning
from ._laws import Theorem5
from ._schema import (
    COUNTS,
    SINGLE_PRECISION,
    cf_dataset,
    model_coords,
    output_entries,
    provenance,
    schema_entry,
    variable,
)
from .engine import decay

#: what a grid point's row holds for a member it did not run (a study pads the tables of
#: grid points run until decided to the most members any ran): NaN for real numbers,
#: these for integers, 0 for the other integers
NOT_RUN = {"status": int(Status.NOT_NEEDED), "verdict": int(Verdict.UNDECIDED),
           "verdict_reason": int(VerdictReason.NOT_RUN),
           "stability_class": int(StabilityClass.NOT_RUN),
           "beta_reason": int(BetaReason.STOPPED), "diverged_step": -1}  # fmt: skip


@dataclass
class Table:
    """A dataset as plain arrays: ``data`` maps each variable's name to ``(dims, values,
    attrs)``, ``coords`` each coordinate's name to an ``xarray.Variable``, ``attrs`` the
    global attributes.  What :meth:`to_dataset` gives is what :func:`stabdae.ensemble`
    returns."""

    data: dict
    coords: dict
    attrs: dict = field(default_factory=dict)

    def to_dataset(self) -> xr.Dataset:
        return cf_dataset(self.data, coords=self.coords, attrs=self.attrs)

    @classmethod
    def from_dataset(cls, ds: xr.Dataset) -> Table:
        """The table of ``ds`` (its arrays, not copies)."""
        data = {k: (v.dims, v.values, dict(v.attrs)) for k, v in ds.data_vars.items()}
        return cls(data, {k: ds[k].variable for k in ds.coords}, dict(ds.attrs))


def _warn_stopped(name: str, status) -> None:
    """One warning for the members that stopped, counted by reason (as :func:`integrate`
    warns for one trajectory)."""
    status = np.asarray(status)
    total = int((status != 0).sum())
    if not total:
        return
    reasons = _measures.not_run_text(status, status == 0)
    warnings.warn(
        f"ensemble({name}): {total} of {status.shape[0]} members stopped: {reasons}; "
        "their samples up to the stop are kept (see the status variable)",
        IntegrationWarning,
        stacklevel=3,
    )


def ensemble_table(model, p, law, scheme, bound, times, x0, alpha0, norms, traced,
                   x_final, status, fail_step, e0, e1, epsilon, meas, R, run,
                   extra=None, roundoff=0.0, overshoot_theory=math.nan,
                   adaptive=False, referee=None, verdicts=None) -> Table:  # fmt: skip
    """The ensemble's :class:`Table` from what its kernel returned (``verdicts``: the
    members' verdicts and reasons where the caller has them already, from the same record
    and referee)."""
    stopped = status != 0
    for name in ("beta_predicted", "beta", "gamma"):  # (not placed: measured on nothing)
        meas[name][stopped] = np.nan
    reason = meas["reason"]
    reason[stopped & (reason == decay.R_FITTED)] = decay.R_STOPPED
    # γ bounds the transient β was fitted on: none without β (beta_reason says why)
    gamma = meas["gamma"]
    gamma[~np.isfinite(meas["beta"]) | ~np.isfinite(gamma)] = np.nan
    if verdicts is None:
        verdicts = _measures.verdict(meas, status, roundoff=roundoff, **(referee or {}))
    verdicts, why = verdicts
    cls = _measures.classify(meas, status, epsilon, verdicts)
    alpha_norm = _measures.row_max_abs(alpha0)
    summary, radius_why = _measures.summaries(meas, verdicts, why, cls, alpha_norm, epsilon)
    stable, bounded = _measures.flags(meas, verdicts, epsilon)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        overshoot = meas["largest"] / meas["initial"]
    diverged = cls == _measures.DIVERGED

    coords = {
        "member": variable("member", np.arange(x0.shape[0]), "ensemble member", "1"),
        "trace": variable("trace", traced, "member whose residual norm is stored", "1"),
        **model_coords(model, times),
    }
    values = {
        "residual_norm": norms,
        "alpha0": alpha0,
        "alpha0_norm": alpha_norm,
        "x0": x0,
        "x_final": x_final,
        "beta": meas["beta"],
        "beta_reason": reason.astype(np.int8),
        "gamma": meas["gamma"],
        "residual_floor": meas["floor"],
        "floor_reached": meas["floor_reached"].astype(np.int8),
        "max_residual": meas["largest"],
        "final_residual": meas["final"],
        "overshoot": overshoot,
        "fit_start": times[0] + meas["fit_start"],
        "fit_end": times[0] + meas["fit_end"],
        "fit_points": meas["fit_points"],
        "fit_kind": meas["fit_kind"].astype(np.int8),
        "verdict": verdicts,
        "verdict_reason": why,
        "stability_class": cls,
        "stable": stable.astype(np.int8),
        "bounded": bounded.astype(np.int8),
        "diverged": diverged.astype(np.int8),
        "diverged_step": fail_step,
        "status": status,
        **summary,
    }
    motion = (referee or {}).get("motion")
    if motion is not None:  # how the unperturbed run went (per grid point in a study)
        values.update(reference_status=np.int8(motion.status),
                      reference_stop_time=float(motion.stopped_at),
                      reference_exceeds_epsilon_time=float(motion.exceeds_at))  # fmt: skip
    if R.shape[0] > 0:
        beta_pred = meas["beta_predicted"]
        values["beta_predicted"] = beta_pred
        with np.errstate(invalid="ignore", divide="ignore"):
            values["beta_ratio"] = meas["beta"] / beta_pred
        med = _measures.median_interval(values["beta_ratio"])
        values["beta_ratio_median"] = med[0]
        values["overshoot_theory"] = overshoot_theory
    if model.energy is not None:
        values["energy_drift"] = e1 - e0
    values.update(extra or {})
    values.update(_theory_values(law, model, p, scheme, run.get("tau"), adaptive, x0, x_final,
                                 times, norms, traced, alpha0, meas["floor"]))  # fmt: skip
    for name in SINGLE_PRECISION:
        if name in values:
            values[name] = np.asarray(values[name], dtype=np.float32)
    for name in COUNTS:
        if name in values:
            values[name] = np.asarray(values[name], dtype=np.int32)
    data = {name: schema_entry(name, val, model) for name, val in values.items()}
    if model.outputs is not None:  # at each member's final state; NaN for those that stopped
        finals = model.derived(x_final, times[-1], p)
        finals[stopped] = np.nan
        data.update(output_entries(model, finals, ("member",), "_final",
                                   " at the member's final state"))  # fmt: skip
    attrs = data["residual_norm"][2]
    attrs["comment"] = f"stored as {norms.dtype}; " + attrs["comment"]
    data["stability_radius"][2]["comment"] = radius_why
    attrs = provenance(model, p, law, scheme, f"ensemble of {x0.shape[0]} members", **run)
    attrs["verdict_summary"] = _measures.verdict_summary(
        verdicts, why, cls != _measures.NOT_RUN,
        "" if motion is None else motion.describe(epsilon), status)  # fmt: skip
    if referee is not None:
        attrs["reference_floor"] = np.asarray(referee["floor_band"], dtype=float)
    attrs["roundoff_level"] = float(roundoff)
    attrs["residual_norm_dtype"] = str(norms.dtype)
    return Table(data, coords, attrs)


def _theory_values(law, model, p, scheme, tau, adaptive, x0, x_final, times, norms, traced,
                   alpha0, floor) -> dict:  # fmt: skip
    """The theorems' predictions stored beside the measurements (:mod:`stabdae.theory`);
    for adaptive steps only the continuous rate (no step ``tau``)."""
    if law.is_constant and adaptive:
        return {"beta_theory": theory.continuous(law.A_tilde(model))["beta"]}
    if law.is_constant:
        return theory.predictions(model, law, scheme, tau)
    if not isinstance(law, Theorem5):
        return {}
    # Theorem 5 over the states the ensemble visited (its initial and final states)
    states = np.concatenate([x0, x_final])
    c = theory.theorem5(model, law, states, params=p)
    out = {"lambda_min_W": c["lambda_min_W"], "beta_theorem5_proven": c["beta_proven"],
           "beta_theorem5_printed": c["beta_printed"]}  # fmt: skip
    # the Lyapunov argument bounds the 2-norm: γ = √(l_m/l₁)‖α⁰‖₂ also bounds ‖α(t)‖∞
    alpha2 = np.linalg.norm(alpha0, axis=1)
    for which in ("proven", "printed"):  # judged on the stored traces
        out[f"bound_{which}_held"] = theory.bound_held(
            times, norms, alpha2[traced], c[f"beta_{which}"], c["gamma_factor"], floor[traced]
        ).astype(np.int8)
    out["gamma_theorem5"] = c["gamma_factor"] * alpha2
    return out
