"""Knife edge (a skate) on an inclined plane: nonholonomic, with gravity.

Coordinates q = (x, y, φ) of the contact point (x downhill) and the blade's heading; mass m,
moment of inertia J about the vertical through the contact point, plane inclined at α:

    L = ½ m (ẋ² + ẏ²) + ½ J φ̇² + m g sin α x
    h = sin φ ẋ − cos φ ẏ = 0        (the contact point moves along the blade)

Then φ = φ0 + ω t and the speed along the blade u obeys u̇ = g sin α cos φ, which
integrate in closed form (see `exact_solution`).  Constant mass matrix diag(m, m, J).
"""

import math

import numpy as np
from numba import njit

import stabdae

# p = [m, J, g, alpha]


@njit(cache=True)
def mass(t, q, p, out):
    out[:, :] = 0.0
    out[0, 0] = p[0]
    out[1, 1] = p[0]
    out[2, 2] = p[1]


@njit(cache=True)
def forces(t, q, v, p, out):
    # γ = ∂V/∂q with V = −m g sin α x
    out[0] = -p[0] * p[2] * math.sin(p[3])
    out[1] = 0.0
    out[2] = 0.0


@njit(cache=True)
def h(t, q, v, p, out):
    out[0] = math.sin(q[2]) * v[0] - math.cos(q[2]) * v[1]


@njit(cache=True)
def h_q(t, q, v, p, out):
    out[0, 0] = 0.0
    out[0, 1] = 0.0
    out[0, 2] = math.cos(q[2]) * v[0] + math.sin(q[2]) * v[1]


@njit(cache=True)
def h_v(t, q, v, p, out):
    out[0, 0] = math.sin(q[2])
    out[0, 1] = -math.cos(q[2])
    out[0, 2] = 0.0


@njit(cache=True)
def energy(t, q, v, p):
    m, J, g, alpha = p[0], p[1], p[2], p[3]
    return 0.5 * m * (v[0] ** 2 + v[1] ** 2) + 0.5 * J * v[2] ** 2 - m * g * math.sin(alpha) * q[0]


U0, OMEGA = 0.5, 1.5  # initial speed along the blade and turning rate


def reference_state(p):
    """At the origin, blade along x, moving at u0 and turning at ω."""
    return np.array([0.0, 0.0, 0.0, U0, 0.0, OMEGA])


def exact_solution(p, t, u0=U0, omega=OMEGA, x0=0.0, y0=0.0, phi0=0.0):
    """Exact (x, y, φ, ẋ, ẏ, φ̇) at times t (array), for ω ≠ 0.

    With G = g sin α, φ = φ0 + ω t, u = u0 + (G/ω)(sin φ − sin φ0), c0 = u0 − G sin φ0 / ω:
    x = x0 + c0 (sin φ − sin φ0)/ω + G (sin² φ − sin² φ0)/(2ω²)
    y = y0 + c0 (cos φ0 − cos φ)/ω + G [(φ − φ0)/2 − (sin 2φ − sin 2φ0)/4]/ω².
    """
    G = p[2] * math.sin(p[3])
    t = np.asarray(t, dtype=float)
    phi = phi0 + omega * t
    sp, cp, s0, c0_ = np.sin(phi), np.cos(phi), math.sin(phi0), math.cos(phi0)
    u = u0 + (G / omega) * (sp - s0)
    c0 = u0 - G * s0 / omega
    x = x0 + c0 * (sp - s0) / omega + G * (sp**2 - s0**2) / (2 * omega**2)
    y = y0 + c0 * (c0_ - cp) / omega
    y = y + G * ((phi - phi0) / 2 - (np.sin(2 * phi) - math.sin(2 * phi0)) / 4) / omega**2
    return np.stack([x, y, phi, u * cp, u * sp, np.full_like(phi, omega)], axis=-1)


model = stabdae.Model(
    "knife_edge",
    n=3,
    k=1,
    params={"m": 1.0, "J": 0.1, "g": 9.81, "alpha": 0.3},
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
