"""Stiff flyball governor of the IFToMM multibody benchmark library (problem A05), generated.

A vertical shaft turns at angle ψ; two rods of length L hang from hinges A and B at height
h on either side of it (at ± a from its axis), each carrying a point mass at its tip
P_i = (x_i, y_i, z_i); a slider at height s runs along the shaft and turns with it; two
stiff spring-dampers (stiffness K, damping C, rest length l0) join the slider's sides (± e
from the axis) to the rods' midpoints.  Gravity g along −z.  The benchmark's data: shaft
and rods 1.0 × 0.01 × 0.01 m and slider 0.1 m a side, of density 3000 kg/m³ (0.3 kg, 0.3 kg
and 3 kg), point masses 5 kg, K = 8e5 N/m, C = 4e4 N s/m, l0 = 0.5 m; it starts with the
slider at s = 0.5 m, the rods 30° below the horizontal (the springs at their rest length)
and the shaft turning at 2π rad/s, and runs 10 s.  Hinges at a = 0.05 m and springs on
the slider's faces (e = 0.05 m) and at the rods' midpoints.

Coordinates: ψ, s and the two tips' positions (n = 8).  Constraints: each rod's length
|P_i − A_i(ψ)| = L, and each tip in the plane that contains the shaft and turns with it
(the hinge's axis is perpendicular to that plane), −x_i sin ψ + y_i cos ψ = 0 (m = 4),
leaving ψ, s and the two rods' angles.  The rods are slender (their cross-section's share
of their inertia, 1e-4 of it, is left out); the shaft's and the slider's turning inertia
about the axis are those of the benchmark's prisms.  The springs and dampers make the
system stiff (K and C against masses of 3 to 5 kg): RK4 runs at τ = 2.5e-4 s and stops
at 5e-4 s whatever the law.

Nothing turns the system about the axis from outside, so its angular momentum about z,
L_z = ξ(q)ᵀ M(q) v with ξ = (1, 0, −y1, x1, 0, −y2, x2, 0) (a turn of the whole), is a
first integral of the exact motion, off the constraint manifold too (the constraints and
the springs are unchanged by the turn): the test suite holds integrations to it.
"""

import math

import sympy as sp

from stabdae.symbolic import System, coordinates

q, v = coordinates("psi s x1 y1 z1 x2 y2 z2")
psi, s, x1, y1, z1, x2, y2, z2 = q
psi_dot, s_dot = v[0], v[1]
names = "m_rod m_ball m_slider J_shaft J_slider g K C l0 L h a e"
m_rod, m_ball, m_slider, J_shaft, J_slider, g, K, C, l0, L, h, a, e = sp.symbols(names)

c, sn = sp.cos(psi), sp.sin(psi)
hinges = [sp.Matrix([a * c, a * sn, h]), sp.Matrix([-a * c, -a * sn, h])]
sides = [sp.Matrix([e * c, e * sn, s]), sp.Matrix([-e * c, -e * sn, s])]
tips = [sp.Matrix([x1, y1, z1]), sp.Matrix([x2, y2, z2])]
tip_vel = [sp.Matrix(v[2:5]), sp.Matrix(v[5:8])]


def time_derivative(expr):
    return sum(sp.diff(expr, qi) * vi for qi, vi in zip(q, v))


kinetic = (J_shaft + J_slider) * psi_dot**2 / 2 + m_slider * s_dot**2 / 2
potential = m_slider * g * s
springs = []
for A, E, P, Pd in zip(hinges, sides, tips, tip_vel):
    Ad = A.applyfunc(time_derivative)
    # a slender rod from A to P: m/6 (|Ȧ|² + Ȧ·Ṗ + |Ṗ|²)
    kinetic += m_rod / 6 * (Ad.dot(Ad) + Ad.dot(Pd) + Pd.dot(Pd)) + m_ball * Pd.dot(Pd) / 2
    potential += m_rod * g * (A[2] + P[2]) / 2 + m_ball * g * P[2]
    length = sp.sqrt((A + (P - A) / 2 - E).dot(A + (P - A) / 2 - E))
    potential += K * (length - l0) ** 2 / 2
    springs.append(length)

# the dampers: Q = −C ḋ ∇d for each spring's length d
damping = [sum(-C * time_derivative(d) * sp.diff(d, qj) for d in springs) for qj in q]

alpha, omega0 = math.radians(30.0), 2.0 * math.pi
reach, drop = a + L * math.cos(alpha), h - L * math.sin(alpha)  # the tips at the start
system = System(
    "flyball_governor",
    q=q,
    v=v,
    lagrangian=kinetic - potential,
    holonomic=[
        (tips[0] - hinges[0]).dot(tips[0] - hinges[0]) - L**2,
        (tips[1] - hinges[1]).dot(tips[1] - hinges[1]) - L**2,
        -x1 * sn + y1 * c,
        -x2 * sn + y2 * c,
    ],
    forces=damping,
    params={m_rod: 0.3, m_ball: 5.0, m_slider: 3.0, J_shaft: 5e-6, J_slider: 5e-3, g: 9.81,
            K: 8e5, C: 4e4, l0: 0.5, L: 1.0, h: 1.0, a: 0.05, e: 0.05},
    # ψ = 0, s = 0.5, rods 30° below the horizontal, everything turning at 2π rad/s
    reference_state=[0.0, 0.5, reach, 0.0, drop, -reach, 0.0, drop,
                     omega0, 0.0, 0.0, omega0 * reach, 0.0, 0.0, -omega0 * reach, 0.0],
    coordinate_units=["rad", "m", "m", "m", "m", "m", "m", "m"],
    constraint_units=["m2", "m2", "m", "m"],
    energy_units="J",
    simplify=False,
    expand=False,
    description=__doc__,
)
