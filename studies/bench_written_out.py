"""Where the dense path's linear algebra stops being written out: the first ensemble and
the integration of a model at several values of ``UNROLL_MAX_OPS`` (the largest piece, in
multiply-adds, that :mod:`stabdae.engine.linalg` and the structured right-hand side write
out; larger ones keep their loops), and the compile and run time of a written-out dense
factor and solve against the loops by size.

Each (model, limit) runs in a new process with an empty kernel cache (the library's own
functions already in numba's cache, as after any first use): one first ensemble (4096
members, midpoint, Baumgarte ω = 10, ξ = 1, k = 10, τ = 1e-3, 1 s, as
``bench_first_ensemble.py``), then the same ensemble again, whose ``wall_integrate_s`` is
the integration alone::

    python studies/bench_written_out.py --scenes n_four_bar bicycle_redundant --limits 0 512 2048
    python studies/bench_written_out.py --dense 8 12 16 20 24 30
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent

MODEL = r"""
import json, sys, time, warnings
warnings.simplefilter("ignore")
from stabdae.engine import linalg, rhs
linalg.UNROLL_MAX_OPS = rhs.UNROLL_MAX_OPS = int(sys.argv[2])
import stabdae
from stabdae.engine.jit import compile_seconds
model = stabdae.load_model(sys.argv[1])
law = stabdae.baumgarte(10.0, 1.0, 10.0 if model.k else None)
kw = dict(members=4096, radius=(1e-6, 1e-3), seed=1)
clock, c0 = time.perf_counter(), compile_seconds()
stabdae.ensemble(model, law, "midpoint", 1e-3, 1.0, **kw)
first, compiling = time.perf_counter() - clock, compile_seconds() - c0
warm = stabdae.ensemble(model, law, "midpoint", 1e-3, 1.0, **kw).attrs["wall_integrate_s"]
planned = rhs._structured(model, model.n, model.m, model.k) is not None
print(json.dumps(dict(first=first, compiling=compiling, integrate=warm, planned=planned)))
"""

DENSE = r"""
import json, sys, time
import numpy as np
from numba import njit
from stabdae.engine import linalg
n = int(sys.argv[1])
linalg.UNROLL_MAX_OPS = 10**9
clock = time.perf_counter()
factor, solve = linalg.ldl_factor_for(n).emitted, linalg.ldl_solve_for(n).emitted
written = time.perf_counter() - clock

def timed(factor, solve):
    @njit(error_model="numpy")
    def run(A, b, reps):
        s = 0.0
        for _ in range(reps):
            for i in range(A.shape[0]):
                a, x = A[i].copy(), b[i].copy()
                factor(a, n, 1e-14)
                solve(a, n, x)
                s += x[0]
        return s
    return run

out, loops = timed(factor, solve), timed(linalg.ldl_inplace, linalg.ldl_solve_inplace)

rng = np.random.default_rng(0)
B = rng.standard_normal((64, n, n))
A, b = B @ B.transpose(0, 2, 1) + n * np.eye(n), rng.standard_normal((64, n))
clock = time.perf_counter()
out(A, b, 1)
compiling = time.perf_counter() - clock
loops(A, b, 1)
reps = max(1, 20000 // n**2)
clock = time.perf_counter()
s_out = out(A, b, reps)
t_out = time.perf_counter() - clock
clock = time.perf_counter()
s_loops = loops(A, b, reps)
t_loops = time.perf_counter() - clock
assert s_out == s_loops  # the same operations in the same order
print(json.dumps(dict(written=written, compiling=compiling, ratio=t_out / t_loops)))
"""


def child(code: str, *args) -> dict:
    with tempfile.TemporaryDirectory(prefix="stabdae-written-") as cache:
        env = dict(os.environ, PYTHONPATH=str(HERE.parent / "src"), STABDAE_CACHE_DIR=cache)
        out = subprocess.run([sys.executable, "-c", code, *map(str, args)], env=env,
                             check=True, capture_output=True, text=True)  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="*", default=[])
    ap.add_argument("--limits", nargs="+", type=int, default=[0, 512, 2048])
    ap.add_argument("--dense", nargs="*", type=int, default=[], metavar="N")
    args = ap.parse_args(argv)
    if args.scenes:
        child(MODEL, args.scenes[0], args.limits[0])  # the library's functions into the cache
    for scene in args.scenes:
        print(f"\n{scene}: limit  structured  first ensemble  of it compiling  integration (s)")
        for limit in args.limits:
            r = child(MODEL, scene, limit)
            print(f"  {limit:>14}  {'yes' if r['planned'] else 'no':>10}  {r['first']:14.2f}"
                  f"  {r['compiling']:17.2f}  {r['integrate']:11.3f}")
    if args.dense:
        print("\ndense factor + solve written out:  n  multiply-adds  writing (s)  compiling (s)"
              "  run time / loops'")
        for n in args.dense:
            r = child(DENSE, n)
            print(f"  {n:>33}  {n**3 // 6 + n * n:13d}  {r['written']:11.2f}"
                  f"  {r['compiling']:13.2f}  {r['ratio']:17.2f}")


if __name__ == "__main__":
    main()
