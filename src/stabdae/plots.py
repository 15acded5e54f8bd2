"""Pictures of a study dataset (``stabdae plot OUT.nc``; written by ``stabdae run``).

* ``<stem>_stability.png`` — the stability map: ``fraction_stable`` over the first two
  swept axes, with the theory's boundaries drawn over it (``ρ(R(τÃ)) = 1`` and the
  weighted-norm condition of Theorems 6/7); with one swept axis, a curve.
* ``<stem>_decision.png`` — for grid points run until decided (``[ensemble] members =
  { ... }``): each cell coloured by its decision (stable, unstable, undecided with its
  reason) beside the members it used, over the same theory outline.
* ``<stem>_decay.png`` — residual decay of sampled members at one grid point, each with
  its fitted ``γ e^{−βt}`` and the theory's rate.
* ``<stem>_beta.png`` — median fitted ``β`` against the predicted one at every grid point.
* ``<stem>_boundary.png`` — for a boundary search (``stabdae.boundary``, a study with
  ``[search]``), instead of the three above: the measured ``τ*`` with its bracket over
  the first swept axis, beside the theory's limits (``ρ(R(τÃ)) = 1``, and Theorems 6/7
  with the floor the local error forces); with nothing swept, the probes.

Needs matplotlib (``pip install 'stabdae[plots]'``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from ._codes import DecisionReason
from ._schema import open_dataset
from ._version import __version__

__all__ = ["plot_dataset", "stability_map", "decision_map", "decay_curves",
           "beta_comparison", "boundary_curve", "profile_curve"]


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _sweep_dims(ds: xr.Dataset) -> list[str]:
    return list(ds["tau_star" if "tau_star" in ds else "fraction_bounded"].dims)


def _label(ds, dim) -> str:
    units = ds[dim].attrs.get("units", "")
    names = {"tau": "step size τ", "omega": "Baumgarte ω", "xi": "damping ratio ξ",
             "k": "gain k"}  # fmt: skip
    return f"{names.get(dim, dim)}" + (f" [{units}]" if units not in ("", "1") else "")


def _log_scale(ax, which: str, edges) -> None:
    """A log scale on ``ax``'s ``which`` ("x" or "y") axis over cell ``edges``.  Where they
    span a decade or more, the labels are 1 and 3 × 10^k (up to about two and a half
    decades) or the powers of ten: matplotlib's own choice adds 2, 3, 4 and 6 × 10^k up to
    about two decades, and on a map's width those run into each other."""
    from matplotlib.ticker import LogFormatterSciNotation, LogLocator, NullFormatter

    getattr(ax, f"set_{which}scale")("log")
    span = edges.max() / edges.min()
    axis = getattr(ax, f"{which}axis")
    if span >= 10.0:
        axis.set_minor_formatter(NullFormatter())
    if 10.0 <= span < 10.0**2.5:
        axis.set_major_locator(LogLocator(subs=(1.0, 3.0)))
        # every major tick labelled (the default drops the 3s beyond a decade or so)
        axis.set_major_formatter(LogFormatterSciNotation(minor_thresholds=(np.inf, np.inf)))


def _is_log(values) -> bool:
    v = np.asarray(values, dtype=float)
    return bool(len(v) >= 3 and np.all(v > 0) and v.max() / v.min() >= 20)


def _edges(v, log):
    v = np.asarray(v, dtype=float)
    if len(v) == 1:
        return np.array([v[0] * 0.9, v[0] * 1.1]) if log else np.array([v[0] - 0.5, v[0] + 0.5])
    w = np.log(v) if log else v
    mid = 0.5 * (w[1:] + w[:-1])
    e = np.concatenate([[w[0] - (mid[0] - w[0])], mid, [w[-1] + (w[-1] - mid[-1])]])
    return np.exp(e) if log else e


