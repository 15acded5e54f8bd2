"""Andrews' squeezing mechanism (n = 7, m = 6), generated.

Seven rigid bodies in a plane joined without friction (Hairer & Wanner, Solving ODEs II,
§VII.7; the Test Set for IVP Solvers, problem "andrews").  Coordinates are the angles
q = (β, Θ, γ, Φ, δ, Ω, ε); a constant torque `mom` drives β and a spring of stiffness c0
and rest length l0 acts between the points D (on body 3) and C.  Six holonomic constraints
close the three loops.  Parameters and the consistent initial state are the Test Set's;
its reference solution at t = 0.03 (PSIDE, tolerance 1e-14) is in the test suite.

Motion is fast (β̇ reaches 1e3 rad/s within 0.03 s) and the residual law should be chosen
accordingly (ω of order 1e3–1e4 s⁻¹).
"""

import sympy as sp

from stabdae.symbolic import System, coordinates

q, v = coordinates("beta Theta gamma Phi delta Omega epsilon")
beta, Theta, gamma, Phi, delta, Omega, epsilon = q
names = ("m1 m2 m3 m4 m5 m6 m7 xa ya xb yb xc yc c0 i1 i2 i3 i4 i5 i6 i7 d da e ea rr ra l0 "
         "ss sa sb sc sd ta tb u ua ub zf zt fa mom")
par = dict(zip(names.split(), sp.symbols(names)))
P = type("P", (), par)  # P.m1, P.xa, …
values = [0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498,
          -0.06934, -0.00227, -0.03635, 0.03273, 0.014, 0.072, 4530.0,
          2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5,
          28e-3, 115e-4, 2e-2, 1421e-5, 7e-3, 92e-5, 7785e-5,
          35e-3, 1874e-5, 1043e-5, 18e-3, 2e-2, 2308e-5, 916e-5, 4e-2, 1228e-5, 449e-5,
          2e-2, 4e-2, 1421e-5, 33e-3]  # fmt: skip

sin, cos = sp.sin, sp.cos
M = sp.zeros(7, 7)
M[0, 0] = (P.m1 * P.ra**2 + P.m2 * (P.rr**2 - 2 * P.da * P.rr * cos(Theta) + P.da**2)
           + P.i1 + P.i2)  # fmt: skip
M[1, 0] = P.m2 * (P.da**2 - P.da * P.rr * cos(Theta)) + P.i2
M[1, 1] = P.m2 * P.da**2 + P.i2
M[2, 2] = P.m3 * (P.sa**2 + P.sb**2) + P.i3
M[3, 3] = P.m4 * (P.e - P.ea) ** 2 + P.i4
M[4, 3] = P.m4 * ((P.e - P.ea) ** 2 + P.zt * (P.e - P.ea) * sin(Phi)) + P.i4
M[4, 4] = (P.m4 * (P.zt**2 + 2 * P.zt * (P.e - P.ea) * sin(Phi) + (P.e - P.ea) ** 2)
           + P.m5 * (P.ta**2 + P.tb**2) + P.i4 + P.i5)  # fmt: skip
M[5, 5] = P.m6 * (P.zf - P.fa) ** 2 + P.i6
M[6, 5] = P.m6 * ((P.zf - P.fa) ** 2 - P.u * (P.zf - P.fa) * sin(Omega)) + P.i6
M[6, 6] = (P.m6 * ((P.zf - P.fa) ** 2 - 2 * P.u * (P.zf - P.fa) * sin(Omega) + P.u**2)
           + P.m7 * (P.ua**2 + P.ub**2) + P.i6 + P.i7)  # fmt: skip
for i in range(7):
    for j in range(i):
        M[j, i] = M[i, j]
vel = sp.Matrix(v)
kinetic = (vel.T * M * vel)[0, 0] / 2

# the spring between D (on body 3, turning with γ) and the fixed point C
xd = P.sd * cos(gamma) + P.sc * sin(gamma) + P.xb
yd = P.sd * sin(gamma) - P.sc * cos(gamma) + P.yb
length = sp.sqrt((xd - P.xc) ** 2 + (yd - P.yc) ** 2)
potential = P.c0 / 2 * (length - P.l0) ** 2

# loop closure: the point where bodies 1–2 meet the others, reached along each loop
px = P.rr * cos(beta) - P.d * cos(beta + Theta)
py = P.rr * sin(beta) - P.d * sin(beta + Theta)
holonomic = [
    px - P.ss * sin(gamma) - P.xb,
    py + P.ss * cos(gamma) - P.yb,
    px - P.e * sin(Phi + delta) - P.zt * cos(delta) - P.xa,
    py + P.e * cos(Phi + delta) - P.zt * sin(delta) - P.ya,
    px - P.zf * cos(Omega + epsilon) - P.u * sin(epsilon) - P.xa,
    py - P.zf * sin(Omega + epsilon) + P.u * cos(epsilon) - P.ya,
]

q0 = [-0.0617138900142764496358948458001, 0.0, 0.455279819163070380255912382449,
      0.222668390165885884674473185609, 0.487364979543842550225598953530,
      -0.222668390165885884674473185609, 1.23054744454982119249735015568]  # fmt: skip

system = System(
    "andrews",
    q=q,
    v=v,
    lagrangian=kinetic - potential,
    holonomic=holonomic,
    params=dict(zip(par.values(), values)),
    reference_state=q0 + [0.0] * 7,
    forces=[P.mom, 0, 0, 0, 0, 0, 0],  # the driving torque on β
    energy=False,  # the torque does work; there is no first integral to check
    coordinate_units=["rad"] * 7,
    constraint_units=["m"] * 6,
    energy_units="J",
    simplify=False,  # 7×7 with trigonometry: expansion and CSE suffice
    expand=True,  # the shipped scene was derived expanded; its numbers stay as they are
    description=__doc__,
)
