"""Parallelogram four-bar linkage with one redundant constraint (n = 4, m = 4), generated.

Two equal cranks of length l turn about the fixed pivots A = (0, 0) and B = (d, 0); a
coupler of length d joins their tips P1 = (x1, y1) and P2 = (x2, y2), where point masses m
sit; gravity g along −y.  The three rod constraints make a one-degree-of-freedom
mechanism; the fourth, y2 − y1 = 0 (the coupler stays horizontal), is implied by them on
the parallelogram branch, so the rows of F are dependent along the whole motion and
S = F M⁻¹ Fᵀ is singular.  By default stabdae stops with status SINGULAR_S; with
`multiplier="lstsq"` it takes the least-squares (pseudo-inverse) multiplier and goes on.
"""

import math

import sympy as sp

from stabdae.symbolic import System, coordinates

(x1, y1, x2, y2), (x1_dot, y1_dot, x2_dot, y2_dot) = coordinates("x1 y1 x2 y2")
m, g, l, d = sp.symbols("m g l d")
theta0, rate0 = 1.0, 1.0  # crank angle from +x and its rate

system = System(
    "four_bar_redundant",
    q=[x1, y1, x2, y2],
    v=[x1_dot, y1_dot, x2_dot, y2_dot],
    lagrangian=m * (x1_dot**2 + y1_dot**2 + x2_dot**2 + y2_dot**2) / 2 - m * g * (y1 + y2),
    holonomic=[
        x1**2 + y1**2 - l**2,  # crank A–P1
        (x2 - x1) ** 2 + (y2 - y1) ** 2 - d**2,  # coupler P1–P2
        (x2 - d) ** 2 + y2**2 - l**2,  # crank B–P2
        y2 - y1,  # redundant: implied by the three above on the parallelogram branch
    ],
    params={m: 1.0, g: 9.81, l: 1.0, d: 2.0},
    reference_state=[
        l * math.cos(theta0), l * math.sin(theta0),
        d + l * math.cos(theta0), l * math.sin(theta0),
        -l * rate0 * math.sin(theta0), l * rate0 * math.cos(theta0),
        -l * rate0 * math.sin(theta0), l * rate0 * math.cos(theta0),
    ],
    coordinate_units=["m"] * 4,
    constraint_units=["m2", "m2", "m2", "m"],
    energy_units="J",
    expand=True,  # the shipped scene was derived expanded; its numbers stay as they are
    description=__doc__,
)
