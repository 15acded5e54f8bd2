"""Run the probe cases of :mod:`cases` and count the outcomes.

    python tests/probes/run.py [--only SUBSTRING ...] [--timeout S] [--json FILE]

Each case runs in a worker process (a crash or a hang costs that case, not the run; the
worker is started again for the next one).  Outcomes:

* ``clear``: a case that expects an error ended in one whose message names what the user
  called (a ``ValueError``, ``TypeError``, ``FileNotFoundError`` or stabdae error, or a
  command that exits 2 with one line and no traceback);
* ``ran``: a case that expects a run ran, its checks held (and a ``warn`` case warned,
  naming what it is about);
* ``defect``: anything else — another exception, a traceback, a check that failed, a
  crash, a hang, an error where a run was expected or a run where an error was.

Prints one line per case and the counts; exits 1 when there is a defect.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import traceback
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
SRC = HERE.parents[1] / "src"
CLEAR_TYPES = (ValueError, TypeError, MemoryError, FileNotFoundError, NotADirectoryError,
               IsADirectoryError)


def classify(expect: str, who: str, fn, ctx) -> tuple[str, str]:
    """Run one case here; (outcome, what happened)."""
    from cases import CliError

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            fn(ctx)
        except CliError as exc:
            if expect == "error" and exc.code == 2:
                return "clear", str(exc)
            return "defect", f"{'unexpected ' if expect != 'error' else ''}{exc}"
        except AssertionError as exc:
            return "defect", f"check failed: {exc}"[:400]
        except Exception as exc:
            message = f"{type(exc).__name__}: {exc}".replace("\n", " ")[:400]
            if expect != "error":
                return "defect", f"raised {message}"
            stabdae_error = type(exc).__module__.startswith("stabdae")
            if (isinstance(exc, CLEAR_TYPES) or stabdae_error) and who in str(exc):
                return "clear", message
            tb = traceback.extract_tb(exc.__traceback__)[-1]
            return "defect", f"unclear: {message} (at {Path(tb.filename).name}:{tb.lineno})"
    if expect == "error":
        return "defect", "ran where an error was expected"
    if expect == "warn":
        said = [str(w.message) for w in caught if who in str(w.message)]
        if not said:
            return "defect", "no warning that names " + who
        return "ran", said[0][:300]
    return "ran", "ok"


def worker(names: list[str], tmp: str) -> None:
    """Run cases one by one, a JSON line each (flushed: the parent sees how far it got)."""
    sys.path.insert(0, str(HERE))
    from cases import CASES, Context

    ctx = Context(Path(tmp), SRC)
    table = {name: (expect, who, fn) for name, expect, who, fn in CASES}
    for name in names:
        expect, who, fn = table[name]
        start = time.perf_counter()
        outcome, what = classify(expect, who, fn, ctx)
        seconds = round(time.perf_counter() - start, 2)
        print(json.dumps({"case": name, "outcome": outcome, "what": what, "seconds": seconds}),
              flush=True)  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", nargs="*", default=None)
    parser.add_argument("--timeout", type=float, default=900.0, help="seconds per case")
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--worker", nargs="*", help=argparse.SUPPRESS)
    parser.add_argument("--tmp", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker is not None:
        worker(args.worker, args.tmp)
        return 0

    sys.path.insert(0, str(HERE))
    from cases import CASES

    names = [c[0] for c in CASES if not args.only or any(o in c[0] for o in args.only)]
    results = []
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(SRC), str(HERE)]))
    with tempfile.TemporaryDirectory(prefix="stabdae-probes-") as tmp:
        todo = list(names)
        while todo:
            errors = Path(tmp) / "worker.err"  # a file: a full pipe would stop the worker
            with open(errors, "w") as err_file:
                proc = subprocess.Popen([sys.executable, __file__, "--worker", *todo, "--tmp",
                                         tmp], stdout=subprocess.PIPE, stderr=err_file,
                                        text=True, env=env)  # fmt: skip
                done = _read(proc, todo, results, args.timeout)
            todo = todo[done:]
            if todo:  # the worker died or hung on todo[0]
                proc.kill()
                err = [ln for ln in errors.read_text().strip().splitlines() if ln.strip()]
                kind = "hang" if proc.returncode in (None, -9) else f"crash ({proc.returncode})"
                results.append({"case": todo[0], "outcome": "defect",
                                "what": f"{kind}: {err[-1] if err else ''}"[:400],
                                "seconds": None})  # fmt: skip
                print(_line(results[-1]), flush=True)
                todo = todo[1:]
    counts = {k: sum(r["outcome"] == k for r in results) for k in ("clear", "ran", "defect")}
    print(f"\n{len(results)} cases: {counts['clear']} clear errors, {counts['ran']} ran as "
          f"expected, {counts['defect']} defects")  # fmt: skip
    if args.json:
        args.json.write_text(json.dumps({"counts": counts, "results": results}, indent=1))
    return 1 if counts["defect"] else 0


def _read(proc, todo, results, timeout) -> int:
    """Lines of the worker until it ends or a case passes ``timeout``; cases finished."""
    import selectors

    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    done = 0
    while done < len(todo):
        if not sel.select(timeout):
            proc.kill()
            proc.wait()
            return done
        line = proc.stdout.readline()
        if not line:
            proc.wait()
            return done
        try:
            result = json.loads(line)
        except json.JSONDecodeError:
            continue  # something the case printed
        results.append(result)
        print(_line(result), flush=True)
        done += 1
    proc.wait()
    return done


def _line(r) -> str:
    secs = "" if r["seconds"] is None else f" ({r['seconds']:.1f} s)"
    return f"{r['outcome']:7s} {r['case']}{secs}: {r['what']}"


if __name__ == "__main__":
    sys.exit(main())
