"""The package's floors, its one validation module, its one dataset schema, its named
workspace and its debuggability (generated source, running without the JIT)."""

from __future__ import annotations

import ast
import importlib
import inspect
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from numba import literal_unroll, njit

import stabdae
from conftest import ROOT, assert_schema, compiled_only, load_scene
from stabdae import theory
from stabdae._laws import bind_law
from stabdae._schema import schema_markdown, udunits_ok
from stabdae.engine.ensemble.block import ensemble_kernel_for
from stabdae.engine.rhs import kernels_for
from stabdae.engine.rk.steps import _member_step_source, tableau_pattern
from stabdae.engine.workspace import LAYOUT, shapes

SRC = ROOT / "src" / "stabdae"


# ---------------------------------------------------------------- the floors
def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """Every stabdae module (and third-party top-level package) ``path`` imports, at module
    level or inside functions (``TYPE_CHECKING`` blocks left out: they never run)."""
    mod = _module_name(path)
    package = mod if path.name == "__init__.py" else mod.rsplit(".", 1)[0]
    tree = ast.parse(path.read_text())
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skip.update(id(n) for n in ast.walk(node))
    out = set()
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.Import):
            out.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0:
                base = node.module
            else:
                parts = package.split(".")
                parts = parts[: len(parts) - (node.level - 1)]
                base = ".".join(parts + ([node.module] if node.module else []))
            out.add(base)
            for alias in node.names:  # "from . import theory" imports a module
                if f"{base}.{alias.name}" in _MODULES:
                    out.add(f"{base}.{alias.name}")
    return out


_MODULES = {_module_name(p) for p in SRC.rglob("*.py")}
_GRAPH = {_module_name(p): {m for m in _imports(p) if m in _MODULES} for p in SRC.rglob("*.py")}


def test_no_import_circle():
    """The stabdae modules import each other without a cycle (packages' __init__ aside:
    the top-level one re-exports the API)."""
    graph = {m: {d for d in deps if d != "stabdae"} for m, deps in _GRAPH.items()
             if m != "stabdae"}  # fmt: skip
    state: dict[str, int] = {}

    def visit(m, path):
        if state.get(m) == 1:
            raise AssertionError("import circle: " + " -> ".join(path + [m]))
        if state.get(m) == 2:
            return
        state[m] = 1
        for d in sorted(graph.get(m, ())):
            visit(d, path + [m])
        state[m] = 2

    for m in sorted(graph):
        visit(m, [])


def _reachable(start: str) -> set[str]:
    seen, todo = set(), [start]
    while todo:
        m = todo.pop()
        for d in _GRAPH.get(m, ()):
            if d not in seen and d != "stabdae":
                seen.add(d)
                todo.append(d)
    return seen


def test_theory_is_a_leaf():
    """stabdae.theory computes on matrices: it reaches no driver, no study module and no
    kernel that integrates."""
    reached = _reachable("stabdae.theory")
    drivers = {"stabdae._integrate", "stabdae._adaptive", "stabdae._ensemble"}
    assert not reached & drivers, reached & drivers
    assert not any(m.startswith("stabdae.study") for m in reached), reached
    integrating = ("stabdae.engine.rk", "stabdae.engine.ensemble")
    assert not any(m.startswith(integrating) for m in reached), reached


def test_engine_floor_imports_nothing_above_it():
    """The compiled floor imports no xarray, no validation, no driver and no study module:
    only itself and the table of codes, not even for annotations."""
    for path in (SRC / "engine").rglob("*.py"):
        deps = _imports(path)
        assert "xarray" not in deps, path.name
        above = {d for d in deps if d in _MODULES and not d.startswith("stabdae.engine")}
        assert above <= {"stabdae._codes"}, (path.name, above)
        # annotation-only imports (skipped by _imports) would point upwards too
        assert "TYPE_CHECKING" not in path.read_text(), path.name


