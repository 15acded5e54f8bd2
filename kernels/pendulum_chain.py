"""A chain of N planar pendulums (n = 2N, m = N; N = 8 here).

N point masses m_i = m hang from the origin, each joined to the one before by a massless
rod of length l; gravity pulls in −y.  Coordinates p_i = (x_i, y_i); the constraints are
the rods' lengths:

    f_1 = |p_1|² − l²,      f_i = |p_i − p_{i−1}|² − l²   (i = 2 … N).

Each constraint touches the two masses it joins (the first only its own), so F = f_q has
at most four non-zeros per row and S = F M⁻¹ Fᵀ is tridiagonal: its L D Lᵀ factor has no
fill, and the cost of the stabilized right-hand side's constraint part grows like N, not
N³.  The model is written for any N (the functions read N from their arrays' shapes):
``build(N)`` gives the chain of N masses, ``model`` the one of 8.  The reference state is
the chain stretched straight at 60° from the downward vertical, at rest.
"""

import math

import numpy as np
from numba import njit

import stabdae


@njit(cache=True)
def mass(t, q, p, out):
    out[:, :] = 0.0
    for i in range(q.shape[0]):
        out[i, i] = p[0]


@njit(cache=True)
def forces(t, q, v, p, out):
    # γ = −Q: gravity on every mass
    for i in range(q.shape[0] // 2):
        out[2 * i] = 0.0
        out[2 * i + 1] = p[0] * p[2]


@njit(cache=True)
def f(t, q, p, out):
    x0 = y0 = 0.0
    for i in range(out.shape[0]):
        dx, dy = q[2 * i] - x0, q[2 * i + 1] - y0
        out[i] = dx * dx + dy * dy - p[1] * p[1]
        x0, y0 = q[2 * i], q[2 * i + 1]


@njit(cache=True)
def f_q(t, q, p, out):
    out[:, :] = 0.0
    x0 = y0 = 0.0
    for i in range(out.shape[0]):
        dx, dy = q[2 * i] - x0, q[2 * i + 1] - y0
        out[i, 2 * i] = 2.0 * dx
        out[i, 2 * i + 1] = 2.0 * dy
        if i > 0:
            out[i, 2 * i - 2] = -2.0 * dx
            out[i, 2 * i - 1] = -2.0 * dy
        x0, y0 = q[2 * i], q[2 * i + 1]


@njit(cache=True)
def f_accel(t, q, v, p, out):
    # (d/dt f_q) v = 2 |v_i − v_{i−1}|²
    u0 = w0 = 0.0
    for i in range(out.shape[0]):
        du, dw = v[2 * i] - u0, v[2 * i + 1] - w0
        out[i] = 2.0 * (du * du + dw * dw)
        u0, w0 = v[2 * i], v[2 * i + 1]


@njit(cache=True)
def energy(t, q, v, p):
    e = 0.0
    for i in range(q.shape[0] // 2):
        e += 0.5 * p[0] * (v[2 * i] ** 2 + v[2 * i + 1] ** 2) + p[0] * p[2] * q[2 * i + 1]
    return e


def build(N: int) -> stabdae.Model:
    """The chain of ``N`` masses."""

    def reference_state(p):
        s = np.arange(1, N + 1) * p[1]
        q = np.column_stack([s * math.sin(math.pi / 3), -s * math.cos(math.pi / 3)]).ravel()
        return np.concatenate([q, np.zeros(2 * N)])

    return stabdae.Model(
        f"pendulum_chain_{N}",
        n=2 * N,
        m=N,
        params={"m": 1.0, "l": 1.0, "g": 9.81},
        reference_state=reference_state,
        coordinates=[f"{c}{i + 1}" for i in range(N) for c in "xy"],
        coordinate_units="m",
        constraint_units=["m2"] * N,
        energy_units="J",
        mass=mass,
        forces=forces,
        f=f,
        f_q=f_q,
        f_accel=f_accel,
        energy=energy,
        description=__doc__,
    )


model = build(8)
