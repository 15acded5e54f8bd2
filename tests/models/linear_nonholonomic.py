"""Two linear nonholonomic constraints on a free particle (n = 3, m = 0, k = 2).

    M = I,   γ = 0,   h = H v  with  H = [[3, 0, 0], [0, 2, 0]]

so that h_v = H and W = h_v h_vᵀ = diag(9, 4) are constant.  Under Theorem 5's law
ḣ = −k W L h the residual obeys that linear law exactly, h(t) = expm(−k W L t) h(0), and
Theorem 5's constants have closed forms: λ_min(W) = 4, w₀ = 2, and for a given L its
extreme eigenvalues l₁, l_m.
"""

from __future__ import annotations

import numpy as np
from numba import njit

import stabdae

H = np.array([[3.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
W = H @ H.T


@njit
def forces(t, q, v, p, out):
    out[0] = 0.0
    out[1] = 0.0
    out[2] = 0.0


@njit
def h(t, q, v, p, out):
    out[0] = 3.0 * v[0]
    out[1] = 2.0 * v[1]


@njit
def h_q(t, q, v, p, out):
    out[:, :] = 0.0


@njit
def h_v(t, q, v, p, out):
    out[:, :] = 0.0
    out[0, 0] = 3.0
    out[1, 1] = 2.0


model = stabdae.Model(
    "linear_nonholonomic",
    n=3,
    k=2,
    reference_state=np.array([0.1, -0.2, 0.3, 0.0, 0.0, 0.7]),
    forces=forces,
    h=h,
    h_q=h_q,
    h_v=h_v,
    coordinate_units="m",
    constraint_units=["m s-1", "m s-1"],
)
