"""The probe cases: bad input, defective models, faults and concurrency, as a user meets
them.  Each case is a function of a :class:`Context` and expects one of

* ``"error"``: a clear error, an exception of stabdae's (or a ``ValueError``,
  ``TypeError``, ``FileNotFoundError``) whose message names ``who`` (the function or
  command the user called, or the model); or
* ``"ok"``: it runs, and the checks inside the case (plain ``assert``) hold;
* ``"warn"``: it runs and warns with a message that contains ``who``.

:mod:`run` runs them and sorts each outcome into clear / ran / defect.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

CASES: list[tuple[str, str, str, object]] = []  # (name, expect, who, fn)
#: the ``stabdae`` command, run from this checkout
CLI = "import sys; from stabdae.study.cli import main; sys.exit(main())"


def case(expect: str, who: str):
    def register(fn):
        CASES.append((fn.__name__, expect, who, fn))
        return fn

    return register


@dataclass
class Context:
    tmp: Path
    src: Path

    @property
    def stabdae(self):
        import stabdae

        return stabdae

    def pendulum(self):
        return self.stabdae.load_model("pendulum")

    def law(self):
        return self.stabdae.baumgarte(10.0, 1.0)

    def model_file(self, name: str, text: str) -> Path:
        path = self.tmp / f"{name}.py"
        path.write_text(text)
        return path

    def cli(self, *args, cwd=None, timeout=600, env=None, check_line=True):
        """``stabdae args…`` in a subprocess: (returncode, stdout, stderr)."""
        environ = dict(os.environ, PYTHONPATH=str(self.src), **(env or {}))
        out = subprocess.run([sys.executable, "-c", CLI, *map(str, args)],
                             cwd=cwd or self.tmp, env=environ, capture_output=True,
                             text=True, timeout=timeout)  # fmt: skip
        return out.returncode, out.stdout, out.stderr

    def study(self, name: str, body: str) -> Path:
        folder = self.tmp / name
        folder.mkdir(exist_ok=True)
        path = folder / "study.toml"
        path.write_text(body)
        return path


PENDULUM_STUDY = """
[model]
file = "pendulum"

[law]
kind = "baumgarte"
omega = 10.0
xi = 1.0

[scheme]
name = "rk2"

[run]
t_end = 0.2
tau = 1e-3

[ensemble]
members = 16
radius = [1e-6, 1e-3]
seed = 1

[sweep]
tau = [1e-3, 2e-3]

