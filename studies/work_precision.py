"""Work–precision: error at the end time against cost, for every scheme × stabilization of
stabdae and for peers solving the same problems, measured side by side in one run.

For each scene (Andrews' squeezing mechanism, the car axis, the slider-crank near its dead
centre, the rolling disk, the double pendulum, the redundant four-bar), from the scene's
consistent reference state to ``t_end``:

* stabdae, through the public API (``stabdae.integrate`` / ``integrate_adaptive``), every
  combination of

  - method: fixed-step ``rk4``, ``dopri5`` and ``dop853`` over a ladder of steps τ, and
    the adaptive pairs Dormand–Prince 5(4) and DOP853 over a ladder of tolerances;
  - stabilization: ``none`` (the index-1 equations, A = 0), ``baumgarte`` (the paper's
    law), ``acpr`` (Ascher–Chin–Petzold–Reich), ``post`` (A = 0 with post-stabilization
    after each step), ``projection`` (A = 0 with coordinate projection after each step);

* peers on the index-1 equations (the same compiled right-hand side stabdae uses with
  A = 0, called from Python, so that the comparison is of the methods and their drivers,
  not of the model code): ``scipy.integrate`` DOP853 and Radau, each plain and with the
  same coordinate projection after every step; SUNDIALS IDA (BDF, through scikit-sundae)
  on the index-1 DAE in (q, v, λ) with λ algebraic, when scikit-sundae is installed.

Measured per run: wall time (best of three for runs under 0.2 s), right-hand-side
evaluations (as each solver counts them), the error of the positions at ``t_end`` against
the reference (``error``: max |q − q_ref| / max(1, |q_ref|); ``digits``: the Test Set's
significant correct digits, −log10 max |q − q_ref|/|q_ref|), and the constraint residual
max-norm at ``t_end``.  References: the Test Set for IVP Solvers' published solutions for
Andrews (t = 0.03) and the car axis (t = 3); otherwise stabdae's adaptive pair at
rtol = 1e-13 with coordinate projection, checked against scipy's DOP853 at 1e-13 with
projection (their difference is stored as ``reference_agreement``).

Results: ``work_precision.nc`` (one row per run), ``work_precision.json`` (the cost of
reaching an error of 1e-6 per configuration, interpolated log-log along each ladder, the
best stabdae configuration and the ratio of every peer to it), and two figures.

Usage::

    python studies/work_precision.py [--scenes andrews car_axis ...] [--quick]
                                     [--out studies/results]
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr
from numba import njit
from scipy.integrate import DOP853, Radau

import stabdae
from stabdae._laws import bind_law
from stabdae._schema import write_netcdf
from stabdae.engine.rhs import _noop4, _noop5, kernels_for

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from references import ANDREWS_T003, CAR_AXIS_T3  # noqa: E402

TARGET = 1e-6
STABILIZATIONS = ("none", "baumgarte", "acpr", "post", "projection")


@dataclass
class Scene:
    name: str
    t_end: float
    omega: float  # Baumgarte ω (ξ = 1) and the nonholonomic gain; the ACPR γ_s
    steps: tuple  # fixed-step ladder: numbers of steps over [t0, t_end]
    tols: tuple = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
    reference: np.ndarray | None = None  # published positions (and velocities)
    multiplier: str = "ldl"
    stabilizations: tuple = STABILIZATIONS
    peers: bool = True
    note: str = ""


SCENES = {
    "andrews": Scene("andrews", 0.03, 1e4, (1000, 2000, 4000, 8000, 16000),
                     reference=ANDREWS_T003, note="Test Set reference at t = 0.03"),
    "car_axis": Scene("car_axis", 3.0, 100.0, (1000, 2000, 4000, 8000, 16000),
                      reference=CAR_AXIS_T3[:4], note="Test Set reference at t = 3"),
    "slider_crank": Scene("slider_crank", 2.0, 20.0, (250, 500, 1000, 2000, 4000, 8000),
                          note="passes its dead centre 3 times"),
    "rolling_disk": Scene("rolling_disk", 2.0, 20.0, (100, 200, 400, 800, 1600, 3200)),
    "double_pendulum": Scene("double_pendulum", 10.0, 10.0, (500, 1000, 2000, 4000, 8000)),
    "four_bar_redundant": Scene(
        "four_bar_redundant", 2.0, 20.0, (100, 200, 400, 800, 1600), multiplier="lstsq",
        stabilizations=("none", "baumgarte"), peers=False,
        note="redundant constraint: S singular; stabdae with multiplier='lstsq' only (the "
        "peers' index-1 equations and the projections need a regular S)"),
}  # fmt: skip


def law_for(model, scene: Scene, stabilization: str):
    if stabilization == "baumgarte":
        return stabdae.baumgarte(scene.omega if model.m else None, 1.0,
                                 scene.omega if model.k else None)  # fmt: skip
    if stabilization == "acpr":
        return stabdae.acpr(scene.omega)
    return stabdae.none()


def projection_for(stabilization: str):
    return {"post": "post", "projection": "full"}.get(stabilization)


def timed(fn, *args, repeat: int = 3, **kwargs):
    """(fn(*args, **kwargs), best wall time): repeated only when a run is short."""
    clock = time.perf_counter()
    out = fn(*args, **kwargs)
    best = time.perf_counter() - clock
    if best < 0.2:
        for _ in range(repeat - 1):
            clock = time.perf_counter()
            out = fn(*args, **kwargs)
            best = min(best, time.perf_counter() - clock)
    return out, best


# --------------------------------------------------------------------------- peers
class Index1:
    """The index-1 equations of a model for solvers that call Python: stabdae's compiled
    right-hand side with A = 0, its coordinate projection, and the DAE residual in
    (q, v, λ) for IDA."""

    def __init__(self, model, p):
        self.model, self.p = model, p
        bound = bind_law(stabdae.none(), model)
        K = kernels_for(model, bound)
        self.mat, self.scal = bound.matrix, bound.scalars
        rhs, project = K.rhs, K.project
        self.ws = K.make_workspace()

        @njit
        def f1(t, x, p, mat, scal, ws, out):
            return rhs(t, x, p, mat, scal, ws, out)

        @njit
        def proj(t, x, p, ws):
            return project(t, x, p, ws, 8, 0.0)

        self._f1, self._proj = f1, proj
        self.n, self.m, self.k = model.n, model.m, model.k
        self._dae = _dae_residual(model)

    def fun(self, t, x):
        x = np.ascontiguousarray(x, dtype=np.float64)  # one compiled signature
        out = np.empty_like(x)
        self._f1(float(t), x, self.p, self.mat, self.scal, self.ws, out)
        return out

    def project(self, t, x):
        self._proj(float(t), x, self.p, self.ws)

    def dae_start(self, t, x):
        """(y0, yp0) of the index-1 DAE: λ from M a = Fᵀλ − γ at the consistent start."""
        model, p, n = self.model, self.p, self.n
        a = self.fun(t, x)[n:]
        M = model.evaluate("mass", t, x, p)
        gam = model.evaluate("forces", t, x, p)
        F = np.vstack([model.evaluate("f_q", t, x, p)[: self.m],
                       model.evaluate("h_v", t, x, p)[: self.k]])  # fmt: skip
        lam = np.linalg.lstsq(F.T, M @ a + gam, rcond=None)[0]
        y0 = np.concatenate([x, lam])
        yp0 = np.concatenate([x[n:], a, np.zeros_like(lam)])
        return y0, yp0

    def dae_residual(self, t, y, yp, res):
        self._dae(float(t), y, yp, res, self.p)


def _dae_residual(model):
    """``res(t, y, yp, out, p)`` of ``q' = v``, ``M v' − Fᵀλ + γ = 0``, ``F v' + c = 0``.

    Its small work arrays are allocated per call: passing preallocated buffers from Python
    was slower (unboxing nine arrays per call: 1.71 against 1.04 µs on Andrews)."""
    n, m, k = model.n, model.m, model.k
    fns = model.functions
    HAS_MASS, HAS_HT = "mass" in fns, "h_t" in fns
    mass = fns.get("mass", _noop4)
    forces = fns["forces"]
    f_q, f_accel = fns.get("f_q", _noop4), fns.get("f_accel", _noop5)
    h_q, h_v, h_t = fns.get("h_q", _noop5), fns.get("h_v", _noop5), fns.get("h_t", _noop5)
    mk, kk = max(m, 1), max(k, 1)

    @njit
    def res(t, y, yp, out, p):
        q, v, lam = y[:n].copy(), y[n : 2 * n].copy(), y[2 * n :]
        vp = yp[n : 2 * n]
        M = np.eye(n)
        if HAS_MASS:
            mass(t, q, p, M)
        gam = np.empty(n)
        forces(t, q, v, p, gam)
        fq, fa = np.zeros((mk, n)), np.zeros(mk)
        hq, hv, ht = np.zeros((kk, n)), np.zeros((kk, n)), np.zeros(kk)
        if m:
            f_q(t, q, p, fq)
            f_accel(t, q, v, p, fa)
        if k:
            h_q(t, q, v, p, hq)
            h_v(t, q, v, p, hv)
            if HAS_HT:
                h_t(t, q, v, p, ht)
        for i in range(n):
            out[i] = yp[i] - v[i]
            s = gam[i]
            for j in range(n):
                s += M[i, j] * vp[j]
            for a in range(m):
                s -= fq[a, i] * lam[a]
            for b in range(k):
                s -= hv[b, i] * lam[m + b]
            out[n + i] = s
        for a in range(m):
            s = fa[a]
            for j in range(n):
                s += fq[a, j] * vp[j]
            out[2 * n + a] = s
        for b in range(k):
            s = ht[b]
            for j in range(n):
                s += hv[b, j] * vp[j] + hq[b, j] * v[j]
            out[2 * n + m + b] = s

    return res


def run_scipy(sys1: Index1, solver_cls, x0, t0, t_end, tol, project: bool):
    """Step a scipy OdeSolver by hand, projecting after each step when asked."""
    solver = solver_cls(sys1.fun, t0, x0.copy(), t_end, rtol=tol, atol=tol)
    while solver.status == "running":
        msg = solver.step()
        if msg is not None:
            return None, solver.nfev, msg
        if project:
            sys1.project(solver.t, solver.y)
            solver.f = solver.fun(solver.t, solver.y)
    return solver.y.copy(), solver.nfev, "ok"


def run_ida(sys1: Index1, x0, t0, t_end, tol):
    from sksundae.ida import IDA

    y0, yp0 = sys1.dae_start(t0, x0)
    r = sys1.m + sys1.k
    ida = IDA(sys1.dae_residual, rtol=tol, atol=tol, max_num_steps=10**7,
              algebraic_idx=list(range(2 * sys1.n, 2 * sys1.n + r)))  # fmt: skip
    out = ida.solve(np.array([t0, 0.5 * (t0 + t_end), t_end]), y0, yp0)
    if not out.success:
        return None, int(out.nfev), str(out.message)
    return out.y[-1, : 2 * sys1.n].copy(), int(out.nfev), "ok"


# --------------------------------------------------------------------------- a scene
def errors(model, x, ref):
    n = model.n
    if x is None or not np.all(np.isfinite(x)):
        return math.nan, math.nan
    q, qr = x[:n], ref[:n]
    err = float(np.max(np.abs(q - qr) / np.maximum(1.0, np.abs(qr))))
    nz = np.abs(qr) > 0
    rel = np.max(np.abs(q - qr)[nz] / np.abs(qr)[nz])
    return err, float(-np.log10(rel)) if rel > 0 else 16.0


def reference_state(model, scene: Scene, x0, t0):
    """Published reference, else stabdae's tight adaptive run checked against DOP853."""
    if scene.reference is not None:
        ref = np.full(2 * model.n, np.nan)
        ref[: scene.reference.shape[0]] = scene.reference
        return ref, math.nan
    kw = dict(rtol=1e-13, atol=1e-13, multiplier=scene.multiplier)
    proj = None if scene.multiplier == "lstsq" else "full"
    ds = stabdae.integrate_adaptive(model, x0, stabdae.none(), scene.t_end,
                                    projection=proj, **kw)  # fmt: skip
    ref = ds["x"].values[-1]
    agree = math.nan
    if scene.peers:
        sys1 = Index1(model, model.default_params())
        other, _, _ = run_scipy(sys1, DOP853, x0, t0, scene.t_end, 1e-13, True)
        agree = float(np.max(np.abs(other[: model.n] - ref[: model.n])))
    return ref, agree


