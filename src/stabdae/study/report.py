"""Tables of a study's grid: the theorems' predictions (``stabdae theory``) and the
measurements beside them (``stabdae run``), one row per grid point."""

from __future__ import annotations

import numpy as np
import xarray as xr

from .._codes import DecisionReason, RadiusReason, Status, TauStarReason, Verdict, VerdictReason
from .._measures import Motion

VERDICT_WORDS = {int(v): v.message for v in Verdict}

__all__ = ["format_table", "grid_table", "summary"]


def format_table(ds: xr.Dataset, columns=None) -> str:
    """A readable table of :func:`for_study`'s dataset, one row per grid point."""
    columns = columns or [v for v in ("spectral_radius", "norm_max", "norm_weighted",
                                      "norm_condition", "beta_theory", "beta_theory_discrete",
                                      "lyapunov_holds", "tau_limit_spectral",
                                      "theorem5_lambda_min_W", "theorem5_beta_proven",
                                      "theorem5_beta_printed", "path_spectral_radius_max",
                                      "path_norm_weighted_max", "path_epsilon")
                          if v in ds]  # fmt: skip
    short = {"spectral_radius": "rho(R)", "norm_max": "|R|max", "norm_weighted": "|R|P",
             "norm_condition": "cond", "beta_theory": "beta", "beta_theory_discrete":
             "beta_disc", "lyapunov_holds": "Lyap", "tau_limit_spectral": "tau_lim",
             "theorem5_lambda_min_W": "lmin(W)", "theorem5_beta_proven": "b_proven",
             "theorem5_beta_printed": "b_printed", "path_spectral_radius_max": "rho_path",
             "path_norm_weighted_max": "q_path", "path_epsilon": "eps_path"}  # fmt: skip
    return grid_table(ds, columns, short, flags=("norm_condition", "lyapunov_holds"),
                      precise=("norm_weighted", "spectral_radius", "path_norm_weighted_max"))


def _censored(values: dict, c: str, i: int) -> str:
    """A censored statistic ``c`` (δ*) as read: its value with its bracket, ``> low`` or
    ``< high`` where the sample bounds it from one side only, ``none`` where it holds no
    decided member (``c_low``, ``c_high``, ``c_reason``, :class:`RadiusReason`)."""
    low, high = float(values[f"{c}_low"][i]), float(values[f"{c}_high"][i])
    why = int(values[f"{c}_reason"][i])
    if why == int(RadiusReason.BRACKETED):
        return f"{float(values[c][i]):.4g} [{low:.4g}, {high:.4g}]"
    if why == int(RadiusReason.ABOVE_SAMPLE):
        return f"> {low:.4g}"
    if why == int(RadiusReason.BELOW_SAMPLE):
        return f"< {high:.4g}"
    return "none"


def grid_table(ds: xr.Dataset, columns, short: dict, *, flags=(), precise=(),
               codes=None, censored=()) -> str:  # fmt: skip
    """One row per grid point of ``ds`` (its swept dimensions first, then ``columns``,
    headed by ``short`` names): ``flags`` as yes/no, ``codes`` (column → {code: word}) as
    words, ``censored`` as :func:`_censored` reads them (where ``ds`` holds their bracket
    and reason), ``precise`` with 6 digits (the ones that decide "< 1"), the rest with
    4."""
    codes = codes or {}
    censored = [c for c in censored if c in columns
                and all(f"{c}_{s}" in ds for s in ("low", "high", "reason"))]
    extra = [f"{c}_{s}" for c in censored for s in ("low", "high", "reason")]
    dims = list(ds[columns[0]].dims)
    names = [*columns, *extra]
    flat = ds[names].stack(point=dims) if dims else ds[names].expand_dims(point=[0])
    head = [d.split(".", 1)[-1] for d in dims] + [short.get(c, c) for c in columns]
    values = {k: flat[k].values for k in [*dims, *names]}  # (xarray's indexing per cell
    rows = []                                               # was most of the table's time)
    for i in range(flat.sizes["point"]):
        row = [f"{float(values[d][i]):.4g}" for d in dims]
        for c in columns:
            v = float(values[c][i])
            if c in censored:
                row.append(_censored(values, c, i))
            elif c in flags:
                row.append("yes" if v == 1 else "no")
            elif c in codes:
                row.append(codes[c].get(int(v), str(v)))
            else:
                row.append(f"{v:.6g}" if c in precise else f"{v:.4g}")
        rows.append(row)
    width = [max(len(h), *(len(r[j]) for r in rows)) for j, h in enumerate(head)]
    lines = ["  ".join(h.rjust(w) for h, w in zip(head, width))]
    lines += ["  ".join(x.rjust(w) for x, w in zip(r, width)) for r in rows]
    return "\n".join(lines)


