"""The right-hand side's buffers follow one declaration on the heap and on the stack;
generated source is visible and can be dumped."""

from __future__ import annotations

import inspect

import numpy as np
import pytest
from numba import literal_unroll, njit

import stabdae
from conftest import compiled_only, load_scene
from stabdae._laws import bind_law
from stabdae.engine.rhs import kernels_for
from stabdae.engine.workspace import KINEMATIC, LAYOUT, shapes


# ---------------------------------------------------------------- the named workspace
@compiled_only
@pytest.mark.parametrize("name", ["pendulum", "rolling_disk", "heavy_top"])
def test_heap_and_stack_workspaces_follow_one_declaration(name):
    """The heap and stack workspaces of a model have the buffers of the declaration, by
    name, with its shapes; the kinematic map's only where a model declares one."""
    model = load_scene(name)
    K = kernels_for(model, bind_law(stabdae.none(), model))
    heap = K.make_workspace()
    expect = shapes(model.n, model.m, model.k, model.kinematic)
    layout = LAYOUT + (KINEMATIC if model.kinematic else ())
    assert model.kinematic == (name == "heavy_top")
    assert list(heap._fields) == [n for n, _, _ in layout]
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
def test_generated_source_is_visible_and_can_be_dumped(tmp_path, monkeypatch):
    """Source the library generates (here the adaptive ensemble's attempted step of
    DOP853, for the pendulum's 2n = 4) is registered with linecache (inspect shows it),
    and STABDAE_DUMP_SOURCE writes it to a file."""
    from stabdae._schemes import embedded_pair
    from stabdae.engine.rk.adaptive import _attempt_source, _pattern, attempt_for

    monkeypatch.setenv("STABDAE_DUMP_SOURCE", str(tmp_path))
    ep = embedded_pair("dop853")
    s, s_e = ep.scheme.stages, ep.error.shape[1]
    source = _attempt_source(s, s_e, ep.combined, _pattern(ep), 4)
    step = attempt_for(lambda *a: 0, s, s_e, ep.combined, _pattern(ep), 4, 2)
    dumped = [p.read_text() for p in tmp_path.glob("adaptive_attempt_*.py")]
    assert source in dumped
    assert inspect.getsource(step.py_func) == source
    assert inspect.getsourcefile(step.py_func).startswith("<stabdae generated adaptive_attempt")