def _outline(ax, mask, xe, ye, **style):
    """Draw the cell edges between cells where ``mask`` (ny × nx) holds and where it does
    not (or the border): the prediction exactly per grid cell, nothing interpolated."""
    ny, nx = mask.shape
    segs = []
    for i in range(ny):
        for j in range(nx):
            if not mask[i, j]:
                continue
            if j == 0 or not mask[i, j - 1]:
                segs.append(((xe[j], ye[i]), (xe[j], ye[i + 1])))
            if j == nx - 1 or not mask[i, j + 1]:
                segs.append(((xe[j + 1], ye[i]), (xe[j + 1], ye[i + 1])))
            if i == 0 or not mask[i - 1, j]:
                segs.append(((xe[j], ye[i]), (xe[j + 1], ye[i])))
            if i == ny - 1 or not mask[i + 1, j]:
                segs.append(((xe[j], ye[i + 1]), (xe[j + 1], ye[i + 1])))
    if not segs:
        return None
    from matplotlib.collections import LineCollection

    kw = {"colors": style.get("color"), "linewidths": style.get("lw", 1.5),
          "linestyles": style.get("ls", "-")}  # fmt: skip
    ax.add_collection(LineCollection(segs, **kw))
    from matplotlib.lines import Line2D

    return Line2D([], [], color=style.get("color"), lw=style.get("lw", 1.5),
                  ls=style.get("ls", "-"))


def motion_unstable(ds: xr.Dataset):
    """Per grid point, whether the scheme is unstable on the motion itself: a member's
    verdict says so (``verdict_reason`` ``motion_unstable``, where the unperturbed run
    blew up or left ε beyond roundoff); None for a dataset without verdicts."""
    from ._codes import VerdictReason

    if "verdict_reason" not in ds or "member" not in ds["verdict_reason"].dims:
        return None
    return (ds["verdict_reason"] == int(VerdictReason.MOTION_UNSTABLE)).any("member")


def _hatch_motion(ax, sub, xd, yd, xe, ye):
    """Hatch the cells where the scheme is unstable on the motion itself; the legend's
    handle, or None where there is no such cell."""
    bad = motion_unstable(sub)
    if bad is None or not bool(bad.any()):
        return None
    import matplotlib.patches as mpatches

    for j, i in zip(*np.nonzero(bad.transpose(yd, xd).values)):
        ax.add_patch(mpatches.Rectangle((xe[i], ye[j]), xe[i + 1] - xe[i], ye[j + 1] - ye[j],
                                        fill=False, hatch="xx", edgecolor="black",
                                        linewidth=0.0, alpha=0.45))  # fmt: skip
    return mpatches.Patch(facecolor="none", edgecolor="black", hatch="xx",
                          label="unstable on the motion itself (unperturbed run diverges "
                                "or leaves ε)")  # fmt: skip


def _first_of_others(ds, keep):
    sel = {d: 0 for d in _sweep_dims(ds) if d not in keep}
    note = ", ".join(f"{d} = {float(ds[d][0]):g}" for d in sel)
    return ds.isel(sel), note


