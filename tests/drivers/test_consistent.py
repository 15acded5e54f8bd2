"""model.consistent_state(): held components kept, the rest solved onto the manifold;
under-determined and contradictory choices refused with the names that matter."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import stabdae
from conftest import load_scene


def test_pendulum_state_is_the_closed_form():
    """Holding x and ẋ of the pendulum (l = 1): y = −√(l² − x²) (the branch of the
    reference, below the pivot) and ẏ = −x ẋ / y, from f = x² + y² − l² and ḟ = 0."""
    model = load_scene("pendulum")
    x = model.consistent_state({"x": 0.3, "x_dot": 0.5})
    y = -math.sqrt(1.0 - 0.3**2)
    np.testing.assert_allclose(x, [0.3, y, 0.5, -0.3 * 0.5 / y], rtol=1e-15, atol=1e-15)
    assert np.max(np.abs(model.residual(x))) <= 1e-13


@pytest.mark.parametrize("name, fixed", [
    ("double_pendulum", {"x1": 0.5, "x2": 0.9, "x1_dot": 0.2, "x2_dot": -0.1}),
    ("slider_crank", {"phi": 0.4, "phi_dot": 2.0}),
    ("n_four_bar", {"x0": 0.6, "x0_dot": -0.4}),  # one crank's tip: the rest follows
    ("flyball_governor", {"psi": 0.3, "s": 0.55, "x1": 0.8, "x2": -0.7, "psi_dot": 5.0,
                          "s_dot": 0.1, "z1_dot": 0.2, "z2_dot": -0.1}),
    ("knife_edge", {"x": 0.1, "y": 0.2, "phi": 0.7, "x_dot": 1.0, "phi_dot": 0.3}),
    ("rolling_disk", {"x": 0.1, "y": 0.2, "phi": 0.3, "theta": 0.2, "psi": 0.1,
                      "phi_dot": 1.0, "theta_dot": 0.2, "psi_dot": 3.0}),
])  # fmt: skip
def test_consistent_states_of_scenes(name, fixed):
    """Holonomic (double pendulum, slider-crank, the N-four-bar, the flyball governor),
    nonholonomic (knife edge) and both (rolling disk): the residual g = (f, ḟ, h) is at
    most 1e-13 and every held component keeps its value exactly."""
    model = load_scene(name)
    x = model.consistent_state(fixed)
    assert np.max(np.abs(model.residual(x))) <= 1e-13
    names = model.state_names
    for key, value in fixed.items():
        assert x[names.index(key)] == value, key


def test_impossible_and_loose_choices_are_refused_by_name():
    pend = load_scene("pendulum")
    # x = 2 > l: no real y
    with pytest.raises(ValueError, match=r"pendulum.consistent_state: no consistent state "
                       r"near the start with the values held \(x\): the constraints f_0 = "):
        pend.consistent_state({"x": 2.0})
    # both coordinates held, off the circle: f contradicts them
    with pytest.raises(ValueError, match=r"held \(x, y\): the constraints f_0 = -0.82"):
        pend.consistent_state({"x": 0.3, "y": 0.3})
    # both velocities held, not tangent: ḟ contradicts them
    with pytest.raises(ValueError, match=r"held \(x, x_dot, y_dot\): the constraints fdot_0"):
        pend.consistent_state({"x": 0.3, "x_dot": 1.0, "y_dot": 1.0})
    # nothing held: one coordinate of two is free
    with pytest.raises(ValueError, match=r"determine 1 of the 2 coordinates not held; hold 1 "
                       r"more of x, y"):
        pend.consistent_state()
    # no holonomic constraint: every coordinate must be held
    with pytest.raises(ValueError, match=r"no holonomic constraint determines the coordinates "
                       r"x, y, phi"):
        load_scene("knife_edge").consistent_state({"x_dot": 1.0})
    with pytest.raises(ValueError, match=r"'z' is not a state component; they are x, y, "
                       r"x_dot, y_dot"):
        pend.consistent_state({"z": 1.0})
    with pytest.raises(ValueError, match=r"guess must have shape \(2n,\) = \(4,\), got \(3,\)"):
        pend.consistent_state({"x": 0.1}, guess=[0.0, 1.0, 0.0])


def test_the_guess_picks_the_branch():
    """Above the pivot (y > 0) when the guess is there."""
    pend = load_scene("pendulum")
    x = pend.consistent_state({"x": 0.3, "x_dot": 0.0}, guess=[0.0, 1.0, 0.0, 0.0])
    assert x[1] == pytest.approx(math.sqrt(1 - 0.09), rel=1e-15)


@pytest.mark.parametrize("tol", [float("nan"), -1.0, 0.0, float("inf"), "1e-3", True])
def test_a_tolerance_that_is_not_a_positive_number_is_refused(tol):
    """``tol=nan`` returned a state that breaks the constraint (every comparison with NaN
    is false, so nothing was refused)."""
    model = stabdae.load_model("pendulum")
    with pytest.raises(ValueError, match=r"pendulum\.consistent_state: tol must be a "
                                         r"positive finite number"):
        model.consistent_state({"x": 0.3, "x_dot": 1.0}, tol=tol)


def test_a_component_held_by_name_and_by_index_is_refused():
    """``{"x": 0.3, 0: 0.4}`` kept 0.4 without a word."""
    model = stabdae.load_model("pendulum")
    with pytest.raises(ValueError, match=r"x is held twice, as 'x' = 0\.3 and as 0 = 0\.4"):
        model.consistent_state({"x": 0.3, 0: 0.4, "x_dot": 1.0})


def test_a_singular_configuration_is_warned_of_and_a_regular_one_is_not():
    """Holding the pendulum's x at its length leaves y at the double root of x² + y² = 1:
    the velocity ẏ = −x ẋ / y solved there was 10⁷ m/s without a warning.  A state
    away from it solves silently."""
    model = stabdae.load_model("pendulum")
    with pytest.warns(RuntimeWarning) as record:
        x = model.consistent_state({"x": 1.0, "x_dot": 1.0})
    said = [str(w.message) for w in record]
    assert any("barely determine the coordinates solved for (y)" in m for m in said), said
    assert any("barely determine the velocities solved for (y_dot)" in m for m in said), said
    assert abs(x[3]) > 1e5  # what it solved is the sensitive solution it warns of
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        x = model.consistent_state({"x": 0.3, "x_dot": 1.0})
    np.testing.assert_allclose(x[0] * x[2] + x[1] * x[3], 0.0, atol=1e-12)
