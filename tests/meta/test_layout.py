"""The package's floors: no import circle, theory a leaf, the compiled floor importing
nothing above it, every module importable alone and listed, the trajectory tests
without the JIT."""

from __future__ import annotations

import ast
import importlib
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import stabdae
from conftest import ROOT

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
# a package's own name is no edge ("from . import vector_width" in its __init__)
_GRAPH = {_module_name(p): {m for m in _imports(p) if m in _MODULES and m != _module_name(p)}
          for p in SRC.rglob("*.py")}  # fmt: skip


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


def test_command_line_answers_without_the_numerical_stack():
    """``stabdae --version`` and ``--help`` import neither numba, NumPy, SciPy, xarray nor
    matplotlib: ``import stabdae`` loads its names on first use, and the command line
    imports what a command needs inside it."""
    script = (
        "import sys\n"
        "from stabdae.study.cli import main\n"
        "for argv in (['--version'], ['--help'], ['run', '--help']):\n"
        "    try:\n"
        "        main(argv)\n"
        "    except SystemExit:\n"
        "        pass\n"
        "heavy = {'numba', 'numpy', 'scipy', 'xarray', 'matplotlib', 'dask'}\n"
        "print('LOADED', sorted({m.split('.')[0] for m in sys.modules} & heavy))\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "stabdae " in proc.stdout and "usage: stabdae run" in proc.stdout
    assert proc.stdout.strip().splitlines()[-1] == "LOADED []", proc.stdout[-500:]


def test_public_names_load_on_first_use_after_the_engine_boots():
    """Every name of ``stabdae.__all__`` resolves (and is the object of its module); in a
    fresh process, a module imported first (not through ``stabdae.<name>``) still finds
    the compiled floor booted: the library's ``cache=True`` functions carry the checked
    cache, whichever module is imported first."""
    for name in stabdae.__all__:
        value = getattr(stabdae, name)
        assert value is not None and name in dir(stabdae), name
    assert stabdae.ensemble is importlib.import_module("stabdae._ensemble").ensemble
    with pytest.raises(AttributeError, match="no attribute 'not_a_name'"):
        stabdae.not_a_name  # noqa: B018
    for first in ("stabdae.simdmath", "stabdae.theory", "stabdae._model", "stabdae.rigid"):
        # (a model file imports stabdae.rigid first: numba's own cache format there, read
        # by the checked one on the next run, failed to unpickle)
        script = (f"import {first}, stabdae.simdmath as s, stabdae.rigid as r\n"
                  "print(type(s._reduce._cache).__name__, type(r.norm._cache).__name__)\n")
        proc = subprocess.run([sys.executable, "-c", script], capture_output=True,
                              text=True, timeout=600)  # fmt: skip
        assert proc.returncode == 0, proc.stderr[-3000:]
        assert proc.stdout.split() == ["_CheckedFunctionCache"] * 2, (first, proc.stdout)


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="already without JIT")
def test_trajectory_tests_pass_without_the_jit():
    """NUMBA_DISABLE_JIT=1: the library runs as Python (intrinsics have stand-ins), and the
    trajectory tests pass that way."""
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", STABDAE_CACHE_DIR="off")
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "tests/drivers/test_integrate.py"], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=900)  # fmt: skip
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    # the summary line, not a test's name ("..._failed_write_...") or a duration listing
    assert re.search(r"\b\d+ passed\b", proc.stdout), proc.stdout[-3000:]
    assert not re.search(r"\b\d+ (failed|errors?)\b", proc.stdout), proc.stdout[-3000:]


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
