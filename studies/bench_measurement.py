"""The in-kernel decay measurement's cost beside the step, per model.

The ensemble kernel alone (as ``studies/bench_throughput.py`` times it: the inputs and
outputs ``stabdae.ensemble`` gives it, outside the timer), with the measurement as
``stabdae.ensemble`` runs it (every ``measure_every``-th state), against the same
compiled kernel measuring the first state only (a stride longer than the run: the steps,
the stored samples and each member's start and end are the same work).  The two
alternate, ``--repeat`` times each, and each keeps its best; the final states must agree
bit for bit.  Midpoint rule, Baumgarte ω = 10, ξ = 1 (k = 10 for nonholonomic rows),
τ = 1e-3, the members placed as ``stabdae.ensemble`` places them (radius 1e-6 to 1e-3)::

    python studies/bench_measurement.py --scenes pendulum n_four_bar bicycle \
        --members 1024 --t-end 10
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

import stabdae
from stabdae import _ensemble as E

TAU = 1e-3


def timed(run, x0, alpha0, g_ref):
    """Seconds of one run of the kernel over the members ``x0``, and its outputs."""
    status = np.zeros(x0.shape[0], dtype=np.int8)
    start = time.perf_counter()
    out = run.mode.integrate(run, x0, alpha0, status, g_ref)
    return time.perf_counter() - start, out


def scene(name: str, members: int, t_end: float, repeat: int) -> dict:
    model = stabdae.load_model(name)
    law = stabdae.baumgarte(10.0, 1.0, 10.0 if model.k else None)
    placed = stabdae.ensemble(model, law, "midpoint", TAU, 10 * TAU, members=members,
                              radius=(1e-6, 1e-3), seed=1, states=True)  # fmt: skip
    x0 = np.ascontiguousarray(placed.x0.values)
    run = E._run_spec("bench", model, law, "midpoint", TAU, model.t0 + t_end, None, None,
                      members, (1e-6, 1e-3), 0, None, x0, None, None, None, None, None,
                      None, "float32", "none", True)  # fmt: skip
    nsteps = int(run.mode.grid.nsteps)
    off = dataclasses.replace(run, mode=dataclasses.replace(run.mode, stride=nsteps + 1))
    alpha0 = E._residual_rows(model, x0, run.p, run.t0)
    g_ref = run.mode.reference(run)
    best = {"with": np.inf, "without": np.inf}
    finals = {}
    timed(run, x0, alpha0, g_ref)  # compiled (or loaded) and warm
    for _ in range(repeat):
        for key, spec in (("with", run), ("without", off)):
            seconds, out = timed(spec, x0, alpha0, g_ref)
            best[key] = min(best[key], seconds)
            finals[key] = out
    same = np.array_equal(finals["with"].x_final, finals["without"].x_final, equal_nan=True)
    stopped = int(np.count_nonzero(finals["with"].status))
    return dict(scene=name, n=model.n, members=members, t_end=t_end, stride=run.mode.stride,
                with_s=best["with"], without_s=best["without"],
                over=best["with"] / best["without"] - 1.0, same_final_states=same,
                stopped=stopped)  # fmt: skip


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="+", default=["pendulum", "n_four_bar", "bicycle"])
    ap.add_argument("--members", type=int, default=1024)
    ap.add_argument("--t-end", type=float, default=10.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    print(f"{'model':22s} {'n':>3s} {'stride':>6s} {'with (s)':>9s} {'without (s)':>11s} "
          f"{'over the step':>13s}  same final states, members stopped")  # fmt: skip
    for name in args.scenes:
        r = scene(name, args.members, args.t_end, args.repeat)
        print(f"{r['scene']:22s} {r['n']:3d} {r['stride']:6d} {r['with_s']:9.3f} "
              f"{r['without_s']:11.3f} {100 * r['over']:12.1f} %  {r['same_final_states']}, "
              f"{r['stopped']}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
