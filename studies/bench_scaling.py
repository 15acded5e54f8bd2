"""Throughput and compile time against model size: Fekete's N charges, a chain of N pendulums.

Fekete's N constraints ``|p_i|² = 1`` touch three coordinates each, so S = F M⁻¹ Fᵀ is
diagonal and the stabilized right-hand side's constraint part is N scalar divisions; its
cost is the Coulomb sum, O(N²).  Beside stabdae's ensemble (the sparse right-hand side it
builds from the detected pattern, and the dense one for comparison), a kernel written by
hand in Numba for this model alone: one member per thread, the stabilized acceleration
in closed form (v̇_i = 2 λ_i p_i − γ_i, λ_i from the charge's own scalar equation), the
same midpoint steps.  Both start from the same states; their final states are compared.

The chain of N planar pendulums (``kernels/pendulum_chain.py``: n = 2N, m = N, unit
masses) couples neighbouring constraints: S is tridiagonal and its factor has no fill.  It
has no kernel written by hand; ``--dense`` sets the dense right-hand side beside it.

    python studies/bench_scaling.py                 # Fekete, N = 5, 10, 20, 40
    python studies/bench_scaling.py --N 20 --members 4096 --dense
    python studies/bench_scaling.py --model chain --N 4 8 16 32 64 --dense

Compile time is the first ensemble of each model in this process (the library's own
functions, shared by every model, come from the kernel cache after the first).
"""

from __future__ import annotations

import argparse
import math
import platform
import time
from pathlib import Path

import numpy as np
from numba import get_num_threads, njit, prange

import stabdae

HERE = Path(__file__).resolve().parent


@njit(inline="always")
def _accel(x, n, a, omega, xi, xdot):
    N = n // 3
    for i in range(n):
        xdot[i] = x[n + i]
        xdot[n + i] = a * x[n + i]  # γ = a v − Coulomb
    for i in range(N):
        for j in range(i + 1, N):
            d0 = x[3 * i] - x[3 * j]
            d1 = x[3 * i + 1] - x[3 * j + 1]
            d2 = x[3 * i + 2] - x[3 * j + 2]
            r2 = d0 * d0 + d1 * d1 + d2 * d2
            w = 1.0 / (r2 * math.sqrt(r2))
            xdot[n + 3 * i] -= w * d0
            xdot[n + 3 * i + 1] -= w * d1
            xdot[n + 3 * i + 2] -= w * d2
            xdot[n + 3 * j] += w * d0
            xdot[n + 3 * j + 1] += w * d1
            xdot[n + 3 * j + 2] += w * d2
    for i in range(N):
        qq = qv = vv = qg = 0.0
        for c in range(3):
            q, v, g = x[3 * i + c], x[n + 3 * i + c], xdot[n + 3 * i + c]
            qq += q * q
            qv += q * v
            vv += v * v
            qg += q * g
        target = -omega * omega * (qq - 1.0) - 2.0 * xi * omega * (2.0 * qv)
        lam = (target - 2.0 * vv + 2.0 * qg) / (4.0 * qq)
        for c in range(3):
            xdot[n + 3 * i + c] = 2.0 * lam * x[3 * i + c] - xdot[n + 3 * i + c]


@njit(parallel=True, error_model="numpy")
def hand_midpoint(x0s, tau, nsteps, a, omega, xi, out):
    """Baumgarte-stabilized Fekete, midpoint rule, one member per iteration."""
    M, n2 = x0s.shape
    n = n2 // 2
    for i in prange(M):
        x = x0s[i].copy()
        k = np.empty(n2)
        xm = np.empty(n2)
        for _ in range(nsteps):
            _accel(x, n, a, omega, xi, k)
            for l in range(n2):
                xm[l] = x[l] + 0.5 * tau * k[l]
            _accel(xm, n, a, omega, xi, k)
            for l in range(n2):
                x[l] = x[l] + tau * k[l]
        out[i] = x


FILES = {"fekete": "fekete.py", "chain": "pendulum_chain.py"}


