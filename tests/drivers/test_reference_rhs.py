"""The compiled stabilized right-hand side against a plain NumPy one written from the
theory page's equations (``tests/reference/rhs.py``): every scene, constant laws of
each shape and Theorem 5's state-dependent law, at perturbed states off the manifold."""

from __future__ import annotations

import numpy as np
import pytest

import stabdae
from conftest import KINEMATIC, SCENES, load_kinematic, load_scene, perturbed_state, rhs_function
from reference.rhs import stabilized_rhs

LAWS = {
    "baumgarte": lambda model: stabdae.baumgarte(10.0, 0.7, k=3.0 if model.k else None),
    "none": lambda model: stabdae.none(),
    # a full constant A: every block coupled (the general sums, not Baumgarte's diagonal)
    "matrix": lambda model: stabdae.matrix(
        -np.random.default_rng(7).uniform(0.5, 2.0, (model.r, model.m + model.r))),
}


@pytest.mark.parametrize("law_name", list(LAWS))
@pytest.mark.parametrize("scene", SCENES)
def test_compiled_rhs_equals_the_numpy_reference(scene, law_name):
    model = load_scene(scene)
    law = LAWS[law_name](model)
    F = rhs_function(model, law)
    for seed in range(3):
        x = perturbed_state(model, 1e-2, seed)
        t = model.t0 + 0.1 * seed
        got, want = F(t, x), stabilized_rhs(model, law, t, x)
        scale = np.abs(want).max() + 1.0
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-11 * scale,
                                   err_msg=f"{scene}, {law_name}, state {seed}")


@pytest.mark.parametrize("law_name", ["baumgarte", "matrix"])
@pytest.mark.parametrize("name", list(KINEMATIC))
def test_rhs_with_a_kinematic_map_equals_the_numpy_reference(name, law_name):
    """q̇ = T v, F = [f_q T; h_v], h_q T v: the quaternion models off the manifold (|p| ≠ 1,
    w ≠ 0), where a map applied in the wrong place changes every component."""
    model = load_kinematic(name)
    law = LAWS[law_name](model)
    F = rhs_function(model, law)
    for seed in range(3):
        x = perturbed_state(model, 1e-2, seed)
        assert abs(np.linalg.norm(x[model.n - 4 : model.n]) - 1.0) > 1e-4
        got, want = F(0.0, x), stabilized_rhs(model, law, 0.0, x)
        scale = np.abs(want).max() + 1.0
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-11 * scale,
                                   err_msg=f"{name}, {law_name}, state {seed}")
        assert np.abs(got[: model.n] - x[model.n :]).max() > 1e-3  # q̇ is not v here


@pytest.mark.parametrize("scene", ["chaplygin_sleigh", "knife_edge"])
def test_theorem5_rhs_equals_the_numpy_reference(scene):
    model = load_scene(scene)
    assert model.m == 0 and model.k > 0  # Theorem 5's law: nonholonomic constraints only
    law = stabdae.theorem5(2.0)
    F = rhs_function(model, law)
    for seed in range(3):
        x = perturbed_state(model, 1e-2, seed)
        np.testing.assert_allclose(F(model.t0, x), stabilized_rhs(model, law, model.t0, x),
                                   rtol=1e-9, atol=1e-11)  # fmt: skip