def stability_map(ds: xr.Dataset, path: Path) -> Path:
    plt = _plt()
    dims = _sweep_dims(ds)
    fig, ax = plt.subplots(figsize=(7.2, 5.2), constrained_layout=True)
    title = f"{ds.attrs.get('model', '')}: {ds.attrs.get('law', '')} law, " \
            f"{ds.attrs.get('scheme', '')} — fraction of members stable"  # fmt: skip
    if len(dims) >= 2:
        xd, yd = dims[0], dims[1]
        sub, note = _first_of_others(ds, (xd, yd))
        x, y = sub[xd].values, sub[yd].values
        xlog, ylog = _is_log(x), _is_log(y)
        frac = sub[_fraction(sub)].transpose(yd, xd).values
        mesh = ax.pcolormesh(_edges(x, xlog), _edges(y, ylog), frac, cmap="viridis",
                             vmin=0, vmax=1, shading="flat")  # fmt: skip
        fig.colorbar(mesh, ax=ax, label="fraction of members stable (not growing, not diverged)")
        handles = []
        xe, ye = _edges(x, xlog), _edges(y, ylog)
        for var, style, label in (
            ("spectral_radius", dict(color="white", lw=3.0), "ρ(R(τÃ)) < 1 (spectral radius)"),
            ("norm_weighted", dict(color="orangered", lw=1.4, ls="--"),
             "weighted-norm condition of Thms 6/7"),
            ("path_spectral_radius_max", dict(color="white", lw=3.0),
             "max ρ(R_k) < 1 along the reference path"),
            ("path_norm_weighted_max", dict(color="orangered", lw=1.4, ls="--"),
             "weighted-norm condition along the path"),
        ):  # fmt: skip
            if var not in sub:
                continue
            holds = (sub[var].transpose(yd, xd).values < 1.0)
            line = _outline(ax, holds, xe, ye, **style)
            if line is not None:
                handles.append((line, label))
        hatched = _hatch_motion(ax, sub, xd, yd, xe, ye)
        if hatched is not None:
            handles.append((hatched, hatched.get_label()))
        if handles:
            leg = ax.legend(*zip(*handles), loc="upper right", framealpha=0.9, fontsize=8.5)
            leg.set_title("theory: holds inside the outline", prop={"size": 8.5})
        for which, log, edges in (("x", xlog, xe), ("y", ylog, ye)):
            if log:
                _log_scale(ax, which, edges)
        ax.set_xlabel(_label(ds, xd))
        ax.set_ylabel(_label(ds, yd))
        if note:
            title += f"\n(at {note})"
    elif len(dims) == 1:
        xd = dims[0]
        x = ds[xd].values
        ax.plot(x, ds[_fraction(ds)].values, "o-",
                label=_fraction(ds).replace("_", " ") + " (measured)")
        bad = motion_unstable(ds)
        if bad is not None and bool(bad.any()):
            pick = bad.values
            ax.plot(x[pick], ds[_fraction(ds)].values[pick], "kx", ms=10,
                    label="unstable on the motion itself (unperturbed run diverges or "
                          "leaves ε)")  # fmt: skip
        if "spectral_radius" in ds:
            rho = ds["spectral_radius"].values
            ax.plot(x, np.minimum(rho, 2.0), "s--", color="gray", label="ρ(R(τÃ)) (theory)")
            ax.axhline(1.0, color="gray", lw=0.8)
        ax.set_xscale("log" if _is_log(x) else "linear")
        ax.set_xlabel(_label(ds, xd))
        ax.set_ylim(-0.05, 2.05)
        ax.legend(fontsize=9)
    else:
        frac = float(ds[_fraction(ds)])
        name = _fraction(ds).replace("_", " ")
        ax.text(0.5, 0.5, f"nothing swept: {name} = {frac:.3g}", ha="center",
                transform=ax.transAxes)  # fmt: skip
    ax.set_title(title, fontsize=10)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


#: an undecided cell's mark in the decision map, by its ``decision_reason``, and the
#: legend's words for it (the codes' own text, shortened to what fits a legend)
_REASON_MARKS = {int(DecisionReason.MAX_REACHED): "m", int(DecisionReason.MEMBERS_UNDECIDED): "u",
                 int(DecisionReason.WITHIN_TOLERANCE): "t", int(DecisionReason.NOT_RUN): "n"}
_REASON_WORDS = {int(DecisionReason.MAX_REACHED): "m  max members reached, q inside",
                 int(DecisionReason.MEMBERS_UNDECIDED): "u  members undecided (verdict_reason)",
                 int(DecisionReason.WITHIN_TOLERANCE): "t  interval within tolerance",
                 int(DecisionReason.NOT_RUN): "n  members not run (not placed; status)"}


