"""A bead on a straight horizontal wire that turns at a constant rate Ω about the vertical
axis through the origin (n = 2, m = 1; no force along the wire).

    f = −sin(Ω t) x + cos(Ω t) y          (on the wire at angle Ω t; time-dependent)

Relative to the wire the bead is flung outwards: its distance from the axis grows as
r(t) = r₀ cosh(Ω t) from rest, and with it the state and the truncation error of any
scheme (a floor that rises with the motion, not an instability of the constraint law).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

import stabdae

# p = [Omega]


@njit
def forces(t, q, v, p, out):
    out[0] = 0.0
    out[1] = 0.0


@njit
def f(t, q, p, out):
    s, c = math.sin(p[0] * t), math.cos(p[0] * t)
    out[0] = -s * q[0] + c * q[1]


@njit
def f_q(t, q, p, out):
    s, c = math.sin(p[0] * t), math.cos(p[0] * t)
    out[0, 0] = -s
    out[0, 1] = c


@njit
def f_t(t, q, p, out):
    om = p[0]
    s, c = math.sin(om * t), math.cos(om * t)
    out[0] = -om * (c * q[0] + s * q[1])


@njit
def f_accel(t, q, v, p, out):
    om = p[0]
    s, c = math.sin(om * t), math.cos(om * t)
    # (d/dt f_q) v + d/dt f_t
    out[0] = -2.0 * om * (c * v[0] + s * v[1]) + om * om * (s * q[0] - c * q[1])


def radius(p, t, r0=1.0):
    """The bead's exact distance from the axis, from rest relative to the wire at r0."""
    return r0 * math.cosh(p[0] * t)


model = stabdae.Model(
    "wire_bead",
    n=2,
    m=1,
    params={"Omega": 1.0},
    reference_state=lambda p: np.array([1.0, 0.0, 0.0, p[0]]),
    coordinates=["x", "y"],
    coordinate_units="m",
    constraint_units="m",
    forces=forces,
    f=f,
    f_q=f_q,
    f_t=f_t,
    f_accel=f_accel,
    description=__doc__,
)
