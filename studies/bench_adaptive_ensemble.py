"""Adaptive ensembles: ``stabdae.ensemble(..., rtol=...)`` of this revision against an
earlier one, measured in one run.

For each model, embedded pair and tolerance: the best wall time of ``--repeat`` runs of the
integration (``wall_integrate_s``: compilation excluded, one run first), the right-hand
sides per member, and whether both revisions give the same final states bit for bit.  The
earlier revision runs in a second process from a git worktree with its own kernel cache;
the two alternate, never run at once.

Usage::

    python studies/bench_adaptive_ensemble.py [--models pendulum double_pendulum]
        [--rtol 1e-6 1e-10] [--members 4096] [--t-end 10] [--repeat 3] [--baseline REV]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def law_for(stabdae, name):
    return stabdae.baumgarte(1e4 if name == "andrews" else 10.0, 1.0)


def measure(name, pair, rtol, members, t_end, repeat, out_npy=None) -> dict:
    import stabdae

    model = stabdae.load_model(name)
    law = law_for(stabdae, name)
    kw = dict(tau=1e-3, t_end=t_end, radius=(1e-6, 1e-3), seed=1, rtol=rtol, atol=rtol,
              traces="none")  # fmt: skip
    stabdae.ensemble(model, law, pair, members=4, **kw)  # compile
    best = np.inf
    for _ in range(repeat):
        ds = stabdae.ensemble(model, law, pair, members=members, **kw)
        best = min(best, ds.attrs["wall_integrate_s"])
    if out_npy:
        np.save(out_npy, ds.x_final.values)
    return dict(wall_s=best, evals_per_member=float(ds.rhs_evaluations.mean()),
                steps_per_member=float(ds.steps_accepted.mean()))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--models", nargs="+", default=["pendulum", "double_pendulum"])
    ap.add_argument("--pairs", nargs="+", default=["dopri5", "dop853"])
    ap.add_argument("--rtol", nargs="+", type=float, default=[1e-6, 1e-10])
    ap.add_argument("--members", type=int, default=4096)
    ap.add_argument("--t-end", type=float, default=10.0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--baseline", metavar="REV")
    ap.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:  # one measurement for the baseline process
        name, pair, rtol, npy = args.child
        print(json.dumps(measure(name, pair, float(rtol), args.members, args.t_end,
                                 args.repeat, npy)))  # fmt: skip
        return
    tree = None
    if args.baseline:
        tmp = Path(tempfile.mkdtemp(prefix="stabdae-baseline-"))
        tree = tmp / "tree"
        subprocess.run(["git", "-C", str(HERE.parent), "worktree", "add", "--detach", str(tree),
                        args.baseline], check=True, capture_output=True)  # fmt: skip
        env = dict(os.environ, PYTHONPATH=str(tree / "src"), STABDAE_CACHE_DIR=str(tmp / "c"))
    rows = []
    try:
        for name in args.models:
            for pair in args.pairs:
                for rtol in args.rtol:
                    npy = str(Path(tempfile.gettempdir()) / "stabdae-bench-now.npy")
                    row = dict(model=name, pair=pair, rtol=rtol,
                               **measure(name, pair, rtol, args.members, args.t_end,
                                         args.repeat, npy))  # fmt: skip
                    if tree is not None:
                        base_npy = str(tmp / "base.npy")
                        out = subprocess.run(
                            [sys.executable, __file__, "--child", name, pair, str(rtol),
                             base_npy, "--members", str(args.members), "--t-end",
                             str(args.t_end), "--repeat", str(args.repeat)],
                            check=True, capture_output=True, text=True, env=env,
                            cwd=str(tmp))  # fmt: skip
                        base = json.loads(out.stdout.strip().splitlines()[-1])
                        row["baseline_wall_s"] = base["wall_s"]
                        row["speedup"] = base["wall_s"] / row["wall_s"]
                        row["same_final_states"] = bool(np.array_equal(np.load(npy),
                                                                       np.load(base_npy)))
                    rows.append(row)
                    print(json.dumps(row), flush=True)
    finally:
        if tree is not None:
            subprocess.run(["git", "-C", str(HERE.parent), "worktree", "remove", "--force",
                            str(tree)], check=False, capture_output=True)  # fmt: skip
    return rows


if __name__ == "__main__":
    main()
