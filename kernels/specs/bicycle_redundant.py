"""The Whipple bicycle of the benchmark by Meijaard, Papadopoulos, Ruina & Schwab, in 12
redundant coordinates, generated: the same bicycle as `bicycle`, with the two wheels'
centres as coordinates of their own.

Coordinates (n = 12): the six angles of `bicycle` (the rear frame's yaw ψ, roll φ and
pitch θ, the rear wheel's turn θ_R, the steer angle δ and the front wheel's turn θ_F), then
the rear wheel's centre (x_r, y_r, z_r) and the front wheel's (x_f, y_f, z_f); the rear
contact point is the rear centre's foot.  Constraints: the rear centre at r_R up the
rolled vertical from the ground, z_r = −r_R cos φ, the front centre where the angles put
it from the rear one (three), the front wheel on the ground (m = 5), and neither wheel
slipping (k = 4): the same three free velocities.  The frames' mass centres hang from the
wheels' centres, so no position nests more than one body's turn, and the wheels' energy
of motion is that of a point mass.

The benchmark's parameters and the reference state (upright, straight running at `speed`,
5 m/s) are those of `bicycle`; the test suite compares the eigenvalues of this model's
linearisation with those of the benchmark's published matrices (Meijaard et al., Proc.
R. Soc. A 463, 2007), as it does for `bicycle`, and `docs/models.md` compares the two
models' derivation and size.
"""

import sympy as sp

from stabdae.symbolic import System, coordinates

q, v = coordinates("psi phi theta theta_R delta theta_F x_r y_r z_r x_f y_f z_f")
psi, phi, theta, theta_R, delta, theta_F = q[:6]
rear_centre, front_centre = sp.Matrix(q[6:9]), sp.Matrix(q[9:12])
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
omega_B = (rot_y(theta).T * (rot_x(phi).T * (v[0] * e_z) + v[1] * e_x) + v[2] * e_y)
omega_H = turn.T * (omega_B + v[4] * steer_axis)
omega_R = omega_B + v[3] * e_y
omega_F = omega_H + v[5] * e_y

# points, relative to a wheel's centre in the reference configuration's axes: the steer
# axis meets the ground at w + c; where the angles put the front centre
on_axis = sp.Matrix([w + c, 0, r_R])
front_in_rear = sp.Matrix([w, 0, r_R - r_F])  # the front centre from the rear one
front_placed = rear_centre + R_B * (on_axis + turn * (front_in_rear - on_axis))
frame_centre = rear_centre + R_B * sp.Matrix([x_B, 0, z_B + r_R])
fork_centre = front_centre + R_H * sp.Matrix([x_H - w, 0, z_H + r_F])

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
    "bicycle_redundant",
    q=q,
    v=v,
    lagrangian=kinetic - potential,
    holonomic=[rear_centre[2] + r_R * sp.cos(phi), *(front_centre - front_placed),
               front_centre[2] + front_offset[2]],
    nonholonomic=[rear_slip[0], rear_slip[1], front_slip[0], front_slip[1]],
    params={w: 1.02, c: 0.08, lam: 0.31415926535897931, r_R: 0.3, r_F: 0.35,
            m_R: 2.0, m_B: 85.0, m_H: 4.0, m_F: 3.0, I_Rxx: 0.0603, I_Ryy: 0.12,
            I_Bxx: 9.2, I_Byy: 11.0, I_Bzz: 2.8, I_Bxz: 2.4,
            I_Hxx: 0.05892, I_Hyy: 0.06, I_Hzz: 0.00708, I_Hxz: -0.00756,
            I_Fxx: 0.1405, I_Fyy: 0.28, x_B: 0.3, z_B: -0.9, x_H: 0.9, z_H: -0.7,
            g: 9.81, speed: 5.0},
    # upright, straight ahead at `speed`, each wheel turning at −speed/radius
    reference_state=[0, 0, 0, 0, 0, 0, 0, 0, -r_R, w, 0, -r_F,
                     0, 0, 0, -speed / r_R, 0, -speed / r_F, speed, 0, 0, speed, 0, 0],
    coordinate_units=["rad"] * 6 + ["m"] * 6,
    constraint_units=["m"] * 5 + ["m s-1"] * 4,
    energy_units="J",
    simplify=False,
    expand=False,
    description=__doc__,
)
