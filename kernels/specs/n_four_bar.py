"""N-four-bar mechanism of the IFToMM multibody benchmark library (problem A02), generated.

N = 4 four-bar windows side by side: N + 1 cranks turn about the fixed pivots
A_i = (i·l, 0), i = 0 … N, and N couplers join their tips B_i = (x_i, y_i); all 2N + 1
links are uniform rods of length l and mass m, under gravity g along −y.  The coordinates
are the tips' positions, 2N + 2 of them; the 2N + 1 rod-length constraints leave one
degree of freedom, and the mass matrix of the couplers couples neighbouring tips (a
block-tridiagonal M).  The benchmark starts with the cranks upright and B_0 moving along +x
at 1 m/s; the links (1 m, 1 kg, g = 9.81 m/s²) are the benchmark's, and it defines the
problem for any N (its published data use a larger N).

Each time the cranks pass the horizontal, every rod lies on the x-axis: the rows of the
constraint Jacobian F all point along x, F has rank N + 1 instead of 2N + 1, and the
mechanism's degrees of freedom jump from 1 to N + 1 for an instant.  S = F M⁻¹ Fᵀ is
singular there and ill-conditioned near it; `multiplier="lstsq"` takes the least-squares
(pseudo-inverse) multiplier through those positions.

On the parallelogram branch every crank keeps the angle φ of the first, and the motion
reduces to the one-degree-of-freedom equation I φ̈ = −k cos φ with I = m l² (N + 1)/3 +
N m l² and k = m g l (N + 1)/2 + N m g l; from φ = π/2 with φ̇ = −(1 m/s)/l the mechanism
turns over and over, through a singular position every half turn.  The test suite holds
the generated model to that equation, solved to 1e-12.
"""

import sympy as sp

from stabdae.symbolic import System, coordinates

N = 4  # four-bar windows
names = [f"x{i}" for i in range(N + 1)] + [f"y{i}" for i in range(N + 1)]
q, v = coordinates(names)
x, y = q[: N + 1], q[N + 1 :]
xd, yd = v[: N + 1], v[N + 1 :]
m, g, l = sp.symbols("m g l")


def rod(a_dot, b_dot):
    """Kinetic energy of a uniform rod whose ends move at a_dot and b_dot."""
    return m / 6 * sum(a * a + a * b + b * b for a, b in zip(a_dot, b_dot))


cranks = sum(rod((0, 0), (xd[i], yd[i])) - m * g * y[i] / 2 for i in range(N + 1))
couplers = sum(
    rod((xd[i], yd[i]), (xd[i + 1], yd[i + 1])) - m * g * (y[i] + y[i + 1]) / 2
    for i in range(N)
)

system = System(
    "n_four_bar",
    q=q,
    v=v,
    lagrangian=cranks + couplers,
    holonomic=[(x[i] - i * l) ** 2 + y[i] ** 2 - l**2 for i in range(N + 1)]
    + [(x[i + 1] - x[i]) ** 2 + (y[i + 1] - y[i]) ** 2 - l**2 for i in range(N)],
    params={m: 1.0, g: 9.81, l: 1.0},
    # cranks upright, every tip moving along +x at 1 m/s
    reference_state=[i * l for i in range(N + 1)] + [l] * (N + 1) + [1.0] * (N + 1)
    + [0.0] * (N + 1),
    coordinate_units=["m"] * (2 * N + 2),
    constraint_units=["m2"] * (2 * N + 1),
    energy_units="J",
    expand=True,  # the shipped scene was derived expanded; its numbers stay as they are
    description=__doc__,
)