def test_each_module_imports_alone():
    """Every module imports on its own, first in a fresh package state (so that no module
    relies on another having been imported before it)."""
    script = (
        "import importlib, sys\n"
        f"for m in {sorted(_MODULES)!r}:\n"
        "    for k in [k for k in sys.modules if k == 'stabdae' or k.startswith('stabdae.')]:\n"
        "        del sys.modules[k]\n"
        "    importlib.import_module(m)\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]


# ---------------------------------------------------------------- argument errors
_PEND = None


def _pendulum():
    global _PEND
    if _PEND is None:
        _PEND = load_scene("pendulum")
    return _PEND


def _bad_calls():
    law = stabdae.baumgarte(10.0)
    m = _pendulum
    return [
        ("integrate", lambda: stabdae.integrate("pendulum", None, law)),
        ("integrate", lambda: stabdae.integrate(m(), None, None)),
        ("integrate", lambda: stabdae.integrate(m(), None, law, "rk9")),
        ("integrate", lambda: stabdae.integrate(m(), None, law, tau=-1.0)),
        ("integrate", lambda: stabdae.integrate(m(), None, law, tau=0.3, t_end=1.0)),
        ("integrate", lambda: stabdae.integrate(m(), None, law, save_dt=0.0015)),
        ("integrate", lambda: stabdae.integrate(m(), np.zeros(3), law)),
        ("integrate", lambda: stabdae.integrate(m(), None, law, params={"nope": 1.0})),
        ("integrate", lambda: stabdae.integrate(m(), None, law, multiplier="qr")),
        ("integrate", lambda: stabdae.integrate(m(), None, law, projection="half")),
        ("integrate", lambda: stabdae.integrate(m(), None, stabdae.matrix(np.zeros((2, 2))))),
        ("integrate", lambda: stabdae.integrate(m(), None, law, t_end="soon")),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), None, None)),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), None, law, rtol=0.0)),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), None, law, t_end=-1)),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), None, law,
                                                                  max_steps=0)),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), np.ones(5), law)),
        ("integrate_adaptive", lambda: stabdae.integrate_adaptive(m(), None, law,
                                                                  params=[1.0])),
        ("ensemble", lambda: stabdae.ensemble(m(), None)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, tau=0.0)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, members=0)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, radius=(1.0, 0.1))),
        ("ensemble", lambda: stabdae.ensemble(m(), law, seed=np.random.default_rng(1))),
        ("ensemble", lambda: stabdae.ensemble(m(), law, seed=-1)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, x0=np.zeros((2, 3)))),
        ("ensemble", lambda: stabdae.ensemble(m(), law, block=0)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, block=10**6)),  # past the stack
        ("ensemble", lambda: stabdae.ensemble(m(), law, threads=0)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, residual_dtype="float16")),
        ("ensemble", lambda: stabdae.ensemble(m(), law, epsilon=-1.0)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, "rk4", rtol=1e-6)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, atol=1e-6)),
        ("ensemble", lambda: stabdae.ensemble(m(), law, "nope")),
        ("ensemble", lambda: stabdae.ensemble(m(), law, params={"g": "x"})),
        ("ensemble", lambda: stabdae.ensemble(m(), law, progress=3)),
        ("sample_perturbations", lambda: stabdae.sample_perturbations(m(), 0)),
        ("sample_perturbations", lambda: stabdae.sample_perturbations(m(), 4, radius=-1.0)),
        ("sample_perturbations", lambda: stabdae.sample_perturbations(m(), 4, seed=1.5)),
        ("sample_perturbations", lambda: stabdae.sample_perturbations(m(), 4, threads=-2)),
        ("sample_perturbations", lambda: stabdae.sample_perturbations(m(), 4,
                                                                      params={"l": -np.inf})),
    ]  # fmt: skip


@pytest.mark.parametrize("index", range(len(_bad_calls())))
def test_every_argument_error_names_the_function_called(index):
    who, call = _bad_calls()[index]
    with pytest.raises((ValueError, TypeError)) as info:
        call()
    assert str(info.value).startswith(f"{who}: "), str(info.value)


