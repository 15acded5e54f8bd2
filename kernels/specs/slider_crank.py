"""Rigid slider-crank near its dead centre (n = 3, m = 2), generated.

A crank of length r turns about the origin (angle phi, a uniform bar of mass m1); a
connecting rod of length l (angle psi, uniform, mass m2) joins the crank pin to a slider of
mass m3 that moves on the x axis (position xs).  Loop closure:

    r cos(phi) + l cos(psi) − xs = 0,      r sin(phi) + l sin(psi) = 0.

With r close to l the mechanism passes close to the folded dead-centre position at
phi = ±π/2: there the second row of f_q is (0, l cos(psi), 0) with cos(psi) =
√(1 − r²/l²) small, so S = F M⁻¹ Fᵀ is close to singular and the rod swings fast (r = l is
the bifurcation where S is singular).  No gravity: the energy is a first integral.
"""

import sympy as sp

from stabdae.symbolic import System, coordinates

(phi, psi, xs), (phi_dot, psi_dot, xs_dot) = coordinates("phi psi xs")
r, l, m1, m2, m3, w0 = sp.symbols("r l m1 m2 m3 w0")

# crank: inertia about the origin; rod: centre of mass velocity and inertia about it
crank = m1 * r**2 / 3 * phi_dot**2 / 2
rod_cx = -r * sp.sin(phi) * phi_dot - l / 2 * sp.sin(psi) * psi_dot
rod_cy = r * sp.cos(phi) * phi_dot + l / 2 * sp.cos(psi) * psi_dot
rod = m2 * (rod_cx**2 + rod_cy**2) / 2 + m2 * l**2 / 12 * psi_dot**2 / 2
slider = m3 * xs_dot**2 / 2

system = System(
    "slider_crank",
    q=[phi, psi, xs],
    v=[phi_dot, psi_dot, xs_dot],
    lagrangian=crank + rod + slider,
    holonomic=[r * sp.cos(phi) + l * sp.cos(psi) - xs, r * sp.sin(phi) + l * sp.sin(psi)],
    params={r: 0.99, l: 1.0, m1: 1.0, m2: 1.0, m3: 1.0, w0: 6.0},
    # stretched out (top dead centre of a normal crank), crank turning at w0
    reference_state=[0, 0, r + l, w0, -r * w0 / l, 0],
    coordinate_units=["rad", "rad", "m"],
    constraint_units=["m", "m"],
    energy_units="J",
    expand=True,  # the shipped scene was derived expanded; its numbers stay as they are
    description=__doc__,
)
