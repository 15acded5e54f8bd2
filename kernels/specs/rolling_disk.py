"""Rolling disk (n = 6, m = 1, k = 2), generated: holonomic and nonholonomic together.

A thin uniform disk of mass m and radius R rolls without slipping on the horizontal plane
z = 0.  Coordinates: the centre (x, y, z) and the z-x-z Euler angles phi (heading of the
line of nodes), theta (angle between the disk's axis and the vertical; upright is π/2) and
psi (spin).  The axis is n = (sin θ sin φ, −sin θ cos φ, cos θ); the contact point lies at
r_c = R (cos θ sin φ, −cos θ cos φ, −sin θ) from the centre.

* holonomic: the disk touches the plane, z − R sin(theta) = 0;
* nonholonomic: the contact point does not slip, the x and y components of
  v_centre + ω × r_c vanish (the z component is the derivative of the holonomic one).

Inertia: m R²/4 about a diameter, m R²/2 about the axis.  Gravity g along −z; the energy
is a first integral.
"""

import sympy as sp

from stabdae.symbolic import System, coordinates

(x, y, z, phi, theta, psi), vel = coordinates("x y z phi theta psi")
x_dot, y_dot, z_dot, phi_dot, theta_dot, psi_dot = vel
m, R, g, w0 = sp.symbols("m R g w0")

axis = sp.Matrix([sp.sin(theta) * sp.sin(phi), -sp.sin(theta) * sp.cos(phi), sp.cos(theta)])
nodes = sp.Matrix([sp.cos(phi), sp.sin(phi), 0])
omega = phi_dot * sp.Matrix([0, 0, 1]) + theta_dot * nodes + psi_dot * axis
contact = R * sp.Matrix([sp.cos(theta) * sp.sin(phi), -sp.cos(theta) * sp.cos(phi),
                         -sp.sin(theta)])  # fmt: skip
slip = sp.Matrix([x_dot, y_dot, z_dot]) + omega.cross(contact)

# rotational energy in the nodal frame (the disk is symmetric about its axis)
I1, I3 = m * R**2 / 4, m * R**2 / 2
kinetic = (m * (x_dot**2 + y_dot**2 + z_dot**2)
           + I1 * (theta_dot**2 + (phi_dot * sp.sin(theta)) ** 2)
           + I3 * (phi_dot * sp.cos(theta) + psi_dot) ** 2) / 2  # fmt: skip

# reference: tilted by 0.3 rad from upright, turning at 1.5 rad/s, spinning at w0; the
# centre's velocity follows from the no-slip rows (a consistent state)
tilted = {theta: sp.pi / 2 - sp.Rational(3, 10), phi: 0, z_dot: 0, theta_dot: 0,
          phi_dot: sp.Rational(3, 2), psi_dot: w0}  # fmt: skip
rolling = sp.solve([slip[0].subs(tilted), slip[1].subs(tilted)], [x_dot, y_dot], dict=True)[0]
rolling = {key: sp.simplify(value) for key, value in rolling.items()}

system = System(
    "rolling_disk",
    q=[x, y, z, phi, theta, psi],
    v=list(vel),
    lagrangian=kinetic - m * g * z,
    holonomic=[z - R * sp.sin(theta)],
    nonholonomic=[slip[0], slip[1]],
    params={m: 1.0, R: 0.5, g: 9.81, w0: 4.0},
    reference_state=[0, 0, R * sp.sin(tilted[theta]), 0, tilted[theta], 0,
                     rolling[x_dot], rolling[y_dot], 0, tilted[phi_dot], 0, w0],
    coordinate_units=["m", "m", "m", "rad", "rad", "rad"],
    constraint_units=["m", "m s-1", "m s-1"],
    energy_units="J",
    expand=True,  # the shipped scene was derived expanded; its numbers stay as they are
    description=__doc__,
)
