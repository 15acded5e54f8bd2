"""The heavy symmetric top of ``kernels/heavy_top.py`` as a spec: a unit quaternion with
body angular velocities and the norm's rate, ``q̇ = ½ p ⊗ (w, ω)``, the Lagrangian written
in the quasi-velocities; ``stabdae generate`` derives the equations in them (Hamel's
form), which must be the hand-written model's."""

import sympy as sp

from stabdae.symbolic import System

p0, p1, p2, p3 = sp.symbols("p0 p1 p2 p3")
w, wx, wy, wz = sp.symbols("w omega_x omega_y omega_z")
A, C, mgl, mu = sp.symbols("A C mgl mu")
half = sp.Rational(1, 2)
T = half * sp.Matrix([[p0, -p1, -p2, -p3], [p1, p0, -p3, p2], [p2, p3, p0, -p1],
                      [p3, -p2, p1, p0]])
norm2 = p0**2 + p1**2 + p2**2 + p3**2
r22 = (p0**2 - p1**2 - p2**2 + p3**2) / norm2
theta0 = sp.Rational(1, 2)
spin = 10
c = sp.cos(theta0)
rate = (C * spin - sp.sqrt((C * spin) ** 2 - 4 * A * mgl * c)) / (2 * A * c)

system = System(
    "heavy_top_generated",
    q=[p0, p1, p2, p3],
    v=[w, wx, wy, wz],
    kinematics=T,
    lagrangian=half * (mu * w**2 + A * (wx**2 + wy**2) + C * wz**2) - mgl * r22,
    holonomic=[norm2 - 1],
    params={A: 1.0, C: 0.5, mgl: 1.0, mu: 1.0},
    reference_state=[sp.cos(theta0 / 2), sp.sin(theta0 / 2), 0, 0,
                     0, 0, rate * sp.sin(theta0), spin],
    description=__doc__,
)
