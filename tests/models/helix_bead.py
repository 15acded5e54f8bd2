"""A bead sliding down a helix under gravity with linear drag (n = 3, m = 2): a particle
on a curve in space, written for the tests as a user would write a model.

    f1 = x² + y² − R²                      (on the cylinder of radius R)
    f2 = x sin(z/c) − y cos(z/c)           (at the helix's angle z/c on it)

Unit mass, gravity g along −z, drag −d·v.  The bead speeds up along the helix towards its
terminal speed; the constraint residual then decays at the law's rate over a floor that
moves with the motion.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

import stabdae

# p = [g, R, c, d]


@njit
def forces(t, q, v, p, out):
    # γ of M v̇ = Fᵀλ − γ: ∂V/∂q (V = g z) plus the drag's d·v
    out[0] = p[3] * v[0]
    out[1] = p[3] * v[1]
    out[2] = p[0] + p[3] * v[2]


@njit
def f(t, q, p, out):
    a = q[2] / p[2]
    out[0] = q[0] * q[0] + q[1] * q[1] - p[1] * p[1]
    out[1] = q[0] * math.sin(a) - q[1] * math.cos(a)


@njit
def f_q(t, q, p, out):
    a = q[2] / p[2]
    s, co = math.sin(a), math.cos(a)
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]
    out[0, 2] = 0.0
    out[1, 0] = s
    out[1, 1] = -co
    out[1, 2] = (q[0] * co + q[1] * s) / p[2]


@njit
def f_accel(t, q, v, p, out):
    a = q[2] / p[2]
    s, co = math.sin(a), math.cos(a)
    w = v[2] / p[2]
    out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1])
    out[1] = 2.0 * w * (co * v[0] + s * v[1]) + w * w * (q[1] * co - q[0] * s)


@njit
def energy(t, q, v, p):
    return 0.5 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + p[0] * q[2]


def _reference(p):
    g, R, c, d = p
    rate = 1.0  # dθ/dt at the start
    return np.array([R, 0.0, 0.0, 0.0, R * rate, c * rate])


model = stabdae.Model(
    "helix_bead",
    n=3,
    m=2,
    params={"g": 9.81, "R": 1.0, "c": 0.3, "d": 0.5},
    reference_state=_reference,
    coordinates=["x", "y", "z"],
    coordinate_units="m",
    constraint_units=["m2", "m"],
    energy_units="m2 s-2",
    forces=forces,
    f=f,
    f_q=f_q,
    f_accel=f_accel,
    energy=energy,
    description=__doc__,
)
