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

    L = I_Byy*(psi_dot*sin(phi) + theta_dot)**2/2 + I_Fxx*(((1 - cos(delta))*(delta_dot*sin(lam)
        + phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi))*sin(lam)*cos(lam) -
        (psi_dot*sin(phi) + theta_dot)*sin(delta)*sin(lam) + ((1 - cos(delta))*cos(lam)**2 +
        cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta)))**2
        + ((1 - cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta))*sin(lam)*cos(lam) + (psi_dot*sin(phi) +
        theta_dot)*sin(delta)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi)))**2)/2 + I_Fyy*(theta_F_dot + (psi_dot*sin(phi) +
        theta_dot)*cos(delta) - (delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(delta)*cos(lam) + (delta_dot*cos(lam) +
        phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*sin(delta)*sin(lam))**2/2 +
        I_Hyy*((psi_dot*sin(phi) + theta_dot)*cos(delta) - (delta_dot*sin(lam) +
        phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi))*sin(delta)*cos(lam) +
        (delta_dot*cos(lam) + phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta))*sin(delta)*sin(lam))**2/2 + I_Rxx*((phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta))**2 + (phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))**2)/2 + I_Ryy*(psi_dot*sin(phi) + theta_R_dot +
        theta_dot)**2/2 + g*(m_B*(-r_R*cos(phi) - x_B*sin(theta)*cos(phi) + (r_R +
        z_B)*cos(phi)*cos(theta)) + m_F*(-r_R*cos(phi) + (-c*sin(delta)*cos(lam) +
        r_F*sin(delta)*sin(lam))*sin(phi) + (-c*(1 - cos(delta))*sin(lam)*cos(lam) - r_F*((1 -
        cos(delta))*cos(lam)**2 + cos(delta)) + r_R)*cos(phi)*cos(theta) - (-c*((1 -
        cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1 - cos(delta))*sin(lam)*cos(lam) +
        w)*sin(theta)*cos(phi)) + m_H*(-r_R*cos(phi) + (-z_H*sin(delta)*sin(lam) + (-c - w +
        x_H)*sin(delta)*cos(lam))*sin(phi) + (r_R + z_H*((1 - cos(delta))*cos(lam)**2 +
        cos(delta)) + (1 - cos(delta))*(-c - w + x_H)*sin(lam)*cos(lam))*cos(phi)*cos(theta) -
        (c + w + z_H*(1 - cos(delta))*sin(lam)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*(-c - w + x_H))*sin(theta)*cos(phi)) - m_R*r_R*cos(phi)) +
        m_B*((phi_dot*(r_R*sin(phi) + x_B*sin(phi)*sin(theta) - (r_R + z_B)*sin(phi)*cos(theta))
        + theta_dot*(-x_B*cos(phi)*cos(theta) - (r_R + z_B)*sin(theta)*cos(phi)))**2 +
        (phi_dot*(-r_R*sin(psi)*cos(phi) - x_B*sin(psi)*sin(theta)*cos(phi) + (r_R +
        z_B)*sin(psi)*cos(phi)*cos(theta)) + psi_dot*(-r_R*sin(phi)*cos(psi) +
        x_B*(-sin(phi)*sin(theta)*cos(psi) - sin(psi)*cos(theta)) + (r_R +
        z_B)*(sin(phi)*cos(psi)*cos(theta) - sin(psi)*sin(theta))) +
        theta_dot*(x_B*(-sin(phi)*sin(psi)*cos(theta) - sin(theta)*cos(psi)) + (r_R +
        z_B)*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta))) + x_dot)**2 +
        (phi_dot*(r_R*cos(phi)*cos(psi) + x_B*sin(theta)*cos(phi)*cos(psi) - (r_R +
        z_B)*cos(phi)*cos(psi)*cos(theta)) + psi_dot*(-r_R*sin(phi)*sin(psi) +
        x_B*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta)) + (r_R +
        z_B)*(sin(phi)*sin(psi)*cos(theta) + sin(theta)*cos(psi))) +
        theta_dot*(x_B*(sin(phi)*cos(psi)*cos(theta) - sin(psi)*sin(theta)) + (r_R +
        z_B)*(sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta))) + y_dot)**2)/2 +
        m_F*((delta_dot*(-(-c*(sin(delta)*sin(lam)**2 - sin(delta)) -
        r_F*sin(delta)*sin(lam)*cos(lam))*sin(theta)*cos(phi) + (-c*cos(delta)*cos(lam) +
        r_F*sin(lam)*cos(delta))*sin(phi) + (-c*sin(delta)*sin(lam)*cos(lam) -
        r_F*(sin(delta)*cos(lam)**2 - sin(delta)))*cos(phi)*cos(theta)) + phi_dot*(r_R*sin(phi)
        + (-c*sin(delta)*cos(lam) + r_F*sin(delta)*sin(lam))*cos(phi) - (-c*(1 -
        cos(delta))*sin(lam)*cos(lam) - r_F*((1 - cos(delta))*cos(lam)**2 + cos(delta)) +
        r_R)*sin(phi)*cos(theta) + (-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1
        - cos(delta))*sin(lam)*cos(lam) + w)*sin(phi)*sin(theta)) + theta_dot*(-(-c*(1 -
        cos(delta))*sin(lam)*cos(lam) - r_F*((1 - cos(delta))*cos(lam)**2 + cos(delta)) +
        r_R)*sin(theta)*cos(phi) - (-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1
        - cos(delta))*sin(lam)*cos(lam) + w)*cos(phi)*cos(theta)))**2 +
        (delta_dot*((-c*(sin(delta)*sin(lam)**2 - sin(delta)) -
        r_F*sin(delta)*sin(lam)*cos(lam))*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta))
        - (-c*cos(delta)*cos(lam) + r_F*sin(lam)*cos(delta))*sin(psi)*cos(phi) +
        (sin(phi)*sin(psi)*cos(theta) + sin(theta)*cos(psi))*(-c*sin(delta)*sin(lam)*cos(lam) -
        r_F*(sin(delta)*cos(lam)**2 - sin(delta)))) + phi_dot*(-r_R*sin(psi)*cos(phi) +
        (-c*sin(delta)*cos(lam) + r_F*sin(delta)*sin(lam))*sin(phi)*sin(psi) + (-c*(1 -
        cos(delta))*sin(lam)*cos(lam) - r_F*((1 - cos(delta))*cos(lam)**2 + cos(delta)) +
        r_R)*sin(psi)*cos(phi)*cos(theta) - (-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c
        - r_F*(1 - cos(delta))*sin(lam)*cos(lam) + w)*sin(psi)*sin(theta)*cos(phi)) +
        psi_dot*(-r_R*sin(phi)*cos(psi) - (-c*sin(delta)*cos(lam) +
        r_F*sin(delta)*sin(lam))*cos(phi)*cos(psi) + (-sin(phi)*sin(theta)*cos(psi) -
        sin(psi)*cos(theta))*(-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1 -
        cos(delta))*sin(lam)*cos(lam) + w) + (sin(phi)*cos(psi)*cos(theta) -
        sin(psi)*sin(theta))*(-c*(1 - cos(delta))*sin(lam)*cos(lam) - r_F*((1 -
        cos(delta))*cos(lam)**2 + cos(delta)) + r_R)) +
        theta_dot*((-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta))*(-c*(1 -
        cos(delta))*sin(lam)*cos(lam) - r_F*((1 - cos(delta))*cos(lam)**2 + cos(delta)) + r_R) +
        (-sin(phi)*sin(psi)*cos(theta) - sin(theta)*cos(psi))*(-c*((1 - cos(delta))*sin(lam)**2
        + cos(delta)) + c - r_F*(1 - cos(delta))*sin(lam)*cos(lam) + w)) + x_dot)**2 +
        (delta_dot*((-c*(sin(delta)*sin(lam)**2 - sin(delta)) -
        r_F*sin(delta)*sin(lam)*cos(lam))*(sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta)) +
        (-c*cos(delta)*cos(lam) + r_F*sin(lam)*cos(delta))*cos(phi)*cos(psi) +
        (-sin(phi)*cos(psi)*cos(theta) + sin(psi)*sin(theta))*(-c*sin(delta)*sin(lam)*cos(lam) -
        r_F*(sin(delta)*cos(lam)**2 - sin(delta)))) + phi_dot*(r_R*cos(phi)*cos(psi) -
        (-c*sin(delta)*cos(lam) + r_F*sin(delta)*sin(lam))*sin(phi)*cos(psi) - (-c*(1 -
        cos(delta))*sin(lam)*cos(lam) - r_F*((1 - cos(delta))*cos(lam)**2 + cos(delta)) +
        r_R)*cos(phi)*cos(psi)*cos(theta) + (-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c
        - r_F*(1 - cos(delta))*sin(lam)*cos(lam) + w)*sin(theta)*cos(phi)*cos(psi)) +
        psi_dot*(-r_R*sin(phi)*sin(psi) - (-c*sin(delta)*cos(lam) +
        r_F*sin(delta)*sin(lam))*sin(psi)*cos(phi) + (-sin(phi)*sin(psi)*sin(theta) +
        cos(psi)*cos(theta))*(-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1 -
        cos(delta))*sin(lam)*cos(lam) + w) + (sin(phi)*sin(psi)*cos(theta) +
        sin(theta)*cos(psi))*(-c*(1 - cos(delta))*sin(lam)*cos(lam) - r_F*((1 -
        cos(delta))*cos(lam)**2 + cos(delta)) + r_R)) + theta_dot*((sin(phi)*sin(theta)*cos(psi)
        + sin(psi)*cos(theta))*(-c*(1 - cos(delta))*sin(lam)*cos(lam) - r_F*((1 -
        cos(delta))*cos(lam)**2 + cos(delta)) + r_R) + (sin(phi)*cos(psi)*cos(theta) -
        sin(psi)*sin(theta))*(-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1 -
        cos(delta))*sin(lam)*cos(lam) + w)) + y_dot)**2)/2 +
        m_H*((delta_dot*((z_H*(sin(delta)*cos(lam)**2 - sin(delta)) + (-c - w +
        x_H)*sin(delta)*sin(lam)*cos(lam))*cos(phi)*cos(theta) + (-z_H*sin(lam)*cos(delta) + (-c
        - w + x_H)*cos(delta)*cos(lam))*sin(phi) - (z_H*sin(delta)*sin(lam)*cos(lam) +
        (sin(delta)*sin(lam)**2 - sin(delta))*(-c - w + x_H))*sin(theta)*cos(phi)) +
        phi_dot*(r_R*sin(phi) + (-z_H*sin(delta)*sin(lam) + (-c - w +
        x_H)*sin(delta)*cos(lam))*cos(phi) - (r_R + z_H*((1 - cos(delta))*cos(lam)**2 +
        cos(delta)) + (1 - cos(delta))*(-c - w + x_H)*sin(lam)*cos(lam))*sin(phi)*cos(theta) +
        (c + w + z_H*(1 - cos(delta))*sin(lam)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*(-c - w + x_H))*sin(phi)*sin(theta)) + theta_dot*(-(r_R + z_H*((1 -
        cos(delta))*cos(lam)**2 + cos(delta)) + (1 - cos(delta))*(-c - w +
        x_H)*sin(lam)*cos(lam))*sin(theta)*cos(phi) - (c + w + z_H*(1 -
        cos(delta))*sin(lam)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 + cos(delta))*(-c - w +
        x_H))*cos(phi)*cos(theta)))**2 + (delta_dot*((z_H*(sin(delta)*cos(lam)**2 - sin(delta))
        + (-c - w + x_H)*sin(delta)*sin(lam)*cos(lam))*(sin(phi)*sin(psi)*cos(theta) +
        sin(theta)*cos(psi)) - (-z_H*sin(lam)*cos(delta) + (-c - w +
        x_H)*cos(delta)*cos(lam))*sin(psi)*cos(phi) + (-sin(phi)*sin(psi)*sin(theta) +
        cos(psi)*cos(theta))*(z_H*sin(delta)*sin(lam)*cos(lam) + (sin(delta)*sin(lam)**2 -
        sin(delta))*(-c - w + x_H))) + phi_dot*(-r_R*sin(psi)*cos(phi) +
        (-z_H*sin(delta)*sin(lam) + (-c - w + x_H)*sin(delta)*cos(lam))*sin(phi)*sin(psi) + (r_R
        + z_H*((1 - cos(delta))*cos(lam)**2 + cos(delta)) + (1 - cos(delta))*(-c - w +
        x_H)*sin(lam)*cos(lam))*sin(psi)*cos(phi)*cos(theta) - (c + w + z_H*(1 -
        cos(delta))*sin(lam)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 + cos(delta))*(-c - w +
        x_H))*sin(psi)*sin(theta)*cos(phi)) + psi_dot*(-r_R*sin(phi)*cos(psi) -
        (-z_H*sin(delta)*sin(lam) + (-c - w + x_H)*sin(delta)*cos(lam))*cos(phi)*cos(psi) +
        (-sin(phi)*sin(theta)*cos(psi) - sin(psi)*cos(theta))*(c + w + z_H*(1 -
        cos(delta))*sin(lam)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 + cos(delta))*(-c - w +
        x_H)) + (sin(phi)*cos(psi)*cos(theta) - sin(psi)*sin(theta))*(r_R + z_H*((1 -
        cos(delta))*cos(lam)**2 + cos(delta)) + (1 - cos(delta))*(-c - w +
        x_H)*sin(lam)*cos(lam))) + theta_dot*((-sin(phi)*sin(psi)*sin(theta) +
        cos(psi)*cos(theta))*(r_R + z_H*((1 - cos(delta))*cos(lam)**2 + cos(delta)) + (1 -
        cos(delta))*(-c - w + x_H)*sin(lam)*cos(lam)) + (-sin(phi)*sin(psi)*cos(theta) -
        sin(theta)*cos(psi))*(c + w + z_H*(1 - cos(delta))*sin(lam)*cos(lam) + ((1 -
        cos(delta))*sin(lam)**2 + cos(delta))*(-c - w + x_H))) + x_dot)**2 +
        (delta_dot*((z_H*(sin(delta)*cos(lam)**2 - sin(delta)) + (-c - w +
        x_H)*sin(delta)*sin(lam)*cos(lam))*(-sin(phi)*cos(psi)*cos(theta) + sin(psi)*sin(theta))
        + (-z_H*sin(lam)*cos(delta) + (-c - w + x_H)*cos(delta)*cos(lam))*cos(phi)*cos(psi) +
        (sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta))*(z_H*sin(delta)*sin(lam)*cos(lam) +
        (sin(delta)*sin(lam)**2 - sin(delta))*(-c - w + x_H))) + phi_dot*(r_R*cos(phi)*cos(psi)
        - (-z_H*sin(delta)*sin(lam) + (-c - w + x_H)*sin(delta)*cos(lam))*sin(phi)*cos(psi) -
        (r_R + z_H*((1 - cos(delta))*cos(lam)**2 + cos(delta)) + (1 - cos(delta))*(-c - w +
        x_H)*sin(lam)*cos(lam))*cos(phi)*cos(psi)*cos(theta) + (c + w + z_H*(1 -
        cos(delta))*sin(lam)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 + cos(delta))*(-c - w +
        x_H))*sin(theta)*cos(phi)*cos(psi)) + psi_dot*(-r_R*sin(phi)*sin(psi) -
        (-z_H*sin(delta)*sin(lam) + (-c - w + x_H)*sin(delta)*cos(lam))*sin(psi)*cos(phi) +
        (-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta))*(c + w + z_H*(1 -
        cos(delta))*sin(lam)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 + cos(delta))*(-c - w +
        x_H)) + (sin(phi)*sin(psi)*cos(theta) + sin(theta)*cos(psi))*(r_R + z_H*((1 -
        cos(delta))*cos(lam)**2 + cos(delta)) + (1 - cos(delta))*(-c - w +
        x_H)*sin(lam)*cos(lam))) + theta_dot*((sin(phi)*sin(theta)*cos(psi) +
        sin(psi)*cos(theta))*(r_R + z_H*((1 - cos(delta))*cos(lam)**2 + cos(delta)) + (1 -
        cos(delta))*(-c - w + x_H)*sin(lam)*cos(lam)) + (sin(phi)*cos(psi)*cos(theta) -
        sin(psi)*sin(theta))*(c + w + z_H*(1 - cos(delta))*sin(lam)*cos(lam) + ((1 -
        cos(delta))*sin(lam)**2 + cos(delta))*(-c - w + x_H))) + y_dot)**2)/2 +
        m_R*(phi_dot**2*r_R**2*sin(phi)**2 + (-phi_dot*r_R*sin(psi)*cos(phi) -
        psi_dot*r_R*sin(phi)*cos(psi) + x_dot)**2 + (phi_dot*r_R*cos(phi)*cos(psi) -
        psi_dot*r_R*sin(phi)*sin(psi) + y_dot)**2)/2 + (I_Bxx*(phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi)) + I_Bxz*(phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta)))*(phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi))/2 +
        (I_Bxz*(phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi)) + I_Bzz*(phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta)))*(phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))/2 +
        (I_Hxx*((1 - cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta))*sin(lam)*cos(lam) + (psi_dot*sin(phi) +
        theta_dot)*sin(delta)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi))) +
        I_Hxz*((1 - cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(lam)*cos(lam) - (psi_dot*sin(phi) +
        theta_dot)*sin(delta)*sin(lam) + ((1 - cos(delta))*cos(lam)**2 +
        cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta))))*((1 - cos(delta))*(delta_dot*cos(lam) +
        phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*sin(lam)*cos(lam) + (psi_dot*sin(phi)
        + theta_dot)*sin(delta)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi)))/2 +
        (I_Hxz*((1 - cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta))*sin(lam)*cos(lam) + (psi_dot*sin(phi) +
        theta_dot)*sin(delta)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi))) +
        I_Hzz*((1 - cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(lam)*cos(lam) - (psi_dot*sin(phi) +
        theta_dot)*sin(delta)*sin(lam) + ((1 - cos(delta))*cos(lam)**2 +
        cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta))))*((1 - cos(delta))*(delta_dot*sin(lam) +
        phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi))*sin(lam)*cos(lam) - (psi_dot*sin(phi)
        + theta_dot)*sin(delta)*sin(lam) + ((1 - cos(delta))*cos(lam)**2 +
        cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta)))/2
    f[0] = r_F*sqrt(1 - (sin(delta)*sin(lam)*cos(phi)*cos(theta) +
        sin(delta)*sin(theta)*cos(lam)*cos(phi) + sin(phi)*cos(delta))**2) - r_R*cos(phi) +
        (-c*sin(delta)*cos(lam) + r_F*sin(delta)*sin(lam))*sin(phi) + (-c*(1 -
        cos(delta))*sin(lam)*cos(lam) - r_F*((1 - cos(delta))*cos(lam)**2 + cos(delta)) +
        r_R)*cos(phi)*cos(theta) - (-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1
        - cos(delta))*sin(lam)*cos(lam) + w)*sin(theta)*cos(phi) = 0
    h[0] = -phi_dot*r_R*sin(psi)*cos(phi) - psi_dot*r_R*sin(phi)*cos(psi) +
        r_R*((phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*(-sin(phi)*cos(psi)*cos(theta) +
        sin(psi)*sin(theta)) + (phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*(sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta)) +
        (psi_dot*sin(phi) + theta_R_dot + theta_dot)*cos(phi)*cos(psi))*cos(phi) +
        r_R*((phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*cos(phi)*cos(theta) -
        (phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi))*sin(theta)*cos(phi) +
        (psi_dot*sin(phi) + theta_R_dot + theta_dot)*sin(phi))*sin(phi)*cos(psi) + x_dot = 0
    h[1] = phi_dot*r_R*cos(phi)*cos(psi) - psi_dot*r_R*sin(phi)*sin(psi) - r_R*((phi_dot*sin(theta)
        + psi_dot*cos(phi)*cos(theta))*(sin(phi)*sin(psi)*cos(theta) + sin(theta)*cos(psi)) +
        (phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi))*(-sin(phi)*sin(psi)*sin(theta) +
        cos(psi)*cos(theta)) - (psi_dot*sin(phi) + theta_R_dot +
        theta_dot)*sin(psi)*cos(phi))*cos(phi) + r_R*((phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta))*cos(phi)*cos(theta) - (phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(theta)*cos(phi) + (psi_dot*sin(phi) + theta_R_dot +
        theta_dot)*sin(phi))*sin(phi)*sin(psi) + y_dot = 0
    h[2] = delta_dot*((-c*(sin(delta)*sin(lam)**2 - sin(delta)) -
        r_F*sin(delta)*sin(lam)*cos(lam))*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta))
        - (-c*cos(delta)*cos(lam) + r_F*sin(lam)*cos(delta))*sin(psi)*cos(phi) +
        (sin(phi)*sin(psi)*cos(theta) + sin(theta)*cos(psi))*(-c*sin(delta)*sin(lam)*cos(lam) -
        r_F*(sin(delta)*cos(lam)**2 - sin(delta)))) + phi_dot*(-r_R*sin(psi)*cos(phi) +
        (-c*sin(delta)*cos(lam) + r_F*sin(delta)*sin(lam))*sin(phi)*sin(psi) + (-c*(1 -
        cos(delta))*sin(lam)*cos(lam) - r_F*((1 - cos(delta))*cos(lam)**2 + cos(delta)) +
        r_R)*sin(psi)*cos(phi)*cos(theta) - (-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c
        - r_F*(1 - cos(delta))*sin(lam)*cos(lam) + w)*sin(psi)*sin(theta)*cos(phi)) +
        psi_dot*(-r_R*sin(phi)*cos(psi) - (-c*sin(delta)*cos(lam) +
        r_F*sin(delta)*sin(lam))*cos(phi)*cos(psi) + (-sin(phi)*sin(theta)*cos(psi) -
        sin(psi)*cos(theta))*(-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1 -
        cos(delta))*sin(lam)*cos(lam) + w) + (sin(phi)*cos(psi)*cos(theta) -
        sin(psi)*sin(theta))*(-c*(1 - cos(delta))*sin(lam)*cos(lam) - r_F*((1 -
        cos(delta))*cos(lam)**2 + cos(delta)) + r_R)) + r_F*sqrt(1 -
        (sin(delta)*sin(lam)*cos(phi)*cos(theta) + sin(delta)*sin(theta)*cos(lam)*cos(phi) +
        sin(phi)*cos(delta))**2)*((-(sin(phi)*sin(theta)*cos(psi) +
        sin(psi)*cos(theta))*sin(delta)*cos(lam) + (-sin(phi)*cos(psi)*cos(theta) +
        sin(psi)*sin(theta))*sin(delta)*sin(lam) + cos(delta)*cos(phi)*cos(psi))*(theta_F_dot +
        (psi_dot*sin(phi) + theta_dot)*cos(delta) - (delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(delta)*cos(lam) + (delta_dot*cos(lam) +
        phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*sin(delta)*sin(lam)) + ((1 -
        cos(delta))*(sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta))*sin(lam)*cos(lam) + ((1
        - cos(delta))*cos(lam)**2 + cos(delta))*(-sin(phi)*cos(psi)*cos(theta) +
        sin(psi)*sin(theta)) - sin(delta)*sin(lam)*cos(phi)*cos(psi))*((1 -
        cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(lam)*cos(lam) - (psi_dot*sin(phi) +
        theta_dot)*sin(delta)*sin(lam) + ((1 - cos(delta))*cos(lam)**2 +
        cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))) +
        ((1 - cos(delta))*(-sin(phi)*cos(psi)*cos(theta) +
        sin(psi)*sin(theta))*sin(lam)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*(sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta)) +
        sin(delta)*cos(lam)*cos(phi)*cos(psi))*((1 - cos(delta))*(delta_dot*cos(lam) +
        phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*sin(lam)*cos(lam) + (psi_dot*sin(phi)
        + theta_dot)*sin(delta)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi)))) +
        r_F*(((1 - cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(lam)*cos(lam) - (psi_dot*sin(phi) +
        theta_dot)*sin(delta)*sin(lam) + ((1 - cos(delta))*cos(lam)**2 +
        cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta)))*(-(1 - cos(delta))*sin(lam)*sin(theta)*cos(lam)*cos(phi) +
        ((1 - cos(delta))*cos(lam)**2 + cos(delta))*cos(phi)*cos(theta) -
        sin(delta)*sin(lam)*sin(phi)) + ((1 - cos(delta))*(delta_dot*cos(lam) +
        phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*sin(lam)*cos(lam) + (psi_dot*sin(phi)
        + theta_dot)*sin(delta)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi)))*((1
        - cos(delta))*sin(lam)*cos(lam)*cos(phi)*cos(theta) - ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*sin(theta)*cos(phi) + sin(delta)*sin(phi)*cos(lam)) +
        (sin(delta)*sin(lam)*cos(phi)*cos(theta) + sin(delta)*sin(theta)*cos(lam)*cos(phi) +
        sin(phi)*cos(delta))*(theta_F_dot + (psi_dot*sin(phi) + theta_dot)*cos(delta) -
        (delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(delta)*cos(lam) + (delta_dot*cos(lam) +
        phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta))*sin(delta)*sin(lam)))*(-(sin(phi)*sin(theta)*cos(psi) +
        sin(psi)*cos(theta))*sin(delta)*cos(lam) + (-sin(phi)*cos(psi)*cos(theta) +
        sin(psi)*sin(theta))*sin(delta)*sin(lam) +
        cos(delta)*cos(phi)*cos(psi))*(sin(delta)*sin(lam)*cos(phi)*cos(theta) +
        sin(delta)*sin(theta)*cos(lam)*cos(phi) + sin(phi)*cos(delta))/sqrt(1 -
        (sin(delta)*sin(lam)*cos(phi)*cos(theta) + sin(delta)*sin(theta)*cos(lam)*cos(phi) +
        sin(phi)*cos(delta))**2) + theta_dot*((-sin(phi)*sin(psi)*sin(theta) +
        cos(psi)*cos(theta))*(-c*(1 - cos(delta))*sin(lam)*cos(lam) - r_F*((1 -
        cos(delta))*cos(lam)**2 + cos(delta)) + r_R) + (-sin(phi)*sin(psi)*cos(theta) -
        sin(theta)*cos(psi))*(-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1 -
        cos(delta))*sin(lam)*cos(lam) + w)) + x_dot = 0
    h[3] = delta_dot*((-c*(sin(delta)*sin(lam)**2 - sin(delta)) -
        r_F*sin(delta)*sin(lam)*cos(lam))*(sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta)) +
        (-c*cos(delta)*cos(lam) + r_F*sin(lam)*cos(delta))*cos(phi)*cos(psi) +
        (-sin(phi)*cos(psi)*cos(theta) + sin(psi)*sin(theta))*(-c*sin(delta)*sin(lam)*cos(lam) -
        r_F*(sin(delta)*cos(lam)**2 - sin(delta)))) + phi_dot*(r_R*cos(phi)*cos(psi) -
        (-c*sin(delta)*cos(lam) + r_F*sin(delta)*sin(lam))*sin(phi)*cos(psi) - (-c*(1 -
        cos(delta))*sin(lam)*cos(lam) - r_F*((1 - cos(delta))*cos(lam)**2 + cos(delta)) +
        r_R)*cos(phi)*cos(psi)*cos(theta) + (-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c
        - r_F*(1 - cos(delta))*sin(lam)*cos(lam) + w)*sin(theta)*cos(phi)*cos(psi)) +
        psi_dot*(-r_R*sin(phi)*sin(psi) - (-c*sin(delta)*cos(lam) +
        r_F*sin(delta)*sin(lam))*sin(psi)*cos(phi) + (-sin(phi)*sin(psi)*sin(theta) +
        cos(psi)*cos(theta))*(-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1 -
        cos(delta))*sin(lam)*cos(lam) + w) + (sin(phi)*sin(psi)*cos(theta) +
        sin(theta)*cos(psi))*(-c*(1 - cos(delta))*sin(lam)*cos(lam) - r_F*((1 -
        cos(delta))*cos(lam)**2 + cos(delta)) + r_R)) - r_F*sqrt(1 -
        (sin(delta)*sin(lam)*cos(phi)*cos(theta) + sin(delta)*sin(theta)*cos(lam)*cos(phi) +
        sin(phi)*cos(delta))**2)*((-(-sin(phi)*sin(psi)*sin(theta) +
        cos(psi)*cos(theta))*sin(delta)*cos(lam) + (sin(phi)*sin(psi)*cos(theta) +
        sin(theta)*cos(psi))*sin(delta)*sin(lam) - sin(psi)*cos(delta)*cos(phi))*(theta_F_dot +
        (psi_dot*sin(phi) + theta_dot)*cos(delta) - (delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(delta)*cos(lam) + (delta_dot*cos(lam) +
        phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*sin(delta)*sin(lam)) + ((1 -
        cos(delta))*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta))*sin(lam)*cos(lam) +
        ((1 - cos(delta))*cos(lam)**2 + cos(delta))*(sin(phi)*sin(psi)*cos(theta) +
        sin(theta)*cos(psi)) + sin(delta)*sin(lam)*sin(psi)*cos(phi))*((1 -
        cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(lam)*cos(lam) - (psi_dot*sin(phi) +
        theta_dot)*sin(delta)*sin(lam) + ((1 - cos(delta))*cos(lam)**2 +
        cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))) +
        ((1 - cos(delta))*(sin(phi)*sin(psi)*cos(theta) + sin(theta)*cos(psi))*sin(lam)*cos(lam)
        + ((1 - cos(delta))*sin(lam)**2 + cos(delta))*(-sin(phi)*sin(psi)*sin(theta) +
        cos(psi)*cos(theta)) - sin(delta)*sin(psi)*cos(lam)*cos(phi))*((1 -
        cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta))*sin(lam)*cos(lam) + (psi_dot*sin(phi) +
        theta_dot)*sin(delta)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi)))) -
        r_F*(((1 - cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(lam)*cos(lam) - (psi_dot*sin(phi) +
        theta_dot)*sin(delta)*sin(lam) + ((1 - cos(delta))*cos(lam)**2 +
        cos(delta))*(delta_dot*cos(lam) + phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta)))*(-(1 - cos(delta))*sin(lam)*sin(theta)*cos(lam)*cos(phi) +
        ((1 - cos(delta))*cos(lam)**2 + cos(delta))*cos(phi)*cos(theta) -
        sin(delta)*sin(lam)*sin(phi)) + ((1 - cos(delta))*(delta_dot*cos(lam) +
        phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*sin(lam)*cos(lam) + (psi_dot*sin(phi)
        + theta_dot)*sin(delta)*cos(lam) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*(delta_dot*sin(lam) + phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi)))*((1
        - cos(delta))*sin(lam)*cos(lam)*cos(phi)*cos(theta) - ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*sin(theta)*cos(phi) + sin(delta)*sin(phi)*cos(lam)) +
        (sin(delta)*sin(lam)*cos(phi)*cos(theta) + sin(delta)*sin(theta)*cos(lam)*cos(phi) +
        sin(phi)*cos(delta))*(theta_F_dot + (psi_dot*sin(phi) + theta_dot)*cos(delta) -
        (delta_dot*sin(lam) + phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*sin(delta)*cos(lam) + (delta_dot*cos(lam) +
        phi_dot*sin(theta) +
        psi_dot*cos(phi)*cos(theta))*sin(delta)*sin(lam)))*(-(-sin(phi)*sin(psi)*sin(theta) +
        cos(psi)*cos(theta))*sin(delta)*cos(lam) + (sin(phi)*sin(psi)*cos(theta) +
        sin(theta)*cos(psi))*sin(delta)*sin(lam) -
        sin(psi)*cos(delta)*cos(phi))*(sin(delta)*sin(lam)*cos(phi)*cos(theta) +
        sin(delta)*sin(theta)*cos(lam)*cos(phi) + sin(phi)*cos(delta))/sqrt(1 -
        (sin(delta)*sin(lam)*cos(phi)*cos(theta) + sin(delta)*sin(theta)*cos(lam)*cos(phi) +
        sin(phi)*cos(delta))**2) + theta_dot*((sin(phi)*sin(theta)*cos(psi) +
        sin(psi)*cos(theta))*(-c*(1 - cos(delta))*sin(lam)*cos(lam) - r_F*((1 -
        cos(delta))*cos(lam)**2 + cos(delta)) + r_R) + (sin(phi)*cos(psi)*cos(theta) -
        sin(psi)*sin(theta))*(-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1 -
        cos(delta))*sin(lam)*cos(lam) + w)) + y_dot = 0

