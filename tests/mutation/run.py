"""Apply single-point changes to a copy of the repository and see which the tests catch.

Usage: ``python tests/mutation/run.py [--jobs N] [--list] [NAME ...]`` (see README.md).
Each mutant of :data:`mutants.MUTANTS` replaces one exact snippet (it must occur exactly
once in its file) in a fresh copy of the tracked and untracked files, then runs its test
selection with ``pytest -x`` against that copy (its own kernel cache, so that nothing
compiled from the real source is reused).  A mutant is *caught* when a test fails; it is
*NOT RUN* when pytest ran no test (exit 4: a path that does not exist; exit 5: a
selection that matches nothing), and *BROKEN* when pytest could not run its tests (exit 2:
a collection error or an interruption; exit 3: an internal error): neither says a test
caught the change, and both fail the run like a survivor.  ``--write-results`` writes
``RESULTS.md`` from a full run (every mutant of the list, or of a generated sample), with
the commit and the date at its top; a partial run cannot write it.
"""

from __future__ import annotations

import argparse
import itertools
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from generate import generate  # noqa: E402
from mutants import MUTANTS  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
#: pytest's exit codes that mean no test of the selection ran
NOT_RUN = {4: "usage error: a test path or option that does not exist",
           5: "no test collected: the selection matches nothing"}
#: pytest's exit codes that mean its tests could not run: no test caught anything
BROKEN = {2: "a collection error or an interruption", 3: "pytest's internal error"}
RESULTS = Path(__file__).resolve().parent / "RESULTS.md"


def _copy_tree(dest: Path) -> None:
    files = subprocess.run(["git", "ls-files", "-co", "--exclude-standard"], cwd=ROOT,
                           capture_output=True, text=True, check=True).stdout.split()  # fmt: skip
    for rel in files:
        src = ROOT / rel
        if src.is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / rel)


def outcome_of(code, out: str) -> tuple[str, str]:
    """What a pytest run of a mutant's selection says: (outcome, the catching test)."""
    failed = re.findall(r"^FAILED (\S+)", out, re.M) or re.findall(r"^ERROR (\S+)", out, re.M)
    last = out.strip().splitlines()[-1] if out.strip() else ""
    if code == 0:
        return "SURVIVED", ""
    if code in NOT_RUN:
        # no test ran: a test path that no longer exists (4) or a selection that matches
        # nothing (5) says nothing about the mutant
        return f"NOT RUN ({NOT_RUN[code]})", last
    if code == "timeout":
        return "timeout", ""
    if code in BROKEN:
        # a test file that does not import, or pytest itself failing, catches nothing
        return f"BROKEN ({BROKEN[code]}: exit {code})", last
    if failed:
        return "caught", failed[0]
    if code < 0 or "Fatal Python error" in out or "Segmentation fault" in out:
        return "caught (crash)", f"signal {-code}" if code < 0 else "crash"
    return f"caught (exit {code})", last


