"""Ensemble work–precision: core-seconds per member against the final-state error, stabdae
against heyoka's batch mode (and JAX/diffrax when installed), measured side by side in one
run.

For each scene (the planar pendulum over 10 s, the double pendulum over 2 s, Andrews'
squeezing mechanism over the Test Set's 0.03 s), one ensemble of ``--members`` initial
states (Andrews: at most 1000, its runs take minutes at 10⁴) sampled by
``stabdae.ensemble`` around the scene's reference state (constraint residuals α⁰ of the
given radii, seed 0), integrated under the Baumgarte law (ω, ξ = 1) to ``t_end``:

* stabdae through the public API (``stabdae.ensemble``, no traces, one stored sample at
  the end), every thread: fixed steps with ``midpoint``, ``rk4``, ``dopri5`` and
  ``dop853`` over a ladder of steps, and adaptive steps with the pairs Dormand–Prince
  5(4) and DOP853 over a ladder of tolerances (``atol = rtol``); and fixed-step DOP853
  again on one thread (cost per core against thread count), and once more on one thread
  from the sampled states given as ``x0`` (as the peers get them: no sampling and no
  reference trajectory; the residual's decay is still measured);
* heyoka's batch mode (``heyoka.taylor_adaptive_batch``, one member per SIMD lane, each
  lane with its own step), on the same stabilized ODE built from the scene's sympy spec
  (``kernels/specs``): M, γ, F and F's acceleration term derived by ``stabdae.symbolic``,
  converted with ``heyoka.from_sympy``, and the two symmetric positive definite solves
  (M y = γ, M Y = Fᵀ; S λ = r with S = F Y) written as Gaussian elimination without
  pivoting over heyoka expressions, skipping structural zeros; over a ladder of
  tolerances, (a) one thread, a loop over batches reusing one integrator, (b) the same
  loop on every thread, one integrator each, and (c)
  ``heyoka.ensemble_propagate_until_batch`` on every thread; at heyoka's recommended
  batch size and, where the CPU has AVX-512 and heyoka recommends 4, also at 8 (as
  stabdae's kernels, :mod:`stabdae.engine.vector_width`), the driver (c) at the recommended
  size only;
* ``diffrax.diffeqsolve`` with ``Tsit5`` and a PID controller, ``jax.vmap`` over members
  and ``jax.jit``, on the first ``--diffrax-members`` members and tolerances down to 1e-9
  (slower runs take minutes), when jax and diffrax are installed: the spec's pieces as
  jax.numpy functions (``sympy.lambdify``), the solves by ``jnp.linalg.solve`` (XLA may
  use every thread, so its cost counts every core).

The error of a member is max_i |x_i − x_ref,i| / max(1, |x_ref,i|) over the 2n
coordinates and velocities at ``t_end``; a run's error is the largest over its members
(``error``) and their median (``error_median``).  The reference is heyoka at tolerance
1e-16 (``high_accuracy``); stabdae's DOP853 with the scene's finest step checks it, and
their largest difference is stored as ``reference_agreement``: errors below about ten
times that are not resolved.

Cost is core-seconds per member: wall time × threads used / members (best of
``--repeat`` for runs under 2 s).  Compile times are reported apart: stabdae's first
ensemble of each scheme in this process (from the kernel cache when it is warm), heyoka's
integrator construction (LLVM) per tolerance, diffrax's first call per tolerance.

Results: ``work_precision_ensemble.json`` (every run; per scene and error level 1e-6,
1e-9, 1e-12 the cheapest run of each tool reaching it and the ratio stabdae / heyoka, and
beside them each tool's cost interpolated log–log along its ladders to the level itself,
which shows how much of a ratio the ladders' spacing makes) and a figure
``work_precision_ensemble.png``.

Usage::

    python studies/bench_work_precision_ensemble.py [--scenes pendulum double_pendulum andrews]
                                                   [--members 10000] [--repeat 3] [--quick]
                                                   [--out studies/results] [--figures docs/figures]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numba
import numpy as np
import sympy as sp

import stabdae
from stabdae.symbolic import load_spec

sys.path.insert(0, str(Path(__file__).resolve().parent))
from work_precision import cost_at  # noqa: E402  (a sibling study, not a package)

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
LEVELS = (1e-6, 1e-9, 1e-12)


@dataclass
class Scene:
    name: str
    t_end: float
    omega: float
    radius: tuple
    fixed: dict  # scheme -> numbers of steps over [0, t_end]
    tols: tuple  # adaptive tolerances (stabdae and diffrax)
    heyoka_tols: tuple
    members: int | None = None  # fewer than --members where one run takes minutes


# Where the cost is cheap to measure, the two ladders that decide the comparison (stabdae's
# fixed-step DOP853, heyoka's tolerances) go in steps of about 1.25 and of one decade: the
# cheapest run reaching an error level then overshoots it by at most a step of the ladder.
DECADES = tuple(float(f"1e-{e}") for e in range(5, 16))

SCENES = {
    "pendulum": Scene(
        "pendulum", 10.0, 10.0, (1e-6, 1e-2),
        fixed={"midpoint": (1000, 4000, 16000, 64000), "rk4": (500, 1000, 2000, 4000, 8000),
               "dopri5": (250, 500, 1000, 2000, 4000),
               "dop853": (64, 80, 100, 125, 160, 200, 250, 320, 400, 500, 640, 800, 1000,
                          2000)},
        tols=(1e-5, 1e-7, 1e-9, 1e-11, 1e-13),
        heyoka_tols=DECADES),
    "double_pendulum": Scene(
        "double_pendulum", 2.0, 10.0, (1e-6, 1e-2),
        fixed={"midpoint": (1000, 4000, 16000, 64000), "rk4": (250, 500, 1000, 2000, 4000),
               "dopri5": (125, 250, 500, 1000, 2000),
               "dop853": (32, 40, 50, 64, 80, 100, 125, 160, 200, 250, 320, 400, 500,
                          1000)},
        tols=(1e-5, 1e-7, 1e-9, 1e-11, 1e-13),
        heyoka_tols=DECADES),
    "andrews": Scene(
        "andrews", 0.03, 1e4, (1e-8, 1e-5),
        fixed={"midpoint": (2000, 8000), "rk4": (250, 500, 1000, 2000, 4000),
               "dopri5": (250, 500, 1000, 2000, 4000),
               "dop853": (125, 160, 200, 250, 320, 400, 500, 640, 800, 1000, 2000)},
        tols=(1e-5, 1e-7, 1e-9, 1e-11, 1e-13),
        heyoka_tols=DECADES, members=1000),
}  # fmt: skip


def best_time(fn, repeat):
    """(fn(), best wall time): repeated only when a run is short."""
    clock = time.perf_counter()
    out = fn()
    best = time.perf_counter() - clock
    for _ in range(repeat - 1 if best < 2.0 else 0):
        clock = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - clock)
    return out, best


def member_errors(x, ref):
    return np.max(np.abs(x - ref) / np.maximum(1.0, np.abs(ref)), axis=1)


# --------------------------------------------------------------------------- the ODE
def _add(a, b):
    return b if a is None else a if b is None else a + b


def _mul(a, b):
    return None if a is None or b is None else a * b


def _sub_mul(a, b, c):
    """a − b c with None for a structural zero."""
    bc = _mul(b, c)
    return a if bc is None else -bc if a is None else a - bc


def _solve(A, columns):
    """Solve A X = B column by column, A symmetric positive definite (no pivoting), the
    entries heyoka expressions or None (structurally zero); the eliminations are shared
    by all columns."""
    n = len(A)
    A = [row[:] for row in A]
    B = [col[:] for col in columns]
    inv = [None] * n
    for k in range(n):
        inv[k] = 1.0 / A[k][k]
        for i in range(k + 1, n):
            if A[i][k] is None:
                continue
            lik = A[i][k] * inv[k]
            for j in range(k + 1, n):
                A[i][j] = _sub_mul(A[i][j], lik, A[k][j])
            for col in B:
                col[i] = _sub_mul(col[i], lik, col[k])
    X = []
    for col in B:
        x = [None] * n
        for i in reversed(range(n)):
            s = col[i]
            for j in range(i + 1, n):
                s = _sub_mul(s, A[i][j], x[j])
            x[i] = _mul(s, inv[i])
        X.append(x)
    return X


def heyoka_system(name: str, omega: float, xi: float = 1.0):
    """The Baumgarte-stabilized ODE ẋ = (v, M⁻¹(Fᵀλ − γ)) of a scene's spec, with
    S λ = A0 f + A1 ḟ − f_accel + F M⁻¹ γ (A0 = −ω², A1 = −2ξω), as heyoka expressions."""
    import heyoka as hy

    spec = load_spec(ROOT / "kernels" / "specs" / f"{name}.py")
    d = spec.derive()
    if spec.k or "f_t" in d:
        raise NotImplementedError(f"{name}: only scleronomic holonomic specs here")
    values = {k: sp.Float(float(v)) for k, v in spec.params.items()}
    qs = hy.make_vars(*[str(s) for s in spec.q])
    vs = hy.make_vars(*[str(s) for s in spec.v])
    qs, vs = (list(qs) if spec.n > 1 else [qs]), (list(vs) if spec.n > 1 else [vs])
    symbols = dict(zip(spec.q, qs)) | dict(zip(spec.v, vs))

    def conv(e):
        e = sp.sympify(e).xreplace(values)
        if e == 0:
            return None
        if e.is_number:
            return hy.expression(float(e))
        return hy.from_sympy(e, symbols)

    n, m = spec.n, spec.m
    M = ([[conv(d["mass"][i, j]) for j in range(n)] for i in range(n)] if "mass" in d else
         [[hy.expression(1.0) if i == j else None for j in range(n)] for i in range(n)])
    gamma = [conv(d["forces"][i, 0]) for i in range(n)]
    F = [[conv(d["f_q"][i, j]) for j in range(n)] for i in range(m)]
    f = [conv(d["f"][i, 0]) for i in range(m)]
    f_accel = [conv(d["f_accel"][i, 0]) for i in range(m)]
    *Y, y = _solve(M, [[F[r][j] for j in range(n)] for r in range(m)] + [gamma])
    S = [[None] * m for _ in range(m)]
    rhs = []
    a0, a1 = -(omega**2), -2.0 * xi * omega
    for r in range(m):
        for c in range(m):
            for j in range(n):
                S[r][c] = _add(S[r][c], _mul(F[r][j], Y[c][j]))
        fdot = None
        for j in range(n):
            fdot = _add(fdot, _mul(F[r][j], vs[j]))
        b = _add(_mul(f[r], hy.expression(a0)), _mul(fdot, hy.expression(a1)))
        b = _sub_mul(b, f_accel[r], hy.expression(1.0))
        for j in range(n):
            b = _add(b, _mul(F[r][j], y[j]))
        rhs.append(b)
    (lam,) = _solve(S, [rhs])
    acc = []
    for j in range(n):
        a = None
        for r in range(m):
            a = _add(a, _mul(Y[r][j], lam[r]))
        acc.append(_sub_mul(a, y[j], hy.expression(1.0)))
    return list(zip(qs, vs)) + [(vs[j], acc[j] if acc[j] is not None else hy.expression(0.0))
                                for j in range(n)]  # fmt: skip


def heyoka_batches():
    """heyoka's recommended batch size and, on a CPU with AVX-512 where it recommends 4
    (256-bit vectors, as LLVM prefers on most Intel models), 8 as well: stabdae's kernels
    run 512-bit vectors there, and the comparison takes each tool at its best."""
    import heyoka as hy
    from numba.core.codegen import get_host_cpu_features

    sizes = {hy.recommended_simd_size()}
    if "+avx512f" in get_host_cpu_features().split(","):
        sizes.add(8)
    return sorted(sizes)


class Heyoka:
    def __init__(self, system, x0, t_end, batch=None):
        import heyoka as hy

        self.hy, self.system, self.t_end = hy, system, t_end
        self.batch = batch or hy.recommended_simd_size()
        self.M = x0.shape[0]  # padded to whole batches with copies of the last member
        self.x0 = np.concatenate([x0, np.repeat(x0[-1:], -self.M % self.batch, axis=0)])

    def integrator(self, tol, high_accuracy=False):
        clock = time.perf_counter()
        ta = self.hy.taylor_adaptive_batch(
            self.system, np.ascontiguousarray(self.x0[: self.batch].T), tol=tol,
            high_accuracy=high_accuracy)  # fmt: skip
        return ta, time.perf_counter() - clock

    def _batches(self, ta, lo, hi, out):
        """Members ``lo … hi − 1`` (whole batches) through one integrator, into ``out``."""
        B = self.batch
        for i in range(lo, hi, B):
            ta.set_time(0.0)
            ta.state[:] = self.x0[i : i + B].T
            ta.propagate_until(self.t_end)
            _check_outcomes(ta)
            out[i : i + B] = ta.state.T

    def one_thread(self, ta):
        out = np.empty_like(self.x0)
        self._batches(ta, 0, self.x0.shape[0], out)
        return out[: self.M]

    def threaded(self, ta, threads):
        """One copy of the integrator per thread, each looping over its share of the
        batches (heyoka releases the GIL while it integrates)."""
        from concurrent.futures import ThreadPoolExecutor
        from copy import deepcopy

        B = self.batch
        bounds = np.linspace(0, self.x0.shape[0] // B, threads + 1).astype(int) * B
        out = np.empty_like(self.x0)

        def work(k):
            self._batches(self._copies[k], bounds[k], bounds[k + 1], out)

        if getattr(self, "_copied", None) is not ta:
            self._copies, self._copied = [deepcopy(ta) for _ in range(threads)], ta
        with ThreadPoolExecutor(threads) as pool:
            list(pool.map(work, range(threads)))
        return out[: self.M]

    def ensemble(self, ta, threads):
        """heyoka's own ensemble driver: one iteration per batch, each on a deep copy of
        the integrator."""
        B, x0 = self.batch, self.x0

        def gen(local, i):
            local.set_time(0.0)
            local.state[:] = x0[i * B : (i + 1) * B].T
            return local

        res = self.hy.ensemble_propagate_until_batch(
            ta, self.t_end, x0.shape[0] // B, gen, max_workers=threads)  # fmt: skip
        out = np.empty_like(x0)
        for i, r in enumerate(res):
            _check_outcomes(r[0])
            out[i * B : (i + 1) * B] = r[0].state.T
        return out[: self.M]


def _check_outcomes(ta):
    import heyoka as hy

    bad = [o for o in ta.propagate_res if o[0] != hy.taylor_outcome.time_limit]
    if bad:
        raise RuntimeError(f"heyoka stopped early: {bad}")


# --------------------------------------------------------------------------- diffrax
class Diffrax:
    """The same stabilized ODE for diffrax: the spec's M, γ, F, f and F's acceleration term
    as jax.numpy functions (``sympy.lambdify``), the two solves by ``jnp.linalg.solve``;
    Tsit5 with a PID controller, ``vmap`` over members, compiled once per tolerance."""

    def __init__(self, name, omega, x0, t_end, xi=1.0):
        import diffrax
        import jax
        import jax.numpy as jnp

        jax.config.update("jax_enable_x64", True)
        spec = load_spec(ROOT / "kernels" / "specs" / f"{name}.py")
        d = spec.derive()
        values = {k: sp.Float(float(v)) for k, v in spec.params.items()}
        n = spec.n
        mass = d["mass"] if "mass" in d else sp.eye(n)
        pieces = [sp.Matrix(e).xreplace(values) for e in
                  (mass, d["forces"], d["f_q"], d["f"], d["f_accel"])]  # fmt: skip
        fns = sp.lambdify([list(spec.q), list(spec.v)], pieces, modules="jax")
        a0, a1 = -(omega**2), -2.0 * xi * omega

        def rhs(t, x, args):
            q, v = x[:n], x[n:]
            M, gam, F, f, fa = (jnp.asarray(a, dtype=x.dtype).reshape(np.shape(e))
                                for a, e in zip(fns(q, v), pieces))  # fmt: skip
            Yy = jnp.linalg.solve(M, jnp.concatenate([F.T, gam], axis=1))
            Y, y = Yy[:, :-1], Yy[:, -1]
            lam = jnp.linalg.solve(F @ Y, a0 * f[:, 0] + a1 * (F @ v) - fa[:, 0] + F @ y)
            return jnp.concatenate([v, Y @ lam - y])

        self.diffrax, self.jax, self.jnp = diffrax, jax, jnp
        self.term, self.x0, self.t_end = diffrax.ODETerm(rhs), jnp.asarray(x0), t_end
        self._solvers = {}

    def solver(self, rtol):
        dx, jax = self.diffrax, self.jax

        def one(x0):
            sol = dx.diffeqsolve(self.term, dx.Tsit5(), 0.0, self.t_end, None, x0,
                                 stepsize_controller=dx.PIDController(rtol=rtol, atol=rtol),
                                 saveat=dx.SaveAt(t1=True), max_steps=1_000_000)  # fmt: skip
            return sol.ys[-1]

        fn = jax.jit(jax.vmap(one))
        clock = time.perf_counter()
        fn(self.x0).block_until_ready()
        return fn, time.perf_counter() - clock

    def run(self, fn):
        return np.asarray(fn(self.x0).block_until_ready())


# --------------------------------------------------------------------------- the run
def run_scene(scene: Scene, members: int, repeat: int, quick: bool, diffrax_members: int,
              log=print):  # fmt: skip
    members = min(members, scene.members or members)
    model = stabdae.load_model(scene.name)
    law = stabdae.baumgarte(scene.omega, 1.0)
    threads = numba.get_num_threads()
    common = dict(members=members, radius=scene.radius, seed=0, traces=0, states=True,
                  save_dt=scene.t_end)  # fmt: skip
    rows, compile_s = [], {}

    def stabdae_run(scheme, steps=None, rtol=None, threads=None):
        tau = scene.t_end / steps if steps else scene.t_end / 1000
        return stabdae.ensemble(model, law, scheme, tau, scene.t_end, rtol=rtol,
                                threads=threads, **common)  # fmt: skip

    # the sampled initial states, and every scheme compiled before any timing
    for scheme in scene.fixed:
        clock = time.perf_counter()
        ds = stabdae_run(scheme, steps=scene.fixed[scheme][0])
        compile_s[f"stabdae {scheme}"] = time.perf_counter() - clock
    for pair in ("dopri5", "dop853"):
        clock = time.perf_counter()
        stabdae_run(pair, rtol=1e-4)
        compile_s[f"stabdae {pair} adaptive"] = time.perf_counter() - clock
    x0 = ds["x0"].values

    # the reference: heyoka at 1e-16, checked by stabdae's DOP853 at the finest step
    system = heyoka_system(scene.name, scene.omega)
    hy_ = Heyoka(system, x0, scene.t_end)
    ta, _ = hy_.integrator(1e-16, high_accuracy=True)
    ref = hy_.threaded(ta, threads)
    check = stabdae_run("dop853", steps=4 * scene.fixed["dop853"][-1])["x_final"].values
    agreement = float(member_errors(check, ref).max())
    log(f"{scene.name}: reference agreement {agreement:.2e}")

    def record(tool, config, setting, x, wall, used):
        n = x.shape[0]  # diffrax runs the first members only
        err = member_errors(x, ref[:n])
        ok = np.all(np.isfinite(x), axis=1)
        row = dict(scene=scene.name, tool=tool, config=config, setting=setting,
                   error=float(err.max()) if ok.all() else float("inf"),
                   error_median=float(np.median(err)), finite=int(ok.sum()), wall_s=wall,
                   members=n, threads=used, core_s_per_member=wall * used / n)  # fmt: skip
        rows.append(row)
        log(f"  {tool:8s} {config:22s} {setting:>9.3g}  error {row['error']:.2e} "
            f"(median {row['error_median']:.1e})  {row['core_s_per_member'] * 1e6:9.2f} "
            "core-µs/member")

    ladder = lambda v: v[:2] if quick else v  # noqa: E731
    for scheme, steps_ladder in scene.fixed.items():
        for steps in ladder(steps_ladder):
            ds, wall = best_time(partial(stabdae_run, scheme, steps=steps), repeat)
            record("stabdae", f"{scheme} fixed", scene.t_end / steps, ds["x_final"].values,
                   wall, threads)  # fmt: skip
    for pair in ("dopri5", "dop853"):
        for rtol in ladder(scene.tols):
            ds, wall = best_time(partial(stabdae_run, pair, rtol=rtol), repeat)
            record("stabdae", f"{pair} adaptive", rtol, ds["x_final"].values, wall, threads)
    if threads > 1:  # per core on one thread: DOP853, the cheapest family on every scene
        for steps in ladder(scene.fixed["dop853"]):
            ds, wall = best_time(partial(stabdae_run, "dop853", steps=steps, threads=1), repeat)
            record("stabdae", "dop853 fixed, 1 thread", scene.t_end / steps,
                   ds["x_final"].values, wall, 1)  # fmt: skip
    # the same on the states given (x0=, as heyoka and diffrax get them): no sampling and
    # no reference trajectory, the decay measurement still made
    for steps in ladder(scene.fixed["dop853"]):
        run = partial(stabdae.ensemble, model, law, "dop853", scene.t_end / steps, scene.t_end,
                      x0=x0, traces=0, states=True, save_dt=scene.t_end, threads=1)
        ds, wall = best_time(run, repeat)
        record("stabdae", "dop853 fixed, 1 thread, given states", scene.t_end / steps,
               ds["x_final"].values, wall, 1)  # fmt: skip
    for batch in heyoka_batches():
        hy_b = Heyoka(system, x0, scene.t_end, batch)
        for tol in ladder(scene.heyoka_tols):
            ta, built = hy_b.integrator(tol)
            compile_s[f"heyoka batch {batch} tol={tol:g}"] = built
            x, wall = best_time(partial(hy_b.one_thread, ta), repeat)
            record("heyoka", f"batch of {batch}, 1 thread", tol, x, wall, 1)
            x, wall = best_time(partial(hy_b.threaded, ta, threads), repeat)
            record("heyoka", f"batch of {batch}, {threads} thr.", tol, x, wall, threads)
            if batch == hy_.batch:  # 20-60x the batch loops in every run so far
                x, wall = best_time(partial(hy_b.ensemble, ta, threads), repeat)
                record("heyoka", f"ensemble driver, {threads} thr.", tol, x, wall, threads)
    try:
        dfx = Diffrax(scene.name, scene.omega, x0[:diffrax_members], scene.t_end)
    except ImportError:
        dfx = None
    for rtol in ladder(scene.tols[:3]) if dfx is not None else ():  # slow beyond
        fn, built = dfx.solver(rtol)
        compile_s[f"diffrax rtol={rtol:g}"] = built
        x, wall = best_time(partial(dfx.run, fn), repeat)
        record("diffrax", f"tsit5 vmap, {os.cpu_count()} thr.", rtol, x, wall, os.cpu_count())
    return rows, compile_s, agreement


def cheapest(rows, level):
    ok = [r for r in rows if r["error"] <= level]
    return min(ok, key=lambda r: r["core_s_per_member"]) if ok else None


def interpolated(rows, level):
    """The cheapest cost at which a configuration reaches ``level`` when its ladder is read
    log–log between the runs around the level (:func:`work_precision.cost_at`).  Not a
    measurement: it shows how much of a ratio the ladders' spacing makes."""
    best = None
    for config in dict.fromkeys(r["config"] for r in rows):
        sel = [r for r in rows if r["config"] == config]
        cost, how = cost_at([r["error"] for r in sel], [r["core_s_per_member"] for r in sel],
                            level)  # fmt: skip
        if np.isfinite(cost) and (best is None or cost < best["core_s_per_member"]):
            best = dict(config=config, core_s_per_member=cost, how=how)
    return best


