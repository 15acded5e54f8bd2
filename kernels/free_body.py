"""Torque-free asymmetric rigid body near its intermediate axis (the tennis-racket or
Dzhanibekov flip), in a unit quaternion with body angular velocities (n = 4, m = 1).

Principal moments ``I₁ < I₂ < I₃`` about the centre of mass, no forces.  Orientation: the
quaternion ``p = q`` (body to world, scalar first) with ``|p|² = 1``; velocities
``v = (w, ω)``, the norm's rate and the body angular velocity, ``q̇ = ½ p ⊗ (w, ω)``
(:mod:`stabdae.rigid`); Euler's equations ``I ω̇ = −ω × Iω``.  The energy ``½ ωᵀIω`` and
the angular momentum in the world frame ``R I ω`` (three components) are first integrals.

The reference state spins at ω₂ = 2 rad/s about the intermediate axis with a small
ω₃ = 0.1 rad/s beside it: the spin axis flips over every half-period of the
elliptic-function solution (:func:`exact_omega`, 6.6 s here).
"""

import math

import numpy as np
from numba import njit

import stabdae
from stabdae import rigid

OMEGA0 = (0.0, 2.0, 0.1)  # body angular velocity at t = 0, rad/s


@njit(cache=True)
def kinematics(t, q, p, out):
    rigid.quaternion_map(q, 0, out)


@njit(cache=True)
def mass(t, q, p, out):
    out[:, :] = 0.0
    out[0, 0] = p[3]  # the norm's rate w: any positive inertia (it sets λ, not the motion)
    out[1, 1] = p[0]
    out[2, 2] = p[1]
    out[3, 3] = p[2]


@njit(cache=True)
def forces(t, q, v, p, out):
    # γ = ω × Iω (Euler's equations I ω̇ = −ω × Iω, no torque)
    i1, i2, i3 = p[0], p[1], p[2]
    wx, wy, wz = v[1], v[2], v[3]
    out[0] = 0.0
    out[1] = (i3 - i2) * wy * wz
    out[2] = (i1 - i3) * wz * wx
    out[3] = (i2 - i1) * wx * wy


@njit(cache=True)
def f(t, q, p, out):
    out[0] = rigid.norm(q, 0)


@njit(cache=True)
def f_q(t, q, p, out):
    rigid.norm_row(q, 0, out, 0)


@njit(cache=True)
def f_accel(t, q, v, p, out):
    out[0] = rigid.norm_accel(q, v, 0)


@njit(cache=True)
def energy(t, q, v, p):
    return 0.5 * (p[0] * v[1] * v[1] + p[1] * v[2] * v[2] + p[2] * v[3] * v[3])


def exact_omega(t, p):
    """The body angular velocity at times ``t`` from the Jacobi elliptic functions
    (Landau & Lifshitz, *Mechanics*, §37), for an initial ω with ω₁ = 0 and
    ``M² > 2E I₂``: ``ω = (a cn τ, b sn τ, c dn τ)``, ``τ = ν t + K(k)``; shape (len(t), 3).
    Also the flip's half-period ``2K/ν`` (the spin axis's turn from +e₂ to −e₂)."""
    from scipy.special import ellipj, ellipk

    i1, i2, i3 = p[0], p[1], p[2]
    w = np.asarray(OMEGA0)
    two_e = float(i1 * w[0] ** 2 + i2 * w[1] ** 2 + i3 * w[2] ** 2)
    m2 = float(i1**2 * w[0] ** 2 + i2**2 * w[1] ** 2 + i3**2 * w[2] ** 2)
    a = math.sqrt((two_e * i3 - m2) / (i1 * (i3 - i1)))
    b = math.sqrt((two_e * i3 - m2) / (i2 * (i3 - i2)))
    c = math.sqrt((m2 - two_e * i1) / (i3 * (i3 - i1)))
    nu = math.sqrt((i3 - i2) * (m2 - two_e * i1) / (i1 * i2 * i3))
    k2 = (i2 - i1) * (two_e * i3 - m2) / ((i3 - i2) * (m2 - two_e * i1))
    K = float(ellipk(k2))
    sn, cn, dn, _ = ellipj(nu * np.asarray(t, dtype=float) + K, k2)
    return np.stack([a * cn, b * sn, c * dn], axis=-1), 2.0 * K / nu


def reference_state(p):
    """Body frame = world frame at t = 0, ω = (0, 2, 0.1) rad/s, w = 0."""
    return np.concatenate([[1.0, 0.0, 0.0, 0.0], [0.0], OMEGA0])


model = stabdae.Model(
    "free_body",
    n=4,
    m=1,
    params={"I1": 1.0, "I2": 2.0, "I3": 3.0, "mu": 1.0},
    reference_state=reference_state,
    coordinates=["p0", "p1", "p2", "p3"],
    velocities=["w", "omega_x", "omega_y", "omega_z"],
    velocity_units="s-1",
    constraint_units=["1"],
    energy_units="kg m2 s-2",
    kinematics=kinematics,
    mass=mass,
    forces=forces,
    f=f,
    f_q=f_q,
    f_accel=f_accel,
    energy=energy,
    scales=[1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 1.0],
    description=__doc__,
)