def build(name: str, N: int, sparsity: str = "detect") -> stabdae.Model:
    """The model ``name`` (a key of :data:`FILES`) of size ``N``."""
    import sys

    from stabdae._loading import module_name

    path = HERE.parent / "kernels" / FILES[name]
    base = stabdae.load_model(path)
    model = sys.modules[module_name(path)].build(N) if N != base.m else base
    return model if sparsity == "detect" else model.replace(sparsity=sparsity)


def measure(name: str, N: int, members: int, t_end: float, repeats: int,
            dense: bool) -> list[dict]:  # fmt: skip
    tau, omega, xi = 0.01, 10.0, 1.0
    law = stabdae.baumgarte(omega, xi)
    nsteps = round(t_end / tau)
    rows = []
    for kind in ("sparse", "dense") if dense else ("sparse",):
        model = build(name, N, "detect" if kind == "sparse" else "dense")
        assert (model.sparse_structure() is not None) == (kind == "sparse")
        clock = time.perf_counter()
        stabdae.ensemble(model, law, "midpoint", tau, 2 * tau, members=8, radius=(1e-6, 1e-5),
                         seed=1)  # fmt: skip
        compile_s = time.perf_counter() - clock
        best, ds = math.inf, None
        for _ in range(repeats):
            ds = stabdae.ensemble(model, law, "midpoint", tau, t_end, members=members,
                                  radius=(1e-6, 1e-4), seed=1, traces=0)  # fmt: skip
            best = min(best, ds.attrs["wall_integrate_s"])
        rows.append(dict(N=N, n=model.n, kind=kind, compile_s=compile_s, wall_s=best,
                         rate=members * nsteps / best, x0=ds.x0.values,
                         x_final=ds.x_final.values))  # fmt: skip
    if name != "fekete":  # no hand-written kernel: the paths against each other
        for row in rows[1:]:
            row["diff"] = float(np.max(np.abs(row["x_final"] - rows[0]["x_final"])))
        return rows
    x0 = np.ascontiguousarray(rows[0]["x0"])
    out = np.empty_like(x0)
    clock = time.perf_counter()
    hand_midpoint(x0[:2], tau, 2, 0.5, omega, xi, out[:2])
    hand_compile = time.perf_counter() - clock
    best = math.inf
    for _ in range(repeats):
        clock = time.perf_counter()
        hand_midpoint(x0, tau, nsteps, 0.5, omega, xi, out)
        best = min(best, time.perf_counter() - clock)
    for row in rows:
        row["diff"] = float(np.max(np.abs(out - row["x_final"])))
    rows.append(dict(N=N, n=model.n, kind="hand", compile_s=hand_compile, wall_s=best,
                     rate=members * nsteps / best))  # fmt: skip
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", choices=sorted(FILES), default="fekete")
    parser.add_argument("--N", type=int, nargs="+", default=[5, 10, 20, 40])
    parser.add_argument("--members", type=int, default=4096)
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--dense", action="store_true", help="also the dense right-hand side")
    args = parser.parse_args()
    print(f"# {args.model}, {platform.processor() or platform.machine()}, "
          f"{get_num_threads()} threads, {args.members} members, {args.t_end} s, "
          "midpoint τ = 0.01, Baumgarte ω = 10, ξ = 1")  # fmt: skip
    against = "hand" if args.model == "fekete" else "sparse"
    print(f"{'N':>4} {'n':>4} {'path':>7} {'first (s)':>10} {'member-steps/s':>15} "
          f"{'/ ' + against:>8}  max |Δx_final| vs {against}")  # fmt: skip
    for N in args.N:
        rows = measure(args.model, N, args.members, args.t_end, args.repeats, args.dense)
        ref = rows[-1] if against == "hand" else rows[0]
        for row in rows:
            extra = f"{row['diff']:.1e}" if "diff" in row else ""
            print(f"{N:>4} {row['n']:>4} {row['kind']:>7} {row['compile_s']:>10.2f} "
                  f"{row['rate']:>15.3e} {row['rate'] / ref['rate']:>8.2f}  {extra}")


if __name__ == "__main__":
    main()
