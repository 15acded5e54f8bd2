"""The stability radius as a profile: the probability that a member is stable, by the size
of its initial perturbation.

``δ*`` from one ensemble's sample (``stability_radius``: between the largest ``‖α⁰‖∞`` up
to which every member was stable and the smallest that was not) is one order statistic,
and a single member judged wrongly, or none sampled near it, moves it.
:func:`radial_profile` instead bins the members by ``‖α⁰‖∞`` (log-spaced bins over the
ensemble's radius range) and gives in each bin the fraction stable with an exact
Clopper–Pearson interval, all bins' intervals holding together at the stated confidence
(each side of each bin at level ``(1 − confidence)/(2B)``: a Bonferroni split).  A member
whose verdict is *undecided* counts against stability for the lower end and for it for
the upper end.

``δ*`` is then bracketed at the bins' resolution: its low end is the top of the leading
run of bins whose fraction stable is shown to be at least ``1 − q``; its high end the top
of the first bin above them shown to be below ``1 − q`` (some radius in it is not stable
that often).  Where no bin is shown below, or none above, the bracket is open on that side
and ``delta_star_reason`` says why.
"""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from ._codes import ProfileReason, Status, Verdict
from ._schema import cf_dataset, schema_variable, variable
from ._sequential import bounds

__all__ = ["paired_difference", "radial_profile"]


