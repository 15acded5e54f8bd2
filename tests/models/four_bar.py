"""A planar four-bar linkage in its three link angles (n = 3, m = 2): a closed loop,
written for the tests as a user would write a model.

The crank (length l1) turns about the origin O, the rocker (l3) about D = (d, 0), and the
coupler (l2) joins their free ends.  The loop closes where

    f1 = l1 cos θ1 + l2 cos θ2 − l3 cos θ3 − d
    f2 = l1 sin θ1 + l2 sin θ2 − l3 sin θ3

Uniform rods of masses m1, m2, m3 under gravity g along −y.  The crank and rocker turn
about their pivots (inertias m l²/3); the coupler's centre moves with the crank's end, so
the mass matrix couples θ1 and θ2: ``M12 = (m2 l1 l2 / 2) cos(θ1 − θ2)``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

import stabdae

# p = [g, d, l1, l2, l3, m1, m2, m3]


@njit
def mass(t, q, p, out):
    l1, l2, l3, m1, m2, m3 = p[2], p[3], p[4], p[5], p[6], p[7]
    out[0, 0] = m1 * l1 * l1 / 3.0 + m2 * l1 * l1
    out[0, 1] = 0.5 * m2 * l1 * l2 * math.cos(q[0] - q[1])
    out[0, 2] = 0.0
    out[1, 0] = out[0, 1]
    out[1, 1] = m2 * l2 * l2 / 3.0
    out[1, 2] = 0.0
    out[2, 0] = 0.0
    out[2, 1] = 0.0
    out[2, 2] = m3 * l3 * l3 / 3.0


@njit
def forces(t, q, v, p, out):
    # γ of M v̇ = Fᵀλ − γ: the coupler's velocity terms plus ∂V/∂q
    g, l1, l2, l3, m1, m2, m3 = p[0], p[2], p[3], p[4], p[5], p[6], p[7]
    a = 0.5 * m2 * l1 * l2 * math.sin(q[0] - q[1])
    out[0] = a * v[1] * v[1] + g * (0.5 * m1 + m2) * l1 * math.cos(q[0])
    out[1] = -a * v[0] * v[0] + g * 0.5 * m2 * l2 * math.cos(q[1])
    out[2] = g * 0.5 * m3 * l3 * math.cos(q[2])


@njit
def f(t, q, p, out):
    d, l1, l2, l3 = p[1], p[2], p[3], p[4]
    out[0] = l1 * math.cos(q[0]) + l2 * math.cos(q[1]) - l3 * math.cos(q[2]) - d
    out[1] = l1 * math.sin(q[0]) + l2 * math.sin(q[1]) - l3 * math.sin(q[2])


@njit
def f_q(t, q, p, out):
    l1, l2, l3 = p[2], p[3], p[4]
    out[0, 0] = -l1 * math.sin(q[0])
    out[0, 1] = -l2 * math.sin(q[1])
    out[0, 2] = l3 * math.sin(q[2])
    out[1, 0] = l1 * math.cos(q[0])
    out[1, 1] = l2 * math.cos(q[1])
    out[1, 2] = -l3 * math.cos(q[2])


@njit
def f_accel(t, q, v, p, out):
    l1, l2, l3 = p[2], p[3], p[4]
    a, b, c = v[0] * v[0], v[1] * v[1], v[2] * v[2]
    out[0] = -l1 * math.cos(q[0]) * a - l2 * math.cos(q[1]) * b + l3 * math.cos(q[2]) * c
    out[1] = -l1 * math.sin(q[0]) * a - l2 * math.sin(q[1]) * b + l3 * math.sin(q[2]) * c


@njit
def energy(t, q, v, p):
    g, l1, l2, l3, m1, m2, m3 = p[0], p[2], p[3], p[4], p[5], p[6], p[7]
    kinetic = 0.5 * ((m1 / 3.0 + m2) * l1 * l1 * v[0] * v[0] + m2 * l2 * l2 / 3.0 * v[1] * v[1]
                     + m3 * l3 * l3 / 3.0 * v[2] * v[2]) \
        + 0.5 * m2 * l1 * l2 * math.cos(q[0] - q[1]) * v[0] * v[1]
    potential = g * ((0.5 * m1 + m2) * l1 * math.sin(q[0]) + 0.5 * m2 * l2 * math.sin(q[1])
                     + 0.5 * m3 * l3 * math.sin(q[2]))
    return kinetic + potential


def _reference(p):
    """The loop closed at a crank angle of 1 rad (the coupler and rocker from the circles'
    upper intersection), the crank turning at 2 rad/s."""
    g, d, l1, l2, l3 = p[:5]
    theta1 = 1.0
    B = np.array([l1 * math.cos(theta1), l1 * math.sin(theta1)])
    D = np.array([d, 0.0])
    r = np.linalg.norm(D - B)
    along = (l2 * l2 - l3 * l3 + r * r) / (2 * r)
    e = (D - B) / r
    C = B + along * e + math.sqrt(l2 * l2 - along * along) * np.array([-e[1], e[0]])
    theta2 = math.atan2(C[1] - B[1], C[0] - B[0])
    theta3 = math.atan2(C[1] - D[1], C[0] - D[0])
    w1 = 2.0
    Fq = np.array([[-l2 * math.sin(theta2), l3 * math.sin(theta3)],
                   [l2 * math.cos(theta2), -l3 * math.cos(theta3)]])  # fmt: skip
    w23 = np.linalg.solve(Fq, -w1 * np.array([-l1 * math.sin(theta1), l1 * math.cos(theta1)]))
    return np.array([theta1, theta2, theta3, w1, w23[0], w23[1]])


model = stabdae.Model(
    "four_bar",
    n=3,
    m=2,
    params={"g": 9.81, "d": 1.0, "l1": 0.4, "l2": 1.0, "l3": 0.8, "m1": 1.0, "m2": 2.0,
            "m3": 1.5},
    reference_state=_reference,
    coordinates=["theta1", "theta2", "theta3"],
    coordinate_units="rad",
    constraint_units="m",
    energy_units="J",
    mass=mass,
    forces=forces,
    f=f,
    f_q=f_q,
    f_accel=f_accel,
    energy=energy,
    description=__doc__,
)
