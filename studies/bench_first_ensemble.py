"""The first ensemble of a model: seconds from calling ``stabdae.ensemble`` in a new process
with an empty kernel cache to its dataset, and where they go (numba's ``numba:compile`` and
``numba:llvm_lock`` events: each kernel's compilation, and LLVM's part of it).

Every run is a new process with a new kernel cache (``STABDAE_CACHE_DIR``); the library's
own functions are in numba's cache already (one run per source tree first, not counted),
as after any first use.  With ``--baseline REV`` the same runs of that git revision (a
worktree) alternate with this tree's, so that both see the same machine::

    python studies/bench_first_ensemble.py --scenes fekete pendulum --repeat 3 --baseline HEAD

The ensemble: 4096 members, radius (1e-6, 1e-3), midpoint, Baumgarte ω = 10, ξ = 1 (and
k = 10 for nonholonomic rows), over 1 s, τ = 0.01 for Fekete's charges and 1e-3 otherwise.

With ``--table``: per scene, its sizes and right-hand side's size
(:func:`stabdae.engine.rhs.rhs_size`), the seconds to load it, its first ensemble cold
with the compile-ahead helper off and on (``STABDAE_COMPILE_AHEAD=0`` and the default),
idle and with ``--load`` busy processes beside it, and a warm ensemble (a new process,
the kernels in the cache); a Markdown table, and ``results/first_ensemble.json``::

    python studies/bench_first_ensemble.py --table --scenes bicycle heavy_top --load 1
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
MEMBERS = 4096

CHILD = r"""
import json, sys, time
from numba.core import event
import stabdae

class Events(event.Listener):
    def __init__(self):
        self.llvm, self.held, self.depth, self.rows = 0.0, None, [], []
    def on_start(self, ev):
        if ev.kind == "numba:llvm_lock":
            self.held = time.perf_counter()
        elif ev.kind == "numba:compile":
            self.depth.append((ev.data["dispatcher"], time.perf_counter(), self.llvm))
    def on_end(self, ev):
        if ev.kind == "numba:llvm_lock":
            self.llvm += time.perf_counter() - self.held
        elif ev.kind == "numba:compile":
            d, t0, l0 = self.depth.pop()
            if not self.depth:  # a kernel (what it compiles inside it included)
                name = getattr(d, "__qualname__", str(d)).split("<locals>.")[-1]
                self.rows.append((name, time.perf_counter() - t0, self.llvm - l0))

ev = Events()
event.register("numba:llvm_lock", ev)
event.register("numba:compile", ev)
scene, members = sys.argv[1], int(sys.argv[2])
clock = time.perf_counter()
model = stabdae.load_model(scene)
load_s = time.perf_counter() - clock
tau = 0.01 if scene == "fekete" else 1e-3
clock = time.perf_counter()
law = stabdae.baumgarte(10.0, 1.0, 10.0 if model.k else None)
ds = stabdae.ensemble(model, law, "midpoint", tau, 1.0,
                      members=members, radius=(1e-6, 1e-3), seed=1)
first = time.perf_counter() - clock
from stabdae._laws import bind_law
from stabdae.engine.rhs import kernels_for
size = kernels_for(model, bind_law(law, model)).size
print(json.dumps(dict(first=first, llvm=ev.llvm, kernels=ev.rows, load=load_s,
                      integrate=ds.attrs["wall_integrate_s"], size=size, n=model.n,
                      m=model.m, k=model.k)))