Generated by `stabdae generate kernels/specs/bicycle.py`
with stabdae 0.1.0 (stabdae.symbolic), sympy 1.14.0.  Spec SHA-256: b0a1d598a60a9da6
Edit the spec and regenerate rather than editing this file.
"""


import math

import numpy as np
from numba import njit

import stabdae
from stabdae import simdmath

# p = [w, c, lam, r_R, r_F, m_R, m_B, m_H, m_F, I_Rxx, I_Ryy, I_Bxx, I_Byy, I_Bzz, I_Bxz, I_Hxx,
#     I_Hyy, I_Hzz, I_Hxz, I_Fxx, I_Fyy, x_B, z_B, x_H, z_H, g, speed]


@njit(cache=True)
def mass(t, q, p, out):
    # M = ∂²L/∂v²
    psi, phi, theta, delta = q[2], q[3], q[4], q[6]
    w = p[0]
    c = p[1]
    lam = p[2]
    r_R = p[3]
    r_F = p[4]
    m_R = p[5]
    m_B = p[6]
    m_H = p[7]
    m_F = p[8]
    I_Rxx = p[9]
    I_Ryy = p[10]
    I_Bxx = p[11]
    I_Byy = p[12]
    I_Bzz = p[13]
    I_Bxz = p[14]
    I_Hxx = p[15]
    I_Hyy = p[16]
    I_Hzz = p[17]
    I_Hxz = p[18]
    I_Fxx = p[19]
    I_Fyy = p[20]
    x_B = p[21]
    z_B = p[22]
    x_H = p[23]
    z_H = p[24]
    e0 = m_B + m_F + m_H + m_R
    e1 = simdmath.cos(psi)
    e2 = simdmath.sin(phi)
    e3 = e2 * r_R
    e4 = e1 * e3
    e5 = 2.0 * e4
    e6 = simdmath.sin(psi)
    e7 = simdmath.cos(theta)
    e8 = e6 * e7
    e9 = simdmath.sin(theta)
    e10 = e1 * e9
    e11 = e10 * e2 + e8
    e12 = -e11
    e13 = e12 * x_B
    e14 = r_R + z_B
    e15 = e6 * e9
    e16 = e1 * e7
    e17 = -e15 + e16 * e2
    e18 = e14 * e17
    e19 = 2.0 * e13 + 2.0 * e18 - e5
    e20 = 0.5 * m_B
    e21 = simdmath.cos(phi)
    e22 = simdmath.sin(delta)
    e23 = simdmath.cos(lam)
    e24 = e22 * e23
    e25 = simdmath.sin(lam)
    e26 = -c * e24 + e22 * e25 * r_F
    e27 = e21 * e26
    e28 = e1 * e27
    e29 = simdmath.cos(delta)
    e30 = 1.0 - e29
    e31 = e23 * e25 * e30
    e32 = (e23 * e23)
    e33 = e30 * e32
    e34 = e29 + e33
    e35 = -c * e31 - e34 * r_F + r_R
    e36 = (e25 * e25)
    e37 = e30 * e36
    e38 = e29 + e37
    e39 = -c * e38 + c - e31 * r_F + w
    e40 = 2.0 * e12 * e39 + 2.0 * e17 * e35 - 2.0 * e28 - e5
    e41 = 0.5 * m_F
    e42 = e22 * e25
    e43 = e42 * z_H
    e44 = c + w
    e45 = -e44 + x_H
    e46 = e22 * e23 * e45 - e43
    e47 = e21 * e46
    e48 = e1 * e47
    e49 = e31 * e45 + e34 * z_H + r_R
    e50 = e31 * z_H + e38 * e45 + e44
    e51 = 2.0 * e12 * e50 + 2.0 * e17 * e49 - 2.0 * e48 - e5
    e52 = 0.5 * m_H
    e53 = e21 * r_R
    e54 = e53 * e6
    e55 = 2.0 * e54
    e56 = e21 * x_B
    e57 = e15 * e56
    e58 = 2.0 * e14 * e21 * e6 * e7 - e55 - 2.0 * e57
    e59 = e21 * e39
    e60 = e15 * e59
    e61 = 2.0 * e2 * e26 * e6 + 2.0 * e21 * e35 * e6 * e7 - e55 - 2.0 * e60
    e62 = e21 * e50
    e63 = e15 * e62
    e64 = 2.0 * e2 * e46 * e6 + 2.0 * e21 * e49 * e6 * e7 - e55 - 2.0 * e63
    e65 = e10 + e2 * e8
    e66 = -e65
    e67 = e66 * x_B
    e68 = e1 * e7 - e15 * e2
    e69 = e14 * e68
    e70 = 2.0 * e67 + 2.0 * e69
    e71 = e35 * e68
    e72 = e39 * e66
    e73 = 2.0 * e71 + 2.0 * e72
    e74 = e49 * e68
    e75 = e50 * e66
    e76 = 2.0 * e74 + 2.0 * e75
    e77 = -c * e23 * e29 + e25 * e29 * r_F
    e78 = e21 * e77
    e79 = e6 * e78
    e80 = e23 * e42
    e81 = -e22
    e82 = e22 * e32 + e81
    e83 = -c * e80 - e82 * r_F
    e84 = e65 * e83
    e85 = e22 * e36 + e81
    e86 = -c * e85 - e23 * e42 * r_F
    e87 = e68 * e86
    e88 = -2.0 * e79 + 2.0 * e84 + 2.0 * e87
    e89 = e23 * e29 * e45 - e25 * e29 * z_H
    e90 = e21 * e89
    e91 = e6 * e90
    e92 = e45 * e80 + e82 * z_H
    e93 = e65 * e92
    e94 = e23 * e43 + e45 * e85
    e95 = e68 * e94
    e96 = -2.0 * e91 + 2.0 * e93 + 2.0 * e95
    e97 = e3 * e6
    e98 = 2.0 * e97
    e99 = e68 * x_B
    e100 = e14 * e65
    e101 = 2.0 * e100 - e98 + 2.0 * e99
    e102 = e27 * e6
    e103 = -2.0 * e102 + 2.0 * e35 * e65 + 2.0 * e39 * e68 - e98
    e104 = e47 * e6
    e105 = -2.0 * e104 + 2.0 * e49 * e65 + 2.0 * e50 * e68 - e98
    e106 = e1 * e53
    e107 = 2.0 * e106
    e108 = e10 * e56
    e109 = e14 * e16 * e21
    e110 = e107 + 2.0 * e108 - 2.0 * e109
    e111 = e1 * e2 * e26
    e112 = e16 * e21 * e35
    e113 = e10 * e59
    e114 = e107 - 2.0 * e111 - 2.0 * e112 + 2.0 * e113
    e115 = e1 * e2 * e46
    e116 = e16 * e21 * e49
    e117 = e10 * e62
    e118 = e107 - 2.0 * e115 - 2.0 * e116 + 2.0 * e117
    e119 = e17 * x_B
    e120 = e11 * e14
    e121 = 2.0 * e119 + 2.0 * e120
    e122 = e11 * e35
    e123 = e17 * e39
    e124 = 2.0 * e122 + 2.0 * e123
    e125 = e11 * e49
    e126 = e17 * e50
    e127 = 2.0 * e125 + 2.0 * e126
    e128 = e1 * e78
    e129 = e11 * e86
    e130 = -e17
    e131 = e130 * e83
    e132 = 2.0 * e128 + 2.0 * e129 + 2.0 * e131
    e133 = e1 * e90
    e134 = e11 * e94
    e135 = e130 * e92
    e136 = 2.0 * e133 + 2.0 * e134 + 2.0 * e135
    e137 = (e2 * e2)
    e138 = I_Bxz * e9
    e139 = I_Bzz * e21 * e7 - e138 * e21
    e140 = e21 * e7
    e141 = e21 * e9
    e142 = -I_Bxx * e141 + I_Bxz * e21 * e7
    e143 = (e21 * e21)
    e144 = 2.0 * (e9 * e9)
    e145 = 2.0 * (e7 * e7)
    e146 = 0.5 * I_Rxx
    e147 = (e6 * e6)
    e148 = 2.0 * (r_R * r_R)
    e149 = e137 * e148
    e150 = (e1 * e1)
    e151 = 0.5 * m_R
    e152 = e2 * e29
    e153 = e140 * e42
    e154 = e141 * e24
    e155 = e152 + e153 + e154
    e156 = 2.0 * e152 + 2.0 * e153 + 2.0 * e154
    e157 = 0.5 * I_Fyy
    e158 = e156 * e157
    e159 = 0.5 * e156
    e160 = I_Hyy * e159
    e161 = e2 * e24
    e162 = e140 * e31
    e163 = e141 * e38
    e164 = e161 + e162 - e163
    e165 = e2 * e42
    e166 = e141 * e31
    e167 = -e165 - e166 + e21 * e34 * e7
    e168 = I_Hxx * e164 + I_Hxz * e167
    e169 = I_Hxz * e164 + I_Hzz * e167
    e170 = 2.0 * e161 + 2.0 * e162 - 2.0 * e163
    e171 = -2.0 * e165 - 2.0 * e166 + 2.0 * e21 * e34 * e7
    e172 = 0.5 * I_Fxx
    e173 = I_Bxx * e7 + e138
    e174 = I_Bxz * e7 + I_Bzz * e9
    e175 = e42 * e9
    e176 = e24 * e7
    e177 = e175 - e176
    e178 = e31 * e9
    e179 = e38 * e7
    e180 = e178 + e179
    e181 = e31 * e7
    e182 = e34 * e9
    e183 = e181 + e182
    e184 = I_Hxx * e180 + I_Hxz * e183
    e185 = 0.5 * e164
    e186 = I_Hxz * e180 + I_Hzz * e183
    e187 = 0.5 * e167
    e188 = 0.5 * e168
    e189 = 0.5 * e169
    e190 = e106 + e108 - e109
    e191 = e14 * e21 * e6 * e7 - e54 - e57
    e192 = e106 - e111 - e112 + e113
    e193 = e2 * e26 * e6 + e21 * e35 * e6 * e7 - e54 - e60
    e194 = e106 - e115 - e116 + e117
    e195 = e2 * e46 * e6 + e21 * e49 * e6 * e7 - e54 - e63
    e196 = I_Ryy * e2
    e197 = I_Fyy * e29
    e198 = I_Hxx * e24 - I_Hxz * e42
    e199 = I_Hxz * e24 - I_Hzz * e42
    e200 = e119 + e120
    e201 = e67 + e69
    e202 = e122 + e123
    e203 = e71 + e72
    e204 = e125 + e126
    e205 = e74 + e75
    e206 = e25 * e33
    e207 = e25 * e38
    e208 = e206 + e207
    e209 = e23 * e37
    e210 = e23 * e34
    e211 = e209 + e210
    e212 = I_Hxx * e208 + I_Hxz * e211
    e213 = I_Hxz * e208 + I_Hzz * e211
    e214 = e128 + e129 + e131
    e215 = -e79 + e84 + e87
    e216 = e133 + e134 + e135
    e217 = -e91 + e93 + e95
    e218 = 2.0 * e175 - 2.0 * e176
    e219 = e157 * e218
    e220 = 0.5 * e218
    e221 = I_Hyy * e220
    e222 = e143 * e148
    e223 = 2.0 * e178 + 2.0 * e179
    e224 = 2.0 * e181 + 2.0 * e182
    e225 = e2 * e9
    e226 = e225 * x_B
    e227 = e2 * e7
    e228 = e14 * e227
    e229 = 2.0 * e3
    e230 = 2.0 * e226 - 2.0 * e228 + e229
    e231 = e227 * e35
    e232 = e225 * e39
    e233 = e229 - 2.0 * e231 + 2.0 * e232 + 2.0 * e27
    e234 = e227 * e49
    e235 = e225 * e50
    e236 = e229 - 2.0 * e234 + 2.0 * e235 + 2.0 * e47
    e237 = 0.5 * e180
    e238 = 0.5 * e183
    e239 = 0.5 * e24
    e240 = 0.5 * e42
    e241 = e140 * x_B
    e242 = e14 * e141
    e243 = -e241 - e242
    e244 = e141 * e35
    e245 = e140 * e39
    e246 = -e244 - e245
    e247 = e141 * e49
    e248 = e140 * e50
    e249 = -e247 - e248
    e250 = 0.5 * e208
    e251 = 0.5 * e211
    e252 = e2 * e77
    e253 = e140 * e83
    e254 = e141 * e86
    e255 = e252 + e253 - e254
    e256 = e2 * e89
    e257 = e140 * e92
    e258 = e141 * e94
    e259 = e256 + e257 - e258
    e260 = (e29 * e29)
    e261 = 2.0 * (e22 * e22)
    e262 = -2.0 * e244 - 2.0 * e245
    e263 = -2.0 * e247 - 2.0 * e248
    out[:, :] = 0.0
    out[0, 0] = e0
    out[0, 2] = e19 * e20 - e4 * m_R + e40 * e41 + e51 * e52
    out[0, 3] = e20 * e58 + e41 * e61 + e52 * e64 - e54 * m_R
    out[0, 4] = e20 * e70 + e41 * e73 + e52 * e76
    out[0, 6] = e41 * e88 + e52 * e96
    out[1, 1] = e0
    out[1, 2] = e101 * e20 + e103 * e41 + e105 * e52 - e97 * m_R
    out[1, 3] = e106 * m_R + e110 * e20 + e114 * e41 + e118 * e52
    out[1, 4] = e121 * e20 + e124 * e41 + e127 * e52
    out[1, 6] = e132 * e41 + e136 * e52
    out[2, 2] = (
        I_Byy * e137 + I_Ryy * e137 + e139 * e140 - e141 * e142 + e146 * (e143 * e144 + e143 * e145)
        + e151 * (e147 * e149 + e149 * e150) + e155 * e158 + e155 * e160 + e164 * e168 + e167 * e169
        + e172 * (e164 * e170 + e167 * e171)
        + e20 * (e101 * (e100 - e97 + e99) + e19 * (e13 + e18 - e4))
        + e41
          * (
                e103 * (-e102 + e35 * e65 + e39 * e68 - e97)
                + e40 * (e12 * e39 + e17 * e35 - e28 - e4)
            )
         + e52
        * (e105 * (-e104 + e49 * e65 + e50 * e68 - e97) + e51 * (e12 * e50 + e17 * e49 - e4 - e48))
    )
    out[2, 3] = (
        0.5 * e139 * e9 + 0.5 * e140 * e174 - 0.5 * e141 * e173 + 0.5 * e142 * e7 + e158 * e177
        + e160 * e177 + e172 * (e170 * e180 + e171 * e183) + e180 * e188 + e183 * e189 + e184 * e185
        + e186 * e187 + e20 * (e101 * e190 + e19 * e191) + e41 * (e103 * e192 + e193 * e40)
        + e52 * (e105 * e194 + e195 * e51)
    )
    out[2, 4] = (
        I_Byy * e2 + e159 * e197 + e160 * e29 + e172 * (e170 * e22 * e23 - e171 * e42) + e185 * e198
        + e187 * e199 + e188 * e24 - e189 * e42 + e196 + e20 * (e101 * e200 + e19 * e201)
        + e41 * (e103 * e202 + e203 * e40) + e52 * (e105 * e204 + e205 * e51)
    )
    out[2, 5] = e196
    out[2, 6] = (
        e172 * (e170 * e208 + e171 * e211) + e185 * e212 + e187 * e213 + e188 * e208 + e189 * e211
        + e41 * (e103 * e214 + e215 * e40) + e52 * (e105 * e216 + e217 * e51)
    )
    out[2, 7] = e158
    out[3, 3] = (
        e146 * (e144 + e145) + e151 * (e147 * e222 + e149 + e150 * e222)
        + e172 * (e180 * e223 + e183 * e224) + e173 * e7 + e174 * e9 + e177 * e219 + e177 * e221
        + e180 * e184 + e183 * e186 + e20 * (e110 * e190 + e191 * e58 + e230 * (e226 - e228 + e3))
        + e41 * (e114 * e192 + e193 * e61 + e233 * (-e231 + e232 + e27 + e3))
        + e52 * (e118 * e194 + e195 * e64 + e236 * (-e234 + e235 + e3 + e47))
    )
    out[3, 4] = (
        e172 * (e223 * e24 - e224 * e42) + e184 * e239 - e186 * e240 + e197 * e220 + e198 * e237
        + e199 * e238 + e20 * (e110 * e200 + e201 * e58 + e230 * e243) + e221 * e29
        + e41 * (e114 * e202 + e203 * e61 + e233 * e246)
        + e52 * (e118 * e204 + e205 * e64 + e236 * e249)
    )
    out[3, 6] = (
        e172 * (e208 * e223 + e211 * e224) + e184 * e250 + e186 * e251 + e212 * e237 + e213 * e238
        + e41 * (e114 * e214 + e215 * e61 + e233 * e255)
        + e52 * (e118 * e216 + e217 * e64 + e236 * e259)
    )
    out[3, 7] = e219
    out[4, 4] = (
        I_Byy + I_Fyy * e260 + I_Hyy * e260 + I_Ryy + e172 * (e261 * e32 + e261 * e36) + e198 * e24
        - e199 * e42 + e20 * (e121 * e200 + e201 * e70 + e243 * (-2.0 * e241 - 2.0 * e242))
        + e41 * (e124 * e202 + e203 * e73 + e246 * e262)
        + e52 * (e127 * e204 + e205 * e76 + e249 * e263)
    )
    out[4, 5] = I_Ryy
    out[4, 6] = (
        e172 * (2.0 * e208 * e24 - 2.0 * e211 * e42) + e198 * e250 + e199 * e251 + e212 * e239
        - e213 * e240 + e41 * (e124 * e214 + e215 * e73 + e255 * e262)
        + e52 * (e127 * e216 + e217 * e76 + e259 * e263)
    )
    out[4, 7] = e197
    out[5, 5] = I_Ryy
    out[6, 6] = (
        e172 * (e208 * (2.0 * e206 + 2.0 * e207) + e211 * (2.0 * e209 + 2.0 * e210)) + e208 * e212
        + e211 * e213
        + e41 * (e132 * e214 + e215 * e88 + e255 * (2.0 * e252 + 2.0 * e253 - 2.0 * e254))
        + e52 * (e136 * e216 + e217 * e96 + e259 * (2.0 * e256 + 2.0 * e257 - 2.0 * e258))
    )
    out[7, 7] = I_Fyy
    out[2, 0] = out[0, 2]
    out[2, 1] = out[1, 2]
    out[3, 0] = out[0, 3]
    out[3, 1] = out[1, 3]
    out[3, 2] = out[2, 3]
    out[4, 0] = out[0, 4]
    out[4, 1] = out[1, 4]
    out[4, 2] = out[2, 4]
    out[4, 3] = out[3, 4]
    out[5, 2] = out[2, 5]
    out[5, 4] = out[4, 5]
    out[6, 0] = out[0, 6]
    out[6, 1] = out[1, 6]
    out[6, 2] = out[2, 6]
    out[6, 3] = out[3, 6]
    out[6, 4] = out[4, 6]
    out[7, 2] = out[2, 7]
    out[7, 3] = out[3, 7]
    out[7, 4] = out[4, 7]


@njit(cache=True)
def forces(t, q, v, p, out):
    # γ = (∂²L/∂v∂q) v + ∂²L/∂v∂t − ∂L/∂q − Q, so that M v̇ = Fᵀλ − γ  (3.3)
    psi, phi, theta, delta = q[2], q[3], q[4], q[6]
    x_dot = v[0]
    y_dot = v[1]
    psi_dot = v[2]
    phi_dot = v[3]
    theta_dot = v[4]
    theta_R_dot = v[5]
    delta_dot = v[6]
    theta_F_dot = v[7]
    w = p[0]
    c = p[1]
    lam = p[2]
    r_R = p[3]
    r_F = p[4]
    m_R = p[5]
    m_B = p[6]
    m_H = p[7]
    m_F = p[8]
    I_Rxx = p[9]
    I_Ryy = p[10]
    I_Bxx = p[11]
    I_Byy = p[12]
    I_Bzz = p[13]
    I_Bxz = p[14]
    I_Hxx = p[15]
    I_Hyy = p[16]
    I_Hzz = p[17]
    I_Hxz = p[18]
    I_Fxx = p[19]
    I_Fyy = p[20]
    x_B = p[21]
    z_B = p[22]
    x_H = p[23]
    z_H = p[24]
    g = p[25]
    e0 = simdmath.cos(psi)
    e1 = simdmath.cos(phi)
    e2 = e1 * r_R
    e3 = e0 * e2
    e4 = e3 * psi_dot
    e5 = 4.0 * phi_dot
    e6 = (phi_dot * phi_dot)
    e7 = simdmath.sin(psi)
    e8 = simdmath.sin(phi)
    e9 = e8 * r_R
    e10 = e7 * e9
    e11 = 2.0 * e10
    e12 = (psi_dot * psi_dot)
    e13 = 0.5 * m_R
    e14 = simdmath.sin(theta)
    e15 = e0 * e14
    e16 = e15 * psi_dot
    e17 = e1 * x_B
    e18 = e16 * e17
    e19 = simdmath.cos(theta)
    e20 = e19 * e7
    e21 = e20 * theta_dot
    e22 = e17 * e21
    e23 = r_R + z_B
    e24 = e20 * e8
    e25 = e23 * e24
    e26 = e14 * e7
    e27 = e26 * theta_dot
    e28 = e1 * e23
    e29 = e27 * e28
    e30 = (
        phi_dot
        * (
              e0 * e1 * e19 * e23 * psi_dot + e14 * e7 * e8 * phi_dot * x_B - e18 - e22
              - e25 * phi_dot - e29 - e4 + e7 * e8 * phi_dot * r_R
          )
    )
    e31 = e0 * e19
    e32 = e31 * theta_dot
    e33 = e1 * phi_dot
    e34 = e8 * psi_dot
    e35 = -e14 * e7 * e8 * theta_dot - e14 * e7 * psi_dot + e20 * e33 + e31 * e34 + e32
    e36 = -e35
    e37 = e36 * x_B
    e38 = e15 * theta_dot
    e39 = -e15 * e34 - e20 * psi_dot - e21 * e8 - e26 * e33 - e38
    e40 = e23 * e39
    e41 = theta_dot * (e37 + e40)
    e42 = e31 * psi_dot
    e43 = -e14 * e7 * e8 * psi_dot - e14 * e7 * theta_dot + e15 * e33 + e32 * e8 + e42
    e44 = -e43
    e45 = e44 * x_B
    e46 = -e0 * e1 * e19 * phi_dot + e16 + e20 * e34 + e21 + e38 * e8
    e47 = -e46
    e48 = e23 * e47
    e49 = e34 * r_R
    e50 = e49 * e7
    e51 = e3 * phi_dot
    e52 = e50 - e51
    e53 = psi_dot * (e45 + e48 + e52)
    e54 = 0.5 * m_B
    e55 = e26 * e8
    e56 = -e0 * e19 + e55
    e57 = -e56
    e58 = simdmath.sin(lam)
    e59 = simdmath.sin(delta)
    e60 = delta_dot * e59
    e61 = simdmath.cos(lam)
    e62 = c * e61
    e63 = e60 * e62
    e64 = -e60
    e65 = (e61 * e61)
    e66 = e59 * e65
    e67 = delta_dot * e66 + e64
    e68 = -e58 * e63 - e67 * r_F
    e69 = e57 * e68
    e70 = e15 + e24
    e71 = -e70
    e72 = e58 * r_F
    e73 = e60 * e72
    e74 = (e58 * e58)
    e75 = e59 * e74
    e76 = delta_dot * e75 + e64
    e77 = -c * e76 - e61 * e73
    e78 = e71 * e77
    e79 = simdmath.cos(delta)
    e80 = 1.0 - e79
    e81 = e61 * e80
    e82 = e74 * e80
    e83 = e79 + e82
    e84 = -c * e83 + c - e72 * e81 + w
    e85 = e36 * e84
    e86 = e58 * e80
    e87 = e65 * e80
    e88 = e79 + e87
    e89 = -e62 * e86 - e88 * r_F + r_R
    e90 = e39 * e89
    e91 = theta_dot * (e69 + e78 + e85 + e90)
    e92 = e62 * e79
    e93 = e58 * e79 * r_F - e92
    e94 = e8 * e93
    e95 = e7 * e94
    e96 = e1 * e93
    e97 = e0 * e96
    e98 = e63 - e73
    e99 = e1 * e7
    e100 = e98 * e99
    e101 = delta_dot * e79
    e102 = e101 * e62
    e103 = -e101
    e104 = e101 * e65 + e103
    e105 = -e102 * e58 - e104 * r_F
    e106 = e105 * e70
    e107 = e101 * e74 + e103
    e108 = -c * e107 - e101 * e61 * e72
    e109 = e108 * e57
    e110 = e59 * e62
    e111 = -e59
    e112 = e111 + e66
    e113 = -e110 * e58 - e112 * r_F
    e114 = e113 * e35
    e115 = e111 + e75
    e116 = -c * e115 - e59 * e61 * e72
    e117 = e116 * e39
    e118 = delta_dot * (-e100 + e106 + e109 + e114 + e117 + e95 * phi_dot - e97 * psi_dot)
    e119 = e15 * e8
    e120 = e119 + e20
    e121 = -e120
    e122 = e121 * e77
    e123 = -e26 + e31 * e8
    e124 = e123 * e68
    e125 = e47 * e89
    e126 = e44 * e84
    e127 = delta_dot * e58 * e79 * r_F - e102
    e128 = e1 * e127
    e129 = e0 * e128
    e130 = e110 - e58 * e59 * r_F
    e131 = -e130
    e132 = e131 * e8
    e133 = e0 * e132
    e134 = e1 * e131
    e135 = e134 * e7
    e136 = psi_dot * (e122 + e124 + e125 + e126 - e129 + e133 * phi_dot + e135 * psi_dot + e52)
    e137 = e7 * e8
    e138 = e127 * e137
    e139 = e0 * e34
    e140 = e131 * e139
    e141 = e1 * e20
    e142 = e141 * e68
    e143 = e1 * e26
    e144 = e143 * e77
    e145 = e55 * e84
    e146 = e1 * e89
    e147 = e146 * e42
    e148 = e24 * e89
    e149 = e1 * e84
    e150 = e149 * e16
    e151 = e146 * e27
    e152 = e149 * e21
    e153 = e10 * phi_dot - e4
    e154 = (
        phi_dot
        * (
              e135 * phi_dot + e138 + e140 + e142 - e144 + e145 * phi_dot + e147 - e148 * phi_dot
              - e150 - e151 - e152 + e153
          )
    )
    e155 = 0.5 * m_F
    e156 = c + w
    e157 = -e156 + x_H
    e158 = e157 * e61
    e159 = e158 * e60
    e160 = e159 * e58 + e67 * z_H
    e161 = e160 * e57
    e162 = e58 * z_H
    e163 = e162 * e60
    e164 = e157 * e76 + e163 * e61
    e165 = e164 * e71
    e166 = e156 + e157 * e83 + e162 * e81
    e167 = e166 * e36
    e168 = e158 * e86 + e88 * z_H + r_R
    e169 = e168 * e39
    e170 = theta_dot * (e161 + e165 + e167 + e169)
    e171 = e162 * e79
    e172 = e157 * e61 * e79 - e171
    e173 = e172 * e8
    e174 = e173 * e7
    e175 = e1 * e172
    e176 = e0 * e175
    e177 = -e159 + e163
    e178 = e177 * e99
    e179 = e101 * e158 * e58 + e104 * z_H
    e180 = e179 * e70
    e181 = e101 * e162
    e182 = e107 * e157 + e181 * e61
    e183 = e182 * e57
    e184 = e112 * z_H + e158 * e58 * e59
    e185 = e184 * e35
    e186 = e162 * e59
    e187 = e115 * e157 + e186 * e61
    e188 = e187 * e39
    e189 = delta_dot * (e174 * phi_dot - e176 * psi_dot - e178 + e180 + e183 + e185 + e188)
    e190 = e123 * e160
    e191 = e121 * e164
    e192 = e168 * e47
    e193 = e166 * e44
    e194 = delta_dot * e157 * e61 * e79 - e181
    e195 = e1 * e194
    e196 = e0 * e195
    e197 = -e157 * e59 * e61 + e186
    e198 = -e197
    e199 = e198 * e8
    e200 = e0 * e199
    e201 = e1 * e198
    e202 = e201 * e7
    e203 = psi_dot * (e190 + e191 + e192 + e193 - e196 + e200 * phi_dot + e202 * psi_dot + e52)
    e204 = e137 * e194
    e205 = e139 * e198
    e206 = e141 * e160
    e207 = e143 * e164
    e208 = e166 * e55
    e209 = e1 * e168
    e210 = e209 * e42
    e211 = e168 * e24
    e212 = e1 * e166
    e213 = e16 * e212
    e214 = e209 * e27
    e215 = e21 * e212
    e216 = (
        phi_dot
        * (
              e153 + e202 * phi_dot + e204 + e205 + e206 - e207 + e208 * phi_dot + e210
              - e211 * phi_dot - e213 - e214 - e215
          )
    )
    e217 = 0.5 * m_H
    e218 = e2 * e7
    e219 = e218 * psi_dot
    e220 = e0 * e9
    e221 = 2.0 * e220
    e222 = e119 * x_B
    e223 = e26 * psi_dot
    e224 = e17 * e223
    e225 = e219 + e220 * phi_dot
    e226 = (
        phi_dot
        * (
              e0 * e1 * e14 * e23 * theta_dot + e0 * e1 * e19 * theta_dot * x_B
              + e0 * e19 * e23 * e8 * phi_dot + e1 * e19 * e23 * e7 * psi_dot - e222 * phi_dot
              - e224 - e225
          )
    )
    e227 = e47 * x_B
    e228 = e23 * e43
    e229 = theta_dot * (e227 + e228)
    e230 = e218 * phi_dot
    e231 = e0 * e49
    e232 = e230 + e231
    e233 = psi_dot * (e23 * e35 - e232 + e39 * x_B)
    e234 = e120 * e68
    e235 = e123 * e77
    e236 = e43 * e89
    e237 = e47 * e84
    e238 = theta_dot * (e234 + e235 + e236 + e237)
    e239 = e0 * e1
    e240 = e239 * e98
    e241 = e0 * e94
    e242 = e7 * e96
    e243 = e108 * e120
    e244 = -e123
    e245 = e105 * e244
    e246 = e113 * e46
    e247 = e116 * e43
    e248 = delta_dot * (e240 - e241 * phi_dot - e242 * psi_dot + e243 + e245 + e246 + e247)
    e249 = e57 * e77
    e250 = e68 * e70
    e251 = e35 * e89
    e252 = e39 * e84
    e253 = e128 * e7
    e254 = e132 * e7
    e255 = e0 * e134
    e256 = -e230 - e231
    e257 = psi_dot * (e249 + e250 + e251 + e252 - e253 + e254 * phi_dot - e255 * psi_dot + e256)
    e258 = e0 * e8
    e259 = e127 * e258
    e260 = e1 * e31
    e261 = e260 * e68
    e262 = e119 * e84
    e263 = e149 * e223
    e264 = (
        phi_dot
        * (
              e0 * e1 * e14 * e77 + e0 * e1 * e14 * e89 * theta_dot
              + e0 * e1 * e19 * e84 * theta_dot + e0 * e19 * e8 * e89 * phi_dot
              + e1 * e19 * e7 * e89 * psi_dot + e131 * e7 * e8 * psi_dot - e225 - e255 * phi_dot
              - e259 - e261 - e262 * phi_dot - e263
          )
    )
    e265 = e120 * e160
    e266 = e123 * e164
    e267 = e168 * e43
    e268 = e166 * e47
    e269 = theta_dot * (e265 + e266 + e267 + e268)
    e270 = e177 * e239
    e271 = e0 * e173
    e272 = e175 * e7
    e273 = e120 * e182
    e274 = e179 * e244
    e275 = e184 * e46
    e276 = e187 * e43
    e277 = delta_dot * (e270 - e271 * phi_dot - e272 * psi_dot + e273 + e274 + e275 + e276)
    e278 = e160 * e70
    e279 = e164 * e57
    e280 = e168 * e35
    e281 = e166 * e39
    e282 = e195 * e7
    e283 = e199 * e7
    e284 = e0 * e201
    e285 = psi_dot * (e256 + e278 + e279 + e280 + e281 - e282 + e283 * phi_dot - e284 * psi_dot)
    e286 = e194 * e258
    e287 = e160 * e260
    e288 = e119 * e166
    e289 = e212 * e223
    e290 = (
        phi_dot
        * (
              e0 * e1 * e14 * e164 + e0 * e1 * e14 * e168 * theta_dot
              + e0 * e1 * e166 * e19 * theta_dot + e0 * e168 * e19 * e8 * phi_dot
              + e1 * e168 * e19 * e7 * psi_dot + e198 * e7 * e8 * psi_dot - e225 - e284 * phi_dot
              - e286 - e287 - e288 * phi_dot - e289
          )
    )
    e291 = e33 * e34
    e292 = e34 + theta_dot
    e293 = I_Byy * e292
    e294 = I_Ryy * (e292 + theta_R_dot)
    e295 = e14 * phi_dot
    e296 = e1 * psi_dot
    e297 = e19 * e296
    e298 = e295 + e297
    e299 = e19 * phi_dot
    e300 = e14 * e296
    e301 = e299 - e300
    e302 = 0.5 * I_Bxx * e301 + 0.5 * I_Bxz * e298
    e303 = e295 * e8
    e304 = e299 * e8
    e305 = I_Bxz * e301
    e306 = I_Bzz * e298 + e305
    e307 = 0.5 * e306
    e308 = e1 * e19
    e309 = e1 * e14
    e310 = e14 * e8 * phi_dot * psi_dot - e295 * theta_dot - e297 * theta_dot
    e311 = 0.5 * e310
    e312 = I_Bxz * e14
    e313 = e1 * e312
    e314 = e19 * phi_dot * theta_dot - e299 * e34 - e300 * theta_dot
    e315 = 0.5 * e314
    e316 = I_Bxz * e19
    e317 = I_Bzz * e14
    e318 = e1 * theta_dot
    e319 = 0.5 * e298
    e320 = I_Bxx * e19
    e321 = 0.5 * e301
    e322 = 0.5 * I_Bxx * e310 + 0.5 * I_Bxz * e314
    e323 = 0.5 * I_Bxz * e310 + 0.5 * I_Bzz * e314
    e324 = 2.0 * phi_dot
    e325 = e218 * e324
    e326 = 2.0 * e231
    e327 = e325 + e326
    e328 = -e50 + e51 + y_dot
    e329 = e3 * e324
    e330 = -e232 + x_dot
    e331 = 2.0 * e8
    e332 = e299 * e331
    e333 = 2.0 * theta_dot
    e334 = e309 * e333
    e335 = e308 * e333
    e336 = 2.0 * e310
    e337 = 0.5 * I_Rxx
    e338 = e59 * e8
    e339 = e338 * e58
    e340 = 2.0 * e299
    e341 = e338 * e61
    e342 = 2.0 * e295
    e343 = e58 * e59
    e344 = (
        2.0 * delta_dot * e1 * e14 * e61 * e79 + 2.0 * delta_dot * e1 * e19 * e58 * e79
        + 2.0 * e1 * e19 * e59 * e61 * theta_dot + 2.0 * e1 * e79 * phi_dot - e331 * e60
        - e334 * e343 - e339 * e340 - e341 * e342
    )
    e345 = e292 * e79
    e346 = delta_dot * e61
    e347 = e298 + e346
    e348 = e343 * e347
    e349 = delta_dot * e58
    e350 = e301 + e349
    e351 = e59 * e61
    e352 = e345 + e348 - e350 * e351
    e353 = 0.5 * I_Hyy
    e354 = e352 * e353
    e355 = e352 + theta_F_dot
    e356 = 0.5 * I_Fyy
    e357 = e355 * e356
    e358 = e292 * e60
    e359 = e101 * e61
    e360 = e350 * e359
    e361 = e310 * e351
    e362 = (
        delta_dot * e347 * e58 * e79 + e1 * e79 * phi_dot * psi_dot + e314 * e58 * e59 - e358 - e360
        - e361
    )
    e363 = 2.0 * e343
    e364 = 2.0 * e351
    e365 = e362 * (e308 * e363 + e309 * e364 + e331 * e79)
    e366 = e10 * e12 + e10 * e6 - e324 * e4
    e367 = -e12 * e220 - e219 * e324 - e220 * e6
    e368 = e58 * e81
    e369 = e308 * e368
    e370 = e309 * e83
    e371 = e341 + e369 - e370
    e372 = e309 * e368
    e373 = e1 * e19 * e88 - e339 - e372
    e374 = e296 * e351
    e375 = e101 * e292
    e376 = e60 * e61
    e377 = e310 * e83 + e314 * e368 + e347 * e376 * e58 + e350 * e76 + e374 * phi_dot + e375 * e61
    e378 = 0.5 * e377
    e379 = e296 * e343
    e380 = e350 * e61
    e381 = e310 * e368 + e314 * e88 + e347 * e67 - e375 * e58 - e379 * phi_dot + e380 * e58 * e60
    e382 = 0.5 * e381
    e383 = e101 * e8
    e384 = e376 * e58
    e385 = e308 * e384
    e386 = e309 * e76
    e387 = e19 * e83
    e388 = (
        e303 * e83 - e304 * e368 - e318 * e387 + e33 * e351 - e372 * theta_dot + e383 * e61 + e385
        - e386
    )
    e389 = e292 * e59
    e390 = e347 * e368 + e350 * e83 + e389 * e61
    e391 = e347 * e88 + e350 * e368 - e389 * e58
    e392 = I_Hxx * e390 + I_Hxz * e391
    e393 = 0.5 * e392
    e394 = e309 * e384
    e395 = e14 * e88
    e396 = (
        e1 * e19 * e67 + e14 * e58 * e61 * e8 * e80 * phi_dot - e304 * e88 - e318 * e395
        - e33 * e343 - e369 * theta_dot - e383 * e58 - e394
    )
    e397 = 0.5 * I_Hxz * e390 + 0.5 * I_Hzz * e391
    e398 = 0.5 * e390
    e399 = 0.5 * e391
    e400 = I_Hxx * e377 + I_Hxz * e381
    e401 = 0.5 * e400
    e402 = 0.5 * I_Hxz * e377 + 0.5 * I_Hzz * e381
    e403 = e1 * e15
    e404 = e403 * x_B
    e405 = e23 * e260
    e406 = e3 + e404 - e405
    e407 = e123 * x_B
    e408 = e120 * e23
    e409 = e57 * x_B
    e410 = e23 * e70
    e411 = e406 * phi_dot + psi_dot * (-e10 + e409 + e410) + theta_dot * (e407 + e408) + y_dot
    e412 = e143 * x_B
    e413 = e1 * e19 * e23 * e7 - e218 - e412
    e414 = e413 * phi_dot
    e415 = e71 * x_B
    e416 = e23 * e57
    e417 = e415 + e416
    e418 = e417 * theta_dot
    e419 = e121 * x_B
    e420 = e123 * e23
    e421 = e419 + e420
    e422 = psi_dot * (-e220 + e421)
    e423 = e414 + e418 + e422 + x_dot
    e424 = -e406
    e425 = e121 * e23 + e244 * x_B
    e426 = e23 * e71 + e56 * x_B
    e427 = 2.0 * psi_dot
    e428 = e1 * e324
    e429 = e295 * e331
    e430 = e1 * e333
    e431 = e101 * e58
    e432 = 0.5 * I_Fxx
    e433 = -e329 + 2.0 * e50
    e434 = e226 + e229 + e233
    e435 = e30 + e41 + e53
    e436 = e120 * e89
    e437 = e123 * e84
    e438 = e116 * e120
    e439 = e113 * e244
    e440 = e260 * e89
    e441 = e403 * e84
    e442 = -e133 + e3 - e440 + e441
    e443 = e10 + e135
    e444 = (
        delta_dot * (e438 + e439 + e97) + e442 * phi_dot + psi_dot * (-e443 + e57 * e84 + e70 * e89)
        + theta_dot * (e436 + e437) + y_dot
    )
    e445 = e57 * e89
    e446 = e71 * e84
    e447 = e445 + e446
    e448 = e447 * theta_dot
    e449 = e113 * e70
    e450 = e116 * e57
    e451 = -e242 + e449 + e450
    e452 = delta_dot * e451
    e453 = e143 * e84
    e454 = e1 * e19 * e7 * e89 + e131 * e7 * e8 - e218 - e453
    e455 = e454 * phi_dot
    e456 = e220 + e255
    e457 = psi_dot * (e121 * e84 + e123 * e89 - e456)
    e458 = e448 + e452 + e455 + e457 + x_dot
    e459 = e121 * e89 + e244 * e84
    e460 = e113 * e123 + e116 * e121 - e97
    e461 = 2.0 * delta_dot
    e462 = -e442
    e463 = e56 * e84 + e71 * e89
    e464 = e120 * e168
    e465 = e123 * e166
    e466 = e120 * e187
    e467 = e184 * e244
    e468 = e168 * e260
    e469 = e166 * e403
    e470 = -e200 + e3 - e468 + e469
    e471 = e10 + e202
    e472 = (
        delta_dot * (e176 + e466 + e467) + e470 * phi_dot
        + psi_dot * (e166 * e57 + e168 * e70 - e471) + theta_dot * (e464 + e465) + y_dot
    )
    e473 = e168 * e57
    e474 = e166 * e71
    e475 = e473 + e474
    e476 = e475 * theta_dot
    e477 = e184 * e70
    e478 = e187 * e57
    e479 = -e272 + e477 + e478
    e480 = delta_dot * e479
    e481 = e143 * e166
    e482 = e1 * e168 * e19 * e7 + e198 * e7 * e8 - e218 - e481
    e483 = e482 * phi_dot
    e484 = e220 + e284
    e485 = psi_dot * (e121 * e166 + e123 * e168 - e484)
    e486 = e476 + e480 + e483 + e485 + x_dot
    e487 = e121 * e168 + e166 * e244
    e488 = e121 * e187 + e123 * e184 - e176
    e489 = -e470
    e490 = e166 * e56 + e168 * e71
    e491 = -e325 - e326
    e492 = e238 + e248 + e257 + e264
    e493 = e118 + e136 + e154 + e91
    e494 = e269 + e277 + e285 + e290
    e495 = e170 + e189 + e203 + e216
    e496 = e14 * theta_dot
    e497 = e19 * e34
    e498 = e14 * e34
    e499 = e19 * theta_dot
    e500 = 2.0 * e1 * e79 * psi_dot - e363 * e497 - e364 * e498
    e501 = (r_R * r_R)
    e502 = e220 * e324
    e503 = e218 * e427
    e504 = e502 + e503
    e505 = e3 * e427
    e506 = e10 * e324 - e505
    e507 = e19 * e333
    e508 = e14 * e333
    e509 = 2.0 * e431
    e510 = e14 * e509 - 2.0 * e19 * e359 + e343 * e507 + e351 * e508
    e511 = e362 * (e14 * e363 - e19 * e364)
    e512 = e19 * e368
    e513 = e498 * e83
    e514 = -e34 * e512 + e374 + e513
    e515 = e497 * e88
    e516 = e14 * e58 * e61 * e8 * e80 * psi_dot - e379 - e515
    e517 = 2.0 * e218
    e518 = e14 * e384
    e519 = e19 * e76
    e520 = e368 * e499 - e496 * e83 + e518 + e519
    e521 = e19 * e384
    e522 = e14 * e67
    e523 = -e368 * e496 + e499 * e88 + e521 + e522
    e524 = e14 * e368
    e525 = e387 + e524
    e526 = e395 + e512
    e527 = 2.0 * e512
    e528 = e14 * e8
    e529 = e19 * e8
    e530 = -e23 * e529 + e528 * x_B + e9
    e531 = e134 + e528 * e84 - e529 * e89 + e9
    e532 = e166 * e528 - e168 * e529 + e201 + e9
    e533 = e308 * x_B
    e534 = e23 * e309
    e535 = -e533 - e534
    e536 = e530 * phi_dot + e535 * theta_dot
    e537 = e529 * x_B
    e538 = e23 * e528
    e539 = e537 + e538
    e540 = e309 * x_B
    e541 = e23 * e308
    e542 = e540 - e541
    e543 = e23 * e403 + e260 * x_B
    e544 = -e141 * x_B - e143 * e23
    e545 = e2 * e324
    e546 = 2.0 * e9
    e547 = e14 * e331
    e548 = e19 * e331
    e549 = e2 * phi_dot
    e550 = e1 * e295
    e551 = e1 * e299
    e552 = (
        phi_dot * (-e23 * e551 + e537 * theta_dot + e538 * theta_dot + e549 + e550 * x_B)
        + theta_dot * (e23 * e303 + e304 * x_B + e540 * theta_dot - e541 * theta_dot)
    )
    e553 = 2.0 * e3
    e554 = e309 * e89
    e555 = e308 * e84
    e556 = -e554 - e555
    e557 = e113 * e308
    e558 = e116 * e309
    e559 = e557 - e558 + e94
    e560 = delta_dot * e559 + e531 * phi_dot + e556 * theta_dot
    e561 = e528 * e89
    e562 = e529 * e84
    e563 = e561 + e562
    e564 = -e113 * e529 + e116 * e528 + e96
    e565 = e308 * e89
    e566 = e309 * e84
    e567 = e260 * e84 + e403 * e89
    e568 = e0 * e1 * e116 * e14 - e113 * e260 - e241
    e569 = -e141 * e84 - e143 * e89
    e570 = e113 * e141 - e116 * e143 + e95
    e571 = e168 * e309
    e572 = e166 * e308
    e573 = -e571 - e572
    e574 = e184 * e308
    e575 = e187 * e309
    e576 = e173 + e574 - e575
    e577 = delta_dot * e576 + e532 * phi_dot + e573 * theta_dot
    e578 = e168 * e528
    e579 = e166 * e529
    e580 = e578 + e579
    e581 = e175 - e184 * e529 + e187 * e528
    e582 = e168 * e308
    e583 = e166 * e309
    e584 = e166 * e260 + e168 * e403
    e585 = e0 * e1 * e14 * e187 - e184 * e260 - e271
    e586 = -e141 * e166 - e143 * e168
    e587 = e141 * e184 - e143 * e187 + e174
    e588 = e308 * e77
    e589 = e309 * e68
    e590 = e8 * e98
    e591 = e116 * e308
    e592 = e113 * e309
    e593 = e105 * e308
    e594 = e108 * e309
    e595 = (
        delta_dot
        * (
              -e113 * e304 + e116 * e303 + e590 - e591 * theta_dot - e592 * theta_dot + e593 - e594
              + e96 * phi_dot
          )
         + phi_dot
        * (
              e128 - e132 * phi_dot + e528 * e77 - e529 * e68 + e549 + e550 * e84 - e551 * e89
              + e561 * theta_dot + e562 * theta_dot
          )
         + theta_dot * (e303 * e89 + e304 * e84 - e565 * theta_dot + e566 * theta_dot - e588 - e589)
    )
    e596 = e164 * e308
    e597 = e160 * e309
    e598 = e184 * e309
    e599 = e187 * e308
    e600 = e182 * e309
    e601 = (
        delta_dot
        * (
              e1 * e172 * phi_dot + e1 * e179 * e19 + e14 * e187 * e8 * phi_dot + e177 * e8
              - e184 * e304 - e598 * theta_dot - e599 * theta_dot - e600
          )
         + phi_dot
        * (
              -e160 * e529 + e164 * e528 + e166 * e550 - e168 * e551 + e195 - e199 * phi_dot + e549
              + e578 * theta_dot + e579 * theta_dot
          )
         + theta_dot
        * (e166 * e304 + e168 * e303 - e582 * theta_dot + e583 * theta_dot - e596 - e597)
    )
    e602 = -e298
    e603 = 2.0 * e301 * e58 * e59 - e364 * e602
    e604 = e301 * e368
    e605 = e602 * e83
    e606 = e604 + e605
    e607 = e368 * e602
    e608 = e301 * e88
    e609 = e607 + e608
    e610 = -e591 - e592
    e611 = e113 * e120 + e116 * e123
    e612 = e113 * e57 + e116 * e71
    e613 = -e598 - e599
    e614 = e120 * e184 + e123 * e187
    e615 = e184 * e57 + e187 * e71
    e616 = 2.0 * e347 * e58 * e79 - 2.0 * e380 * e79 - 2.0 * e389
    e617 = e349 * e66
    e618 = e58 * e76
    e619 = e617 + e618
    e620 = e346 * e75
    e621 = e61 * e67
    e622 = e620 + e621
    e623 = e345 * e61
    e624 = e348 * e61
    e625 = e115 * e350
    e626 = e623 + e624 + e625
    e627 = e345 * e58
    e628 = e112 * e347
    e629 = e343 * e380 - e627 + e628
    e630 = e58 * e87
    e631 = e58 * e83
    e632 = e630 + e631
    e633 = e61 * e82
    e634 = e61 * e88
    e635 = e633 + e634
    e636 = -e79
    e637 = e636 + e65 * e79
    e638 = -e58 * e92 - e637 * r_F
    e639 = e636 + e74 * e79
    e640 = -c * e639 - e61 * e72 * e79
    e641 = e158 * e58 * e79 + e637 * z_H
    e642 = e157 * e639 + e171 * e61
    out[0] = (
        e13 * (e11 * e12 + e11 * e6 - e4 * e5)
        + e155 * (2.0 * e118 + 2.0 * e136 + 2.0 * e154 + 2.0 * e91)
        + e217 * (2.0 * e170 + 2.0 * e189 + 2.0 * e203 + 2.0 * e216)
        + e54 * (2.0 * e30 + 2.0 * e41 + 2.0 * e53)
    )
    out[1] = (
        e13 * (-e12 * e221 - e219 * e5 - e221 * e6)
        + e155 * (2.0 * e238 + 2.0 * e248 + 2.0 * e257 + 2.0 * e264)
        + e217 * (2.0 * e269 + 2.0 * e277 + 2.0 * e285 + 2.0 * e290)
        + e54 * (2.0 * e226 + 2.0 * e229 + 2.0 * e233)
    )
    out[2] = (
        I_Byy * e291 + I_Ryy * e291
        - e13 * (-e327 * e328 + e330 * (-e329 + 2.0 * e7 * e8 * psi_dot * r_R))
        + e13
          * (
                -e11 * e367 - e221 * e366 - e325 * e328 - e326 * e328 - e329 * e330
                + 2.0 * e330 * e7 * e8 * psi_dot * r_R
            )
         - e155
        * (
              e444 * (2.0 * e448 + 2.0 * e452 + 2.0 * e455 + 2.0 * e457)
              + e458 * (e324 * e462 + e333 * e459 + e427 * (e443 + e463) + e460 * e461)
          )
         + e155
        * (
              e444
              * (
                    2.0 * e249 + 2.0 * e250 + 2.0 * e251 + 2.0 * e252 - 2.0 * e253 + e254 * e324
                    - e255 * e427 + e491
                )
               + e458
              * (
                    2.0 * e122 + 2.0 * e124 + 2.0 * e125 + 2.0 * e126 - 2.0 * e129 + e133 * e324
                    + e135 * e427 + e433
                )
               + e492 * (-e11 - 2.0 * e135 + 2.0 * e57 * e84 + 2.0 * e70 * e89)
              + e493 * (2.0 * e121 * e84 + 2.0 * e123 * e89 - e221 - 2.0 * e255)
          )
         - e217
        * (
              e472 * (2.0 * e476 + 2.0 * e480 + 2.0 * e483 + 2.0 * e485)
              + e486 * (e324 * e489 + e333 * e487 + e427 * (e471 + e490) + e461 * e488)
          )
         + e217
        * (
              e472
              * (
                    2.0 * e278 + 2.0 * e279 + 2.0 * e280 + 2.0 * e281 - 2.0 * e282 + e283 * e324
                    - e284 * e427 + e491
                )
               + e486
              * (
                    2.0 * e190 + 2.0 * e191 + 2.0 * e192 + 2.0 * e193 - 2.0 * e196 + e200 * e324
                    + e202 * e427 + e433
                )
               + e494 * (-e11 + 2.0 * e166 * e57 + 2.0 * e168 * e70 - 2.0 * e202)
              + e495 * (2.0 * e121 * e166 + 2.0 * e123 * e168 - e221 - 2.0 * e284)
          )
         + e293 * e33 + e294 * e33 + e302 * e303 - e302 * e308 * theta_dot - e304 * e307
        - e307 * e309 * theta_dot + e308 * e323 - e309 * e322
        + e311 * (-I_Bxx * e309 + I_Bxz * e1 * e19) + e315 * (I_Bzz * e1 * e19 - e313)
        + e319 * (I_Bxz * e14 * e8 * phi_dot - I_Bzz * e304 - e1 * e316 * theta_dot - e317 * e318)
        + e321 * (I_Bxx * e14 * e8 * phi_dot - I_Bxz * e304 - e313 * theta_dot - e318 * e320)
        + e337
          * (
                2.0 * e1 * e19 * e314 + 2.0 * e14 * e301 * e8 * phi_dot - e298 * e332 - e298 * e334
                - e301 * e335 - e309 * e336
            )
         + e344 * e354 + e344 * e357 + e353 * e365 + e356 * e365 + e371 * e401 + e373 * e402
        + e378 * (I_Hxx * e371 + I_Hxz * e373) + e382 * (I_Hxz * e371 + I_Hzz * e373) + e388 * e393
        + e396 * e397 + e398 * (I_Hxx * e388 + I_Hxz * e396) + e399 * (I_Hxz * e388 + I_Hzz * e396)
        + e432
          * (
                e377 * (2.0 * e341 + 2.0 * e369 - 2.0 * e370)
                + e381 * (2.0 * e1 * e19 * e88 - 2.0 * e339 - 2.0 * e372)
                + e390
                  * (
                        e331 * e359 - e332 * e368 - e334 * e368 + e351 * e428 + 2.0 * e385
                        - 2.0 * e386 - e387 * e430 + e429 * e83
                    )
                 + e391
                * (
                      2.0 * e1 * e19 * e67 + 2.0 * e14 * e58 * e61 * e8 * e80 * phi_dot
                      - e331 * e431 - e332 * e88 - e335 * e368 - e343 * e428 - 2.0 * e394
                      - e395 * e430
                  )
            )
         - e54
        * (
              e411 * (2.0 * e414 + 2.0 * e418 + 2.0 * e422)
              + e423 * (e324 * e424 + e333 * e425 + e427 * (e10 + e426))
          )
         + e54
        * (
              e411 * (2.0 * e23 * e35 - e327 + 2.0 * e39 * x_B)
              + e423 * (e433 + 2.0 * e45 + 2.0 * e48) + e434 * (-e11 + 2.0 * e409 + 2.0 * e410)
              + e435 * (-e221 + 2.0 * e419 + 2.0 * e420)
          )
    )
    out[3] = (
        -e13 * (e1 * e331 * e501 * e6 - e328 * e504 + e330 * e506)
        + e13
          * (
                2.0 * e0 * e1 * e367 * r_R + 4.0 * e1 * e501 * e6 * e8 - e328 * e502 - e328 * e503
                - e330 * e505 + 2.0 * e330 * e7 * e8 * phi_dot * r_R - e366 * e517
            )
         + e14 * e323
        - e155
          * (
                e444
                * (
                      e324 * (e0 * e19 * e8 * e89 - e262 - e456) + e333 * e567 + e427 * e454
                      + e461 * e568
                  )
                 + e458 * (e324 * (e145 - e148 + e443) + e333 * e569 + e427 * e462 + e461 * e570)
                + e560 * (e324 * (-e132 + e2 - e565 + e566) + e333 * e563 + e461 * e564)
            )
         + e155
        * (
              e444
              * (
                    2.0 * e0 * e1 * e14 * e77 + 2.0 * e0 * e1 * e14 * e89 * theta_dot
                    + 2.0 * e0 * e1 * e19 * e84 * theta_dot + 2.0 * e0 * e19 * e8 * e89 * phi_dot
                    + 2.0 * e1 * e19 * e7 * e89 * psi_dot + 2.0 * e131 * e7 * e8 * psi_dot
                    - e255 * e324 - 2.0 * e259 - 2.0 * e261 - e262 * e324 - 2.0 * e263 - e504
                )
               + e458
              * (
                    e135 * e324 + 2.0 * e138 + 2.0 * e140 + 2.0 * e142 - 2.0 * e144 + e145 * e324
                    + 2.0 * e147 - e148 * e324 - 2.0 * e150 - 2.0 * e151 - 2.0 * e152 + e506
                )
               + e492 * (-2.0 * e133 - 2.0 * e440 + 2.0 * e441 + e553)
              + e493 * (2.0 * e1 * e19 * e7 * e89 + 2.0 * e131 * e7 * e8 - 2.0 * e453 - e517)
              + e560
                * (
                      2.0 * e128 - e132 * e324 - e146 * e340 + e149 * e342 + e333 * e561
                      + e333 * e562 + e545 + e547 * e77 - e548 * e68
                  )
               + e595 * (2.0 * e134 + e546 + e547 * e84 - e548 * e89)
          )
         + e19 * e322
        - e217
          * (
                e472
                * (
                      e324 * (e0 * e168 * e19 * e8 - e288 - e484) + e333 * e584 + e427 * e482
                      + e461 * e585
                  )
                 + e486 * (e324 * (e208 - e211 + e471) + e333 * e586 + e427 * e489 + e461 * e587)
                + e577 * (e324 * (-e199 + e2 - e582 + e583) + e333 * e580 + e461 * e581)
            )
         + e217
        * (
              e472
              * (
                    2.0 * e0 * e1 * e14 * e164 + 2.0 * e0 * e1 * e14 * e168 * theta_dot
                    + 2.0 * e0 * e1 * e166 * e19 * theta_dot + 2.0 * e0 * e168 * e19 * e8 * phi_dot
                    + 2.0 * e1 * e168 * e19 * e7 * psi_dot + 2.0 * e198 * e7 * e8 * psi_dot
                    - e284 * e324 - 2.0 * e286 - 2.0 * e287 - e288 * e324 - 2.0 * e289 - e504
                )
               + e486
              * (
                    e202 * e324 + 2.0 * e204 + 2.0 * e205 + 2.0 * e206 - 2.0 * e207 + e208 * e324
                    + 2.0 * e210 - e211 * e324 - 2.0 * e213 - 2.0 * e214 - 2.0 * e215 + e506
                )
               + e494 * (-2.0 * e200 - 2.0 * e468 + 2.0 * e469 + e553)
              + e495 * (2.0 * e1 * e168 * e19 * e7 + 2.0 * e198 * e7 * e8 - 2.0 * e481 - e517)
              + e577
                * (
                      -e160 * e548 + e164 * e547 + 2.0 * e195 - e199 * e324 - e209 * e340
                      + e212 * e342 + e333 * e578 + e333 * e579 + e545
                  )
               + e601 * (e166 * e547 - e168 * e548 + 2.0 * e201 + e546)
          )
         - e293 * e296 - e294 * e296 - e302 * e496 - e302 * e498 + e307 * e497 + e307 * e499
        + e311 * (e312 + e320) + e315 * (e316 + e317) - e319 * (-I_Bzz * e497 + e312 * e34)
        + e319 * (I_Bzz * e19 * theta_dot - e312 * theta_dot)
        + e321 * (-I_Bxx * e496 + I_Bxz * e19 * theta_dot) - e321 * (I_Bxx * e498 - e316 * e34)
        - e337 * (2.0 * e14 * e301 * e8 * psi_dot - 2.0 * e298 * e497)
        + e337 * (2.0 * e14 * e314 + e19 * e336 + e298 * e507 - e301 * e508) + e353 * e511
        - e354 * e500 + e354 * e510 + e356 * e511 - e357 * e500 + e357 * e510
        + e378 * (I_Hxx * e525 + I_Hxz * e526) + e382 * (I_Hxz * e525 + I_Hzz * e526) - e393 * e514
        + e393 * e520 - e397 * e516 + e397 * e523 - e398 * (I_Hxx * e514 + I_Hxz * e516)
        + e398 * (I_Hxx * e520 + I_Hxz * e523) - e399 * (I_Hxz * e514 + I_Hzz * e516)
        + e399 * (I_Hxz * e520 + I_Hzz * e523) + e401 * e525 + e402 * e526
        - e432
          * (
                e390 * (-e34 * e527 + 2.0 * e374 + 2.0 * e513)
                + e391 * (2.0 * e14 * e58 * e61 * e8 * e80 * psi_dot - 2.0 * e379 - 2.0 * e515)
            )
         + e432
        * (
              e377 * (2.0 * e387 + 2.0 * e524) + e381 * (2.0 * e395 + e527)
              + e390 * (e368 * e507 - e508 * e83 + 2.0 * e518 + 2.0 * e519)
              + e391 * (-e368 * e508 + e507 * e88 + 2.0 * e521 + 2.0 * e522)
          )
         - e54
        * (
              e411 * (e324 * (e0 * e19 * e23 * e8 - e220 - e222) + e333 * e543 + e413 * e427)
              + e423 * (e324 * (e10 - e25 + e55 * x_B) + e333 * e544 + e424 * e427)
              + e536 * (e324 * (e2 + e542) + e333 * e539)
          )
         + e54
        * (
              e411
              * (
                    2.0 * e0 * e1 * e14 * e23 * theta_dot + 2.0 * e0 * e1 * e19 * theta_dot * x_B
                    + 2.0 * e0 * e19 * e23 * e8 * phi_dot + 2.0 * e1 * e19 * e23 * e7 * psi_dot
                    - e222 * e324 - 2.0 * e224 - e504
                )
               + e423
              * (
                    2.0 * e0 * e1 * e19 * e23 * psi_dot + 2.0 * e14 * e7 * e8 * phi_dot * x_B
                    - 2.0 * e18 - 2.0 * e22 - e25 * e324 - 2.0 * e29 - e505
                    + 2.0 * e7 * e8 * phi_dot * r_R
                )
               + e434 * (2.0 * e404 - 2.0 * e405 + e553)
              + e435 * (2.0 * e1 * e19 * e23 * e7 - 2.0 * e412 - e517)
              + e536 * (e17 * e342 - e28 * e340 + e333 * e537 + e333 * e538 + e545)
              + e552 * (-e23 * e548 + e546 + e547 * x_B)
          )
         - g * (e530 * m_B + e531 * m_F + e532 * m_H + e9 * m_R)
    )
    out[4] = (
        I_Byy * e1 * phi_dot * psi_dot
        + 0.5 * I_Fxx
          * (
                2.0 * delta_dot * e390 * e61 * e79 - e363 * e381 + 2.0 * e377 * e59 * e61
                - e391 * e509
            )
         - I_Fyy * e355 * e60 + I_Fyy * e362 * e79 - I_Hyy * e352 * e60 + I_Hyy * e362 * e79
        + I_Ryy * e1 * phi_dot * psi_dot + 0.5 * delta_dot * e392 * e61 * e79
        - e155
          * (
                e444 * (e324 * e567 + e333 * (e121 * e84 + e123 * e89) + e427 * e447 + e461 * e611)
                + e458 * (e324 * e569 + e333 * e463 + e427 * e459 + e461 * e612)
                + e560 * (e324 * e563 + e333 * (e1 * e14 * e84 - e565) + e461 * e610)
            )
         - e217
        * (
              e472 * (e324 * e584 + e333 * (e121 * e166 + e123 * e168) + e427 * e475 + e461 * e614)
              + e486 * (e324 * e586 + e333 * e490 + e427 * e487 + e461 * e615)
              + e577 * (e324 * e580 + e333 * (e1 * e14 * e166 - e582) + e461 * e613)
          )
         - e302 * e602 - e306 * e321 - e319 * (I_Bxz * e602 + I_Bzz * e301)
        - e321 * (I_Bxx * e602 + e305)
        - e337 * (e298 * (-2.0 * e300 + e340) + e301 * (-2.0 * e297 - e342)) - e343 * e402
        - e354 * e603 - e357 * e603 + 0.5 * e377 * (I_Hxx * e351 - I_Hxz * e343)
        + 0.5 * e381 * (I_Hxz * e351 - I_Hzz * e343) + 0.5 * e390 * (I_Hxx * e359 - I_Hxz * e431)
        + 0.5 * e391 * (I_Hxz * e359 - I_Hzz * e431) - e393 * e606 - e397 * e431 - e397 * e609
        - e398 * (I_Hxx * e606 + I_Hxz * e609) - e399 * (I_Hxz * e606 + I_Hzz * e609)
        + 0.5 * e400 * e59 * e61
        - e432 * (e390 * (2.0 * e604 + 2.0 * e605) + e391 * (2.0 * e607 + 2.0 * e608))
        - e54
          * (
                e411 * (e324 * e543 + e333 * e421 + e417 * e427)
                + e423 * (e324 * e544 + e333 * e426 + e425 * e427)
                + e536 * (e324 * e539 + e333 * e542)
            )
         - g * (e535 * m_B + e556 * m_F + e573 * m_H)
        + 0.5 * m_B
          * (
                e411 * (2.0 * e227 + 2.0 * e228) + e423 * (2.0 * e37 + 2.0 * e40)
                + e434 * (2.0 * e407 + 2.0 * e408) + e435 * (2.0 * e415 + 2.0 * e416)
                + e536 * (e23 * e429 + e332 * x_B + e333 * e540 - e333 * e541)
                + e552 * (-2.0 * e533 - 2.0 * e534)
            )
         + 0.5 * m_F
        * (
              e444 * (2.0 * e234 + 2.0 * e235 + 2.0 * e236 + 2.0 * e237)
              + e458 * (2.0 * e69 + 2.0 * e78 + 2.0 * e85 + 2.0 * e90)
              + e492 * (2.0 * e436 + 2.0 * e437) + e493 * (2.0 * e445 + 2.0 * e446)
              + e560
                * (e332 * e84 - e333 * e565 + e333 * e566 + e429 * e89 - 2.0 * e588 - 2.0 * e589)
               + e595 * (-2.0 * e554 - 2.0 * e555)
          )
         + 0.5 * m_H
        * (
              e472 * (2.0 * e265 + 2.0 * e266 + 2.0 * e267 + 2.0 * e268)
              + e486 * (2.0 * e161 + 2.0 * e165 + 2.0 * e167 + 2.0 * e169)
              + e494 * (2.0 * e464 + 2.0 * e465) + e495 * (2.0 * e473 + 2.0 * e474)
              + e577
                * (e166 * e332 + e168 * e429 - e333 * e582 + e333 * e583 - 2.0 * e596 - 2.0 * e597)
               + e601 * (-2.0 * e571 - 2.0 * e572)
          )
    )
    out[5] = I_Ryy * e296 * phi_dot
    out[6] = (
        -e155
        * (
              e444
              * (
                    e324 * e568 + e333 * e611 + e427 * e451
                    + e461 * (e120 * e640 + e130 * e239 + e244 * e638)
                )
               + e458
              * (
                    e324 * e570 + e333 * e612 + e427 * e460
                    + e461 * (-e130 * e99 + e57 * e640 + e638 * e70)
                )
               + e560 * (e324 * e564 + e333 * e610 + e461 * (e130 * e8 + e308 * e638 - e309 * e640))
          )
         + e155
        * (
              e444
              * (
                    2.0 * e240 - e241 * e324 - e242 * e427 + 2.0 * e243 + 2.0 * e245 + 2.0 * e246
                    + 2.0 * e247
                )
               + e458
              * (
                    -2.0 * e100 + 2.0 * e106 + 2.0 * e109 + 2.0 * e114 + 2.0 * e117 + e324 * e95
                    - e427 * e97
                )
               + e492 * (2.0 * e438 + 2.0 * e439 + 2.0 * e97)
              + e493 * (-2.0 * e242 + 2.0 * e449 + 2.0 * e450)
              + e560
                * (
                      -e113 * e332 + e116 * e429 + e324 * e96 - e333 * e591 - e333 * e592
                      + 2.0 * e590 + 2.0 * e593 - 2.0 * e594
                  )
               + e595 * (2.0 * e557 - 2.0 * e558 + 2.0 * e94)
          )
         - e217
        * (
              e472
              * (
                    e324 * e585 + e333 * e614 + e427 * e479
                    + e461 * (e120 * e642 + e197 * e239 + e244 * e641)
                )
               + e486
              * (
                    e324 * e587 + e333 * e615 + e427 * e488
                    + e461 * (-e197 * e99 + e57 * e642 + e641 * e70)
                )
               + e577 * (e324 * e581 + e333 * e613 + e461 * (e197 * e8 + e308 * e641 - e309 * e642))
          )
         + e217
        * (
              e472
              * (
                    2.0 * e270 - e271 * e324 - e272 * e427 + 2.0 * e273 + 2.0 * e274 + 2.0 * e275
                    + 2.0 * e276
                )
               + e486
              * (
                    e174 * e324 - e176 * e427 - 2.0 * e178 + 2.0 * e180 + 2.0 * e183 + 2.0 * e185
                    + 2.0 * e188
                )
               + e494 * (2.0 * e176 + 2.0 * e466 + 2.0 * e467)
              + e495 * (-2.0 * e272 + 2.0 * e477 + 2.0 * e478)
              + e577
                * (
                      2.0 * e1 * e172 * phi_dot + 2.0 * e1 * e179 * e19
                      + 2.0 * e14 * e187 * e8 * phi_dot + 2.0 * e177 * e8 - e184 * e332
                      - e333 * e598 - e333 * e599 - 2.0 * e600
                  )
               + e601 * (2.0 * e173 + 2.0 * e574 - 2.0 * e575)
          )
         - e354 * e616 - e357 * e616 + e378 * (I_Hxx * e632 + I_Hxz * e635)
        + e382 * (I_Hxz * e632 + I_Hzz * e635) + e393 * e619 - e393 * e626 + e397 * e622
        - e397 * e629 + e398 * (I_Hxx * e619 + I_Hxz * e622) - e398 * (I_Hxx * e626 + I_Hxz * e629)
        + e399 * (I_Hxz * e619 + I_Hzz * e622) - e399 * (I_Hxz * e626 + I_Hzz * e629) + e401 * e632
        + e402 * e635
        - e432
          * (
                e390 * (2.0 * e623 + 2.0 * e624 + 2.0 * e625)
                + e391 * (e363 * e380 - 2.0 * e627 + 2.0 * e628)
            )
         + e432
        * (
              e377 * (2.0 * e630 + 2.0 * e631) + e381 * (2.0 * e633 + 2.0 * e634)
              + e390 * (2.0 * e617 + 2.0 * e618) + e391 * (2.0 * e620 + 2.0 * e621)
          )
         - g * (e559 * m_F + e576 * m_H)
    )
    out[7] = (
        e356
        * (
              2.0 * delta_dot * e347 * e58 * e79 + 2.0 * e1 * e79 * phi_dot * psi_dot
              + 2.0 * e314 * e58 * e59 - 2.0 * e358 - 2.0 * e360 - 2.0 * e361
          )
    )


@njit(cache=True)
def f(t, q, p, out):
    phi, theta, delta = q[3], q[4], q[6]
    w, c, lam, r_R, r_F = p[0], p[1], p[2], p[3], p[4]
    e0 = simdmath.cos(phi)
    e1 = simdmath.sin(phi)
    e2 = simdmath.sin(delta)
    e3 = simdmath.cos(lam)
    e4 = e2 * e3
    e5 = simdmath.sin(lam)
    e6 = simdmath.cos(delta)
    e7 = e0 * simdmath.cos(theta)
    e8 = e0 * simdmath.sin(theta)
    e9 = 1.0 - e6
    e10 = e3 * e5 * e9
    out[0] = (
        -e0 * r_R + e1 * (-c * e4 + e2 * e5 * r_F)
        + e7 * (-c * e10 - r_F * ((e3 * e3) * e9 + e6) + r_R)
        - e8 * (-c * ((e5 * e5) * e9 + e6) + c - e10 * r_F + w)
        + r_F
          * math.sqrt(
                1.0 - ((e1 * e6 + e2 * e5 * e7 + e4 * e8) * (e1 * e6 + e2 * e5 * e7 + e4 * e8))
            )
    )


@njit(cache=True)
def f_q(t, q, p, out):
    phi, theta, delta = q[3], q[4], q[6]
    w, c, lam, r_R, r_F = p[0], p[1], p[2], p[3], p[4]
    e0 = simdmath.sin(phi)
    e1 = simdmath.cos(phi)
    e2 = simdmath.sin(delta)
    e3 = simdmath.cos(lam)
    e4 = c * e3
    e5 = e2 * e4
    e6 = simdmath.sin(lam)
    e7 = simdmath.cos(delta)
    e8 = 1.0 - e7
    e9 = (e3 * e3)
    e10 = -e4 * e6 * e8 - r_F * (e7 + e8 * e9) + r_R
    e11 = simdmath.cos(theta)
    e12 = e0 * e11
    e13 = e6 * r_F
    e14 = (e6 * e6)
    e15 = -c * (e14 * e8 + e7) + c - e13 * e3 * e8 + w
    e16 = simdmath.sin(theta)
    e17 = e0 * e16
    e18 = 2.0 * e2
    e19 = e1 * e11
    e20 = e2 * e6
    e21 = e1 * e16
    e22 = e0 * e7 + e19 * e20 + e2 * e21 * e3
    e23 = 0.5 * e22 * r_F / math.sqrt(1.0 - (e22 * e22))
    e24 = 2.0 * e1
    e25 = -e2
    e26 = e24 * e7
    out[:, :] = 0.0
    out[0, 3] = (
        e0 * r_R + e1 * (e2 * e6 * r_F - e5) - e10 * e12 + e15 * e17
        - e23 * (2.0 * e1 * e7 - e12 * e18 * e6 - e17 * e18 * e3)
    )
    out[0, 4] = -e10 * e21 - e15 * e19 - e23 * (2.0 * e1 * e11 * e2 * e3 - e16 * e20 * e24)
    out[0, 6] = (
        e0 * (-e4 * e7 + e6 * e7 * r_F) + e1 * e11 * (-e5 * e6 - r_F * (e2 * e9 + e25))
        - e21 * (-c * (e14 * e2 + e25) - e13 * e2 * e3)
        - e23 * (-e0 * e18 + e11 * e26 * e6 + e16 * e26 * e3)
    )


@njit(cache=True)
def f_accel(t, q, v, p, out):
    # f̈ = f_q v̇ + f_accel:  ∂ḟ/∂q v + ∂ḟ/∂t with ḟ = f_q v + f_t
    phi, theta, delta = q[3], q[4], q[6]
    phi_dot, theta_dot, delta_dot = v[3], v[4], v[6]
    w, c, lam, r_R, r_F = p[0], p[1], p[2], p[3], p[4]
    e0 = (phi_dot * phi_dot)
    e1 = simdmath.cos(phi)
    e2 = e0 * e1
    e3 = (delta_dot * delta_dot)
    e4 = simdmath.cos(lam)
    e5 = c * e4
    e6 = simdmath.sin(lam)
    e7 = e6 * r_F
    e8 = e5 - e7
    e9 = simdmath.sin(phi)
    e10 = simdmath.sin(delta)
    e11 = e10 * e9
    e12 = e11 * e8
    e13 = simdmath.cos(delta)
    e14 = e1 * e13
    e15 = 2.0 * delta_dot
    e16 = e14 * e3
    e17 = simdmath.sin(theta)
    e18 = e4 * e7
    e19 = (e6 * e6)
    e20 = c * (e19 - 1.0) + e18
    e21 = e17 * e20
    e22 = delta_dot * e11
    e23 = 2.0 * e22 * phi_dot
    e24 = simdmath.cos(theta)
    e25 = e5 * e6
    e26 = (e4 * e4)
    e27 = e25 + r_F * (e26 - 1.0)
    e28 = e24 * e27
    e29 = e1 * e10
    e30 = e29 * theta_dot
    e31 = e15 * e30
    e32 = e13 - 1.0
    e33 = -e13
    e34 = e25 * e32 - r_F * (-e26 * e32 - e33) + r_R
    e35 = 2.0 * theta_dot
    e36 = e35 * e9 * phi_dot
    e37 = e24 * e34
    e38 = -c * (-e19 * e32 - e33) + c + e18 * e32 + w
    e39 = e17 * e38
    e40 = (theta_dot * theta_dot)
    e41 = e1 * e40
    e42 = e24 * e6
    e43 = e11 * phi_dot
    e44 = e17 * e4
    e45 = e17 * e6
    e46 = (
        (
            (
                delta_dot * e1 * e13 * e17 * e4 + delta_dot * e1 * e13 * e24 * e6
                + e1 * e10 * e24 * e4 * theta_dot + e1 * e13 * phi_dot - e22 - e30 * e45 - e42 * e43
                - e43 * e44
            )
             * (
                delta_dot * e1 * e13 * e17 * e4 + delta_dot * e1 * e13 * e24 * e6
                + e1 * e10 * e24 * e4 * theta_dot + e1 * e13 * phi_dot - e22 - e30 * e45 - e42 * e43
                - e43 * e44
            )
        )
    )
    e47 = e13 * e9
    e48 = e29 * e42
    e49 = e29 * e44
    e50 = e47 + e48 + e49
    e51 = (e50 * e50)
    e52 = 1.0 - e51
    e53 = r_F / math.sqrt(e52)
    e54 = e15 * phi_dot
    e55 = e10 * e2
    e56 = e47 * e54
    e57 = delta_dot * e14 * e35
    e58 = e24 * e4
    e59 = e35 * e43
    out[0] = (
        e0 * e12 + e12 * e3 - e14 * e15 * e8 * phi_dot + e16 * e21 - e16 * e28 + e17 * e27 * e31
        + e17 * e34 * e36 - e2 * e37 + e2 * e39 + e2 * r_R + e20 * e24 * e31 - e21 * e23 + e23 * e28
        + e24 * e36 * e38 - e37 * e41 + e39 * e41 - e46 * e51 * r_F / e52**(1.5) - e46 * e53
        + e50 * e53
          * (
                e0 * e47 + e29 * e54 + e3 * e47 + e3 * e48 + e3 * e49 + e40 * e48 + e40 * e49
                + e42 * e55 + e42 * e56 + e44 * e55 + e44 * e56 + e45 * e57 - e45 * e59 - e57 * e58
                + e58 * e59
            )
    )


@njit(cache=True)
def h(t, q, v, p, out):
    psi, phi, theta, delta = q[2], q[3], q[4], q[6]
    x_dot = v[0]
    y_dot = v[1]
    psi_dot = v[2]
    phi_dot = v[3]
    theta_dot = v[4]
    theta_R_dot = v[5]
    delta_dot = v[6]
    theta_F_dot = v[7]
    w, c, lam, r_R, r_F = p[0], p[1], p[2], p[3], p[4]
    e0 = simdmath.sin(psi)
    e1 = simdmath.cos(phi)
    e2 = e1 * r_R
    e3 = e0 * e2
    e4 = simdmath.cos(psi)
    e5 = simdmath.sin(phi)
    e6 = e5 * psi_dot
    e7 = e6 * r_R
    e8 = e6 + theta_dot
    e9 = e8 + theta_R_dot
    e10 = simdmath.sin(theta)
    e11 = simdmath.cos(theta)
    e12 = e1 * psi_dot
    e13 = e10 * phi_dot + e11 * e12
    e14 = e1 * e11
    e15 = -e10 * e12 + e11 * phi_dot
    e16 = e1 * e10
    e17 = e13 * e14 - e15 * e16 + e5 * e9
    e18 = e5 * r_R
    e19 = e18 * e4
    e20 = e1 * e9
    e21 = e11 * e4
    e22 = -e0 * e10 + e21 * e5
    e23 = -e22
    e24 = e0 * e11
    e25 = e10 * e4
    e26 = e24 + e25 * e5
    e27 = e2 * e4
    e28 = e0 * e18
    e29 = e24 * e5 + e25
    e30 = e0 * e10
    e31 = e11 * e4 - e30 * e5
    e32 = simdmath.cos(lam)
    e33 = c * e32
    e34 = simdmath.cos(delta)
    e35 = 1.0 - e34
    e36 = simdmath.sin(lam)
    e37 = e35 * e36
    e38 = (e32 * e32)
    e39 = e34 + e35 * e38
    e40 = -e33 * e37 - e39 * r_F + r_R
    e41 = e36 * r_F
    e42 = (e36 * e36)
    e43 = e34 + e35 * e42
    e44 = -c * e43 + c - e32 * e35 * e41 + w
    e45 = e1 * (-e33 * e34 + e34 * e36 * r_F)
    e46 = simdmath.sin(delta)
    e47 = e33 * e46
    e48 = -e46
    e49 = -e36 * e47 - r_F * (e38 * e46 + e48)
    e50 = -c * (e42 * e46 + e48) - e32 * e41 * e46
    e51 = e36 * e46 * r_F - e47
    e52 = e1 * e44
    e53 = e1 * e4
    e54 = e32 * e46
    e55 = e36 * e46
    e56 = e23 * e55 - e26 * e54 + e34 * e53
    e57 = delta_dot * e32 + e13
    e58 = delta_dot * e36 + e15
    e59 = e34 * e8 - e54 * e58 + e55 * e57 + theta_F_dot
    e60 = e32 * e37
    e61 = e46 * e8
    e62 = e32 * e61 + e43 * e58 + e57 * e60
    e63 = -e36 * e61 + e39 * e57 + e58 * e60
    e64 = e14 * e55 + e16 * e54 + e34 * e5
    e65 = math.sqrt(1.0 - (e64 * e64))
    e66 = e65 * r_F
    e67 = (
        e64 * r_F
        * (
              e59 * e64 + e62 * (e14 * e60 - e16 * e43 + e5 * e54)
              + e63 * (e1 * e11 * e39 - e16 * e60 - e5 * e55)
          )
         / e65
    )
    e68 = e0 * e1
    e69 = e29 * e36 * e46 - e31 * e54 - e34 * e68
    out[0] = e17 * e19 + e2 * (e13 * e23 + e15 * e26 + e20 * e4) - e3 * phi_dot - e4 * e7 + x_dot
    out[1] = -e0 * e7 + e17 * e28 - e2 * (-e0 * e20 + e13 * e29 + e15 * e31) + e27 * phi_dot + y_dot
    out[2] = (
        delta_dot * (-e0 * e45 + e29 * e49 + e31 * e50) + e56 * e67
        + e66
          * (
                e56 * e59 + e62 * (e23 * e60 + e26 * e43 + e53 * e54)
                + e63 * (e23 * e39 + e26 * e60 - e53 * e55)
            )
         + phi_dot * (e0 * e1 * e11 * e40 + e0 * e5 * e51 - e3 - e30 * e52)
        + psi_dot * (-e19 + e22 * e40 - e26 * e44 - e51 * e53)
        + theta_dot * (-e29 * e44 + e31 * e40) + x_dot
    )
    out[3] = (
        delta_dot * (e23 * e49 + e26 * e50 + e4 * e45)
        - e66
          * (
                e59 * e69 + e62 * (e29 * e60 + e31 * e43 - e54 * e68)
                + e63 * (e29 * e39 + e31 * e60 + e55 * e68)
            )
         - e67 * e69 + phi_dot * (-e1 * e21 * e40 + e25 * e52 + e27 - e4 * e5 * e51)
        + psi_dot * (-e28 + e29 * e40 + e31 * e44 - e51 * e68) + theta_dot * (e22 * e44 + e26 * e40)
        + y_dot
    )


@njit(cache=True)
def h_q(t, q, v, p, out):
    psi, phi, theta, delta = q[2], q[3], q[4], q[6]
    psi_dot = v[2]
    phi_dot = v[3]
    theta_dot = v[4]
    theta_R_dot = v[5]
    delta_dot = v[6]
    theta_F_dot = v[7]
    w, c, lam, r_R, r_F = p[0], p[1], p[2], p[3], p[4]
    e0 = simdmath.cos(psi)
    e1 = simdmath.cos(phi)
    e2 = e1 * r_R
    e3 = e0 * e2
    e4 = simdmath.sin(phi)
    e5 = simdmath.sin(psi)
    e6 = e4 * psi_dot
    e7 = e6 + theta_dot
    e8 = e7 + theta_R_dot
    e9 = simdmath.sin(theta)
    e10 = simdmath.cos(theta)
    e11 = e1 * psi_dot
    e12 = e10 * e11 + e9 * phi_dot
    e13 = e1 * e10
    e14 = e10 * phi_dot - e11 * e9
    e15 = e1 * e9
    e16 = e12 * e13 - e14 * e15 + e4 * e8
    e17 = e4 * e5
    e18 = e17 * r_R
    e19 = e1 * e8
    e20 = e0 * e9
    e21 = e10 * e5
    e22 = e21 * e4
    e23 = e20 + e22
    e24 = e5 * e9
    e25 = e24 * e4
    e26 = -e0 * e10 + e25
    e27 = -e26
    e28 = e2 * e5
    e29 = e0 * e10
    e30 = -e24 + e29 * e4
    e31 = e20 * e4
    e32 = e21 + e31
    e33 = -e32
    e34 = simdmath.cos(lam)
    e35 = c * e34
    e36 = simdmath.cos(delta)
    e37 = 1.0 - e36
    e38 = simdmath.sin(lam)
    e39 = e37 * e38
    e40 = (e34 * e34)
    e41 = e36 + e37 * e40
    e42 = -e35 * e39 - e41 * r_F + r_R
    e43 = -e30
    e44 = e38 * r_F
    e45 = (e38 * e38)
    e46 = e36 + e37 * e45
    e47 = -c * e46 + c - e34 * e37 * e44 + w
    e48 = e33 * e42 + e43 * e47
    e49 = e35 * e36
    e50 = e36 * e38 * r_F - e49
    e51 = e0 * e1
    e52 = simdmath.sin(delta)
    e53 = e35 * e52
    e54 = -e52
    e55 = e40 * e52 + e54
    e56 = -e38 * e53 - e55 * r_F
    e57 = e45 * e52 + e54
    e58 = -c * e57 - e34 * e44 * e52
    e59 = e30 * e56 + e33 * e58 - e50 * e51
    e60 = -e38 * e52 * r_F + e53
    e61 = -e60
    e62 = e1 * e47
    e63 = e0 * e1 * e10 * e42 + e0 * e4 * e61 - e20 * e62 - e3
    e64 = -e23
    e65 = e26 * e47 + e42 * e64
    e66 = e1 * e5
    e67 = e18 + e61 * e66
    e68 = e1 * e36
    e69 = e5 * e68
    e70 = e34 * e52
    e71 = e23 * e38 * e52 - e27 * e70 - e69
    e72 = e36 * e7
    e73 = delta_dot * e34 + e12
    e74 = e38 * e52
    e75 = e73 * e74
    e76 = delta_dot * e38 + e14
    e77 = -e70 * e76 + e72 + e75 + theta_F_dot
    e78 = e34 * e39
    e79 = e27 * e78
    e80 = e23 * e41 + e66 * e74 + e79
    e81 = e52 * e7
    e82 = -e38 * e81 + e41 * e73 + e76 * e78
    e83 = e23 * e78 + e27 * e46 - e66 * e70
    e84 = e34 * e81 + e46 * e76 + e73 * e78
    e85 = e71 * e77 + e80 * e82 + e83 * e84
    e86 = e36 * e4
    e87 = e13 * e74
    e88 = e15 * e70 + e86 + e87
    e89 = (e88 * e88)
    e90 = 1.0 - e89
    e91 = math.sqrt(e90)
    e92 = e91 * r_F
    e93 = (1.0 / e91)
    e94 = e4 * e52
    e95 = e34 * e94
    e96 = e13 * e78
    e97 = -e15 * e46 + e95 + e96
    e98 = e38 * e94
    e99 = e15 * e78
    e100 = e1 * e10 * e41 - e98 - e99
    e101 = r_F * (e100 * e82 + e77 * e88 + e84 * e97)
    e102 = e101 * e93
    e103 = e102 * e88
    e104 = e1 * e42
    e105 = -e104 * e24 - e21 * e62
    e106 = e1 * e56
    e107 = -e1 * e24 * e58 + e106 * e21 + e17 * e50
    e108 = e1 * e74
    e109 = e1 * e70
    e110 = -e0 * e86 - e108 * e29 - e109 * e20
    e111 = e10 * e98
    e112 = e9 * e95
    e113 = e1 * e36 - e111 - e112
    e114 = e0 * e68
    e115 = e43 * e74
    e116 = e114 + e115 - e32 * e70
    e117 = e102 * e116
    e118 = 2.0 * e1 * e36 - 2.0 * e111 - 2.0 * e112
    e119 = 0.5 * e101 * e89 / e90**(1.5)
    e120 = e116 * e119
    e121 = e51 * e70
    e122 = e121 + e32 * e46 + e43 * e78
    e123 = e51 * e74
    e124 = e32 * e78
    e125 = -e123 + e124 + e41 * e43
    e126 = e88 * e93 * r_F
    e127 = 0.5 * e126
    e128 = e127 * (e116 * e77 + e122 * e84 + e125 * e82)
    e129 = e10 * e6
    e130 = e1 * e36 * psi_dot - e129 * e74 - e6 * e70 * e9
    e131 = e46 * e9
    e132 = e11 * e70 - e129 * e78 + e131 * e6
    e133 = e10 * e41
    e134 = -e11 * e74 - e133 * e6 + e34 * e37 * e38 * e4 * e9 * psi_dot
    e135 = (
        e100 * e134 + e113 * e77 + e130 * e88 + e132 * e97
        + e82 * (-e108 - e133 * e4 + e34 * e37 * e38 * e4 * e9)
        + e84 * (-e10 * e4 * e78 + e109 + e131 * e4)
    )
    e136 = e116 * e126
    e137 = e1 * e78
    e138 = e27 * e56 + e58 * e64
    e139 = e32 * e74
    e140 = e139 - e30 * e70
    e141 = e15 * e74
    e142 = e1 * e10 * e34 * e52 - e141
    e143 = 2.0 * e1 * e10 * e34 * e52 - 2.0 * e141
    e144 = -e12
    e145 = e14 * e38 * e52 - e144 * e70
    e146 = e14 * e78 + e144 * e46
    e147 = e14 * e41 + e144 * e78
    e148 = (
        e100 * e147 + e142 * e77 + e145 * e88 + e146 * e97 + e82 * (-e15 * e41 - e96)
        + e84 * (-e13 * e46 - e99)
    )
    e149 = e30 * e78
    e150 = -e36
    e151 = -e38 * e49 - r_F * (e150 + e36 * e40)
    e152 = -c * (e150 + e36 * e45) - e34 * e36 * e44
    e153 = e10 * e38
    e154 = e34 * e9
    e155 = e153 * e68 + e154 * e68 - e94
    e156 = e34 * e36
    e157 = -e156 * e32 + e36 * e38 * e43 - e51 * e52
    e158 = 2.0 * e68
    e159 = e153 * e158 + e154 * e158 - 2.0 * e94
    e160 = -e156 * e76 + e36 * e38 * e73 - e81
    e161 = e34 * e72 + e34 * e75 + e57 * e76
    e162 = e34 * e74 * e76 - e38 * e72 + e55 * e73
    e163 = (
        e100 * e162 + e155 * e77 + e160 * e88 + e161 * e97
        + e82 * (e1 * e10 * e55 - e141 * e34 - e38 * e86)
        + e84 * (-e15 * e57 + e34 * e86 + e34 * e87)
    )
    e164 = e27 * e42 + e47 * e64
    e165 = e23 * e56 + e27 * e58 - e50 * e66
    e166 = e1 * e10 * e42 * e5 - e24 * e62 - e28 + e4 * e5 * e61
    e167 = e0 * e4
    e168 = e167 * r_R + e51 * e61
    e169 = -e114 + e30 * e38 * e52 - e33 * e70
    e170 = e104 * e20 + e29 * e62
    e171 = e0 * e1 * e58 * e9 - e106 * e29 - e167 * e50
    e172 = e108 * e21 + e109 * e24 + e5 * e86
    e173 = e102 * e71
    e174 = e119 * e71
    e175 = e127 * e85
    e176 = e126 * e71
    e177 = e30 * e58 + e32 * e56
    e178 = e27 * e74
    e179 = e178 - e64 * e70
    e180 = -e156 * e27 + e23 * e36 * e38 + e52 * e66
    out[:, :] = 0.0
    out[0, 2] = (
        e1 * r_R * (e12 * e23 + e14 * e27 - e19 * e5) - e16 * e18 - e3 * phi_dot
        + e4 * e5 * psi_dot * r_R
    )
    out[1, 2] = (
        e0 * e16 * e4 * r_R - e0 * e6 * r_R - e2 * (-e0 * e19 + e12 * e30 + e14 * e33)
        - e28 * phi_dot
    )
    out[2, 2] = (
        delta_dot * e59 + e103 * e71 + e48 * theta_dot + e63 * phi_dot + e85 * e92
        + psi_dot * (e65 + e67)
    )
    out[2, 3] = (
        delta_dot * e107 + e103 * e110 + e105 * theta_dot + e113 * e117 + e118 * e120 - e118 * e128
        + e135 * e136 + e63 * psi_dot
        + e92
          * (
                e110 * e77 + e116 * e130 + e122 * e132 + e125 * e134
                + e82 * (e0 * e98 - e1 * e29 * e41 + e137 * e20)
                + e84 * (e0 * e1 * e46 * e9 - e0 * e95 - e137 * e29)
            )
         + phi_dot * (-e22 * e42 + e25 * e47 + e67)
    )
    out[2, 4] = (
        delta_dot * e138 + e103 * e140 + e105 * phi_dot + e117 * e142 + e120 * e143 - e128 * e143
        + e136 * e148 + e48 * psi_dot + e65 * theta_dot
        + e92
          * (
                e116 * e145 + e122 * e146 + e125 * e147 + e140 * e77 + e82 * (e149 + e32 * e41)
                + e84 * (e124 + e30 * e46)
            )
    )
    out[2, 6] = (
        delta_dot * (e151 * e23 + e152 * e27 - e60 * e66) + e103 * e157 + e107 * phi_dot
        + e117 * e155 + e120 * e159 - e128 * e159 + e136 * e163 + e138 * theta_dot + e59 * psi_dot
        + e92
          * (
                e116 * e160 + e122 * e161 + e125 * e162 + e157 * e77
                + e82 * (-e114 * e38 + e139 * e34 + e43 * e55)
                + e84 * (e114 * e34 + e115 * e34 + e32 * e57)
            )
    )
    out[3, 2] = (
        delta_dot * e165 - e103 * e169 + e164 * theta_dot + e166 * phi_dot
        - e92
          * (e169 * e77 + e82 * (e123 + e30 * e41 + e33 * e78) + e84 * (-e121 + e149 + e33 * e46))
         + psi_dot * (-e168 + e30 * e42 + e33 * e47)
    )
    out[3, 3] = (
        delta_dot * e171 - e103 * e172 - e113 * e173 - e118 * e174 + e118 * e175 - e135 * e176
        + e166 * psi_dot + e170 * theta_dot
        - e92
          * (
                e130 * e71 + e132 * e83 + e134 * e80 + e172 * e77
                + e82 * (e1 * e10 * e41 * e5 - e137 * e24 - e5 * e98)
                + e84 * (-e1 * e24 * e46 + e137 * e21 + e5 * e95)
            )
         + phi_dot * (e0 * e10 * e4 * e42 - e168 - e31 * e47)
    )
    out[3, 4] = (
        delta_dot * e177 - e103 * e179 - e142 * e173 - e143 * e174 + e143 * e175 - e148 * e176
        + e164 * psi_dot + e170 * phi_dot
        - e92
          * (
                e145 * e71 + e146 * e83 + e147 * e80 + e179 * e77 + e82 * (e27 * e41 + e64 * e78)
                + e84 * (e46 * e64 + e79)
            )
         + theta_dot * (e30 * e42 + e33 * e47)
    )
    out[3, 6] = (
        delta_dot * (e151 * e43 + e152 * e32 + e51 * e60) - e103 * e180 - e155 * e173 - e159 * e174
        + e159 * e175 - e163 * e176 + e165 * psi_dot + e171 * phi_dot + e177 * theta_dot
        - e92
          * (
                e160 * e71 + e161 * e83 + e162 * e80 + e180 * e77
                + e82 * (e178 * e34 + e23 * e55 + e38 * e69)
                + e84 * (e23 * e34 * e74 + e27 * e57 - e34 * e69)
            )
    )


@njit(cache=True)
def h_v(t, q, v, p, out):
    psi, phi, theta, delta = q[2], q[3], q[4], q[6]
    w, c, lam, r_R, r_F = p[0], p[1], p[2], p[3], p[4]
    e0 = simdmath.sin(phi)
    e1 = (e0 * e0)
    e2 = simdmath.cos(psi)
    e3 = e2 * r_R
    e4 = simdmath.cos(phi)
    e5 = (e4 * e4)
    e6 = e1 * e3 + e3 * e5
    e7 = simdmath.sin(psi)
    e8 = e7 * r_R
    e9 = e1 * e8 + e5 * e8
    e10 = simdmath.sin(delta)
    e11 = simdmath.cos(lam)
    e12 = e10 * e11
    e13 = simdmath.sin(lam)
    e14 = -c * e12 + e10 * e13 * r_F
    e15 = e2 * e4
    e16 = simdmath.sin(theta)
    e17 = e16 * e7
    e18 = simdmath.cos(theta)
    e19 = e18 * e2
    e20 = e0 * e19 - e17
    e21 = simdmath.cos(delta)
    e22 = 1.0 - e21
    e23 = c * e11
    e24 = (e11 * e11)
    e25 = e22 * e24
    e26 = e21 + e25
    e27 = -e13 * e22 * e23 - e26 * r_F + r_R
    e28 = e18 * e7
    e29 = e16 * e2
    e30 = e0 * e29 + e28
    e31 = e11 * e22
    e32 = (e13 * e13)
    e33 = e22 * e32
    e34 = e21 + e33
    e35 = -c * e34 + c - e13 * e31 * r_F + w
    e36 = e18 * e4
    e37 = e10 * e13
    e38 = e16 * e4
    e39 = e0 * e21 + e12 * e38 + e36 * e37
    e40 = (e39 * e39)
    e41 = e0 * e10
    e42 = e13 * e31
    e43 = e11 * e41 - e34 * e38 + e36 * e42
    e44 = -e13 * e41 + e18 * e26 * e4 - e38 * e42
    e45 = e40 + (e43 * e43) + (e44 * e44)
    e46 = -e20
    e47 = -e12 * e30 + e15 * e21 + e37 * e46
    e48 = e39 * e47
    e49 = math.sqrt(1.0 - e40)
    e50 = r_F / e49
    e51 = e48 * e50
    e52 = e12 * e15 + e30 * e34 + e42 * e46
    e53 = -e15 * e37 + e26 * e46 + e30 * e42
    e54 = e49 * r_F
    e55 = e14 * e7
    e56 = e27 * e4
    e57 = -e12 * e18 + e16 * e37
    e58 = e16 * e42 + e18 * e34
    e59 = e16 * e26 + e18 * e42
    e60 = e39 * e57 + e43 * e58 + e44 * e59
    e61 = -e0 * e17 + e18 * e2
    e62 = e0 * e28 + e29
    e63 = e12 * e43 + e21 * e39 - e37 * e44
    e64 = e13 * e21 * r_F - e21 * e23
    e65 = e4 * e7
    e66 = -e10
    e67 = -e23 * e37 - r_F * (e10 * e24 + e66)
    e68 = -c * (e10 * e32 + e66) - e11 * e37 * r_F
    e69 = e13 * e25 + e13 * e34
    e70 = e11 * e26 + e11 * e33
    e71 = e43 * e69 + e44 * e70
    e72 = e40 * e50
    e73 = e10 * e13 * e62 - e12 * e61 - e21 * e65
    e74 = e39 * e73
    e75 = e50 * e74
    e76 = e26 * e62 + e37 * e65 + e42 * e61
    e77 = -e12 * e65 + e34 * e61 + e42 * e62
    out[:, :] = 0.0
    out[0, 0] = 1.0
    out[0, 4] = e6
    out[0, 5] = e6
    out[1, 1] = 1.0
    out[1, 4] = e9
    out[1, 5] = e9
    out[2, 0] = 1.0
    out[2, 2] = (
        -e0 * e3 - e14 * e15 + e20 * e27 - e30 * e35 + e45 * e51
        + e54 * (e43 * e52 + e44 * e53 + e48)
    )
    out[2, 3] = (
        e0 * e55 - e17 * e35 * e4 + e28 * e56 - e4 * e8 + e51 * e60
        + e54 * (e47 * e57 + e52 * e58 + e53 * e59)
    )
    out[2, 4] = e27 * e61 - e35 * e62 + e51 * e63 + e54 * (e12 * e52 + e21 * e47 - e37 * e53)
    out[2, 6] = e51 * e71 + e54 * (e52 * e69 + e53 * e70) + e61 * e68 + e62 * e67 - e64 * e65
    out[2, 7] = e47 * e54 + e47 * e72
    out[3, 1] = 1.0
    out[3, 2] = (
        -e0 * e8 + e27 * e62 + e35 * e61 - e4 * e55 - e45 * e75
        - e54 * (e43 * e77 + e44 * e76 + e74)
    )
    out[3, 3] = (
        -e0 * e14 * e2 + e16 * e2 * e35 * e4 - e19 * e56 + e2 * e4 * r_R
        - e54 * (e57 * e73 + e58 * e77 + e59 * e76) - e60 * e75
    )
    out[3, 4] = e20 * e35 + e27 * e30 - e54 * (e12 * e77 + e21 * e73 - e37 * e76) - e63 * e75
    out[3, 6] = e15 * e64 + e30 * e68 + e46 * e67 - e54 * (e69 * e77 + e70 * e76) - e71 * e75
    out[3, 7] = -e54 * e73 - e72 * e73


@njit(cache=True)
def energy(t, q, v, p):
    # Jacobi integral vᵀ ∂L/∂v − L
    psi, phi, theta, delta = q[2], q[3], q[4], q[6]
    x_dot = v[0]
    y_dot = v[1]
    psi_dot = v[2]
    phi_dot = v[3]
    theta_dot = v[4]
    theta_R_dot = v[5]
    delta_dot = v[6]
    theta_F_dot = v[7]
    w = p[0]
    c = p[1]
    lam = p[2]
    r_R = p[3]
    r_F = p[4]
    m_R = p[5]
    m_B = p[6]
    m_H = p[7]
    m_F = p[8]
    I_Rxx = p[9]
    I_Ryy = p[10]
    I_Bxx = p[11]
    I_Byy = p[12]
    I_Bzz = p[13]
    I_Bxz = p[14]
    I_Hxx = p[15]
    I_Hyy = p[16]
    I_Hzz = p[17]
    I_Hxz = p[18]
    I_Fxx = p[19]
    I_Fyy = p[20]
    x_B = p[21]
    z_B = p[22]
    x_H = p[23]
    z_H = p[24]
    g = p[25]
    e0 = simdmath.sin(phi)
    e1 = e0 * psi_dot
    e2 = e1 + theta_dot
    e3 = 0.5 * I_Byy
    e4 = e2 + theta_R_dot
    e5 = 0.5 * I_Ryy
    e6 = 2.0 * e1
    e7 = e6 + 2.0 * theta_dot
    e8 = simdmath.sin(theta)
    e9 = e8 * phi_dot
    e10 = simdmath.cos(theta)
    e11 = simdmath.cos(phi)
    e12 = e11 * psi_dot
    e13 = e10 * e12
    e14 = e13 + e9
    e15 = e10 * phi_dot
    e16 = e12 * e8
    e17 = e15 - e16
    e18 = 0.5 * I_Rxx
    e19 = (e0 * e0) * (phi_dot * phi_dot) * (r_R * r_R)
    e20 = simdmath.cos(psi)
    e21 = e11 * r_R
    e22 = e20 * e21
    e23 = e22 * phi_dot
    e24 = simdmath.sin(psi)
    e25 = e1 * r_R
    e26 = e23 - e24 * e25 + y_dot
    e27 = e21 * e24
    e28 = e27 * phi_dot
    e29 = -e20 * e25 - e28 + x_dot
    e30 = 0.5 * m_R
    e31 = simdmath.cos(delta)
    e32 = e2 * e31
    e33 = simdmath.sin(delta)
    e34 = simdmath.cos(lam)
    e35 = delta_dot * e34 + e14
    e36 = simdmath.sin(lam)
    e37 = e35 * e36
    e38 = e33 * e37
    e39 = delta_dot * e36 + e17
    e40 = e34 * e39
    e41 = e33 * e40
    e42 = e32 + e38 - e41
    e43 = 0.5 * I_Hyy
    e44 = e42 + theta_F_dot
    e45 = 0.5 * I_Fyy
    e46 = 2.0 * y_dot
    e47 = e6 * r_R
    e48 = 2.0 * e32 + 2.0 * e38 - 2.0 * e41
    e49 = e2 * e33
    e50 = e34 * e49
    e51 = 1.0 - e31
    e52 = e34 * e51
    e53 = e37 * e52
    e54 = (e36 * e36)
    e55 = e31 + e51 * e54
    e56 = e39 * e55
    e57 = e50 + e53 + e56
    e58 = e36 * e49
    e59 = e36 * e51
    e60 = e40 * e59
    e61 = (e34 * e34)
    e62 = e31 + e51 * e61
    e63 = e35 * e62
    e64 = -e58 + e60 + e63
    e65 = 0.5 * I_Fxx
    e66 = e11 * e8
    e67 = r_R + z_B
    e68 = c * e34
    e69 = e33 * e68
    e70 = e33 * e36 * r_F - e69
    e71 = -e59 * e68 - e62 * r_F + r_R
    e72 = e36 * r_F
    e73 = -c * e55 + c - e52 * e72 + w
    e74 = e36 * z_H
    e75 = e33 * e74
    e76 = c + w
    e77 = -e76 + x_H
    e78 = e33 * e34 * e77 - e75
    e79 = e34 * e77
    e80 = e59 * e79 + e62 * z_H + r_R
    e81 = e52 * e74 + e55 * e77 + e76
    e82 = e10 * e11
    e83 = theta_dot * (-e66 * e67 - e82 * x_B)
    e84 = e0 * r_R
    e85 = e0 * e8
    e86 = e0 * e10
    e87 = phi_dot * (-e67 * e86 + e84 + e85 * x_B)
    e88 = e83 + e87
    e89 = e20 * e8
    e90 = e11 * x_B
    e91 = e10 * e20
    e92 = phi_dot * (-e11 * e67 * e91 + e22 + e89 * e90)
    e93 = e24 * e8
    e94 = e0 * e91 - e93
    e95 = e10 * e24
    e96 = e0 * e89 + e95
    e97 = theta_dot * (e67 * e96 + e94 * x_B)
    e98 = e24 * e84
    e99 = -e0 * e93 + e10 * e20
    e100 = e0 * e95 + e89
    e101 = psi_dot * (e100 * e67 - e98 + e99 * x_B)
    e102 = e101 + e92 + e97 + y_dot
    e103 = phi_dot * (e10 * e11 * e24 * e67 - e27 - e90 * e93)
    e104 = -e100
    e105 = theta_dot * (e104 * x_B + e67 * e99)
    e106 = e20 * e84
    e107 = -e96
    e108 = psi_dot * (-e106 + e107 * x_B + e67 * e94)
    e109 = e103 + e105 + e108 + x_dot
    e110 = 0.5 * m_B
    e111 = 2.0 * x_dot
    e112 = theta_dot * (-e66 * e71 - e73 * e82)
    e113 = e31 * e36 * r_F - e31 * e68
    e114 = -e33
    e115 = e114 + e33 * e61
    e116 = -e115 * r_F - e36 * e69
    e117 = e114 + e33 * e54
    e118 = -c * e117 - e33 * e34 * e72
    e119 = delta_dot * (e0 * e113 + e116 * e82 - e118 * e66)
    e120 = e11 * e70
    e121 = phi_dot * (e120 - e71 * e86 + e73 * e85 + e84)
    e122 = e112 + e119 + e121
    e123 = theta_dot * (e71 * e96 + e73 * e94)
    e124 = e11 * e113
    e125 = -e94
    e126 = delta_dot * (e116 * e125 + e118 * e96 + e124 * e20)
    e127 = e11 * e73
    e128 = phi_dot * (-e0 * e20 * e70 - e11 * e71 * e91 + e127 * e89 + e22)
    e129 = psi_dot * (e100 * e71 - e120 * e24 + e73 * e99 - e98)
    e130 = e123 + e126 + e128 + e129 + y_dot
    e131 = theta_dot * (e104 * e73 + e71 * e99)
    e132 = delta_dot * (e100 * e116 + e118 * e99 - e124 * e24)
    e133 = phi_dot * (e0 * e24 * e70 + e10 * e11 * e24 * e71 - e127 * e93 - e27)
    e134 = psi_dot * (-e106 + e107 * e73 - e120 * e20 + e71 * e94)
    e135 = e131 + e132 + e133 + e134 + x_dot
    e136 = 0.5 * m_F
    e137 = theta_dot * (-e66 * e80 - e81 * e82)
    e138 = e31 * e34 * e77 - e31 * e74
    e139 = e115 * z_H + e33 * e36 * e79
    e140 = e117 * e77 + e34 * e75
    e141 = delta_dot * (e0 * e138 + e139 * e82 - e140 * e66)
    e142 = e11 * e78
    e143 = phi_dot * (e142 - e80 * e86 + e81 * e85 + e84)
    e144 = e137 + e141 + e143
    e145 = theta_dot * (e80 * e96 + e81 * e94)
    e146 = e11 * e138
    e147 = delta_dot * (e125 * e139 + e140 * e96 + e146 * e20)
    e148 = e11 * e81
    e149 = phi_dot * (-e0 * e20 * e78 - e11 * e80 * e91 + e148 * e89 + e22)
    e150 = psi_dot * (e100 * e80 - e142 * e24 + e81 * e99 - e98)
    e151 = e145 + e147 + e149 + e150 + y_dot
    e152 = theta_dot * (e104 * e81 + e80 * e99)
    e153 = delta_dot * (e100 * e139 + e140 * e99 - e146 * e24)
    e154 = phi_dot * (e0 * e24 * e78 + e10 * e11 * e24 * e80 - e148 * e93 - e27)
    e155 = psi_dot * (-e106 + e107 * e81 - e142 * e20 + e80 * e94)
    e156 = e152 + e153 + e154 + e155 + x_dot
    e157 = 0.5 * m_H
    return (
        -e110 * ((e102 * e102) + (e109 * e109) + (e88 * e88))
        + e110
          * (
                e102 * (2.0 * e101 + e46 + 2.0 * e92 + 2.0 * e97)
                + e109 * (2.0 * e103 + 2.0 * e105 + 2.0 * e108 + e111)
                + e88 * (2.0 * e83 + 2.0 * e87)
            )
         - e136 * ((e122 * e122) + (e130 * e130) + (e135 * e135))
        + e136
          * (
                e122 * (2.0 * e112 + 2.0 * e119 + 2.0 * e121)
                + e130 * (2.0 * e123 + 2.0 * e126 + 2.0 * e128 + 2.0 * e129 + e46)
                + e135 * (e111 + 2.0 * e131 + 2.0 * e132 + 2.0 * e133 + 2.0 * e134)
            )
         + 0.5 * e14 * (I_Bxz * e17 + I_Bzz * e14)
        - e157 * ((e144 * e144) + (e151 * e151) + (e156 * e156))
        + e157
          * (
                e144 * (2.0 * e137 + 2.0 * e141 + 2.0 * e143)
                + e151 * (2.0 * e145 + 2.0 * e147 + 2.0 * e149 + 2.0 * e150 + e46)
                + e156 * (e111 + 2.0 * e152 + 2.0 * e153 + 2.0 * e154 + 2.0 * e155)
            )
         + 0.5 * e17 * (I_Bxx * e17 + I_Bxz * e14) - e18 * ((e14 * e14) + (e17 * e17))
        + e18 * (e14 * (2.0 * e13 + 2.0 * e9) + e17 * (2.0 * e15 - 2.0 * e16)) - (e2 * e2) * e3
        + e2 * e3 * e7 - e30 * (e19 + (e26 * e26) + (e29 * e29))
        + e30
          * (
                2.0 * e19 + e26 * (2.0 * e23 - e24 * e47 + e46)
                + e29 * (-e20 * e47 - 2.0 * e28 + 2.0 * x_dot)
            )
         - (e4 * e4) * e5 + e4 * e5 * (e7 + 2.0 * theta_R_dot) - (e42 * e42) * e43 + e42 * e43 * e48
        - (e44 * e44) * e45 + e44 * e45 * (e48 + 2.0 * theta_F_dot)
        + 0.5 * e57 * (I_Hxx * e57 + I_Hxz * e64) + 0.5 * e64 * (I_Hxz * e57 + I_Hzz * e64)
        - e65 * ((e57 * e57) + (e64 * e64))
        + e65
          * (e57 * (2.0 * e50 + 2.0 * e53 + 2.0 * e56) + e64 * (-2.0 * e58 + 2.0 * e60 + 2.0 * e63))
         - g
        * (
              -e21 * m_R + m_B * (e10 * e11 * e67 - e21 - e66 * x_B)
              + m_F * (e0 * e70 + e10 * e11 * e71 - e21 - e66 * e73)
              + m_H * (e0 * e78 + e10 * e11 * e80 - e21 - e66 * e81)
          )
    )


def reference_state(p):
    r_R, r_F, speed = p[3], p[4], p[26]
    return np.array(
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, speed, 0.0, 0.0, 0.0, 0.0, -speed / r_R, 0.0,
         -speed / r_F],
        dtype=np.float64,
    )


model = stabdae.Model(
    "bicycle",
    n=8,
    m=1,
    k=4,
    params={
        "w": 1.02,
        "c": 0.08,
        "lam": 0.3141592653589793,
        "r_R": 0.3,
        "r_F": 0.35,
        "m_R": 2.0,
        "m_B": 85.0,
        "m_H": 4.0,
        "m_F": 3.0,
        "I_Rxx": 0.0603,
        "I_Ryy": 0.12,
        "I_Bxx": 9.2,
        "I_Byy": 11.0,
        "I_Bzz": 2.8,
        "I_Bxz": 2.4,
        "I_Hxx": 0.05892,
        "I_Hyy": 0.06,
        "I_Hzz": 0.00708,
        "I_Hxz": -0.00756,
        "I_Fxx": 0.1405,
        "I_Fyy": 0.28,
        "x_B": 0.3,
        "z_B": -0.9,
        "x_H": 0.9,
        "z_H": -0.7,
        "g": 9.81,
        "speed": 5.0,
    },
    reference_state=reference_state,
    coordinates=["x", "y", "psi", "phi", "theta", "theta_R", "delta", "theta_F"],
    coordinate_units=["m", "m", "rad", "rad", "rad", "rad", "rad", "rad"],
    constraint_units=["m", "m s-1", "m s-1", "m s-1", "m s-1"],
    energy_units="J",
    mass=mass,
    forces=forces,
    f=f,
    f_q=f_q,
    f_accel=f_accel,
    h=h,
    h_q=h_q,
    h_v=h_v,
    energy=energy,
    description=__doc__,
)