def run_scene(scene: Scene, *, quick: bool, ida: bool, log=print) -> tuple[list, dict]:
    model = stabdae.load_model(ROOT / "kernels" / f"{scene.name}.py")
    p = model.default_params()
    t0 = model.t0
    x0 = model.reference_state(p)
    steps = scene.steps[:3] if quick else scene.steps
    tols = scene.tols[:3] if quick else scene.tols
    ref, agree = reference_state(model, scene, x0, t0)
    rows = []

    def record(method, stabilization, setting_kind, setting, x, wall, nfev, status, res):
        err, dig = errors(model, x, ref)
        rows.append(dict(scene=scene.name, method=method, stabilization=stabilization,
                         setting_kind=setting_kind, setting=float(setting), wall_s=wall,
                         rhs_evaluations=int(nfev), error=err, digits=dig,
                         residual=float(res), status=status))  # fmt: skip
        log(f"  {method:>16s} {stabilization:>10s} {setting_kind}={setting:<9.3g} "
            f"error {err:9.2e}  digits {dig:5.2f}  |g| {res:9.2e}  {wall * 1e3:9.2f} ms  "
            f"{nfev:8d} f  {status}")  # fmt: skip

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stabdae.IntegrationWarning)
        for stab in scene.stabilizations:
            law, proj = law_for(model, scene, stab), projection_for(stab)
            for scheme, make in (("rk4", stabdae.rk4), ("dopri5", stabdae.dopri5),
                                 ("dop853", stabdae.dop853)):  # fmt: skip
                stages = make().stages
                tau = (scene.t_end - t0) / steps[0]
                stabdae.integrate(model, x0, law, scheme, tau, t0 + tau, tau,
                                  multiplier=scene.multiplier, projection=proj)  # compile
                for nsteps in steps:
                    tau = (scene.t_end - t0) / nsteps
                    ds, wall = timed(stabdae.integrate, model, x0, law, scheme, tau,
                                     scene.t_end, scene.t_end - t0,
                                     multiplier=scene.multiplier, projection=proj)  # fmt: skip
                    st = stabdae.Status(ds.attrs["status"]).name.lower()
                    record(scheme, stab, "tau", tau, ds["x"].values[-1], wall,
                           stages * nsteps, st, ds.residual_norm.values[-1])  # fmt: skip
            stabdae.integrate_adaptive(model, x0, law, scene.t_end, rtol=1e-3, atol=1e-3,
                                       max_steps=10, multiplier=scene.multiplier,
                                       projection=proj)  # compile  # fmt: skip
            for pair in ("dopri5", "dop853"):
                for tol in tols:
                    ds, wall = timed(stabdae.integrate_adaptive, model, x0, law, scene.t_end,
                                     scheme=pair, rtol=tol, atol=tol,
                                     multiplier=scene.multiplier, projection=proj)  # fmt: skip
                    st = stabdae.Status(ds.attrs["status"]).name.lower()
                    record(f"{pair}-adaptive", stab, "rtol", tol, ds["x"].values[-1], wall,
                           ds.attrs["rhs_evaluations"], st,
                           ds.residual_norm.values[-1])  # fmt: skip

    if scene.peers:
        sys1 = Index1(model, p)
        sys1.fun(t0, x0)
        sys1.project(t0, x0.copy())
        for name, cls in (("scipy-DOP853", DOP853), ("scipy-Radau", Radau)):
            for project in (False, True):
                run_scipy(sys1, cls, x0, t0, t0 + 0.01 * (scene.t_end - t0), 1e-3, project)
                for tol in tols:
                    (x, nfev, st), wall = timed(run_scipy, sys1, cls, x0, t0, scene.t_end, tol,
                                                project)  # fmt: skip
                    res = np.max(np.abs(model.residual(x, scene.t_end, p))) if x is not None \
                        else math.nan  # fmt: skip
                    record(name, "projection" if project else "none", "rtol", tol, x, wall,
                           nfev, st, res)  # fmt: skip
        if ida:
            y0, yp0 = sys1.dae_start(t0, x0)
            sys1.dae_residual(t0, y0, yp0, np.empty_like(y0))  # compile
            for tol in tols:
                (x, nfev, st), wall = timed(run_ida, sys1, x0, t0, scene.t_end, tol)
                res = np.max(np.abs(model.residual(x, scene.t_end, p))) if x is not None \
                    else math.nan  # fmt: skip
                record("sundials-IDA", "none", "rtol", tol, x, wall, nfev, st, res)
    info = dict(t_end=scene.t_end, omega=scene.omega, multiplier=scene.multiplier,
                reference=("published" if scene.reference is not None else
                           "stabdae dopri5-adaptive rtol 1e-13 + projection"),
                reference_agreement=agree, note=scene.note, n=model.n, m=model.m,
                k=model.k)  # fmt: skip
    return rows, info


