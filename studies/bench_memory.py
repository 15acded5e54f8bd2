"""Memory and size of large ensembles and studies.

1. Peak resident memory of one ``stabdae.ensemble`` of ``--members`` planar pendulums
   (Baumgarte ω = 10, ξ = 1, midpoint rule, τ = 1e-3, 2 s), without traces, with and
   without the states ``x0``/``x_final``; each in a fresh process (``ru_maxrss``), beside
   the memory of the dataset it returns and its size written as NetCDF (zlib level 4).
2. With ``--study``: ``stabdae run studies/pendulum_tau_omega.toml --members N`` (100 grid
   points) in a fresh process, its peak memory, wall time and the size of the dataset file.

Usage::

    python studies/bench_memory.py [--members 1000000] [--study 100000]
                                   [--out studies/results]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent

ONE = """
import json, os, resource, sys, time
import stabdae
from stabdae._schema import write_netcdf
members, states, path = int(sys.argv[1]), sys.argv[2] == "1", sys.argv[3]
model = stabdae.load_model("pendulum")
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
clock = time.perf_counter()
ds = stabdae.ensemble(model, stabdae.baumgarte(10.0, 1.0), "midpoint", 1e-3, 2.0,
                      members=members, seed=1, traces="none", states=states)
wall = time.perf_counter() - clock
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
write_netcdf(ds, path)
print(json.dumps({"members": members, "states": states, "wall_s": wall,
                  "peak_rss_GiB": peak / 2**20, "rss_before_GiB": before / 2**20,
                  "dataset_MiB": ds.nbytes / 2**20,
                  "file_MiB": os.path.getsize(path) / 2**20}))
"""


def one_ensemble(members: int, states: bool) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        out = subprocess.run([sys.executable, "-c", ONE, str(members), str(int(states)),
                              os.path.join(tmp, "e.nc")], check=True, capture_output=True,
                             text=True)  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])


def study(members: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "study.nc"
        clock = time.perf_counter()
        subprocess.run([sys.executable, "-m", "stabdae.study.cli", "run",
                        str(HERE / "pendulum_tau_omega.toml"), "-o", str(path), "--members",
                        str(members), "--quiet", "--no-plots"], check=True,
                       stdout=subprocess.DEVNULL)  # fmt: skip
        wall = time.perf_counter() - clock
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        import xarray as xr

        with xr.open_dataset(path) as ds:
            points = int(ds.sizes["tau"] * ds.sizes["omega"])
            nbytes = ds.nbytes
        return {"members": members, "grid_points": points, "wall_s": wall,
                "peak_rss_GiB": peak / 2**20, "dataset_GiB": nbytes / 2**30,
                "file_MB": path.stat().st_size / 1e6}  # fmt: skip


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--members", type=int, default=10**6)
    ap.add_argument("--study", type=int, default=None, metavar="MEMBERS")
    ap.add_argument("--out", default=str(HERE / "results"))
    args = ap.parse_args(argv)
    result = {"ensemble": [one_ensemble(args.members, s) for s in (False, True)]}
    for row in result["ensemble"]:
        print(f"{row['members']} members, states={row['states']}: peak RSS "
              f"{row['peak_rss_GiB']:.2f} GiB, dataset {row['dataset_MiB']:.0f} MiB, file "
              f"{row['file_MiB']:.0f} MiB, {row['wall_s']:.1f} s")  # fmt: skip
    if args.study:
        row = result["study"] = study(args.study)
        print(f"study: {row['grid_points']} points x {row['members']} members: peak RSS "
              f"{row['peak_rss_GiB']:.2f} GiB, dataset {row['dataset_GiB']:.2f} GiB in "
              f"memory, file {row['file_MB']:.0f} MB, {row['wall_s']:.0f} s")  # fmt: skip
    Path(args.out).mkdir(parents=True, exist_ok=True)
    (Path(args.out) / "bench_memory.json").write_text(json.dumps(result, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
