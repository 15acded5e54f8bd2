"""The Whipple bicycle of the benchmark by Meijaard, Papadopoulos, Ruina & Schwab, in its
eight minimal coordinates, generated.

Four rigid bodies: a rear wheel R, a rear frame with its rider B, a front frame (handlebar
and fork) H and a front wheel F, joined by three hinges (the wheels' axles and the steer
axis), the two wheels knife-edge disks rolling without slipping on level ground.  Axes as
in the benchmark: x forward, y to the right, z down, gravity g along +z.

Coordinates (n = 8): the rear contact point (x, y), the rear frame's yaw ψ, roll φ and
pitch θ (turned in that order: ψ about z, φ about the new x, θ about the new y; θ = 0 in
the benchmark's reference configuration), the rear wheel's turn θ_R about its axle, the
steer angle δ (right-handed about the steer axis pointing down, tilted back by λ from the
vertical) and the front wheel's turn θ_F.  Constraints: the front wheel touches the ground,
z of its contact point = 0, which fixes the pitch (m = 1); and neither wheel slips, the
contact points' material velocities zero in x and y (k = 4), leaving three velocities of
the eight free.

A wheel of radius r whose axle is the unit vector a touches the ground at its centre plus
r (e_z − a_z a) / √(1 − a_z²); the rear wheel's contact, at (x, y, 0), puts its centre at
r_R up the rear frame's rolled vertical.  The benchmark's parameters (its Table 1):
wheelbase w = 1.02 m, trail c = 0.08 m, steer axis tilt λ = π/10, wheels of radii 0.3 and
0.35 m, masses 2, 85, 4 and 3 kg, the frames' mass centres at (0.3, −0.9) and (0.9, −0.7) m
and their inertia tensors about them in the reference configuration's axes.  The
reference state is upright, straight running at `speed` (5 m/s), the wheels turning at
−speed/r.

Linearised about upright, straight running at speed v, the roll and steer angles obey the
benchmark's published M q̈ + v C₁ q̇ + (g K₀ + v² K₂) q = 0 (Meijaard et al., Proc. R.
Soc. A 463, 2007, eq. 5.4 with its Table 1's values); the test suite compares the
eigenvalues of this model's linearisation with those of the published matrices.
"""

import sympy as sp

from stabdae.symbolic import System, coordinates

q, v = coordinates("x y psi phi theta theta_R delta theta_F")
x, y, psi, phi, theta, theta_R, delta, theta_F = q
names = ("w c lam r_R r_F m_R m_B m_H m_F I_Rxx I_Ryy I_Bxx I_Byy I_Bzz I_Bxz I_Hxx I_Hyy "
         "I_Hzz I_Hxz I_Fxx I_Fyy x_B z_B x_H z_H g speed")
(w, c, lam, r_R, r_F, m_R, m_B, m_H, m_F, I_Rxx, I_Ryy, I_Bxx, I_Byy, I_Bzz, I_Bxz, I_Hxx,
 I_Hyy, I_Hzz, I_Hxz, I_Fxx, I_Fyy, x_B, z_B, x_H, z_H, g, speed) = sp.symbols(names)
e_x, e_y, e_z = sp.eye(3)[:, 0], sp.eye(3)[:, 1], sp.eye(3)[:, 2]


def rot_x(a):
    return sp.Matrix([[1, 0, 0], [0, sp.cos(a), -sp.sin(a)], [0, sp.sin(a), sp.cos(a)]])


def rot_y(a):
    return sp.Matrix([[sp.cos(a), 0, sp.sin(a)], [0, 1, 0], [-sp.sin(a), 0, sp.cos(a)]])


def rot_z(a):
    return sp.Matrix([[sp.cos(a), -sp.sin(a), 0], [sp.sin(a), sp.cos(a), 0], [0, 0, 1]])


def rot_about(s, a):
    """Rodrigues: the turn by a about the unit vector s."""
    cross = sp.Matrix([[0, -s[2], s[1]], [s[2], 0, -s[0]], [-s[1], s[0], 0]])
    return sp.cos(a) * sp.eye(3) + sp.sin(a) * cross + (1 - sp.cos(a)) * s * s.T


def velocity(r):
    return r.jacobian(q) * sp.Matrix(v)


def contact_offset(axle, radius):
    """From a wheel's centre to its contact point, for a wheel of that axle (unit)."""
    return radius * (e_z - axle[2] * axle) / sp.sqrt(1 - axle[2] ** 2)


