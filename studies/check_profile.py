"""δ* as a profile against an independent bisection in the perturbation's size.

The planar pendulum under Baumgarte's law with ω = 100 (ξ = 1), the midpoint rule at
τ = 0.015 (τω = 1.5: ρ(R) = 0.625, the law's linear part stable) over 1.5 s: small
perturbations decay, large ones knock the pendulum into motions the step cannot follow.

1. :func:`stabdae.radial_profile` of one ensemble of ``--members`` members with ``‖α⁰‖∞``
   log-uniform in [1e-4, 1]: the fraction stable per bin and δ* bracketed at confidence
   0.95 with q = 0.05.
2. Independently, a bisection in r: at each probe an ensemble of ``--probe-members``
   members all with ``‖α⁰‖∞ = r`` (another seed); r is *stable enough* where at least
   1 − q of them are stable; 20 halvings of the log-bracket [1e-4, 1].

The bisection's r must lie in the profile's bracket.  Writes the profile picture to
``--figure`` and the figures to ``--out``.

Usage::

    python studies/check_profile.py [--members 4096] [--probe-members 10000]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings
from pathlib import Path

import stabdae
from stabdae.plots import profile_curve

HERE = Path(__file__).resolve().parent
TAU, T_END, Q = 0.015, 1.5, 0.05


def ensemble(model, law, members, radius, seed):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stabdae.IntegrationWarning)
        return stabdae.ensemble(model, law, "midpoint", TAU, T_END, members=members,
                                radius=radius, seed=seed, traces="none", states=False)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--members", type=int, default=4096)
    ap.add_argument("--probe-members", type=int, default=10_000)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--figure", type=Path, default=HERE.parent / "docs" / "figures")
    args = ap.parse_args(argv)
    model = stabdae.load_model("pendulum")
    law = stabdae.baumgarte(100.0, 1.0)
    clock = time.perf_counter()
    ds = ensemble(model, law, args.members, (1e-4, 1.0), seed=1)
    profile = stabdae.radial_profile(ds, bins=12, q=Q)
    wall_profile = time.perf_counter() - clock

    def stable_enough(r: float) -> tuple[bool, float]:
        probe = ensemble(model, law, args.probe_members, (r, r), seed=2)
        share = float((probe.verdict.values == 0).mean())
        return share >= 1 - Q, share

    clock = time.perf_counter()
    lo, hi = 1e-4, 1.0
    probes = []
    assert stable_enough(lo)[0] and not stable_enough(hi)[0]
    for _ in range(20):
        mid = math.sqrt(lo * hi)
        ok, share = stable_enough(mid)
        probes.append([mid, share])
        lo, hi = (mid, hi) if ok else (lo, mid)
    r_star = math.sqrt(lo * hi)
    d_low, d_high = float(profile.delta_star_low), float(profile.delta_star_high)
    inside = (not math.isfinite(d_low) or d_low <= r_star) and \
        (not math.isfinite(d_high) or r_star <= d_high)  # fmt: skip
    report = {"members": args.members, "probe_members": args.probe_members, "q": Q,
              "delta_star_low": d_low, "delta_star_high": d_high,
              "delta_star_reason": int(profile.delta_star_reason),
              "sample_delta_star": [float(ds.stability_radius_low),
                                    float(ds.stability_radius_high)],
              "bisection_r": r_star, "bisection_probes": probes, "inside": inside,
              "wall_profile_s": wall_profile,
              "wall_bisection_s": time.perf_counter() - clock,
              "bins": profile[["radius_low", "radius_high", "members", "members_stable",
                               "fraction_stable_low", "fraction_stable_high"]]
              .to_dataframe().reset_index().to_dict("records")}  # fmt: skip
    print(json.dumps({k: v for k, v in report.items() if k not in ("bins", "bisection_probes")},
                     indent=1))  # fmt: skip
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "check_profile.json").write_text(json.dumps(report, indent=1))
    args.figure.mkdir(parents=True, exist_ok=True)
    profile_curve(profile, args.figure / "pendulum_radial_profile.png", reference=r_star)
    return 0 if inside else 1


if __name__ == "__main__":
    sys.exit(main())
