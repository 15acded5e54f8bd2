"""Straight-line code compiled by :mod:`stabdae.engine.emit` against numba's compilation
of the same Python source: the same bits on values chosen to tell operations apart
(signed zeros, infinities, NaN, products that round differently fused), the same bits as
numba on every shipped model's functions, and a refusal, when the function is emitted, of
code outside the language it lowers."""

from __future__ import annotations

import ast
import math

import numpy as np
import pytest
from numba import njit

from stabdae import simdmath
from stabdae.engine.emit import emitted, emitted_source
from stabdae.engine.fma import fma
from stabdae.engine.jit import JIT

pytestmark = pytest.mark.skipif(not JIT, reason="lowers to LLVM IR: needs the JIT")

SCALE = 0.25  # a global number, frozen as numba freezes it

#: every construct of the language, in the forms the generators write
SOURCE = '''
def f(a, b, k, x):
    """A docstring is skipped."""
    s, t = a[0, 0], a[0, 1]
    u = b[0]
    s = fma(s, t, u)
    w = fnma(t, u, s)
    m = abs(a[1, 0])
    m = max(m, abs(u))
    m = min(m, x) + max(x, -2.0)
    q = 1.0 / w + k / 3 + 2 ** -1 * x - (3 - 1) ** 2 * 1e-3
    r = -q * t + m - u ** 2 + abs(t) ** 1.5 + SCALE * math.sqrt(abs(q))
    r *= 2.0
    r += simdmath.sin(t) * math.cos(u)
    bad = not (r > x)
    code = 0
    code += 3 * (bad & (code == 0))
    code += k
    b[1] = r
    a[1, 1] = q
    b[2] = w
    a[0, 0] = s
    return code
'''


def _fnma(a, b, c):
    return fma(-a, b, c)


def _fma2(a, b, c):
    return a * b + c


def _fnma2(a, b, c):
    return -a * b + c


def _pair(fused):
    """The emitted function and numba's compilation of the Python source."""
    names = {"fma": fma if fused else njit(_fma2), "SCALE": SCALE, "math": math,
             "simdmath": simdmath, "fnma": njit(_fnma) if fused else njit(_fnma2)}
    fn_def = ast.parse(SOURCE).body[0]
    special = {k: v for k, v in names.items() if k not in ("fma", "fnma")}
    intr = emitted(fn_def, special, "emit_test_" + ("fused" if fused else "unfused"),
                   fused=fused)  # fmt: skip
    ns = {"_emitted": intr}
    exec("def g(a, b, k, x):\n    return _emitted(a, b, k, x)\n", ns)
    exec(SOURCE, names)
    return njit(error_model="numpy")(ns["g"]), njit(error_model="numpy")(names["f"])


SPECIAL = [0.0, -0.0, 1.0, -1.5, 1e-300, 3.0e300, np.inf, -np.inf, np.nan, 1.0 + 2**-52,
           1.0 / 3.0]


def _bits(a) -> bytes:
    """``a``'s bytes with every NaN the same NaN.  Which of two NaN operands an x86
    addition returns (and so the result's sign) depends on their order, which LLVM may
    commute, and does differently from one build to another (numba's code and the emitted
    code returned NaNs of opposite signs for ``q`` below in one environment of the
    development machine, the same NaN in an earlier one)."""
    return np.where(np.isnan(a), np.nan, a).tobytes()


@pytest.mark.parametrize("fused", [True, False])
def test_emitted_code_gives_numbas_bits(fused):
    """The same bits, signed zeros included; NaN as NaN (:func:`_bits`)."""
    emitted_fn, numba_fn = _pair(fused)
    rng = np.random.default_rng(7)
    for trial in range(400):
        values = rng.choice(SPECIAL, 6) if trial % 2 else rng.standard_normal(6) * 10
        a = np.array([[values[0], values[1]], [values[2], 5.0]])
        b = np.array([values[3], 7.0, 8.0])
        x = float(values[4])
        k = int(trial % 5)
        a1, b1, a2, b2 = a.copy(), b.copy(), a.copy(), b.copy()
        assert emitted_fn(a1, b1, k, x) == numba_fn(a2, b2, k, x)
        assert _bits(a1) == _bits(a2) and _bits(b1) == _bits(b2), (a, b, x)


