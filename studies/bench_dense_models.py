"""Ensembles of models on the dense path (a mass matrix that is not diagonal), this
revision against an earlier one, in one run.

    python studies/bench_dense_models.py [--baseline REV] [--repeat 3] [--only SCENE:SCHEME ...]

Each configuration runs in a fresh process per revision with a fresh kernel cache: the
first call (compiling the sampler, the reference stepper and the ensemble kernel, then
integrating) and the best of ``--repeat`` further calls' ``wall_integrate_s`` (the kernel
on every thread), with a digest of the final states, which must be equal between the two
revisions when the change moved no number.  ``--baseline`` takes a git revision, checked
out in a temporary worktree; each revision runs its own model files.  The environment is
passed on (``STABDAE_VECTOR_WIDTH=256`` runs this revision at the compiler's default
vector width).  The results go to ``results/dense_models.json``.
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

#: (scene, scheme, ω, τ, t_end, members): Baumgarte ξ = 1 (k = 10 for nonholonomic
#: rows), radii 1e-8 … 1e-4
CONFIGS = [
    ("andrews", "midpoint", 1e3, 1e-5, 0.006, 2000),
    ("andrews", "rk4", 1e3, 1e-5, 0.006, 2000),
    ("andrews", "dop853", 1e3, 1e-4, 0.006, 2000),
    ("slider_crank", "rk4", 100.0, 1e-4, 0.2, 4000),
    ("double_pendulum", "midpoint", 10.0, 1e-3, 2.0, 10000),
    ("double_pendulum", "dop853", 10.0, 0.02, 2.0, 10000),
    ("spherical_pendulum", "rk4", 10.0, 1e-3, 2.0, 4000),
    ("pendulum", "dop853", 10.0, 0.02, 10.0, 10000),  # diagonal mass: the width alone
    # coupled mechanisms of many constraints (k = 10 for the bicycle's rolling rows)
    ("n_four_bar", "rk4", 10.0, 1e-3, 1.0, 4096),
    ("bricard_independent", "midpoint", 10.0, 1e-3, 1.0, 4096),
    ("bicycle_redundant", "midpoint", 10.0, 1e-3, 1.0, 4096),
]

_CHILD = """
import hashlib, json, sys, time
import numpy as np
import stabdae
scene, scheme, omega, tau, t_end, members, repeat, kernels = sys.argv[1:]
model = stabdae.load_model(f"{kernels}/{scene}.py")
law = stabdae.baumgarte(float(omega), 1.0, 10.0 if model.k else None)
kw = dict(members=int(members), radius=(1e-8, 1e-4), seed=1, traces="none", states=True)
start = time.perf_counter()
stabdae.ensemble(model, law, scheme, float(tau), float(t_end), **kw)
first = time.perf_counter() - start
best = min(float(stabdae.ensemble(model, law, scheme, float(tau), float(t_end), **kw)
                 .attrs["wall_integrate_s"]) for _ in range(int(repeat)))
ds = stabdae.ensemble(model, law, scheme, float(tau), float(t_end), **kw)
digest = hashlib.sha256(np.ascontiguousarray(ds.x_final.values).tobytes()).hexdigest()[:16]
print(json.dumps(dict(first_call_s=first, wall_integrate_s=best, final_states=digest)))
"""


def _run(tree: Path, config, repeat: int, cache: Path) -> dict:
    """One configuration with the library and the model files of ``tree`` (a generated
    model file uses what its own revision's generator emitted)."""
    env = dict(os.environ, PYTHONPATH=str(tree / "src"), STABDAE_CACHE_DIR=str(cache))
    out = subprocess.run([sys.executable, "-c", _CHILD, *map(str, config), str(repeat),
                          str(tree / "kernels")], env=env, check=True,
                         capture_output=True, text=True).stdout  # fmt: skip
    return json.loads(out.strip().splitlines()[-1])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--baseline", metavar="REV", default=None)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--only", nargs="+", metavar="SCENE:SCHEME", default=None,
                    help="run these configurations only (e.g. andrews:dop853)")
    args = ap.parse_args(argv)
    configs = [c for c in CONFIGS if args.only is None or f"{c[0]}:{c[1]}" in args.only]
    if not configs:
        ap.error(f"--only {' '.join(args.only)}: none of "
                 + ", ".join(f"{c[0]}:{c[1]}" for c in CONFIGS))
    tmp = Path(tempfile.mkdtemp(prefix="stabdae-dense-"))
    trees = {"this": HERE.parent}
    if args.baseline:
        subprocess.run(["git", "-C", str(HERE.parent), "worktree", "add", "--detach",
                        str(tmp / "tree"), args.baseline], check=True, capture_output=True)
        trees[args.baseline] = tmp / "tree"
    rows = []
    try:
        for config in configs:
            row = dict(zip(("scene", "scheme", "omega", "tau", "t_end", "members"), config))
            for name, src in trees.items():
                row[name] = _run(src, config, args.repeat, tmp / f"cache-{len(rows)}-{name}")
            this = row["this"]
            line = (f"{config[0]:>18} {config[1]:>8}: first call {this['first_call_s']:6.1f} s, "
                    f"integration {this['wall_integrate_s']:.4f} s")  # fmt: skip
            if args.baseline:
                base = row[args.baseline]
                row["speedup"] = base["wall_integrate_s"] / this["wall_integrate_s"]
                row["same_final_states"] = base["final_states"] == this["final_states"]
                line += (f"  | {args.baseline}: {base['first_call_s']:6.1f} s, "
                         f"{base['wall_integrate_s']:.4f} s  | {row['speedup']:.2f}x, "
                         f"same final states: {row['same_final_states']}")  # fmt: skip
            print(line, flush=True)
            rows.append(row)
    finally:
        if args.baseline:
            subprocess.run(["git", "-C", str(HERE.parent), "worktree", "remove", "--force",
                            str(tmp / "tree")], check=False, capture_output=True)  # fmt: skip
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "dense_models.json").write_text(json.dumps(
        dict(baseline=args.baseline, cpus=os.cpu_count(),
             vector_width=os.environ.get("STABDAE_VECTOR_WIDTH", "512 where the CPU has it"),
             rows=rows), indent=1))


if __name__ == "__main__":
    main()
