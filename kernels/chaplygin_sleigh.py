"""Chaplygin sleigh: a rigid body on a plane with a knife edge at its contact point.

Coordinates q = (x, y, φ): the contact point P and the heading.  The centre of mass lies a
distance a ahead of P on the body axis; mass m, moment of inertia I about the centre of
mass, J = I + m a² about P.  No potential.  The knife edge forbids sideways motion of P:

    h = s_h (−sin φ ẋ + cos φ ẏ) = 0          (one nonholonomic constraint, k = 1)

(s_h scales the constraint row: W = h_v h_vᵀ = s_h², used by Theorem 5 studies.)
With u = cos φ ẋ + sin φ ẏ and ω = φ̇ the motion obeys u̇ = a ω², J ω̇ = −m a u ω,
which integrate in closed form (see `exact_solution`).  The mass matrix depends on φ.
"""

import math

import numpy as np
from numba import njit

import stabdae

# p = [m, I, a, s_h]


@njit(cache=True)
def mass(t, q, p, out):
    m, inertia, a = p[0], p[1], p[2]
    s, c = math.sin(q[2]), math.cos(q[2])
    out[0, 0] = m
    out[0, 1] = 0.0
    out[0, 2] = -m * a * s
    out[1, 0] = 0.0
    out[1, 1] = m
    out[1, 2] = m * a * c
    out[2, 0] = -m * a * s
    out[2, 1] = m * a * c
    out[2, 2] = inertia + m * a * a


@njit(cache=True)
def forces(t, q, v, p, out):
    # Christoffel terms of T = ½ m |ṙ_G|² + ½ I φ̇², r_G = (x + a cos φ, y + a sin φ)
    m, a = p[0], p[2]
    w2 = v[2] * v[2]
    out[0] = -m * a * math.cos(q[2]) * w2
    out[1] = -m * a * math.sin(q[2]) * w2
    out[2] = 0.0


@njit(cache=True)
def h(t, q, v, p, out):
    out[0] = p[3] * (-math.sin(q[2]) * v[0] + math.cos(q[2]) * v[1])


@njit(cache=True)
def h_q(t, q, v, p, out):
    out[0, 0] = 0.0
    out[0, 1] = 0.0
    out[0, 2] = -p[3] * (math.cos(q[2]) * v[0] + math.sin(q[2]) * v[1])


@njit(cache=True)
def h_v(t, q, v, p, out):
    out[0, 0] = -p[3] * math.sin(q[2])
    out[0, 1] = p[3] * math.cos(q[2])
    out[0, 2] = 0.0


@njit(cache=True)
def energy(t, q, v, p):
    m, inertia, a = p[0], p[1], p[2]
    s, c = math.sin(q[2]), math.cos(q[2])
    gx, gy = v[0] - a * s * v[2], v[1] + a * c * v[2]
    return 0.5 * m * (gx * gx + gy * gy) + 0.5 * inertia * v[2] * v[2]


U0, OMEGA0 = 0.5, 2.0  # initial forward speed of P and turning rate


def reference_state(p):
    """At the origin, heading along x, moving forward at u0 while turning at ω0."""
    return np.array([0.0, 0.0, 0.0, U0, 0.0, OMEGA0])


def exact_solution(p, t, u0=U0, omega0=OMEGA0, phi0=0.0):
    """Closed form of (u, ω, φ) at times t (array), from u(0) = u0, ω(0) = ω0, φ(0) = φ0.

    With J = I + m a², energy E = ½ m u² + ½ J ω², u∞ = √(2E/m) and κ = a m u∞ / J:
    u = u∞ tanh θ, ω = ±u∞ √(m/J) sech θ, θ = κ t + artanh(u0/u∞), and
    φ = φ0 ± (u∞ √(m/J) / κ) (gd θ − gd θ(0)) with gd θ = atan(sinh θ).
    """
    m, inertia, a = p[0], p[1], p[2]
    J = inertia + m * a * a
    t = np.asarray(t, dtype=float)
    u_inf = math.sqrt(u0 * u0 + J * omega0 * omega0 / m)
    kappa = a * m * u_inf / J
    th0 = math.atanh(u0 / u_inf)
    th = kappa * t + th0
    w_max = math.copysign(u_inf * math.sqrt(m / J), omega0)
    u = u_inf * np.tanh(th)
    omega = w_max / np.cosh(th)
    phi = phi0 + (w_max / kappa) * (np.arctan(np.sinh(th)) - math.atan(math.sinh(th0)))
    return u, omega, phi


model = stabdae.Model(
    "chaplygin_sleigh",
    n=3,
    k=1,
    params={"m": 1.0, "I": 0.2, "a": 0.5, "s_h": 1.0},
    reference_state=reference_state,
    coordinates=["x", "y", "phi"],
    coordinate_units=["m", "m", "rad"],
    constraint_units=["m s-1"],
    energy_units="J",
    mass=mass,
    forces=forces,
    h=h,
    h_q=h_q,
    h_v=h_v,
    energy=energy,
    description=__doc__,
)
