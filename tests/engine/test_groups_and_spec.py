"""The compiled floor's interfaces: the measurement record declared by name and kind, the
ensemble kernels' named argument groups, and the compile spec that is both the memo key
and the on-disk key."""

from __future__ import annotations

import ast
import dataclasses
import inspect

import numpy as np
import pytest
from numba import njit

import stabdae
from conftest import load_scene
from stabdae._laws import bind_law
from stabdae._schemes import embedded_pair
from stabdae.engine import decay
from stabdae.engine.cache import Spec, memo
from stabdae.engine.decay.record import COLUMNS, FLOATS, INTEGERS, Record
from stabdae.engine.ensemble import block, groups, lanes


# ---------------------------------------------------------------- the record
def test_record_columns_by_name_and_kind():
    """Every column is in exactly one of the two arrays, by its declared kind; codes,
    counts and flags are integers (never floats); a name reads its own column."""
    assert set(FLOATS) | set(INTEGERS) == {name for name, _ in COLUMNS}
    assert not set(FLOATS) & set(INTEGERS)
    assert {"reason", "fit_kind", "fit_points", "floor_reached"} == set(INTEGERS)
    rec = Record.empty(3)
    assert rec.values.dtype == np.float64 and rec.codes.dtype == np.int64
    assert rec.values.shape == (3, len(FLOATS)) and rec.codes.shape == (3, len(INTEGERS))
    rec.values[:] = np.arange(len(FLOATS))
    rec.codes[:] = 100 + np.arange(len(INTEGERS))
    for i, name in enumerate(FLOATS):
        assert (rec[name] == i).all()
    for i, name in enumerate(INTEGERS):
        assert (rec[name] == 100 + i).all() and rec[name].dtype == np.int64
    rec["beta"][1] = -7.0  # a view: the kernels' array is written
    assert rec.values[1, decay.C_BETA] == -7.0
    with pytest.raises(KeyError, match="no measured column 'bta'.*beta"):
        rec["bta"]


def test_measure_traces_writes_integer_codes():
    """The estimator's codes come back as integers in the record's code array: a member
    that stops has reason 'stopped' and no fit points; a decaying one is fitted."""
    t = np.linspace(0.0, 1.0, 200)
    decaying = 1e-3 * np.exp(-20.0 * t) + 1e-15
    stopped = decaying.copy()
    stopped[50:] = np.nan
    rec = decay.measure_traces(np.stack([decaying, stopped]), t)
    assert list(rec["reason"]) == [decay.R_FITTED, decay.R_STOPPED]
    assert rec["fit_points"][0] >= decay.MIN_POINTS and rec["fit_points"][1] == 0
    assert rec["fit_kind"][1] == decay.K_NONE


# ---------------------------------------------------------------- named groups
def _positionals(fn) -> int:
    return len(inspect.signature(getattr(fn, "py_func", fn)).parameters)


def test_ensemble_kernels_take_named_groups():
    """Both ensemble kernels take five named groups and the range of work items, not two
    dozen positionals."""
    model = load_scene("pendulum")
    bound = bind_law(stabdae.baumgarte(10.0, 1.0), model)
    fixed = block.ensemble_kernel_for(model, bound, stabdae.midpoint(), 8)
    pair = embedded_pair("dopri5")
    adaptive = lanes.adaptive_block_for(model, bound, pair, 4)
    for kernel in (fixed, adaptive):
        names = list(inspect.signature(kernel.py_func).parameters)
        assert names[:5] == ["inputs", "grid", "tableau", "measure", "out"]
        assert _positionals(kernel) == 7


def test_group_constructors_fix_the_field_types():
    """A caller's int for a float (``t0 = 0``) gives the same field types as the float, so
    that it does not compile a second kernel."""
    from numba import typeof

    a = groups.FixedGrid.of(0, 1, 5, 1)
    b = groups.FixedGrid.of(0.0, 1.0, np.int32(5), np.int64(1))
    assert typeof(a) == typeof(b)
    t = groups.AdaptiveGrid.of(0, [1, 2], 1, 1, 1, 10)
    assert typeof(t) == typeof(groups.AdaptiveGrid.of(0.0, np.array([1.0, 2.0]), 1.0, 1e-8,
                                                      1e-8, 10))  # fmt: skip


