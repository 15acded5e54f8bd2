"""The rigid-body scenes against their references over 10 s, scheme by scheme.

``heavy_top`` (a Lagrange top in steady precession) and ``free_body`` (a torque-free
asymmetric body flipping about its intermediate axis), both in a unit quaternion with body
angular velocities (a kinematic map ``q̇ = T(q) v``), under Baumgarte ω = 10, ξ = 1, from
their reference states, with Euler (τ = 1e-4), the midpoint rule and RK4 (τ = 1e-3) and
DOP853 (rtol = atol = 1e-12).  Per run: the largest error against the closed form over
10 s (the top's symmetry axis against the steady precession at its closed-form rate; the
body's angular velocity against the Jacobi elliptic solution), the largest drifts of the
first integrals (energy; the top's vertical and axial momenta; the body's world angular
momentum, all three components), the largest constraint residual ‖g‖∞ (the quaternion's
norm and its rate) and the wall time of the call, compiling included the first time a
kernel is needed.

Usage::

    python studies/check_rigid_bodies.py [--out studies/results]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

import stabdae
from stabdae import rigid

HERE = Path(__file__).resolve().parent
RUNS = (("euler", 1e-4), ("midpoint", 1e-3), ("rk4", 1e-3), ("dop853", None))


def _run(model, scheme, tau, save_dt):
    law = stabdae.baumgarte(10.0, 1.0)
    clock = time.perf_counter()
    if tau is None:
        ds = stabdae.integrate_adaptive(model, None, law, 10.0, scheme=scheme, rtol=1e-12,
                                        atol=1e-12, save_dt=save_dt)
    else:
        ds = stabdae.integrate(model, None, law, scheme, tau, 10.0, save_dt)
    return ds, time.perf_counter() - clock


def _module(model):
    return sys.modules[model.functions["forces"].py_func.__module__]


def top_row(scheme, tau) -> dict:
    model = stabdae.load_model("heavy_top")
    top, p = _module(model), model.default_params()
    ds, wall = _run(model, scheme, tau, 0.05)
    t, X = ds.time.values, ds.x.values
    exact = top.exact_axis(t, p)
    axis = rigid.rotations(X)[:, :, 2]  # R(p/|p|) e₃
    A, C = p[0], p[1]
    L = rigid.angular_momentum(X, np.diag([A, A, C]))
    E = ds.energy.values
    return {"scene": "heavy_top", "scheme": scheme, "tau": tau, "wall_s": wall,
            "reference_error": float(np.abs(axis - exact).max()),
            "energy_drift": float(np.abs(E - E[0]).max()),
            "momentum_drift": float(max(np.abs(L[:, 2] - L[0, 2]).max(),
                                        np.abs(C * (X[:, 7] - X[0, 7])).max())),
            "residual_max": float(ds.residual_norm.values.max())}  # fmt: skip


def body_row(scheme, tau) -> dict:
    model = stabdae.load_model("free_body")
    body, p = _module(model), model.default_params()
    ds, wall = _run(model, scheme, tau, 0.01)
    t, X = ds.time.values, ds.x.values
    exact, _ = body.exact_omega(t, p)
    L = rigid.angular_momentum(X, np.diag(p[:3]))
    E = ds.energy.values
    return {"scene": "free_body", "scheme": scheme, "tau": tau, "wall_s": wall,
            "reference_error": float(np.abs(X[:, 5:8] - exact).max()),
            "energy_drift": float(np.abs(E - E[0]).max()),
            "momentum_drift": float(np.abs(L - L[0]).max()),
            "residual_max": float(ds.residual_norm.values.max())}  # fmt: skip


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=str(HERE / "results"))
    args = ap.parse_args(argv)
    rows = [row(s, tau) for row in (top_row, body_row) for s, tau in RUNS]
    print("scene       scheme     tau     reference   energy      momenta     max ‖g‖∞   wall_s")
    for r in rows:
        tau = "adaptive" if r["tau"] is None else f"{r['tau']:.0e}"
        print(f"{r['scene']:11s} {r['scheme']:9s} {tau:8s} {r['reference_error']:.2e}   "
              f"{r['energy_drift']:.2e}   {r['momentum_drift']:.2e}   {r['residual_max']:.2e}  "
              f"{r['wall_s']:6.1f}")  # fmt: skip
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    stamp = time.strftime("%Y-%m-%d")
    (out / "rigid_bodies.json").write_text(json.dumps({"date": stamp, "rows": rows}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