def test_tau_limit_names_an_unknown_condition():
    with pytest.raises(ValueError, match=r"tau_limit: condition must be one of .*'spectral'"):
        theory.tau_limit(np.array([[-1.0]]), "euler", condition="spectal")


# ---------------------------------------------------------------- one schema
def test_udunits_check_accepts_units_and_refuses_prose():
    for good in ("1", "m", "m2", "m2 s-1", "m s-1", "s-1", "rad s-1", "J", "kg m^2",
                 "m/s", "m2 s-2"):  # fmt: skip
        assert udunits_ok(good), good
    for bad in ("", "model units", "mixed (see state_units)", "m2 per s", "meters"):
        assert not udunits_ok(bad), bad


def test_every_dataset_has_valid_units_history_and_one_time_format(tmp_path):
    """Trajectories (fixed and adaptive), ensembles (fixed and adaptive, with Theorem 5's
    columns), the theory over a study's grid and along a path: valid units or
    per-component units, a history, one created_at format; the pendulum's residual in m²
    and its velocity in m s-1."""
    from stabdae.study.spec import load_study
    from stabdae.study.theory import for_study

    pend = _pendulum()
    law = stabdae.baumgarte(10.0)
    traj = stabdae.integrate(pend, None, law, "rk4", 0.01, 0.2, 0.01)
    assert traj.residual.attrs.get("units_per_component") == "component_units"
    assert list(traj.component_units.values) == ["m2", "m2 s-1"]
    assert traj.attrs["history"].endswith("integrate: one trajectory (stabdae "
                                          f"{stabdae.__version__})")  # fmt: skip
    sleigh = load_scene("chaplygin_sleigh")
    datasets = [
        traj,
        stabdae.integrate_adaptive(pend, None, law, 0.2, rtol=1e-6, save_dt=0.1),
        stabdae.integrate(pend, None, law, "rk4", 0.01, 0.2, 0.1, with_multipliers=True),
        stabdae.ensemble(pend, law, "midpoint", 0.01, 0.2, members=8),
        stabdae.ensemble(pend, law, tau=0.01, t_end=0.2, rtol=1e-6, members=4),
        stabdae.ensemble(sleigh, stabdae.theorem5(2.0), "rk4", 0.01, 0.2, members=4),
        theory.along_path(pend, law, "euler", stabdae.integrate(pend, None, law, "euler",
                                                                0.01, 0.2, 0.01)),  # fmt: skip
    ]
    study = tmp_path / "s.toml"
    study.write_text('[model]\nfile = "pendulum"\n[law]\nkind = "baumgarte"\nomega = 10.0\n'
                     '[run]\nt_end = 0.2\ntau = 0.01\n[sweep]\ntau = [0.01, 0.02]\n')  # fmt: skip
    datasets.append(for_study(load_study(study)))
    for ds in datasets:
        assert_schema(ds)
    ens = datasets[3]
    assert ens.residual_norm.attrs["units_per_component"] == "component_units"
    assert ens.beta.attrs["units"] == "s-1"
    # a model whose constraints share one unit: the norms carry it
    sl = datasets[5]
    assert sl.residual_norm.attrs["units"] == "m s-1" and sl.gamma.attrs["units"] == "m s-1"


def test_schema_page_is_generated_from_the_schema():
    page = (ROOT / "docs" / "schema.md").read_text()
    assert page == schema_markdown(), (
        "docs/schema.md is stale: regenerate it with python -c \"from stabdae._schema import "
        "schema_markdown; open('docs/schema.md', 'w').write(schema_markdown())\""
    )