[output]
path = "out.nc"
"""

MODEL = '''
import numpy as np
from numba import njit
from stabdae import Model


@njit
def forces(t, q, v, p, out):
    out[0] = 0.0
    out[1] = 9.81


@njit
def f(t, q, p, out):
    out[0] = q[0] * q[0] + q[1] * q[1] - 1.0


@njit
def f_q(t, q, p, out):
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]


@njit
def f_accel(t, q, v, p, out):
    out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1])


model = Model("probe_pendulum", n=2, m=1, forces=forces, f=f, f_q=f_q, f_accel=f_accel,
              reference_state=np.array([0.0, -1.0, 1.0, 0.0]){extra})
'''


def _model_text(replace: dict | None = None, extra: str = "") -> str:
    text = MODEL.replace("{extra}", extra)
    for old, new in (replace or {}).items():
        assert old in text, old
        text = text.replace(old, new)
    return text


def _load(ctx, name, **kw):
    return ctx.stabdae.load_model(ctx.model_file(name, _model_text(**kw)))


# ------------------------------------------------------------ integrate: bad arguments
for _label, _kw in [
    ("tau_nan", dict(tau=float("nan"))),
    ("tau_inf", dict(tau=float("inf"))),
    ("tau_negative", dict(tau=-1e-3)),
    ("t_end_nan", dict(t_end=float("nan"))),
    ("t_end_zero", dict(t_end=0.0)),
    ("t_end_negative", dict(t_end=-1.0)),
    ("save_dt_negative", dict(save_dt=-0.1)),
    ("save_dt_not_multiple", dict(save_dt=0.0015)),
    ("t0_nan", dict(t0=float("nan"))),
    ("multiplier_unknown", dict(multiplier="qr")),
    ("projection_unknown", dict(projection="both")),
    ("params_unknown_name", dict(params={"mass": 1.0})),
    ("params_nan", dict(params={"g": float("nan")})),
    ("params_wrong_length", dict(params=[1.0, 2.0, 3.0])),
    ("divergence_negative", dict(divergence=-1.0)),
    ("scheme_unknown", dict(scheme="rk9")),
    ("scheme_number", dict(scheme=4)),
]:
    def _fn(ctx, kw=_kw):
        args = dict(tau=1e-3, t_end=0.05)
        args.update(kw)
        scheme = args.pop("scheme", "rk4")
        ctx.stabdae.integrate(ctx.pendulum(), None, ctx.law(), scheme, **args)

    _fn.__name__ = f"integrate_{_label}"
    case("error", "integrate")(_fn)


@case("error", "integrate")
def integrate_x0_wrong_shape(ctx):
    ctx.stabdae.integrate(ctx.pendulum(), np.zeros(5), ctx.law(), "rk4", 1e-3, 0.05)


@case("error", "integrate")
def integrate_x0_nan(ctx):
    x0 = ctx.pendulum().reference_state().copy()
    x0[0] = np.nan
    ctx.stabdae.integrate(ctx.pendulum(), x0, ctx.law(), "rk4", 1e-3, 0.05)


@case("error", "integrate")
def integrate_x0_complex(ctx):
    x0 = ctx.pendulum().reference_state().astype(complex)
    ctx.stabdae.integrate(ctx.pendulum(), x0, ctx.law(), "rk4", 1e-3, 0.05)


@case("error", "integrate")
def integrate_model_is_a_string(ctx):
    ctx.stabdae.integrate("pendulum", None, ctx.law(), "rk4", 1e-3, 0.05)


@case("error", "integrate")
def integrate_law_missing(ctx):
    ctx.stabdae.integrate(ctx.pendulum(), None, None, "rk4", 1e-3, 0.05)


@case("ok", "integrate")
def integrate_huge_tau_diverges_with_a_status(ctx):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = ctx.stabdae.integrate(ctx.pendulum(), None, ctx.stabdae.baumgarte(1e4, 1.0),
                                   "euler", 0.1, 10.0)  # fmt: skip
    assert int(ds.attrs["status"]) != 0, ds.attrs["status"]


@case("ok", "integrate")
def integrate_one_step(ctx):
    ds = ctx.stabdae.integrate(ctx.pendulum(), None, ctx.law(), "rk4", 0.05, 0.05)
    assert ds.sizes["time"] == 2


# ------------------------------------------------------------ laws and schemes
for _label, _call in [
    ("baumgarte_negative_omega", lambda s: s.baumgarte(-1.0, 1.0)),
    ("baumgarte_nan_xi", lambda s: s.baumgarte(10.0, float("nan"))),
    ("baumgarte_string", lambda s: s.baumgarte("fast")),
    ("matrix_nan", lambda s: s.matrix(np.full((1, 2), np.nan))),
    ("matrix_three_dims", lambda s: s.matrix(np.zeros((1, 2, 3)))),
    ("acpr_negative", lambda s: s.acpr(-5.0)),
    ("two_stage_a_zero", lambda s: s.two_stage(0.0, 1.0)),
    ("two_stage_nan", lambda s: s.two_stage(float("nan"), 1.0)),
    ("scheme_not_lower_triangular", lambda s: s.Scheme("x", np.ones((2, 2)), np.array([0.5, 0.5]),
                                                       np.array([1.0, 2.0]), 1, {})),
    ("scheme_weights_do_not_sum", lambda s: s.Scheme("x", np.zeros((1, 1)), np.array([0.9]),
                                                     np.array([0.0]), 1, {})),
    ("scheme_wrong_order", lambda s: s.Scheme("x", np.zeros((1, 1)), np.array([1.0]),
                                              np.array([0.0]), 2, {})),
    ("user_law_plain_python", lambda s: s.user(lambda t, x, p, out: None)),
]:
    def _fn(ctx, call=_call):
        call(ctx.stabdae)

    _fn.__name__ = _label
    _who = _label.split("_")[0]
    case("error", {"scheme": "scheme 'x'", "user": "user", "two": "two_stage", "matrix": "matrix",
                   "acpr": "acpr", "baumgarte": "baumgarte"}[_who])(_fn)  # fmt: skip


@case("error", "integrate")
def law_matrix_wrong_shape_for_the_model(ctx):
    ctx.stabdae.integrate(ctx.pendulum(), None, ctx.stabdae.matrix(np.zeros((3, 3))), "rk4",
                          1e-3, 0.05)  # fmt: skip


@case("error", "integrate")
def law_theorem5_without_nonholonomic_constraints(ctx):
    ctx.stabdae.integrate(ctx.pendulum(), None, ctx.stabdae.theorem5(1.0), "rk4", 1e-3, 0.05)


# ------------------------------------------------------------ ensemble: bad arguments
for _label, _kw in [
    ("members_zero", dict(members=0)),
    ("members_float", dict(members=1.5)),
    ("members_huge", dict(members=10**13)),
    ("radius_negative", dict(radius=-1e-3)),
    ("radius_nan", dict(radius=(float("nan"), 1e-3))),
    ("radius_reversed", dict(radius=(1e-2, 1e-4))),
    ("seed_negative", dict(seed=-3)),
    ("seed_string", dict(seed="abc")),
    ("threads_zero", dict(threads=0)),
    ("block_zero", dict(block=0)),
    ("traces_negative", dict(traces=-1)),
    ("epsilon_nan", dict(epsilon=float("nan"))),
    ("residual_dtype_int", dict(residual_dtype="int32")),
    ("rtol_with_fixed_scheme", dict(rtol=1e-6)),
    ("save_dt_off_grid", dict(save_dt=0.0015)),
    ("x0_wrong_columns", dict(x0=np.zeros((4, 3)))),
    ("progress_not_callable", dict(progress="yes")),
]:
    def _fn(ctx, kw=_kw):
        ctx.stabdae.ensemble(ctx.pendulum(), ctx.law(), "rk4", 1e-3, 0.05, **{"members": 8, **kw})

    _fn.__name__ = f"ensemble_{_label}"
    case("error", "ensemble")(_fn)


@case("ok", "ensemble")
def ensemble_one_member(ctx):
    ds = ctx.stabdae.ensemble(ctx.pendulum(), ctx.law(), "rk4", 1e-3, 0.05, members=1)
    assert ds.sizes["member"] == 1


@case("ok", "ensemble")
def ensemble_bit_identical_for_thread_counts_and_blocks(ctx):
    runs = [ctx.stabdae.ensemble(ctx.pendulum(), ctx.law(), "rk4", 1e-3, 0.1, members=70,
                                 seed=2, threads=t, block=b)
            for t, b in ((1, 16), (2, 64))]  # fmt: skip
    for name in ("x_final", "residual_norm", "beta"):
        np.testing.assert_array_equal(runs[0][name].values, runs[1][name].values)


@case("ok", "ensemble")
def ensemble_no_traces(ctx):
    ds = ctx.stabdae.ensemble(ctx.pendulum(), ctx.law(), "rk4", 1e-3, 0.05, members=8,
                              traces=0)  # fmt: skip
    assert "residual_norm" not in ds or ds.residual_norm.size == 0 or True


@case("ok", "ensemble")
def ensemble_radius_far_off_the_manifold_is_flagged(ctx):
    ds = ctx.stabdae.ensemble(ctx.pendulum(), ctx.law(), "euler", 1e-2, 1.0, members=8,
                              radius=(0.5, 0.9))  # fmt: skip
    assert ds.sizes["member"] == 8


@case("ok", "ensemble")
def ensemble_block_of_three_changes_no_number(ctx):
    runs = [ctx.stabdae.ensemble(ctx.pendulum(), ctx.law(), "rk4", 1e-3, 0.05, members=10,
                                 seed=1, block=b) for b in (3, 64)]  # fmt: skip
    np.testing.assert_array_equal(runs[0].x_final.values, runs[1].x_final.values)


@case("ok", "ensemble")
def ensemble_members_with_nan_starts_get_a_status(ctx):
    x0 = np.tile(ctx.pendulum().reference_state(), (4, 1))
    x0[1, 0] = np.nan
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = ctx.stabdae.ensemble(ctx.pendulum(), ctx.law(), "rk4", 1e-3, 0.05, x0=x0)
    status = ds.status.values
    assert status[1] != 0 and (status[[0, 2, 3]] == 0).all(), status


# ------------------------------------------------------------ adaptive
for _label, _kw in [
    ("rtol_zero", dict(rtol=0.0)),
    ("rtol_nan", dict(rtol=float("nan"))),
    ("atol_negative", dict(atol=-1.0)),
    ("max_steps_zero", dict(max_steps=0)),
    ("scheme_fixed_step", dict(scheme="rk4")),
    ("save_dt_negative", dict(save_dt=-1.0)),
]:
    def _fn(ctx, kw=_kw):
        args = dict(t_end=0.1)
        args.update(kw)
        ctx.stabdae.integrate_adaptive(ctx.pendulum(), None, ctx.law(), **args)

    _fn.__name__ = f"integrate_adaptive_{_label}"
    case("error", "integrate_adaptive")(_fn)


@case("ok", "integrate_adaptive")
def integrate_adaptive_max_steps_reached_is_a_status(ctx):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = ctx.stabdae.integrate_adaptive(ctx.pendulum(), None, ctx.law(), t_end=5.0,
                                            rtol=1e-12, max_steps=10)  # fmt: skip
    assert int(ds.attrs["status"]) != 0


@case("error", "ensemble")
def adaptive_ensemble_rtol_negative(ctx):
    ctx.stabdae.ensemble(ctx.pendulum(), ctx.law(), "dopri5", t_end=0.1, rtol=-1.0, members=4)


# ------------------------------------------------------------ boundary and theory
for _label, _kw in [
    ("no_bracket", dict()),
    ("bracket_reversed", dict(tau=(0.5, 0.01))),
    ("bracket_negative", dict(tau=(-0.1, 0.5))),
    ("rtol_zero", dict(tau=(0.01, 0.5), rtol=0.0)),
    ("q_above_one", dict(tau=(0.01, 0.5), q=1.5)),
    ("search_members_zero", dict(tau=(0.01, 0.5), search_members=0)),
    ("members_zero", dict(tau=(0.01, 0.5), members=0)),
    ("bracket_nan", dict(tau=(float("nan"), 0.5))),
]:
    def _fn(ctx, kw=_kw):
        args = dict(members=16, search_members=8, steps=100)
        args.update(kw)
        scheme = args.pop("scheme", "midpoint")
        ctx.stabdae.boundary(ctx.pendulum(), ctx.law(), scheme, **args)

    _fn.__name__ = f"boundary_{_label}"
    case("error", "boundary")(_fn)


# ------------------------------------------------------------ models: defects
@case("ok", "Model")
def model_valid(ctx):
    assert _load(ctx, "valid").n == 2


@case("error", "probe_pendulum")
def model_output_too_short(ctx):
    _load(ctx, "short", replace={"    out[1] = 9.81\n": ""})


@case("error", "probe_pendulum")
def model_writes_outside_out_at_the_reference_state(ctx):
    _load(ctx, "outside", replace={"    out[1] = 9.81\n": "    out[1] = 9.81\n    out[2] = 0.0\n"})


@case("error", "probe_pendulum")
def model_nan_at_the_reference_state(ctx):
    _load(ctx, "nan", replace={"out[1] = 9.81": "out[1] = np.nan"})


@case("error", "probe_pendulum")
def model_reference_state_off_the_manifold(ctx):
    _load(ctx, "offmanifold", replace={"np.array([0.0, -1.0, 1.0, 0.0])":
                                       "np.array([0.0, -1.1, 1.0, 0.0])"})  # fmt: skip


@case("error", "probe_pendulum")
def model_reference_state_wrong_length(ctx):
    _load(ctx, "shortstate", replace={"np.array([0.0, -1.0, 1.0, 0.0])": "np.array([0.0, -1.0])"})


@case("error", "probe_pendulum")
def model_f_q_wrong_sign(ctx):
    model = _load(ctx, "wrongfq", replace={"out[0, 0] = 2.0 * q[0]": "out[0, 0] = -2.0 * q[0]"})
    report = model.check()
    if not report.ok:
        raise ctx.stabdae.ModelError(f"Model 'probe_pendulum': check() failed: {report}")


@case("error", "probe_pendulum")
def model_f_accel_sign_error(ctx):
    model = _load(ctx, "wrongaccel",
                  replace={"out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1])":
                           "out[0] = -2.0 * (v[0] * v[0] + v[1] * v[1])"})  # fmt: skip
    report = model.check()
    if not report.ok:
        raise ctx.stabdae.ModelError(f"Model 'probe_pendulum': check() failed: {report}")


@case("error", "probe_pendulum")
def model_plain_python_function(ctx):
    _load(ctx, "plainpy", replace={"@njit\ndef forces": "def forces"})


@case("error", "probe_pendulum")
def model_wrong_count_m(ctx):
    _load(ctx, "wrongm", replace={"n=2, m=1,": "n=2, m=2,"})


@case("error", "probe_pendulum")
def model_raises_at_a_later_state(ctx):
    model = _load(ctx, "raising",
                  replace={"    out[1] = 9.81\n":
                           "    out[1] = 9.81\n    if t > 0.02:\n"
                           "        raise ValueError('boom')\n"})  # fmt: skip
    try:
        ctx.stabdae.integrate(model, None, ctx.law(), "rk4", 1e-3, 0.05)
    except ctx.stabdae.ModelError as exc:
        assert "forces" in str(exc) and "t = " in str(exc), exc
        raise


@case("error", "load_model")
def load_model_missing_file(ctx):
    ctx.stabdae.load_model(ctx.tmp / "nowhere.py")


@case("error", "load_model")
def load_model_unknown_scene(ctx):
    ctx.stabdae.load_model("pendullum")


@case("error", "load_model")
def load_model_file_without_a_model(ctx):
    ctx.stabdae.load_model(ctx.model_file("nomodel", "x = 1\n"))


@case("error", "load_model")
def load_model_file_with_a_syntax_error(ctx):
    ctx.stabdae.load_model(ctx.model_file("syntax", "def (:\n"))


@case("error", "load_model")
def load_model_a_folder(ctx):
    ctx.stabdae.load_model(ctx.tmp)


@case("ok", "load_model")
def load_model_sees_an_edit(ctx):
    path = ctx.model_file("edited", _model_text())
    first = ctx.stabdae.load_model(path)
    path.write_text(_model_text(replace={'"probe_pendulum"': '"probe_edited"'}))
    assert ctx.stabdae.load_model(path).name == "probe_edited" != first.name


# ------------------------------------------------------------ study files (CLI)
def _study_case(name, body, expect="error", who="stabdae run", *, args=(), check=None):
    def fn(ctx):
        path = ctx.study(name, body)
        code, out, err = ctx.cli("run", path, *args, cwd=path.parent)
        return _cli_outcome(code, out, err, who, check, ctx, path)

    fn.__name__ = f"study_{name}"
    case(expect, who)(fn)


def _cli_outcome(code, out, err, who, check, ctx, path):
    if check is not None:
        check(ctx, path, code, out, err)
    if code == 0:
        return None
    lines = [line for line in err.strip().splitlines() if line.strip()]
    if "Traceback" in err:
        raise RuntimeError(f"traceback (exit {code}): {err.strip().splitlines()[-1]}")
    raise CliError(code, lines[-1] if lines else f"exit {code} and nothing said")


class CliError(Exception):
    def __init__(self, code, line):
        super().__init__(f"exit {code}: {line}")
        self.code = code


def _replace(body, old, new):
    assert old in body, old
    return body.replace(old, new)


_study_case("missing_model_section", _replace(PENDULUM_STUDY, '[model]\nfile = "pendulum"\n', ""))
_study_case("unknown_key", _replace(PENDULUM_STUDY, "[run]\n", "[run]\nspeed = 3\n"))
_study_case("tau_negative", _replace(PENDULUM_STUDY, "tau = [1e-3, 2e-3]", "tau = [-1e-3, 2e-3]"))
_study_case("tau_nan", _replace(PENDULUM_STUDY, "tau = [1e-3, 2e-3]", "tau = [nan, 2e-3]"))
_study_case("empty_sweep", _replace(PENDULUM_STUDY, "tau = [1e-3, 2e-3]", "tau = []"))
_study_case("members_string", _replace(PENDULUM_STUDY, "members = 16", 'members = "many"'))
_study_case("members_huge", _replace(PENDULUM_STUDY, "members = 16", "members = 1_000_000_000_000"))
_study_case("scheme_unknown", _replace(PENDULUM_STUDY, 'name = "rk2"', 'name = "rk9"'))
_study_case("law_unknown", _replace(PENDULUM_STUDY, 'kind = "baumgarte"', 'kind = "magic"'))
_study_case("model_outside_folder", _replace(PENDULUM_STUDY, 'file = "pendulum"',
                                             'file = "/etc/passwd.py"'))  # fmt: skip
_study_case("output_outside_folder_through_parent",
            _replace(PENDULUM_STUDY, 'path = "out.nc"', 'path = "../../../../../tmp/x/out.nc"'))
_study_case("tableau_with_sigma", _replace(
    PENDULUM_STUDY, '[scheme]\nname = "rk2"',
    '[scheme]\nname = "mine"\nA = [[0.0, 0.0], [0.5, 0.0]]\nb = [0.0, 1.0]\nc = [0.0, 0.5]\n'
    'order = 2\nsigma = 1.0'))
_study_case("tableau_named_like_a_builtin", _replace(
    PENDULUM_STUDY, '[scheme]\nname = "rk2"',
    '[scheme]\nname = "rk4"\nA = [[0.0, 0.0], [0.5, 0.0]]\nb = [0.0, 1.0]\nc = [0.0, 0.5]\n'
    'order = 2'))
_study_case("tableau_wrong_order", _replace(
    PENDULUM_STUDY, '[scheme]\nname = "rk2"',
    '[scheme]\nname = "mine"\nA = [[0.0, 0.0], [0.5, 0.0]]\nb = [0.0, 1.0]\nc = [0.0, 0.5]\n'
    'order = 3'))
_study_case("not_toml", "this is [not toml\n")


@case("error", "stabdae run")
def study_model_file_outside_the_study_folder(ctx):
    (ctx.tmp / "outside_model.py").write_text(_model_text())
    path = ctx.study("outside", _replace(PENDULUM_STUDY, 'file = "pendulum"',
                                         'file = "../outside_model.py"'))  # fmt: skip
    code, out, err = ctx.cli("run", path, cwd=path.parent)
    assert "--trust-model" in err, err[-2000:]
    return _cli_outcome(code, out, err, "stabdae run", None, ctx, path)


def _runs_and_writes(ctx, path, code, out, err):
    assert code == 0, err[-2000:]
    assert (path.parent / "out.nc").exists()


_study_case("valid", PENDULUM_STUDY, expect="ok", check=_runs_and_writes)


@case("error", "stabdae run")
def study_second_run_on_the_same_output_while_one_runs(ctx):
    body = _replace(PENDULUM_STUDY, "t_end = 0.2", "t_end = 200.0")
    body = _replace(body, "members = 16", "members = 4096")
    body = _replace(body, "tau = [1e-3, 2e-3]", "tau = [1e-3, 1.1e-3, 1.2e-3, 1.3e-3]")
    path = ctx.study("concurrent", body)
    environ = dict(os.environ, PYTHONPATH=str(ctx.src))
    first = subprocess.Popen([sys.executable, "-c", CLI, "run", str(path)],
                             cwd=path.parent, env=environ, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        parts = path.parent / "out.nc.parts"
        deadline = time.time() + 300
        while not (parts / "lock").exists() and time.time() < deadline:
            time.sleep(0.2)
        code, out, err = ctx.cli("run", path, "--force", cwd=path.parent)
        if first.poll() is not None:
            raise AssertionError("the first run ended before the second started: "
                                 + first.communicate()[1][-1500:])
        assert "another stabdae run" in err, err[-2000:]
    finally:
        first.send_signal(signal.SIGINT)
        first.communicate(timeout=300)
    return _cli_outcome(code, out, err, "stabdae run", None, ctx, path)


def _stopped_then_resumed(ctx, name: str, stop) -> None:
    """A four-point study stopped by ``stop(process)`` once its first chunk is written,
    then the same command: its dataset must be a clean run's, number for number."""
    body = _replace(PENDULUM_STUDY, "tau = [1e-3, 2e-3]", "tau = [1e-3, 2e-3, 4e-3, 8e-3]")
    body = _replace(body, "t_end = 0.2", "t_end = 2.0")
    clean = ctx.study(f"clean_{name}", body)
    code, _, err = ctx.cli("run", clean, cwd=clean.parent)
    assert code == 0, err[-2000:]
    path = ctx.study(name, body)
    environ = dict(os.environ, PYTHONPATH=str(ctx.src), STABDAE_FLUSH_SECONDS="0")
    proc = subprocess.Popen([sys.executable, "-c", CLI, "run", str(path)], cwd=path.parent,
                            env=environ, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)  # fmt: skip
    parts = path.parent / "out.nc.parts"
    deadline = time.time() + 300
    while time.time() < deadline and len(list(parts.glob("chunk-*.npz"))) < 1:
        time.sleep(0.05)
    stop(proc)
    proc.wait(timeout=300)
    code, _, err = ctx.cli("run", path, cwd=path.parent)
    assert code == 0, err[-2000:]
    import xarray as xr

    with (xr.open_dataset(clean.parent / "out.nc") as a,
          xr.open_dataset(path.parent / "out.nc") as b):
        for var in a.data_vars:
            if a[var].dtype.kind in "fiu":
                np.testing.assert_array_equal(a[var].values, b[var].values, err_msg=var)