def decision_map(ds: xr.Dataset, path: Path) -> Path:
    """Each grid point's decision (stable, unstable, undecided) and the members it took,
    over the first two swept axes (one axis: a strip), with the outline ``ρ(R(τÃ)) < 1``."""
    from matplotlib.colors import ListedColormap, LogNorm

    plt = _plt()
    dims = _sweep_dims(ds)
    sub, note = _first_of_others(ds, tuple(dims[:2]))
    if len(dims) == 1:
        sub = sub.expand_dims(_row=[0])
        dims = [dims[0], "_row"]
    xd, yd = dims[0], dims[1]
    x, y = sub[xd].values, sub[yd].values
    xlog, ylog = _is_log(x), _is_log(y)
    xe, ye = _edges(x, xlog), _edges(y, ylog)
    dec = sub["decision"].transpose(yd, xd).values
    used = sub["members_used"].transpose(yd, xd).values
    why = (sub["decision_reason"].transpose(yd, xd).values if "decision_reason" in sub
           else np.full(dec.shape, -1))  # fmt: skip
    fig, axes = plt.subplots(1, 2, figsize=(11.5, 4.8), constrained_layout=True)
    colors = ListedColormap(["#3b8b3b", "#c0392b", "#bdbdbd"])
    axes[0].pcolormesh(xe, ye, dec, cmap=colors, vmin=-0.5, vmax=2.5, shading="flat")
    mesh = axes[1].pcolormesh(xe, ye, used, cmap="magma_r", shading="flat",
                              norm=LogNorm(vmin=max(1, used.min()), vmax=max(2, used.max())))
    fig.colorbar(mesh, ax=axes[1], label="members used")
    for j, row in enumerate(used):  # the counts, readable without the colour bar
        for i, n in enumerate(row):
            cx = np.sqrt(xe[i] * xe[i + 1]) if xlog else 0.5 * (xe[i] + xe[i + 1])
            cy = np.sqrt(ye[j] * ye[j + 1]) if ylog else 0.5 * (ye[j] + ye[j + 1])
            axes[1].text(cx, cy, str(int(n)), ha="center", va="center", fontsize=6.5,
                         color="white" if n > np.sqrt(used.max() * used.min()) else "black")
            if dec[j, i] == 2:
                axes[0].text(cx, cy, _REASON_MARKS.get(int(why[j, i]), "?"), ha="center",
                             va="center", fontsize=9)  # fmt: skip
    handles = [plt.Rectangle((0, 0), 1, 1, color=c) for c in colors.colors]
    labels = ["stable (≤ q unstable)", "unstable (> q)", "undecided, by its reason:"]
    for code in sorted({int(c) for c in why[dec == 2]}):  # the marks drawn, decoded
        handles.append(plt.Line2D([], [], ls="", marker=f"${_REASON_MARKS.get(code, '?')}$",
                                  color="black", ms=7))  # fmt: skip
        labels.append(_REASON_WORDS.get(code, f"reason code {code}"))
    hatched = _hatch_motion(axes[0], sub, xd, yd, xe, ye)
    if hatched is not None:
        handles.append(hatched)
        labels.append(hatched.get_label())
    if "spectral_radius" in sub:
        holds = sub["spectral_radius"].transpose(yd, xd).values < 1.0
        for ax in axes:
            line = _outline(ax, holds, xe, ye, color="white", lw=2.5)
        if line is not None:
            handles.append(line)
            labels.append("ρ(R(τÃ)) < 1 inside")
    axes[0].legend(handles, labels, loc="upper right", fontsize=8, framealpha=0.9)
    conf = ds.attrs.get("sequential_confidence", "")
    q = ds.attrs.get("sequential_q", "")
    for ax, what in zip(axes, ("decision", "members used")):
        if xlog:
            _log_scale(ax, "x", xe)
        ax.set_xlabel(_label(ds, xd))
        if yd == "_row":
            ax.set_yticks([])
        else:
            if ylog:
                _log_scale(ax, "y", ye)
            ax.set_ylabel(_label(ds, yd))
        ax.set_title(f"{what}" + (f" (q = {q}, confidence {conf})" if what == "decision"
                                  else f", {int(used.sum())} in all"), fontsize=10)
    title = (f"{ds.attrs.get('model', '')}: {ds.attrs.get('law', '')} law, "
             f"{ds.attrs.get('scheme', '')} — each grid point run until decided")
    if note:
        title += f" (at {note})"
    fig.suptitle(title, fontsize=10.5)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def _fraction(ds) -> str:
    """The fraction the pictures show: stable members (bounded in older datasets)."""
    return "fraction_stable" if "fraction_stable" in ds else "fraction_bounded"


def _pick_point(ds):
    """The grid point that shows decay best: every member bounded and the longest
    transient above the truncation floor."""
    dims = _sweep_dims(ds)
    if not dims:
        return {}
    frac = ds["fraction_stable"] if "fraction_stable" in ds else ds["fraction_bounded"]
    # samples of the transient above 10x the floor, median over the traced members
    floor = ds["residual_floor"].sel(member=ds["trace"])
    visible = (ds["residual_norm"] > 10.0 * floor).sum("time").median("trace")
    score = xr.where(frac >= 0.99, visible.fillna(-1.0), -np.inf)
    if not np.isfinite(score.values).any():
        score = frac
    idx = np.unravel_index(int(np.argmax(score.values)), score.shape)
    return {d: int(i) for d, i in zip(score.dims, idx)}


