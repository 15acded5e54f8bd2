"""Planar pendulum in Cartesian coordinates (n = 2, m = 1, unit mass).

A point of unit mass at q = (x, y) on a massless rod of length l, gravity g along −y:

    L = ½ (ẋ² + ẏ²) − g y,     f(q) = x² + y² − l² = 0.

With unit mass the mass matrix is the identity, so it is omitted (no factorization).
"""

import math

import numpy as np
from numba import njit

import stabdae


@njit(cache=True)
def forces(t, q, v, p, out):
    # γ = ∂V/∂q with V = g y
    out[0] = 0.0
    out[1] = p[0]


@njit(cache=True)
def f(t, q, p, out):
    out[0] = q[0] * q[0] + q[1] * q[1] - p[1] * p[1]


@njit(cache=True)
def f_q(t, q, p, out):
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]


@njit(cache=True)
def f_accel(t, q, v, p, out):
    # (d/dt f_q) v = 2 (ẋ² + ẏ²)
    out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1])


@njit(cache=True)
def energy(t, q, v, p):
    return 0.5 * (v[0] * v[0] + v[1] * v[1]) + p[0] * q[1]


def reference_state(p):
    """At angle θ₀ = 0.5 rad from the downward vertical, swinging with θ̇₀ = 1 rad/s."""
    l, th, om = p[1], 0.5, 1.0
    return np.array(
        [l * math.sin(th), -l * math.cos(th), l * om * math.cos(th), l * om * math.sin(th)]
    )


model = stabdae.Model(
    "pendulum",
    n=2,
    m=1,
    params={"g": 9.81, "l": 1.0},
    reference_state=reference_state,
    coordinates=["x", "y"],
    coordinate_units=["m", "m"],
    constraint_units=["m2"],
    energy_units="m2 s-2",
    forces=forces,
    f=f,
    f_q=f_q,
    f_accel=f_accel,
    energy=energy,
    description=__doc__,
)