def test_the_floors_above_read_the_record_by_name():
    """No module above the compiled floor indexes the record by a column constant."""
    src = inspect.getfile(stabdae).rsplit("/", 1)[0]
    import pathlib

    for path in pathlib.Path(src).rglob("*.py"):
        if "engine" in path.parts:
            continue
        names = {n.attr for n in ast.walk(ast.parse(path.read_text()))
                 if isinstance(n, ast.Attribute)}  # fmt: skip
        assert not {n for n in names if n.startswith(("C_", "I_")) or n == "NCOLS"}, path


# ---------------------------------------------------------------- the compile spec
def _law(t, q, v, p, out):  # a user's law function, with a source file
    out[0, 0] = -1.0


def test_spec_is_the_memo_key_and_the_disk_key():
    """Equal specs are one memo entry and one disk key; a spec that differs in any field
    is another entry and another key; the law function is keyed by its fingerprint
    (source), not its identity, and a function without a source file is not cached."""
    base = Spec("block", law=0, pattern=((), (True,)), block=64, n_params=3,
                law_shape=(2, 2), pooled=1)  # fmt: skip

    class Holder:
        _kernel_cache: dict = {}

    built = []
    model = Holder()
    one = memo(model, base, lambda: built.append(1) or object())
    assert memo(model, dataclasses.replace(base), lambda: built.append(2)) is one
    assert built == [1]
    assert base.key("m") == dataclasses.replace(base).key("m")
    assert base.key("m") != base.key("other model") and base.key(None) is None
    for field in dataclasses.fields(Spec):
        value = getattr(base, field.name)
        if field.name == "law_fn":
            continue
        changed = {"kind": "lanes", "law": 1, "multiplier": "lstsq", "pattern": (),
                   "stages": (7, 7), "combined": True, "block": 8, "n_params": 4,
                   "law_shape": (1, 1), "pooled": -1, "sparse": True}[field.name]  # fmt: skip
        assert changed != value
        other = dataclasses.replace(base, **{field.name: changed})
        assert other != base and other.key("m") != base.key("m"), field.name
    # two compilations of one law function: two memo entries, one disk key
    law_a, law_b = njit(_law), njit(_law)
    spec_a, spec_b = (dataclasses.replace(base, law_fn=f) for f in (law_a, law_b))
    assert spec_a != spec_b and spec_a.key("m") == spec_b.key("m") != base.key("m")
    anonymous = eval("lambda t, q, v, p, out: None")  # no source file
    assert dataclasses.replace(base, law_fn=anonymous).key("m") is None


def test_ensemble_kernel_is_looked_up_once_per_run(monkeypatch):
    """``ensemble`` builds its run spec once: the kernel factory is asked once per run."""
    from stabdae import _ensemble

    calls = []
    real = _ensemble.ensemble_kernel_for
    monkeypatch.setattr(_ensemble, "ensemble_kernel_for",
                        lambda *a, **k: calls.append(1) or real(*a, **k))  # fmt: skip
    stabdae.ensemble(load_scene("pendulum"), stabdae.baumgarte(10.0, 1.0), "midpoint", 1e-3,
                     0.05, members=8, seed=1)  # fmt: skip
    assert len(calls) == 1


# ---------------------------------------------------------------- declared buffers
_ALLOCATORS = ("stack1", "stack2", "stack_int1", "np.empty", "np.zeros", "np.full",
               "ladders", "scratch", "map_buffers", "make_workspace", "K_make_workspace",
               "stack_workspace", "reference_logs")  # fmt: skip


def _allocations(module, factory: str) -> dict:
    """``{target: allocation}`` of every buffer the kernel built by ``factory`` allocates
    (its closures included)."""
    tree = ast.parse(inspect.getsource(module))
    fn = next(n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name == factory)
    out = {}
    for node in ast.walk(fn):
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call) \
                and ast.unparse(node.value.func) in _ALLOCATORS:  # fmt: skip
            target = ast.unparse(node.targets[0]).strip("()")
            call = ast.unparse(node.value)
            assert out.get(target, call) == call, (target, call)
            out[target] = call
    return out


@pytest.mark.parametrize("module, factory", [(block, "build_block_kernel"),
                                             (lanes, "_build_adaptive_block")])  # fmt: skip
def test_kernel_buffers_are_the_declared_ones(module, factory):
    """Each ensemble kernel allocates exactly the buffers its ``BUFFERS`` declares, each
    as declared: a buffer added, removed or resized without its declaration fails."""
    got = _allocations(module, factory)
    assert got == {name: alloc for name, (alloc, _) in module.BUFFERS.items()}
