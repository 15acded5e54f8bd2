"""Double pendulum in Cartesian coordinates (n = 4, m = 2).

Point masses m1 at (x1, y1) and m2 at (x2, y2) on massless rods of lengths l1 (pivot to
mass 1) and l2 (mass 1 to mass 2), gravity g along −y:

    L = ½ m1 (ẋ1² + ẏ1²) + ½ m2 (ẋ2² + ẏ2²) − g (m1 y1 + m2 y2)
    f1 = x1² + y1² − l1²,     f2 = (x2 − x1)² + (y2 − y1)² − l2².
"""

import math

import numpy as np
from numba import njit

import stabdae

# p = [m1, m2, l1, l2, g]


@njit(cache=True)
def mass(t, q, p, out):
    out[:, :] = 0.0
    out[0, 0] = p[0]
    out[1, 1] = p[0]
    out[2, 2] = p[1]
    out[3, 3] = p[1]


@njit(cache=True)
def forces(t, q, v, p, out):
    out[0] = 0.0
    out[1] = p[0] * p[4]
    out[2] = 0.0
    out[3] = p[1] * p[4]


@njit(cache=True)
def f(t, q, p, out):
    dx, dy = q[2] - q[0], q[3] - q[1]
    out[0] = q[0] * q[0] + q[1] * q[1] - p[2] * p[2]
    out[1] = dx * dx + dy * dy - p[3] * p[3]


@njit(cache=True)
def f_q(t, q, p, out):
    dx, dy = q[2] - q[0], q[3] - q[1]
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]
    out[0, 2] = 0.0
    out[0, 3] = 0.0
    out[1, 0] = -2.0 * dx
    out[1, 1] = -2.0 * dy
    out[1, 2] = 2.0 * dx
    out[1, 3] = 2.0 * dy


@njit(cache=True)
def f_accel(t, q, v, p, out):
    du, dw = v[2] - v[0], v[3] - v[1]
    out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1])
    out[1] = 2.0 * (du * du + dw * dw)


@njit(cache=True)
def energy(t, q, v, p):
    kinetic = 0.5 * p[0] * (v[0] ** 2 + v[1] ** 2) + 0.5 * p[1] * (v[2] ** 2 + v[3] ** 2)
    return kinetic + p[4] * (p[0] * q[1] + p[1] * q[3])


def reference_state(p):
    """Rod angles θ1 = 0.6, θ2 = −0.3 rad from the downward vertical, at rest."""
    l1, l2 = p[2], p[3]
    th1, th2 = 0.6, -0.3
    x1, y1 = l1 * math.sin(th1), -l1 * math.cos(th1)
    x2, y2 = x1 + l2 * math.sin(th2), y1 - l2 * math.cos(th2)
    return np.array([x1, y1, x2, y2, 0.0, 0.0, 0.0, 0.0])


model = stabdae.Model(
    "double_pendulum",
    n=4,
    m=2,
    params={"m1": 1.0, "m2": 1.0, "l1": 1.0, "l2": 1.0, "g": 9.81},
    reference_state=reference_state,
    coordinates=["x1", "y1", "x2", "y2"],
    coordinate_units="m",
    constraint_units=["m2", "m2"],
    energy_units="J",
    mass=mass,
    forces=forces,
    f=f,
    f_q=f_q,
    f_accel=f_accel,
    energy=energy,
    description=__doc__,
)
