"""Double pendulum in Cartesian coordinates (n = 4, m = 2), generated.

Point masses m1 at (x1, y1) and m2 at (x2, y2) on massless rods of lengths l1 (pivot to
mass 1) and l2 (mass 1 to mass 2), gravity g along −y.  The same system as the
hand-written scene `kernels/double_pendulum.py`.
"""

import math

import sympy as sp

from stabdae.symbolic import System, coordinates

(x1, y1, x2, y2), (x1_dot, y1_dot, x2_dot, y2_dot) = coordinates("x1 y1 x2 y2")
m1, m2, l1, l2, g = sp.symbols("m1 m2 l1 l2 g")

kinetic = m1 * (x1_dot**2 + y1_dot**2) / 2 + m2 * (x2_dot**2 + y2_dot**2) / 2
potential = g * (m1 * y1 + m2 * y2)

th1, th2 = 0.6, -0.3  # rod angles from the downward vertical, at rest (as the scene)
system = System(
    "double_pendulum_generated",
    q=[x1, y1, x2, y2],
    v=[x1_dot, y1_dot, x2_dot, y2_dot],
    lagrangian=kinetic - potential,
    holonomic=[x1**2 + y1**2 - l1**2, (x2 - x1) ** 2 + (y2 - y1) ** 2 - l2**2],
    params={m1: 1.0, m2: 1.0, l1: 1.0, l2: 1.0, g: 9.81},
    reference_state=[
        l1 * math.sin(th1),
        -l1 * math.cos(th1),
        l1 * math.sin(th1) + l2 * math.sin(th2),
        -l1 * math.cos(th1) - l2 * math.cos(th2),
        0, 0, 0, 0,
    ],
    coordinate_units=["m"] * 4,
    constraint_units=["m2", "m2"],
    energy_units="J",
    description=__doc__,
)
