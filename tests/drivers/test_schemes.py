"""Butcher tableaus: the order conditions from rooted trees, and DOP853's coefficients.

References: the numbers of rooted trees of orders 1 … 9 (Hairer, Nørsett & Wanner I,
Table II.2.1; OEIS A000081); the orders of the classical schemes; DOP853's coefficients as
SciPy publishes them (``scipy.integrate.DOP853``, a second copy of Hairer's code)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import DOP853

import stabdae
from stabdae._schemes import (
    EmbeddedPair,
    SchemeError,
    _density,
    _order_of,
    embedded_pair,
    rooted_trees,
    tableau_order,
)


def test_rooted_trees_are_counted_as_butchers():
    trees = rooted_trees(9)
    assert [len(trees[p]) for p in range(1, 10)] == [1, 1, 2, 4, 9, 20, 48, 115, 286]
    for p, ts in trees.items():
        assert len(set(ts)) == len(ts)  # each tree once
        assert all(_order_of(t) == p for t in ts)


def test_tree_densities():
    """γ of the bushy tree of order p is p, of the tall one p!; γ([τ, [τ]]) = 4 · 1 · 2."""
    leaf = ()
    assert _density((leaf, leaf, leaf)) == 4
    assert _density((((leaf,),),)) == 24
    assert _density((leaf, (leaf,))) == 8


@pytest.mark.parametrize("make,order", [(stabdae.euler, 1), (stabdae.midpoint, 2),
                                        (stabdae.heun3, 3), (stabdae.rk4, 4),
                                        (stabdae.dopri5, 5), (stabdae.dop853, 8)])  # fmt: skip
def test_order_conditions_give_the_known_orders(make, order):
    s = make()
    assert s.order == order
    assert tableau_order(s.A, s.b) == order  # and not one more: the next order fails


def test_a_changed_coefficient_lowers_dop853s_order():
    """Each non-zero coefficient of A matters to some condition up to order 8 (changed by
    1e-4 of itself: the second stage enters the conditions only through products, where
    1e-7 of ``a₂₁`` stays under the conditions' tolerance)."""
    s = stabdae.dop853()
    A = np.array(s.A)
    for i, j in zip(*np.nonzero(A)):
        B = A.copy()
        B[i, j] *= 1 + 1e-4
        assert tableau_order(B, s.b) < 8, (i, j)
    with pytest.raises(SchemeError, match="declared order 8 but the order conditions hold up "
                                          "to order"):
        stabdae.Scheme("bad", B, s.b, B.sum(axis=1), 8, {})


def test_dop853_is_scipys_dop853():
    s, pair = stabdae.dop853(), embedded_pair("dop853")
    np.testing.assert_array_equal(s.A, DOP853.A)
    np.testing.assert_array_equal(s.b, DOP853.B)
    np.testing.assert_array_equal(s.c, DOP853.C)
    np.testing.assert_array_equal(pair.error, np.stack([DOP853.E5, DOP853.E3]))
    assert (pair.error_order, pair.combined) == (DOP853.error_estimator_order, True)


def test_embedded_formulas_have_their_orders():
    """The pairs check their embedded formulas at construction: Dormand–Prince's b̂ is of
    order 4; DOP853's over thirteen stages (the last one ẋ at the new state) of orders 5
    and 3.  Declared the other way round, construction fails."""
    assert embedded_pair("dopri5").embedded_orders == (4,)
    good = embedded_pair("dop853")
    assert good.embedded_orders == (5, 3) and good.error.shape == (2, 13)
    with pytest.raises(SchemeError, match=r"declared order 3 satisfies the order conditions "
                                          r"up to 5"):
        EmbeddedPair(good.scheme, good.error, (3, 5), 7, True)
    with pytest.raises(SchemeError, match=r"error weights must be \(2, s\) or \(2, s \+ 1\) "
                                          r"for s = 12 stages, got \(2, 7\)"):
        EmbeddedPair(good.scheme, embedded_pair("dopri5").error, (4,), 4, False)
    with pytest.raises(SchemeError, match="^integrate_adaptive: adaptive steps need an "
                                          "embedded pair.*got 'rk4'"):
        stabdae.integrate_adaptive(stabdae.load_model("pendulum"), None, stabdae.none(),
                                   scheme="rk4")
