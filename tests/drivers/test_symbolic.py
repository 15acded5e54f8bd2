"""stabdae.symbolic: models generated from a sympy Lagrangian.

References: the hand-written scenes (every function, at random states, to 1e-12), the exact
residual law g(t) = expm(Ã t) g(0) (the paper's §3) for a system with no hand-written scene,
and the conical spherical pendulum's closed-form motion.
"""

from __future__ import annotations

import hashlib
import math
import re
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from test_residual_law import constant_laws, relative_law_error

import stabdae
from conftest import KERNELS, ROOT, load_file, load_scene
from stabdae.study.cli import main
from stabdae.symbolic import SymbolicError, System, coordinates, generate, load_spec

SPECS = KERNELS / "specs"
PIECES = ["mass", "forces", "f", "f_q", "f_t", "f_accel", "h", "h_q", "h_v", "h_t"]


def generated(tmp_path: Path, spec: Path) -> stabdae.Model:
    out = generate(spec, tmp_path / f"{spec.stem}_gen.py")
    return stabdae.load_model(out)


def piece_value(model: stabdae.Model, piece: str, t: float, x, p):
    """A piece's value; an absent mass is the identity, absent f_t/h_t zero."""
    if piece in model.functions:
        return np.asarray(model.evaluate(piece, t, x, p))
    if piece == "mass":
        return np.eye(model.n)
    if piece == "f_t" and model.m:
        return np.zeros(model.m)
    if piece == "h_t" and model.k:
        return np.zeros(model.k)
    return None


def largest_difference(a: stabdae.Model, b: stabdae.Model, states: int = 6, seed: int = 0):
    """max over pieces and random states of |a − b| / max(1, |b|), and the pieces compared."""
    assert a.param_names == b.param_names
    rng = np.random.default_rng(seed)
    p = b.default_params()
    worst, compared = 0.0, set()
    for _ in range(states):
        x = b.reference_state(p) + rng.standard_normal(2 * b.n)
        t = float(rng.uniform(0.0, 3.0))
        for piece in PIECES:
            va, vb = piece_value(a, piece, t, x, p), piece_value(b, piece, t, x, p)
            if vb is None:
                assert va is None, f"{piece} generated but absent from the hand-written scene"
                continue
            assert va.shape == vb.shape, piece
            worst = max(worst, float(np.max(np.abs(va - vb) / np.maximum(1.0, np.abs(vb)))))
            compared.add(piece)
        if b.energy is not None:
            ea, eb = a.energy(t, x[: a.n], x[a.n :], p), b.energy(t, x[: b.n], x[b.n :], p)
            worst = max(worst, abs(ea - eb) / max(1.0, abs(eb)))
            compared.add("energy")
    return worst, compared


@pytest.mark.parametrize("name", ["pendulum", "double_pendulum", "chaplygin_sleigh"])
def test_generated_equals_hand_written(tmp_path, name):
    model = generated(tmp_path, SPECS / f"{name}.py")
    hand = load_scene(name)
    worst, compared = largest_difference(model, hand)
    assert worst <= 1e-12, (name, worst)
    assert {"forces", "energy"} <= compared
    assert model.check().ok
    np.testing.assert_allclose(model.reference_state(), hand.reference_state(), atol=1e-15)


def test_comparison_can_fail(tmp_path):
    """A generated model that differs in one parameter's role is caught by the comparison."""
    (x, y), (xd, yd) = coordinates("x y")
    g, l = sp.symbols("g l")
    wrong = System(
        "pendulum_wrong", q=[x, y], v=[xd, yd],
        lagrangian=(xd**2 + yd**2) / 2 - 1.01 * g * y,  # gravity 1 % too strong
        holonomic=[x**2 + y**2 - l**2], params={g: 9.81, l: 1.0},
        reference_state=list(load_scene("pendulum").reference_state()),
    )  # fmt: skip
    model = stabdae.load_model(wrong.write(tmp_path / "wrong.py"))
    worst, _ = largest_difference(model, load_scene("pendulum"))
    assert worst > 1e-3