def decay_curves(ds: xr.Dataset, path: Path, members: int = 12) -> Path:
    plt = _plt()
    point = _pick_point(ds)
    sub = ds.isel(point)
    t = sub["time"].values - sub["time"].values[0]
    fig, ax = plt.subplots(figsize=(7.2, 5.0), constrained_layout=True)
    # members spread over the upper half of the perturbation sizes: the ones whose decay
    # is visible above the truncation floor
    traced = sub["trace"].values
    order = np.argsort(-sub["alpha0_norm"].values[traced])
    top = order[: max(1, len(order) // 2)]
    chosen = top[np.linspace(0, len(top) - 1, min(members, len(top))).astype(int)] \
        if len(top) else np.zeros(0, dtype=int)  # fmt: skip
    colors = plt.cm.viridis(np.linspace(0, 0.9, max(len(chosen), 1)))
    for c, j in zip(colors, chosen):
        y = sub["residual_norm"].values[j].astype(float)
        ok = np.isfinite(y)
        ax.semilogy(t[ok], y[ok], "-", color=c, lw=1.1)
        b = float(sub["beta"].values[traced[j]])
        g = float(sub["gamma"].values[traced[j]])
        if np.isfinite(b) and np.isfinite(g):  # only fits that exist, over their window
            t0 = float(sub["time"].values[0])
            lo = float(sub["fit_start"].values[traced[j]]) - t0
            hi = float(sub["fit_end"].values[traced[j]]) - t0
            span = (t >= min(lo, 0.0)) & (t <= hi)
            ax.semilogy(t[span], g * np.exp(-b * t[span]), ":", color=c, lw=0.9)
    if "beta_theory_discrete" in sub and np.isfinite(float(sub["beta_theory_discrete"])):
        bd = float(sub["beta_theory_discrete"])
        a0 = float(np.nanmax(sub["alpha0_norm"].values))
        ax.semilogy(t, a0 * np.exp(-bd * t), "k--", lw=1.6,
                    label=f"theory: slope −ln ρ(R)/τ = {bd:.4g} s⁻¹")  # fmt: skip
    if "beta_theorem5_proven" in sub:
        for var, st, name in (("beta_theorem5_proven", "k--", "proven"),
                              ("beta_theorem5_printed", "r--", "printed")):  # fmt: skip
            b = float(sub[var])
            a0 = float(np.nanmax(sub["gamma_theorem5"].values))
            ax.semilogy(t, a0 * np.exp(-b * t), st, lw=1.4,
                        label=f"Theorem 5 bound, {name} β = {b:.4g} s⁻¹")  # fmt: skip
    data = sub["residual_norm"].values[chosen].astype(float) if len(chosen) else np.zeros(0)
    data = data[np.isfinite(data) & (data > 0)]
    if data.size:
        ax.set_ylim(0.3 * data.min(), 3.0 * data.max())
    ax.plot([], [], "-", color="gray", label="‖g(t)‖∞ of a member")
    ax.plot([], [], ":", color="gray", label="its fitted γ·exp(−βt), over the fit's window")
    ax.set_xlabel("t − t₀ [s]")
    ax.set_ylabel("constraint residual ‖g‖∞")
    where = ", ".join(f"{d} = {float(sub[d]):g}" for d in point) or "the study"
    ax.set_title(f"{ds.attrs.get('model', '')}: residual decay of {len(chosen)} members "
                 f"at {where}\n(median fitted β = {float(sub['beta_median']):.4g} s⁻¹; "
                 "curves level off at the scheme's truncation floor)", fontsize=10)  # fmt: skip
    ax.legend(fontsize=8.5, loc="lower left")
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def beta_comparison(ds: xr.Dataset, path: Path) -> Path:
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.8, 5.4), constrained_layout=True)
    meas = ds["beta_median"].values.ravel()
    drew = False
    for var, marker, label in (("beta_theory_discrete", "o", "−ln ρ(R(τÃ))/τ (discrete)"),
                               ("beta_theory", "x", "−max Re λ(Ã) (continuous, Thm 3)"),
                               ("beta_theorem5_proven", "s", "Theorem 5, proven"),
                               ("beta_theorem5_printed", "^", "Theorem 5, printed")):  # fmt: skip
        if var not in ds:
            continue
        pred = np.broadcast_to(ds[var].values, ds["beta_median"].shape).ravel()
        ok = np.isfinite(pred) & np.isfinite(meas) & (pred > 0) & (meas > 0)
        if ok.any():
            ax.loglog(pred[ok], meas[ok], marker, ms=6, mfc="none", label=label)
            drew = True
    if drew:
        lo, hi = ax.get_xlim()
        lo2, hi2 = ax.get_ylim()
        lo, hi = min(lo, lo2), max(hi, hi2)
        ax.plot([lo, hi], [lo, hi], "k-", lw=0.8, label="measured = predicted")
        ax.set_xlim(lo, hi)
        ax.set_ylim(lo, hi)
        ax.legend(fontsize=8.5)
    else:
        ax.text(0.5, 0.5, "no grid point with a fitted β\n(run longer, or smaller residual "
                "floor)", ha="center", va="center", transform=ax.transAxes)  # fmt: skip
    ax.set_xlabel("predicted decay rate β [s⁻¹]")
    ax.set_ylabel("measured median β [s⁻¹]")
    ax.set_title(f"{ds.attrs.get('model', '')}: measured against predicted β\n"
                 "(one marker per grid point)", fontsize=10)  # fmt: skip
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def plot_dataset(dataset, output=None) -> list[Path]:
    """Write the three pictures for a dataset (a path or an open ``xarray.Dataset``)."""
    if isinstance(dataset, xr.Dataset):
        ds, src = dataset, None
    else:
        src = Path(dataset)
        if not src.is_file():
            raise FileNotFoundError(f"stabdae plot: no such dataset: {src}")
        try:
            ds = open_dataset(src).load()
        except (ValueError, OSError) as exc:  # not NetCDF: xarray names its backends instead
            first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise ValueError(f"stabdae plot: {src} is not a NetCDF dataset that xarray can "
                             f"open ({first})") from None  # fmt: skip
    if "fraction_bounded" not in ds and "tau_star" not in ds:
        raise ValueError("stabdae plot: the dataset has no fraction_bounded or tau_star; it "
                         "is not an ensemble, boundary or study dataset")  # fmt: skip
    if output is None:
        stem = src.with_suffix("") if src is not None else Path("stabdae")
    else:
        out = Path(output)
        stem = out / (src.stem if src else "stabdae") if out.is_dir() else out.with_suffix("")
    stem.parent.mkdir(parents=True, exist_ok=True)
    try:
        if "tau_star" in ds:
            return [boundary_curve(ds, Path(f"{stem}_boundary.png"))]
        pictures = [stability_map(ds, Path(f"{stem}_stability.png"))]
        if "decision" in ds and _sweep_dims(ds):
            pictures.append(decision_map(ds, Path(f"{stem}_decision.png")))
        return pictures + [decay_curves(ds, Path(f"{stem}_decay.png")),
                           beta_comparison(ds, Path(f"{stem}_beta.png"))]
    except (KeyError, AttributeError, IndexError, ValueError) as exc:
        written = str(ds.attrs.get("stabdae_version", "an unknown version"))
        if written == __version__:
            raise  # this version's own dataset: a defect to see in full
        what = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
        raise ValueError(
            f"stabdae plot: {src or 'the dataset'} was written by stabdae {written}; "
            f"stabdae {__version__} plots what it writes itself and cannot draw this one "
            f"(missing or different: {what!r}); plot it with stabdae {written}, or run its "
            "study again with this version"
        ) from None


