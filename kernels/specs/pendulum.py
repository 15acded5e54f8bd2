"""Planar pendulum in Cartesian coordinates (n = 2, m = 1, unit mass), generated.

A point of unit mass at q = (x, y) on a massless rod of length l, gravity g along −y.
The same system as the hand-written scene `kernels/pendulum.py`; the test suite checks
that the two agree in every function.
"""

import math

import sympy as sp

from stabdae.symbolic import System, coordinates

(x, y), (x_dot, y_dot) = coordinates("x y")
g, l = sp.symbols("g l")
theta0, omega0 = 0.5, 1.0  # the hand-written scene's reference swing

system = System(
    "pendulum_generated",
    q=[x, y],
    v=[x_dot, y_dot],
    lagrangian=(x_dot**2 + y_dot**2) / 2 - g * y,
    holonomic=[x**2 + y**2 - l**2],
    params={g: 9.81, l: 1.0},
    reference_state=[
        l * math.sin(theta0),
        -l * math.cos(theta0),
        l * omega0 * math.cos(theta0),
        l * omega0 * math.sin(theta0),
    ],
    coordinate_units=["m", "m"],
    constraint_units=["m2"],
    energy_units="m2 s-2",
    description=__doc__,
)
