"""Bricard's mechanism of the IFToMM multibody benchmark library (problem A04), generated.

Five rods of length L and mass m (square cross-section of side a) and a fixed sixth link
close a loop through six revolute joints.  In the starting position the joints sit at
corners of a cube of side L, J0 = (0, 0, 0), J1 = (L, 0, 0), J2 = (L, −L, 0),
J3 = (L, −L, L), J4 = (0, −L, L), J5 = (0, 0, L), the fixed link runs from J5 to J0, and
each joint's axis is perpendicular to both links it joins (J0's along y, J1's along z,
J2's along x, J3's along y, J4's along z, J5's along x).  Gravity g along −y; the
benchmark's rods are 1 m, 1 kg, a = 0.1 m.  Here the mechanism starts from rest in that
position (the benchmark's own initial velocity is not restated).

Coordinates: the rods' vectors r_i = J_i − J_(i−1), i = 1 … 5 (n = 15).  Each rod carries
the axis of the joint at its start, w_(i−1), and of the joint at its end,
w_i = r_i × w_(i−1) / L (w_0 = ŷ is the ground's); the rod's frame (r_i/L, w_(i−1), w_i)
gives its joints' axes.  The rods turn with the moment m (L² + a²)/12 across them; their
spin about their own axes (m a²/6, 2 % of it) is left out, which keeps the generated code
small.  Constraints (m = 15): each rod's length, each rod perpendicular
to the axis at its start, the loop's closure Σ r_i = J5 − J0, and the last axis w_5 along
the ground's x.  Grübler's count gives no motion at all (15 coordinates, 15 constraints),
yet the mechanism moves with one degree of freedom: one constraint is redundant all along
the motion, F has rank 14 and S = F M⁻¹ Fᵀ is singular.  `multiplier="lstsq"` integrates
it; the default L D Lᵀ solve stops with status SINGULAR_S.  The energy (no dissipation)
is a first integral.
"""

import sympy as sp

from stabdae.symbolic import System, coordinates

names = [f"{c}{i}" for i in range(1, 6) for c in "xyz"]
q, v = coordinates(names)
m, g, L, a = sp.symbols("m g L a")
rods = [sp.Matrix(q[3 * i : 3 * i + 3]) for i in range(5)]
rates = [sp.Matrix(v[3 * i : 3 * i + 3]) for i in range(5)]


def time_derivative(expr):
    return sum(sp.diff(expr, qi) * vi for qi, vi in zip(q, v))


axes = [sp.Matrix([0, 1, 0])]  # w_0: the ground's axis at J0
for r in rods:
    axes.append(r.cross(axes[-1]) / L)

J_turn = m * (L**2 + a**2) / 12  # about an axis across the rod, through its centre
kinetic, potential = 0, 0
start, start_rate = sp.zeros(3, 1), sp.zeros(3, 1)  # J_(i−1) and its velocity
for r, rd in zip(rods, rates):
    centre_rate = start_rate + rd / 2
    # turning across the rod: |ω × e1|² = |ė1|² = |ṙ|²/L² (e1 = r/L).  The spin about the
    # rod's own axis (moment m a²/6, 2 % of the one across) is left out: through the
    # nested axes it made the generated forces 1500 lines and the model's load 14 s
    kinetic += (m * centre_rate.dot(centre_rate) + J_turn * rd.dot(rd) / L**2) / 2
    potential += m * g * (start[1] + r[1] / 2)
    start, start_rate = start + r, start_rate + rd

closure = sum(rods, sp.zeros(3, 1)) - sp.Matrix([0, 0, L])
system = System(
    "bricard",
    q=q,
    v=v,
    lagrangian=kinetic - potential,
    holonomic=[r.dot(r) - L**2 for r in rods]
    + [rods[i].dot(axes[i]) for i in range(5)]
    + list(closure)
    + [axes[5][1], axes[5][2]],
    params={m: 1.0, g: 9.81, L: 1.0, a: 0.1},
    # the cube's edges, at rest
    reference_state=[L, 0, 0, 0, -L, 0, 0, 0, L, -L, 0, 0, 0, L, 0] + [0.0] * 15,
    coordinate_units=["m"] * 15,
    constraint_units=["m2"] * 5 + ["m"] * 5 + ["m"] * 3 + ["1"] * 2,
    energy_units="J",
    simplify=False,
    expand=False,
    description=__doc__,
)
