"""Pendulum whose length is prescribed in time (time-dependent holonomic constraint).

Unit point mass at q = (x, y), gravity g along −y, rod length driven as

    l(t) = l0 (1 + ε sin Ω t),      f(q, t) = x² + y² − l(t)².

The constraint depends on t explicitly, so the model supplies f_t = −2 l l̇ and includes
d/dt f_t in f_accel.  Energy is not conserved (the drive does work), so none is given.
"""

import math

import numpy as np
from numba import njit

import stabdae

# p = [g, l0, eps, Omega]


@njit(cache=True)
def _length(t, p):
    """l, l̇, l̈ at time t."""
    l0, eps, om = p[1], p[2], p[3]
    s, c = math.sin(om * t), math.cos(om * t)
    return l0 * (1.0 + eps * s), l0 * eps * om * c, -l0 * eps * om * om * s


@njit(cache=True)
def forces(t, q, v, p, out):
    out[0] = 0.0
    out[1] = p[0]


@njit(cache=True)
def f(t, q, p, out):
    l, _, _ = _length(t, p)
    out[0] = q[0] * q[0] + q[1] * q[1] - l * l


@njit(cache=True)
def f_q(t, q, p, out):
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]


@njit(cache=True)
def f_t(t, q, p, out):
    l, ldot, _ = _length(t, p)
    out[0] = -2.0 * l * ldot


@njit(cache=True)
def f_accel(t, q, v, p, out):
    # (d/dt f_q) v + d/dt f_t = 2 |v|² − 2 (l̇² + l l̈)
    l, ldot, lddot = _length(t, p)
    out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1]) - 2.0 * (ldot * ldot + l * lddot)


def reference_state(p):
    """At t = 0: angle 0.4 rad, angular rate 0, radial speed l̇(0)."""
    l0, eps, om = p[1], p[2], p[3]
    th, thdot = 0.4, 0.0
    ldot = l0 * eps * om
    er = np.array([math.sin(th), -math.cos(th)])
    et = np.array([math.cos(th), math.sin(th)])
    return np.concatenate([l0 * er, ldot * er + l0 * thdot * et])


model = stabdae.Model(
    "pendulum_varying_length",
    n=2,
    m=1,
    params={"g": 9.81, "l0": 1.0, "eps": 0.1, "Omega": 3.0},
    reference_state=reference_state,
    coordinates=["x", "y"],
    coordinate_units="m",
    constraint_units=["m2"],
    forces=forces,
    f=f,
    f_q=f_q,
    f_t=f_t,
    f_accel=f_accel,
    description=__doc__,
)
