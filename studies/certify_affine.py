"""How often a grid point run until decided is decided wrongly, where the truth is known.

The affine test system (``tests/models/affine.py``: constraints affine in q, v and t) maps
its residual exactly by the scheme's stability polynomial, ``g_{k+1} = R(τÃ) g_k``, so a
grid point is stable exactly where ``ρ(R(τÃ)) < 1``: every member, or none.  Over a
10 × 10 map of (τ, ω) under the critically damped Baumgarte law (``f̈ = −ω² f − 2ω ḟ``,
``ḣ = −ω h``; ω from 1 to 100, τ at 1 ± 0.1, 0.03, 0.01, 0.003, 0.001 times the scheme's
spectral limit, where the decisions are hardest: ρ from about 0.8 to 1.2, and within
1 % of 1 at the four or six nearest), for Euler, the midpoint rule and RK4, each grid
point runs the default
sequential plan (:class:`stabdae.Sequential`: confidence 0.95, q = 0.05, looks at 64,
128, …, 1024 members) over 400 steps, repeated with ``--repetitions`` seeds.

A decision is wrong when it is *stable* where ρ ≥ 1 or *unstable* where ρ < 1; an
undecided point is not wrong (it says so).  Reported: the share of wrong decisions per
grid point (the worst one and overall), the wrong decisions at points with ρ ≤ 0.99 or
ρ ≥ 1.01, the undecided share, and the members used against a fixed 256 per point.

Usage::

    python studies/certify_affine.py [--repetitions 100] [--out studies/results]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import stabdae
from stabdae import theory

HERE = Path(__file__).resolve().parent
AFFINE = HERE.parent / "tests" / "models" / "affine.py"
SCHEMES = ("euler", "midpoint", "rk4")
STEPS = 400


def law(omega: float):
    return stabdae.matrix([[-omega**2, -2.0 * omega, 0.0], [0.0, 0.0, -omega]])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repetitions", type=int, default=100)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    args = ap.parse_args(argv)
    model = stabdae.load_model(AFFINE)
    omegas = np.logspace(0, 2, 10)
    # of the spectral limit, across it: |ρ − 1| from about 0.2 down to 0.002 on each side
    offsets = np.array([0.1, 0.03, 0.01, 0.003, 0.001])
    factors = 1.0 + np.concatenate([-offsets, offsets[::-1]])
    plan = stabdae.Sequential()
    report = {"repetitions": args.repetitions, "steps": STEPS, "plan": plan.as_dict(),
              "schemes": {}}  # fmt: skip
    clock = time.perf_counter()
    for scheme in SCHEMES:
        rho, taus = np.empty((10, 10)), np.empty((10, 10))
        wrong = np.zeros((10, 10), dtype=int)
        undecided = np.zeros((10, 10), dtype=int)
        used = 0
        for i, omega in enumerate(omegas):
            A = law(omega).A_tilde(model)
            limit = theory.tau_limit(A, scheme)
            for j, factor in enumerate(factors):
                tau = factor * limit
                taus[i, j] = tau
                rho[i, j] = theory.discrete(A, scheme, tau).spectral_radius
                truth = 0 if rho[i, j] < 1.0 else 1
                for rep in range(args.repetitions):
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", stabdae.IntegrationWarning)
                        ds = stabdae.ensemble(model, law(omega), scheme, tau, STEPS * tau,
                                              members=plan, seed=1000 + rep, traces="none",
                                              states=False)  # fmt: skip
                    d = int(ds.decision)
                    used += int(ds.members_used)
                    undecided[i, j] += d == 2
                    wrong[i, j] += d != 2 and d != truth
            print(f"{scheme}: omega = {omega:.3g} done ({time.perf_counter() - clock:.0f} s)",
                  file=sys.stderr)  # fmt: skip
        n = args.repetitions
        far = (rho <= 0.99) | (rho >= 1.01)
        worst = np.unravel_index(int(np.argmax(wrong)), wrong.shape)
        report["schemes"][scheme] = {
            "wrong_overall": float(wrong.sum() / (100 * n)),
            "wrong_worst_cell": float(wrong.max() / n),
            "worst_cell": {"omega": float(omegas[worst[0]]),
                           "tau": float(taus[worst]),
                           "rho": float(rho[worst])},  # fmt: skip
            "wrong_far_from_one": int(wrong[far].sum()),
            "cells_far_from_one": int(far.sum()),
            "undecided_overall": float(undecided.sum() / (100 * n)),
            "undecided_cells": [{"omega": float(omegas[i]), "tau": float(taus[i, j]),
                                 "rho": float(rho[i, j]), "share": float(undecided[i, j] / n)}
                                for i, j in zip(*np.nonzero(undecided))],  # fmt: skip
            "members_per_map_mean": used / n,
            "wrong_by_rho": sorted(([float(r), int(w)] for r, w in zip(rho.ravel(), wrong.ravel())
                                    if w), key=lambda rw: rw[0]),  # fmt: skip
            "members_per_map_fixed_256": 25_600,
        }
        print(json.dumps({scheme: report["schemes"][scheme]}, indent=1))
    report["wall_s"] = time.perf_counter() - clock
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "certify_affine.json").write_text(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