"""


def run(src: Path, scene: str, members: int, helper: str | None = None,
        warm: bool = False) -> dict:
    """One first ensemble of ``scene`` with the library at ``src``, a fresh kernel cache
    (``helper``: ``STABDAE_COMPILE_AHEAD``'s value, else the environment's); with
    ``warm``, also a second one in a new process on the same cache (``"warm"``)."""
    with tempfile.TemporaryDirectory(prefix="stabdae-first-") as cache:
        env = dict(os.environ, PYTHONPATH=str(src), STABDAE_CACHE_DIR=cache)
        if helper is not None:
            env["STABDAE_COMPILE_AHEAD"] = helper
        out = subprocess.run([sys.executable, "-c", CHILD, scene, str(members)], env=env,
                             check=True, capture_output=True, text=True)  # fmt: skip
        res = json.loads(out.stdout.strip().splitlines()[-1])
        if warm:
            again = subprocess.run([sys.executable, "-c", CHILD, scene, str(members)],
                                   env=env, check=True, capture_output=True, text=True)
            res["warm"] = json.loads(again.stdout.strip().splitlines()[-1])["first"]
    return res


def _busy(count: int) -> list:
    """``count`` processes that keep a CPU each busy (a second user of the machine)."""
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(count)]


def table(src: Path, scenes, members: int, load: int, out: Path) -> None:
    """The first-ensemble table of ``--table`` (the module's text)."""
    rows = []
    for scene in scenes:
        run(src, scene, 64)  # the library's own functions into numba's cache
        row = {"scene": scene}
        for label, count in (("idle", 0), ("loaded", load)):
            procs = _busy(count)
            try:
                for helper in ("0", "1"):
                    res = run(src, scene, members, helper, warm=(label == "idle"
                                                                 and helper == "0"))
                    row[f"{label}_{'helper' if helper == '1' else 'alone'}"] = res["first"]
                    row.update({k: res[k] for k in ("n", "m", "k", "size", "load")})
                    if "warm" in res:
                        row["warm"] = res["warm"]
            finally:
                for proc in procs:
                    proc.kill()
        rows.append(row)
        print(f"{scene}: {row}", flush=True)
    print(f"\n| scene | n | m + k | size | load, s | warm, s | cold idle: alone / helper, s | "
          f"cold beside {load} busy: alone / helper, s |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| `{r['scene']}` | {r['n']} | {r['m']} + {r['k']} | {r['size']} | "
              f"{r['load']:.2f} | {r['warm']:.2f} | {r['idle_alone']:.1f} / "
              f"{r['idle_helper']:.1f} | {r['loaded_alone']:.1f} / {r['loaded_helper']:.1f} |")
    out.mkdir(parents=True, exist_ok=True)
    (out / "first_ensemble.json").write_text(json.dumps(
        {"date": time.strftime("%Y-%m-%d"), "members": members, "busy": load,
         "rows": rows}, indent=1))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="+", default=["fekete", "pendulum"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--members", type=int, default=MEMBERS)
    ap.add_argument("--baseline", metavar="REV", help="also run this git revision (a worktree)")
    ap.add_argument("--table", action="store_true",
                    help="the per-scene table: sizes, load, warm, cold with and without the "
                         "helper, idle and loaded")
    ap.add_argument("--load", type=int, default=1,
                    help="with --table: busy processes beside the loaded runs (default 1)")
    ap.add_argument("--out", default=str(HERE / "results"))
    args = ap.parse_args(argv)
    if args.table:
        table(HERE.parent / "src", args.scenes, args.members, args.load, Path(args.out))
        return

    trees = {"this tree": HERE.parent / "src"}
    work = None
    if args.baseline:
        work = Path(tempfile.mkdtemp(prefix="stabdae-first-base-")) / "tree"
        subprocess.run(["git", "-C", str(HERE.parent), "worktree", "add", "--detach", str(work),
                        args.baseline], check=True, capture_output=True)  # fmt: skip
        rev = subprocess.run(["git", "-C", str(work), "rev-parse", "--short", "HEAD"],
                             check=True, capture_output=True, text=True).stdout.strip()  # fmt: skip
        trees[f"at {rev}"] = work / "src"
    try:
        for src in trees.values():  # the library's own functions into numba's cache (each
            for scene in args.scenes:  # scene's: the sines of one, the fits of another)
                run(src, scene, 64)
        for scene in args.scenes:
            print(f"\n{scene}: first ensemble, {args.members} members (s)")
            best = {}
            for _ in range(args.repeat):
                for label, src in trees.items():
                    res = run(src, scene, args.members)
                    kernels = ", ".join(f"{n} {s:.2f} (LLVM {ll:.2f})"
                                        for n, s, ll in res["kernels"] if s >= 0.1)  # fmt: skip
                    print(f"  {label:>14}: {res['first']:6.2f}  integration "
                          f"{res['integrate']:.2f}, LLVM {res['llvm']:.2f}; {kernels}")
                    best[label] = min(best.get(label, float("inf")), res["first"])
            print("  best: " + ", ".join(f"{k} {v:.2f}" for k, v in best.items()))
    finally:
        if work is not None:
            subprocess.run(["git", "-C", str(HERE.parent), "worktree", "remove", "--force",
                            str(work)], check=False, capture_output=True)  # fmt: skip


if __name__ == "__main__":
    main()