def test_time_dependent_constraint(tmp_path):
    """f_t and the time terms of f_accel: the varying-length pendulum, l(t) = l0(1 + ε sin Ωt)."""
    hand = load_scene("pendulum_varying_length")
    (x, y), (xd, yd) = coordinates("x y")
    g, l0, eps, om = sp.symbols("g l0 eps Omega")
    t = stabdae.symbolic.t
    length = l0 * (1 + eps * sp.sin(om * t))
    system = System(
        "varying_generated", q=[x, y], v=[xd, yd],
        lagrangian=(xd**2 + yd**2) / 2 - g * y,
        holonomic=[x**2 + y**2 - length**2],
        params={g: 9.81, l0: 1.0, eps: 0.1, om: 3.0},
        reference_state=[float(c) for c in hand.reference_state()], energy=False,
    )  # fmt: skip
    assert "f_t" in system.derive()
    model = stabdae.load_model(system.write(tmp_path / "varying.py"))
    worst, compared = largest_difference(model, hand)
    assert "f_t" in compared
    assert worst <= 1e-12
    assert model.check().ok


def test_spherical_pendulum_exact_residual_law(tmp_path):
    """No hand-written scene: generated, then the foundation issue's residual-law test."""
    model = generated(tmp_path, SPECS / "spherical_pendulum.py")
    assert (model.n, model.m, model.k) == (3, 1, 0)
    assert model.check().ok
    rng = np.random.default_rng(7)
    x0 = model.reference_state() + 1e-3 * rng.standard_normal(6)
    assert np.max(np.abs(model.residual(x0))) > 1e-5
    for law_name, law in constant_laws(model).items():
        err = relative_law_error(model, law, x0)
        assert err <= 1e-6, (law_name, err)


def test_spherical_pendulum_conical_motion(tmp_path):
    """Closed form: from the reference state the mass circles at Ω = √(g/(l cos θ0)) at
    constant height; RK4 at τ = 1e-3 over 2 s reproduces it to 1e-9."""
    model = generated(tmp_path, SPECS / "spherical_pendulum.py")
    p = model.default_params()
    g, l = p[1], p[2]
    theta0 = 0.5
    rate = math.sqrt(g / (l * math.cos(theta0)))
    ds = stabdae.integrate(model, model.reference_state(), stabdae.baumgarte(10.0, 1.0),
                           "rk4", 1e-3, 2.0, 0.1)  # fmt: skip
    t = ds.time.values
    q = ds["x"].values[:, :3]
    exact = np.stack([l * math.sin(theta0) * np.cos(rate * t),
                      l * math.sin(theta0) * np.sin(rate * t),
                      np.full_like(t, -l * math.cos(theta0))], axis=1)  # fmt: skip
    assert np.max(np.abs(q - exact)) < 1e-9


def test_committed_scene_is_fresh(tmp_path):
    """kernels/spherical_pendulum.py was generated from the spec as it is now."""
    spec = SPECS / "spherical_pendulum.py"
    text = (KERNELS / "spherical_pendulum.py").read_text()
    recorded = re.search(r"Spec SHA-256: ([0-9a-f]{16})", text).group(1)
    assert recorded == hashlib.sha256(spec.read_bytes()).hexdigest()[:16], (
        "regenerate: stabdae generate kernels/specs/spherical_pendulum.py "
        "-o kernels/spherical_pendulum.py"
    )
    worst, _ = largest_difference(load_scene("spherical_pendulum"), generated(tmp_path, spec))
    assert worst == 0.0


@pytest.mark.parametrize("spec", sorted(p.name for p in SPECS.glob("*.py")
                                         if "Spec SHA-256" in (KERNELS / p.name).read_text()))
def test_every_generated_scene_records_its_specs_current_hash(spec):
    """Each shipped generated scene was made from its spec as the spec is now (the hash
    only: regenerating every scene is the freshness test's job for one of them).  The
    hand-written scenes with a spec beside them have no hash and are compared with their
    specs elsewhere."""
    text = (KERNELS / spec).read_text()
    recorded = re.search(r"Spec SHA-256: ([0-9a-f]{16})", text).group(1)
    assert recorded == hashlib.sha256((SPECS / spec).read_bytes()).hexdigest()[:16], (
        f"regenerate: stabdae generate kernels/specs/{spec} -o kernels/{spec}")


@pytest.mark.parametrize("name", ["pendulum", "double_pendulum", "chaplygin_sleigh",
                                  "spherical_pendulum"])  # fmt: skip