def radial_profile(ds: xr.Dataset, bins: int = 10, *, q: float = 0.05,
                   confidence: float = 0.95, radius=None) -> xr.Dataset:  # fmt: skip
    """The fraction of stable members by perturbation size, and ``δ*`` bracketed from it.

    Parameters
    ----------
    ds : xarray.Dataset
        An ensemble (:func:`stabdae.ensemble`), or one grid point of a study
        (``study.sel(tau=..., omega=...)``): its ``alpha0_norm`` and ``verdict`` per member.
    bins : int
        Log-spaced bins of ``‖α⁰‖∞`` over ``radius``.
    q : float
        ``δ*`` is the largest radius up to which at least ``1 − q`` of the members are
        stable.
    confidence : float
        Every bin's interval holds, together with all the others, with at least this
        probability.
    radius : (low, high), optional
        The range binned (default the ensemble's ``radius_low``, ``radius_high``).

    Returns
    -------
    xarray.Dataset
        Per bin (dimension ``radius_bin``, its ends ``radius_low``, ``radius_high``):
        ``members``, ``members_stable``, ``members_unstable``, ``fraction_stable`` with
        ``fraction_stable_low`` and ``fraction_stable_high``; ``delta_star_low``,
        ``delta_star_high`` and ``delta_star_reason``.
    """
    who = "radial_profile"
    missing = {"alpha0_norm", "verdict"} - set(ds.variables)
    if missing:
        raise ValueError(f"{who}: the dataset has no {', '.join(sorted(missing))}: it is not "
                         "an ensemble (or one grid point of a study)")  # fmt: skip
    if ds["verdict"].dims != ("member",):
        raise ValueError(f"{who}: expected one ensemble (verdict over member), got verdict "
                         f"over {ds['verdict'].dims}: select one grid point first, e.g. "
                         "study.isel(tau=0, omega=0)")  # fmt: skip
    if isinstance(bins, bool) or not isinstance(bins, (int, np.integer)) or bins < 1:
        raise ValueError(f"{who}: bins must be a positive integer, got {bins!r}")
    for name, x in (("q", q), ("confidence", confidence)):
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not 0.0 < x < 1.0:
            raise ValueError(f"{who}: {name} must be a number between 0 and 1, got {x!r}")
    if radius is None:
        radius = (ds.attrs.get("radius_low"), ds.attrs.get("radius_high"))
        if radius[0] is None or radius[1] is None:
            raise ValueError(f"{who}: the dataset has no radius_low, radius_high attributes: "
                             "give radius=(low, high)")  # fmt: skip
    low, high = float(radius[0]), float(radius[1])
    if not 0.0 < low < high:
        raise ValueError(f"{who}: radius must be (low, high) with 0 < low < high, got "
                         f"{radius!r}")  # fmt: skip
    ran = np.ones(ds.sizes["member"], dtype=bool)
    if "status" in ds:  # a study's padding: members the grid point did not run
        ran = ds["status"].values != int(Status.NOT_NEEDED)
    norm = ds["alpha0_norm"].values[ran]
    verdict = ds["verdict"].values[ran]
    edges = np.geomspace(low, high, int(bins) + 1)
    edges[-1] = high * (1 + 1e-12)  # the largest member belongs to the last bin
    which = np.searchsorted(edges, norm, side="right") - 1
    edges[-1] = high
    level = (1.0 - confidence) / (2 * int(bins))
    cols = {k: np.zeros(bins) for k in ("members", "members_stable", "members_unstable",
                                        "fraction_stable", "fraction_stable_low",
                                        "fraction_stable_high")}  # fmt: skip
    for b in range(bins):
        v = verdict[which == b]
        n, k = v.size, int((v == int(Verdict.STABLE)).sum())
        u = int((v == int(Verdict.UNSTABLE)).sum())
        cols["members"][b], cols["members_stable"][b], cols["members_unstable"][b] = n, k, u
        if n == 0:
            lo_b = hi_b = frac = math.nan
        else:
            frac = k / n
            lo_b = bounds(k, n, level)[0]  # undecided counted as not stable
            hi_b = bounds(n - u, n, level)[1]  # ... and as stable
        cols["fraction_stable"][b] = frac
        cols["fraction_stable_low"][b], cols["fraction_stable_high"][b] = lo_b, hi_b
    d_low, d_high, why = _bracket(edges, cols["fraction_stable_low"],
                                  cols["fraction_stable_high"], 1.0 - q)  # fmt: skip
    dims = "radius_bin"
    data = {
        "members": variable(dims, cols["members"].astype(np.int32), "members in the bin", "1"),
        "members_stable": variable(dims, cols["members_stable"].astype(np.int32),
                                   "stable members in the bin", "1"),
        "members_unstable": variable(dims, cols["members_unstable"].astype(np.int32),
                                     "unstable members in the bin", "1"),
        "fraction_stable": variable(dims, cols["fraction_stable"],
                                    "fraction of the bin's members stable", "1"),
        "fraction_stable_low": variable(dims, cols["fraction_stable_low"],
                                        "exact interval of fraction_stable, low (undecided "
                                        "members counted as not stable)", "1"),
        "fraction_stable_high": variable(dims, cols["fraction_stable_high"],
                                         "exact interval of fraction_stable, high (undecided "
                                         "members counted as stable)", "1"),
        "delta_star_low": variable((), d_low, "delta* bracket, low: every bin up to it "
                                   "stable at least 1 - q of the time", "1"),
        "delta_star_high": variable((), d_high, "delta* bracket, high: the top of the first "
                                    "bin shown stable less than 1 - q of the time", "1"),
        "delta_star_reason": schema_variable("delta_star_reason", np.int8(why)),
    }  # fmt: skip
    coords = {
        "radius_bin": variable(dims, np.arange(bins), "bin of |alpha0| (log-spaced)", "1"),
        "radius_low": variable(dims, edges[:-1], "bin's smallest |alpha0|", "1"),
        "radius_high": variable(dims, edges[1:], "bin's largest |alpha0|", "1"),
    }
    units = ds["alpha0_norm"].attrs.get("units")
    for v in (data["delta_star_low"], data["delta_star_high"], coords["radius_low"],
              coords["radius_high"]):  # fmt: skip
        if units:
            v.attrs["units"] = units
    attrs = {"q": float(q), "confidence": float(confidence), "bins": int(bins),
             "members_binned": int(ran.sum()),
             "comment": "every bin's interval holds together with the others at the "
                        "stated confidence (exact Clopper-Pearson bounds, each side of "
                        "each bin at level (1 - confidence)/(2 bins))"}  # fmt: skip
    for key in ("model", "law", "scheme", "tau", "seed"):
        if key in ds.attrs:
            attrs[key] = ds.attrs[key]
    return cf_dataset(data, coords=coords, attrs=attrs)


