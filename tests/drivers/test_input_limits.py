"""Values out of range refused where they are given, naming the function and the value
(each of them used to fail later, in numpy or at the NetCDF write, or ran silently)."""

from __future__ import annotations

import pytest

import stabdae
from conftest import load_scene
from stabdae._schemes import SchemeError, from_tableau


def test_a_step_count_no_run_can_take_is_refused():
    """``integrate(tau=1e-300)`` ended in numpy's "Maximum allowed dimension exceeded"."""
    model = load_scene("pendulum")
    with pytest.raises(ValueError, match=r"integrate: .* is 1e\+300 steps: at most 1e\+12"):
        stabdae.integrate(model, None, stabdae.baumgarte(10.0), "rk2", 1e-300, 1.0)


def test_a_gain_k_on_a_model_without_nonholonomic_constraints_is_refused():
    """``baumgarte(omega=10, k=5)`` on the pendulum was accepted and the gain ignored."""
    model = load_scene("pendulum")
    with pytest.raises(stabdae.LawError, match=r"no nonholonomic constraints \(k = 0\), so "
                                               r"the gain k = 5 has nothing to act on"):
        stabdae.integrate(model, None, stabdae.baumgarte(10.0, k=5.0), "rk2", 1e-2, 0.1)
    sleigh = load_scene("chaplygin_sleigh")
    assert stabdae.baumgarte(k=5.0).A(sleigh).shape == (sleigh.k, sleigh.k)


@pytest.mark.parametrize("order", ["two", 2.9, True, 0, -1, None])
def test_a_tableau_order_must_be_a_positive_integer(order):
    """``order = "two"`` gave ``invalid literal for int()`` without the key; ``2.9`` ran as
    order 2 silently."""
    spec = {"A": [[0, 0], [1, 0]], "b": [0.5, 0.5], "c": [0, 1], "order": order}
    with pytest.raises(SchemeError, match=r"tableau order must be a positive integer"):
        from_tableau(spec, name="mine")
    spec["order"] = 2
    assert from_tableau(spec, name="mine").order == 2


@pytest.mark.parametrize("kw, match", [(dict(rtol=-1.0), "rtol must be positive"),
                                       (dict(rtol=float("nan")), "rtol must be positive"),
                                       (dict(radius=0.0), "radius must be positive"),
                                       (dict(states=-1), "states must be a non-negative")])
def test_check_refuses_tolerances_and_sizes_out_of_range(kw, match):
    with pytest.raises(ValueError, match=rf"pendulum\.check: {match}"):
        load_scene("pendulum").check(**kw)


def test_a_complex_value_held_in_a_consistent_state_is_refused_with_its_name():
    with pytest.raises(ValueError, match=r"consistent_state: the value held for x must be a "
                                         r"real number, got \(0\.3\+1j\)"):
        load_scene("pendulum").consistent_state({"x": 0.3 + 1j, "x_dot": 1.0})