# --------------------------------------------------------------------------- summary
def cost_at(errors_, costs, target=TARGET):
    """Cost of reaching ``target`` along one ladder: log-log interpolation between the
    last run above and the first run below it (runs ordered by cost); NaN if none below."""
    pts = sorted((c, e) for c, e in zip(costs, errors_) if np.isfinite(e) and np.isfinite(c))
    for i, (c, e) in enumerate(pts):
        if e <= target:
            if i == 0:
                return c, "first run already below"
            c0, e0 = pts[i - 1]
            if e0 <= e:
                return c, "interpolated"
            w = (math.log(e0) - math.log(target)) / (math.log(e0) - math.log(e))
            return math.exp(math.log(c0) + w * (math.log(c) - math.log(c0))), "interpolated"
    return math.nan, "never below"


def summarize(ds: xr.Dataset) -> dict:
    out = {}
    for scene in np.unique(ds.scene.values):
        sel = ds.where(ds.scene == scene, drop=True)
        fams = {}
        for method, stab in sorted(set(zip(sel.method.values, sel.stabilization.values))):
            mask = (sel.method == method) & (sel.stabilization == stab)
            e = sel.error.values[mask.values]
            for cost_name in ("wall_s", "rhs_evaluations"):
                c, how = cost_at(e, sel[cost_name].values[mask.values])
                fams.setdefault(f"{method}/{stab}", {})[cost_name] = c
                fams[f"{method}/{stab}"][f"{cost_name}_how"] = how
        ours = {k: v for k, v in fams.items() if not k.startswith(("scipy", "sundials"))}
        best = min(ours, key=lambda k: ours[k]["wall_s"] if np.isfinite(ours[k]["wall_s"])
                   else math.inf)  # fmt: skip
        peers = {k: v for k, v in fams.items() if k.startswith(("scipy", "sundials"))}
        out[str(scene)] = dict(
            target_error=TARGET, best_stabdae=best, best_stabdae_wall_s=ours[best]["wall_s"],
            peers={k: dict(wall_s=v["wall_s"], how=v["wall_s_how"],
                           ratio_to_best_stabdae=v["wall_s"] / ours[best]["wall_s"])
                   for k, v in peers.items()},
            configurations=fams,
        )  # fmt: skip
    return out


