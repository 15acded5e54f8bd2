"""Structural sparsity: patterns found at construction, declared patterns checked, and the
sparse right-hand side against the dense one."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

import stabdae
from conftest import KERNELS, SCENES, load_scene, perturbed_state, scene_module
from stabdae._laws import BoundLaw, bind_law
from stabdae.engine.rhs import LAW_CONSTANT, LAW_SCALAR_BLOCKS, kernels_for
from stabdae.engine.sparsity import dense_cost, fill_pattern, sparse_cost, structure


def _rhs_and_projection(model, law, x, t=0.05, full=False):
    """ẋ at ``x`` and ``x`` after one full projection, through the compiled pieces;
    ``full``: the constant law applied as its full matrix ``A`` (the sums with their zero
    terms), whatever form it binds to."""
    bound = bind_law(law, model)
    if full:
        bound = BoundLaw(law, LAW_CONSTANT, np.ascontiguousarray(law.A(model)), np.zeros(1))
    K = kernels_for(model, bound)
    # parameters away from their defaults (unit masses would hide a forgotten M⁻¹)
    p = model.param_vector() * np.linspace(1.1, 1.5, len(model.params))
    ws = K.make_workspace()
    out = np.empty_like(x)
    status = K.rhs(t, x, p, bound.matrix, bound.scalars, ws, out)
    y = x.copy()
    # (the redundant four-bar's position level is singular: both paths say so)
    projected = K.project(t, y, p, ws, 8, 0.0)
    return (status, out), (projected, y if projected == 0 else None)


@pytest.mark.parametrize("name", [*SCENES, "pendulum_chain"])
def test_sparse_and_dense_paths_agree_on_every_scene(name):
    """The sparse path does the dense path's arithmetic minus the structurally zero terms:
    the same numbers up to the sign of a zero, for the right-hand side and the
    projection, at states off the manifold."""
    model = load_scene(name)
    sparse = model.replace(sparsity="sparse")
    if sparse.sparse_structure() is None:  # a mass matrix that is not diagonal
        assert model.has_mass and (model.patterns["mass"] & ~np.eye(model.n, dtype=bool)).any()
        pytest.skip("the mass matrix is not diagonal: dense path only")
    # (the scene itself where it takes the dense path: its kernels may be compiled already)
    dense = model if model.sparse_structure() is None else model.replace(sparsity="dense")
    assert dense.sparse_structure() is None
    law = stabdae.baumgarte(omega=6.0, xi=0.8, k=4.0 if model.k else None)
    # Baumgarte's blocks are multiples of the identity: both paths apply A by its three
    # factors; here the dense one applies it as the full matrix
    assert bind_law(law, sparse).code == bind_law(law, dense).code == LAW_SCALAR_BLOCKS
    for seed in range(3):
        x = perturbed_state(model, 1e-2, seed)
        (a, pa), (b, pb) = (_rhs_and_projection(sparse, law, x),
                            _rhs_and_projection(dense, law, x, full=True))  # fmt: skip
        assert a[0] == b[0] == 0 and pa[0] == pb[0]
        np.testing.assert_array_equal(a[1], b[1])
        np.testing.assert_array_equal(pa[1], pb[1])


@pytest.mark.parametrize("name", SCENES)
def test_written_out_structure_and_dense_loops_agree_on_every_scene(name):
    """Where the sparse path does not apply (a mass matrix that is not diagonal, or too
    little to save), the dense path's linear algebra and its products ``f_q v``, ``h_q v``
    are written out without the model's structural zeros, and the law is applied by its
    three factors: the same numbers as the dense loops with the law's full matrix up to
    the sign of a zero, at states off the manifold."""
    from stabdae.engine.rhs import _structured

    model = load_scene(name)
    plan = None if model.sparse_structure() is not None else _structured(
        model, model.n, model.m, model.k)
    if name in ("andrews", "double_pendulum", "slider_crank", "rolling_disk", "car_axis"):
        assert plan is not None  # block-diagonal or diagonal mass, few couplings
    if plan is None:
        pytest.skip("no written-out structure: the sparse path, or nothing to save")
    dense = model.replace(sparsity="dense")
    assert _structured(dense, dense.n, dense.m, dense.k) is None
    k_dense = kernels_for(dense, bind_law(stabdae.baumgarte(6.0, 0.8, k=4.0 if model.k else None), dense))
    k_plan = kernels_for(model, bind_law(stabdae.baumgarte(6.0, 0.8, k=4.0 if model.k else None), model))
    assert k_plan.key != k_dense.key  # different code, different cache entries
    for law in (stabdae.baumgarte(omega=6.0, xi=0.8, k=4.0 if model.k else None), stabdae.none()):
        for seed in range(3):
            x = perturbed_state(model, 1e-2, seed)
            (a, _), (b, _) = (_rhs_and_projection(model, law, x),
                              _rhs_and_projection(dense, law, x, full=True))  # fmt: skip
            assert a[0] == b[0] == 0
            np.testing.assert_array_equal(a[1], b[1])


def test_fekete_uses_the_sparse_path_and_matches_a_direct_evaluation():
    """Fekete's S is diagonal: no product between two charges, no fill; the stabilized
    acceleration equals the closed form of one charge, v̇_i = −γ_i + 2 λ_i p_i with
    λ_i from the scalar equation of its own constraint."""
    model = stabdae.load_model(KERNELS / "fekete.py")
    st = model.sparse_structure()
    assert st is not None
    assert (st.nnz_f, st.nnz_s, st.nnz_l) == (60, 20, 0)
    assert st.sj.size == 60 and st.oq.size == 0
    omega, xi = 10.0, 1.0
    law = stabdae.baumgarte(omega, xi)
    x = perturbed_state(model, 1e-3, 1)
    (status, xdot), _ = _rhs_and_projection(model, law, x, t=0.0)
    assert status == 0
    n, N = model.n, model.n // 3
    q, v = x[:n].reshape(N, 3), x[n:].reshape(N, 3)
    gamma = model.evaluate("forces", 0.0, x, model.param_vector() * 1.1).reshape(N, 3)
    f = (q * q).sum(1) - 1.0
    fdot = 2.0 * (q * v).sum(1)
    accel = 2.0 * (v * v).sum(1)  # f̈ = 2 q·v̇ + 2|v|² = ω² (−f) … the law: f̈ = −ω² f − 2ξω ḟ
    target = -omega**2 * f - 2 * xi * omega * fdot
    # v̇ = 2 λ q − γ, so f̈ = 2 q·(2 λ q − γ) + accel: λ = (target − accel + 2 q·γ) / (4|q|²)
    lam = (target - accel + 2 * (q * gamma).sum(1)) / (4 * (q * q).sum(1))
    expected = 2 * lam[:, None] * q - gamma
    np.testing.assert_allclose(xdot[n:].reshape(N, 3), expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(xdot[:n], x[n:])


def test_law_kinds_share_the_pieces_no_law_touches():
    """The sampler's kernels (the constant law) and a run's under Baumgarte's law (its three
    factors on the sparse path) use the same residual, projection and workspace, compiled
    once; each law kind has its own right-hand side; the least-squares multiplier, which
    stays dense, has its own pieces."""
    from stabdae.engine.sampler import _Unstabilized

    model = stabdae.load_model(KERNELS / "fekete.py")
    run = kernels_for(model, bind_law(stabdae.baumgarte(10.0, 1.0), model))
    sampler = kernels_for(model, _Unstabilized)
    assert (run.residual, run.project, run.energy, run.make_workspace) == (
        sampler.residual, sampler.project, sampler.energy, sampler.make_workspace)
    assert run.rhs is not sampler.rhs and run.key != sampler.key
    dense = kernels_for(model, bind_law(stabdae.baumgarte(10.0, 1.0), model), "lstsq")
    assert dense.residual is not run.residual


def test_fill_of_an_arrow_matrix_and_of_a_band():
    """The factor's pattern: an arrow pointing up-left fills completely, one pointing
    down-right not at all; a band keeps its width."""
    r = 5
    up = np.eye(r, dtype=bool)
    up[:, 0] = up[0, :] = True
    assert fill_pattern(up).sum() == r * (r + 1) // 2
    down = np.eye(r, dtype=bool)
    down[:, -1] = down[-1, :] = True
    np.testing.assert_array_equal(fill_pattern(down), np.tril(down))
    band = np.abs(np.subtract.outer(np.arange(r), np.arange(r))) <= 1
    np.testing.assert_array_equal(fill_pattern(band), np.tril(band))


def test_fill_pattern_is_that_of_a_numerical_factor():
    """The fill of ``L D Lᵀ`` from the pattern alone against the factor itself: for 300
    random symmetric patterns (2 to 9 rows, sparse to dense), NumPy's Cholesky factor of
    a matrix with that pattern and random values (diagonally dominant: positive definite;
    generic: no entry cancels) has its nonzeros exactly where ``fill_pattern`` says."""
    rng = np.random.default_rng(11)
    filled = 0
    for _ in range(300):
        r = int(rng.integers(2, 10))
        low = np.tril(rng.random((r, r)) < rng.uniform(0.1, 0.6), -1)
        A = np.where(low, rng.uniform(0.5, 1.5, (r, r)), 0.0)
        A = A + A.T
        A += np.diag(np.abs(A).sum(axis=1) + 1.0)
        L = np.linalg.cholesky(A)
        numeric = np.abs(L) > 1e-12 * np.abs(L).max()
        got = fill_pattern(low)
        np.testing.assert_array_equal(got, numeric)
        filled += int((got & ~np.tril(low | np.eye(r, dtype=bool))).any())
    assert filled > 50  # the sample exercises fill, not only patterns that keep theirs


def test_chain_structure_is_banded():
    """A chain of links, each constraint touching its own point and the one before: S is
    tridiagonal, its factor has no fill, and each entry is made of the products of the
    shared coordinates only."""
    N = 6
    F = np.zeros((N, 2 * N), dtype=bool)
    for i in range(N):
        F[i, 2 * i: 2 * i + 2] = True
        if i:
            F[i, 2 * i - 2: 2 * i] = True
    st = structure(F)
    assert st.nnz_s == N + (N - 1)
    assert st.nnz_l == N - 1 and st.oq.size == 0
    assert st.sj.size == 2 + 4 * (N - 1) + 2 * (N - 1)  # S00, S_ii (4 terms), S_i,i-1 (2)


def test_the_pendulum_chain_is_found_tridiagonal():
    """The chain of N pendulums, detected from its functions: F has the two masses of each
    rod, S is tridiagonal with no fill, the mass matrix diagonal, so the sparse path is
    taken; its constraint part's cost grows like N where the dense one grows like N³."""
    model = load_scene("pendulum_chain")
    N = model.m
    st = model.sparse_structure()
    assert st is not None and model.n == 2 * N
    assert (st.nnz_f, st.nnz_s, st.nnz_l) == (2 + 4 * (N - 1), 2 * N - 1, N - 1)
    np.testing.assert_array_equal(model.patterns["mass"], np.eye(model.n, dtype=bool))
    double = scene_module("pendulum_chain").build(2 * N)
    assert sparse_cost(double.sparse_structure()) / sparse_cost(st) == pytest.approx(2, rel=0.1)
    assert dense_cost(4 * N, 2 * N) / dense_cost(2 * N, N) > 6  # (8 for large N)


