"""Bead on a circular hoop spinning about its vertical diameter at a constant rate Ω.

Unit point mass at q = (x, y, z), gravity g along −z.  The hoop (radius R, centre at the
origin) lies in the vertical plane through the z axis turned by the angle Ω t:

    f1 = x² + y² + z² − R²                  (on the sphere of the hoop)
    f2 = −sin(Ω t) x + cos(Ω t) y           (in the turning plane; time-dependent)

For Ω² R > g the bead has a relative equilibrium at cos θ* = g / (Ω² R), θ measured from
the bottom, where it turns with the hoop.  The energy function is the Jacobi integral
½ |v − Ω × r|² − ½ Ω² (x² + y²) + g z, which the exact motion conserves.
"""

import math

import numpy as np
from numba import njit

import stabdae

# p = [g, R, Omega]


@njit(cache=True)
def forces(t, q, v, p, out):
    out[0] = 0.0
    out[1] = 0.0
    out[2] = p[0]


@njit(cache=True)
def f(t, q, p, out):
    s, c = math.sin(p[2] * t), math.cos(p[2] * t)
    out[0] = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - p[1] * p[1]
    out[1] = -s * q[0] + c * q[1]


@njit(cache=True)
def f_q(t, q, p, out):
    s, c = math.sin(p[2] * t), math.cos(p[2] * t)
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]
    out[0, 2] = 2.0 * q[2]
    out[1, 0] = -s
    out[1, 1] = c
    out[1, 2] = 0.0


@njit(cache=True)
def f_t(t, q, p, out):
    om = p[2]
    s, c = math.sin(om * t), math.cos(om * t)
    out[0] = 0.0
    out[1] = -om * (c * q[0] + s * q[1])


@njit(cache=True)
def f_accel(t, q, v, p, out):
    om = p[2]
    s, c = math.sin(om * t), math.cos(om * t)
    out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    # (d/dt f_q2) v + d/dt f_t2 = −2Ω (c ẋ + s ẏ) + Ω² (s x − c y)
    out[1] = -2.0 * om * (c * v[0] + s * v[1]) + om * om * (s * q[0] - c * q[1])


@njit(cache=True)
def energy(t, q, v, p):
    om = p[2]
    ux, uy = v[0] + om * q[1], v[1] - om * q[0]  # v − Ω × r
    rel = 0.5 * (ux * ux + uy * uy + v[2] * v[2])
    return rel - 0.5 * om * om * (q[0] * q[0] + q[1] * q[1]) + p[0] * q[2]


def relative_equilibrium_angle(p):
    """θ* with cos θ* = g / (Ω² R) (0 when the hoop spins too slowly)."""
    g, R, om = p
    return math.acos(g / (om * om * R)) if om * om * R > g else 0.0


def relative_equilibrium(p, t):
    """Exact state at time t of the bead resting at θ* relative to the hoop."""
    g, R, om = p
    th = relative_equilibrium_angle(p)
    s, c = math.sin(om * t), math.cos(om * t)
    rho = R * math.sin(th)
    return np.array([rho * c, rho * s, -R * math.cos(th), -rho * om * s, rho * om * c, 0.0])


model = stabdae.Model(
    "hoop_bead",
    n=3,
    m=2,
    params={"g": 9.81, "R": 1.0, "Omega": 5.0},
    reference_state=lambda p: relative_equilibrium(p, 0.0),
    coordinates=["x", "y", "z"],
    coordinate_units="m",
    constraint_units=["m2", "m"],
    energy_units="m2 s-2",
    forces=forces,
    f=f,
    f_q=f_q,
    f_t=f_t,
    f_accel=f_accel,
    energy=energy,
    description=__doc__,
)