# ---------------------------------------------------------------- the ensemble's summary
def test_ensemble_warns_once_with_the_stopped_members_by_reason():
    """Euler at τω = 2.5 diverges: one warning counts the stopped members by reason."""
    pend = _pendulum()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = stabdae.ensemble(pend, stabdae.baumgarte(100.0), "euler", 0.025, 2.0, members=16,
                              radius=(1e-4, 1e-3))  # fmt: skip
    stopped = [w for w in caught if issubclass(w.category, stabdae.IntegrationWarning)]
    assert len(stopped) == 1
    n = int((ds.status.values != 0).sum())
    assert n == 16
    assert f"16 of 16 members stopped: {n} diverged" in str(stopped[0].message)
    assert stopped[0].filename == __file__  # points at the caller
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a run where every member finishes is silent
        stabdae.ensemble(pend, stabdae.baumgarte(10.0), "midpoint", 0.01, 0.2, members=8)


# ---------------------------------------------------------------- the named workspace
@compiled_only
@pytest.mark.parametrize("name", ["pendulum", "rolling_disk"])
def test_heap_and_stack_workspaces_follow_one_declaration(name):
    """The heap and stack workspaces of a model have the buffers of the declaration, by
    name, with its shapes."""
    model = load_scene(name)
    K = kernels_for(model, bind_law(stabdae.none(), model))
    heap = K.make_workspace()
    expect = shapes(model.n, model.m, model.k)
    assert list(heap._fields) == [n for n, _, _ in LAYOUT]
    assert {f: getattr(heap, f).shape for f in heap._fields} == expect
    stack_workspace = K.stack_workspace

    @njit
    def stack_sizes():
        ws = stack_workspace()
        sizes, ndims = [], []
        for a in literal_unroll(ws):
            sizes.append(a.size)
            ndims.append(a.ndim)
        return sizes, ndims

    sizes, ndims = stack_sizes()
    assert list(sizes) == [int(np.prod(s)) for s in expect.values()]
    assert list(ndims) == [len(s) for s in expect.values()]


# ---------------------------------------------------------------- generated source
def test_generated_member_step_is_visible_and_can_be_dumped(tmp_path, monkeypatch):
    """The member step's generated source is registered with linecache (inspect shows it),
    and STABDAE_DUMP_SOURCE writes it to a file."""
    monkeypatch.setenv("STABDAE_DUMP_SOURCE", str(tmp_path))
    model = load_scene("pendulum")
    scheme = stabdae.two_stage(0.25, 2.0)  # every weight and stage coefficient 'other'
    ensemble_kernel_for(model, bind_law(stabdae.baumgarte(10.0), model), scheme, 8)
    source = _member_step_source(tableau_pattern(scheme), 4)  # the pendulum's 2n = 4
    dumped = [p.read_text() for p in tmp_path.glob("member_step_*.py")]
    assert source in dumped
    from stabdae.engine.rk.steps import _member_step

    step = _member_step(lambda *a: 0, 4, 2, tableau_pattern(scheme))
    assert inspect.getsource(step.py_func) == source
    assert inspect.getsourcefile(step.py_func).startswith("<stabdae generated member_step")


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="already without JIT")
def test_trajectory_tests_pass_without_the_jit():
    """NUMBA_DISABLE_JIT=1: the library runs as Python (intrinsics have stand-ins), and the
    trajectory tests pass that way."""
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", STABDAE_CACHE_DIR="off")
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "tests/test_integrate.py"], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=900)  # fmt: skip
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    assert " passed" in proc.stdout and "failed" not in proc.stdout


def test_engine_init_and_architecture_list_every_module():
    """A contributor finds every room of the compiled floor from its ``__init__`` and from
    the architecture page: a module added, moved or removed without them fails here."""
    engine = SRC / "engine"
    modules = sorted(".".join(p.relative_to(engine).with_suffix("").parts)
                     for p in engine.rglob("*.py") if p.name != "__init__.py")  # fmt: skip
    listed = importlib.import_module("stabdae.engine").__doc__
    page = (ROOT / "docs" / "architecture.md").read_text()
    for mod in modules:
        assert f":mod:`.{mod}`" in listed, f"stabdae.engine's docstring does not list {mod}"
        assert f"`{mod}`" in page, f"docs/architecture.md does not list engine.{mod}"
