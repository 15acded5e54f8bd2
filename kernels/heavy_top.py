"""Heavy symmetric top (Lagrange top) in a unit quaternion with body angular velocities
(n = 4, m = 1).

A rigid body with a fixed point on its symmetry axis, its centre of mass at distance l up
that axis, inertia ``diag(A, A, C)`` about the fixed point in its body frame, gravity along
−z.  Orientation: the quaternion ``p = q`` (body to world, scalar first) with the one
holonomic constraint ``|p|² = 1``; velocities: ``v = (w, ω)``, the norm's rate and the
body angular velocity, with the kinematic map ``q̇ = ½ p ⊗ (w, ω)`` (:mod:`stabdae.rigid`)::

    A ω̇x = (A − C) ωy ωz + mgl R₂₁,   A ω̇y = (C − A) ωx ωz − mgl R₂₀,   C ω̇z = 0

(Euler's equations with the gravity torque ``l e₃ × Rᵀ(−mg e_z)``, R the rotation of
``p/|p|``).  Energy ``½ ωᵀIω + mgl R₂₂``, the vertical momentum ``(R I ω)·e_z`` and the
axial one ``C ωz`` are first integrals.

The reference state is a steady precession: the axis at θ₀ = 0.5 rad from the upward
vertical, spinning with ωz = 10 rad/s about it and precessing about the vertical at the
slow root Ω of ``A Ω² cos θ₀ − C ωz Ω + mgl = 0``, so that the axis stays at θ₀ and turns
about e_z at the constant rate Ω (:func:`precession_rate`, :func:`exact_axis`).
"""

import math

import numpy as np
from numba import njit

import stabdae
from stabdae import rigid

THETA0 = 0.5  # the axis's tilt from the upward vertical, rad
SPIN = 10.0  # ωz, rad/s


@njit(cache=True)
def kinematics(t, q, p, out):
    rigid.quaternion_map(q, 0, out)


@njit(cache=True)
def mass(t, q, p, out):
    A, C, mu = p[0], p[1], p[3]
    out[:, :] = 0.0
    out[0, 0] = mu  # the norm's rate w: any positive inertia (it sets λ, not the motion)
    out[1, 1] = A
    out[2, 2] = A
    out[3, 3] = C


@njit(cache=True)
def forces(t, q, v, p, out):
    # γ = ω × Iω − τ, τ = mgl (R₂₁, −R₂₀, 0) the gravity torque in the body frame
    A, C, mgl = p[0], p[1], p[2]
    r20, r21, r22 = rigid.vertical(q, 0)
    wx, wy, wz = v[1], v[2], v[3]
    out[0] = 0.0
    out[1] = (C - A) * wy * wz - mgl * r21
    out[2] = (A - C) * wx * wz + mgl * r20
    out[3] = 0.0


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
    A, C, mgl = p[0], p[1], p[2]
    r20, r21, r22 = rigid.vertical(q, 0)
    return 0.5 * (A * (v[1] * v[1] + v[2] * v[2]) + C * v[3] * v[3]) + mgl * r22


def precession_rate(p) -> float:
    """The slow steady-precession rate Ω at tilt θ₀ and spin ωz (the smaller root of
    ``A Ω² cos θ₀ − C ωz Ω + mgl = 0``)."""
    A, C, mgl = p[0], p[1], p[2]
    c = math.cos(THETA0)
    return (C * SPIN - math.sqrt((C * SPIN) ** 2 - 4.0 * A * mgl * c)) / (2.0 * A * c)


def exact_axis(t, p):
    """The symmetry axis in the world frame at times ``t`` of the steady precession from
    the reference state: at θ₀ from the vertical, turning about it at Ω; shape
    (len(t), 3)."""
    t = np.asarray(t, dtype=float)
    th, om = THETA0, precession_rate(p)
    return np.stack([np.sin(th) * np.sin(om * t), -np.sin(th) * np.cos(om * t),
                     np.full_like(t, np.cos(th))], axis=1)


def reference_state(p):
    """The steady precession: tilted by θ₀ about the world x axis, ω = (0, Ω sin θ₀, ωz)."""
    om = precession_rate(p)
    quat = rigid.quaternion_about([1.0, 0.0, 0.0], THETA0)
    return np.concatenate([quat, [0.0, 0.0, om * math.sin(THETA0), SPIN]])


model = stabdae.Model(
    "heavy_top",
    n=4,
    m=1,
    params={"A": 1.0, "C": 0.5, "mgl": 1.0, "mu": 1.0},
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
    scales=[1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, SPIN],
    description=__doc__,
)