def summarize(rows, agreement):
    out = {}
    for level in LEVELS:
        entry = {}
        for tool in ("stabdae", "heyoka", "diffrax"):
            best = cheapest([r for r in rows if r["tool"] == tool], level)
            if best is not None:
                entry[tool] = {k: best[k] for k in ("config", "setting", "error",
                                                    "core_s_per_member")}  # fmt: skip
            between = interpolated([r for r in rows if r["tool"] == tool], level)
            if between is not None:
                entry[f"{tool} interpolated"] = between
        if "stabdae" in entry and "heyoka" in entry:
            entry["stabdae_over_heyoka"] = (entry["stabdae"]["core_s_per_member"]
                                            / entry["heyoka"]["core_s_per_member"])  # fmt: skip
        if "stabdae interpolated" in entry and "heyoka interpolated" in entry:
            entry["stabdae_over_heyoka_interpolated"] = (
                entry["stabdae interpolated"]["core_s_per_member"]
                / entry["heyoka interpolated"]["core_s_per_member"])
        entry["resolved"] = level >= 10 * agreement
        out[f"{level:g}"] = entry
    return out


def plot(results, path: Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = list(results)
    fig, axes = plt.subplots(1, len(scenes), figsize=(5.2 * len(scenes), 4.4), squeeze=False)
    for ax, name in zip(axes[0], scenes):
        rows = results[name]["rows"]
        configs = dict.fromkeys((r["tool"], r["config"]) for r in rows)
        for tool, config in configs:
            sel = sorted((r for r in rows if (r["tool"], r["config"]) == (tool, config)),
                         key=lambda r: -r["setting"])  # along the ladder  # fmt: skip
            err = [r["error"] for r in sel]
            cost = [r["core_s_per_member"] * 1e6 for r in sel]
            style = "-o" if tool == "stabdae" else "--s" if tool == "heyoka" else ":^"
            ax.loglog(cost, err, style, ms=4, label=f"{tool} {config}")
        ax.axhline(10 * results[name]["reference_agreement"], color="0.6", lw=0.8)
        ax.set_title(f"{name} ({results[name]['members']} members)")
        ax.set_xlabel("core-µs per member")
        ax.set_ylabel("max final-state error")
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES))
    ap.add_argument("--members", type=int, default=10_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="two settings per ladder")
    ap.add_argument("--diffrax-members", type=int, default=1000,
                    help="diffrax runs the first members only (its cost per member is "
                    "the same at 1000; a run of 10⁴ takes minutes)")  # fmt: skip
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--figures", type=Path, default=None,
                    help="also write the figure here (e.g. docs/figures)")  # fmt: skip
    args = ap.parse_args(argv)
    results = {}
    import heyoka

    meta = dict(machine=platform.processor() or platform.machine(), cpus=os.cpu_count(),
                threads=numba.get_num_threads(), stabdae=stabdae.__version__,
                heyoka=heyoka.__version__, numba=numba.__version__,
                simd=heyoka.recommended_simd_size(), heyoka_batches=heyoka_batches(),
                stabdae_512_bit_vectors=stabdae.engine.vector_width.PREFER_512,
                argv=sys.argv[1:])  # fmt: skip
    for name in args.scenes:
        rows, compile_s, agreement = run_scene(SCENES[name], args.members, args.repeat,
                                               args.quick, args.diffrax_members)  # fmt: skip
        members = min(args.members, SCENES[name].members or args.members)
        results[name] = dict(members=members, reference_agreement=agreement,
                             compile_s=compile_s, summary=summarize(rows, agreement),
                             rows=rows)  # fmt: skip
        for level, entry in results[name]["summary"].items():
            print(f"{name} error <= {level}: " + ", ".join(
                f"{tool} {e['config']}" + (f" {e['setting']:g}" if "setting" in e else "")
                + f" {e['core_s_per_member'] * 1e6:.2f} µs"
                for tool, e in entry.items() if isinstance(e, dict))
                + (f"; stabdae/heyoka {entry['stabdae_over_heyoka']:.2f}"
                   if "stabdae_over_heyoka" in entry else "")
                + (f" (interpolated {entry['stabdae_over_heyoka_interpolated']:.2f})"
                   if "stabdae_over_heyoka_interpolated" in entry else ""))  # fmt: skip
        args.out.mkdir(parents=True, exist_ok=True)  # after every scene: nothing lost
        (args.out / "work_precision_ensemble.json").write_text(
            json.dumps(dict(meta=meta, scenes=results), indent=1))
        plot(results, args.out / "work_precision_ensemble.png")
        if args.figures is not None:
            args.figures.mkdir(parents=True, exist_ok=True)
            plot(results, args.figures / "work_precision_ensemble.png")
    return results


if __name__ == "__main__":
    main()
