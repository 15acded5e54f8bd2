"""What a study costs beside its integration: a study run in-process, its phases timed.

    python studies/bench_study.py [STUDY] [--members N] [--repeat 3]
    python studies/bench_study.py --ensemble 100000

For each run: the grid points' wall time, their sampling and integration (the
ensembles' own ``wall_sample_s + wall_integrate_s``), and the phases around them
(building each point's table, writing the chunks, stacking the dataset, writing it,
the summary).  ``--ensemble M``: instead, one ensemble of M members without traces
(pendulum, midpoint, 5 s), its time and the process's peak memory.  The first run
compiles (or loads the kernels from the cache); report the later ones.
"""

from __future__ import annotations

import argparse
import collections
import functools
import resource
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _timed(phases, owner, name, label):
    real = getattr(owner, name)

    @functools.wraps(real)
    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        try:
            return real(*args, **kwargs)
        finally:
            phases[label] += time.perf_counter() - start

    setattr(owner, name, wrapper)


def study(path: Path, members: int | None, repeat: int) -> None:
    import stabdae._ensemble as ens
    import stabdae.study.run as run
    import stabdae.study.store as store

    phases = collections.Counter()
    _timed(phases, run, "run_point", "points")
    _timed(phases, run, "combine", "stack")
    _timed(phases, run, "write_netcdf", "write")
    _timed(phases, run, "summary", "summary")
    _timed(phases, store.Store, "flush", "chunks")
    _timed(phases, ens, "_table", "tables")
    said = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeat):
            phases.clear()
            said.clear()
            start = time.perf_counter()
            run.run_study(path, Path(tmp) / "out.nc", force=True, members=members,
                          progress=False, log=said.append)  # fmt: skip
            wall = time.perf_counter() - start
            line = next(s for s in said if str(s).startswith("dataset written"))
            print(f"run {k + 1}: {wall:.2f} s in run_study; {line.split(' (', 1)[1][:-1]}")
            print("   phases: " + ", ".join(f"{n} {v:.3f} s" for n, v in phases.items()))


def one_ensemble(members: int) -> None:
    import stabdae

    model = stabdae.load_model("pendulum")
    for _ in range(2):
        start = time.perf_counter()
        ds = stabdae.ensemble(model, stabdae.baumgarte(10, 1), "midpoint", 1e-3, 5.0,
                              members=members, radius=(1e-8, 1e-3), seed=1,
                              traces="none")  # fmt: skip
        wall = time.perf_counter() - start
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        print(f"{members} members: {wall:.2f} s (sampling {ds.attrs['wall_sample_s']:.2f} s, "
              f"integration {ds.attrs['wall_integrate_s']:.2f} s), dataset "
              f"{ds.nbytes / 2**20:.1f} MiB, peak RSS {peak:.0f} MiB")  # fmt: skip


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("study", nargs="?", default=str(ROOT / "studies" / "pendulum_tau_omega.toml"))
    ap.add_argument("--members", type=int, help="override [ensemble] members")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ensemble", type=int, metavar="M", help="one ensemble of M members")
    args = ap.parse_args(argv)
    if args.ensemble:
        one_ensemble(args.ensemble)
    else:
        study(Path(args.study), args.members, args.repeat)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