def test_generated_file_is_readable(name):
    """A header saying how it was made, lines within 100 characters, no leftover symbols."""
    system = load_spec(SPECS / f"{name}.py")
    text = system.source(SPECS / f"{name}.py")
    compile(text, name, "exec")
    assert "Generated by `stabdae generate" in text and "Spec SHA-256" in text
    assert max(len(line) for line in text.splitlines()) <= 100
    assert "**2" not in text.split('"""', 2)[2]  # squares written as products
    assert text.count("@njit") == len(system.derive())


def spec_system(**overrides):
    (x, y), (xd, yd) = coordinates("x y")
    g, l = sp.symbols("g l")
    kw = dict(
        q=[x, y], v=[xd, yd], lagrangian=(xd**2 + yd**2) / 2 - g * y,
        holonomic=[x**2 + y**2 - l**2], params={g: 9.81, l: 1.0},
        reference_state=[0, -1, 1, 0],
    )  # fmt: skip
    kw.update(overrides)
    return System("bad", **kw)


def test_errors_name_the_piece_and_symbol():
    (x, y), (xd, yd) = coordinates("x y")
    k = sp.Symbol("k")
    with pytest.raises(SymbolicError, match=r"lagrangian uses 'k'"):
        spec_system(lagrangian=(xd**2 + yd**2) / 2 - k * y)
    with pytest.raises(SymbolicError, match=r"holonomic\[0\].*must not contain velocities.*"
                                            r"'x_dot'"):  # fmt: skip
        spec_system(holonomic=[x * xd])
    with pytest.raises(SymbolicError, match=r"reference_state must have 2n = 4 entries.* got 3"):
        spec_system(reference_state=[0, -1, 1])
    with pytest.raises(SymbolicError, match=r"reference_state\[1\] \(parameters only\) uses 'y'"):
        spec_system(reference_state=[0, y, 1, 0])
    with pytest.raises(SymbolicError, match=r"mass matrix .* depends on the velocities"):
        spec_system(lagrangian=(xd**2 + yd**2) / 2 + xd**4).derive()
    with pytest.raises(SymbolicError, match="no constraints"):
        spec_system(holonomic=[])
    with pytest.raises(SymbolicError, match="forces must have n = 2 entries, got 1"):
        spec_system(forces=[xd])


def test_nonconservative_forces_enter_gamma():
    """M v̇ = Fᵀλ − γ with γ = … − Q: a damping force −c v appears as +c v in γ."""
    (x, y), (xd, yd) = coordinates("x y")
    c = sp.Symbol("c")
    system = spec_system(forces=[-c * xd, -c * yd], params={sp.Symbol("g"): 9.81,
                                                            sp.Symbol("l"): 1.0, c: 0.3})
    gamma = system.derive()["forces"]
    assert sp.simplify(gamma[0] - c * xd) == 0
    assert sp.simplify(gamma[1] - (sp.Symbol("g") + c * yd)) == 0


@pytest.mark.parametrize("expand", [True, False])
def test_derived_pieces_match_their_definitions(expand):
    """γ, f_accel and the energy, derived as derivatives along the motion, against their
    definitions written out with full Jacobians: γ = (∂²L/∂v∂q) v + ∂²L/∂v∂t − ∂L/∂q − Q,
    f_accel = (∂ḟ/∂q) v + ∂ḟ/∂t with ḟ = f_q v + f_t, and E = vᵀ ∂L/∂v − L.  The system
    has time in its mass, its velocity terms and its constraint, and a non-conservative
    force, so every term of each definition is there; compared at random states."""
    (x, y, z), (xd, yd, zd) = coordinates("x y z")
    a, b, c, g = sp.symbols("a b c g")
    tt = stabdae.symbolic.t
    lagrangian = ((1 + a * sp.sin(tt) * x**2) * xd**2 / 2 + (yd**2 + zd**2) / 2
                  + b * sp.cos(tt) * (x * yd - y * xd) * sp.exp(z) - g * z)  # fmt: skip
    holonomic = [sp.sqrt(x**2 + y**2 + 1) * sp.cos(z + tt) - 1,
                 x * y * z - c * sp.sin(2 * tt)]  # fmt: skip
    system = System("along", q=[x, y, z], v=[xd, yd, zd], lagrangian=lagrangian,
                    holonomic=holonomic, forces=[-c * xd * yd, 0, sp.sin(tt) * zd],
                    params={a: 0.3, b: 0.7, c: 0.2, g: 9.81}, reference_state=[0] * 6,
                    simplify=False, expand=expand)  # fmt: skip
    q, v = sp.Matrix(system.q), sp.Matrix(system.v)
    p_v = sp.Matrix([lagrangian.diff(s) for s in v])
    f = sp.Matrix(holonomic)
    f_dot = f.jacobian(q) * v + f.diff(tt)
    definition = {
        "forces": p_v.jacobian(q) * v + p_v.diff(tt) - sp.Matrix([lagrangian.diff(s) for s in q])
        - system.Q,
        "f_accel": f_dot.jacobian(q) * v + f_dot.diff(tt),
        "energy": sp.Matrix([(v.T * p_v)[0, 0] - lagrangian]),
    }
    derived = system.derive()
    rng = np.random.default_rng(3)
    for _ in range(5):
        point = dict(zip([*q, *v, tt], rng.uniform(-1.0, 1.0, 7)))
        point.update(system.params)
        for piece, expected in definition.items():
            got = sp.Matrix([derived[piece]]) if piece == "energy" else derived[piece]
            for e_got, e_want in zip(got, expected):
                want = float(e_want.evalf(subs=point))
                assert abs(float(e_got.evalf(subs=point)) - want) <= 1e-12 * max(1.0, abs(want))


