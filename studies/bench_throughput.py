"""Throughput benchmark: member-steps per second for an ensemble of planar pendulums.

Configuration: planar pendulum, explicit midpoint rule (RK2, a = ½, σ = 1),
Baumgarte ω = 10, ξ = 1, τ = 1e-3, 10 s (10⁴ steps), residual norm stored every 0.05 s,
10⁴ and 10⁵ members.  Measured side by side in one run, as ratios to the vectorized C:

* stabdae through the public API (``stabdae.ensemble``), compile time reported apart, and
  its ensemble kernel alone (called on the same thread pool, outputs allocated outside
  the timer; the API also fits every member's decay and builds the dataset), with the
  measurement and without (:func:`run_kernel`), and its steps alone: twice the
  difference of the kernel's time without the measurement over the run and over half
  of it (each member's start and end, and the call's own cost, cancel);
* C compiled with ``gcc -O3 -march=native -fopenmp``: one member per loop iteration
  (``run_scalar``) and blocks of 64 members with the member loop innermost (``run_blocked``,
  vectorized by gcc), both OpenMP-parallel (``studies/bench_c/pendulum_rk2.c``); the blocked
  form also with ``-ffp-contract=off`` (no fused multiply-adds at all; gcc's default fuses
  wherever it likes, stabdae fuses its own multiply-adds explicitly, not the user's
  expressions, see ``stabdae.engine.fma``), and with the failure test stabdae's step
  makes (``run_blocked_checked``: each stage's pivot ``S > 1e-12 |S|``, ORed per member;
  the ratios are given to the blocked C without it);
* NumPy vectorized over members;
* JAX ``lax.scan`` + ``vmap`` when jax is installed.

The kernel without the measurement and the blocked C also run on one thread each (set
through the C's own ``set_threads``: with ``OMP_NUM_THREADS=1`` in the environment of
this script the C still ran on two threads, 0.084 s against 0.168 s after
``set_threads(1)``), so that the ratio is given per thread count: where threads share a
core (SMT) or memory bandwidth, the two can scale differently.

All start from the same sampled initial states; the final states are compared to make
sure every variant computes the same thing.  OpenMP's workers sleep between parallel
regions (``OMP_WAIT_POLICY=PASSIVE`` unless set otherwise): by default they spin for a
while after each C run and took cores from the variant timed next (the API at 10⁴
members, two runs each: 0.106 / 0.109 s against 0.104 / 0.104 s; the C timings the same
either way).  The API, the kernel and the two blocked C
builds run ``--repeat`` times in turn and each keeps its best time (timings on a shared
machine vary by 10 % from run to run); the others run once.

Usage::

    python studies/bench_throughput.py [--members 10000 100000] [--repeat 3]
                                       [--t-end 10 2] [--baseline REV]
                                       [--out studies/results]

``--baseline REV`` times ``stabdae.ensemble`` of an earlier revision as well (a git
worktree in a second process with its own kernel cache; its runs alternate with this
revision's), e.g. the cost of measuring every member's decay at every step.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

import stabdae

HERE = Path(__file__).resolve().parent
G, L, OMEGA, XI = 9.81, 1.0, 10.0, 1.0
A0, A1 = -(OMEGA**2), -2.0 * XI * OMEGA
TAU, T_END, SAVE_DT = 1e-3, 10.0, 0.05
NSTEPS, SAVE_EVERY = round(T_END / TAU), round(SAVE_DT / TAU)
#: the members' ends as in the timed runs: read from runs of this many steps and twice
#: as many (2 s and 4 s: the same members measured by their one-step maps in both, about
#: a quarter.  The members are given as ``x0``, so each is measured on its raw residual,
#: whose floor is the midpoint rule's along the motion, about 7e-6: those that start
#: less than about 2.5 decades above it have no transient to fit)
MAP_ENDS_STEPS = 2000
#: best of at least this many runs for each of the two runs the ends are read from (their
#: difference is a small number from two larger ones)
ENDS_REPEAT = 9


def build_c(*extra: str) -> ctypes.CDLL:
    out = Path(tempfile.mkdtemp()) / "pendulum_rk2.so"
    cmd = ["gcc", "-O3", "-march=native", "-fopenmp", *extra, "-shared", "-fPIC",
           str(HERE / "bench_c" / "pendulum_rk2.c"), "-o", str(out), "-lm"]  # fmt: skip
    subprocess.run(cmd, check=True)
    lib = ctypes.CDLL(str(out))
    argtypes = [ctypes.c_int64, ctypes.c_void_p, ctypes.c_double, ctypes.c_double,
                ctypes.c_double, ctypes.c_double, ctypes.c_double, ctypes.c_int64,
                ctypes.c_int64, ctypes.c_void_p, ctypes.c_void_p]  # fmt: skip
    for name in ("run_scalar", "run_blocked"):
        getattr(lib, name).argtypes = argtypes
        getattr(lib, name).restype = None
    lib.run_blocked_checked.argtypes = [*argtypes, ctypes.c_void_p]
    lib.run_blocked_checked.restype = None
    lib.set_threads.argtypes = [ctypes.c_int]
    lib.set_threads.restype = None
    return lib


def run_c(fn, x0):
    M = x0.shape[0]
    norms = np.empty((M, NSTEPS // SAVE_EVERY + 1), dtype=np.float32)
    xf = np.empty_like(x0)
    start = time.perf_counter()
    fn(M, x0.ctypes.data, G, L, A0, A1, TAU, NSTEPS, SAVE_EVERY, norms.ctypes.data,
       xf.ctypes.data)  # fmt: skip
    return time.perf_counter() - start, xf


def run_c_checked(lib, x0):
    """The blocked C with the failure test of stabdae's step (each stage's pivot tested,
    ``run_blocked_checked``): seconds, final states, and whether any member's test
    failed."""
    M = x0.shape[0]
    norms = np.empty((M, NSTEPS // SAVE_EVERY + 1), dtype=np.float32)
    xf = np.empty_like(x0)
    failed = np.empty(M, dtype=np.uint8)
    start = time.perf_counter()
    lib.run_blocked_checked(M, x0.ctypes.data, G, L, A0, A1, TAU, NSTEPS, SAVE_EVERY,
                            norms.ctypes.data, xf.ctypes.data, failed.ctypes.data)
    return time.perf_counter() - start, xf, bool(failed.any())


def run_kernel(model, law, x0, divergence, nsteps, measure=True):
    """stabdae's ensemble kernel alone, with the inputs and outputs ``stabdae.ensemble``
    gives it (the reference trajectory's residuals, the linear prediction's ``R``; every
    member traced, as the C stores every member's norms).  ``measure=False``: the decay
    measured at the first state only (a stride longer than the run), so that the time is
    the step's and the stored norms', as the C's."""
    import dataclasses

    from stabdae import _ensemble as E

    run = E._run_spec("bench", model, law, "midpoint", TAU, model.t0 + nsteps * TAU, None,
                      None, x0.shape[0], (1e-6, 1e-2), 0, TAU * SAVE_EVERY, x0, None, None,
                      divergence, None, None, None, "float32", "all", True)  # fmt: skip
    if not measure:
        run = dataclasses.replace(run, mode=dataclasses.replace(run.mode, stride=nsteps + 1))
    alpha0 = E._residual_rows(model, x0, run.p, run.t0)
    g_ref = run.mode.reference(run)
    status = np.zeros(x0.shape[0], dtype=np.int8)
    start = time.perf_counter()
    out = run.mode.integrate(run, x0, alpha0, status, g_ref)
    return time.perf_counter() - start, out.x_final


def one_thread(model, law, x0, divergence, lib, repeat):
    """The kernel without the measurement and the blocked C, each on one thread (best of
    ``repeat``, in turn)."""
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    lib.set_threads(1)
    try:
        kernel = c = np.inf
        for _ in range(repeat):
            kernel = min(kernel, run_kernel(model, law, x0, divergence, NSTEPS, measure=False)[0])
            c = min(c, run_c(lib.run_blocked, x0)[0])
    finally:
        numba.set_num_threads(threads)
        lib.set_threads(threads)
    return kernel, c


def member_ends(model, law, x0, divergence, repeat, short=SAVE_EVERY):
    """Core time per member of what the kernel does once per member (placing it in a
    slot, its decay fit, the map's radius, γ, its outputs), in µs: the intercept at zero
    steps of the kernel's time over ``short`` and ``2 short`` steps (best of ``repeat``,
    at least ``ENDS_REPEAT``, each), times the threads.  Over 50 and 100 steps (0.1 s) few
    members' residuals have fallen a decade: nearly all go through the envelope's fit;
    over ``MAP_ENDS_STEPS`` and twice as many, the members are measured as in the runs
    timed."""
    repeat = max(repeat, ENDS_REPEAT)
    t1 = min(run_kernel(model, law, x0, divergence, short)[0] for _ in range(repeat))
    t2 = min(run_kernel(model, law, x0, divergence, 2 * short)[0] for _ in range(repeat))
    return (2.0 * t1 - t2) * numba.get_num_threads() / x0.shape[0] * 1e6


def run_numpy(x0):
    """The same scheme vectorized over members with NumPy (no compilation)."""
    x, y, vx, vy = (x0[:, i].copy() for i in range(4))
    norms = np.empty((x0.shape[0], NSTEPS // SAVE_EVERY + 1), dtype=np.float32)

    def acc(x, y, vx, vy):
        f = x * x + y * y - L * L
        fd = 2.0 * x * vx + 2.0 * y * vy
        lam = (A0 * f + A1 * fd - 2.0 * (vx * vx + vy * vy) + 2.0 * y * G) / (4.0 * (x * x + y * y))
        return 2.0 * x * lam, 2.0 * y * lam - G

    start = time.perf_counter()
    for i in range(1, NSTEPS + 1):
        ax, ay = acc(x, y, vx, vy)
        h = 0.5 * TAU
        xm, ym, vxm, vym = x + h * vx, y + h * vy, vx + h * ax, vy + h * ay
        bx, by = acc(xm, ym, vxm, vym)
        x, y, vx, vy = x + TAU * vxm, y + TAU * vym, vx + TAU * bx, vy + TAU * by
        if i % SAVE_EVERY == 0:
            f = np.abs(x * x + y * y - L * L)
            fd = np.abs(2.0 * x * vx + 2.0 * y * vy)
            norms[:, i // SAVE_EVERY] = np.maximum(f, fd)
    return time.perf_counter() - start, np.stack([x, y, vx, vy], axis=1)


def run_jax(x0):
    try:
        import jax
        import jax.numpy as jnp
    except ImportError:
        return None
    jax.config.update("jax_enable_x64", True)

    def acc(s):
        x, y, vx, vy = s
        f = x * x + y * y - L * L
        fd = 2.0 * x * vx + 2.0 * y * vy
        lam = (A0 * f + A1 * fd - 2.0 * (vx * vx + vy * vy) + 2.0 * y * G) / (4.0 * (x * x + y * y))
        return jnp.stack([vx, vy, 2.0 * x * lam, 2.0 * y * lam - G])

    def member(s0):
        def save_block(s, _):
            def step(s, _):
                mid = s + 0.5 * TAU * acc(s)
                return s + TAU * acc(mid), None

            s, _ = jax.lax.scan(step, s, None, length=SAVE_EVERY)
            x, y, vx, vy = s
            n = jnp.maximum(jnp.abs(x * x + y * y - L * L), jnp.abs(2 * x * vx + 2 * y * vy))
            return s, n.astype(jnp.float32)

        return jax.lax.scan(save_block, s0, None, length=NSTEPS // SAVE_EVERY)

    fn = jax.jit(jax.vmap(member))
    small = jnp.asarray(x0[:8])
    start = time.perf_counter()
    jax.block_until_ready(fn(small))
    compile_s = time.perf_counter() - start
    start = time.perf_counter()
    xf, _ = jax.block_until_ready(fn(jnp.asarray(x0)))
    return time.perf_counter() - start, np.asarray(xf), compile_s


def second_process_start() -> float:
    """Seconds from interpreter start to a finished tiny ensemble, in a new process that
    finds the kernels in the on-disk cache (``import stabdae`` included)."""
    code = ("import time; t = time.perf_counter(); import stabdae; "
            "m = stabdae.load_model('pendulum'); "
            f"stabdae.ensemble(m, stabdae.baumgarte({OMEGA}, {XI}), 'midpoint', {TAU}, "
            f"{10 * TAU}, members=8, save_dt={TAU}); print(time.perf_counter() - t)")  # fmt: skip
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                         text=True, env=dict(os.environ))  # fmt: skip
    return float(out.stdout.strip().splitlines()[-1])


_BASELINE_SERVER = """
import sys, time, numpy as np, stabdae
model = stabdae.load_model("pendulum")
law = stabdae.baumgarte(float(sys.argv[1]), float(sys.argv[2]))
for line in sys.stdin:
    path, t_end, tau, save_dt = line.split()
    x0 = np.load(path)
    start = time.perf_counter()
    ds = stabdae.ensemble(model, law, "midpoint", float(tau), float(t_end), x0=x0,
                          save_dt=float(save_dt))
    secs = time.perf_counter() - start
    np.save(path + ".xf.npy", ds.x_final.values)
    print(secs, flush=True)
"""


class Baseline:
    """``stabdae.ensemble`` of an earlier revision (a git worktree of ``rev``), in a second
    process with its own kernel cache, timed on request so that its runs alternate with
    this revision's (the two never run at once)."""

    def __init__(self, rev: str):
        self.dir = Path(tempfile.mkdtemp(prefix="stabdae-baseline-"))
        subprocess.run(["git", "-C", str(HERE.parent), "worktree", "add", "--detach",
                        str(self.dir / "tree"), rev], check=True, capture_output=True)  # fmt: skip
        self.rev = subprocess.run(["git", "-C", str(self.dir / "tree"), "rev-parse", "HEAD"],
                                  check=True, capture_output=True, text=True).stdout.strip()
        env = dict(os.environ, PYTHONPATH=str(self.dir / "tree" / "src"),
                   STABDAE_CACHE_DIR=str(self.dir / "cache"))  # fmt: skip
        self.proc = subprocess.Popen([sys.executable, "-c", _BASELINE_SERVER, str(OMEGA),
                                      str(XI)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     text=True, env=env, cwd=str(self.dir))  # fmt: skip

    def run(self, x0, t_end):
        path = str(self.dir / "x0.npy")
        np.save(path, x0)
        self.proc.stdin.write(f"{path} {t_end!r} {TAU!r} {SAVE_DT!r}\n")
        self.proc.stdin.flush()
        secs = float(self.proc.stdout.readline())
        return secs, np.load(path + ".xf.npy")

    def close(self):
        self.proc.stdin.close()
        self.proc.wait()
        subprocess.run(["git", "-C", str(HERE.parent), "worktree", "remove", "--force",
                        str(self.dir / "tree")], check=False, capture_output=True)  # fmt: skip


def _runs(args, model, law, lib, lib_ieee, baseline, report):
    """Every configuration (run length × members), each variant timed in turn."""
    global T_END, NSTEPS  # the run length, set per configuration
    configs = [(t, M) for t in args.t_end for M in args.members]
    for T_END, M in configs:
        NSTEPS = round(T_END / TAU)
        x0, _, _ = stabdae.sample_perturbations(model, M, (1e-6, 1e-2), seed=1)
        steps = M * NSTEPS
        api = api_all = kernel = step_only = half = t_blocked = t_ieee = t_base = np.inf
        t_checked = np.inf
        for _ in range(max(1, args.repeat)):  # in turn, best of each
            start = time.perf_counter()
            ds = stabdae.ensemble(model, law, "midpoint", TAU, T_END, x0=x0, save_dt=SAVE_DT)
            api = min(api, time.perf_counter() - start)
            start = time.perf_counter()  # every member's norms stored, as the C does
            stabdae.ensemble(model, law, "midpoint", TAU, T_END, x0=x0, save_dt=SAVE_DT,
                             traces="all")  # fmt: skip
            api_all = min(api_all, time.perf_counter() - start)
            t, xf_kernel = run_kernel(model, law, x0, ds.attrs["divergence"], NSTEPS)
            kernel = min(kernel, t)
            t, xf_step = run_kernel(model, law, x0, ds.attrs["divergence"], NSTEPS,
                                    measure=False)  # fmt: skip
            step_only = min(step_only, t)
            half = min(half, run_kernel(model, law, x0, ds.attrs["divergence"], NSTEPS // 2,
                                        measure=False)[0])  # fmt: skip
            if baseline:
                t, xf_base = baseline.run(x0, T_END)
                t_base = min(t_base, t)
            t, xf_blocked = run_c(lib.run_blocked, x0)
            t_blocked = min(t_blocked, t)
            t_ieee = min(t_ieee, run_c(lib_ieee.run_blocked, x0)[0])
            t, xf_checked, failed = run_c_checked(lib, x0)
            t_checked = min(t_checked, t)
        assert np.array_equal(xf_kernel, ds.x_final.values)
        assert np.array_equal(xf_step, xf_kernel)  # the measurement changes no state
        assert np.array_equal(xf_checked, xf_blocked) and not failed  # the test changes none
        one_kernel, one_c = one_thread(model, law, x0, ds.attrs["divergence"], lib,
                                       max(1, args.repeat))  # fmt: skip
        ends = member_ends(model, law, x0, ds.attrs["divergence"], max(1, args.repeat))
        ends_map = member_ends(model, law, x0, ds.attrs["divergence"], max(1, args.repeat),
                               short=MAP_ENDS_STEPS)  # fmt: skip
        t_scalar, xf_scalar = run_c(lib.run_scalar, x0)
        xs = ds.x_final.values
        row = {"members": M, "t_end": T_END, "member_steps": steps,
               "repeat": max(1, args.repeat), "stabdae_api_s": api,
               "stabdae_api_all_traces_s": api_all, "stabdae_kernel_s": kernel,
               "stabdae_kernel_step_only_s": step_only,
               "stabdae_step_slope_s": 2.0 * (step_only - half),
               "member_ends_core_us": ends, "member_ends_map_core_us": ends_map,
               "one_thread_kernel_step_only_s": one_kernel, "one_thread_c_blocked_s": one_c,
               "c_scalar_s": t_scalar, "c_blocked_s": t_blocked,
               "c_blocked_no_fma_s": t_ieee, "c_blocked_checked_s": t_checked,
               "max_diff_vs_c": float(np.max(np.abs(xs - xf_blocked)))}  # fmt: skip
        if baseline:
            row["baseline_api_s"] = t_base
            row["baseline_same_final_states"] = bool(np.array_equal(xf_base, xs))
        if M <= args.numpy_members:
            row["numpy_s"], xf_np = run_numpy(x0)
            row["max_diff_numpy_vs_c"] = float(np.max(np.abs(xf_np - xf_blocked)))
        jax_run = run_jax(x0)
        if jax_run is not None:
            row["jax_s"], _, row["jax_compile_s"] = jax_run
        report["runs"].append(row)
        print(f"\nmembers = {M}, t_end = {T_END:g} s: {steps:.3g} member-steps "
              f"(final states agree with C to {row['max_diff_vs_c']:.1e})")
        print(f"{'variant':<34} {'seconds':>9} {'member-steps/s':>15} {'÷ vectorized C':>15}")
        variants = [("stabdae ensemble (public API)", api),
                    ("  the same, every member traced", api_all),
                    ("stabdae kernel only", kernel),
                    ("  the same, measurement off", step_only),
                    ("  its steps alone (slope)", 2.0 * (step_only - half))]  # fmt: skip
        if baseline:
            variants.append((f"stabdae API at {baseline.rev[:10]}", t_base))
        variants += [("C, one member per iteration", t_scalar),
                     ("C, blocked + vectorized", t_blocked),
                     ("C, blocked, -ffp-contract=off", t_ieee),
                     ("C, blocked, failures tested", t_checked)]  # fmt: skip
        if "numpy_s" in row:
            variants.append(("NumPy over members", row["numpy_s"]))
        if "jax_s" in row:
            variants.append(("JAX scan + vmap", row["jax_s"]))
        for name, secs in variants:
            print(f"{name:<34} {secs:9.3f} {steps / secs:15.3g} {t_blocked / secs:15.3f}")
        print(f"one thread each: the kernel without the measurement {one_kernel:.3f} s, the "
              f"blocked C {one_c:.3f} s: {one_c / one_kernel:.3f} of the C (the C's time on "
              f"{numba.get_num_threads()} threads is {t_blocked / one_c:.2f} of its time on one)")
        print(f"against the blocked C that tests each stage's pivot as stabdae's step "
              f"does: the kernel without the measurement {t_checked / step_only:.3f}, its "
              f"steps alone {t_checked / (2.0 * (step_only - half)):.3f}")
        print(f"each member's start and end in the kernel: {ends:.3f} µs of core time "
              f"(runs of {SAVE_EVERY} and {2 * SAVE_EVERY} steps), {ends_map:.3f} µs (runs "
              f"of {MAP_ENDS_STEPS} and {2 * MAP_ENDS_STEPS} steps; "
              f"{numba.get_num_threads()} threads)")
        if baseline:
            print(f"this revision's API over {baseline.rev[:10]}'s: {t_base / api:.3f} "
                  f"(same final states: {row['baseline_same_final_states']})")


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--members", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--numpy-members", type=int, default=10_000,
                        help="NumPy is slow: run it at this size only")  # fmt: skip
    parser.add_argument("--repeat", type=int, default=3,
                        help="runs of the API, kernel and blocked C variants (best kept)")
    parser.add_argument("--t-end", type=float, nargs="+", default=[T_END],
                        help="run lengths (s); 2 s: runs short enough that what the API does "
                             "besides integrating shows")  # fmt: skip
    parser.add_argument("--baseline", metavar="REV",
                        help="also time stabdae.ensemble of this git revision (a worktree, "
                             "a second process), alternating with this one")  # fmt: skip
    parser.add_argument("--out", default=str(HERE / "results"))
    args = parser.parse_args(argv)

    # before libgomp is loaded (build_c): its workers must not spin after a C run
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    # compile time from a cold, private kernel cache; then a second process on that cache
    os.environ["STABDAE_CACHE_DIR"] = tempfile.mkdtemp(prefix="stabdae-bench-cache-")
    model = stabdae.load_model("pendulum")
    law = stabdae.baumgarte(OMEGA, XI)
    start = time.perf_counter()
    ds = stabdae.ensemble(model, law, "midpoint", TAU, 10 * TAU, members=8, save_dt=TAU)
    compile_s = time.perf_counter() - start
    stabdae.ensemble(model, law, "midpoint", TAU, 10 * TAU, x0=ds.x0.values, save_dt=TAU)
    warm_s = second_process_start()
    lib = build_c()
    # gcc contracts every a*b + c into an FMA by default; stabdae fuses only its own sums
    # (no fastmath), so the build without contraction is reported beside it
    lib_ieee = build_c("-ffp-contract=off")
    report = {"machine": platform.processor() or platform.machine(),
              "threads": numba.get_num_threads(), "stabdae_compile_s": compile_s,
              "omp_wait_policy": os.environ["OMP_WAIT_POLICY"],
              "config": dict(tau=TAU, t_end=T_END, save_dt=SAVE_DT, omega=OMEGA, xi=XI),
              "runs": []}  # fmt: skip
    report["stabdae_second_process_s"] = warm_s
    print(f"stabdae compile (first call of a new model, tiny ensemble): {compile_s:.2f} s; "
          f"a second process, import to first ensemble done: {warm_s:.2f} s; "
          f"threads: {report['threads']}")
    baseline = Baseline(args.baseline) if args.baseline else None
    if baseline:
        report["baseline_rev"] = baseline.rev
        baseline.run(ds.x0.values, SAVE_DT)  # its compilation, outside the timings
    try:
        _runs(args, model, law, lib, lib_ieee, baseline, report)
    finally:  # the worktree goes even when a run fails
        if baseline:
            baseline.close()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "bench_throughput.json").write_text(json.dumps(report, indent=2))
    print(f"\nwritten {out / 'bench_throughput.json'}")
    return report


if __name__ == "__main__":
    main()
