"""Convergence orders and energy conservation of the schemes of §5.

The order is the log–log slope of the state error at t = 1 against τ, over four halvings
of τ in the asymptotic range.  References: the closed form for the knife edge, RK4 at
τ = 1e-4 for the others (its error there is below 1e-12, far under the errors fitted).
"""

from __future__ import annotations

import numpy as np
import pytest

import stabdae
from conftest import CONSERVATIVE, HARD, SCENES, load_scene, rhs_function, scene_module

T_END = 1.0
SCHEMES = {
    "euler": (stabdae.euler, 1, 0.005),
    "midpoint": (stabdae.midpoint, 2, 0.01),
    "heun": (stabdae.heun, 2, 0.01),
    "two_stage_a0.25": (lambda: stabdae.two_stage(0.25, 2.0), 2, 0.01),
    "rk3": (stabdae.rk3, 3, 0.02),
    "heun3": (stabdae.heun3, 3, 0.02),
    "rk4": (stabdae.rk4, 4, 0.02),
}


def law_for(model):
    return stabdae.baumgarte(omega=5.0 if model.m else None, xi=1.0, k=5.0 if model.k else None)


def reference_final_state(name, model):
    x0 = model.reference_state()
    if name == "knife_edge":
        return scene_module(name).exact_solution(model.default_params(), T_END)
    return stabdae.integrate(model, x0, law_for(model), "rk4", 1e-4, T_END, T_END)["x"].values[-1]


def slope(taus, errors) -> float:
    return float(np.polyfit(np.log(taus), np.log(errors), 1)[0])


@pytest.mark.parametrize("scheme_name", list(SCHEMES))
@pytest.mark.parametrize("name", [s for s in SCENES if s not in HARD])
def test_convergence_order(name, scheme_name):
    make, order, tau0 = SCHEMES[scheme_name]
    model = load_scene(name)
    ref = reference_final_state(name, model)
    taus = tau0 * 0.5 ** np.arange(4)
    errors = []
    for tau in taus:
        ds = stabdae.integrate(model, None, law_for(model), make(), tau, T_END, T_END)
        errors.append(np.max(np.abs(ds["x"].values[-1] - ref)))
    assert abs(slope(taus, errors) - order) <= 0.15, errors


#: 1/τ of the largest step of DOP853's ladder per scene: from there down by √2 four
#: times (a factor 4 in τ, 4.8 decades of error), in the asymptotic range (larger steps
#: give local slopes of 4 to 14 on the double pendulum and the rolling disk) and above
#: roundoff (the smallest errors are 1e-14 to 3e-12)
DOP853_STEPS = {"pendulum": 5, "double_pendulum": 28, "pendulum_varying_length": 10,
                "hoop_bead": 10, "chaplygin_sleigh": 5, "knife_edge": 5,
                "spherical_pendulum": 5, "rolling_disk": 20}  # fmt: skip


@pytest.mark.parametrize("name", [s for s in SCENES if s not in HARD])
def test_dop853_is_eighth_order(name):
    """The log–log slope of DOP853's fixed-step error is 8 ± 0.3 (measured 7.82 … 8.22);
    the reference is the closed form for the knife edge, DOP853 at τ = 1/1024 otherwise
    (its error there is ≤ 1e-10 of the smallest fitted one, by the same order)."""
    model = load_scene(name)
    law = law_for(model)
    if name == "knife_edge":
        ref = scene_module(name).exact_solution(model.default_params(), T_END)
    else:
        ref = stabdae.integrate(model, None, law, "dop853", 1 / 1024, T_END, T_END)["x"].values[-1]
    taus = 1.0 / np.round(DOP853_STEPS[name] * 2.0 ** (np.arange(5) / 2))
    errors = [np.max(np.abs(stabdae.integrate(model, None, law, "dop853", tau, T_END, T_END)
                            ["x"].values[-1] - ref)) for tau in taus]  # fmt: skip
    assert abs(slope(taus, errors) - 8.0) <= 0.3, errors


@pytest.mark.parametrize("scheme_name", list(SCHEMES))
@pytest.mark.parametrize("name", CONSERVATIVE)
def test_energy_conserved_to_order(name, scheme_name):
    """max_t |E(t) − E(0)| shrinks at least like τ^p (RK4 is often faster: cancellations)."""
    make, order, tau0 = SCHEMES[scheme_name]
    model = load_scene(name)
    taus = tau0 * 0.5 ** np.arange(4)
    drifts = []
    for tau in taus:
        e = stabdae.integrate(model, None, law_for(model), make(), tau, T_END, 0.1)["energy"].values
        drifts.append(np.max(np.abs(e - e[0])))
    assert slope(taus, drifts) >= order - 0.2, drifts
    assert drifts[-1] < drifts[0]


def test_two_stage_first_order_when_2a_sigma_not_1():
    """2aσ ≠ 1 warns and the measured order drops to one (the paper's §5)."""
    with pytest.warns(UserWarning, match=r"2·a·σ = 1\.5 ≠ 1"):
        scheme = stabdae.two_stage(0.75, 1.0)
    assert scheme.order == 1
    model = load_scene("knife_edge")
    ref = reference_final_state("knife_edge", model)
    taus = 0.005 * 0.5 ** np.arange(4)
    errors = [
        np.max(np.abs(stabdae.integrate(model, None, law_for(model), scheme, tau, T_END, T_END)
                      ["x"].values[-1] - ref))
        for tau in taus
    ]  # fmt: skip
    assert abs(slope(taus, errors) - 1) <= 0.15


@pytest.mark.parametrize("tau", [0.1, 0.02])
def test_heun_step_is_heuns_map_of_the_right_hand_side(tau):
    """One step of ``heun`` is Heun's method, x₁ = x₀ + τ/2 (k₁ + k₂) with
    k₁ = F(t₀, x₀), k₂ = F(t₀ + τ, x₀ + τk₁), on a time-dependent model (F the stabilized
    right-hand side, called directly).  Any other second-order two-stage scheme (Ralston's
    a = 2/3, σ = 3/4, say) differs from it at order τ³."""
    model = load_scene("pendulum_varying_length")
    law = stabdae.baumgarte(5.0, 1.0)
    F = rhs_function(model, law)
    t0 = 0.3
    x0 = model.reference_state() + 1e-3
    ds = stabdae.integrate(model, x0, law, "heun", tau, t0 + tau, tau, t0=t0)
    k1 = F(t0, x0)
    k2 = F(t0 + tau, x0 + tau * k1)
    np.testing.assert_allclose(ds.x.values[1], x0 + 0.5 * tau * (k1 + k2), rtol=4e-15,
                               atol=1e-15)  # fmt: skip
    k2r = F(t0 + 2 * tau / 3, x0 + 2 * tau / 3 * k1)
    ralston = x0 + tau * (0.25 * k1 + 0.75 * k2r)
    assert np.abs(ds.x.values[1] - ralston).max() > 1e3 * np.abs(ralston).max() * 1e-15
