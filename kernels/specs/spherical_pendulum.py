"""Spherical pendulum in Cartesian coordinates (n = 3, m = 1), generated.

A point mass m at q = (x, y, z) on a massless rod of length l from a pivot at the origin,
gravity g along −z:

    L = ½ m (ẋ² + ẏ² + ż²) − m g z,     f = x² + y² + z² − l² = 0.

The reference state is a conical motion: the rod at θ0 from the downward vertical, the mass
circling at the rate Ω = √(g / (l cos θ0)) that keeps θ constant.  The model file
`kernels/spherical_pendulum.py` is generated from this spec by
`stabdae generate kernels/specs/spherical_pendulum.py -o kernels/spherical_pendulum.py`;
it has no hand-written counterpart.
"""

import sympy as sp

from stabdae.symbolic import System, coordinates

(x, y, z), (x_dot, y_dot, z_dot) = coordinates("x y z")
m, g, l = sp.symbols("m g l")

theta0 = sp.Rational(1, 2)  # rad from the downward vertical
rate = sp.sqrt(g / (l * sp.cos(theta0)))  # conical pendulum: θ stays at θ0

system = System(
    "spherical_pendulum",
    q=[x, y, z],
    v=[x_dot, y_dot, z_dot],
    lagrangian=m * (x_dot**2 + y_dot**2 + z_dot**2) / 2 - m * g * z,
    holonomic=[x**2 + y**2 + z**2 - l**2],
    params={m: 1.0, g: 9.81, l: 1.0},
    reference_state=[
        l * sp.sin(theta0), 0, -l * sp.cos(theta0),
        0, l * sp.sin(theta0) * rate, 0,
    ],
    coordinate_units=["m", "m", "m"],
    constraint_units=["m2"],
    energy_units="J",
    expand=True,  # the shipped scene was derived expanded; its numbers stay as they are
    description=__doc__,
)
