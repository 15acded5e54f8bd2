"""Datasets: one schema for every variable the library writes, one provenance stamp, atomic
NetCDF writing.

:data:`SCHEMA` names every variable of every dataset (a trajectory, an ensemble, the
theory of a study's grid, the theory along a path, a study) with its dimensions, long name
and units, and :func:`schema_variable` builds it.  Units are UDUNITS strings
(:func:`udunits_ok`).  A variable whose entries have different units (the state
``x = (q, v)``, the residual ``g = (f, ḟ, h)``) has no single ``units`` attribute in
memory: its ``units_per_component`` attribute names the coordinate that holds each entry's
unit (``state_units``, ``component_units``), taken from the model's declaration
(:class:`stabdae.Model`'s ``coordinate_units`` and ``constraint_units``).  On disk
(:func:`write_netcdf`) such a variable is one variable per entry, each with its unit, as
CF has it; :func:`open_dataset` stacks them again.  A norm of the residual has the
constraints' unit when its components share one, and is otherwise the norm of ``g`` with
each component divided by its unit: unit ``1``.

:func:`provenance` stamps what produced a dataset; :func:`append_history` adds a line to
its ``history`` for every later action, with times in one format (:func:`utc_now`).
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import os
import re
import shutil
import signal
import tempfile
import threading
from pathlib import Path

import numpy as np
import xarray as xr

from ._codes import (
    BetaReason,
    DecisionReason,
    FitKind,
    ProbeStage,
    ProfileReason,
    RadiusReason,
    StabilityClass,
    Status,
    TauStarReason,
    Verdict,
    VerdictReason,
    flag_attrs,
)
from .engine.vector_width import PREFER_512
from ._version import __version__
from .engine.fma import HOST_FMA

__all__ = ["SCHEMA", "append_history", "component_coords", "model_coords", "open_dataset",
           "provenance", "schema_markdown", "schema_variable", "split_entries",
           "trajectory_dataset", "udunits_ok", "utc_now", "variable", "write_netcdf"]  # fmt: skip

#: units markers resolved per model: the state's, the residual components', the residual
#: norm's (the constraints' common unit), the energy's
STATE, COMPONENT, RESIDUAL, ENERGY = "@state", "@component", "@residual", "@energy"
MULTIPLIER, ACCELERATION = "@multiplier", "@acceleration"

#: per-member measurements an ensemble stores in single precision: seven digits are more
#: than any of them is measured to, and they are most of a large study's bytes (its
#: summaries are computed before, in double precision).  Residual norms, their ratios and
#: the energy stay double (a diverging member's exceed the single range), and so does
#: ``alpha0_norm``, which the stability radius's bracket quotes.
SINGLE_PRECISION = ("beta", "fit_start", "fit_end", "beta_predicted", "beta_ratio")
#: per-member counts, stored as 32-bit integers
COUNTS = ("fit_points", "diverged_step", "steps_accepted", "rhs_evaluations")

_FLAG = {"flag_values": [0, 1], "flag_meanings": "no yes"}

_HELD = {**_FLAG, "comment": "judged on the stored residual traces (one per trace), above "
         "10x the member's residual floor, that floor added to the bound"}  # fmt: skip

#: name -> (dims, long_name, units, extra attributes).  ``dims`` of theory variables of a
#: study's grid are the grid's axes (given when built).
SCHEMA: dict[str, tuple] = {
    # --- one trajectory (integrate, integrate_adaptive)
    "x": (("time", "state"), "state x = (q, v)", STATE, {}),
    "residual": (("time", "component"), "constraint residual g = (f, fdot, h) (3.2)",
                 COMPONENT, {}),
    "energy": ("time", "energy (model's energy function)", ENERGY, {}),
    "multiplier": (("time", "constraint"), "Lagrange multipliers lambda of (3.11): "
                   "M dv/dt = F^T lambda - gamma", MULTIPLIER, {}),
    "acceleration": (("time", "coordinate"), "acceleration dv/dt", ACCELERATION, {}),
    # --- an ensemble (and, per grid point, a study)
    "residual_norm": (("trace", "time"), "max-norm of the constraint residual of the "
                      "traced members", RESIDUAL, {"comment": "NaN after a member stopped"}),
    "alpha0": (("member", "component"), "initial perturbation g(x0, t0) achieved", COMPONENT,
               {}),
    "alpha0_norm": ("member", "max-norm of alpha0", RESIDUAL, {}),
    "x0": (("member", "state"), "initial state", STATE, {}),
    "x_final": (("member", "state"), "final state (last state before a stop)", STATE, {}),
    "beta": ("member", "decay rate of the residual norm, measured at every step", "s-1",
             {"comment": "fitted on the right envelope of the transient above the floor; "
              "NaN with beta_reason where there is none"}),
    "beta_reason": ("member", "why beta is or is not fitted", "1", flag_attrs(BetaReason)),
    "gamma": ("member", "prefactor: max over the transient of |g| exp(beta t)", RESIDUAL, {}),
    "residual_floor": ("member", "largest residual norm over the last fifth of the run "
                       "(truncation floor)", RESIDUAL, {}),
    "floor_reached": ("member", "the residual settled before the end (not still decaying)",
                      "1", _FLAG),
    "max_residual": ("member", "largest residual norm reached (at any step)", RESIDUAL, {}),
    "final_residual": ("member", "residual norm at the last state", RESIDUAL, {}),
    "overshoot": ("member", "max_residual / alpha0_norm", "1", {}),
    "overshoot_theory": ((), "sup_k of the max-norm of R(tau A~)^k: the law's own transient "
                         "growth", "1", {}),
    "fit_start": ("member", "start of the window beta is fitted on", "s", {}),
    "fit_end": ("member", "end of the window beta is fitted on", "s", {}),
    "fit_points": ("member", "right-envelope points in the fit window (pairs of the "
                   "one-step map)", "1", {}),
    "fit_kind": ("member", "kind of decay fit", "1", flag_attrs(FitKind)),
    "beta_predicted": ("member", "beta of the member's linear prediction R^k alpha0 (or "
                       "exp(A~ t) alpha0), same window and fit", "s-1", {}),
    "beta_ratio": ("member", "beta / beta_predicted", "1", {}),
    "beta_ratio_median": ((), "median of beta / beta_predicted", "1", {}),
    "verdict": ("member", "verdict: stable, unstable or undecided", "1", flag_attrs(Verdict)),
    "verdict_reason": ("member", "why the member has its verdict", "1",
                       flag_attrs(VerdictReason)),
    "stability_class": ("member", "stability class", "1", flag_attrs(StabilityClass)),
    "stable": ("member", "verdict stable: the deviation from the reference trajectory "
               "decayed, or stayed within the law's transient bound", "1", _FLAG),
    "bounded": ("member", "stable and within epsilon (Definition 2)", "1", _FLAG),
    "diverged": ("member", "stopped: blew up (diverged, non-finite or singular S)", "1",
                 _FLAG),
    "diverged_step": ("member", "step at which the member stopped (-1: ran to the end)", "1",
                      {}),
    "status": ("member", "member status", "1", flag_attrs(Status)),
    "steps_accepted": ("member", "accepted steps (adaptive steps)", "1", {}),
    "rhs_evaluations": ("member", "right-hand-side evaluations (adaptive steps)", "1", {}),
    "energy_drift": ("member", "energy change E(final) - E(x0)", ENERGY, {}),
    "decision": ((), "the cell's decision, run member by member: stable (at most q of its "
                 "members unstable), unstable (more) or undecided", "1", flag_attrs(Verdict)),
    "decision_reason": ((), "why the cell has its decision", "1", flag_attrs(DecisionReason)),
    "decision_low": ((), "sequential interval of the unstable fraction, low (from the "
                     "unstable members; holds at every look at the stated confidence)", "1",
                     {}),
    "decision_high": ((), "sequential interval of the unstable fraction, high (from the "
                      "members not stable: unstable or undecided)", "1", {}),
    "members_used": ((), "members run before the decision", "1", {}),
    "tau_star_confidence": ((), "probability, at least, that every probe of the boundary "
                            "search was decided right and the unstable fraction crosses q "
                            "between tau_star_low and tau_star_high (NaN: probes of a fixed "
                            "size, no stated confidence)", "1", {}),
    "delta_star_reason": ((), "how the delta* bracket of a radial profile is known "
                          "(stabdae.radial_profile)", "1", flag_attrs(ProfileReason)),
    "fraction_stable": ((), "fraction of stable members (of those that ran)", "1", {}),
    "fraction_stable_low": ((), "Wilson 95% interval of fraction_stable, low", "1", {}),
    "fraction_stable_high": ((), "Wilson 95% interval of fraction_stable, high", "1", {}),
    "fraction_unstable": ((), "fraction of unstable members (of those that ran)", "1", {}),
    "fraction_unstable_low": ((), "Wilson 95% interval of fraction_unstable, low", "1", {}),
    "fraction_unstable_high": ((), "Wilson 95% interval of fraction_unstable, high", "1",
                               {}),
    "fraction_undecided": ((), "fraction of undecided members (of those that ran)", "1", {}),
    "fraction_undecided_low": ((), "Wilson 95% interval of fraction_undecided, low", "1",
                               {}),
    "fraction_undecided_high": ((), "Wilson 95% interval of fraction_undecided, high", "1",
                                {}),
    "fraction_bounded": ((), "fraction of bounded members (of those that ran)", "1", {}),
    "fraction_bounded_low": ((), "Wilson 95% interval of fraction_bounded, low", "1", {}),
    "fraction_bounded_high": ((), "Wilson 95% interval of fraction_bounded, high", "1", {}),
    "stability_radius": ((), "delta*: between the largest |alpha0| with every member up to it "
                         "stable and the smallest that is not", RESIDUAL, {}),
    "stability_radius_low": ((), "delta* bracket, low: every member up to it stable",
                             RESIDUAL, {}),
    "stability_radius_high": ((), "delta* bracket, high: smallest |alpha0| not stable",
                              RESIDUAL, {}),
    "beta_median": ((), "median measured decay rate", "s-1", {}),
    "beta_median_low": ((), "95% order-statistics interval of beta_median, low", "s-1", {}),
    "beta_median_high": ((), "95% order-statistics interval of beta_median, high", "s-1", {}),
    "beta_median_coverage": ((), "exact coverage of the beta_median interval (binomial "
                             "order statistics; below 0.95 only for 5 or fewer values)", "1",
                             {}),
    "stability_radius_reason": ((), "how delta* is known (censored where the sample does "
                                "not bracket it)", "1", flag_attrs(RadiusReason)),
    "members_run": ((), "members that ran (placed, not out of steps)", "1", {}),
    "members_stable": ((), "stable members", "1", {}),
    "members_bounded": ((), "bounded members", "1", {}),
    "members_diverged": ((), "diverged members", "1", {}),
    "members_growing": ((), "growing members", "1", {}),
    "members_unstable": ((), "unstable members", "1", {}),
    "members_undecided": ((), "undecided members", "1", {}),
    "members_with_beta": ((), "members with a measured beta", "1", {}),
    "reference_status": ((), "status of the unperturbed run (alpha0 = 0), the reference "
                         "trajectory", "1", flag_attrs(Status)),
    "reference_stop_time": ((), "time at which the unperturbed run stopped (NaN: it ran to "
                            "the end, or the time is not known)", "s", {}),
    "reference_exceeds_epsilon_time": ((), "first time the unperturbed run's residual "
                                       "exceeded epsilon (NaN: never, or not measured "
                                       "where it blew up); where set, or where it blew up, "
                                       "the scheme is unstable on the motion itself", "s",
                                       {}),
    # --- the theorems' predictions (ensemble, study grid)
    "beta_theory": ((), "continuous decay rate -max Re eig(A~) (Theorem 3)", "s-1", {}),
    "beta_theory_discrete": ((), "discrete decay rate -ln rho(R(tau A~))/tau", "s-1", {}),
    "spectral_radius": ((), "spectral radius of R(tau A~)", "1", {}),
    "norm_max": ((), "max-norm of R(tau A~) (the paper's norm; Theorems 6, 7)", "1", {}),
    "norm_2": ((), "2-norm of R(tau A~)", "1", {}),
    "norm_weighted": ((), "norm of R(tau A~) in the discrete-Lyapunov weight", "1",
                      {"comment": "inf when no weight exists (spectral radius >= 1)"}),
    "norm_condition": ((), "weighted-norm condition of Theorems 6/7 holds", "1", _FLAG),
    "lyapunov_holds": ((), "Theorem 4: Sylvester's criterion on L and the symmetric part of "
                       "-LA~", "1", _FLAG),
    "beta_lyapunov": ((), "rate proven by the Lyapunov function, lambda_min(Q)/l_m", "s-1",
                      {}),
    "tau_limit_spectral": ((), "largest tau with rho(R) < 1", "s", {}),
    "tau_limit_max_norm": ((), "largest tau with max-norm of R < 1", "s", {}),
    "tau_limit_two_norm": ((), "largest tau with 2-norm of R < 1", "s", {}),
    "tau_limit_weighted_norm": ((), "largest tau with the weighted norm of R < 1", "s", {}),
    # --- a boundary search (stabdae.boundary; per grid point of a [search] study)
    "tau_star": ((), "largest stable step size: the geometric mean of its bracket", "s", {}),
    "tau_star_low": ((), "tau_star bracket, low: stable with the full ensemble", "s", {}),
    "tau_star_high": ((), "tau_star bracket, high: not stable", "s", {}),
    "tau_star_reason": ((), "why tau_star is or is not bracketed", "1",
                        flag_attrs(TauStarReason)),
    "tau_limit_floor": ((), "largest tau at which Theorems 6/7 with condition 4 bound the "
                        "residual by epsilon (the floor the local error forces)", "s", {}),
    "probe_tau": ("probe", "step size of the probe", "s", {}),
    "probe_members": ("probe", "members of the probe's ensemble", "1", {}),
    "probe_fraction_stable": ("probe", "fraction of stable members at the probe", "1", {}),
    "probe_verdict": ("probe", "the probe's verdict: stable (at least 1 - q of its members "
                      "stable), unstable (more than q unstable) or undecided", "1",
                      flag_attrs(Verdict)),
    "probe_stable": ("probe", "the probe counted as stable (fraction at least 1 - q)", "1",
                     _FLAG),
    "probe_stage": ("probe", "stage of the search", "1", flag_attrs(ProbeStage)),
    "probe_motion_unstable": ("probe", "the scheme is unstable on the motion itself at the "
                              "probe (its unperturbed run diverges or leaves epsilon)", "1",
                              _FLAG),
    "lambda_min_W": ((), "min eigenvalue of W = h_v h_v^T over x0 and x_final", "1", {}),
    "beta_theorem5_proven": ((), "Theorem 5 rate k0 lambda_min(W) l1^2/lm (proven)", "s-1",
                             {}),
    "beta_theorem5_printed": ((), "Theorem 5 rate k0 w0 l1^2/lm as printed, w0^2 = "
                              "lambda_min(W)", "s-1", {}),
    "gamma_theorem5": ("member", "Theorem 5 prefactor |alpha0|_2 sqrt(lm/l1)", RESIDUAL, {}),
    "bound_proven_held": ("trace", "|alpha(t)| <= gamma exp(-beta t) held, proven beta", "1",
                          _HELD),
    "bound_printed_held": ("trace", "|alpha(t)| <= gamma exp(-beta t) held, printed beta",
                           "1", _HELD),
    "theorem5_lambda_min_W": ((), "Theorem 5: min eigenvalue of W = h_v h_v^T near the "
                              "manifold", "1", {}),
    "theorem5_beta_proven": ((), "Theorem 5 rate k0 lambda_min(W) l1^2/lm (proven)", "s-1",
                             {}),
    "theorem5_beta_printed": ((), "Theorem 5 rate as printed", "s-1", {}),
    "theorem5_gamma_factor": ((), "Theorem 5 factor sqrt(lm/l1)", "1", {}),
    "path_spectral_radius_max": ((), "max spectral radius of R_k along the path", "1", {}),
    "path_norm_weighted_max": ((), "max weighted norm of R_k along the path", "1", {}),
    "path_epsilon": ((), "floor implied by condition 4 along the path (max-norm)", RESIDUAL,
                     {}),
    # --- Theorems 6/7 along one trajectory (theory.along_path)
    "path_spectral_radius": ("step", "spectral radius of R_k", "1", {}),
    "path_norm_max": ("step", "max-norm of R_k", "1", {}),
    "path_norm_2": ("step", "2-norm of R_k", "1", {}),
    "path_norm_weighted": ("step", "norm of R_k in the path weight P", "1", {}),
    "path_remainder": ("step", "max-norm of g_{k+1} - R_k g_k", RESIDUAL, {}),
    "path_residual_norm": ("step", "max-norm of g along the path", RESIDUAL, {}),
    "path_q": ((), "max_k of the weighted norm of R_k", "1", {}),
    "path_bound_start": ((), "|P^-1| |P g0|: the bound's start", RESIDUAL, {}),
}  # fmt: skip


#: the datasets each variable appears in (for the generated reference page)
_GROUPS = (
    ("One trajectory: `integrate`, `integrate_adaptive` (`multiplier`, `acceleration` with "
     "`with_multipliers=True`)", ("x", "residual", "residual_norm", "energy", "multiplier",
                                  "acceleration")),
    ("An ensemble: `ensemble` (and per grid point, `stabdae run`)", (
        "residual_norm", "alpha0", "alpha0_norm", "x0", "x_final", "beta", "beta_reason",
        "gamma", "residual_floor", "floor_reached", "max_residual", "final_residual",
        "overshoot", "fit_start", "fit_end", "fit_points", "fit_kind", "beta_predicted",
        "beta_ratio", "verdict", "verdict_reason", "stability_class", "stable", "bounded",
        "diverged", "diverged_step", "status", "steps_accepted", "rhs_evaluations",
        "energy_drift", "fraction_stable", "fraction_stable_low", "fraction_stable_high",
        "fraction_unstable", "fraction_unstable_low", "fraction_unstable_high",
        "fraction_undecided", "fraction_undecided_low", "fraction_undecided_high",
        "fraction_bounded", "fraction_bounded_low", "fraction_bounded_high",
        "stability_radius", "stability_radius_low", "stability_radius_high",
        "stability_radius_reason", "beta_median", "beta_median_low", "beta_median_high",
        "beta_median_coverage", "beta_ratio_median", "members_run", "members_stable",
        "members_unstable", "members_undecided", "members_bounded", "members_diverged",
        "members_growing", "members_with_beta", "reference_status", "reference_stop_time",
        "reference_exceeds_epsilon_time", "decision", "decision_reason",
        "decision_low", "decision_high", "members_used",
        "overshoot_theory", "beta_theory", "beta_theory_discrete",
        "spectral_radius", "norm_max", "norm_weighted", "norm_condition", "lambda_min_W",
        "beta_theorem5_proven", "beta_theorem5_printed", "gamma_theorem5",
        "bound_proven_held", "bound_printed_held")),
    ("The theory of a study's grid: `stabdae theory` (and `path_*` in `stabdae run` with a "
     "state-dependent law)", (
        "beta_theory", "beta_theory_discrete", "spectral_radius", "norm_max", "norm_2",
        "norm_weighted", "norm_condition", "lyapunov_holds", "beta_lyapunov",
        "tau_limit_spectral", "tau_limit_max_norm", "tau_limit_two_norm",
        "tau_limit_weighted_norm", "theorem5_lambda_min_W", "theorem5_beta_proven",
        "theorem5_beta_printed", "theorem5_gamma_factor", "path_spectral_radius_max",
        "path_norm_weighted_max", "path_epsilon")),
    ("A boundary search: `boundary` (and per grid point, `stabdae run` with `[search]`)", (
        "tau_star", "tau_star_low", "tau_star_high", "tau_star_reason", "tau_star_confidence",
        "fraction_stable",
        "fraction_stable_low", "fraction_stable_high", "members_run", "members_stable",
        "members_unstable", "members_undecided", "members_diverged", "members_growing",
        "tau_limit_spectral", "tau_limit_weighted_norm", "tau_limit_floor", "spectral_radius",
        "probe_tau", "probe_members", "probe_fraction_stable", "probe_stable",
        "probe_verdict", "probe_stage", "probe_motion_unstable")),
    ("Theorems 6/7 along a trajectory: `theory.along_path` (the variables drop the `path_` "
     "prefix)", ("path_spectral_radius", "path_norm_max", "path_norm_2", "path_norm_weighted",
                 "path_remainder", "path_residual_norm", "path_q", "path_bound_start")),
)  # fmt: skip
_MARKER_TEXT = {
    STATE: "per state entry (`state_units`)",
    COMPONENT: "per residual component (`component_units`)",
    RESIDUAL: "the constraints' unit (`1` where they differ: each component divided by "
              "its unit)",
    ENERGY: "the model's `energy_units`",
    MULTIPLIER: "per constraint (`multiplier_units`: energy per constraint unit)",
    ACCELERATION: "per coordinate (`acceleration_units`)",
}


def schema_markdown() -> str:
    """The reference page of :data:`SCHEMA` (``docs/schema.md`` is this text; a test
    keeps them equal)."""
    out = [
        "# Dataset schema",
        "",
        "Generated from `stabdae._schema.SCHEMA` (a test checks that this page matches it).",
        "Units are UDUNITS strings.  In memory, a variable whose entries have different",
        "units (the state `x = (q, v)`, the residual `g = (f, ḟ, h)`) has no `units`",
        "attribute but `units_per_component`, naming the coordinate (`state_units`,",
        "`component_units`) that holds each entry's unit, from the model's",
        "`coordinate_units` and `constraint_units`.  In a file written by",
        "`stabdae.write_netcdf` it is one variable per entry (`x__theta`, each with its",
        "`units` and `stacked_from = \"x\"`), as CF has it; `stabdae.open_dataset` stacks",
        "them again.  A norm over residual components of different units (the pendulum's",
        "f in m² and ḟ in m² s-1) is the norm of g with each component divided by its unit,",
        "a pure number: unit `1`, and a `comment` that says so.",
        "Every dataset has `created_at` (`YYYY-MM-DDThh:mm:ssZ`, UTC)",
        "and a `history` with one line per action (`<time>: <action> (stabdae <version>)`).",
        "An ensemble stores " + ", ".join(f"`{n}`" for n in SINGLE_PRECISION) + " in single",
        "precision (seven digits: more than any of them is measured to) and its counts",
        "(" + ", ".join(f"`{n}`" for n in COUNTS) + ") as 32-bit integers; `x0` and `x_final`",
        "are left out with `states=False` (a study's default).",
    ]
    for title, names in _GROUPS:
        out += ["", f"## {title}", "", "| name | dims | units | meaning |", "|---|---|---|---|"]
        for name in names:
            dims, long_name, units, _ = SCHEMA[name]
            dims = (dims,) if isinstance(dims, str) else dims
            if title.startswith("The theory of a study"):
                dims = ("grid axes",)
            elif title.startswith("One trajectory"):
                dims = tuple(d for d in dims if d != "member")
            shown = name.removeprefix("path_") if title.startswith("Theorems 6/7") else name
            unit = _MARKER_TEXT.get(units, f"`{units}`")
            meaning = long_name.replace("|", "\\|")
            out.append(f"| `{shown}` | ({', '.join(dims)}) | {unit} | {meaning} |")
    out += ["", "## Codes", "",
            "Every integer code a dataset stores, with its message (`stabdae._codes`; each",
            "code variable's `flag_values` and `flag_meanings` come from the same table)."]
    for variable, family in _CODE_VARIABLES:
        out += ["", f"### `{variable}` — `{family.__name__}`", "", "| value | name | meaning |",
                "|---|---|---|"]
        out += [f"| {int(c)} | `{c.name}` | {c.message.replace('|', chr(92) + '|')} |"
                for c in family]
    return "\n".join(out) + "\n"


#: the stored code variables and their families, as the schema page lists them
_CODE_VARIABLES = (("status", Status), ("beta_reason", BetaReason), ("fit_kind", FitKind),
                   ("verdict", Verdict), ("verdict_reason", VerdictReason),
                   ("decision", Verdict), ("decision_reason", DecisionReason),
                   ("stability_class", StabilityClass), ("reference_status", Status),
                   ("stability_radius_reason", RadiusReason),
                   ("tau_star_reason", TauStarReason), ("probe_stage", ProbeStage),
                   ("delta_star_reason", ProfileReason))  # fmt: skip


# --------------------------------------------------------------------- units
_UNIT_SYMBOLS = {
    "1", "m", "s", "kg", "g", "rad", "sr", "deg", "degree", "N", "J", "W", "Pa", "Hz", "K",
    "A", "V", "C", "mol", "cd", "min", "h", "day", "percent", "km", "cm", "mm", "um", "nm",
    "ms", "us", "ns", "kJ", "kN", "kW", "MPa", "kPa", "L", "l",
}  # fmt: skip
_FACTOR = re.compile(r"^([A-Za-z]+|1)(?:(?:\^|\*\*)?(-?\d+))?$")


def udunits_ok(units: str) -> bool:
    """Whether ``units`` is a UDUNITS product of known symbols with integer powers
    (``"1"``, ``"m2 s-1"``, ``"kg m^2"``, ``"m/s"``).  A check of the strings this library
    writes and models declare, not a parser of the whole UDUNITS grammar."""
    if not isinstance(units, str) or not units.strip():
        return False
    for part in re.split(r"\s*/\s*", units.strip()):
        if not part:
            return False
        for factor in re.split(r"[\s.*]+", part):
            m = _FACTOR.match(factor)
            if m is None or m.group(1) not in _UNIT_SYMBOLS:
                return False
    return True


def _common(units) -> str | None:
    units = set(units)
    return units.pop() if len(units) == 1 else None


#: markers of variables whose entries each have their own unit -> the model property (and
#: the dataset coordinate of the same name) that lists them
_PER_ENTRY = {STATE: "state_units", COMPONENT: "component_units", RESIDUAL: "component_units",
              MULTIPLIER: "multiplier_units", ACCELERATION: "acceleration_units"}  # fmt: skip


def _resolve_units(marker: str, model) -> dict:
    """The units attributes of a variable: ``{"units": ...}``, or for a mixed variable
    ``{"units_per_component": <coordinate>}``."""
    if marker == ENERGY:
        return {"units": getattr(model, "energy_units", "1")}
    coord = _PER_ENTRY.get(marker)
    if coord is None:
        return {"units": marker}
    common = _common(getattr(model, coord)) if model is not None else None
    if common:
        return {"units": common}
    if marker == RESIDUAL:
        # a norm over components of different units is the norm of the vector whose
        # entries are g_i / [g_i], each component divided by its declared unit: a pure
        # number (what every stored norm's value is), the way a solver's error norm
        # divides each component by its tolerance
        return {"units": "1", "comment_units": MIXED_NORM}
    return {"units_per_component": coord}


#: what a norm over residual components of different units is (its ``comment``)
MIXED_NORM = ("a norm over components of different units (component_units): of g with "
              "each component divided by its unit, a pure number")


def variable(dims, data, long_name: str, units: str | None, **attrs) -> xr.Variable:
    """An ``xr.Variable`` with the CF attributes every stabdae variable has."""
    head = {"long_name": long_name}
    if units is not None:
        head["units"] = units
    return xr.Variable(dims, data, attrs={**head, **attrs})


#: coordinate names of stabdae's datasets (beside the variables of :data:`SCHEMA`)
_COORDINATES = ("time", "member", "trace", "state", "state_units", "component",
                "component_units", "coordinate", "constraint", "acceleration_units",
                "multiplier_units", "probe", "point")  # fmt: skip


def reserved_names() -> set[str]:
    """Names a model's derived outputs may not take: the datasets' own variables and
    coordinates."""
    return set(SCHEMA) | set(_COORDINATES)


def output_entries(model, values, dims, suffix: str = "", comment: str = "") -> dict:
    """The model's derived outputs as variables ``(dims, values[..., j], attrs)``, one per
    name (``<name><suffix>``), with its own units."""
    out = {}
    for j, (name, unit) in enumerate(zip(model.output_names, model.output_units)):
        attrs = {"long_name": f"{name}: a derived output of the model{comment}", "units": unit}
        out[f"{name}{suffix}"] = (dims, values[..., j], attrs)
    return out


def schema_variable(name: str, data, model=None, dims=None, key: str | None = None
                    ) -> xr.Variable:  # fmt: skip
    """Variable ``name`` of :data:`SCHEMA` (entry ``key``, default ``name``) holding
    ``data``; ``dims`` replaces the schema's (a study grid's axes)."""
    return xr.Variable(*schema_entry(name, data, model, dims, key))


def schema_entry(name: str, data, model=None, dims=None, key: str | None = None) -> tuple:
    """:func:`schema_variable` as ``(dims, data, attrs)``, without building the
    ``xarray.Variable``."""
    sdims, long_name, marker, extra = SCHEMA[name if key is None else key]
    attrs = {"long_name": long_name, **_resolve_units(marker, model), **extra}
    if "comment" in extra and "comment_units" in attrs:
        attrs["comment"] = f"{extra['comment']}; {attrs.pop('comment_units')}"
    elif "comment_units" in attrs:
        attrs["comment"] = attrs.pop("comment_units")
    return (sdims if dims is None else dims), data, attrs


def component_coords(model) -> dict:
    """The residual components and their units (what ``units_per_component`` of a residual
    variable names)."""
    return {
        "component": variable(
            "component", model.component_names, "residual component g = (f, fdot, h) (3.2)",
            None,
        ),
        "component_units": variable("component", model.component_units,
                                    "units of each residual component", None),
    }  # fmt: skip


def units_quotient(numerator: str, denominator: str) -> str:
    """``numerator / denominator`` as a product of UDUNITS factors with integer powers
    (``"J", "m s-1" -> "J m-1 s"``)."""
    powers: dict[str, int] = {}
    for text, sign in ((numerator, 1), (denominator, -1)):
        for factor in re.split(r"[\s.*]+", text.strip()):
            m = _FACTOR.match(factor)
            if m is None or m.group(1) == "1":
                continue
            powers[m.group(1)] = powers.get(m.group(1), 0) + sign * int(m.group(2) or 1)
    out = [f"{u}{'' if k == 1 else k}" for u, k in powers.items() if k]
    return " ".join(out) or "1"


def mechanics_coords(model) -> dict:
    """The coordinates and constraints, and the units of the accelerations and
    multipliers, for the optional ``acceleration`` and ``multiplier`` variables."""
    return {
        "coordinate": variable("coordinate", list(model.coordinates), "generalized coordinate",
                               None),
        "acceleration_units": variable("coordinate", model.acceleration_units,
                                       "units of each acceleration", None),
        "constraint": variable("constraint", model.multiplier_names,
                               "constraint of each multiplier (f_i, then h_j)", None),
        "multiplier_units": variable("constraint", model.multiplier_units,
                                     "units of each multiplier", None),
    }  # fmt: skip


def model_coords(model, times) -> dict:
    """Coordinates every stabdae dataset of a model shares: time, state, component, and
    the units of each state and residual component."""
    return {
        "time": variable("time", times, "time", "s"),
        "state": variable("state", model.state_names, "state component x = (q, v)", None),
        "state_units": variable("state", model.state_units, "units of each state component",
                                None),
        **component_coords(model),
    }  # fmt: skip


# --------------------------------------------------------------------- provenance
def utc_now() -> str:
    """The current time, as every stabdae timestamp writes it: ``2026-11-23T01:16:57Z``."""
    return _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


def append_history(attrs: dict, action: str) -> dict:
    """Add ``"<time>: <action> (stabdae <version>)"`` as a new line of ``attrs["history"]``
    (CF: one line per action, oldest first); returns ``attrs``."""
    line = f"{utc_now()}: {action} (stabdae {__version__})"
    old = attrs.get("history")
    attrs["history"] = f"{old}\n{line}" if old else line
    return attrs


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


def provenance(model, p: np.ndarray | None, law, scheme, action: str, **run) -> dict:
    """Global attributes: what produced a dataset (model, parameters, law, scheme, run),
    when (``created_at``), and its ``history`` started with ``action``."""
    attrs = {
        "Conventions": "CF-1.10",
        "title": f"stabdae: {model.name}",
        "source": f"stabdae {__version__}",
        "stabdae_version": __version__,
        "created_at": utc_now(),
        "model": model.name,
        "model_n": model.n,
        "model_m": model.m,
        "model_k": model.k,
        "model_param_names": " ".join(model.param_names),
        # 1: the library's multiply-adds were fused (engine.fma); results differ at
        # roundoff from a machine without FMA, which computes them with two roundings
        "fused_multiply_add": int(HOST_FMA),
        # 1: compiled for 512-bit SIMD vectors (the same bits as with 256: speed only)
        "prefer_512_bit_vectors": int(PREFER_512),
    }
    if p is not None:
        attrs.update(flat_attrs("model_param_", dict(zip(model.param_names, p.tolist()))))
    if law is not None:
        law_attrs = law.attrs()
        attrs["law"] = law_attrs.pop("law")
        attrs.update(flat_attrs("law_", law_attrs))
    if scheme is not None:
        attrs.update(flat_attrs("", scheme.attrs()))
    attrs.update(flat_attrs("", run))
    attrs["history"] = f"{attrs['created_at']}: {action} (stabdae {__version__})"
    return attrs


# --------------------------------------------------------------------- datasets
def trajectory_dataset(model, p, law, scheme, times, xs, gs, es, status, done, run, *,
                       action: str, multipliers=None) -> xr.Dataset:  # fmt: skip
    """The dataset of one trajectory: ``x``, ``residual``, ``residual_norm``, ``energy``, and
    with ``multipliers = (λ, v̇)`` also ``multiplier`` and ``acceleration``."""
    data = {
        "x": schema_variable("x", xs, model),
        "residual": schema_variable("residual", gs, model),
        "residual_norm": schema_variable("residual_norm", np.max(np.abs(gs), axis=1), model,
                                         dims="time"),
    }  # fmt: skip
    data["residual_norm"].attrs["comment"] = "NaN after a stop"
    if model.energy is not None:
        data["energy"] = schema_variable("energy", es, model)
    if model.outputs is not None:
        data.update(output_entries(model, model.derived(xs, times, p), ("time",)))
    coords = model_coords(model, times)
    if multipliers is not None:
        data["multiplier"] = schema_variable("multiplier", multipliers[0], model)
        data["acceleration"] = schema_variable("acceleration", multipliers[1], model)
        coords.update(mechanics_coords(model))
    attrs = provenance(model, p, law, scheme, f"{action}: one trajectory", **run)
    status = Status(status)
    attrs.update(status=int(status), status_name=status.name.lower(), steps_completed=done)
    attrs.update({f"status_{k}": v for k, v in flag_attrs(Status).items()})
    return cf_dataset(data, coords=coords, attrs=attrs)


def write_netcdf(ds: xr.Dataset, path, *, compress: int = 1, overwrite: bool = True) -> Path:
    """Write a stabdae dataset to ``path`` as a CF file, atomically: a temporary file in the
    same folder, then rename.

    Every variable on disk has one unit: a variable whose entries have different units
    (``x``, ``residual``, ``alpha0``, … with ``units_per_component``) is written as one
    variable per entry, ``x__theta`` for entry ``theta`` of ``x``, which
    :func:`open_dataset` stacks again (``xarray.open_dataset`` shows them as they are).
    A reader never sees a half-written file, and a failure leaves any previous file intact.
    Floating-point and integer variables are zlib-compressed at level ``compress`` (with
    the shuffle filter; on the residual traces that make most of a study, level 1 comes
    within a few per cent of level 4's size in less time, and zlib is what every NetCDF
    reader can decode).
    Ctrl-C during the write takes effect once it is done (:func:`deferred_interrupt`).
    """
    with deferred_interrupt():
        return _write_netcdf(ds, path, compress, overwrite)


@contextlib.contextmanager
def deferred_interrupt():
    """Ctrl-C (SIGINT) while the body runs raises ``KeyboardInterrupt`` when it ends, not
    inside it: neither the HDF5 library nor xarray's file locks survive an interrupt in
    the middle of a write (one left xarray's lock held, and the clean-up of the
    interrupted write waited on it forever).  Only in the main thread, where Python runs
    signal handlers; elsewhere the body runs as it is."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        if caught:
            if callable(previous):
                previous(signal.SIGINT, None)  # Python's own handler raises KeyboardInterrupt
            elif previous == signal.SIG_DFL:
                raise KeyboardInterrupt