# --------------------------------------------------------------------- detection, declared
@njit
def _forces(t, q, v, p, out):
    for i in range(q.shape[0]):
        out[i] = 0.0
    out[1] = 1.0


@njit
def _f(t, q, p, out):
    out[0] = q[0] ** 2 + q[1] ** 2 - 1.0
    out[1] = q[2] - q[0] * q[0] * q[0]


@njit
def _f_q(t, q, p, out):
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]
    out[0, 2] = 0.0
    out[1, 0] = -3.0 * q[0] * q[0]
    out[1, 1] = 0.0
    out[1, 2] = 1.0


@njit
def _f_accel(t, q, v, p, out):
    out[0] = 2.0 * (v[0] ** 2 + v[1] ** 2)
    out[1] = -6.0 * q[0] * v[0] * v[0]


def _bead(**kwargs):
    """A point on the unit circle (x, y) with a third coordinate z = x³; at the reference
    state x = 0, so ∂f₁/∂x = −3x² is zero there and non-zero elsewhere."""
    return stabdae.Model("bead", n=3, m=2, reference_state=np.array([0.0, 1.0, 0.0, 0, 0, 0]),
                         forces=_forces, f=_f, f_q=_f_q, f_accel=_f_accel, **kwargs)


def test_detection_sees_entries_that_vanish_at_the_reference_state():
    model = _bead()
    expected = np.array([[True, True, False], [True, False, True]])
    np.testing.assert_array_equal(model.patterns["f_q"], expected)
    assert _bead(sparsity="dense").patterns is None


