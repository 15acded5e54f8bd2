"""model.check(): finite differences catch wrong derivative pieces and name them."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

import stabdae
from conftest import SCENES, load_scene
from models.toy import X_REF, unit_pendulum

KNIFE = load_scene("knife_edge")


@pytest.mark.parametrize("name", SCENES)
def test_scenes_pass_check(name):
    report = load_scene(name).check(states=3)
    assert report.ok, str(report)
    assert {row.piece for row in report.rows} >= ({"f_q", "f_accel"} if "f" in
        load_scene(name).functions else {"h_q", "h_v"})  # fmt: skip





@njit
def f_q_wrong(t, q, p, out):
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = q[1]  # should be 2 y



@njit
def f_accel_wrong(t, q, v, p, out):
    out[0] = v[0] * v[0] + v[1] * v[1]  # factor 2 missing


@njit
def f_moving(t, q, p, out):
    out[0] = q[0] * q[0] + q[1] * q[1] - (1.0 + 0.1 * t) ** 2


@njit
def mass_indefinite(t, q, p, out):
    out[0, 0] = 1.0
    out[0, 1] = 0.0
    out[1, 0] = 0.0
    out[1, 1] = -1.0


@njit
def mass_asymmetric(t, q, p, out):
    out[0, 0] = 1.0
    out[0, 1] = 0.5
    out[1, 0] = 0.0
    out[1, 1] = 1.0




def pendulum(**overrides):
    return unit_pendulum("test_pendulum", **overrides)


def test_check_names_wrong_f_q():
    report = pendulum(f_q=f_q_wrong).check()
    assert not report.ok
    assert "f_q" in report.failures
    assert "pieces that disagree: f_q" in str(report)


def test_check_names_wrong_f_accel():
    report = pendulum(f_accel=f_accel_wrong).check()
    assert report.failures == ["f_accel"]


def test_check_names_missing_time_derivative():
    """f depends on t but the model declares no f_t: f_t (and f_accel) disagree."""
    model = pendulum(f=f_moving, reference_state=X_REF)
    assert "f_t" in model.check().failures


def test_check_mass_matrix():
    assert pendulum(mass=mass_indefinite).check().failures == ["mass"]
    # an asymmetric mass matrix is refused when the model is built (only the lower
    # triangle would be read); check() still tests symmetry at its other states
    with pytest.raises(stabdae.ModelError, match="not symmetric at the reference state"):
        pendulum(mass=mass_asymmetric)


def test_check_nonholonomic_pieces():
    """A wrong h_q in the knife edge is caught and named."""

    @njit
    def h_q_wrong(t, q, v, p, out):
        out[0, 0] = 0.0
        out[0, 1] = 0.0
        out[0, 2] = np.cos(q[2]) * v[0]  # missing + sin φ ẏ

    fns = dict(KNIFE.functions)
    fns["h_q"] = h_q_wrong
    model = stabdae.Model("knife_wrong", 3, 0, 1, params=KNIFE.params,
                          reference_state=KNIFE.reference_state, **fns)  # fmt: skip
    assert model.check().failures == ["h_q"]


@njit
def f_q_writes_far_out(t, q, p, out):
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]
    if q[0] > 0.0:  # away from the reference state (x = 0) only
        out[1, 0] = 0.0  # a row that does not exist


def test_check_probes_every_state_with_bounds_checks():
    """A write outside out that only happens away from the reference state passes Model()'s
    probe; model.check() runs every piece at its other states as Python first, with
    bounds checks, and names the piece and the state instead of corrupting memory."""
    from models.toy import unit_pendulum

    model = unit_pendulum("far_out", f_q=f_q_writes_far_out)  # reference state x = 0
    with pytest.raises(stabdae.ModelError, match=r"f_q\(t, q, p, out\) at check state \d+ "
                                                 r"writes outside out"):  # fmt: skip
        model.check(states=6, radius=0.5)


C_SMALL = 1e-3  # the constraint in small units: f = c (x² + y² − 1)


@njit
def f_small(t, q, p, out):
    out[0] = C_SMALL * (q[0] * q[0] + q[1] * q[1] - 1.0)


@njit
def f_q_small(t, q, p, out):
    out[0, 0] = C_SMALL * 2.0 * q[0]
    out[0, 1] = C_SMALL * 2.0 * q[1]


@njit
def f_accel_small(t, q, v, p, out):
    out[0] = C_SMALL * 2.0 * (v[0] * v[0] + v[1] * v[1])


@njit
def f_accel_small_sign(t, q, v, p, out):
    out[0] = C_SMALL * 2.0 * (v[0] * v[0] - v[1] * v[1])  # the sign of ẏ² wrong


def _dp_sign_error():
    """The shipped double pendulum (at rest in its reference state) with the sign of one
    velocity-squared term of its f_accel wrong."""
    dp = load_scene("double_pendulum")

    @njit
    def f_accel_sign(t, q, v, p, out):
        du, dw = v[2] - v[0], v[3] - v[1]
        out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1])
        out[1] = 2.0 * (du * du - dw * dw)  # should be + dw²

    fns = {**dp.functions, "f_accel": f_accel_sign}
    return stabdae.Model("dp_sign", dp.n, dp.m, dp.k, params=dp.params,
                         reference_state=dp.reference_state, **fns)  # fmt: skip


def test_check_catches_a_sign_error_in_a_velocity_squared_term_at_every_state():
    """Velocities at the scale of the model's motion and errors relative to each piece's
    own size: a sign error in a velocity-squared term of f_accel disagrees at every
    sampled state, in a constraint of small units (f = 1e-3 (x² + y² − 1): with velocities
    of 0.01 and a tolerance of at least 1e-6, its error of 4e-7 ẏ² passed at some states)
    and in the shipped double pendulum (its reference state is at rest, where a
    velocity-squared term is zero whatever its sign, so the reference state agrees).  The
    correct pieces agree everywhere: no false alarm from the relative tolerance."""
    small = pendulum(f=f_small, f_q=f_q_small, f_accel=f_accel_small_sign,
                     reference_state=np.array([0.0, -1.0, 0.0, 0.0]))  # fmt: skip
    for model in (small, _dp_sign_error()):
        for seed in range(3):
            report = model.check(states=4, seed=seed)
            bad = {r.state for r in report.rows if r.piece == "f_accel" and not r.ok}
            assert bad == {1, 2, 3, 4}, str(report)
    good = pendulum(f=f_small, f_q=f_q_small, f_accel=f_accel_small,
                    reference_state=np.array([0.0, -1.0, 0.0, 0.0]))  # fmt: skip
    for seed in range(3):
        assert good.check(states=4, seed=seed).ok
    assert load_scene("double_pendulum").check(states=4).ok