def test_kept_chain_f_accel_grows_linearly_with_the_links():
    """The tip constraint of a chain of N rods in its joint angles nests N sines and
    cosines in a square root; its second derivative along the motion needs a fixed number
    of operations per link.  Built from the full Jacobian (n partial derivatives, each
    dotted with v) it grew as N² (129, 264, 549 operations at 3, 5, 8 links)."""
    chain = load_file(ROOT / "studies" / "bench_generate.py", "stabdae_bench_generate").minimal
    ops = {}
    for links in (3, 8):
        system = chain(links, simplify=False, expand=False)
        system.source()
        ops[links] = system.operations["f_accel"]
    assert ops[8] <= ops[3] * 8 / 3, ops


def test_entries_that_cancel_are_zero_and_parameters_are_not_taken_at_their_defaults():
    """Kept unexpanded, ∂/∂a of (1 + sin 2a − 2 sin a cos a)·ḃ is a sum that cancels only
    to roundoff; the derivation finds it zero (a structural zero the sparsity then sees at
    every state).  An entry that is zero only at a parameter's default value (c = 0)
    stays."""
    (a, b), (ad, bd) = coordinates("a b")
    c = sp.Symbol("c")
    one = 1 + sp.sin(2 * a) - 2 * sp.sin(a) * sp.cos(a)
    system = System("cancel", q=[a, b], v=[ad, bd], lagrangian=(ad**2 + bd**2) / 2,
                    nonholonomic=[one * bd + c * b * ad],
                    params={c: 0.0}, reference_state=[0] * 4, simplify=False,
                    expand=False)  # fmt: skip
    h_q, h_v = system.derive()["h_q"], system.derive()["h_v"]
    assert h_q[0, 0] == 0 and h_q[0, 1] != 0  # c·ȧ stays though c = 0 by default
    assert h_v[0, 0] != 0 and h_v[0, 1] != 0


def test_cli_generate(tmp_path, capsys):
    out = tmp_path / "sph.py"
    code = main(["generate", str(SPECS / "spherical_pendulum.py"), "-o", str(out)])
    text = capsys.readouterr().out
    assert code == 0 and out.is_file()
    assert "written to" in text and "all pieces agree" in text
    assert main(["generate", str(SPECS / "pendulum.py")]) == 0
    assert "def f_accel(t, q, v, p, out):" in capsys.readouterr().out


def test_cli_generate_bad_spec(tmp_path, capsys):
    spec = tmp_path / "empty.py"
    spec.write_text("x = 1\n")
    assert main(["generate", str(spec), "-o", str(tmp_path / "m.py")]) == 2
    err = capsys.readouterr().err
    assert "must define one stabdae.symbolic.System" in err
    assert not (tmp_path / "m.py").exists()


