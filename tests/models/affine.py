"""A test system whose constraints are affine in q, v and t (n = 3, m = 1, k = 1).

    f = q0 + 2 q1 − t/2 − 1,        h = v0 − 3 v2 + q1/5 − t/10

with nonlinear forces.  The residual g = (f, ḟ, h) is then affine in (x, t), so one
explicit Runge–Kutta step maps it exactly by the scheme's stability polynomial:
g_{k+1} = R(τÃ) g_k, up to roundoff (the discrete theory holds with equality).

``forced`` adds ``FORCING · t²/2`` to f.  Under Euler the step then makes the constant
remainder ``g_{k+1} − (I + τÃ) g_k = (FORCING τ²/2, 0, 0)`` (f picks up the t² term's
second-order part, ḟ and h stay affine in (x, t)): the setting of Theorem 6 with
constant forcing, in closed form.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

import stabdae


@njit
def forces(t, q, v, p, out):
    out[0] = math.sin(q[1])
    out[1] = math.sin(q[0]) + 0.5
    out[2] = -math.cos(q[0] * q[2])


@njit
def f(t, q, p, out):
    out[0] = q[0] + 2.0 * q[1] - 0.5 * t - 1.0


@njit
def f_q(t, q, p, out):
    out[0, 0] = 1.0
    out[0, 1] = 2.0
    out[0, 2] = 0.0


@njit
def f_t(t, q, p, out):
    out[0] = -0.5


@njit
def f_accel(t, q, v, p, out):
    out[0] = 0.0


@njit
def h(t, q, v, p, out):
    out[0] = v[0] - 3.0 * v[2] + 0.2 * q[1] - 0.1 * t


@njit
def h_q(t, q, v, p, out):
    out[0, 0] = 0.0
    out[0, 1] = 0.2
    out[0, 2] = 0.0


@njit
def h_v(t, q, v, p, out):
    out[0, 0] = 1.0
    out[0, 1] = 0.0
    out[0, 2] = -3.0


@njit
def h_t(t, q, v, p, out):
    out[0] = -0.1


model = stabdae.Model(
    "affine",
    n=3,
    m=1,
    k=1,
    reference_state=np.array([1.0, 0.0, 0.0, 0.5, 0.0, 0.5 / 3.0]),
    forces=forces,
    f=f,
    f_q=f_q,
    f_t=f_t,
    f_accel=f_accel,
    h=h,
    h_q=h_q,
    h_v=h_v,
    h_t=h_t,
)


#: the coefficient of t²/2 in the forced variant's f
FORCING = 0.04


@njit
def f_forced(t, q, p, out):
    out[0] = q[0] + 2.0 * q[1] - 0.5 * t - 1.0 + 0.5 * FORCING * t * t


@njit
def f_t_forced(t, q, p, out):
    out[0] = -0.5 + FORCING * t


@njit
def f_accel_forced(t, q, v, p, out):
    out[0] = FORCING


forced = model.replace(name="affine_forced", f=f_forced, f_t=f_t_forced,
                       f_accel=f_accel_forced)


#: the same system without its holonomic constraint (m = 0, k = 1): the residual is h
#: alone, and under ``ḣ = −k h`` one step maps it by the scalar ``R(−τk)``, so
#: ``‖g_k‖ e^{βt_k} = ‖α⁰‖`` at every step, with ``β = −ln |R(−τk)|/τ``
nonholonomic = stabdae.Model(
    "affine_nonholonomic",
    n=3,
    m=0,
    k=1,
    reference_state=np.array([1.0, 0.0, 0.0, 0.5, 0.0, 0.5 / 3.0]),
    forces=forces,
    h=h,
    h_q=h_q,
    h_v=h_v,
    h_t=h_t,
)
