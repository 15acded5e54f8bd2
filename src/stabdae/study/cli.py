"""Command line: ``stabdae check``, ``integrate``, ``theory``, ``run``, ``plot``, ``generate``."""

from __future__ import annotations

import argparse
import math
import re
import sys
import time
from pathlib import Path

from .._version import __version__


def _params(pairs: list[str]) -> dict[str, float]:
    out = {}
    for pair in pairs or []:
        if "=" not in pair:
            raise SystemExit(f"stabdae: --param expects NAME=VALUE, got {pair!r}")
        key, val = pair.split("=", 1)
        try:
            out[key.strip()] = float(val)
        except ValueError:
            raise SystemExit(f"stabdae: --param {key}: {val!r} is not a number") from None
    return out


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {value}")
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}") from None
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"expected a positive finite number, got {value}")
    return value


def _safe_stem(name: str) -> str:
    """A model's name as a file name: letters, digits, ``_``, ``-`` and ``.``, no leading
    dot (a name is the model author's text, not a path: ``../../x`` stays in results/)."""
    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", name).lstrip(".")
    return stem or "model"


def _cmd_check(args) -> int:
    from .._loading import load_model

    model = load_model(args.model)
    report = model.check(_params(args.param), states=args.states, rtol=args.rtol,
                         velocity=args.velocity)  # fmt: skip
    print(model)
    print(report)
    return 0 if report.ok else 1