def to_dataset(rows, infos) -> xr.Dataset:
    cols = {k: np.array([r[k] for r in rows]) for k in rows[0]}
    units = dict(setting="s or 1", wall_s="s", rhs_evaluations="1", error="1", digits="1",
                 residual="1")  # fmt: skip
    long = dict(
        scene="scene (kernels/NAME.py)", method="integration method",
        stabilization="constraint stabilization", setting_kind="what setting is (tau, rtol)",
        setting="fixed step tau, or rtol = atol", wall_s="wall time of one run (best of 3)",
        rhs_evaluations="right-hand-side evaluations as the solver counts them",
        error="max |q - q_ref| / max(1, |q_ref|) at t_end",
        digits="significant correct digits of the positions at t_end (Test Set scd)",
        residual="max-norm of the constraint residual at t_end", status="run status",
    )  # fmt: skip
    data = {k: xr.Variable("run", v.astype(str) if v.dtype.kind in "OU" else v,
                           attrs={"long_name": long[k], **({"units": units[k]} if k in units
                                                             else {})})
            for k, v in cols.items()}  # fmt: skip
    ds = xr.Dataset(data, coords={"run": np.arange(len(rows))})
    ds.attrs.update(
        title="stabdae work-precision study", stabdae_version=stabdae.__version__,
        created=time.strftime("%Y-%m-%dT%H:%M:%S"), machine=platform.machine(),
        python=platform.python_version(), target_error=TARGET,
        scenes=json.dumps(infos), threads=1,
    )  # fmt: skip
    return ds