def test_a_wrongly_declared_pattern_is_refused_and_caught_by_check(monkeypatch):
    """An entry declared structurally zero that is zero at the reference state only (a
    kernel built on it would drop the term and run on): Model() refuses it, naming the
    function, the entry and the state where it is not zero; and check(), at its own
    states, names it too."""
    wrong = np.array([[True, True, False], [False, False, True]])  # misses ∂f₁/∂x
    with pytest.raises(stabdae.ModelError, match=r"f_q\(t, q, p, out\) writes out\[1, 0\] = "
                                                 r"\S+ at t = 0, x = \[.*\], an entry its "
                                                 r"declared sparsity pattern"):  # fmt: skip
        _bead(sparsity={"f_q": wrong})
    # check() judges the pattern on states of its own (here with construction's states
    # reduced to the reference one, where the wrong entry happens to be zero)
    monkeypatch.setattr(stabdae.Model, "_detect_states",
                        lambda self, x_ref, states=4, seed=0: ([self.t0], [x_ref]))
    model = _bead(sparsity={"f_q": wrong})
    np.testing.assert_array_equal(model.patterns["f_q"], wrong)
    report = model.check()
    assert not report.ok
    assert "sparsity" in report.failures
    text = str(report)
    assert "f_q" in text and "out[1, 0]" in text and "structurally zero" in text
    assert _bead(sparsity={"f_q": model.patterns["f_q"] | True}).check().ok