def boundary_curve(ds: xr.Dataset, path: Path) -> Path:
    """The measured stability boundary ``τ*`` with its bracket against the first swept
    axis, over the theory's limits; with nothing swept, the probes of the search."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.2, 5.0), constrained_layout=True)
    title = f"{ds.attrs.get('model', '')}: {ds.attrs.get('law', '')} law, " \
            f"{ds.attrs.get('scheme', '')} — largest stable step τ*"  # fmt: skip
    dims = _sweep_dims(ds)
    if dims:
        sub, note = _first_of_others(ds, (dims[0],))
        x = sub[dims[0]].values
        for var, style, label in (
            ("tau_limit_spectral", dict(color="black", lw=2.0), "ρ(R(τÃ)) = 1 (spectral)"),
            ("tau_limit_floor", dict(color="orangered", lw=1.5, ls="--"),
             "Theorems 6/7 with the floor: ‖g‖ ≤ ε guaranteed below"),
        ):  # fmt: skip
            if var in sub and np.isfinite(sub[var].values).any():
                ax.plot(x, sub[var].values, label=label, **style)
        star = sub["tau_star"].values
        lo, hi = sub["tau_star_low"].values, sub["tau_star_high"].values
        ok = np.isfinite(star)
        conf = sub["tau_star_confidence"].values if "tau_star_confidence" in sub else None
        what = "measured τ* (bracket)"
        if conf is not None and np.isfinite(conf).any():  # probes decided at a confidence
            what = f"measured τ* (bracket: the boundary inside at {np.nanmin(conf):g})"
            ax.fill_between(x[ok], lo[ok], hi[ok], color="tab:blue", alpha=0.2, lw=0)
        ax.errorbar(x[ok], star[ok], yerr=[star[ok] - lo[ok], hi[ok] - star[ok]], fmt="o",
                    color="tab:blue", ms=5, capsize=3, label=what)
        for xi, l_, h_ in zip(x[~ok], lo[~ok], hi[~ok]):  # no bracket: the end that held
            y = l_ if np.isfinite(l_) else h_
            ax.plot([xi], [y], marker="^" if np.isfinite(l_) else "v", color="tab:red")
        if (~ok).any():
            ax.plot([], [], "^", color="tab:red", label="not bracketed (▲ stable up to, ▼ "
                    "unstable from)")  # fmt: skip
        ax.set_xlabel(_label(sub, dims[0]))
        if _is_log(x) or (len(x) >= 2 and np.all(x > 0) and x.max() / x.min() >= 5):
            ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylabel("step size τ [s]")
        if note:
            title += f"\n(at {note})"
    else:
        t = ds["probe_tau"].values
        stable = ds["probe_stable"].values == 1
        k = np.arange(t.size)
        ax.plot(k, t, color="0.6", lw=0.8)
        ax.plot(k[stable], t[stable], "o", color="tab:blue", label="stable")
        ax.plot(k[~stable], t[~stable], "x", color="tab:red", label="not stable")
        for var, style, label in (("tau_limit_spectral", dict(color="black"), "ρ = 1"),
                                  ("tau_limit_floor", dict(color="orangered", ls="--"),
                                   "Theorems 6/7 with the floor")):  # fmt: skip
            v = float(ds[var])
            if np.isfinite(v) and v > 0:
                ax.axhline(v, label=label, **style)
        ax.set_yscale("log")
        ax.set_xlabel("probe")
        ax.set_ylabel("step size τ [s]")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def profile_curve(profile: xr.Dataset, path: Path, reference: float | None = None) -> Path:
    """A radial profile (:func:`stabdae.radial_profile`): the fraction of members stable
    per bin of ``‖α⁰‖∞`` with its interval, the line ``1 − q``, and δ*'s bracket shaded
    (``reference``: a radius to mark, e.g. an independent estimate)."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.2, 4.4), constrained_layout=True)
    lo, hi = profile.radius_low.values, profile.radius_high.values
    centre = np.sqrt(lo * hi)
    frac = profile.fraction_stable.values
    err = [frac - profile.fraction_stable_low.values, profile.fraction_stable_high.values - frac]
    ax.errorbar(centre, frac, yerr=err, xerr=[centre - lo, hi - centre], fmt="o", ms=4,
                capsize=2, label="fraction stable per bin, with its interval")  # fmt: skip
    q = float(profile.attrs["q"])
    ax.axhline(1 - q, color="gray", lw=1, ls="--", label=f"1 − q = {1 - q:g}")
    d_low, d_high = float(profile.delta_star_low), float(profile.delta_star_high)
    span = (d_low if np.isfinite(d_low) else lo[0], d_high if np.isfinite(d_high) else hi[-1])
    ax.axvspan(*span, color="tab:orange", alpha=0.2,
               label=f"δ* bracket [{d_low:.3g}, {d_high:.3g}]")  # fmt: skip
    if reference is not None:
        ax.axvline(reference, color="black", lw=1.2, label=f"bisection: {reference:.3g}")
    ax.set_xscale("log")
    ax.set_ylim(-0.03, 1.03)
    units = profile.radius_low.attrs.get("units", "")
    ax.set_xlabel(f"initial perturbation |α⁰|∞{f' [{units}]' if units else ''}")
    ax.set_ylabel("fraction of members stable")
    conf = profile.attrs.get("confidence", "")
    head = " ".join(str(profile.attrs.get(k, "")) for k in ("model", "law", "scheme"))
    ax.set_title(f"{head} — radial profile (intervals together at {conf})", fontsize=10)
    ax.legend(fontsize=8.5, loc="lower left")
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path