@pytest.mark.parametrize("text, line, what", [
    ("import sympy as sp\nq = sp.symbols('q'\n", 2, "SyntaxError"),
    ("import sympy as sp\n\nx = undefined_name + 1\n", 3, "NameError: name 'undefined_name'"),
])  # fmt: skip
def test_cli_generate_names_the_spec_files_own_error_and_line(tmp_path, capsys, text, line,
                                                             what):  # fmt: skip
    """A mistake in the spec file: one line with the file, the line and the error (before:
    a traceback and exit 1)."""
    spec = tmp_path / "broken.py"
    spec.write_text(text)
    assert main(["generate", str(spec), "-o", str(tmp_path / "m.py")]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.count("\n") == 1, err
    assert f"generate: {spec}:{line}: {what}" in err, err


def test_load_model_names_the_model_files_own_error_and_line(tmp_path):
    """A model file that fails when run (a NameError in its third line): load_model says
    where, in one line, as it does for a syntax error."""
    path = tmp_path / "broken_model.py"
    path.write_text("import numpy as np\n\nM = np.eye(2) * undefined_mass\n")
    with pytest.raises(stabdae.ModelError) as info:
        stabdae.load_model(path)
    assert str(info.value).startswith(f"load_model: {path}:3: NameError: name 'undefined_mass'")


def test_unexpanded_derivation_is_the_same_model_in_fewer_operations(tmp_path):
    """``expand=False`` keeps the product and chain rules' trees and lets common
    subexpressions share them: the same model (every piece within 1e-12 at random
    states, and it passes check) in well under half the operations of the expanded one
    (measured: 356 against 1379 at 3 links; at 5 links 654 against 7309, derived in
    0.7 s against 96 s).  ``stabdae generate`` reports the count."""
    # a chain of rods in its joint angles whose tip is held at a fixed distance from a
    # pin: a constraint that nests the angles in a square root of squared sums
    chain = load_file(ROOT / "studies" / "bench_generate.py", "stabdae_bench_generate").minimal
    expanded = chain(3, simplify=False, expand=True)
    kept = chain(3, simplify=False, expand=False)
    a = stabdae.load_model(expanded.write(tmp_path / "expanded.py"))
    b = stabdae.load_model(kept.write(tmp_path / "kept.py"))
    worst, compared = largest_difference(b, a)
    assert worst <= 1e-12 and {"forces", "f_accel", "mass"} <= compared
    assert b.check().ok
    assert 2 * sum(kept.operations.values()) < sum(expanded.operations.values())
    assert set(kept.operations) == set(expanded.operations)


def test_a_generated_model_of_8000_operations_runs_every_driver(tmp_path):
    """A model as large as a generated bicycle's (at least 8000 operations after common
    subexpressions, f_accel one expression about 900 deep) at Python's default recursion
    limit: it raised RecursionError from every driver.  A particle on a polynomial surface
    z = Σᵢ (x − aᵢ)² (y + bᵢ)³ / 100i, 210 terms: check passes, the fixed-step and adaptive
    runs keep its energy (a first integral: no forces but gravity, constraint
    scleronomic), and an ensemble's residual decays at the law's rate.  (A surface of
    sines compiles five to ten times slower at the same size; polynomials keep this test
    short.)"""
    import sys

    assert sys.getrecursionlimit() <= 1200
    (x, y, z), (xd, yd, zd) = coordinates("x y z")
    g = sp.Symbol("g")
    terms = 210
    surface = sum(sp.Rational(1, 100 * i) * (x - sp.Rational(i, terms)) ** 2
                  * (y + sp.Rational(i, 2 * terms)) ** 3 for i in range(1, terms + 1))  # fmt: skip
    system = System("polynomial_surface", q=[x, y, z], v=[xd, yd, zd],
                    lagrangian=(xd**2 + yd**2 + zd**2) / 2 - g * z,
                    holonomic=[z - surface], params={g: 9.81},
                    reference_state=[0.1, 0.2, float(surface.subs({x: 0.1, y: 0.2})),
                                     0.0, 0.0, 0.0],
                    simplify=False, expand=False)  # fmt: skip
    model = stabdae.load_model(system.write(tmp_path / "polynomial_surface.py"))
    assert sum(system.operations.values()) >= 8000, system.operations
    assert model.check(states=2).ok
    law = stabdae.baumgarte(10.0, 1.0)
    fixed = stabdae.integrate(model, law=law, scheme="rk4", tau=1e-4, t_end=0.2)
    adaptive = stabdae.integrate_adaptive(model, law=law, t_end=0.2, rtol=1e-10, atol=1e-12)
    for run in (fixed, adaptive):
        energy = run["energy"].values
        assert np.all(np.isfinite(energy))
        assert np.max(np.abs(energy - energy[0])) <= 1e-7 * max(1.0, abs(energy[0]))
    ds = stabdae.ensemble(model, law, "midpoint", tau=1e-3, t_end=1.0, members=16)
    beta = ds["beta"].values
    assert np.all(np.isfinite(beta)) and np.all(np.abs(beta / 10.0 - 1.0) <= 0.02), beta


def test_a_sum_of_thousands_of_terms_is_written_as_partial_sums(tmp_path, monkeypatch):
    """An expanded derivation writes sums of thousands of terms (the bicycle's spec with
    ``expand=True``: an expression 12,715 levels deep in its energy), and Python itself
    could not compile the model file ("maximum recursion depth exceeded during
    compilation").  Now a sum is written as partial sums of at most 64 terms into its
    target, in the order written, so the functions give the same bits as the sum in one
    statement, and no statement is deeper than a few dozen levels."""
    import ast

    import stabdae.symbolic as symbolic

    (x, y), (xd, yd) = coordinates("x y")
    terms = 150  # one sum of ~150 terms in f, f_q, f_accel and the energy
    potential = sum(sp.Rational(i, 7) * x ** (i % 5) * y ** (i % 3 + 1) * sp.cos(i * x)
                    for i in range(1, terms + 1))  # fmt: skip
    def system():
        return System("long_sums", q=[x, y], v=[xd, yd],
                      lagrangian=(xd**2 + yd**2) / 2 - potential,
                      holonomic=[y - sum(x ** (i % 4) * sp.sin(i * x) / i
                                         for i in range(1, terms + 1))],
                      params={}, reference_state=[0.0] * 4, simplify=False,
                      expand=True)  # fmt: skip

    split = system().write(tmp_path / "split.py")
    monkeypatch.setattr(symbolic, "_TERMS", 10**9)
    whole = system().write(tmp_path / "whole.py")
    depth = {}
    for path in (split, whole):
        tree = ast.parse(path.read_text())
        deepest, stack = 0, [(tree, 0)]
        while stack:
            node, d = stack.pop()
            deepest = max(deepest, d)
            stack.extend((c, d + 1) for c in ast.iter_child_nodes(node))
        depth[path.stem] = deepest
    assert depth["whole"] > 150 and depth["split"] < 100, depth
    a = stabdae.load_model(split)
    b = stabdae.load_model(whole)
    rng = np.random.default_rng(1)
    for _ in range(3):
        xs = rng.uniform(-1.0, 1.0, 4)
        for piece in ("forces", "f", "f_q", "f_accel", "energy"):
            # as Python (numba's compilation of the long sums would take minutes; the
            # emitted code gives Python's bits, test_emit)
            va = np.asarray(a._value(piece, 0.0, xs, a.default_params(), python=True))
            vb = np.asarray(b._value(piece, 0.0, xs, b.default_params(), python=True))
            assert va.tobytes() == vb.tobytes(), piece


# ---------------------------------------------------------------- quasi-velocities
def test_a_quaternion_spec_derives_the_hand_written_top(tmp_path):
    """The heavy top's Lagrangian in body angular velocities and the norm's rate, with
    the map ``q̇ = ½ p ⊗ (w, ω)``: Hamel's equations give the hand-written scene's
    gyroscopic and gravity terms (Euler's equations) at states off the manifold
    (|p| ≠ 1, w ≠ 0), its f_accel and map; the energy differs by the norm's ½ μ w²."""
    model = generated(tmp_path, ROOT / "tests" / "models" / "heavy_top_spec.py")
    top = load_scene("heavy_top")
    assert model.kinematic and model.velocities == ("w", "omega_x", "omega_y", "omega_z")
    assert model.check().ok
    rng = np.random.default_rng(5)
    p = top.default_params()
    for _ in range(4):
        x = top.reference_state(p) + 0.1 * rng.standard_normal(8)
        for piece in ("mass", "forces", "f", "f_q", "f_accel", "kinematics"):
            np.testing.assert_allclose(model.evaluate(piece, 0.0, x, p),
                                       top.evaluate(piece, 0.0, x, p), rtol=0, atol=1e-13,
                                       err_msg=piece)  # fmt: skip
        assert abs(top.evaluate("forces", 0.0, x, p)).max() > 0.1  # a real comparison
        half_w2 = 0.5 * p[3] * x[4] ** 2
        assert model.evaluate("energy", 0.0, x, p) == pytest.approx(
            top.evaluate("energy", 0.0, x, p) + half_w2, rel=1e-13)
    np.testing.assert_array_equal(model.reference_state(p), top.reference_state(p))


def test_hamel_terms_of_polar_quasi_velocities_in_closed_form():
    """A pendulum in polar coordinates q = (r, θ) with the quasi-velocities v = (ṙ, r θ̇)
    (T = diag(1, 1/r)), L* = ½ m (v_r² + v_θ²) + m g r cos θ: Hamel's equations are
    ``m v̇_r − m v_θ²/r − m g cos θ = λ`` and ``m v̇_θ + m v_r v_θ / r + m g sin θ = 0``, so
    γ = (−m v_θ²/r − m g cos θ, m v_r v_θ/r + m g sin θ); the constraint r = l has
    f_q T = (1, 0) and f_accel = 0."""
    (r, th), (vr, vt) = coordinates("r theta")
    m, g, l = sp.symbols("m g l")
    system = System("polar", q=[r, th], v=[vr, vt],
                    kinematics=sp.Matrix([[1, 0], [0, 1 / r]]),
                    lagrangian=m * (vr**2 + vt**2) / 2 + m * g * r * sp.cos(th),
                    holonomic=[r - l], params={m: 2.0, g: 9.81, l: 1.5},
                    reference_state=[l, sp.Rational(1, 2), 0, l])  # fmt: skip
    pieces = system.derive()
    gamma = sp.Matrix([-m * vt**2 / r - m * g * sp.cos(th), m * vr * vt / r + m * g * sp.sin(th)])
    assert sp.simplify(pieces["forces"] - gamma) == sp.zeros(2, 1)
    assert sp.simplify(pieces["f_q"] * pieces["kinematics"]) == sp.Matrix([[1, 0]])
    assert pieces["f_accel"] == sp.zeros(1, 1)
    assert sp.simplify(pieces["energy"] - (m * (vr**2 + vt**2) / 2 - m * g * r * sp.cos(th))) == 0


def test_a_generated_polar_pendulum_in_quasi_velocities_swings_as_the_cartesian_one(tmp_path):
    """The polar pendulum above generated and integrated (T = diag(1, 1/r) depends on the
    state): its angle follows the Cartesian pendulum scene's from the same start, θ₀ = 0.5,
    θ̇₀ = 1, over 2 s."""
    (r, th), (vr, vt) = coordinates("r theta")
    g, l = sp.symbols("g l")
    system = System("polar_pendulum", q=[r, th], v=[vr, vt],
                    kinematics=sp.Matrix([[1, 0], [0, 1 / r]]),
                    lagrangian=(vr**2 + vt**2) / 2 + g * r * sp.cos(th), holonomic=[r - l],
                    params={g: 9.81, l: 1.0},
                    reference_state=[l, sp.Rational(1, 2), 0, l])  # fmt: skip
    polar = stabdae.load_model(system.write(tmp_path / "polar_pendulum.py"))
    cartesian = load_scene("pendulum")
    law = stabdae.baumgarte(10.0, 1.0)
    a = stabdae.integrate(polar, None, law, "rk4", 1e-3, 2.0, 0.1)
    b = stabdae.integrate(cartesian, None, law, "rk4", 1e-3, 2.0, 0.1)
    theta = np.arctan2(b.x.values[:, 0], -b.x.values[:, 1])
    assert np.ptp(theta) > 0.5  # it swings
    np.testing.assert_allclose(a.x.values[:, 1], theta, rtol=0, atol=1e-10)
    np.testing.assert_allclose(a.x.values[:, 0], 1.0, rtol=0, atol=1e-12)


def test_a_kinematic_map_must_be_square_and_free_of_velocities():
    (r, th), (vr, vt) = coordinates("r theta")
    args = dict(q=[r, th], v=[vr, vt], lagrangian=(vr**2 + vt**2) / 2, holonomic=[r - 1],
                reference_state=[1, 0, 0, 1])
    with pytest.raises(SymbolicError, match=r"kinematics must be an n × n = 2 × 2 matrix"):
        System("bad", kinematics=sp.Matrix([[1, 0]]), **args)
    with pytest.raises(SymbolicError, match=r"kinematics\[1, 1\] \(T\(q, t\): no velocities\)"):
        System("bad", kinematics=sp.Matrix([[1, 0], [0, vr]]), **args)