def summary(ds: xr.Dataset) -> str:
    """Per grid point: fractions stable, undecided and bounded, δ*, median β (with the members that
    have one) beside the predictions; for a boundary search, τ* with its bracket beside
    the theory's limits."""
    if "tau_star" in ds:
        cols = ["tau_star", "tau_star_low", "tau_star_high", "tau_limit_floor",
                "tau_limit_spectral", "spectral_radius", "fraction_stable"]  # fmt: skip
        cols += ["tau_star_reason"] if "tau_star_reason" in ds else []
        short = {"tau_star": "tau*", "tau_star_low": "low", "tau_star_high": "high",
                 "tau_limit_floor": "tau_floor", "tau_limit_spectral": "tau_spectral",
                 "spectral_radius": "rho(tau*)", "fraction_stable": "stable",
                 "tau_star_reason": "how"}  # fmt: skip
        head = ("boundary (tau*: largest stable step, between low (stable with the full "
                "ensemble) and high; tau_floor: Theorems 6/7 with the floor the local error "
                "forces; tau_spectral: rho(R) = 1; how: tau_star_reason, "
                "bracketed_by_motion: at high the unperturbed run itself diverges or "
                "leaves epsilon):")  # fmt: skip
        if "tau_star_confidence" in ds and np.isfinite(ds.tau_star_confidence.values).any():
            conf = float(np.nanmin(ds.tau_star_confidence.values))
            head = head[:-2] + (f"; the probes decided at confidence {conf:g} all together: "
                                "the boundary lies between low and high with at least that "
                                "probability):")  # fmt: skip
        return "\n" + head + "\n" + grid_table(
            ds, cols, short, precise=cols[:5],
            codes={"tau_star_reason": {int(c): c.name.lower() for c in TauStarReason}}) + "\n"
    cols = [c for c in ("decision", "members_used",
                        "fraction_stable", "fraction_unstable", "fraction_undecided",
                        "fraction_bounded",
                        "stability_radius",
                        "beta_median", "members_with_beta", "beta_ratio_median",
                        "beta_theory_discrete", "spectral_radius", "norm_condition",
                        "beta_theorem5_proven", "beta_theorem5_printed") if c in ds]  # fmt: skip
    short = {"decision": "decision", "members_used": "n",
             "fraction_stable": "stable", "fraction_unstable": "unstable",
             "fraction_undecided": "undecided",
             "fraction_bounded": "bounded",
             "stability_radius": "delta*", "beta_median": "beta_med",
             "members_with_beta": "n_beta", "beta_ratio_median": "meas/lin",
             "beta_theory_discrete": "beta_pred", "spectral_radius": "rho(R)",
             "norm_condition": "cond", "beta_theorem5_proven": "b5_proven",
             "beta_theorem5_printed": "b5_printed"}  # fmt: skip
    head = ("summary (" + ("decision: the grid point's, at the stated confidence (see "
                           "decision_reason), after n members; " if "decision" in ds else "")
            + "stable, unstable, undecided, bounded: fractions of members "
            "(undecided: the run "
            "cannot tell, see verdict_reason); delta*: stability radius [its bracket], "
            "'> x' or '< x' where the sample bounds it from one side only; "
            "n_beta: members with a measured beta; meas/lin: median of measured over the "
            "linear prediction's beta; beta_pred = -ln rho(R)/tau):")  # fmt: skip
    table = grid_table(ds, cols, short, flags=("norm_condition",),
                       codes={"decision": VERDICT_WORDS}, censored=("stability_radius",))
    return "\n" + head + "\n" + table + "\n" + unstable_below_one(ds) + undecided_points(ds)


def _epsilon(ds: xr.Dataset, arrays: dict, i: int) -> float:
    """ε at the ``i``-th grid point: swept (``run.epsilon``) or the study's one."""
    for name in ("run.epsilon", "epsilon"):
        if name in arrays:
            return float(arrays[name][i])
    return float(ds.attrs.get("epsilon", np.nan))