def plot(ds: xr.Dataset, path: Path, cost: str):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = list(dict.fromkeys(ds.scene.values.tolist()))
    cols = 3
    rows_ = -(-len(scenes) // cols)
    fig, axes = plt.subplots(rows_, cols, figsize=(5.2 * cols, 4.2 * rows_), squeeze=False)
    colors = dict(none="tab:gray", baumgarte="tab:blue", acpr="tab:green", post="tab:orange",
                  projection="tab:red")  # fmt: skip
    marks = {"rk4": "o", "dopri5": "s", "dop853": "v", "dopri5-adaptive": "^",
             "dop853-adaptive": "<", "scipy-DOP853": "P",
             "scipy-Radau": "X", "sundials-IDA": "D"}  # fmt: skip
    for ax, scene in zip(axes.ravel(), scenes):
        sel = ds.where(ds.scene == scene, drop=True)
        for method, stab in sorted(set(zip(sel.method.values, sel.stabilization.values))):
            mask = ((sel.method == method) & (sel.stabilization == stab)).values
            e, c = sel.error.values[mask], sel[cost].values[mask]
            ok = np.isfinite(e) & (e > 0)
            if not ok.any():
                continue
            order = np.argsort(c[ok])
            peer = method.startswith(("scipy", "sundials"))
            ax.loglog(c[ok][order], e[ok][order], marker=marks[method], ms=4,
                      color="black" if peer else colors[stab], ls="--" if peer else "-",
                      lw=1.0, alpha=0.9, label=f"{method} / {stab}")  # fmt: skip
        ax.axhline(TARGET, color="k", lw=0.5, ls=":")
        ax.set_title(scene)
        ax.set_xlabel("wall time per trajectory [s]" if cost == "wall_s" else
                      "right-hand-side evaluations")  # fmt: skip
        ax.set_ylabel("error of the positions at t_end")
        ax.grid(True, which="major", lw=0.3)
    for ax in axes.ravel()[len(scenes):]:
        ax.axis("off")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    for ax in axes.ravel()[1 : len(scenes)]:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0.03 + 0.035 * math.ceil(len(labels) / 5), 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES))
    ap.add_argument("--quick", action="store_true", help="three settings per ladder")
    ap.add_argument("--no-ida", action="store_true", help="leave SUNDIALS IDA out")
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--figures", type=Path, default=None,
                    help="also copy the figures here (e.g. docs/figures)")  # fmt: skip
    args = ap.parse_args(argv)
    try:
        import sksundae  # noqa: F401

        ida = not args.no_ida
    except ImportError:
        ida = False
        print("scikit-sundae is not installed: SUNDIALS IDA left out")
    rows, infos = [], {}
    for name in args.scenes:
        print(f"{name}:")
        r, info = run_scene(SCENES[name], quick=args.quick, ida=ida)
        rows += r
        infos[name] = info
    ds = to_dataset(rows, infos)
    args.out.mkdir(parents=True, exist_ok=True)
    write_netcdf(ds, args.out / "work_precision.nc")
    summary = summarize(ds)
    (args.out / "work_precision.json").write_text(json.dumps(
        dict(scenes=infos, at_target=summary), indent=1, default=float))  # fmt: skip
    for cost, fname in (("wall_s", "work_precision_time.png"),
                        ("rhs_evaluations", "work_precision_evals.png")):  # fmt: skip
        plot(ds, args.out / fname, cost)
        if args.figures is not None:
            args.figures.mkdir(parents=True, exist_ok=True)
            plot(ds, args.figures / fname, cost)
    print(f"\nat error {TARGET:g} (wall time per trajectory, interpolated along each ladder):")
    for scene, s in summary.items():
        print(f"  {scene}: best stabdae {s['best_stabdae']} "
              f"{s['best_stabdae_wall_s'] * 1e3:.3g} ms")  # fmt: skip
        for peer, v in s["peers"].items():
            print(f"      {peer:28s} {v['wall_s'] * 1e3:10.3g} ms   ratio "
                  f"{v['ratio_to_best_stabdae']:8.3g}  ({v['how']})")  # fmt: skip
    return summary


if __name__ == "__main__":
    main()
