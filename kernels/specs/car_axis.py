"""Car axis (n = 4, m = 2, time-dependent constraint), generated.

The Test Set for IVP Solvers' problem "caraxis" (Rentrop, Roche & Steinebach): an axis of
length L carries a wheel at each end, (xl, yl) and (xr, yr), each of mass
k = M ε²/2 and held by a spring of rest length L0; the left wheel rolls over the
ground, the right one is driven over a bump so that the axis end B = (xb(t), yb(t)) with
yb = r sin(ωt) prescribes the left wheel's line (f1 = xb xl + yb yl = 0).  Parameters
and the initial state are the Test Set's; its reference solution at t = 3 is in the test
suite.
"""

import sympy as sp

from stabdae.symbolic import System, coordinates, t

(xl, yl, xr, yr), (xl_dot, yl_dot, xr_dot, yr_dot) = coordinates("xl yl xr yr")
eps, M, L, L0, r, w, g = sp.symbols("eps M L L0 r w g")

k = M * eps**2 / 2  # the wheels' mass
yb = r * sp.sin(w * t)
xb = sp.sqrt(L**2 - yb**2)
left = sp.sqrt(xl**2 + yl**2)
right = sp.sqrt((xr - xb) ** 2 + (yr - yb) ** 2)

kinetic = k * (xl_dot**2 + yl_dot**2 + xr_dot**2 + yr_dot**2) / 2
potential = (left - L0) ** 2 / 2 + (right - L0) ** 2 / 2 + k * g * (yl + yr)

system = System(
    "car_axis",
    q=[xl, yl, xr, yr],
    v=[xl_dot, yl_dot, xr_dot, yr_dot],
    lagrangian=kinetic - potential,
    holonomic=[xb * xl + yb * yl, (xl - xr) ** 2 + (yl - yr) ** 2 - L**2],
    params={eps: 1e-2, M: 10.0, L: 1.0, L0: 0.5, r: 0.1, w: 10.0, g: 1.0},
    reference_state=[0, L0, L, L0, -L0 / L, 0, -L0 / L, 0],
    energy=False,  # the driven bump does work
    coordinate_units=["1"] * 4,
    simplify=False,
    expand=True,  # the shipped scene was derived expanded; its numbers stay as they are
    description=__doc__,
)