def cf_dataset(data, coords=None, attrs=None) -> xr.Dataset:
    """``xarray.Dataset(data, coords, attrs)`` as CF wants it on disk, so that its own
    ``to_netcdf`` writes a file CF checkers accept: each code variable's ``flag_values``
    an array of the variable's own type (CF 3.5; also what reading the file back gives),
    and no ``_FillValue`` on coordinate variables (CF 2.5.1: a coordinate has no missing
    values; xarray gives floats one by default)."""
    ds = xr.Dataset(data, coords=coords, attrs=attrs)
    for name, var in ds.variables.items():
        if "flag_values" in var.attrs and var.dtype.kind in "iu":
            var.attrs["flag_values"] = np.asarray(var.attrs["flag_values"], dtype=var.dtype)
        if name in ds.coords and var.dtype.kind in "fiu":
            var.encoding["_FillValue"] = None
    return ds


def _cf_encoded(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` as CF wants it on disk (a shallow copy): a code variable's ``flag_values`` of
    the variable's own type (CF 3.5), and no ``_FillValue`` on coordinate variables (CF
    2.5.1: a coordinate has no missing values)."""
    ds = ds.copy(deep=False)
    for name, var in ds.variables.items():
        if "flag_values" in var.attrs and var.dtype.kind in "iu":
            var.attrs = {**var.attrs,
                         "flag_values": np.asarray(var.attrs["flag_values"], dtype=var.dtype)}
        if name in ds.coords and var.dtype.kind in "fiu":
            var.encoding = {**var.encoding, "_FillValue": None}
    return ds


#: the attributes that tie a variable on disk to the variable with per-entry units it is
#: one entry of (:func:`split_entries`, :func:`open_dataset`)
STACKED = ("stacked_from", "stacked_along", "stacked_axis", "stacked_units")


def split_entries(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` with one variable per entry in place of each variable whose entries have
    different units (``units_per_component``): CF gives a variable one unit, and a variable
    without one is read as a pure number.  Entry ``label`` of ``x`` along ``state`` becomes
    ``x__label``, with its own ``units`` and the attributes of :data:`STACKED` by which
    :func:`open_dataset` stacks the entries again."""
    split = [name for name, var in ds.data_vars.items() if "units_per_component" in var.attrs]
    if not split:
        return ds
    out = {}
    for name in split:
        var = ds[name]
        units_coord = var.attrs["units_per_component"]
        dim = ds[units_coord].dims[0]
        attrs = {k: v for k, v in var.attrs.items() if k != "units_per_component"}
        for i, (label, unit) in enumerate(zip(ds[dim].values, ds[units_coord].values)):
            entry = var.variable.isel({dim: i})
            entry.attrs = {**attrs, "long_name": f"{attrs.get('long_name', name)}: {label}",
                           "units": str(unit), "stacked_from": name, "stacked_along": dim,
                           "stacked_axis": var.dims.index(dim), "stacked_units": units_coord}
            entry.encoding = dict(var.encoding)
            out[f"{name}__{label}"] = entry
    return ds.drop_vars(split).assign(out)


def open_dataset(path, **kwargs) -> xr.Dataset:
    """Open a NetCDF file that stabdae wrote, as the dataset that was written: the
    variables :func:`write_netcdf` stored one entry at a time (``x__theta``, …, each with
    its own ``units``) stacked again into ``x`` along its entry dimension, with
    ``units_per_component`` naming the coordinate that holds each entry's unit.
    ``kwargs`` go to ``xarray.open_dataset``; a file without such variables opens as
    xarray opens it."""
    ds = xr.open_dataset(path, **kwargs)
    groups: dict[str, list[str]] = {}
    for name, var in ds.data_vars.items():
        if "stacked_from" in var.attrs:
            groups.setdefault(var.attrs["stacked_from"], []).append(name)
    stacked = {}
    for name, parts in groups.items():
        head = ds[parts[0]].attrs
        dim = head["stacked_along"]
        labels = [str(v) for v in ds[dim].values]
        by_label = {n.removeprefix(f"{name}__"): n for n in parts}
        if sorted(by_label) != sorted(labels):
            raise ValueError(f"stabdae.open_dataset: {path}: the entries of {name!r} on disk "
                             f"({sorted(by_label)}) are not those of {dim!r} ({labels})")
        entries = [ds[by_label[label]].variable for label in labels]
        var = xr.Variable.concat(entries, dim)
        order = list(entries[0].dims)
        order.insert(int(head["stacked_axis"]), dim)
        var = var.transpose(*order)
        attrs = {k: v for k, v in head.items() if k not in STACKED and k != "units"}
        attrs["long_name"] = str(head["long_name"]).removesuffix(f": {labels[0]}")
        attrs["units_per_component"] = head["stacked_units"]
        var.attrs = attrs
        # how the entries were stored (compression, type), not where or in what shape
        var.encoding = {k: v for k, v in entries[0].encoding.items()
                        if k not in ("chunksizes", "original_shape", "preferred_chunks",
                                     "source")}  # fmt: skip
        stacked[name] = var
    if not stacked:
        return ds
    parts = [n for names in groups.values() for n in names]
    out = ds.drop_vars(parts).assign(stacked)
    out.set_close(ds.close)  # closing what is returned closes the file
    return out


#: variables of more than two dimensions and at least this many bytes are chunked by
#: their leading indices (:func:`write_netcdf`)
_CHUNK_BY_POINT = 1 << 20


def _write_netcdf(ds, path, compress, overwrite) -> Path:
    path = Path(path)
    ds = split_entries(_cf_encoded(ds))
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass overwrite=True (or --force) to replace it")
    path.parent.mkdir(parents=True, exist_ok=True)
    encoding = {}
    for name, var in ds.data_vars.items():
        if var.dtype.kind in "fiu" and var.ndim > 0:
            encoding[name] = {"zlib": True, "complevel": compress, "shuffle": True}
            if var.ndim > 2 and var.nbytes >= _CHUNK_BY_POINT:
                # a study's traces: a chunk per grid point (of its last two dimensions),
                # compressed faster than HDF5's default chunks and read a point at a time
                encoding[name]["chunksizes"] = (1,) * (var.ndim - 2) + var.shape[-2:]
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        try:
            ds.to_netcdf(tmp, engine="netcdf4", encoding=encoding)
        except (OSError, RuntimeError) as exc:  # the HDF5 library says "HDF error", no more
            free = shutil.disk_usage(path.parent).free
            raise OSError(
                f"could not write {path}: {exc} ({free / 2**20:.0f} MiB free in "
                f"{path.parent}: a full disk reads like this)"
            ) from exc
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the file ordinary modes
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