def run_mutant(m, timeout: float) -> dict:
    """Apply ``m`` in a temporary copy, run its tests; the outcome as a dict."""
    with tempfile.TemporaryDirectory(prefix=f"mutant-{m.name}-") as tmp:
        tmp = Path(tmp)
        _copy_tree(tmp)
        path = tmp / m.file
        text = path.read_text()
        mutated = m.apply(text)
        if mutated is None:
            where = f"line {m.line}" if m.line else f"{text.count(m.old)} matches"
            return {"name": m.name, "outcome": f"NOT APPLIED ({where})", "test": "",
                    "seconds": 0.0}  # fmt: skip
        path.write_text(mutated)
        env = dict(os.environ, PYTHONPATH=str(tmp / "src"),
                   STABDAE_CACHE_DIR=str(tmp / ".cache"), PYTHONDONTWRITEBYTECODE="1",
                   STABDAE_HYPOTHESIS_PROFILE="mutation")
        cmd = [sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider",
               "-W", "ignore", *m.tests]  # fmt: skip
        start = time.perf_counter()
        try:
            proc = subprocess.run(cmd, cwd=tmp, env=env, capture_output=True, text=True,
                                  timeout=timeout)  # fmt: skip
            out, code = proc.stdout + proc.stderr, proc.returncode
        except subprocess.TimeoutExpired:
            out, code = "", "timeout"
        seconds = time.perf_counter() - start
    outcome, test = outcome_of(code, out)
    return {"name": m.name, "outcome": outcome, "test": test, "seconds": seconds}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", help="mutants to run (default: all)")
    ap.add_argument("--jobs", type=int, default=2, help="mutants run at once (default 2)")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds per mutant")
    ap.add_argument("--list", action="store_true", help="list the mutants and exit")
    ap.add_argument("--generate", type=int, metavar="SEED",
                    help="run a generated sample (generate.py) instead of the hand list")
    ap.add_argument("--per-module", type=int, default=8,
                    help="with --generate: mutants per module group (default 8)")
    ap.add_argument("--write-results", action="store_true",
                    help=f"write {RESULTS.name} from this run (a full run only)")
    args = ap.parse_args(argv)
    if args.write_results and args.names:
        ap.error("--write-results needs a full run: name no mutants")
    pool = MUTANTS if args.generate is None else generate(args.generate, args.per_module)
    chosen = [m for m in pool if not args.names or m.name in args.names]
    unknown = set(args.names) - {m.name for m in pool}
    if unknown:
        ap.error(f"unknown mutants: {', '.join(sorted(unknown))}")
    if args.list:
        for m in chosen:
            print(f"{m.name:32s} {m.file}: {m.what}")
        return 0
    print(f"{len(chosen)} mutants, {args.jobs} at a time", flush=True)
    start = time.perf_counter()
    finished = itertools.count(1)  # next() on a count is atomic: no lock for the workers

    def one(m):
        r = run_mutant(m, args.timeout)
        print(f"[{next(finished)}/{len(chosen)}] {m.name}: {r['outcome']} {r['test']} "
              f"({r['seconds']:.0f} s)", flush=True)
        return r

    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        results = list(pool.map(one, chosen))
    survived = [r["name"] for r in results if not r["outcome"].startswith("caught")]
    lines = table(chosen, results) + [
        "", f"{len(results) - len(survived)} of {len(results)} caught in "
        f"{time.perf_counter() - start:.0f} s; not caught: {', '.join(survived) or 'none'}"]
    print("\n" + "\n".join(lines))
    if args.write_results:
        what = (f"`python tests/mutation/run.py --generate {args.generate} --per-module "
                f"{args.per_module}`" if args.generate is not None
                else "`python tests/mutation/run.py` (the hand-written list)")
        RESULTS.write_text("\n".join(results_header(what) + lines) + "\n")
        print(f"written to {RESULTS}")
    return 1 if survived else 0


def table(chosen, results) -> list[str]:
    """The run as a Markdown table, one row per mutant."""
    width = max(len(m.name) for m in chosen)
    rows = [f"| {'mutant':{width}s} | place | change | outcome | caught by | s |",
            f"|{'-' * (width + 2)}|---|---|---|---|---|"]
    for m, r in zip(chosen, results):
        place = m.file.removeprefix("src/") + (f":{m.line}" if m.line else "")
        rows.append(f"| {m.name:{width}s} | `{place}` | {m.what} | {r['outcome']} | "
                    f"{r['test']} | {r['seconds']:.0f} |")
    return rows


def results_header(what: str) -> list[str]:
    """RESULTS.md's top: the commit and the date of the run, and the command."""
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip() or "unknown"
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                           cwd=ROOT, capture_output=True, text=True).stdout.strip()
    return ["# Mutation results", "",
            f"Written by the runner from one full run: {what}, at commit {commit}"
            + (" with uncommitted changes" if dirty else "")
            + f", {time.strftime('%Y-%m-%d')}.  Not edited by hand.", ""]


if __name__ == "__main__":
    sys.exit(main())
