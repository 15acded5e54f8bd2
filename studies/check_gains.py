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

Usage::

    python studies/check_gains.py [--out studies/results]
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


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args(argv)
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
