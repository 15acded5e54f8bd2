"""A particle on a torus under gravity (n = 3, m = 1): a particle on a surface whose
curvature changes sign, written for the tests as a user would write a model.

    f = (√(x² + y²) − R)² + z² − r²

Unit mass, gravity g along −z; it circles the ring and rolls over and under the tube.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

import stabdae

# p = [g, R, r]


@njit
def forces(t, q, v, p, out):
    out[0] = 0.0
    out[1] = 0.0
    out[2] = p[0]


@njit
def f(t, q, p, out):
    rho = math.sqrt(q[0] * q[0] + q[1] * q[1])
    out[0] = (rho - p[1]) ** 2 + q[2] * q[2] - p[2] * p[2]


@njit
def f_q(t, q, p, out):
    rho = math.sqrt(q[0] * q[0] + q[1] * q[1])
    c = 2.0 * (rho - p[1]) / rho
    out[0, 0] = c * q[0]
    out[0, 1] = c * q[1]
    out[0, 2] = 2.0 * q[2]


@njit
def f_accel(t, q, v, p, out):
    # vᵀ (∂²f/∂q²) v
    rho = math.sqrt(q[0] * q[0] + q[1] * q[1])
    w = q[1] * v[0] - q[0] * v[1]
    out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) - 2.0 * p[1] * w * w / rho**3


@njit
def energy(t, q, v, p):
    return 0.5 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + p[0] * q[2]


def _reference(p):
    """On the outer equator, moving round the ring and up over the tube."""
    g, R, r = p
    return np.array([R + r, 0.0, 0.0, 0.0, 1.5, 0.8])


model = stabdae.Model(
    "torus_particle",
    n=3,
    m=1,
    params={"g": 9.81, "R": 1.0, "r": 0.4},
    reference_state=_reference,
    coordinates=["x", "y", "z"],
    coordinate_units="m",
    constraint_units="m2",
    energy_units="m2 s-2",
    forces=forces,
    f=f,
    f_q=f_q,
    f_accel=f_accel,
    energy=energy,
    description=__doc__,
)