def _cmd_integrate(args) -> int:
    import numpy as np
    from scipy.linalg import expm

    from .. import baumgarte, integrate, none
    from .._loading import load_model
    from .._schema import write_netcdf
    from .._schemes import as_scheme, from_tableau
    from ..theory import step_matrix

    model = load_model(args.model)
    p = model.param_vector(_params(args.param))
    if args.law == "none":
        law = none()
    else:
        law = baumgarte(
            omega=args.omega if model.m else None, xi=args.xi, k=args.k if model.k else None
        )
    if args.tableau:
        import json

        try:
            spec = json.loads(args.tableau)
        except ValueError as exc:
            raise ValueError(f"--tableau: not valid JSON: {exc}") from None
        scheme = from_tableau(spec if isinstance(spec, dict) else {}, name="custom")
    else:
        scheme = as_scheme(args.scheme, **({"a": args.a, "sigma": args.sigma}
                                           if args.a is not None else {}))  # fmt: skip
    rng = np.random.default_rng(args.seed)
    x_ref = model.reference_state(p)
    direction = rng.standard_normal(x_ref.shape)
    x0 = x_ref + args.perturb * direction / np.linalg.norm(direction)

    print(f"{model}\nlaw {law}, scheme {scheme}, tau = {args.tau:g}, t_end = {args.t_end:g}")
    start = time.perf_counter()
    ds = integrate(model, x0, law, scheme, args.tau, args.t_end, args.save_dt, params=p)
    wall = time.perf_counter() - start
    g = ds["residual"].values
    times = ds.time.values - ds.time.values[0]
    A_tilde = law.A_tilde(model)
    exact = np.array([np.max(np.abs(expm(A_tilde * t) @ g[0])) for t in times])
    # the scheme's own linear recursion g_{k+1} = R(τÃ) g_k, R its stability polynomial:
    # what the residual does above the truncation floor
    R = step_matrix(A_tilde, scheme, args.tau)
    steps = np.rint(times / args.tau).astype(int)
    discrete = np.array([np.max(np.abs(np.linalg.matrix_power(R, s) @ g[0])) for s in steps])
    print(f"integrated {ds.attrs['steps']} steps in {wall:.2f} s (compile included)")
    print(f"\n{'t':>8} {'|g| measured':>14} {'|R(τÃ)^k g0|':>14} {'|expm(Ã t) g0|':>16}")
    stride = max(1, len(ds.time) // 10)
    rows = sorted(set(range(0, len(ds.time), stride)) | {len(ds.time) - 1})
    for i in rows:
        print(f"{ds.time.values[i]:8.3f} {ds.residual_norm.values[i]:14.3e} "
              f"{discrete[i]:14.3e} {exact[i]:16.3e}")  # fmt: skip
    advice = "shrink --tau" + (" or use --scheme rk4" if scheme.order < 4 else "")
    print(
        "max-norms.  Columns: the integrated residual; the scheme's linear recursion "
        "g_(k+1) = R(tau A~) g_k;\nthe exact law (3.9).  Once the residual reaches the "
        f"scheme's truncation floor (order tau^{scheme.order})\nit stops following the laws: "
        f"{advice} to lower the floor."
    )
    if "energy" in ds:
        e = ds["energy"].values
        change = abs(e[-1] - e[0])
        print(f"\nenergy change |E(t_end) - E(0)| = {change:.3e} "
              "(includes the offset's relaxation)")  # fmt: skip
    out = Path(args.output or f"results/{_safe_stem(model.name)}_trajectory.nc")
    write_netcdf(ds, out)
    print(f"dataset written to {out}")
    return 0 if ds.attrs["status"] == 0 else 1


def _cmd_theory(args) -> int:
    from .. import theory
    from .report import format_table
    from .spec import load_study
    from .theory import for_study

    study = load_study(args.study, trust_model=args.trust_model)
    print(study.describe())
    ds = for_study(study)
    base = study.setup()
    law = base["law"]
    if law.is_constant and not any(n.startswith(("law.", "model.")) for n in study.axes):
        A = law.A_tilde(study.model)
        c, ly = theory.continuous(A), theory.lyapunov(A)
        eig = ", ".join(f"{z:.4g}" for z in c["eigenvalues"])
        print(f"\nTheorem 3: eigenvalues of Ã: {eig}; decay rate {c['beta']:.6g} s-1 "
              f"({'stable' if c['stable'] else 'NOT stable'})")
        print(f"Theorem 4: L from ÃᵀL + LÃ = −I; Sylvester on L and on the symmetric part of "
              f"−LÃ: {'holds' if ly['holds'] else 'fails'}; proven rate {ly['beta']:.6g} s-1")
        scheme = base["scheme"]
        lims = {c_: float(ds[f"tau_limit_{c_}"].values.flat[0]) for c_ in theory.CONDITIONS}
        print("Theorems 6/7, largest tau for " + scheme.name + ": " +
              ", ".join(f"{k} {v:.6g}" for k, v in lims.items()))  # fmt: skip
    scheme, tau = base["scheme"], base["tau"]
    rec = theory.recommend_gain(scheme, tau)
    how = lambda steps: (f"deadbeat: the residual is gone after {steps} step"  # noqa: E731
                         f"{'s' if steps > 1 else ''}" if steps else "the smallest rho")
    print(f"\nrecommended gains for {scheme.name} at tau = {tau:g} (smallest rho(R(τÃ))): "
          f"Baumgarte omega = {rec['omega']:.6g}, xi = {rec['xi']:.6g} "
          f"(rho {rec['rho_holonomic']:.2g}, {how(rec['steps_holonomic'])}); first-order "
          f"k = {rec['k']:.6g} (rho {rec['rho_first_order']:.3g}, "
          f"{how(rec['steps_first_order'])})")  # fmt: skip
    if args.level is not None:
        _print_floors(study, base, rec, args.level)
    print("\nper grid point (R = R(τÃ); cond: the weighted-norm condition of Theorems 6/7):")
    print(format_table(ds))
    print("\ncolumns: rho(R) spectral radius of R(τÃ); |R|max its max-norm (the paper's); "
          "|R|P its norm in the\ndiscrete-Lyapunov weight; cond whether |R|P < 1 (Theorems "
          "6/7); beta −max Re λ(Ã); beta_disc\n−ln rho(R)/τ; Lyap whether Theorem 4's "
          "Lyapunov function exists; tau_lim the largest τ with\nrho(R) < 1")
    return 0


def _print_floors(study, base, rec, level: float) -> None:
    """The floors of the minimal-rho gain and of the study's law, and the balanced gain
    for ``level`` (:mod:`stabdae._gains`), at the study's first grid point."""
    import numpy as np

    from .._gains import balanced_gain, gain_floor
    from .._laws import baumgarte

    if not level > 0:
        raise ValueError(f"stabdae theory: --level must be positive, got {level:g}")
    model, scheme, tau = study.model, base["scheme"], base["tau"]
    t_end, p = base["t_end"], base["params"]
    start = float(study.ensemble["radius"][1])
    dead = gain_floor(model, baumgarte(rec["omega"], rec["xi"]), scheme, tau, t_end, params=p)
    print(f"\nfloors at tau = {tau:g} ({scheme.name}; the residual each gain settles on: "
          "predicted from the scheme's one-step remainders through (I - R)^-1, measured by "
          "16 members):")  # fmt: skip
    print(f"  minimal-rho gain omega = {rec['omega']:.6g}: predicted {dead['predicted']:.3g}, "
          f"measured {dead['measured']:.3g}")  # fmt: skip
    law = base["law"]
    if law.is_constant:
        own = gain_floor(model, law, scheme, tau, t_end, params=p)
        gains = ", ".join(f"{k} = {v:g}" for k, v in study.law.items()
                          if k in ("omega", "xi", "k"))  # fmt: skip
        print(f"  the study's law ({gains or study.law['kind']}): predicted "
              f"{own['predicted']:.3g}, measured {own['measured']:.3g}")  # fmt: skip
    b = balanced_gain(model, scheme, tau, level, start, t_end=t_end, params=p)
    if math.isfinite(b["omega"]):
        print(f"  balanced gain for the level {level:g} from {start:g}: omega = {b['omega']:.4g} "
              f"(xi = 1), below it after {b['time']:.3g} s (predicted); the minimal-rho gain "
              + (f"after {b['deadbeat_time']:.3g} s" if math.isfinite(b["deadbeat_time"])
                 else "never: its floor is above the level")
              + ". A stiffer gain contracts faster but its steps leave more residual behind: "
              "the balanced gain is the one whose floor is just low enough")  # fmt: skip
    else:
        print(f"  no Baumgarte gain from {b['omegas'][0]:.4g} down to {b['omegas'][-1]:.4g} "
              f"brings the residual below {level:g} within the run (smallest predicted floor "
              f"{np.nanmin(b['floors']):.3g}): a smaller step or a higher-order scheme "
              "lowers the floor")  # fmt: skip


def _cmd_run(args) -> int:
    from .run import run_study
    from .spec import load_study

    study = load_study(args.study, members=args.members, trust_model=args.trust_model)
    out = run_study(study, args.output, force=args.force, workers=args.workers,
                    scheduler=args.scheduler, progress=not args.quiet,
                    threads=args.threads)  # fmt: skip
    if not args.no_plots:
        try:
            from ..plots import plot_dataset
        except ImportError:
            print("pictures skipped: matplotlib is not installed (pip install 'stabdae[plots]')")
        else:
            for path in plot_dataset(out):
                print(f"picture written to {path}")
    return 0


def _cmd_plot(args) -> int:
    from ..plots import plot_dataset

    for path in plot_dataset(args.dataset, args.output):
        print(f"picture written to {path}")
    return 0


def _cmd_generate(args) -> int:
    try:
        from ..symbolic import load_spec
    except ImportError as exc:
        print(f"stabdae generate: error: {exc}", file=sys.stderr)
        return 2
    start = time.perf_counter()
    system = load_spec(args.spec)
    if args.output is None:
        print(system.source(args.spec), end="")
        return 0
    out = system.write(args.output, spec=args.spec)
    ops = system.operations
    largest = max(ops, key=ops.get)
    print(f"model {system.name!r} (n = {system.n}, m = {system.m}, k = {system.k}) written to "
          f"{out} in {time.perf_counter() - start:.1f} s: {sum(ops.values())} operations "
          f"after common subexpressions (the most in {largest}: {ops[largest]})")  # fmt: skip
    if args.no_check:
        return 0
    from .._loading import load_model

    model = load_model(out)
    report = model.check()
    print(report)
    return 0 if report.ok else 1


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="stabdae",
        description="Stability of the constraint manifold under numerical integration.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"stabdae {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    chk = sub.add_parser("check", help="check a model's derivatives by finite differences")
    chk.add_argument("model", help="model file (.py) or built-in scene name")
    chk.add_argument("--param", action="append", metavar="NAME=VALUE",
                     help="a parameter value instead of the model's default (repeatable)")
    chk.add_argument("--states", type=int, default=3, help="random states besides the reference")
    chk.add_argument("--velocity", type=float, default=None,
                     help="scale of the random states' velocities, per second (default: the "
                     "reference state's largest speed, or its largest coordinate at rest)")
    chk.add_argument("--rtol", type=_positive_float, default=1e-6,
                     help="relative tolerance of the finite-difference comparison")
    chk.set_defaults(func=_cmd_check)

    itg = sub.add_parser(
        "integrate",
        help="integrate one perturbed trajectory and compare its residual with the exact law",
    )
    itg.add_argument("model", nargs="?", default="pendulum", help="model file or scene name")
    itg.add_argument("--law", choices=["baumgarte", "none"], default="baumgarte",
                     help="the constraint-perturbation law")
    itg.add_argument("--omega", type=float, default=10.0, help="Baumgarte's omega [s-1]")
    itg.add_argument("--xi", type=float, default=1.0, help="Baumgarte's damping ratio xi")
    itg.add_argument("--k", type=float, default=10.0, help="gain of ḣ = −k h")
    itg.add_argument("--scheme", default="rk2",
                     help="euler | rk2 | midpoint | heun | rk3 | heun3 | rk4 | dopri5 | dop853 | "
                          "two_stage")
    itg.add_argument("--tableau", metavar="JSON",
                     help='your own explicit tableau, e.g. \'{"A": [[0, 0], [1, 0]], "b": [0.5, '
                          '0.5], "c": [0, 1], "order": 2}\' (instead of --scheme)')
    itg.add_argument("--a", type=float, default=None, help="two-stage parameter a")
    itg.add_argument("--sigma", type=float, default=1.0, help="two-stage parameter sigma")
    itg.add_argument("--tau", type=float, default=1e-3, help="step size [s]")
    itg.add_argument("--t-end", type=float, default=5.0, help="final time [s]")
    itg.add_argument("--save-dt", type=float, default=0.05,
                     help="spacing of the stored samples [s], a multiple of --tau")
    itg.add_argument("--perturb", type=float, default=1e-3, help="size of the initial offset")
    itg.add_argument("--seed", type=int, default=1, help="seed of the perturbation's direction")
    itg.add_argument("--param", action="append", metavar="NAME=VALUE",
                     help="a parameter value instead of the model's default (repeatable)")
    itg.add_argument("-o", "--output", help="NetCDF output path")
    itg.set_defaults(func=_cmd_integrate)

    thy = sub.add_parser("theory", help="the theorems' predictions for a study, without "
                         "running the ensembles")  # fmt: skip
    thy.add_argument("study", help="study file (TOML)")
    thy.add_argument("--trust-model", action="store_true",
                     help="run a model file the study names outside its own folder")
    thy.add_argument("--level", type=float, metavar="L",
                     help="also weigh the gains' floors: the Baumgarte gain that brings the "
                     "residual below L soonest (from the study's largest perturbation), "
                     "beside the minimal-rho gain and the study's own, each with its floor "
                     "(predicted and measured; integrates the model)")
    thy.set_defaults(func=_cmd_theory)

    run = sub.add_parser("run", help="run a study: ensembles over its grid, dataset and "
                         "pictures")  # fmt: skip
    run.add_argument("study", help="study file (TOML)")
    run.add_argument("-o", "--output", help="NetCDF output (default: the study's [output])")
    run.add_argument("--members", type=int, help="override [ensemble] members")
    run.add_argument("--trust-model", action="store_true",
                     help="run a model file the study names outside its own folder")
    run.add_argument("--force", action="store_true",
                     help="replace an existing output (the grid points this run already "
                     "finished are kept; another study's parts are discarded)")
    grp = run.add_mutually_exclusive_group()
    grp.add_argument("--workers", type=_positive_int, metavar="N",
                     help="start a local dask cluster of N worker processes")
    grp.add_argument("--scheduler", help="address of a running dask scheduler")
    run.add_argument("--threads", type=_positive_int,
                     help="threads per ensemble (default: all cores)")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    run.add_argument("--no-plots", action="store_true", help="do not write pictures")
    run.set_defaults(func=_cmd_run)

    plt_ = sub.add_parser("plot", help="pictures of a study or ensemble dataset")
    plt_.add_argument("dataset", help="NetCDF written by stabdae run")
    plt_.add_argument("-o", "--output", help="folder or file stem for the pictures")
    plt_.set_defaults(func=_cmd_plot)

    gen = sub.add_parser("generate", help="derive a model file from a symbolic Lagrangian "
                         "(sympy spec file)")  # fmt: skip
    gen.add_argument("spec", help="spec file (.py) defining system = stabdae.symbolic.System")
    gen.add_argument("-o", "--output", help="model file to write (default: print it)")
    gen.add_argument("--no-check", action="store_true",
                     help="do not load and check the written model")  # fmt: skip
    gen.set_defaults(func=_cmd_generate)

    for subparser in sub.choices.values():  # every option's help shows its default
        subparser.formatter_class = argparse.ArgumentDefaultsHelpFormatter
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, TypeError, OSError) as exc:  # StudyError, ModelError, a file, …
        print(f"stabdae {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except MemoryError:
        print(f"stabdae {args.command}: error: not enough memory (fewer members, or fewer "
              "stored samples: a larger save_dt)", file=sys.stderr)  # fmt: skip
        return 2
    except KeyboardInterrupt:
        done = " (the grid points done are kept: run the same command to resume)" \
            if args.command == "run" else ""
        print(f"stabdae {args.command}: interrupted{done}", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
