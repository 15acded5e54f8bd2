"""A particle on a paraboloid bowl under gravity (n = 3, m = 1): a particle on a curved
surface, written for the tests as a user would write a model.

    f = z − (x² + y²) / (2a)

Unit mass, gravity g along −z; it circles and rocks in the bowl.
"""

from __future__ import annotations

import numpy as np
from numba import njit

import stabdae

# p = [g, a]


@njit
def forces(t, q, v, p, out):
    # γ of M v̇ = Fᵀλ − γ: ∂V/∂q, V = g z
    out[0] = 0.0
    out[1] = 0.0
    out[2] = p[0]


@njit
def f(t, q, p, out):
    out[0] = q[2] - (q[0] * q[0] + q[1] * q[1]) / (2.0 * p[1])


@njit
def f_q(t, q, p, out):
    out[0, 0] = -q[0] / p[1]
    out[0, 1] = -q[1] / p[1]
    out[0, 2] = 1.0


@njit
def f_accel(t, q, v, p, out):
    out[0] = -(v[0] * v[0] + v[1] * v[1]) / p[1]


@njit
def energy(t, q, v, p):
    return 0.5 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + p[0] * q[2]


def _reference(p):
    """At radius 0.5 on the bowl, moving along it at 1.5 m/s (not a circular orbit: the
    radius rocks)."""
    g, a = p
    return np.array([0.5, 0.0, 0.25 / (2.0 * a), 0.0, 1.5, 0.0])


model = stabdae.Model(
    "bowl_particle",
    n=3,
    m=1,
    params={"g": 9.81, "a": 1.0},
    reference_state=_reference,
    coordinates=["x", "y", "z"],
    coordinate_units="m",
    constraint_units="m",
    energy_units="m2 s-2",
    forces=forces,
    f=f,
    f_q=f_q,
    f_accel=f_accel,
    energy=energy,
    description=__doc__,
)