def unstable_below_one(ds: xr.Dataset) -> str:
    """A note per grid point whose law is stable in the linear theory (``ρ(R) < 1``) but
    whose members are not all stable: how many are unstable, and why (the counts of
    their ``verdict_reason``); empty where there is none."""
    if not {"spectral_radius", "verdict", "verdict_reason"} <= set(ds.variables):
        return ""
    dims = list(ds.spectral_radius.dims)
    flat = ds[["spectral_radius", "verdict", "verdict_reason"]
              + [v for v in ("status", "reference_status", "reference_stop_time",
                             "reference_exceeds_epsilon_time") if v in ds]]  # fmt: skip
    flat = flat.stack(point=dims) if dims else flat.expand_dims(point=[0])
    lines, singular = [], False
    # every variable's values with the point first, once (not xarray's indexing per point)
    arrays = {k: flat[k].transpose("point", ...).values for k in flat.variables
              if k in flat.data_vars or k in dims}  # fmt: skip
    for i in range(flat.sizes["point"]):
        rho = float(arrays["spectral_radius"][i])
        verdict = arrays["verdict"][i]
        unstable = verdict == int(Verdict.UNSTABLE)
        if not (rho < 1.0) or not unstable.any():
            continue
        where = ", ".join(f"{d.split('.', 1)[-1]} = {float(arrays[d][i]):.4g}"
                          for d in dims)  # fmt: skip
        reasons, counts = np.unique(arrays["verdict_reason"][i][unstable],
                                    return_counts=True)  # fmt: skip
        why = [f"{c} {VerdictReason(int(r)).message.split(':')[0]}"
               for r, c in zip(reasons, counts)]  # fmt: skip
        ran = verdict.size
        if "status" in flat:  # (a grid point run until decided: its own members only)
            status = arrays["status"][i]
            ran = int((status != int(Status.NOT_NEEDED)).sum())
            blew = status[unstable & (arrays["verdict_reason"][i]
                                      == int(VerdictReason.BLEW_UP))]  # fmt: skip
            if blew.size:  # how they stopped: a singular S is not the scheme's remainder
                how, many = np.unique(blew, return_counts=True)
                singular = singular or int(Status.SINGULAR_S) in how
                k = [int(r) for r in reasons].index(int(VerdictReason.BLEW_UP))
                why[k] += ": " + ", ".join(f"{c} {Status(int(s)).short}"
                                           for s, c in zip(how, many))  # fmt: skip
        if int(VerdictReason.MOTION_UNSTABLE) in reasons and "reference_status" in arrays:
            k = [int(r) for r in reasons].index(int(VerdictReason.MOTION_UNSTABLE))
            motion = Motion(int(arrays["reference_status"][i]),
                            float(arrays["reference_stop_time"][i]),
                            float(arrays["reference_exceeds_epsilon_time"][i]))
            why[k] += ": " + motion.describe(_epsilon(ds, arrays, i))
        why = "; ".join(why)
        lines.append(f"  {where}: rho(R) = {rho:.4g} < 1, yet {int(unstable.sum())} of "
                     f"{ran} members unstable ({why})")
    if not lines:
        return ""
    cause = ("what grows there is the rest of the step, the scheme's remainder on the motion "
             "that Theorems 6/7 bound, not the law")
    if singular:
        cause += ("; members that stopped at a singular S met a configuration where the "
                  "constraints lose rank, which the theorems exclude")
    return (f"\nunstable where the law's linear part is stable (rho(R) < 1: {cause}):\n"
            + "\n".join(lines) + "\n")


def undecided_points(ds: xr.Dataset) -> str:
    """A note per grid point whose decision is undecided: its ``decision_reason`` (where
    the point was run until decided) and its undecided members' ``verdict_reason`` counts,
    the most frequent first, over the members it ran; empty where every point is
    decided."""
    if not {"decision", "verdict", "verdict_reason"} <= set(ds.variables):
        return ""
    dims = list(ds.decision.dims)
    names = ["decision", "verdict", "verdict_reason"] + [
        v for v in ("decision_reason", "status") if v in ds]
    flat = ds[names].stack(point=dims) if dims else ds[names].expand_dims(point=[0])
    arrays = {k: flat[k].transpose("point", ...).values for k in flat.variables
              if k in flat.data_vars or k in dims}  # fmt: skip
    lines = []
    for i in range(flat.sizes["point"]):
        if int(arrays["decision"][i]) != int(Verdict.UNDECIDED):
            continue
        where = ", ".join(f"{d.split('.', 1)[-1]} = {float(arrays[d][i]):.4g}"
                          for d in dims)  # fmt: skip
        verdict = arrays["verdict"][i]
        ran = np.ones(verdict.shape, dtype=bool)
        if "status" in arrays:  # (a grid point run until decided: its own members only)
            ran = arrays["status"][i] != int(Status.NOT_NEEDED)
        undecided = ran & (verdict == int(Verdict.UNDECIDED))
        reasons, counts = np.unique(arrays["verdict_reason"][i][undecided],
                                    return_counts=True)  # fmt: skip
        order = np.lexsort((reasons, -counts))
        why = "; ".join(f"{counts[k]} {VerdictReason(int(reasons[k])).message.split(':')[0]}"
                        for k in order)  # fmt: skip
        head = (DecisionReason(int(arrays["decision_reason"][i])).message.split(":")[0]
                if "decision_reason" in arrays else "undecided")  # fmt: skip
        tail = f": {why}" if why else ""
        lines.append(f"  {where}: {head} ({int(undecided.sum())} of {int(ran.sum())} "
                     f"members undecided{tail})")
    if not lines:
        return ""
    return ("\nundecided grid points (the decision's reason; the undecided members' "
            "verdict_reason):\n" + "\n".join(lines) + "\n")
