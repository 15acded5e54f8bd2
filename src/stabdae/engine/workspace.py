"""The buffers of one right-hand-side evaluation, declared once by name.

:data:`LAYOUT` lists every buffer of :mod:`.rhs` with its shape in the model's sizes and
what it holds.  From it :func:`builders` generates two compiled constructors of the same
named tuple :class:`Workspace`: ``make_workspace()`` allocates on the heap (one
trajectory, the sampler, the adaptive loop; once per integration), ``stack_workspace()``
on the stack (the ensemble kernel, once per member slot of a block, so that LLVM keeps the
buffers in registers).  The right-hand side reads the buffers by name (``ws.S``), so both
constructors and every reader follow the one declaration.

Sizes: ``n`` coordinates, ``m`` holonomic and ``k`` nonholonomic constraints,
``r = m + k``, ``ng = 2m + k`` residual components; ``mk = max(m, 1)`` and
``kk = max(k, 1)``, so that the buffers of an absent block keep a harmless size 1.  A
model with a kinematic map ``q̇ = T(q, t) v`` has the buffers of :data:`KINEMATIC` too,
in a :class:`KinematicWorkspace` (a model without one compiles no trace of them).

:func:`stack1`, :func:`stack2` and :func:`stack_int1` give arrays on the stack of the
function that calls them (inline that function at the numba IR level, as
``stack_workspace`` is); with ``NUMBA_DISABLE_JIT=1`` they are ``numpy.empty``.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import config, njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from .jit import internal
from .source import exec_source

__all__ = ["KINEMATIC", "LAYOUT", "KinematicWorkspace", "Workspace", "builders", "copy_inputs",
           "copy_tableau", "sizes", "stack1", "stack2", "stack_int1"]

#: (name, shape in the sizes of :func:`sizes`, what it holds)
LAYOUT = (
    ("q", ("n",), "positions q"),
    ("v", ("n",), "velocities v"),
    ("M", ("n", "n"), "mass matrix, then its L D Lᵀ factor"),
    ("z", ("n",), "γ, then z = M⁻¹γ"),
    ("fq", ("mk", "n"), "f_q"),
    ("hv", ("kk", "n"), "h_v"),
    ("hq", ("kk", "n"), "h_q"),
    ("Y", ("n", "r"), "Y = M⁻¹Fᵀ"),
    ("S", ("r", "r"), "S = F M⁻¹ Fᵀ, then its L D Lᵀ factor"),
    ("rl", ("r",), "right side of (3.11), then λ"),
    ("g", ("ng",), "residual g = (f, ḟ, h)"),
    ("sm", ("mk",), "size m: f, f_t, f_accel; the projection's position right side"),
    ("sk", ("kk",), "size k: h, h_t"),
    ("Aw", ("r", "ng"), "A of a user law A(t, x, p, out)"),
    ("W", ("kk", "kk"), "W = h_v h_vᵀ (Theorem 5)"),
    ("Lh", ("kk",), "L h (Theorem 5)"),
    ("V", ("r", "r"), "eigenvectors of S (least-squares multiplier)"),
    ("ev", ("r",), "eigenvalues of S (least-squares multiplier)"),
    ("mu", ("r",), "size r: the correction's and the projection's velocity right side; "
     "the least-squares multiplier's scratch"),
)  # fmt: skip
#: the buffers of a model with a kinematic map, after :data:`LAYOUT`'s
KINEMATIC = (
    ("T", ("n", "n"), "the kinematic map T(q, t) of q̇ = T v"),
    ("fr", ("mk", "n"), "∂f/∂q as the model writes it, before F's rows f_q T"),
    ("qd", ("n",), "q̇ = T v"),
)

Workspace = namedtuple("Workspace", [name for name, _, _ in LAYOUT])
Workspace.__doc__ = "The named buffers of :data:`LAYOUT` (heap or stack arrays)."
KinematicWorkspace = namedtuple("KinematicWorkspace",
                                [name for name, _, _ in LAYOUT + KINEMATIC])
KinematicWorkspace.__doc__ = "The buffers of :data:`LAYOUT` and :data:`KINEMATIC`."


def sizes(n: int, m: int, k: int) -> dict:
    """The sizes :data:`LAYOUT` is written in."""
    return {"n": n, "m": m, "k": k, "r": m + k, "ng": 2 * m + k, "mk": max(m, 1),
            "kk": max(k, 1)}  # fmt: skip


def shapes(n: int, m: int, k: int, kinematic: bool = False) -> dict:
    """``name -> shape`` of every buffer for a model of sizes ``n, m, k`` (and a
    kinematic map: ``kinematic``)."""
    dim = sizes(n, m, k)
    layout = LAYOUT + (KINEMATIC if kinematic else ())
    return {name: tuple(dim[d] for d in shape) for name, shape, _ in layout}


def _builder_source(n: int, m: int, k: int, kinematic: bool) -> str:
    heap, stack = [], []
    for shape in shapes(n, m, k, kinematic).values():
        heap.append(f"np.empty({shape})")
        stack.append(f"stack{len(shape)}({', '.join(map(str, shape))})")
    cls = "KinematicWorkspace" if kinematic else "Workspace"
    return (
        "def make_workspace():\n"
        f"    return {cls}({', '.join(heap)})\n\n"
        "def stack_workspace():\n"
        f"    return {cls}({', '.join(stack)})\n"
    )


def builders(n: int, m: int, k: int, kinematic: bool = False):
    """``(make_workspace, stack_workspace)`` for a model of sizes ``n, m, k`` (with a
    kinematic map: ``kinematic``): compiled
    constructors of :class:`Workspace` with heap and with stack arrays, generated from
    :data:`LAYOUT`.  ``stack_workspace`` is inlined at the numba IR level (its stack
    buffers belong to the caller)."""
    ns = exec_source(_builder_source(n, m, k, kinematic),
                     f"workspace_n{n}_m{m}_k{k}" + ("_T" if kinematic else ""),
                     {"np": np, "Workspace": Workspace,
                      "KinematicWorkspace": KinematicWorkspace, "stack1": stack1,
                      "stack2": stack2})  # fmt: skip
    return (internal(error_model="numpy")(ns["make_workspace"]),
            njit(inline="always")(ns["stack_workspace"]))  # fmt: skip


# --------------------------------------------------------------------- stack arrays
def _stack_array(context, builder, shape, dtype=types.float64):
    arrty = types.Array(dtype, len(shape), "C")
    ary = context.make_array(arrty)(context, builder)
    size = 1
    for s in shape:
        size *= s
    # alloca_once puts the buffer in the entry block of the function being compiled: one
    # buffer per call site, reused by every iteration of the loop around it.
    data = cgutils.alloca_once(builder, context.get_value_type(dtype), size=max(size, 1))
    # aligned to a cache line: the member loops' vector loads and stores then never
    # straddle two lines (8-byte alignment made every other 64-byte access a split)
    data.align = 64
    item = context.get_abi_sizeof(context.get_value_type(dtype))
    intp = lambda v: context.get_constant(types.intp, v)  # noqa: E731
    strides, acc = [], item
    for s in reversed(shape):
        strides.insert(0, intp(acc))
        acc *= s
    context.populate_array(ary, data=data, shape=[intp(s) for s in shape], strides=strides,
                           itemsize=intp(item), meminfo=None)  # fmt: skip
    return ary._getvalue()


def _literal_shape(*dims):
    if not all(isinstance(d, types.IntegerLiteral) for d in dims):
        return None
    return tuple(d.literal_value for d in dims)


@intrinsic
def _stack1(typingctx, n):
    shape = _literal_shape(n)
    if shape is None:
        return None

    def codegen(context, builder, sig, args):
        return _stack_array(context, builder, shape)

    return types.Array(types.float64, 1, "C")(n), codegen


@intrinsic
def _stack2(typingctx, n0, n1):
    shape = _literal_shape(n0, n1)
    if shape is None:
        return None

    def codegen(context, builder, sig, args):
        return _stack_array(context, builder, shape)

    return types.Array(types.float64, 2, "C")(n0, n1), codegen


@intrinsic
def _stack_int1(typingctx, n):
    shape = _literal_shape(n)
    if shape is None:
        return None

    def codegen(context, builder, sig, args):
        return _stack_array(context, builder, shape, types.int64)

    return types.Array(types.int64, 1, "C")(n), codegen


def _empty1(n):
    return np.empty(n)


def _empty2(n0, n1):
    return np.empty((n0, n1))


def _empty_int1(n):
    return np.empty(n, dtype=np.int64)


if config.DISABLE_JIT:  # intrinsics cannot run as Python: plain heap arrays instead
    stack1, stack2, stack_int1 = _empty1, _empty2, _empty_int1
else:
    stack1, stack2, stack_int1 = _stack1, _stack2, _stack_int1
stack1.__doc__ = """A float64 array of compile-time length ``n`` on the stack (no meminfo,
no NRT), valid only inside the function that calls it."""
stack2.__doc__ = """A C-ordered float64 array of compile-time shape ``(n0, n1)`` on the
stack."""
stack_int1.__doc__ = """An int64 array of compile-time length ``n`` on the stack."""


@njit(cache=True, forceinline=True)
def copy_inputs(p, law_mat, law_scal, p_s, lm, ls):
    """Copy the ensemble kernels' small run-time inputs (parameters, the law's matrix and
    scalar) into the caller's stack arrays ``p_s``, ``lm``, ``ls``: the loops then read
    memory no store of theirs can touch (loads hoisted, no run-time alias checks)."""
    for i in range(min(p.shape[0], p_s.shape[0])):  # (the drivers pass exactly p_s's size)
        p_s[i] = p[i]
    for i in range(lm.shape[0]):
        for j in range(lm.shape[1]):
            lm[i, j] = law_mat[i, j]
    ls[0] = law_scal[0]


@njit(cache=True, forceinline=True)
def copy_tableau(tab_a, tab_b, tab_c, ta, tb, tc):
    """Copy a scheme's run-time tableau into the caller's stack arrays (as
    :func:`copy_inputs`, for the same reason)."""
    for i in range(tb.shape[0]):
        tb[i] = tab_b[i]
        tc[i] = tab_c[i]
        for j in range(tb.shape[0]):
            ta[i, j] = tab_a[i, j]