def _bracket(edges, low, high, level) -> tuple[float, float, int]:
    """``(δ*_low, δ*_high, reason)`` from the bins' intervals of the stable fraction."""
    n = low.size
    k = 0
    while k < n and np.isfinite(low[k]) and low[k] >= level:
        k += 1
    d_low = float(edges[k]) if k > 0 else math.nan
    fails = [b for b in range(k, n) if np.isfinite(high[b]) and high[b] < level]
    d_high = float(edges[fails[0] + 1]) if fails else math.nan
    if k == n:
        why = ProfileReason.ABOVE_SAMPLE
    elif fails and k == 0:
        why = ProfileReason.BELOW_SAMPLE if fails[0] == 0 else ProfileReason.OPEN_BELOW
    elif fails:
        why = ProfileReason.BRACKETED
    else:
        why = ProfileReason.OPEN_ABOVE
    return d_low, d_high, int(why)


def paired_difference(a: xr.Dataset, b: xr.Dataset, *, confidence: float = 0.95) -> dict:
    """The difference of the unstable fractions of two grid points, paired member by member.

    The grid points of a study (and ensembles with the same seed and radius) run the same
    members: member ``i`` starts from the same ``α⁰`` target at both.  Their difference is
    then read on the members whose verdicts differ: ``b_ab`` unstable at ``a`` and not at
    ``b``, ``b_ba`` the reverse, of the ``n`` members both ran and judged.  The interval is
    conditional on the discordant members: given ``d = b_ab + b_ba`` of them, ``b_ab`` is
    binomial with ``π = p_ab / (p_ab + p_ba)``; a Clopper–Pearson interval for ``π`` at
    ``confidence`` maps to ``p_a − p_b = (d/n)(2π − 1)`` with the share ``d/n`` taken as
    observed (exact given ``d``; its sign is McNemar's exact test: the interval excludes 0
    where the test rejects equal fractions).  Where no member differs, the difference is
    at most the share of members that would: ``±`` its exact upper bound at
    ``confidence``.

    Returns ``{"members", "a_only", "b_only", "difference", "low", "high"}`` (fractions of
    ``members``); undecided members and members either point did not run are left out."""
    who = "paired_difference"
    for name, ds in (("a", a), ("b", b)):
        if "verdict" not in ds.variables or ds["verdict"].dims != ("member",):
            got = "no verdict" if "verdict" not in ds.variables else ds["verdict"].dims
            raise ValueError(f"{who}: {name} must be one ensemble (verdict over member), "
                             f"got {got}")  # fmt: skip
    for key in ("seed", "radius_low", "radius_high"):
        if key in a.attrs and key in b.attrs and a.attrs[key] != b.attrs[key]:
            raise ValueError(f"{who}: the two ran different members ({key} {a.attrs[key]} "
                             f"against {b.attrs[key]}): pairing needs the same seed and radius")
    if isinstance(confidence, bool) or not 0.0 < float(confidence) < 1.0:
        raise ValueError(f"{who}: confidence must be between 0 and 1, got {confidence!r}")
    k = min(a.sizes["member"], b.sizes["member"])
    va, vb = a["verdict"].values[:k], b["verdict"].values[:k]
    judged = (va != int(Verdict.UNDECIDED)) & (vb != int(Verdict.UNDECIDED))
    for ds in (a, b):
        if "status" in ds:
            judged &= ds["status"].values[:k] != int(Status.NOT_NEEDED)
    ua, ub = va[judged] == int(Verdict.UNSTABLE), vb[judged] == int(Verdict.UNSTABLE)
    n = int(judged.sum())
    ab, ba = int((ua & ~ub).sum()), int((~ua & ub).sum())
    d = ab + ba
    if n == 0:
        return {"members": 0, "a_only": 0, "b_only": 0, "difference": math.nan,
                "low": math.nan, "high": math.nan}  # fmt: skip
    if d == 0:  # no member tells them apart: |p_a − p_b| is at most the discordant share
        most = bounds(0, n, 1.0 - float(confidence))[1]
        return {"members": n, "a_only": 0, "b_only": 0, "difference": 0.0, "low": -most,
                "high": most}  # fmt: skip
    lo, hi = bounds(ab, d, (1.0 - float(confidence)) / 2.0)
    share = d / n
    return {"members": n, "a_only": ab, "b_only": ba, "difference": (ab - ba) / n,
            "low": share * (2.0 * lo - 1.0), "high": share * (2.0 * hi - 1.0)}
