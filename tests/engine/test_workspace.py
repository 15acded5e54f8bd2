"""The right-hand side's buffers follow one declaration on the heap and on the stack;
the generated member step is visible and can be dumped."""

from __future__ import annotations

import inspect

import numpy as np
import pytest
from numba import literal_unroll, njit

import stabdae
from conftest import compiled_only, load_scene
from stabdae._laws import bind_law
from stabdae.engine.ensemble.block import ensemble_kernel_for
from stabdae.engine.rhs import kernels_for
from stabdae.engine.rk.steps import _member_step_source, tableau_pattern
from stabdae.engine.workspace import LAYOUT, shapes


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