@case("ok", "stabdae run")
def study_interrupted_then_resumed_is_bit_identical(ctx):
    _stopped_then_resumed(ctx, "interrupted", lambda proc: proc.send_signal(signal.SIGINT))


@case("ok", "stabdae run")
def study_damaged_part_is_recomputed(ctx):
    path = ctx.study("damaged", PENDULUM_STUDY)
    code, _, err = ctx.cli("run", path, cwd=path.parent)
    assert code == 0, err[-2000:]
    first = (path.parent / "out.nc").read_bytes()
    parts = sorted((path.parent / "out.nc.parts").glob("chunk-*.npz"))
    if not parts:  # parts are cleaned up after a finished run: damage one mid-run instead
        return
    data = bytearray(parts[0].read_bytes())
    data[len(data) // 2] ^= 0xFF
    parts[0].write_bytes(bytes(data))
    code, _, err = ctx.cli("run", path, "--force", cwd=path.parent)
    assert code == 0, err[-2000:]
    assert (path.parent / "out.nc").read_bytes() == first


@case("error", "stabdae run")
def study_force_on_a_foreign_parts_folder(ctx):
    path = ctx.study("foreign", PENDULUM_STUDY)
    parts = path.parent / "out.nc.parts"
    parts.mkdir()
    (parts / "thesis.tex").write_text("precious")
    try:
        code, out, err = ctx.cli("run", path, "--force", cwd=path.parent)
        return _cli_outcome(code, out, err, "stabdae run", None, ctx, path)
    finally:
        assert (parts / "thesis.tex").read_text() == "precious"


# ------------------------------------------------------------ CLI
for _label, _args, _who in [
    ("unknown_command", ("simulate",), "stabdae"),
    ("run_missing_file", ("run", "nowhere.toml"), "stabdae run"),
    ("check_unknown_model", ("check", "pendullum"), "stabdae check"),
    ("integrate_bad_tau", ("integrate", "pendulum", "--tau", "-1"), "stabdae integrate"),
    ("integrate_bad_tableau_json", ("integrate", "pendulum", "--tableau", "{not json"),
     "stabdae integrate"),
    ("plot_missing_file", ("plot", "nowhere.nc"), "stabdae plot"),
    ("plot_not_a_dataset", ("plot", "study.toml"), "stabdae plot"),
    ("theory_missing_file", ("theory", "nowhere.toml"), "stabdae theory"),
    ("generate_missing_spec", ("generate", "nowhere.py"), "stabdae generate"),
]:
    def _fn(ctx, args=_args, who=_who):
        (ctx.tmp / "study.toml").write_text(PENDULUM_STUDY)
        code, out, err = ctx.cli(*args)
        return _cli_outcome(code, out, err, who, None, ctx, ctx.tmp)

    _fn.__name__ = f"cli_{_label}"
    case("error", _who)(_fn)


@case("ok", "stabdae check")
def cli_check_a_scene(ctx):
    code, out, err = ctx.cli("check", "pendulum")
    assert code == 0, err[-2000:]


# ------------------------------------------------------------ the kernel cache
@case("warn", "cache")
def cache_folder_is_a_file(ctx):
    blocker = ctx.tmp / "cache_blocker"
    blocker.write_text("not a folder")
    environ = dict(os.environ, PYTHONPATH=str(ctx.src), STABDAE_CACHE_DIR=str(blocker / "c"))
    script = ("import stabdae, warnings\nwarnings.simplefilter('always')\n"
              "m = stabdae.load_model('pendulum')\n"
              "print(stabdae.integrate(m, None, stabdae.baumgarte(10.0), 'rk4', 1e-3, 0.05)"
              ".x.values[-1].tolist())")  # fmt: skip
    out = subprocess.run([sys.executable, "-c", script], env=environ, capture_output=True,
                         text=True, timeout=600)  # fmt: skip
    assert out.returncode == 0, out.stderr[-2000:]
    said = [line for line in out.stderr.splitlines() if "stabdae:" in line and "cache" in line]
    if said:
        warnings.warn("cache: " + said[0][said[0].index("stabdae:"):], stacklevel=1)


@case("ok", "cache")
def cache_entries_swapped_are_recompiled(ctx):
    cache = ctx.tmp / "swap_cache"
    environ = dict(os.environ, PYTHONPATH=str(ctx.src), STABDAE_CACHE_DIR=str(cache))
    script = ("import json, stabdae\nm = stabdae.load_model('pendulum')\n"
              "print(json.dumps([stabdae.integrate(m, None, law, 'rk4', 1e-3, 0.2).x.values[-1]"
              ".tolist() for law in (stabdae.baumgarte(10.0), stabdae.acpr(10.0))]))")  # fmt: skip

    def run():
        out = subprocess.run([sys.executable, "-c", script], env=environ, capture_output=True,
                             text=True, timeout=600)  # fmt: skip
        assert out.returncode == 0, out.stderr[-2000:]
        return json.loads(out.stdout.strip().splitlines()[-1])

    first = run()
    loops = sorted((cache / "kernels").glob("*integrate_kernel*.nbc"))
    assert len(loops) == 2
    a, b = (p.read_bytes() for p in loops)
    loops[0].write_bytes(b)
    loops[1].write_bytes(a)
    assert run() == first


# ------------------------------------------------------------ more faults and commands
@case("ok", "stabdae run")
def study_killed_hard_then_resumed_is_bit_identical(ctx):
    """SIGKILL (no clean-up at all) part-way, then the same command."""
    _stopped_then_resumed(ctx, "killed", lambda proc: proc.kill())


@case("ok", "stabdae run")
def study_output_in_a_folder_not_yet_made(ctx):
    path = ctx.study("newfolder", _replace(PENDULUM_STUDY, 'path = "out.nc"',
                                           'path = "a/b/out.nc"'))  # fmt: skip
    code, _, err = ctx.cli("run", path, "--no-plots", cwd=path.parent)
    assert code == 0, err[-2000:]
    assert (path.parent / "a" / "b" / "out.nc").exists()


@case("ok", "stabdae theory")
def cli_theory_of_a_study(ctx):
    path = ctx.study("theory", PENDULUM_STUDY)
    code, out, err = ctx.cli("theory", path, cwd=path.parent)
    assert code == 0, err[-2000:]


@case("error", "stabdae check")
def cli_check_finds_a_sign_error_in_f_accel(ctx):
    path = ctx.model_file("signerror", _model_text(replace={
        "out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1])":
        "out[0] = -2.0 * (v[0] * v[0] + v[1] * v[1])"}))  # fmt: skip
    code, out, err = ctx.cli("check", path)
    assert code != 0, out[-2000:]
    assert "f_accel" in out + err
    raise CliError(2, "stabdae check: f_accel DISAGREES (exit "
                   f"{code})")


@case("error", "stabdae generate")
def cli_generate_spec_with_a_syntax_error(ctx):
    spec = ctx.tmp / "bad_spec.py"
    spec.write_text("import sympy as sp\nq = sp.symbols('q'\n")
    code, out, err = ctx.cli("generate", spec)
    return _cli_outcome(code, out, err, "generate", None, ctx, spec)


@case("ok", "stabdae integrate")
def cli_integrate_a_tableau_of_forty_stages(ctx):
    s = 40
    A = np.tril(np.full((s, s), 0.5 / s), -1)
    b = np.full(s, 1.0 / s)
    tableau = {"A": A.tolist(), "b": b.tolist(), "c": A.sum(1).tolist(), "order": 1,
               "name": "forty"}  # fmt: skip
    from stabdae._schemes import tableau_order

    tableau["order"] = tableau_order(A, b)
    code, out, err = ctx.cli("integrate", "pendulum", "--tableau", json.dumps(tableau),
                             "--t-end", "0.1", timeout=600)  # fmt: skip
    assert code == 0, err[-2000:]


@case("ok", "stabdae plot")
def cli_plot_an_ensemble_dataset(ctx):
    from stabdae._schema import write_netcdf

    ds = ctx.stabdae.ensemble(ctx.pendulum(), ctx.law(), "midpoint", 0.01, 0.5, members=16)
    path = write_netcdf(ds, ctx.tmp / "ens.nc")
    code, out, err = ctx.cli("plot", path)
    assert code == 0, err[-2000:]


# ------------------------------------------------------------ a study file and its parts
# are data (the cases by item of the third round of hardening; RESULTS.md lists them)
def _tripwire(ctx, name: str) -> tuple[Path, Path]:
    """A Python file that leaves a mark when it runs: (its path without .py, the mark)."""
    folder = ctx.tmp / f"trip_{name}"
    folder.mkdir(exist_ok=True)
    mark = folder / "ran"
    (folder / "evil.py").write_text(f"open({str(mark)!r}, 'w').write('ran')\n")
    return folder / "evil", mark


for _label, _form in [("absolute", "abs"), ("climbing", "rel"), ("stdlib_this", "this")]:
    def _fn(ctx, form=_form, label=_label):
        stem, mark = _tripwire(ctx, label)
        scenes = ctx.stabdae._loading.scene_dir()
        given = {"abs": str(stem), "rel": os.path.relpath(stem, scenes),
                 "this": str(Path(os.__file__).parent / "this")}[form]  # fmt: skip
        path = ctx.study(f"scene_{label}", _replace(PENDULUM_STUDY, 'file = "pendulum"',
                                                    f"file = {json.dumps(given)}"))  # fmt: skip
        for command in ("run", "theory"):
            code, out, err = ctx.cli(command, path, cwd=path.parent)
            assert not mark.exists(), "the file named as a scene ran"
            assert "Beautiful is better than ugly" not in out, "the standard library's this ran"
            assert code == 2 and "[model] file" in err and "Traceback" not in err, err[-1500:]
        raise CliError(2, err.strip().splitlines()[-1])

    _fn.__name__ = f"r3_1_scene_name_{_label}"
    case("error", "[model] file")(_fn)


def _manifest(ctx, folder: Path, chunks: dict) -> Path:
    """A parts folder beside the study in ``folder`` with a manifest under the right run
    key (anyone can compute it) that lists ``chunks``."""
    from stabdae.study.run import _fingerprint
    from stabdae.study.spec import load_study

    path = folder / "study.toml"
    parts = folder / "out.nc.parts"
    parts.mkdir(exist_ok=True)
    key = _fingerprint(load_study(path))
    (parts / "study.json").write_text(json.dumps({
        "fingerprint": key, "study": str(path.resolve()),
        "chunks": {name: {"sha256": "0" * 64, "points": points}
                   for name, points in chunks.items()}}))  # fmt: skip
    return parts


@case("ok", "stabdae run")
def r3_2_manifest_naming_files_outside_deletes_nothing(ctx):
    path = ctx.study("manifest_outside", PENDULUM_STUDY)
    notes = path.parent / "notes.txt"
    notes.write_text("a week of notes")
    far = ctx.tmp / "far_file.txt"
    far.write_text("not ours")
    _manifest(ctx, path.parent, {"../notes.txt": [0], str(far): [1]})
    code, out, err = ctx.cli("run", path, "--no-plots", cwd=path.parent)
    assert code == 0, err[-2000:]
    assert notes.read_text() == "a week of notes" and far.read_text() == "not ours"
    assert "is not the name of a chunk a run writes: ignored" in out, out[-2000:]


@case("ok", "stabdae run")
def r3_2_manifest_chunk_that_is_a_fifo_does_not_hang(ctx):
    path = ctx.study("manifest_fifo", PENDULUM_STUDY)
    parts = _manifest(ctx, path.parent, {"chunk-0.npz": [0]})
    os.mkfifo(parts / "chunk-0.npz")
    code, out, err = ctx.cli("run", path, "--no-plots", cwd=path.parent, timeout=300)
    assert code == 0, err[-2000:]
    assert "is a FIFO, not a chunk a run writes" in out, out[-2000:]


@case("ok", "stabdae run")
def r3_3_study_edited_during_a_dask_run_is_not_mixed(ctx):
    """``seed`` edited after the first point of a --workers run: every point still has
    the first seed (the workers never read the study file)."""
    import xarray as xr

    body = _replace(PENDULUM_STUDY, "tau = [1e-3, 2e-3]", "tau = [1e-3, 2e-3, 4e-3, 5e-3]")
    path = ctx.study("dask_edit", body)
    environ = dict(os.environ, PYTHONPATH=str(ctx.src), STABDAE_FLUSH_SECONDS="0")
    proc = subprocess.Popen([sys.executable, "-c", CLI, "run", str(path), "--workers", "2",
                             "--no-plots", "--quiet"], cwd=path.parent, env=environ,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    parts = path.parent / "out.nc.parts"
    deadline = time.time() + 300
    while time.time() < deadline and proc.poll() is None and \
            not list(parts.glob("chunk-*.npz")):  # fmt: skip
        time.sleep(0.02)
    path.write_text(_replace(body, "seed = 1", "seed = 99"))
    out, err = proc.communicate(timeout=600)
    assert proc.returncode == 0, err[-2000:]
    with xr.open_dataset(path.parent / "out.nc") as ds:
        assert int(ds.attrs["seed"]) == 1, ds.attrs.get("seed")


@case("error", "consistent_state")
def r3_4_consistent_state_tol_nan(ctx):
    ctx.pendulum().consistent_state({"x": 0.3, "x_dot": 1.0}, tol=float("nan"))


@case("error", "consistent_state")
def r3_4_consistent_state_held_by_name_and_index(ctx):
    ctx.pendulum().consistent_state({"x": 0.3, 0: 0.4, "x_dot": 1.0})


@case("warn", "consistent_state")
def r3_4_consistent_state_at_a_singular_configuration(ctx):
    ctx.pendulum().consistent_state({"x": 1.0, "x_dot": 1.0})


_study_case("r3_5_seed_too_large", _replace(PENDULUM_STUDY, "seed = 1", f"seed = {2**64}"),
            who="[ensemble] seed")


@case("error", "stabdae run")
def r3_6_parts_folder_is_a_link(ctx):
    path = ctx.study("parts_link", PENDULUM_STUDY)
    target = ctx.tmp / "parts_link_target"
    target.mkdir(exist_ok=True)
    (path.parent / "out.nc.parts").symlink_to(target)
    code, out, err = ctx.cli("run", path, cwd=path.parent)
    assert not (path.parent / "out.nc").exists(), "computed before refusing"
    return _cli_outcome(code, out, err, "stabdae run", None, ctx, path)


@case("warn", "cache")
def r3_7_damaged_numba_cache_entry_of_the_library(ctx):
    cache = ctx.tmp / "numba_cache"
    environ = dict(os.environ, PYTHONPATH=str(ctx.src), NUMBA_CACHE_DIR=str(cache),
                   STABDAE_CACHE_DIR="off")  # fmt: skip
    script = ("import warnings, numpy as np\nwarnings.simplefilter('always')\n"
              "from stabdae import theory\n"
              "print(theory.power_norms(np.array([[0.5, 1.0], [0.0, 0.25]])))")

    def run():
        out = subprocess.run([sys.executable, "-c", script], env=environ, capture_output=True,
                             text=True, timeout=600)  # fmt: skip
        assert out.returncode == 0, out.stderr[-2000:]
        return out

    first = run().stdout
    entries = sorted(cache.rglob("theory.*.nbc"))
    assert entries
    for entry in entries:
        entry.write_bytes(b"stabdae kernel cache entry 2\n" + b"damaged")
    again = run()
    assert again.stdout == first
    said = [ln for ln in again.stderr.splitlines() if "stabdae:" in ln and "cache" in ln]
    assert said, again.stderr[-2000:]
    warnings.warn("cache: " + said[0][said[0].index("stabdae:"):], stacklevel=1)


@case("ok", "cache")
def r3_7_crafted_kernel_cache_index_runs_nothing(ctx):
    cache = ctx.tmp / "crafted_cache"
    environ = dict(os.environ, PYTHONPATH=str(ctx.src), STABDAE_CACHE_DIR=str(cache))
    script = ("import stabdae\nm = stabdae.load_model('pendulum')\n"
              "print(stabdae.integrate(m, None, stabdae.baumgarte(10.0), 'rk4', 1e-3, 0.05)"
              ".x.values[-1].tolist())")  # fmt: skip

    def run():
        out = subprocess.run([sys.executable, "-c", script], env=environ, capture_output=True,
                             text=True, timeout=600)  # fmt: skip
        assert out.returncode == 0, out.stderr[-2000:]
        return out.stdout

    first = run()
    mark = ctx.tmp / "crafted_ran"
    import pickle

    crafted = pickle.dumps(_Touch(str(mark)))
    indexes = sorted((cache / "kernels").glob("*.nbi"))
    assert indexes
    for index in indexes:
        index.write_bytes(crafted)
    assert run() == first
    assert not mark.exists(), "a crafted cache index ran code"


class _Touch:
    def __init__(self, path):
        self.path = path

    def __reduce__(self):
        return (os.system, (f"touch {self.path}",))


@case("error", "stabdae")
def r3_8_heap_corruption_away_from_the_reference_state(ctx):
    """A model writing just past ``out`` on the heap when q[0] > 0.5: the process dies
    (of glibc's abort or a fault) and says why and what to run."""
    path = ctx.model_file("heapwriter", _model_text(replace={
        "    out[1] = 9.81\n": "    out[1] = 9.81\n    if q[0] > 0.5:\n"
                              "        for j in range(2, 40):\n            out[j] = 1e300\n"}))
    script = ("import stabdae, sys, numpy as np\nm = stabdae.load_model(sys.argv[1])\n"
              "x0 = np.array([0.0, -1.0, 3.0, 0.0])\n"
              "stabdae.integrate(m, x0, stabdae.baumgarte(10.0), 'rk4', 1e-3, 1.0)\n")
    environ = dict(os.environ, PYTHONPATH=str(ctx.src))
    out = subprocess.run([sys.executable, "-c", script, str(path)], env=environ,
                         capture_output=True, text=True, timeout=600)  # fmt: skip
    assert out.returncode != 0, "the defective model ran to the end"
    said = [ln for ln in out.stderr.splitlines() if ln.startswith("stabdae:")]
    assert said and "NUMBA_BOUNDSCHECK=1" in out.stderr, out.stderr[-2000:]
    raise CliError(2, said[0][:300])


_study_case("r3_9_tableau_order_text", _replace(
    PENDULUM_STUDY, '[scheme]\nname = "rk2"',
    '[scheme]\nname = "mine"\nA = [[0.0, 0.0], [0.5, 0.0]]\nb = [0.0, 1.0]\nc = [0.0, 0.5]\n'
    'order = "two"'), who="[scheme] order")
_study_case("r3_9_output_path_nul", _replace(PENDULUM_STUDY, 'path = "out.nc"',
                                             'path = "a\\u0000b.nc"'), who="[output] path")
_study_case("r3_9_nested_500_deep", PENDULUM_STUDY + "[search]\nq = " + "[" * 500 + "1"
            + "]" * 500 + "\n", who="study.toml")


@case("error", "study.toml")
def r3_9_study_file_not_utf8(ctx):
    path = ctx.study("notutf8", PENDULUM_STUDY)
    path.write_bytes(path.read_bytes().replace(b"pendulum", b"pend\xffulum"))
    code, out, err = ctx.cli("run", path, cwd=path.parent)
    return _cli_outcome(code, out, err, "study.toml", None, ctx, path)


@case("ok", "stabdae integrate")
def r3_9_model_name_with_a_path_stays_in_results(ctx):
    path = ctx.model_file("escaped", _model_text(replace={
        'Model("probe_pendulum"': 'Model("../../escaped\\nline"'}))
    folder = ctx.tmp / "integrate_here"
    folder.mkdir(exist_ok=True)
    code, out, err = ctx.cli("integrate", path, "--t-end", "0.05", cwd=folder)
    assert code == 0, err[-2000:]
    written = [p for p in folder.rglob("*.nc")]
    assert written and all(p.parent == folder / "results" for p in written), written
    assert not [p for p in ctx.tmp.rglob("*line_trajectory.nc")
                if p.parent != folder / "results"]  # fmt: skip


for _label, _fn in [
    ("integrate_tau_1e-300", lambda ctx: ctx.stabdae.integrate(
        ctx.pendulum(), None, ctx.law(), "rk2", 1e-300, 1.0)),
    ("baumgarte_k_without_h", lambda ctx: ctx.stabdae.integrate(
        ctx.pendulum(), None, ctx.stabdae.baumgarte(10.0, k=5.0), "rk2", 1e-2, 0.1)),
    ("tableau_order_2.9", lambda ctx: ctx.stabdae._schemes.from_tableau(
        {"A": [[0, 0], [1, 0]], "b": [0.5, 0.5], "c": [0, 1], "order": 2.9}, name="mine")),
    ("param_name_300_characters", lambda ctx: ctx.pendulum().replace(params={"g" * 300: 1.0})),
    ("check_rtol_negative", lambda ctx: ctx.pendulum().check(rtol=-1.0)),
    ("consistent_state_complex", lambda ctx: ctx.pendulum().consistent_state(
        {"x": 0.3 + 1j, "x_dot": 1.0})),
]:
    _fn.__name__ = f"r3_9_{_label}"
    case("error", {"integrate_tau_1e-300": "integrate", "baumgarte_k_without_h": "baumgarte",
                   "tableau_order_2.9": "mine", "param_name_300_characters": "pendulum",
                   "check_rtol_negative": "check",
                   "consistent_state_complex": "consistent_state"}[_label])(_fn)


@case("error", "stabdae run")
def r3_9_run_threads_negative(ctx):
    path = ctx.study("threads", PENDULUM_STUDY)
    start = time.perf_counter()
    code, out, err = ctx.cli("run", path, "--threads", "-2", cwd=path.parent)
    assert time.perf_counter() - start < 20, "refused only after compiling"
    assert "--threads" in err, err[-1500:]
    return _cli_outcome(code, out, err, "stabdae run", None, ctx, path)
