"""Fekete problem: N unit charges on the unit sphere, damped (n = 3N, m = N; N = 20 here).

The points p_i ∈ R³ repel each other with the Coulomb force and are held on the sphere,
their motion damped at the rate a (the Test Set for IVP Solvers' formulation: Mazzia &
Magherini, problem "Fekete", with a = 1/2):

    p̈_i = Σ_{j≠i} (p_i − p_j) / |p_i − p_j|³ − a ṗ_i + 2 λ_i p_i,     f_i = |p_i|² − 1 = 0.

The constraints are independent, one per charge, so S = F M⁻¹ Fᵀ is diagonal; the model is
written for any N (the functions read N from their arrays' shapes): ``build(N)`` gives the
model of N charges, ``model`` is the one of 20.  The reference state is N points spread by
the golden-angle spiral, at rest; the charges then drift towards a Fekete configuration.
"""

import math

import numpy as np
from numba import njit

import stabdae


@njit(cache=True)
def forces(t, q, v, p, out):
    # γ = −Q: damping a v minus the Coulomb repulsion
    N = q.shape[0] // 3
    for i in range(N):
        for k in range(3):
            out[3 * i + k] = p[0] * v[3 * i + k]
    for i in range(N):
        for j in range(i + 1, N):
            d0 = q[3 * i] - q[3 * j]
            d1 = q[3 * i + 1] - q[3 * j + 1]
            d2 = q[3 * i + 2] - q[3 * j + 2]
            r2 = d0 * d0 + d1 * d1 + d2 * d2
            w = 1.0 / (r2 * math.sqrt(r2))
            out[3 * i] -= w * d0
            out[3 * i + 1] -= w * d1
            out[3 * i + 2] -= w * d2
            out[3 * j] += w * d0
            out[3 * j + 1] += w * d1
            out[3 * j + 2] += w * d2


@njit(cache=True)
def f(t, q, p, out):
    for i in range(out.shape[0]):
        out[i] = q[3 * i] ** 2 + q[3 * i + 1] ** 2 + q[3 * i + 2] ** 2 - 1.0


@njit(cache=True)
def f_q(t, q, p, out):
    out[:, :] = 0.0
    for i in range(out.shape[0]):
        for k in range(3):
            out[i, 3 * i + k] = 2.0 * q[3 * i + k]


@njit(cache=True)
def f_accel(t, q, v, p, out):
    # (d/dt f_q) v = 2 |ṗ_i|²
    for i in range(out.shape[0]):
        out[i] = 2.0 * (v[3 * i] ** 2 + v[3 * i + 1] ** 2 + v[3 * i + 2] ** 2)


def spiral(N: int) -> np.ndarray:
    """N points on the unit sphere along the golden-angle spiral, as (p_1, …, p_N)."""
    i = np.arange(N) + 0.5
    z = 1.0 - 2.0 * i / N
    r = np.sqrt(1.0 - z * z)
    phi = math.pi * (3.0 - math.sqrt(5.0)) * i
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z]).ravel()


def build(N: int) -> stabdae.Model:
    """The model of ``N`` charges."""

    def reference_state(p):
        return np.concatenate([spiral(N), np.zeros(3 * N)])

    return stabdae.Model(
        f"fekete_{N}",
        n=3 * N,
        m=N,
        params={"a": 0.5},
        reference_state=reference_state,
        coordinates=[f"{c}{i + 1}" for i in range(N) for c in "xyz"],
        coordinate_units=["1"] * (3 * N),
        constraint_units=["1"] * N,
        forces=forces,
        f=f,
        f_q=f_q,
        f_accel=f_accel,
        description=__doc__,
    )


model = build(20)