# orientations: the roll frame, the rear frame and the front frame (body to world)
rolled = rot_z(psi) * rot_x(phi)
R_B = rolled * rot_y(theta)
steer_axis = sp.Matrix([sp.sin(lam), 0, sp.cos(lam)])  # in the rear frame, pointing down
turn = rot_about(steer_axis, delta)
R_H = R_B * turn

# angular velocities in each body's own axes
omega_B = (rot_y(theta).T * (rot_x(phi).T * (v[2] * e_z) + v[3] * e_x) + v[4] * e_y)
omega_H = turn.T * (omega_B + v[6] * steer_axis)
omega_R = omega_B + v[5] * e_y
omega_F = omega_H + v[7] * e_y

# points, relative to the rear wheel's centre in the reference configuration's axes: the
# steer axis meets the ground at w + c
rear_centre = sp.Matrix([x, y, 0]) - r_R * rolled * e_z
on_axis = sp.Matrix([w + c, 0, r_R])


def front_point(p):
    return rear_centre + R_B * (on_axis + turn * (p - on_axis))


front_centre = front_point(sp.Matrix([w, 0, r_R - r_F]))
frame_centre = rear_centre + R_B * sp.Matrix([x_B, 0, z_B + r_R])
fork_centre = front_point(sp.Matrix([x_H, 0, z_H + r_R]))

I_B = sp.Matrix([[I_Bxx, 0, I_Bxz], [0, I_Byy, 0], [I_Bxz, 0, I_Bzz]])
I_H = sp.Matrix([[I_Hxx, 0, I_Hxz], [0, I_Hyy, 0], [I_Hxz, 0, I_Hzz]])


def spin(omega, axial, transverse):
    """A wheel's rotational energy: its axle is the body's y axis."""
    return (transverse * (omega[0] ** 2 + omega[2] ** 2) + axial * omega[1] ** 2) / 2


kinetic = 0
for mass, centre in ((m_R, rear_centre), (m_B, frame_centre), (m_H, fork_centre),
                     (m_F, front_centre)):
    u = velocity(centre)
    kinetic += mass * u.dot(u) / 2
kinetic += (omega_B.T * I_B * omega_B)[0, 0] / 2 + (omega_H.T * I_H * omega_H)[0, 0] / 2
kinetic += spin(omega_R, I_Ryy, I_Rxx) + spin(omega_F, I_Fyy, I_Fxx)
potential = -g * (m_R * rear_centre[2] + m_B * frame_centre[2] + m_H * fork_centre[2]
                  + m_F * front_centre[2])

# rolling: each contact point's material velocity, centre's velocity + ω × offset (world)
front_axle = R_H * e_y
front_offset = contact_offset(front_axle, r_F)
rear_slip = velocity(rear_centre) + (R_B * omega_R).cross(r_R * rolled * e_z)
front_slip = velocity(front_centre) + (R_H * omega_F).cross(front_offset)

system = System(
    "bicycle",
    q=q,
    v=v,
    lagrangian=kinetic - potential,
    holonomic=[front_centre[2] + front_offset[2]],
    nonholonomic=[rear_slip[0], rear_slip[1], front_slip[0], front_slip[1]],
    params={w: 1.02, c: 0.08, lam: 0.31415926535897931, r_R: 0.3, r_F: 0.35,
            m_R: 2.0, m_B: 85.0, m_H: 4.0, m_F: 3.0, I_Rxx: 0.0603, I_Ryy: 0.12,
            I_Bxx: 9.2, I_Byy: 11.0, I_Bzz: 2.8, I_Bxz: 2.4,
            I_Hxx: 0.05892, I_Hyy: 0.06, I_Hzz: 0.00708, I_Hxz: -0.00756,
            I_Fxx: 0.1405, I_Fyy: 0.28, x_B: 0.3, z_B: -0.9, x_H: 0.9, z_H: -0.7,
            g: 9.81, speed: 5.0},
    # upright, straight ahead at `speed`, each wheel turning at −speed/radius
    reference_state=[0, 0, 0, 0, 0, 0, 0, 0, speed, 0, 0, 0, 0, -speed / r_R, 0,
                     -speed / r_F],
    coordinate_units=["m", "m", "rad", "rad", "rad", "rad", "rad", "rad"],
    constraint_units=["m", "m s-1", "m s-1", "m s-1", "m s-1"],
    energy_units="J",
    simplify=False,
    expand=False,
    description=__doc__,
)
