"""Chaplygin sleigh (n = 3, k = 1), generated.

A rigid body on a plane with a knife edge at its contact point P = (x, y), heading φ; the
centre of mass lies a distance a ahead of P on the body axis; mass m, moment of inertia I
about the centre of mass.  The knife edge forbids sideways motion of P (the row scaled by
s_h).  The same system as the hand-written scene `kernels/chaplygin_sleigh.py`.
"""

import sympy as sp

from stabdae.symbolic import System, coordinates

(x, y, phi), (x_dot, y_dot, phi_dot) = coordinates("x y phi")
m, I, a, s_h = sp.symbols("m I a s_h")

# velocity of the centre of mass r_G = (x + a cos φ, y + a sin φ)
gx = x_dot - a * sp.sin(phi) * phi_dot
gy = y_dot + a * sp.cos(phi) * phi_dot

system = System(
    "chaplygin_sleigh_generated",
    q=[x, y, phi],
    v=[x_dot, y_dot, phi_dot],
    lagrangian=m * (gx**2 + gy**2) / 2 + I * phi_dot**2 / 2,
    nonholonomic=[s_h * (-sp.sin(phi) * x_dot + sp.cos(phi) * y_dot)],
    params={m: 1.0, I: 0.2, a: 0.5, s_h: 1.0},
    # at the origin, heading along x, moving forward at 0.5 while turning at 2 rad/s
    reference_state=[0, 0, 0, 0.5, 0, 2.0],
    coordinate_units=["m", "m", "rad"],
    constraint_units=["m s-1"],
    energy_units="J",
    description=__doc__,
)