def test_the_fused_form_rounds_once():
    """The comparison above can fail: ``fma(s, t, u)`` with ``s·t = 1 + 2e + e²`` and
    ``u = -(1 + 2e)`` keeps ``e²`` when it rounds once and loses it when it rounds twice."""
    e = 2.0**-30
    out = {}
    for fused in (True, False):
        fn, _ = _pair(fused)
        a = np.array([[1.0 + e, 1.0 + e], [0.0, 0.0]])
        b = np.array([-(1.0 + 2 * e), 0.0, 0.0])
        fn(a, b, 0, 0.0)
        out[fused] = a[0, 0]  # s
    assert out[True] == e * e
    assert out[False] == 0.0


@pytest.mark.parametrize("body", [
    "if x > 0.0:\n        x = 1.0",
    "for i in range(3):\n        x = x + 1.0",
    "x = a[k, 0]",
    "x = a[-1]",
    "x = a[1:, 0]",
    "x = np.sin(x)",
    "x = x if x > 0.0 else 0.0",
    "x = x > 0.0 and x < 1.0",
    "return x\n    x = 1.0",
    "y = g(x)",
    "y = x ** k",
    "a = x",
    "y = z\n    z = 1.0",
    "a[0] += x",
    "y = max(x, x, x)",
])
def test_code_outside_the_language_is_refused_when_emitted(body):
    fn_def = ast.parse(f"def f(a, k, x):\n    {body}\n").body[0]
    with pytest.raises(NotImplementedError):
        emitted(fn_def, {"np": np, "g": len}, "emit_test_refused")


def test_an_entry_of_a_matrix_needs_every_index():
    """``out[0]`` of a matrix is a row, not a number: refused when typed, with a message
    that names the array and says what to do."""
    fn_def = ast.parse("def f(a, out):\n    out[0] = a[1]\n").body[0]
    intr = emitted(fn_def, {}, "emit_test_row")
    ns = {"_emitted": intr}
    exec("def g(a, out):\n    return _emitted(a, out)\n", ns)
    with pytest.raises(Exception, match=r"out\[0\] of a 2-d array in f: give every index"):
        njit(ns["g"])(np.ones(3), np.zeros((2, 2)))


def test_a_function_with_free_variables_or_no_source_is_refused():
    """A model's function is compiled by numba as it is where its source cannot be read
    or it reads variables of an enclosing function (which numba freezes)."""
    c = 2.0

    def closure(x, out):
        out[0] = c * x

    with pytest.raises(NotImplementedError):
        emitted_source(closure, "emit_test_closure")
    ns: dict = {}
    exec("def made(x, out):\n    out[0] = x\n", ns)
    with pytest.raises(NotImplementedError):
        emitted_source(ns["made"], "emit_test_made")


@pytest.mark.parametrize("scene", ["double_pendulum", "car_axis", "knife_edge", "rolling_disk",
                                   "andrews"])  # fmt: skip
def test_shipped_models_functions_give_numbas_bits(scene):
    """What the kernels compile of a shipped model's functions (through the emitter: each
    is straight-line code) gives, at states around its reference, the bits of the model's
    own compiled functions (``Model.evaluate``), ``**``, ``math`` and ``simdmath`` calls
    and whole-array fills included."""
    import stabdae
    from stabdae.engine.jit import python_function

    model = stabdae.load_model(scene)
    p = model.default_params()
    rng = np.random.default_rng(5)
    pieces = dict(model.functions)
    if model.energy is not None:
        pieces["energy"] = model.energy
    for piece, fn in pieces.items():
        pyfunc = python_function(fn)
        intr = emitted_source(pyfunc, f"test_{scene}_{piece}")
        names = list(inspect_params(pyfunc))
        ns = {"_emitted": intr}
        exec(f"def g({', '.join(names)}):\n    return _emitted({', '.join(names)})\n", ns)
        compiled = njit(ns["g"])
        for _ in range(4):
            x = model.reference_state(p) + 0.3 * rng.standard_normal(2 * model.n)
            t = float(rng.uniform(0.0, 2.0))
            want = model.evaluate(piece, t, x, p)
            q, v = x[:model.n].copy(), x[model.n:].copy()
            args = (t, q, p) if names[2] == "p" else (t, q, v, p)
            if piece == "energy":
                got = compiled(*args)
                assert np.float64(got).tobytes() == np.float64(want).tobytes(), piece
            else:
                out = np.zeros_like(want)
                compiled(*args, out)
                assert out.tobytes() == want.tobytes(), (scene, piece)


