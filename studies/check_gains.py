"""Gains that weigh the floor: each gain's residual floor predicted against measured, and
the balanced gain against the minimal-ρ one and ω = 10.

1. For the planar and the double pendulum, Euler, the midpoint rule, Heun and RK4 at
   τ = 0.01 over 5 s, Baumgarte ω = 10 (ξ = 1) and the minimal-ρ gain of
   ``theory.recommend_gain``: the floor :func:`stabdae.gain_floor` predicts from the
   scheme's one-step remainders, against the median ``residual_floor`` of 16 members.
2. The planar pendulum, RK4, τ = 0.01, 20 s: the gain :func:`stabdae.balanced_gain`
   picks to bring a perturbation of 1e-3 below 1e-6 (and 1e-5) soonest, against ω = 10 and
   the minimal-ρ gain, each measured: the time from which every one of 8 members
   (‖α⁰‖∞ = 1e-3) stays below the level (``stabdae.integrate``, every step).
3. With ``--span``: over every candidate gain of :func:`stabdae.balanced_gain` (32, from
   the minimal-ρ gain down to a thousandth of it), on the planar pendulum and a particle
   on a torus (τ = 0.01, 20 s, from 1e-3 to 1e-6 under RK4, and from 1e-2 to 1e-3 under
   the midpoint rule, whose least floor at this step lies near 1e-4): each
   candidate's floor against 16 members' median ``residual_floor``, and the gain the
   function picks against a brute-force scan of the same candidates, each measured as in
   2.  Written to ``check_gains_span.json``.

Usage::

    python studies/check_gains.py [--out studies/results] [--span]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings
from pathlib import Path

import numpy as np

import stabdae
from stabdae import theory

HERE = Path(__file__).resolve().parent
SCHEMES = ("euler", "midpoint", "heun", "rk4")
#: the span check's models: a scene, and a model written as a user writes one
SPAN_MODELS = {"pendulum": "pendulum",
               "torus_particle": HERE.parent / "tests" / "models" / "torus_particle.py"}


def reach_time(model, law, scheme, tau, t_end, level, start) -> float:
    """The time from which every one of 8 members of size ``start`` stays below ``level``
    (inf where one does not by ``t_end``)."""
    x0 = stabdae.sample_perturbations(model, 8, (start, start), seed=3)[0]
    worst = 0.0
    for x in x0:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", stabdae.IntegrationWarning)
            run = stabdae.integrate(model, x, law, scheme, tau, t_end, tau)
        g = np.abs(run.residual.values).max(axis=1)
        above = np.flatnonzero(~(g <= level))
        if above.size and above[-1] == g.size - 1:
            return math.inf
        worst = max(worst, float(run.time.values[above[-1] + 1]) if above.size else 0.0)
    return worst


#: the span check's start and level per scheme (a decade or more above the scheme's least
#: floor at τ = 0.01)
SPAN_LEVELS = {"rk4": (1e-3, 1e-6), "midpoint": (1e-2, 1e-3)}


def span(out: Path, tau=0.01, t_end=20.0) -> int:
    """Every candidate gain's floor, predicted and measured, and the balanced gain against
    the brute-force fastest of the candidates (section 3 of the module's docstring)."""
    rows = []
    worst = 1.0
    for name, source in SPAN_MODELS.items():
        model = stabdae.load_model(source)
        for scheme, (start, level) in SPAN_LEVELS.items():
            b = stabdae.balanced_gain(model, scheme, tau, level, start, t_end=t_end)
            ratios, measured = [], []
            for w, f in zip(b["omegas"], b["floors"]):
                law = stabdae.baumgarte(float(w))
                r = stabdae.gain_floor(model, law, scheme, tau, t_end)
                ratios.append(f / r["measured"] if np.isfinite(f) else math.nan)
                measured.append(reach_time(model, law, scheme, tau, t_end, level, start))
            measured = np.asarray(measured)
            brute = int(np.argmin(measured)) if np.isfinite(measured).any() else -1
            pick = int(np.flatnonzero(b["omegas"] == b["omega"])[0]) if np.isfinite(
                b["omega"]) else -1  # fmt: skip
            finite = np.isfinite(ratios)
            row = {"model": name, "scheme": scheme, "start": start, "level": level,
                   "omegas": b["omegas"].tolist(),
                   "floor_ratio": ratios,
                   "floor_ratio_range": [float(np.nanmin(ratios)), float(np.nanmax(ratios))],
                   "measured_time": measured.tolist(), "predicted_time": b["times"].tolist(),
                   "balanced": b["omega"], "balanced_measured_time":
                   float(measured[pick]) if pick >= 0 else math.inf,
                   "brute_force": float(b["omegas"][brute]) if brute >= 0 else math.nan,
                   "brute_force_time": float(measured[brute]) if brute >= 0 else math.inf,
                   # (a candidate measured as fast as the scan's best is as good a pick)
                   "same": bool(pick >= 0 and brute >= 0 and measured[pick] == measured[brute]
                                or pick == brute)}  # fmt: skip
            rows.append(row)
            worst = min(worst, float(np.nanmin(np.minimum(np.asarray(ratios)[finite],
                                                          1 / np.asarray(ratios)[finite]))))
            print(f"{name:15s} {scheme:8s} floor predicted/measured "
                  f"{row['floor_ratio_range'][0]:.2f}-{row['floor_ratio_range'][1]:.2f} over "
                  f"{int(finite.sum())} gains; balanced omega = {row['balanced']:.4g} "
                  f"(reaches {level:g} at {row['balanced_measured_time']:.2f} s), brute force "
                  f"omega = {row['brute_force']:.4g} ({row['brute_force_time']:.2f} s): "
                  f"{('same' if pick == brute else 'as fast') if row['same'] else 'SLOWER'}",
                  flush=True)  # fmt: skip
    out.mkdir(parents=True, exist_ok=True)
    (out / "check_gains_span.json").write_text(json.dumps(rows, indent=1) + "\n")
    same = all(r["same"] for r in rows)
    print(f"floor within a factor {1 / worst:.2f} at every candidate; the balanced gain as "
          f"fast as the brute force's on every model and scheme: {same}")
    return 0 if same and worst >= 0.5 else 1


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--span", action="store_true",
                    help="every candidate gain's floor, and the balanced gain against a "
                         "brute-force scan")  # fmt: skip
    args = ap.parse_args(argv)
    if args.span:
        return span(args.out)
    floors = []
    for name in ("pendulum", "double_pendulum"):
        model = stabdae.load_model(name)
        for scheme in SCHEMES:
            rec = theory.recommend_gain(scheme, 0.01)
            for label, law in (("omega 10", stabdae.baumgarte(10.0)),
                               ("minimal rho", stabdae.baumgarte(rec["omega"], rec["xi"]))):
                r = stabdae.gain_floor(model, law, scheme, 0.01, 5.0)
                floors.append({"model": name, "scheme": scheme, "gain": label,
                               "predicted": r["predicted"], "measured": r["measured"],
                               "ratio": r["predicted"] / r["measured"]})  # fmt: skip
                print(json.dumps(floors[-1]), flush=True)
    model = stabdae.load_model("pendulum")
    tau, t_end, start = 0.01, 20.0, 1e-3
    balanced = []
    for level in (1e-6, 1e-5):
        b = stabdae.balanced_gain(model, "rk4", tau, level, start, t_end=t_end)
        measured = {}
        for label, law in (("balanced", stabdae.baumgarte(b["omega"])),
                           ("omega 10", stabdae.baumgarte(10.0)),
                           ("minimal rho", stabdae.baumgarte(b["deadbeat"], b["deadbeat_xi"]))):
            measured[label] = reach_time(model, law, "rk4", tau, t_end, level, start)
        balanced.append({"level": level, "omega": b["omega"], "predicted_time": b["time"],
                         "deadbeat": b["deadbeat"], "deadbeat_floor": b["deadbeat_floor"],
                         "measured_time": measured})  # fmt: skip
        print(json.dumps(balanced[-1], indent=1))
    report = {"floors": floors,
              "floor_ratio_range": [min(f["ratio"] for f in floors),
                                    max(f["ratio"] for f in floors)],
              "balanced": balanced}  # fmt: skip
    print("floor ratio range", report["floor_ratio_range"])
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "check_gains.json").write_text(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
