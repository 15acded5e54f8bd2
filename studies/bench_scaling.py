"""Throughput and compile time against model size: the Fekete problem with N charges.

Fekete's N constraints ``|p_i|² = 1`` touch three coordinates each, so S = F M⁻¹ Fᵀ is
diagonal and the stabilized right-hand side's constraint part is N scalar divisions; its
cost is the Coulomb sum, O(N²).  Beside stabdae's ensemble (the sparse right-hand side it
builds from the detected pattern, and the dense one for comparison), a kernel written by
hand in Numba for this model alone: one member per thread, the stabilized acceleration
in closed form (v̇_i = 2 λ_i p_i − γ_i, λ_i from the charge's own scalar equation), the
same midpoint steps.  Both start from the same states; their final states are compared.

    python studies/bench_scaling.py                 # N = 5, 10, 20, 40
    python studies/bench_scaling.py --N 20 --members 4096 --dense

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


def fekete(N: int, sparsity: str = "detect") -> stabdae.Model:
    base = stabdae.load_model(HERE.parent / "kernels" / "fekete.py")
    import sys

    from stabdae._loading import module_name

    module = sys.modules[module_name(HERE.parent / "kernels" / "fekete.py")]
    model = module.build(N) if N != base.n // 3 else base
    return model if sparsity == "detect" else model.replace(sparsity=sparsity)


def measure(N: int, members: int, t_end: float, repeats: int, dense: bool) -> list[dict]:
    tau, omega, xi = 0.01, 10.0, 1.0
    law = stabdae.baumgarte(omega, xi)
    nsteps = round(t_end / tau)
    rows = []
    for kind in ("sparse", "dense") if dense else ("sparse",):
        model = fekete(N, "detect" if kind == "sparse" else "dense")
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
        rows.append(dict(N=N, kind=kind, compile_s=compile_s, wall_s=best,
                         rate=members * nsteps / best, x0=ds.x0.values,
                         x_final=ds.x_final.values))  # fmt: skip
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
    diff = float(np.max(np.abs(out - rows[0]["x_final"])))
    rows.append(dict(N=N, kind="hand", compile_s=hand_compile, wall_s=best,
                     rate=members * nsteps / best, diff=diff))  # fmt: skip
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--N", type=int, nargs="+", default=[5, 10, 20, 40])
    parser.add_argument("--members", type=int, default=4096)
    parser.add_argument("--t-end", type=float, default=1.0)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--dense", action="store_true", help="also the dense right-hand side")
    args = parser.parse_args()
    print(f"# {platform.processor() or platform.machine()}, {get_num_threads()} threads, "
          f"{args.members} members, {args.t_end} s, midpoint τ = 0.01, Baumgarte ω = 10, ξ = 1")
    print(f"{'N':>4} {'n':>4} {'path':>7} {'first (s)':>10} {'member-steps/s':>15} "
          f"{'/ hand':>7}  max |Δx_final| vs hand")  # fmt: skip
    for N in args.N:
        rows = measure(N, args.members, args.t_end, args.repeats, args.dense)
        hand = rows[-1]
        for row in rows:
            extra = f"{hand['diff']:.1e}" if row["kind"] == "sparse" else ""
            print(f"{N:>4} {3 * N:>4} {row['kind']:>7} {row['compile_s']:>10.2f} "
                  f"{row['rate']:>15.3e} {row['rate'] / hand['rate']:>7.2f}  {extra}")


if __name__ == "__main__":
    main()
