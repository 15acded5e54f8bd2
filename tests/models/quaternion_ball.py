"""A ball rolling without slipping on a plane, its orientation a unit quaternion with
body angular velocities: n = 6, m = 1 (the quaternion's norm), k = 2 (rolling).

q = (x, y, p0, p1, p2, p3), v = (ẋ, ẏ, w, ωx, ωy, ωz); the kinematic map is the identity
on (x, y) and ``½ p ⊗ (w, ω)`` on the quaternion.  Rolling: the contact point is at rest,
``(ẋ, ẏ, 0) + Ω × (0, 0, −r) = 0`` with Ω the angular velocity in the world frame, here
``R_h ω`` with ``R_h = |p|² R(p/|p|)`` (quadratic in p, equal to R on the manifold)::

    h = (ẋ − r (R_h ω)_y,  ẏ + r (R_h ω)_x)

so ``h_q`` is not zero: the velocity products ``h_q T v`` of the stabilized equations
are exercised.  Isotropic inertia J, no gyroscopic terms; the energy is a first integral.
"""

import numpy as np
from numba import njit

import stabdae
from stabdae import rigid

# p = [mb, J, r, mu]


@njit(cache=True)
def kinematics(t, q, p, out):
    out[:, :] = 0.0
    out[0, 0] = 1.0
    out[1, 1] = 1.0
    rigid.quaternion_map(q, 2, out)


@njit(cache=True)
def mass(t, q, p, out):
    out[:, :] = 0.0
    out[0, 0] = p[0]
    out[1, 1] = p[0]
    out[2, 2] = p[3]
    out[3, 3] = p[1]
    out[4, 4] = p[1]
    out[5, 5] = p[1]


@njit(cache=True)
def forces(t, q, v, p, out):
    out[:] = 0.0


@njit(cache=True)
def f(t, q, p, out):
    out[0] = rigid.norm(q, 2)


@njit(cache=True)
def f_q(t, q, p, out):
    out[0, 0] = 0.0
    out[0, 1] = 0.0
    rigid.norm_row(q, 2, out, 0)


@njit(cache=True)
def f_accel(t, q, v, p, out):
    out[0] = rigid.norm_accel(q, v, 2)


@njit(cache=True)
def _rows(q):
    """The first two rows of R_h and their gradients in p (2·Q p of each quadratic form)."""
    p0, p1, p2, p3 = q[2], q[3], q[4], q[5]
    r0 = (p0 * p0 + p1 * p1 - p2 * p2 - p3 * p3, 2.0 * (p1 * p2 - p0 * p3),
          2.0 * (p1 * p3 + p0 * p2))
    r1 = (2.0 * (p1 * p2 + p0 * p3), p0 * p0 - p1 * p1 + p2 * p2 - p3 * p3,
          2.0 * (p2 * p3 - p0 * p1))
    d0 = ((2 * p0, 2 * p1, -2 * p2, -2 * p3), (-2 * p3, 2 * p2, 2 * p1, -2 * p0),
          (2 * p2, 2 * p3, 2 * p0, 2 * p1))
    d1 = ((2 * p3, 2 * p2, 2 * p1, 2 * p0), (2 * p0, -2 * p1, 2 * p2, -2 * p3),
          (-2 * p1, -2 * p0, 2 * p3, 2 * p2))
    return r0, r1, d0, d1


@njit(cache=True)
def h(t, q, v, p, out):
    r = p[2]
    r0, r1, d0, d1 = _rows(q)
    wx, wy, wz = v[3], v[4], v[5]
    out[0] = v[0] - r * (r1[0] * wx + r1[1] * wy + r1[2] * wz)
    out[1] = v[1] + r * (r0[0] * wx + r0[1] * wy + r0[2] * wz)


@njit(cache=True)
def h_q(t, q, v, p, out):
    r = p[2]
    r0, r1, d0, d1 = _rows(q)
    wx, wy, wz = v[3], v[4], v[5]
    out[:, :] = 0.0
    for c in range(4):
        out[0, 2 + c] = -r * (d1[0][c] * wx + d1[1][c] * wy + d1[2][c] * wz)
        out[1, 2 + c] = r * (d0[0][c] * wx + d0[1][c] * wy + d0[2][c] * wz)


@njit(cache=True)
def h_v(t, q, v, p, out):
    r = p[2]
    r0, r1, d0, d1 = _rows(q)
    out[:, :] = 0.0
    out[0, 0] = 1.0
    out[1, 1] = 1.0
    for j in range(3):
        out[0, 3 + j] = -r * r1[j]
        out[1, 3 + j] = r * r0[j]


@njit(cache=True)
def energy(t, q, v, p):
    return 0.5 * p[0] * (v[0] * v[0] + v[1] * v[1]) + 0.5 * p[1] * (
        v[3] * v[3] + v[4] * v[4] + v[5] * v[5])


def reference_state(p):
    """Turned by 0.3 rad about (1, 2, 2), rolling with Ω = (0.4, −0.8, 1.5) rad/s in the
    world frame: ω = Rᵀ Ω, (ẋ, ẏ) = r (Ω_y, −Ω_x)."""
    r = p[2]
    quat = rigid.quaternion_about([1.0, 2.0, 2.0], 0.3)
    R = np.empty((3, 3))
    rigid.rotation(quat, 0, R)
    big = np.array([0.4, -0.8, 1.5])
    return np.concatenate([[0.0, 0.0], quat, [r * big[1], -r * big[0], 0.0], R.T @ big])


model = stabdae.Model(
    "quaternion_ball", n=6, m=1, k=2,
    params={"mb": 1.0, "J": 0.4, "r": 1.0, "mu": 1.0},
    reference_state=reference_state,
    coordinates=["x", "y", "p0", "p1", "p2", "p3"],
    velocities=["x_dot", "y_dot", "w", "omega_x", "omega_y", "omega_z"],
    kinematics=kinematics, mass=mass, forces=forces, f=f, f_q=f_q, f_accel=f_accel,
    h=h, h_q=h_q, h_v=h_v, energy=energy,
)