def test_a_declared_pattern_wrong_at_the_reference_state_is_refused_at_once():
    wrong = np.array([[True, False, False], [True, False, True]])  # misses ∂f₀/∂y, = 2 there
    with pytest.raises(stabdae.ModelError, match=r"f_q\(t, q, p, out\) writes out\[0, 1\]"):
        _bead(sparsity={"f_q": wrong})


@pytest.mark.parametrize(
    "sparsity, match",
    [("fast", "sparsity must be 'detect', 'dense', 'sparse' or a mapping"),
     ({"h_v": np.ones((2, 3))}, "not one of the model's pieces"),
     ({"f_q": np.ones((3, 2))}, r"shape of out, \(2, 3\), got \(3, 2\)"),
     (3, "got int")],
)  # fmt: skip
def test_bad_sparsity_arguments_name_what_is_wrong(sparsity, match):
    with pytest.raises(stabdae.ModelError, match=match):
        _bead(sparsity=sparsity)


def test_replace_keeps_the_pieces_and_refuses_unknown_arguments():
    model = _bead()
    other = model.replace(name="bead2")
    assert other.name == "bead2" and other.functions == model.functions
    with pytest.raises(stabdae.ModelError, match=r"Model.replace: \['colour'\]"):
        model.replace(colour="red")
