"""The figures the README gives for its commands, measured and written into it.

    python studies/measure_commands.py            # the main job cold and warm, --version
    python studies/measure_commands.py --suite    # and the test suite (tens of minutes)

Each command runs as the README gives it, in this environment (installed, so no install
time): the main job (``stabdae run studies/pendulum_tau_omega.toml --force``) first with
empty caches (a new ``STABDAE_CACHE_DIR`` and ``NUMBA_CACHE_DIR``: every kernel and the
library's own functions compile), then twice warm; ``stabdae --version``, best of five;
with ``--suite`` the test command (``python -m pytest -n auto --maxprocesses 4``) on the
kernel cache as it is.  Wall and CPU seconds (the children's user + system time), the
load average before each, the machine and the date go to
``studies/results/commands.json``, and the README's figures between its
``<!-- commands:begin -->`` and ``<!-- commands:end -->`` lines are rewritten from it.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "studies" / "results" / "commands.json"
README = ROOT / "README.md"
MAIN = ["stabdae", "run", "studies/pendulum_tau_omega.toml", "--force", "--quiet"]
SUITE = [sys.executable, "-m", "pytest", "-q", "-n", "auto", "--maxprocesses", "4"]


def _cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def timed(cmd, env=None) -> dict:
    """One run of ``cmd``: wall and CPU seconds, the load before it, its exit status and
    the last lines it printed."""
    load = os.getloadavg()[0]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if proc.returncode != 0:  # (pytest reports its failures on stdout)
        raise SystemExit(f"{' '.join(cmd)} failed ({proc.returncode}):\n"
                         f"{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    text = proc.stdout + proc.stderr
    out = {"wall_s": round(wall, 2), "cpu_s": round(cpu, 2), "load": round(load, 2),
           "tail": text.strip().splitlines()[-3:]}
    grid = re.search(r"\((\d+) grid points in ([\d.]+) s: sampling and integration ([\d.]+) s",
                     text)
    if grid:  # the main job's own account of its grid points
        out["grid_s"], out["work_s"] = float(grid.group(2)), float(grid.group(3))
    return out


def measure(suite: bool) -> dict:
    out = {"date": datetime.date.today().isoformat(), "cpu": _cpu_name(),
           "cores": os.cpu_count(), "python": platform.python_version()}
    with tempfile.TemporaryDirectory() as cold:
        env = dict(os.environ, STABDAE_CACHE_DIR=str(Path(cold) / "stabdae"),
                   NUMBA_CACHE_DIR=str(Path(cold) / "numba"))
        out["main_cold"] = timed(MAIN, env)
    warm = [timed(MAIN) for _ in range(3)][1:]  # the first loads this cache's state
    out["main_warm"] = min(warm, key=lambda r: r["wall_s"])
    out["version"] = min((timed(["stabdae", "--version"]) for _ in range(5)),
                         key=lambda r: r["wall_s"])
    if suite:
        run = timed(SUITE)
        counts = re.search(r"(\d+) passed(?:, (\d+) skipped)?", " ".join(run["tail"]))
        run["passed"] = int(counts.group(1)) if counts else None
        run["skipped"] = int(counts.group(2) or 0) if counts else None
        out["suite"] = run
    elif RESULTS.exists():  # keep the last suite figure, with its own date
        last = json.loads(RESULTS.read_text())
        if "suite" in last:
            out["suite"] = {**last["suite"], "date": last["suite"].get("date", last["date"])}
    if "suite" in out and "date" not in out["suite"]:
        out["suite"]["date"] = out["date"]
    return out


def readme_block(r: dict) -> str:
    c, w, v = r["main_cold"], r["main_warm"], r["version"]
    lines = [
        f"Measured by `python studies/measure_commands.py` on {r['date']} ({r['cpu']}, "
        f"{r['cores']} cores, installed; wall / CPU seconds, load average before each run):",
        "",
        "| command | wall | CPU | load |",
        "|---|---|---|---|",
        f"| main job, first run (empty caches: everything compiles) | {c['wall_s']:.1f} s "
        f"| {c['cpu_s']:.1f} s | {c['load']:.1f} |",
        f"| main job, again (kernels from the cache; its 100 grid points "
        f"{w.get('grid_s', float('nan')):.2f} s, of which sampling and integration "
        f"{w.get('work_s', float('nan')):.2f} s) | {w['wall_s']:.1f} s | {w['cpu_s']:.1f} s "
        f"| {w['load']:.1f} |",
        f"| `stabdae --version` | {v['wall_s']:.2f} s | {v['cpu_s']:.2f} s | {v['load']:.1f} |",
    ]
    if "suite" in r:
        s = r["suite"]
        lines.append(f"| tests ({s.get('passed')} passed, {s.get('skipped')} skipped; "
                     f"{s['date']}, kernel cache as found) | {s['wall_s'] / 60:.1f} min "
                     f"| {s['cpu_s'] / 60:.1f} min | {s['load']:.1f} |")
    return "\n".join(lines)


def write_readme(r: dict) -> None:
    text = README.read_text()
    begin, end = "<!-- commands:begin -->", "<!-- commands:end -->"
    if begin not in text or end not in text:
        raise SystemExit(f"README.md has no {begin} … {end} block")
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    README.write_text(f"{head}{begin}\n{readme_block(r)}\n{end}{tail}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--suite", action="store_true", help="also run the test suite")
    ap.add_argument("--readme-only", action="store_true",
                    help="rewrite the README's block from the stored results")
    args = ap.parse_args()
    if args.readme_only:
        r = json.loads(RESULTS.read_text())
    else:
        r = measure(args.suite)
        RESULTS.parent.mkdir(parents=True, exist_ok=True)
        RESULTS.write_text(json.dumps(r, indent=1) + "\n")
    write_readme(r)
    print(readme_block(r))


if __name__ == "__main__":
    main()