def inspect_params(fn):
    import inspect

    return inspect.signature(fn).parameters


def test_checked_kernels_compile_the_models_functions_with_numba(monkeypatch):
    """NUMBA_BOUNDSCHECK=1 asks for kernels that check every index (to find a model's
    stray write): a model's straight-line functions then go to numba as they are."""
    import numba
    from numba.core.dispatcher import Dispatcher

    import stabdae
    from stabdae.engine.rhs import _rejit

    forces = stabdae.load_model("pendulum").functions["forces"]
    assert not isinstance(_rejit(forces, None), Dispatcher)  # the emitter's intrinsic
    monkeypatch.setattr(numba.config, "BOUNDSCHECK", 1)
    assert isinstance(_rejit(forces, None), Dispatcher)


def _long_sum(terms: int) -> str:
    """A function whose one expression is a sum of ``terms`` products, left to right, as
    ``stabdae generate`` writes an expanded model's: an AST ``terms`` deep."""
    body = " + ".join(f"{(-1) ** i * (i + 1) / 7:.17g} * x[{i % 3}] * x[{(i + 1) % 3}]"
                      for i in range(terms))  # fmt: skip
    return f"def f(x, out):\n    out[0] = {body} - 2.0 * 3.0\n    out[1] = -(-x[0])\n"


def test_an_expression_thousands_deep_is_emitted_at_the_default_recursion_limit():
    """A generated 14-coordinate bicycle (8752 operations, one expression of f_accel 4163
    long) raised RecursionError from every driver: the constant folding and the typing
    recursed once per operator.  Now the walks keep their own stacks: 2500 terms (Python's
    own parser stops near 3000 at the default limit) compile under Python's default
    recursion limit and give Python's own bits; a refusal inside such an expression says where
    without printing all of it."""
    import sys

    assert sys.getrecursionlimit() <= 1000 + 200  # as a user's process has it (pytest's)
    source = _long_sum(2500)
    fn_def = ast.parse(source).body[0]
    intr = emitted(fn_def, {}, "emit_test_deep")
    ns = {"_emitted": intr}
    exec("def g(x, out):\n    return _emitted(x, out)\n", ns)
    plain = {}
    exec(source, plain)
    got, want = np.zeros(2), np.zeros(2)
    x = np.array([0.3, -1.25, 2.0 / 3.0])
    njit(error_model="numpy")(ns["g"])(x, got)
    # Python's own float64 evaluation is the reference: the same operations in the same
    # order, unfused (numba's compilation of this source takes minutes)
    plain["f"](x, want)
    assert got.tobytes() == want.tobytes() and got[1] == x[0]

    refused = ast.parse(source.replace("x[2]", "x[2:3]", 1)).body[0]
    with pytest.raises(NotImplementedError) as info:
        emitted(refused, {}, "emit_test_deep_refused")
    assert len(str(info.value)) < 400 and "x[2:3]" in str(info.value)


def test_a_model_with_an_expression_thousands_deep_integrates(tmp_path):
    """The drivers on a model whose force is one expression 2500 operations deep: the
    pendulum's, with terms that cancel exactly left to right (``t - t + u - u + … + g``
    is ``g`` in floating point), so its trajectory is the pendulum's bit for bit."""
    import stabdae
    from stabdae._loading import scene_dir

    terms = " + ".join(f"{(i % 7 + 1) * 1e-3:.3g} * q[{i % 2}] * v[{(i + 1) % 2}] - "
                       f"{(i % 7 + 1) * 1e-3:.3g} * q[{i % 2}] * v[{(i + 1) % 2}]"
                       for i in range(1250))  # fmt: skip
    source = (scene_dir() / "pendulum.py").read_text()
    assert source.count("    out[1] = p[0]\n") == 1
    (tmp_path / "deep.py").write_text(source.replace("    out[1] = p[0]\n",
                                                     f"    out[1] = {terms} + p[0]\n"))
    deep, plain = stabdae.load_model(tmp_path / "deep.py"), stabdae.load_model("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    runs = [stabdae.integrate(m, law=law, scheme="midpoint", tau=1e-3, t_end=0.2)
            for m in (deep, plain)]  # fmt: skip
    assert runs[0]["x"].values.tobytes() == runs[1]["x"].values.tobytes()
