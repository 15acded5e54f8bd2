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
        theta_dot)**2/2 + g*(m_B*(-x_B*sin(theta)*cos(phi) + z_r + (r_R +
        z_B)*cos(phi)*cos(theta)) + m_F*z_f + m_H*(z_f + (r_F + z_H)*(-(1 -
        cos(delta))*sin(lam)*sin(theta)*cos(lam)*cos(phi) + ((1 - cos(delta))*cos(lam)**2 +
        cos(delta))*cos(phi)*cos(theta) - sin(delta)*sin(lam)*sin(phi)) + (-w + x_H)*((1 -
        cos(delta))*sin(lam)*cos(lam)*cos(phi)*cos(theta) - ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*sin(theta)*cos(phi) + sin(delta)*sin(phi)*cos(lam))) + m_R*z_r) +
        m_B*((phi_dot*(x_B*sin(phi)*sin(theta) - (r_R + z_B)*sin(phi)*cos(theta)) +
        theta_dot*(-x_B*cos(phi)*cos(theta) - (r_R + z_B)*sin(theta)*cos(phi)) + z_r_dot)**2 +
        (phi_dot*(-x_B*sin(psi)*sin(theta)*cos(phi) + (r_R + z_B)*sin(psi)*cos(phi)*cos(theta))
        + psi_dot*(x_B*(-sin(phi)*sin(theta)*cos(psi) - sin(psi)*cos(theta)) + (r_R +
        z_B)*(sin(phi)*cos(psi)*cos(theta) - sin(psi)*sin(theta))) +
        theta_dot*(x_B*(-sin(phi)*sin(psi)*cos(theta) - sin(theta)*cos(psi)) + (r_R +
        z_B)*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta))) + x_r_dot)**2 +
        (phi_dot*(x_B*sin(theta)*cos(phi)*cos(psi) - (r_R + z_B)*cos(phi)*cos(psi)*cos(theta)) +
        psi_dot*(x_B*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta)) + (r_R +
        z_B)*(sin(phi)*sin(psi)*cos(theta) + sin(theta)*cos(psi))) +
        theta_dot*(x_B*(sin(phi)*cos(psi)*cos(theta) - sin(psi)*sin(theta)) + (r_R +
        z_B)*(sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta))) + y_r_dot)**2)/2 +
        m_F*(x_f_dot**2 + y_f_dot**2 + z_f_dot**2)/2 + m_H*((delta_dot*((r_F +
        z_H)*((sin(delta)*cos(lam)**2 - sin(delta))*cos(phi)*cos(theta) -
        sin(delta)*sin(lam)*sin(theta)*cos(lam)*cos(phi) - sin(lam)*sin(phi)*cos(delta)) + (-w +
        x_H)*(-(sin(delta)*sin(lam)**2 - sin(delta))*sin(theta)*cos(phi) +
        sin(delta)*sin(lam)*cos(lam)*cos(phi)*cos(theta) + sin(phi)*cos(delta)*cos(lam))) +
        phi_dot*((r_F + z_H)*((1 - cos(delta))*sin(lam)*sin(phi)*sin(theta)*cos(lam) - ((1 -
        cos(delta))*cos(lam)**2 + cos(delta))*sin(phi)*cos(theta) -
        sin(delta)*sin(lam)*cos(phi)) + (-w + x_H)*(-(1 -
        cos(delta))*sin(lam)*sin(phi)*cos(lam)*cos(theta) + ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*sin(phi)*sin(theta) + sin(delta)*cos(lam)*cos(phi))) + theta_dot*((r_F +
        z_H)*(-(1 - cos(delta))*sin(lam)*cos(lam)*cos(phi)*cos(theta) - ((1 -
        cos(delta))*cos(lam)**2 + cos(delta))*sin(theta)*cos(phi)) + (-w + x_H)*(-(1 -
        cos(delta))*sin(lam)*sin(theta)*cos(lam)*cos(phi) - ((1 - cos(delta))*sin(lam)**2 +
        cos(delta))*cos(phi)*cos(theta))) + z_f_dot)**2 + (delta_dot*((r_F +
        z_H)*((sin(delta)*cos(lam)**2 - sin(delta))*(sin(phi)*sin(psi)*cos(theta) +
        sin(theta)*cos(psi)) + (-sin(phi)*sin(psi)*sin(theta) +
        cos(psi)*cos(theta))*sin(delta)*sin(lam)*cos(lam) +
        sin(lam)*sin(psi)*cos(delta)*cos(phi)) + (-w + x_H)*((sin(delta)*sin(lam)**2 -
        sin(delta))*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta)) +
        (sin(phi)*sin(psi)*cos(theta) + sin(theta)*cos(psi))*sin(delta)*sin(lam)*cos(lam) -
        sin(psi)*cos(delta)*cos(lam)*cos(phi))) + phi_dot*((r_F + z_H)*(-(1 -
        cos(delta))*sin(lam)*sin(psi)*sin(theta)*cos(lam)*cos(phi) + ((1 -
        cos(delta))*cos(lam)**2 + cos(delta))*sin(psi)*cos(phi)*cos(theta) -
        sin(delta)*sin(lam)*sin(phi)*sin(psi)) + (-w + x_H)*((1 -
        cos(delta))*sin(lam)*sin(psi)*cos(lam)*cos(phi)*cos(theta) - ((1 -
        cos(delta))*sin(lam)**2 + cos(delta))*sin(psi)*sin(theta)*cos(phi) +
        sin(delta)*sin(phi)*sin(psi)*cos(lam))) + psi_dot*((r_F + z_H)*((1 -
        cos(delta))*(-sin(phi)*sin(theta)*cos(psi) - sin(psi)*cos(theta))*sin(lam)*cos(lam) +
        ((1 - cos(delta))*cos(lam)**2 + cos(delta))*(sin(phi)*cos(psi)*cos(theta) -
        sin(psi)*sin(theta)) + sin(delta)*sin(lam)*cos(phi)*cos(psi)) + (-w + x_H)*((1 -
        cos(delta))*(sin(phi)*cos(psi)*cos(theta) - sin(psi)*sin(theta))*sin(lam)*cos(lam) + ((1
        - cos(delta))*sin(lam)**2 + cos(delta))*(-sin(phi)*sin(theta)*cos(psi) -
        sin(psi)*cos(theta)) - sin(delta)*cos(lam)*cos(phi)*cos(psi))) + theta_dot*((r_F +
        z_H)*((1 - cos(delta))*(-sin(phi)*sin(psi)*cos(theta) -
        sin(theta)*cos(psi))*sin(lam)*cos(lam) + ((1 - cos(delta))*cos(lam)**2 +
        cos(delta))*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta))) + (-w + x_H)*((1 -
        cos(delta))*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta))*sin(lam)*cos(lam) +
        ((1 - cos(delta))*sin(lam)**2 + cos(delta))*(-sin(phi)*sin(psi)*cos(theta) -
        sin(theta)*cos(psi)))) + x_f_dot)**2 + (delta_dot*((r_F + z_H)*((sin(delta)*cos(lam)**2
        - sin(delta))*(-sin(phi)*cos(psi)*cos(theta) + sin(psi)*sin(theta)) +
        (sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta))*sin(delta)*sin(lam)*cos(lam) -
        sin(lam)*cos(delta)*cos(phi)*cos(psi)) + (-w + x_H)*((sin(delta)*sin(lam)**2 -
        sin(delta))*(sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta)) +
        (-sin(phi)*cos(psi)*cos(theta) + sin(psi)*sin(theta))*sin(delta)*sin(lam)*cos(lam) +
        cos(delta)*cos(lam)*cos(phi)*cos(psi))) + phi_dot*((r_F + z_H)*((1 -
        cos(delta))*sin(lam)*sin(theta)*cos(lam)*cos(phi)*cos(psi) - ((1 -
        cos(delta))*cos(lam)**2 + cos(delta))*cos(phi)*cos(psi)*cos(theta) +
        sin(delta)*sin(lam)*sin(phi)*cos(psi)) + (-w + x_H)*(-(1 -
        cos(delta))*sin(lam)*cos(lam)*cos(phi)*cos(psi)*cos(theta) + ((1 -
        cos(delta))*sin(lam)**2 + cos(delta))*sin(theta)*cos(phi)*cos(psi) -
        sin(delta)*sin(phi)*cos(lam)*cos(psi))) + psi_dot*((r_F + z_H)*((1 -
        cos(delta))*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta))*sin(lam)*cos(lam) +
        ((1 - cos(delta))*cos(lam)**2 + cos(delta))*(sin(phi)*sin(psi)*cos(theta) +
        sin(theta)*cos(psi)) + sin(delta)*sin(lam)*sin(psi)*cos(phi)) + (-w + x_H)*((1 -
        cos(delta))*(sin(phi)*sin(psi)*cos(theta) + sin(theta)*cos(psi))*sin(lam)*cos(lam) + ((1
        - cos(delta))*sin(lam)**2 + cos(delta))*(-sin(phi)*sin(psi)*sin(theta) +
        cos(psi)*cos(theta)) - sin(delta)*sin(psi)*cos(lam)*cos(phi))) + theta_dot*((r_F +
        z_H)*((1 - cos(delta))*(sin(phi)*cos(psi)*cos(theta) -
        sin(psi)*sin(theta))*sin(lam)*cos(lam) + ((1 - cos(delta))*cos(lam)**2 +
        cos(delta))*(sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta))) + (-w + x_H)*((1 -
        cos(delta))*(sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta))*sin(lam)*cos(lam) + ((1
        - cos(delta))*sin(lam)**2 + cos(delta))*(sin(phi)*cos(psi)*cos(theta) -
        sin(psi)*sin(theta)))) + y_f_dot)**2)/2 + m_R*(x_r_dot**2 + y_r_dot**2 + z_r_dot**2)/2 +
        (I_Bxx*(phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi)) + I_Bxz*(phi_dot*sin(theta) +
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
    f[0] = r_R*cos(phi) + z_r = 0
    f[1] = x_f - x_r + (-c*sin(delta)*cos(lam) + r_F*sin(delta)*sin(lam))*sin(psi)*cos(phi) -
        (-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta))*(-c*((1 - cos(delta))*sin(lam)**2
        + cos(delta)) + c - r_F*(1 - cos(delta))*sin(lam)*cos(lam) + w) -
        (sin(phi)*sin(psi)*cos(theta) + sin(theta)*cos(psi))*(-c*(1 -
        cos(delta))*sin(lam)*cos(lam) - r_F*((1 - cos(delta))*cos(lam)**2 + cos(delta)) + r_R) = 0
    f[2] = y_f - y_r - (-c*sin(delta)*cos(lam) + r_F*sin(delta)*sin(lam))*cos(phi)*cos(psi) -
        (sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta))*(-c*((1 - cos(delta))*sin(lam)**2 +
        cos(delta)) + c - r_F*(1 - cos(delta))*sin(lam)*cos(lam) + w) -
        (-sin(phi)*cos(psi)*cos(theta) + sin(psi)*sin(theta))*(-c*(1 -
        cos(delta))*sin(lam)*cos(lam) - r_F*((1 - cos(delta))*cos(lam)**2 + cos(delta)) + r_R) = 0
    f[3] = z_f - z_r - (-c*sin(delta)*cos(lam) + r_F*sin(delta)*sin(lam))*sin(phi) - (-c*(1 -
        cos(delta))*sin(lam)*cos(lam) - r_F*((1 - cos(delta))*cos(lam)**2 + cos(delta)) +
        r_R)*cos(phi)*cos(theta) + (-c*((1 - cos(delta))*sin(lam)**2 + cos(delta)) + c - r_F*(1
        - cos(delta))*sin(lam)*cos(lam) + w)*sin(theta)*cos(phi) = 0
    f[4] = r_F*sqrt(1 - (sin(delta)*sin(lam)*cos(phi)*cos(theta) +
        sin(delta)*sin(theta)*cos(lam)*cos(phi) + sin(phi)*cos(delta))**2) + z_f = 0
    h[0] = r_R*((phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*(-sin(phi)*cos(psi)*cos(theta) +
        sin(psi)*sin(theta)) + (phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*(sin(phi)*sin(theta)*cos(psi) + sin(psi)*cos(theta)) +
        (psi_dot*sin(phi) + theta_R_dot + theta_dot)*cos(phi)*cos(psi))*cos(phi) +
        r_R*((phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*cos(phi)*cos(theta) -
        (phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi))*sin(theta)*cos(phi) +
        (psi_dot*sin(phi) + theta_R_dot + theta_dot)*sin(phi))*sin(phi)*cos(psi) + x_r_dot = 0
    h[1] = -r_R*((phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*(sin(phi)*sin(psi)*cos(theta) +
        sin(theta)*cos(psi)) + (phi_dot*cos(theta) -
        psi_dot*sin(theta)*cos(phi))*(-sin(phi)*sin(psi)*sin(theta) + cos(psi)*cos(theta)) -
        (psi_dot*sin(phi) + theta_R_dot + theta_dot)*sin(psi)*cos(phi))*cos(phi) +
        r_R*((phi_dot*sin(theta) + psi_dot*cos(phi)*cos(theta))*cos(phi)*cos(theta) -
        (phi_dot*cos(theta) - psi_dot*sin(theta)*cos(phi))*sin(theta)*cos(phi) +
        (psi_dot*sin(phi) + theta_R_dot + theta_dot)*sin(phi))*sin(phi)*sin(psi) + y_r_dot = 0
    h[2] = r_F*sqrt(1 - (sin(delta)*sin(lam)*cos(phi)*cos(theta) +
        sin(delta)*sin(theta)*cos(lam)*cos(phi) +
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
        sin(phi)*cos(delta))**2) + x_f_dot = 0
    h[3] = -r_F*sqrt(1 - (sin(delta)*sin(lam)*cos(phi)*cos(theta) +
        sin(delta)*sin(theta)*cos(lam)*cos(phi) +
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
        sin(phi)*cos(delta))**2) + y_f_dot = 0

Generated by `stabdae generate kernels/specs/bicycle_redundant.py`
with stabdae 0.1.0 (stabdae.symbolic), sympy 1.14.0.  Spec SHA-256: 53d7ff024982a7a5
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
    psi, phi, theta, delta = q[0], q[1], q[2], q[4]
    w = p[0]
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
    e0 = simdmath.sin(phi)
    e1 = (e0 * e0)
    e2 = simdmath.cos(phi)
    e3 = simdmath.sin(theta)
    e4 = I_Bxz * e3
    e5 = simdmath.cos(theta)
    e6 = I_Bzz * e2 * e5 - e2 * e4
    e7 = e2 * e5
    e8 = e2 * e3
    e9 = -I_Bxx * e8 + I_Bxz * e2 * e5
    e10 = (e2 * e2)
    e11 = 2.0 * (e3 * e3)
    e12 = 2.0 * (e5 * e5)
    e13 = 0.5 * I_Rxx
    e14 = simdmath.cos(delta)
    e15 = e0 * e14
    e16 = simdmath.sin(lam)
    e17 = simdmath.sin(delta)
    e18 = e16 * e17
    e19 = e18 * e7
    e20 = simdmath.cos(lam)
    e21 = e17 * e20
    e22 = e21 * e8
    e23 = e15 + e19 + e22
    e24 = 2.0 * e15 + 2.0 * e19 + 2.0 * e22
    e25 = 0.5 * I_Fyy
    e26 = e24 * e25
    e27 = 0.5 * e24
    e28 = I_Hyy * e27
    e29 = e0 * e17
    e30 = e20 * e29
    e31 = 1.0 - e14
    e32 = e16 * e31
    e33 = e20 * e32
    e34 = e33 * e7
    e35 = (e16 * e16)
    e36 = e31 * e35
    e37 = e14 + e36
    e38 = e37 * e8
    e39 = e30 + e34 - e38
    e40 = e16 * e29
    e41 = e33 * e8
    e42 = (e20 * e20)
    e43 = e31 * e42
    e44 = e14 + e43
    e45 = e2 * e44 * e5 - e40 - e41
    e46 = I_Hxx * e39 + I_Hxz * e45
    e47 = I_Hxz * e39 + I_Hzz * e45
    e48 = simdmath.cos(psi)
    e49 = simdmath.sin(psi)
    e50 = e3 * e49
    e51 = -e0 * e50 + e48 * e5
    e52 = e51 * x_B
    e53 = r_R + z_B
    e54 = e3 * e48
    e55 = e49 * e5
    e56 = e0 * e55 + e54
    e57 = e53 * e56
    e58 = 2.0 * e52 + 2.0 * e57
    e59 = e0 * e54 + e55
    e60 = -e59
    e61 = e60 * x_B
    e62 = e48 * e5
    e63 = e0 * e62 - e50
    e64 = e53 * e63
    e65 = 2.0 * e61 + 2.0 * e64
    e66 = 0.5 * m_B
    e67 = 2.0 * e30 + 2.0 * e34 - 2.0 * e38
    e68 = 2.0 * e2 * e44 * e5 - 2.0 * e40 - 2.0 * e41
    e69 = 0.5 * I_Fxx
    e70 = r_F + z_H
    e71 = e18 * e2
    e72 = e20 * e51
    e73 = e32 * e72
    e74 = e70 * (e44 * e56 + e49 * e71 + e73)
    e75 = -w + x_H
    e76 = e2 * e21
    e77 = e75 * (e33 * e56 + e37 * e51 - e49 * e76)
    e78 = 2.0 * e74 + 2.0 * e77
    e79 = e70 * (e33 * e60 + e44 * e63 + e48 * e71)
    e80 = e33 * e63
    e81 = e75 * (e37 * e60 - e48 * e76 + e80)
    e82 = 2.0 * e79 + 2.0 * e81
    e83 = 0.5 * m_H
    e84 = I_Bxx * e5 + e4
    e85 = I_Bxz * e5 + I_Bzz * e3
    e86 = e18 * e3
    e87 = e21 * e5
    e88 = e86 - e87
    e89 = e3 * e33
    e90 = e37 * e5
    e91 = e89 + e90
    e92 = e33 * e5
    e93 = e3 * e44
    e94 = e92 + e93
    e95 = I_Hxx * e91 + I_Hxz * e94
    e96 = 0.5 * e39
    e97 = I_Hxz * e91 + I_Hzz * e94
    e98 = 0.5 * e45
    e99 = e2 * x_B
    e100 = e54 * e99
    e101 = e2 * e53 * e62
    e102 = e100 - e101
    e103 = e50 * e99
    e104 = -e103 + e2 * e49 * e5 * e53
    e105 = 0.5 * e46
    e106 = 0.5 * e47
    e107 = e2 * e33
    e108 = e70 * (e107 * e54 - e2 * e44 * e62 + e40 * e48)
    e109 = e75 * (-e107 * e62 + e2 * e3 * e37 * e48 - e30 * e48)
    e110 = e108 + e109
    e111 = e70 * (-e107 * e50 + e2 * e44 * e49 * e5 - e40 * e49)
    e112 = e75 * (e107 * e55 - e2 * e37 * e50 + e30 * e49)
    e113 = e111 + e112
    e114 = I_Ryy * e0
    e115 = I_Fyy * e14
    e116 = I_Hxx * e21 - I_Hxz * e18
    e117 = I_Hxz * e21 - I_Hzz * e18
    e118 = e63 * x_B
    e119 = e53 * e59
    e120 = e118 + e119
    e121 = -e56
    e122 = e121 * x_B
    e123 = e51 * e53
    e124 = e122 + e123
    e125 = e70 * (e44 * e59 + e80)
    e126 = e75 * (e33 * e59 + e37 * e63)
    e127 = e125 + e126
    e128 = e70 * (e121 * e33 + e44 * e51)
    e129 = e75 * (e121 * e37 + e73)
    e130 = e128 + e129
    e131 = e16 * e43
    e132 = e16 * e37
    e133 = e131 + e132
    e134 = e20 * e36
    e135 = e20 * e44
    e136 = e134 + e135
    e137 = I_Hxx * e133 + I_Hxz * e136
    e138 = I_Hxz * e133 + I_Hzz * e136
    e139 = e14 * e2
    e140 = e139 * e48
    e141 = e18 * e20
    e142 = -e17
    e143 = e142 + e17 * e42
    e144 = -e63
    e145 = e70 * (-e140 * e16 + e141 * e59 + e143 * e144)
    e146 = e142 + e17 * e35
    e147 = e75 * (e140 * e20 + e141 * e144 + e146 * e59)
    e148 = e145 + e147
    e149 = e139 * e49
    e150 = e70 * (e143 * e56 + e149 * e16 + e18 * e72)
    e151 = e75 * (e141 * e56 + e146 * e51 - e149 * e20)
    e152 = e150 + e151
    e153 = 2.0 * e86 - 2.0 * e87
    e154 = e153 * e25
    e155 = 0.5 * e153
    e156 = I_Hyy * e155
    e157 = e0 * e3
    e158 = e157 * x_B
    e159 = e0 * e5
    e160 = e159 * e53
    e161 = 2.0 * e158 - 2.0 * e160
    e162 = -2.0 * e103 + 2.0 * e2 * e49 * e5 * e53
    e163 = 2.0 * e100 - 2.0 * e101
    e164 = 2.0 * e89 + 2.0 * e90
    e165 = 2.0 * e92 + 2.0 * e93
    e166 = e70 * (e0 * e16 * e20 * e3 * e31 - e159 * e44 - e71)
    e167 = e75 * (e157 * e37 - e159 * e33 + e76)
    e168 = 2.0 * e166 + 2.0 * e167
    e169 = 2.0 * e111 + 2.0 * e112
    e170 = 2.0 * e108 + 2.0 * e109
    e171 = 0.5 * e91
    e172 = 0.5 * e94
    e173 = 0.5 * e21
    e174 = 0.5 * e18
    e175 = e7 * x_B
    e176 = e53 * e8
    e177 = -e175 - e176
    e178 = e70 * (-e2 * e93 - e34)
    e179 = e75 * (-e2 * e90 - e41)
    e180 = e178 + e179
    e181 = 0.5 * e133
    e182 = 0.5 * e136
    e183 = e70 * (-e141 * e8 + e143 * e2 * e5 - e15 * e16)
    e184 = e75 * (-e146 * e8 + e15 * e20 + e19 * e20)
    e185 = e183 + e184
    e186 = (e14 * e14)
    e187 = 2.0 * (e17 * e17)
    e188 = -2.0 * e175 - 2.0 * e176
    e189 = 2.0 * e118 + 2.0 * e119
    e190 = 2.0 * e122 + 2.0 * e123
    e191 = 2.0 * e178 + 2.0 * e179
    e192 = 2.0 * e125 + 2.0 * e126
    e193 = 2.0 * e128 + 2.0 * e129
    e194 = 2.0 * e183 + 2.0 * e184
    e195 = 2.0 * e150 + 2.0 * e151
    e196 = 2.0 * e145 + 2.0 * e147
    e197 = m_B + m_R
    e198 = m_F + m_H
    out[:, :] = 0.0
    out[0, 0] = (
        I_Byy * e1 + I_Ryy * e1 + e13 * (e10 * e11 + e10 * e12) + e23 * e26 + e23 * e28 + e39 * e46
        + e45 * e47 + e6 * e7 + e66 * (e58 * (e52 + e57) + e65 * (e61 + e64))
        + e69 * (e39 * e67 + e45 * e68) - e8 * e9 + e83 * (e78 * (e74 + e77) + e82 * (e79 + e81))
    )
    out[0, 1] = (
        e105 * e91 + e106 * e94 + e26 * e88 + e28 * e88 + 0.5 * e3 * e6 + 0.5 * e5 * e9
        + e66 * (e102 * e58 + e104 * e65) + e69 * (e67 * e91 + e68 * e94) + 0.5 * e7 * e85
        - 0.5 * e8 * e84 + e83 * (e110 * e78 + e113 * e82) + e95 * e96 + e97 * e98
    )
    out[0, 2] = (
        I_Byy * e0 + e105 * e21 - e106 * e18 + e114 + e115 * e27 + e116 * e96 + e117 * e98
        + e14 * e28 + e66 * (e120 * e58 + e124 * e65) + e69 * (e17 * e20 * e67 - e18 * e68)
        + e83 * (e127 * e78 + e130 * e82)
    )
    out[0, 3] = e114
    out[0, 4] = (
        e105 * e133 + e106 * e136 + e137 * e96 + e138 * e98 + e69 * (e133 * e67 + e136 * e68)
        + e83 * (e148 * e78 + e152 * e82)
    )
    out[0, 5] = e26
    out[0, 6] = e65 * e66
    out[0, 7] = e58 * e66
    out[0, 9] = e82 * e83
    out[0, 10] = e78 * e83
    out[1, 1] = (
        e13 * (e11 + e12) + e154 * e88 + e156 * e88 + e3 * e85 + e5 * e84
        + e66 * (e102 * e163 + e104 * e162 + e161 * (e158 - e160)) + e69 * (e164 * e91 + e165 * e94)
        + e83 * (e110 * e170 + e113 * e169 + e168 * (e166 + e167)) + e91 * e95 + e94 * e97
    )
    out[1, 2] = (
        e115 * e155 + e116 * e171 + e117 * e172 + e14 * e156 + e173 * e95 - e174 * e97
        + e66 * (e120 * e163 + e124 * e162 + e161 * e177) + e69 * (e164 * e21 - e165 * e18)
        + e83 * (e127 * e170 + e130 * e169 + e168 * e180)
    )
    out[1, 4] = (
        e137 * e171 + e138 * e172 + e181 * e95 + e182 * e97 + e69 * (e133 * e164 + e136 * e165)
        + e83 * (e148 * e170 + e152 * e169 + e168 * e185)
    )
    out[1, 5] = e154
    out[1, 6] = e162 * e66
    out[1, 7] = e163 * e66
    out[1, 8] = e161 * e66
    out[1, 9] = e169 * e83
    out[1, 10] = e170 * e83
    out[1, 11] = e168 * e83
    out[2, 2] = (
        I_Byy + I_Fyy * e186 + I_Hyy * e186 + I_Ryy + e116 * e21 - e117 * e18
        + e66 * (e120 * e189 + e124 * e190 + e177 * e188) + e69 * (e187 * e35 + e187 * e42)
        + e83 * (e127 * e192 + e130 * e193 + e180 * e191)
    )
    out[2, 3] = I_Ryy
    out[2, 4] = (
        e116 * e181 + e117 * e182 + e137 * e173 - e138 * e174
        + e69 * (2.0 * e133 * e21 - 2.0 * e136 * e18)
        + e83 * (e148 * e192 + e152 * e193 + e185 * e191)
    )
    out[2, 5] = e115
    out[2, 6] = e190 * e66
    out[2, 7] = e189 * e66
    out[2, 8] = e188 * e66
    out[2, 9] = e193 * e83
    out[2, 10] = e192 * e83
    out[2, 11] = e191 * e83
    out[3, 3] = I_Ryy
    out[4, 4] = (
        e133 * e137 + e136 * e138
        + e69 * (e133 * (2.0 * e131 + 2.0 * e132) + e136 * (2.0 * e134 + 2.0 * e135))
        + e83 * (e148 * e196 + e152 * e195 + e185 * e194)
    )
    out[4, 9] = e195 * e83
    out[4, 10] = e196 * e83
    out[4, 11] = e194 * e83
    out[5, 5] = I_Fyy
    out[6, 6] = e197
    out[7, 7] = e197
    out[8, 8] = e197
    out[9, 9] = e198
    out[10, 10] = e198
    out[11, 11] = e198
    out[1, 0] = out[0, 1]
    out[2, 0] = out[0, 2]
    out[2, 1] = out[1, 2]
    out[3, 0] = out[0, 3]
    out[3, 2] = out[2, 3]
    out[4, 0] = out[0, 4]
    out[4, 1] = out[1, 4]
    out[4, 2] = out[2, 4]
    out[5, 0] = out[0, 5]
    out[5, 1] = out[1, 5]
    out[5, 2] = out[2, 5]
    out[6, 0] = out[0, 6]
    out[6, 1] = out[1, 6]
    out[6, 2] = out[2, 6]
    out[7, 0] = out[0, 7]
    out[7, 1] = out[1, 7]
    out[7, 2] = out[2, 7]
    out[8, 1] = out[1, 8]
    out[8, 2] = out[2, 8]
    out[9, 0] = out[0, 9]
    out[9, 1] = out[1, 9]
    out[9, 2] = out[2, 9]
    out[9, 4] = out[4, 9]
    out[10, 0] = out[0, 10]
    out[10, 1] = out[1, 10]
    out[10, 2] = out[2, 10]
    out[10, 4] = out[4, 10]
    out[11, 1] = out[1, 11]
    out[11, 2] = out[2, 11]
    out[11, 4] = out[4, 11]


@njit(cache=True)
def forces(t, q, v, p, out):
    # γ = (∂²L/∂v∂q) v + ∂²L/∂v∂t − ∂L/∂q − Q, so that M v̇ = Fᵀλ − γ  (3.3)
    psi, phi, theta, delta = q[0], q[1], q[2], q[4]
    psi_dot = v[0]
    phi_dot = v[1]
    theta_dot = v[2]
    theta_R_dot = v[3]
    delta_dot = v[4]
    theta_F_dot = v[5]
    x_r_dot = v[6]
    y_r_dot = v[7]
    z_r_dot = v[8]
    x_f_dot = v[9]
    y_f_dot = v[10]
    z_f_dot = v[11]
    w = p[0]
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
    e2 = simdmath.cos(phi)
    e3 = e2 * phi_dot
    e4 = e1 * e3
    e5 = e1 + theta_dot
    e6 = I_Byy * e5
    e7 = I_Ryy * (e5 + theta_R_dot)
    e8 = simdmath.sin(theta)
    e9 = e8 * phi_dot
    e10 = simdmath.cos(theta)
    e11 = e2 * psi_dot
    e12 = e10 * e11
    e13 = e12 + e9
    e14 = e10 * phi_dot
    e15 = e11 * e8
    e16 = e14 - e15
    e17 = 0.5 * I_Bxx * e16 + 0.5 * I_Bxz * e13
    e18 = e0 * e9
    e19 = e0 * e14
    e20 = I_Bxz * e16
    e21 = I_Bzz * e13 + e20
    e22 = 0.5 * e21
    e23 = e10 * e2
    e24 = e23 * theta_dot
    e25 = e2 * e8
    e26 = e25 * theta_dot
    e27 = e0 * e8 * phi_dot * psi_dot - e12 * theta_dot - e9 * theta_dot
    e28 = 0.5 * e27
    e29 = I_Bxz * e8
    e30 = e2 * e29
    e31 = -e1 * e14 + e10 * phi_dot * theta_dot - e15 * theta_dot
    e32 = 0.5 * e31
    e33 = I_Bxz * e10
    e34 = I_Bzz * e8
    e35 = e2 * theta_dot
    e36 = 0.5 * e13
    e37 = I_Bxx * e10
    e38 = 0.5 * e16
    e39 = 0.5 * I_Bxx * e27 + 0.5 * I_Bxz * e31
    e40 = 0.5 * I_Bxz * e27 + 0.5 * I_Bzz * e31
    e41 = 2.0 * e14
    e42 = e0 * e41
    e43 = 2.0 * theta_dot
    e44 = e25 * e43
    e45 = e23 * e43
    e46 = 2.0 * e27
    e47 = 0.5 * I_Rxx
    e48 = simdmath.sin(delta)
    e49 = delta_dot * e48
    e50 = simdmath.cos(delta)
    e51 = simdmath.sin(lam)
    e52 = simdmath.cos(lam)
    e53 = e0 * e48
    e54 = e51 * e53
    e55 = e52 * e53
    e56 = 2.0 * e9
    e57 = e48 * e51
    e58 = (
        2.0 * delta_dot * e10 * e2 * e50 * e51 + 2.0 * delta_dot * e2 * e50 * e52 * e8
        - 2.0 * e0 * e49 + 2.0 * e10 * e2 * e48 * e52 * theta_dot + 2.0 * e2 * e50 * phi_dot
        - e41 * e54 - e44 * e57 - e55 * e56
    )
    e59 = e5 * e50
    e60 = delta_dot * e52
    e61 = e13 + e60
    e62 = e57 * e61
    e63 = delta_dot * e51
    e64 = e16 + e63
    e65 = e48 * e52
    e66 = e59 + e62 - e64 * e65
    e67 = 0.5 * I_Hyy
    e68 = e66 * e67
    e69 = e66 + theta_F_dot
    e70 = 0.5 * I_Fyy
    e71 = e69 * e70
    e72 = e49 * e5
    e73 = e50 * e60
    e74 = e64 * e73
    e75 = e27 * e65
    e76 = (
        delta_dot * e50 * e51 * e61 + e2 * e50 * phi_dot * psi_dot + e31 * e48 * e51 - e72 - e74
        - e75
    )
    e77 = e0 * e50
    e78 = 2.0 * e77
    e79 = 2.0 * e57
    e80 = e23 * e79
    e81 = 2.0 * e65
    e82 = e76 * (e25 * e81 + e78 + e80)
    e83 = 1.0 - e50
    e84 = e51 * e52
    e85 = e83 * e84
    e86 = e23 * e85
    e87 = (e51 * e51)
    e88 = e83 * e87
    e89 = e50 + e88
    e90 = e25 * e89
    e91 = e86 - e90
    e92 = e55 + e91
    e93 = e25 * e85
    e94 = (e52 * e52)
    e95 = e83 * e94
    e96 = e50 + e95
    e97 = e23 * e96
    e98 = e93 - e97
    e99 = e54 + e98
    e100 = -e99
    e101 = e11 * e65
    e102 = -e49
    e103 = e102 + e49 * e87
    e104 = e101 * phi_dot + e103 * e64 + e27 * e89 + e31 * e85 + e59 * e60 + e60 * e62
    e105 = 0.5 * e104
    e106 = e11 * e57
    e107 = e57 * e60
    e108 = e102 + e49 * e94
    e109 = -e106 * phi_dot + e107 * e64 + e108 * e61 + e27 * e85 + e31 * e96 - e59 * e63
    e110 = 0.5 * e109
    e111 = e103 * e25
    e112 = e60 * e77
    e113 = e18 * e89
    e114 = e2 * e65
    e115 = e10 * e89
    e116 = e115 * e2
    e117 = e19 * e85
    e118 = e107 * e23 - e117 - e93 * theta_dot
    e119 = -e111 + e112 + e113 + e114 * phi_dot - e116 * theta_dot + e118
    e120 = e48 * e5
    e121 = e120 * e52 + e61 * e85 + e64 * e89
    e122 = -e120 * e51 + e61 * e96 + e64 * e85
    e123 = I_Hxx * e121 + I_Hxz * e122
    e124 = 0.5 * e123
    e125 = e63 * e77
    e126 = e19 * e96
    e127 = e2 * e57
    e128 = e8 * e96
    e129 = e128 * e2
    e130 = -e0 * e51 * e52 * e8 * e83 * phi_dot + e107 * e25 + e86 * theta_dot
    e131 = e10 * e108 * e2 - e125 - e126 - e127 * phi_dot - e129 * theta_dot - e130
    e132 = 0.5 * I_Hxz * e121 + 0.5 * I_Hzz * e122
    e133 = 0.5 * e121
    e134 = 0.5 * e122
    e135 = I_Hxx * e104 + I_Hxz * e109
    e136 = 0.5 * e135
    e137 = 0.5 * I_Hxz * e104 + 0.5 * I_Hzz * e109
    e138 = simdmath.cos(psi)
    e139 = e138 * e8
    e140 = e2 * x_B
    e141 = e139 * e140
    e142 = e10 * e138
    e143 = r_R + z_B
    e144 = e143 * e2
    e145 = e142 * e144
    e146 = e141 - e145
    e147 = simdmath.sin(psi)
    e148 = e147 * e8
    e149 = e0 * e148
    e150 = -e10 * e138 + e149
    e151 = -e150
    e152 = e151 * x_B
    e153 = e10 * e147
    e154 = e0 * e153
    e155 = e139 + e154
    e156 = e143 * e155
    e157 = e0 * e142
    e158 = -e148 + e157
    e159 = e158 * x_B
    e160 = e0 * e139
    e161 = e153 + e160
    e162 = e143 * e161
    e163 = e146 * phi_dot + psi_dot * (e152 + e156) + theta_dot * (e159 + e162) + y_r_dot
    e164 = e140 * e148
    e165 = e10 * e143 * e147 * e2 - e164
    e166 = e165 * phi_dot
    e167 = -e161
    e168 = e167 * x_B
    e169 = e143 * e158
    e170 = e168 + e169
    e171 = e170 * psi_dot
    e172 = -e155
    e173 = e172 * x_B
    e174 = e143 * e151
    e175 = e173 + e174
    e176 = e175 * theta_dot
    e177 = e166 + e171 + e176 + x_r_dot
    e178 = -e146
    e179 = 2.0 * phi_dot
    e180 = e143 * e172 + e150 * x_B
    e181 = 2.0 * psi_dot
    e182 = -e158
    e183 = e143 * e167 + e182 * x_B
    e184 = 0.5 * m_B
    e185 = e0 * e56
    e186 = 0.5 * I_Fxx
    e187 = e142 * theta_dot
    e188 = e147 * e2
    e189 = e1 * e142 + e14 * e188 - e148 * psi_dot - e149 * theta_dot + e187
    e190 = e143 * e189
    e191 = e139 * theta_dot
    e192 = -e1 * e139 - e153 * psi_dot - e154 * theta_dot - e188 * e9 - e191
    e193 = e192 * x_B
    e194 = e148 * theta_dot
    e195 = e138 * e2
    e196 = e0 * e187 - e1 * e148 + e142 * psi_dot - e194 + e195 * e9
    e197 = -e196
    e198 = e197 * x_B
    e199 = e153 * theta_dot
    e200 = e0 * e191 + e1 * e153 - e10 * e138 * e2 * phi_dot + e139 * psi_dot + e199
    e201 = -e200
    e202 = e143 * e201
    e203 = e140 * e187
    e204 = e11 * x_B
    e205 = e148 * e204
    e206 = e143 * e19
    e207 = e11 * e143 * e153
    e208 = e144 * e191
    e209 = phi_dot * (-e138 * e18 * x_B + e138 * e206 + e203 - e205 + e207 + e208)
    e210 = e201 * x_B
    e211 = e143 * e196
    e212 = theta_dot * (e210 + e211)
    e213 = psi_dot * (e190 + e193)
    e214 = e209 + e212 + e213
    e215 = e139 * e204
    e216 = e140 * e199
    e217 = e144 * e194
    e218 = (
        phi_dot
        * (
              e0 * e147 * e8 * phi_dot * x_B + e10 * e138 * e143 * e2 * psi_dot - e147 * e206 - e215
              - e216 - e217
          )
    )
    e219 = psi_dot * (e198 + e202)
    e220 = -e189
    e221 = e220 * x_B
    e222 = e143 * e192
    e223 = theta_dot * (e221 + e222)
    e224 = e218 + e219 + e223
    e225 = r_F + z_H
    e226 = e138 * e54
    e227 = e2 * e85
    e228 = e139 * e227
    e229 = e2 * e96
    e230 = -e142 * e229 + e226 + e228
    e231 = e225 * e230
    e232 = -w + x_H
    e233 = e138 * e55
    e234 = e142 * e227
    e235 = -e138 * e2 * e8 * e89 + e233 + e234
    e236 = -e232 * e235
    e237 = e158 * e85
    e238 = e225 * (e161 * e96 + e237)
    e239 = e232 * (e158 * e89 + e161 * e85)
    e240 = e2 * e50
    e241 = e240 * e51
    e242 = e138 * e241
    e243 = e52 * e57
    e244 = e161 * e243
    e245 = -e48
    e246 = e48 * e94
    e247 = e245 + e246
    e248 = e225 * (e182 * e247 - e242 + e244)
    e249 = e240 * e52
    e250 = e138 * e249
    e251 = e48 * e87
    e252 = e245 + e251
    e253 = e232 * (e161 * e252 + e182 * e243 + e250)
    e254 = e127 * e147
    e255 = e151 * e85
    e256 = e225 * (e155 * e96 + e254 + e255)
    e257 = e114 * e147
    e258 = e232 * (e151 * e89 + e155 * e85 - e257)
    e259 = (
        delta_dot * (e248 + e253) + phi_dot * (e231 + e236) + psi_dot * (e256 + e258)
        + theta_dot * (e238 + e239) + y_f_dot
    )
    e260 = e147 * e54
    e261 = e148 * e227
    e262 = e225 * (e10 * e147 * e2 * e96 - e260 - e261)
    e263 = e147 * e55
    e264 = e153 * e227
    e265 = e2 * e89
    e266 = e232 * (-e148 * e265 + e263 + e264)
    e267 = e262 + e266
    e268 = e267 * phi_dot
    e269 = e172 * e85
    e270 = e225 * (e151 * e96 + e269)
    e271 = e232 * (e172 * e89 + e255)
    e272 = e270 + e271
    e273 = e272 * theta_dot
    e274 = e151 * e243
    e275 = e225 * (e147 * e241 + e155 * e247 + e274)
    e276 = e232 * (-e147 * e249 + e151 * e252 + e155 * e243)
    e277 = e275 + e276
    e278 = delta_dot * e277
    e279 = e127 * e138
    e280 = e167 * e85
    e281 = e158 * e96 + e280
    e282 = e225 * (e279 + e281)
    e283 = e114 * e138
    e284 = -e283
    e285 = e167 * e89 + e237
    e286 = e232 * (e284 + e285)
    e287 = psi_dot * (e282 + e286)
    e288 = e268 + e273 + e278 + e287 + x_f_dot
    e289 = -e225 * e230 + e232 * e235
    e290 = e225 * (e167 * e96 + e182 * e85) + e232 * (e182 * e89 + e280)
    e291 = e158 * e243
    e292 = e225 * (e158 * e247 + e167 * e243 + e242) + e232 * (e167 * e252 - e250 + e291)
    e293 = 2.0 * delta_dot
    e294 = -e254
    e295 = e150 * e85 + e172 * e96
    e296 = e150 * e89 + e269
    e297 = 0.5 * m_H
    e298 = e240 * e63
    e299 = e107 * e151 + e192 * e85
    e300 = e225 * (e106 * e138 + e108 * e155 + e147 * e298 + e189 * e96 - e260 * phi_dot + e299)
    e301 = e240 * e60
    e302 = (
        e232
        * (
              -e101 * e138 + e103 * e151 + e107 * e155 - e147 * e301 + e189 * e85 + e192 * e89
              + e263 * phi_dot
          )
    )
    e303 = (
        e225
        * (
              -e106 * e147 + e107 * e167 + e108 * e158 + e138 * e298 + e197 * e85 + e201 * e96
              - e226 * phi_dot
          )
    )
    e304 = e107 * e158 + e201 * e85
    e305 = e232 * (e101 * e147 + e103 * e167 - e138 * e301 + e197 * e89 + e233 * phi_dot + e304)
    e306 = e225 * (e108 * e161 + e196 * e96 + e304)
    e307 = e232 * (e103 * e158 + e107 * e161 + e196 * e85 + e201 * e89)
    e308 = theta_dot * (e306 + e307)
    e309 = e195 * e48
    e310 = e51 * e77
    e311 = e138 * e310
    e312 = e11 * e50
    e313 = e147 * e312
    e314 = e51 * e73
    e315 = delta_dot * e50
    e316 = -e315
    e317 = e315 * e94 + e316
    e318 = (
        e225
        * (
              e161 * e314 + e182 * e317 + e196 * e243 + e200 * e247 + e309 * e63 + e311 * phi_dot
              + e313 * e51
          )
    )
    e319 = e52 * e77
    e320 = e138 * e319
    e321 = e315 * e87 + e316
    e322 = (
        e232
        * (
              e161 * e321 + e182 * e314 + e196 * e252 + e200 * e243 - e309 * e60 - e313 * e52
              - e320 * phi_dot
          )
    )
    e323 = delta_dot * (e318 + e322)
    e324 = psi_dot * (e300 + e302)
    e325 = e1 * e147
    e326 = e127 * e60
    e327 = e11 * e85
    e328 = (
        e225
        * (
              -e108 * e142 * e2 + e11 * e153 * e96 + e125 * e138 + e126 * e138 - e138 * e18 * e85
              + e139 * e326 - e148 * e327 + e187 * e227 + e191 * e229 + e279 * phi_dot - e325 * e57
          )
    )
    e329 = e103 * e2
    e330 = e11 * e89
    e331 = (
        e232
        * (
              -e112 * e138 - e113 * e138 + e117 * e138 + e139 * e329 - e142 * e326 - e148 * e330
              + e153 * e327 + e187 * e265 + e191 * e227 - e283 * phi_dot + e325 * e65
          )
    )
    e332 = phi_dot * (e328 + e331)
    e333 = e308 + e323 + e324 + e332
    e334 = e225 * (e107 * e172 + e108 * e151 + e192 * e96 + e220 * e85)
    e335 = e232 * (e103 * e172 + e220 * e89 + e299)
    e336 = theta_dot * (e334 + e335)
    e337 = e138 * e312
    e338 = e188 * e48
    e339 = e147 * e310
    e340 = (
        e225
        * (
              e151 * e314 + e155 * e317 + e189 * e247 + e192 * e243 + e337 * e51 - e338 * e63
              - e339 * phi_dot
          )
    )
    e341 = e147 * e319
    e342 = (
        e232
        * (
              e151 * e321 + e155 * e314 + e189 * e243 + e192 * e252 - e337 * e52 + e338 * e60
              + e341 * phi_dot
          )
    )
    e343 = delta_dot * (e340 + e342)
    e344 = psi_dot * (e303 + e305)
    e345 = e1 * e138
    e346 = (
        e232
        * (
              e112 * e147 + e113 * e147 - e117 * e147 - e139 * e330 + e142 * e327 - e148 * e329
              + e153 * e326 - e194 * e227 - e199 * e265 + e257 * phi_dot + e345 * e65
          )
    )
    e347 = (
        e225
        * (
              e0 * e147 * e51 * e52 * e8 * e83 * phi_dot + e10 * e108 * e147 * e2
              + e10 * e138 * e2 * e96 * psi_dot - e125 * e147 - e126 * e147 - e139 * e327
              - e148 * e326 - e194 * e229 - e199 * e227 - e254 * phi_dot - e345 * e57
          )
    )
    e348 = phi_dot * (e346 + e347)
    e349 = e336 + e343 + e344 + e348
    e350 = e8 * theta_dot
    e351 = e1 * e10
    e352 = e1 * e8
    e353 = e10 * theta_dot
    e354 = 2.0 * e2 * e50 * psi_dot - e351 * e79 - e352 * e81
    e355 = e10 * e43
    e356 = e43 * e8
    e357 = e50 * e63
    e358 = 2.0 * e357
    e359 = -2.0 * e10 * e73 + e355 * e57 + e356 * e65 + e358 * e8
    e360 = e0 * e8
    e361 = e360 * x_B
    e362 = e0 * e10
    e363 = e143 * e362
    e364 = e361 - e363
    e365 = e225 * (e0 * e51 * e52 * e8 * e83 - e127 - e362 * e96)
    e366 = e362 * e85
    e367 = e232 * (e114 + e360 * e89 - e366)
    e368 = e365 + e367
    e369 = e79 * e8
    e370 = e76 * (-e10 * e81 + e369)
    e371 = e10 * e85
    e372 = e352 * e89
    e373 = -e1 * e371 + e101 + e372
    e374 = e351 * e96
    e375 = e0 * e51 * e52 * e8 * e83 * psi_dot - e106 - e374
    e376 = e10 * e103
    e377 = e107 * e8 - e350 * e89 + e353 * e85 + e376
    e378 = e108 * e8
    e379 = e10 * e107 - e350 * e85 + e353 * e96 + e378
    e380 = e8 * e85
    e381 = e115 + e380
    e382 = e128 + e371
    e383 = 2.0 * e371
    e384 = e362 * x_B
    e385 = e143 * e360
    e386 = e384 + e385
    e387 = e25 * x_B
    e388 = e143 * e23
    e389 = e387 - e388
    e390 = e23 * x_B
    e391 = e143 * e25
    e392 = -e390 - e391
    e393 = e364 * phi_dot + e392 * theta_dot + z_r_dot
    e394 = e139 * e144 + e140 * e142
    e395 = -e140 * e153 - e144 * e148
    e396 = e10 * e60
    e397 = phi_dot * (-e14 * e144 + e140 * e9 + e384 * theta_dot + e385 * theta_dot)
    e398 = theta_dot * (e143 * e18 + e19 * x_B + e387 * theta_dot - e388 * theta_dot)
    e399 = e397 + e398
    e400 = e143 * e42
    e401 = e0 * e128
    e402 = e360 * e85
    e403 = e0 * e115
    e404 = e225 * (e366 + e401) + e232 * (e402 + e403)
    e405 = e51 * e55
    e406 = (
        e225 * (e0 * e48 * e51 * e52 * e8 - e241 - e247 * e362)
        + e232 * (-e10 * e405 + e249 + e252 * e360)
    )
    e407 = e225 * (-e129 - e86)
    e408 = e232 * (-e116 - e93)
    e409 = e407 + e408
    e410 = e243 * e25
    e411 = e225 * (e10 * e2 * e247 - e310 - e410)
    e412 = e23 * e243
    e413 = e232 * (-e25 * e252 + e319 + e412)
    e414 = e411 + e413
    e415 = delta_dot * e414 + e368 * phi_dot + e409 * theta_dot + z_f_dot
    e416 = e225 * (e139 * e229 + e234) + e232 * (e142 * e265 + e228)
    e417 = e127 * e52
    e418 = (
        e225 * (e139 * e417 - e142 * e2 * e247 + e311)
        + e232 * (e138 * e2 * e252 * e8 - e142 * e417 - e320)
    )
    e419 = e225 * (-e148 * e229 - e264) + e232 * (-e153 * e265 - e261)
    e420 = (
        e225 * (e10 * e147 * e2 * e247 - e148 * e417 - e339)
        + e232 * (-e148 * e2 * e252 + e153 * e417 + e341)
    )
    e421 = (
        e225
        * (
              -e108 * e362 - e14 * e229 + e227 * e9 - e298 + e366 * theta_dot + e401 * theta_dot
              + e54 * e60 * e8 + e54 * phi_dot
          )
    )
    e422 = (
        e232
        * (
              e103 * e360 - e14 * e227 + e265 * e9 + e301 - e396 * e54 + e402 * theta_dot
              + e403 * theta_dot - e55 * phi_dot
          )
    )
    e423 = e225 * (e0 * e8 * e96 * phi_dot - e118 - e2 * e378 - e97 * theta_dot)
    e424 = e232 * (e0 * e10 * e89 * phi_dot - e130 - e2 * e376 + e2 * e8 * e89 * theta_dot)
    e425 = theta_dot * (e423 + e424)
    e426 = e247 * e25
    e427 = (
        e225
        * (
              delta_dot * e0 * e48 * e51 + e0 * e48 * e51 * e52 * e8 * phi_dot + e10 * e2 * e317
              - e19 * e247 - e24 * e243 - e241 * phi_dot - e25 * e314 - e426 * theta_dot
          )
    )
    e428 = e23 * e252
    e429 = (
        e232
        * (
              delta_dot * e10 * e2 * e50 * e51 * e52 + e0 * e252 * e8 * phi_dot - e14 * e405
              + e2 * e50 * e52 * phi_dot - e243 * e26 - e25 * e321 - e428 * theta_dot - e53 * e60
          )
    )
    e430 = delta_dot * (e427 + e429)
    e431 = phi_dot * (e421 + e422)
    e432 = e425 + e430 + e431
    e433 = -e13
    e434 = 2.0 * e16 * e48 * e51 - e433 * e81
    e435 = e16 * e85
    e436 = e433 * e89
    e437 = e435 + e436
    e438 = e433 * e85
    e439 = e16 * e96
    e440 = e438 + e439
    e441 = e225 * (-e412 - e426) + e232 * (-e410 - e428)
    e442 = e225 * (e161 * e247 + e291) + e232 * (e158 * e252 + e244)
    e443 = e225 * (e151 * e247 + e172 * e243) + e232 * (e172 * e252 + e274)
    e444 = -2.0 * e120 + 2.0 * e50 * e51 * e61 - 2.0 * e50 * e52 * e64
    e445 = e246 * e63
    e446 = e103 * e51
    e447 = e445 + e446
    e448 = e251 * e60
    e449 = e108 * e52
    e450 = e448 + e449
    e451 = e52 * e59
    e452 = e52 * e62
    e453 = e252 * e64
    e454 = e451 + e452 + e453
    e455 = e51 * e59
    e456 = e243 * e64
    e457 = e247 * e61
    e458 = -e455 + e456 + e457
    e459 = e51 * e95
    e460 = e51 * e89
    e461 = e459 + e460
    e462 = e52 * e88
    e463 = e52 * e96
    e464 = e462 + e463
    e465 = e50 * e84
    e466 = -e50
    e467 = e466 + e50 * e94
    e468 = e466 + e50 * e87
    out[0] = (
        I_Byy * e4 + I_Ryy * e4 + e100 * e137 + e105 * (I_Hxx * e92 + I_Hxz * e100)
        + e110 * (I_Hxz * e92 + I_Hzz * e100) + e119 * e124 + e131 * e132
        + e133 * (I_Hxx * e119 + I_Hxz * e131) + e134 * (I_Hxz * e119 + I_Hzz * e131) + e136 * e92
        + e17 * e18 - e17 * e24
        - e184
          * (
                e163 * (2.0 * e166 + 2.0 * e171 + 2.0 * e176)
                + e177 * (e178 * e179 + e180 * e181 + e183 * e43)
            )
         + e184
        * (
              e163 * (2.0 * e190 + 2.0 * e193) + e177 * (2.0 * e198 + 2.0 * e202)
              + e214 * (2.0 * e152 + 2.0 * e156) + e224 * (2.0 * e168 + 2.0 * e169)
          )
         + e186
        * (
              e104 * (2.0 * e55 + 2.0 * e86 - 2.0 * e90)
              + e109 * (2.0 * e10 * e2 * e96 - 2.0 * e54 - 2.0 * e93)
              + e121
                * (
                      -2.0 * e111 + e114 * e179 - e116 * e43 + e185 * e89 - e42 * e85 - e44 * e85
                      + e60 * e78 + e60 * e80
                  )
               + e122
              * (
                    2.0 * e0 * e51 * e52 * e8 * e83 * phi_dot + 2.0 * e10 * e108 * e2 - e127 * e179
                    - e129 * e43 - e25 * e60 * e79 - e42 * e96 - e45 * e85 - e63 * e78
                )
          )
         - e19 * e22 - e22 * e26 + e23 * e40 - e25 * e39 + e28 * (-I_Bxx * e25 + I_Bxz * e10 * e2)
        - e297
          * (
                e259 * (2.0 * e268 + 2.0 * e273 + 2.0 * e278 + 2.0 * e287)
                + e288
                  * (
                        e179 * e289 + e181 * (e225 * (e294 + e295) + e232 * (e257 + e296))
                        + e290 * e43 + e292 * e293
                    )
            )
         + e297
        * (
              e259 * (2.0 * e300 + 2.0 * e302) + e288 * (2.0 * e303 + 2.0 * e305)
              + e333 * (2.0 * e256 + 2.0 * e258) + e349 * (2.0 * e282 + 2.0 * e286)
          )
         + e3 * e6 + e3 * e7 + e32 * (I_Bzz * e10 * e2 - e30)
        + e36 * (I_Bxz * e0 * e8 * phi_dot - I_Bzz * e19 - e2 * e33 * theta_dot - e34 * e35)
        + e38 * (I_Bxx * e0 * e8 * phi_dot - I_Bxz * e19 - e30 * theta_dot - e35 * e37)
        + e47
          * (
                2.0 * e0 * e16 * e8 * phi_dot + 2.0 * e10 * e2 * e31 - e13 * e42 - e13 * e44
                - e16 * e45 - e25 * e46
            )
         + e58 * e68 + e58 * e71 + e67 * e82 + e70 * e82
    )
    out[1] = (
        e10 * e39 + e105 * (I_Hxx * e381 + I_Hxz * e382) - e11 * e6 - e11 * e7
        + e110 * (I_Hxz * e381 + I_Hzz * e382) - e124 * e373 + e124 * e377 - e132 * e375
        + e132 * e379 - e133 * (I_Hxx * e373 + I_Hxz * e375) + e133 * (I_Hxx * e377 + I_Hxz * e379)
        - e134 * (I_Hxz * e373 + I_Hzz * e375) + e134 * (I_Hxz * e377 + I_Hzz * e379) + e136 * e381
        + e137 * e382 - e17 * e350 - e17 * e352
        - e184
          * (
                e163 * (e165 * e181 + e179 * (e0 * e10 * e138 * e143 - e160 * x_B) + e394 * e43)
                + e177 * (e178 * e181 + e179 * (-e143 * e154 + e149 * x_B) + e395 * e43)
                + e393 * (e179 * e389 + e386 * e43)
            )
         + e184
        * (
              e163
              * (
                    -e138 * e185 * x_B + e138 * e400 + 2.0 * e203 - 2.0 * e205 + 2.0 * e207
                    + 2.0 * e208
                )
               + e177
              * (
                    2.0 * e0 * e147 * e8 * phi_dot * x_B + 2.0 * e10 * e138 * e143 * e2 * psi_dot
                    - e147 * e400 - 2.0 * e215 - 2.0 * e216 - 2.0 * e217
                )
               + e214 * (2.0 * e141 - 2.0 * e145)
              + e224 * (2.0 * e10 * e143 * e147 * e2 - 2.0 * e164)
              + e393 * (e140 * e56 - e144 * e41 + e384 * e43 + e385 * e43)
              + e399 * (2.0 * e361 - 2.0 * e363)
          )
         - e186
        * (
              e121 * (-e1 * e383 + 2.0 * e101 + 2.0 * e372)
              + e122 * (2.0 * e0 * e51 * e52 * e8 * e83 * psi_dot - 2.0 * e106 - 2.0 * e374)
          )
         + e186
        * (
              e104 * (2.0 * e115 + 2.0 * e380) + e109 * (2.0 * e128 + e383)
              + e121 * (e355 * e85 - e356 * e89 + e369 * e60 + 2.0 * e376)
              + e122 * (e355 * e96 - e356 * e85 + 2.0 * e378 + e396 * e79)
          )
         + e22 * e351 + e22 * e353 + e28 * (e29 + e37)
        - e297
          * (
                e259
                * (
                      e179
                      * (
                            e225 * (e157 * e96 - e160 * e85 + e279)
                            + e232 * (e0 * e10 * e138 * e51 * e52 * e83 - e160 * e89 - e283)
                        )
                       + e181 * e267 + e293 * e418 + e416 * e43
                  )
                 + e288
                * (
                      e179
                      * (
                            e225 * (e0 * e147 * e51 * e52 * e8 * e83 - e154 * e96 - e254)
                            + e232 * (e149 * e89 - e154 * e85 + e257)
                        )
                       + e181 * e289 + e293 * e420 + e419 * e43
                  )
                 + e415 * (e179 * (e225 * e99 - e232 * e92) + e293 * e406 + e404 * e43)
            )
         + e297
        * (
              e259 * (2.0 * e328 + 2.0 * e331) + e288 * (2.0 * e346 + 2.0 * e347)
              + e333 * (2.0 * e231 + 2.0 * e236) + e349 * (2.0 * e262 + 2.0 * e266)
              + e415 * (2.0 * e421 + 2.0 * e422) + e432 * (2.0 * e365 + 2.0 * e367)
          )
         + e32 * (e33 + e34) - e354 * e68 - e354 * e71 + e359 * e68 + e359 * e71
        - e36 * (-I_Bzz * e351 + e1 * e29) + e36 * (I_Bzz * e10 * theta_dot - e29 * theta_dot)
        + e370 * e67 + e370 * e70 + e38 * (-I_Bxx * e350 + I_Bxz * e10 * theta_dot)
        - e38 * (I_Bxx * e352 - e1 * e33) + e40 * e8
        - e47 * (2.0 * e0 * e16 * e8 * psi_dot - 2.0 * e13 * e351)
        + e47 * (e10 * e46 + e13 * e355 - e16 * e356 + 2.0 * e31 * e8)
        - g * (e364 * m_B + e368 * m_H)
    )
    out[2] = (
        I_Byy * e2 * phi_dot * psi_dot
        + 0.5 * I_Fxx
          * (2.0 * delta_dot * e121 * e50 * e52 + 2.0 * e104 * e48 * e52 - e109 * e79 - e122 * e358)
         - I_Fyy * e49 * e69 + I_Fyy * e50 * e76 - I_Hyy * e49 * e66 + I_Hyy * e50 * e76
        + I_Ryy * e2 * phi_dot * psi_dot + 0.5 * delta_dot * e123 * e50 * e52
        + 0.5 * e104 * (I_Hxx * e65 - I_Hxz * e57) + 0.5 * e109 * (I_Hxz * e65 - I_Hzz * e57)
        + 0.5 * e121 * (I_Hxx * e73 - I_Hxz * e357) + 0.5 * e122 * (I_Hxz * e73 - I_Hzz * e357)
        - e124 * e437 - e132 * e357 - e132 * e440 - e133 * (I_Hxx * e437 + I_Hxz * e440)
        - e134 * (I_Hxz * e437 + I_Hzz * e440) + 0.5 * e135 * e48 * e52 - e137 * e57 - e17 * e433
        - e184
          * (
                e163 * (e170 * e43 + e175 * e181 + e179 * e394)
                + e177 * (e179 * e395 + e180 * e43 + e181 * e183)
                + e393 * (e179 * e386 + e389 * e43)
            )
         - e186 * (e121 * (2.0 * e435 + 2.0 * e436) + e122 * (2.0 * e438 + 2.0 * e439)) - e21 * e38
        - e297
          * (
                e259 * (e179 * e416 + e181 * e272 + e293 * e442 + e43 * (e225 * e281 + e232 * e285))
                + e288
                  * (e179 * e419 + e181 * e290 + e293 * e443 + e43 * (e225 * e295 + e232 * e296))
                 + e415 * (e179 * e404 + e293 * e441 + e43 * (e225 * e98 - e232 * e91))
            )
         - e36 * (I_Bxz * e433 + I_Bzz * e16) - e38 * (I_Bxx * e433 + e20) - e434 * e68 - e434 * e71
        - e47 * (e13 * (-2.0 * e15 + e41) + e16 * (-2.0 * e12 - e56))
        - g * (e392 * m_B + e409 * m_H)
        + 0.5 * m_B
          * (
                e163 * (2.0 * e210 + 2.0 * e211) + e177 * (2.0 * e221 + 2.0 * e222)
                + e214 * (2.0 * e159 + 2.0 * e162) + e224 * (2.0 * e173 + 2.0 * e174)
                + e393 * (e143 * e185 + e387 * e43 - e388 * e43 + e42 * x_B)
                + e399 * (-2.0 * e390 - 2.0 * e391)
            )
         + 0.5 * m_H
        * (
              e259 * (2.0 * e306 + 2.0 * e307) + e288 * (2.0 * e334 + 2.0 * e335)
              + e333 * (2.0 * e238 + 2.0 * e239) + e349 * (2.0 * e270 + 2.0 * e271)
              + e415 * (2.0 * e423 + 2.0 * e424) + e432 * (2.0 * e407 + 2.0 * e408)
          )
    )
    out[3] = I_Ryy * e11 * phi_dot
    out[4] = (
        e105 * (I_Hxx * e461 + I_Hxz * e464) + e110 * (I_Hxz * e461 + I_Hzz * e464) + e124 * e447
        - e124 * e454 + e132 * e450 - e132 * e458 + e133 * (I_Hxx * e447 + I_Hxz * e450)
        - e133 * (I_Hxx * e454 + I_Hxz * e458) + e134 * (I_Hxz * e447 + I_Hzz * e450)
        - e134 * (I_Hxz * e454 + I_Hzz * e458) + e136 * e461 + e137 * e464
        - e186
          * (
                e121 * (2.0 * e451 + 2.0 * e452 + 2.0 * e453)
                + e122 * (-2.0 * e455 + 2.0 * e456 + 2.0 * e457)
            )
         + e186
        * (
              e104 * (2.0 * e459 + 2.0 * e460) + e109 * (2.0 * e462 + 2.0 * e463)
              + e121 * (2.0 * e445 + 2.0 * e446) + e122 * (2.0 * e448 + 2.0 * e449)
          )
         - e297
        * (
              e259
              * (
                    e179 * e418 + e181 * e277
                    + e293
                      * (
                            e225 * (e161 * e465 + e182 * e467 + e279)
                            + e232 * (e161 * e468 + e182 * e465 + e284)
                        )
                     + e43 * e442
                )
               + e288
              * (
                    e179 * e420 + e181 * e292
                    + e293
                      * (
                            e225 * (e151 * e465 + e155 * e467 + e294)
                            + e232 * (e151 * e468 + e155 * e465 + e257)
                        )
                     + e43 * e443
                )
               + e415
              * (
                    e179 * e406
                    + e293
                      * (
                            e225 * (e23 * e467 - e25 * e465 + e54)
                            + e232 * (e10 * e2 * e50 * e51 * e52 - e25 * e468 - e55)
                        )
                     + e43 * e441
                )
          )
         + e297
        * (
              e259 * (2.0 * e318 + 2.0 * e322) + e288 * (2.0 * e340 + 2.0 * e342)
              + e333 * (2.0 * e248 + 2.0 * e253) + e349 * (2.0 * e275 + 2.0 * e276)
              + e415 * (2.0 * e427 + 2.0 * e429) + e432 * (2.0 * e411 + 2.0 * e413)
          )
         - e414 * g * m_H - e444 * e68 - e444 * e71
    )
    out[5] = (
        e70
        * (
              2.0 * delta_dot * e50 * e51 * e61 + 2.0 * e2 * e50 * phi_dot * psi_dot
              + 2.0 * e31 * e48 * e51 - 2.0 * e72 - 2.0 * e74 - 2.0 * e75
          )
    )
    out[6] = e184 * (2.0 * e218 + 2.0 * e219 + 2.0 * e223)
    out[7] = e184 * (2.0 * e209 + 2.0 * e212 + 2.0 * e213)
    out[8] = -g * (m_B + m_R) + 0.5 * m_B * (2.0 * e397 + 2.0 * e398)
    out[9] = e297 * (2.0 * e336 + 2.0 * e343 + 2.0 * e344 + 2.0 * e348)
    out[10] = e297 * (2.0 * e308 + 2.0 * e323 + 2.0 * e324 + 2.0 * e332)
    out[11] = -g * (m_F + m_H) + 0.5 * m_H * (2.0 * e425 + 2.0 * e430 + 2.0 * e431)


@njit(cache=True)
def f(t, q, p, out):
    psi = q[0]
    phi = q[1]
    theta = q[2]
    delta = q[4]
    x_r = q[6]
    y_r = q[7]
    z_r = q[8]
    x_f = q[9]
    y_f = q[10]
    z_f = q[11]
    w, c, lam, r_R, r_F = p[0], p[1], p[2], p[3], p[4]
    e0 = simdmath.cos(phi)
    e1 = simdmath.sin(psi)
    e2 = simdmath.sin(delta)
    e3 = simdmath.cos(lam)
    e4 = c * e3
    e5 = simdmath.sin(lam)
    e6 = -e2 * e4 + e2 * e5 * r_F
    e7 = simdmath.sin(theta)
    e8 = simdmath.cos(psi)
    e9 = e7 * e8
    e10 = simdmath.sin(phi)
    e11 = simdmath.cos(theta)
    e12 = e1 * e11
    e13 = simdmath.cos(delta)
    e14 = 1.0 - e13
    e15 = -e14 * e4 * e5 - r_F * (e13 + e14 * (e3 * e3)) + r_R
    e16 = -c * (e13 + e14 * (e5 * e5)) + c - e14 * e3 * e5 * r_F + w
    e17 = e0 * e11
    out[0] = e0 * r_R + z_r
    out[1] = e0 * e1 * e6 - e15 * (e10 * e12 + e9) - e16 * (-e1 * e10 * e7 + e11 * e8) + x_f - x_r
    out[2] = -e0 * e6 * e8 - e15 * (e1 * e7 - e10 * e11 * e8) - e16 * (e10 * e9 + e12) + y_f - y_r
    out[3] = e0 * e16 * e7 - e10 * e6 - e15 * e17 + z_f - z_r
    out[4] = (
        r_F
        * math.sqrt(
              1.0
              - (
                    (e0 * e2 * e3 * e7 + e10 * e13 + e17 * e2 * e5)
                    * (e0 * e2 * e3 * e7 + e10 * e13 + e17 * e2 * e5)
                )
          )
         + z_f
    )


@njit(cache=True)
def f_q(t, q, p, out):
    psi, phi, theta, delta = q[0], q[1], q[2], q[4]
    w, c, lam, r_R, r_F = p[0], p[1], p[2], p[3], p[4]
    e0 = simdmath.sin(phi)
    e1 = simdmath.cos(phi)
    e2 = simdmath.cos(psi)
    e3 = simdmath.sin(delta)
    e4 = simdmath.cos(lam)
    e5 = c * e4
    e6 = e3 * e5
    e7 = simdmath.sin(lam)
    e8 = e3 * e7 * r_F - e6
    e9 = simdmath.sin(psi)
    e10 = simdmath.sin(theta)
    e11 = e10 * e9
    e12 = simdmath.cos(theta)
    e13 = e12 * e2
    e14 = e0 * e13 - e11
    e15 = simdmath.cos(delta)
    e16 = 1.0 - e15
    e17 = (e4 * e4)
    e18 = -e16 * e5 * e7 - r_F * (e15 + e16 * e17) + r_R
    e19 = e12 * e9
    e20 = e10 * e2
    e21 = e0 * e20 + e19
    e22 = e7 * r_F
    e23 = (e7 * e7)
    e24 = -c * (e15 + e16 * e23) + c - e16 * e22 * e4 + w
    e25 = e0 * e8
    e26 = e1 * e18
    e27 = -e0 * e11 + e12 * e2
    e28 = e0 * e19 + e20
    e29 = -e15 * e5 + e15 * e7 * r_F
    e30 = -e3
    e31 = -e6 * e7 - r_F * (e17 * e3 + e30)
    e32 = -c * (e23 * e3 + e30) - e22 * e3 * e4
    e33 = e0 * e10
    e34 = e1 * e10
    e35 = e1 * e12
    e36 = 2.0 * e3
    e37 = e36 * e7
    e38 = e35 * e7
    e39 = e34 * e4
    e40 = e0 * e15 + e3 * e38 + e3 * e39
    e41 = 0.5 * e40 * r_F / math.sqrt(1.0 - (e40 * e40))
    e42 = 2.0 * e15
    out[:, :] = 0.0
    out[0, 1] = -e0 * r_R
    out[0, 8] = 1.0
    out[1, 0] = e1 * e2 * e8 - e14 * e18 + e21 * e24
    out[1, 1] = e1 * e10 * e24 * e9 - e19 * e26 - e25 * e9
    out[1, 2] = -e18 * e27 + e24 * e28
    out[1, 4] = e1 * e29 * e9 - e27 * e32 - e28 * e31
    out[1, 6] = -1.0
    out[1, 9] = 1.0
    out[2, 0] = e1 * e8 * e9 - e18 * e28 - e24 * e27
    out[2, 1] = -e1 * e20 * e24 + e13 * e26 + e2 * e25
    out[2, 2] = -e14 * e24 - e18 * e21
    out[2, 4] = -e1 * e2 * e29 + e14 * e31 - e21 * e32
    out[2, 7] = -1.0
    out[2, 10] = 1.0
    out[3, 1] = e0 * e12 * e18 - e1 * e8 - e24 * e33
    out[3, 2] = e18 * e34 + e24 * e35
    out[3, 4] = -e0 * e29 + e1 * e10 * e32 - e31 * e35
    out[3, 8] = -1.0
    out[3, 11] = 1.0
    out[4, 1] = -e41 * (-e0 * e12 * e37 + 2.0 * e1 * e15 - e33 * e36 * e4)
    out[4, 2] = -e41 * (2.0 * e1 * e12 * e3 * e4 - e34 * e37)
    out[4, 4] = -e41 * (-e0 * e36 + e38 * e42 + e39 * e42)
    out[4, 11] = 1.0


@njit(cache=True)
def f_accel(t, q, v, p, out):
    # f̈ = f_q v̇ + f_accel:  ∂ḟ/∂q v + ∂ḟ/∂t with ḟ = f_q v + f_t
    psi, phi, theta, delta = q[0], q[1], q[2], q[4]
    psi_dot, phi_dot, theta_dot, delta_dot = v[0], v[1], v[2], v[4]
    w, c, lam, r_R, r_F = p[0], p[1], p[2], p[3], p[4]
    e0 = (phi_dot * phi_dot)
    e1 = simdmath.cos(phi)
    e2 = e0 * e1
    e3 = (delta_dot * delta_dot)
    e4 = simdmath.sin(delta)
    e5 = e1 * e4
    e6 = simdmath.sin(psi)
    e7 = simdmath.cos(lam)
    e8 = c * e7
    e9 = simdmath.sin(lam)
    e10 = e9 * r_F
    e11 = -e10 + e8
    e12 = e11 * e6
    e13 = e12 * e5
    e14 = e2 * e4
    e15 = (psi_dot * psi_dot)
    e16 = simdmath.sin(phi)
    e17 = simdmath.cos(delta)
    e18 = e16 * e17
    e19 = e18 * phi_dot
    e20 = 2.0 * delta_dot
    e21 = e12 * e20
    e22 = simdmath.cos(psi)
    e23 = e11 * e22
    e24 = e20 * e23
    e25 = e1 * e17 * psi_dot
    e26 = e16 * e4
    e27 = e11 * e26
    e28 = 2.0 * psi_dot
    e29 = simdmath.sin(theta)
    e30 = e22 * e29
    e31 = simdmath.cos(theta)
    e32 = e31 * e6
    e33 = e16 * e32
    e34 = e8 * e9
    e35 = (e7 * e7)
    e36 = e34 + r_F * (e35 - 1.0)
    e37 = e17 * e3
    e38 = e36 * e37
    e39 = e22 * e31
    e40 = e29 * e6
    e41 = e16 * e40
    e42 = e10 * e7
    e43 = (e9 * e9)
    e44 = c * (e43 - 1.0) + e42
    e45 = e37 * e44
    e46 = e32 * psi_dot
    e47 = e30 * theta_dot
    e48 = e1 * phi_dot
    e49 = e16 * e30
    e50 = e33 * theta_dot
    e51 = e20 * e4
    e52 = e39 * theta_dot
    e53 = e40 * psi_dot
    e54 = e16 * e39
    e55 = e41 * theta_dot
    e56 = e17 - 1.0
    e57 = -e17
    e58 = e34 * e56 - r_F * (-e35 * e56 - e57) + r_R
    e59 = e15 * e30
    e60 = (theta_dot * theta_dot)
    e61 = e30 * e60
    e62 = 2.0 * theta_dot
    e63 = e39 * psi_dot
    e64 = 2.0 * e48
    e65 = e40 * theta_dot
    e66 = e16 * e47
    e67 = -c * (-e43 * e56 - e57) + c + e42 * e56 + w
    e68 = e15 * e39
    e69 = e39 * e60
    e70 = e30 * psi_dot
    e71 = e32 * theta_dot
    e72 = e16 * e52
    e73 = e23 * e5
    e74 = e1 * e29
    e75 = delta_dot * e26
    e76 = e31 * e62
    e77 = delta_dot * e5
    e78 = e29 * e62
    e79 = e16 * phi_dot
    e80 = e29 * e67
    e81 = e1 * e60
    e82 = e31 * e9
    e83 = e5 * e82
    e84 = e29 * e7
    e85 = e5 * e84
    e86 = e18 + e83 + e85
    e87 = (e86 * e86)
    e88 = 1.0 - e87
    e89 = e26 * phi_dot
    e90 = e29 * e9
    e91 = (
        (
            (
                delta_dot * e1 * e17 * e29 * e7 + delta_dot * e1 * e17 * e31 * e9
                + e1 * e17 * phi_dot + e1 * e31 * e4 * e7 * theta_dot - e5 * e90 * theta_dot - e75
                - e82 * e89 - e84 * e89
            )
             * (
                delta_dot * e1 * e17 * e29 * e7 + delta_dot * e1 * e17 * e31 * e9
                + e1 * e17 * phi_dot + e1 * e31 * e4 * e7 * theta_dot - e5 * e90 * theta_dot - e75
                - e82 * e89 - e84 * e89
            )
        )
    )
    e92 = e4 * e81
    e93 = e19 * e20
    e94 = delta_dot * e17 * e62
    e95 = e62 * e89
    out[0] = -e2 * r_R
    out[1] = (
        e12 * e14 + e13 * e15 + e13 * e3 + e19 * e21 + e22 * e27 * e28 * phi_dot - e24 * e25
        + e36 * e51 * (e32 * e48 + e52 - e53 + e54 * psi_dot - e55) + e38 * (e30 + e33)
        - e44 * e51 * (e40 * e48 + e46 + e47 + e49 * psi_dot + e50) - e45 * (-e39 + e41)
        + e58
          * (
                e0 * e33 + e15 * e33 + e28 * e66 + e33 * e60 + e46 * e62 + e59 + e61 - e63 * e64
                + e64 * e65
            )
         + e67
        * (
              -e0 * e41 - e15 * e41 + e28 * e72 - e41 * e60 - e53 * e62 + e64 * e70 + e64 * e71
              + e68 + e69
          )
    )
    out[2] = (
        2.0 * delta_dot * e36 * e4 * (e33 * psi_dot - e39 * e48 + e66 + e70 + e71)
        + 2.0 * delta_dot * e4 * e44 * (e30 * e48 - e41 * psi_dot + e63 - e65 + e72)
        + 2.0 * e11 * e16 * e4 * e6 * phi_dot * psi_dot - e14 * e23 - e15 * e73
        + e17 * e3 * e44 * (e32 + e49) - e19 * e24 - e21 * e25 - e3 * e73 - e38 * (-e40 + e54)
        - e58
          * (
                e0 * e54 - e15 * e40 + e16 * e68 + e16 * e69 + e28 * e52 - e28 * e55 - e40 * e60
                + e46 * e64 + e47 * e64
            )
         + e67
        * (
              e0 * e49 + e15 * e32 + e16 * e59 + e16 * e61 + e28 * e47 + e28 * e50 + e32 * e60
              - e52 * e64 + e53 * e64
          )
    )
    out[3] = (
        2.0 * delta_dot * e1 * e11 * e17 * phi_dot
        + 2.0 * delta_dot * e16 * e29 * e4 * e44 * phi_dot + e0 * e1 * e31 * e58 - e0 * e27
        + e1 * e17 * e3 * e31 * e36 + e1 * e31 * e58 * e60 - e2 * e80 - e27 * e3
        - 2.0 * e31 * e36 * e75 * phi_dot - e36 * e77 * e78 - e44 * e76 * e77 - e45 * e74
        - e58 * e78 * e79 - e67 * e76 * e79 - e80 * e81
    )
    out[4] = (
        r_F
        * (
              e86
              * (
                    e0 * e18 - e1 * e31 * e7 * e94 + e14 * e82 + e14 * e84 + e18 * e3 + e3 * e83
                    + e3 * e85 + e31 * e7 * e95 + e48 * e51 + e74 * e9 * e94 + e82 * e92 + e82 * e93
                    + e84 * e92 + e84 * e93 - e90 * e95
                )
               - e87 * e91 / e88 - e91
          )
         / math.sqrt(e88)
    )


@njit(cache=True)
def h(t, q, v, p, out):
    psi, phi, theta, delta = q[0], q[1], q[2], q[4]
    psi_dot = v[0]
    phi_dot = v[1]
    theta_dot = v[2]
    theta_R_dot = v[3]
    delta_dot = v[4]
    theta_F_dot = v[5]
    x_r_dot = v[6]
    y_r_dot = v[7]
    x_f_dot = v[9]
    y_f_dot = v[10]
    lam, r_R, r_F = p[2], p[3], p[4]
    e0 = simdmath.cos(psi)
    e1 = simdmath.sin(phi)
    e2 = e1 * psi_dot + theta_dot
    e3 = e2 + theta_R_dot
    e4 = simdmath.sin(theta)
    e5 = simdmath.cos(theta)
    e6 = simdmath.cos(phi)
    e7 = e6 * psi_dot
    e8 = e4 * phi_dot + e5 * e7
    e9 = e5 * e6
    e10 = -e4 * e7 + e5 * phi_dot
    e11 = e4 * e6
    e12 = e1 * r_R * (e1 * e3 - e10 * e11 + e8 * e9)
    e13 = e3 * e6
    e14 = simdmath.sin(psi)
    e15 = -e0 * e1 * e5 + e14 * e4
    e16 = e14 * e5
    e17 = e0 * e4
    e18 = e1 * e17 + e16
    e19 = e6 * r_R
    e20 = e1 * e16 + e17
    e21 = e0 * e5 - e1 * e14 * e4
    e22 = simdmath.cos(delta)
    e23 = e22 * e6
    e24 = simdmath.cos(lam)
    e25 = simdmath.sin(delta)
    e26 = e24 * e25
    e27 = simdmath.sin(lam)
    e28 = e25 * e27
    e29 = e0 * e23 + e15 * e28 - e18 * e26
    e30 = delta_dot * e24 + e8
    e31 = delta_dot * e27 + e10
    e32 = e2 * e22 - e26 * e31 + e28 * e30 + theta_F_dot
    e33 = e0 * e6
    e34 = 1.0 - e22
    e35 = e24 * e27 * e34
    e36 = e22 + (e27 * e27) * e34
    e37 = e2 * e25
    e38 = e24 * e37 + e30 * e35 + e31 * e36
    e39 = e22 + (e24 * e24) * e34
    e40 = -e27 * e37 + e30 * e39 + e31 * e35
    e41 = e1 * e22 + e11 * e26 + e28 * e9
    e42 = math.sqrt(1.0 - (e41 * e41))
    e43 = e42 * r_F
    e44 = (
        e41 * r_F
        * (
              e32 * e41 + e38 * (e1 * e26 - e11 * e36 + e35 * e9)
              + e40 * (-e1 * e28 - e11 * e35 + e39 * e5 * e6)
          )
         / e42
    )
    e45 = -e14 * e23 + e20 * e25 * e27 - e21 * e26
    e46 = e14 * e6
    out[0] = e0 * e12 + e19 * (e0 * e13 + e10 * e18 + e15 * e8) + x_r_dot
    out[1] = e12 * e14 - e19 * (e10 * e21 - e13 * e14 + e20 * e8) + y_r_dot
    out[2] = (
        e29 * e44
        + e43
          * (
                e29 * e32 + e38 * (e15 * e35 + e18 * e36 + e26 * e33)
                + e40 * (e15 * e39 + e18 * e35 - e28 * e33)
            )
         + x_f_dot
    )
    out[3] = (
        -e43
        * (
              e32 * e45 + e38 * (e20 * e35 + e21 * e36 - e26 * e46)
              + e40 * (e20 * e39 + e21 * e35 + e28 * e46)
          )
         - e44 * e45 + y_f_dot
    )


@njit(cache=True)
def h_q(t, q, v, p, out):
    psi, phi, theta, delta = q[0], q[1], q[2], q[4]
    psi_dot = v[0]
    phi_dot = v[1]
    theta_dot = v[2]
    theta_R_dot = v[3]
    delta_dot = v[4]
    theta_F_dot = v[5]
    lam, r_R, r_F = p[2], p[3], p[4]
    e0 = simdmath.sin(psi)
    e1 = simdmath.sin(phi)
    e2 = e1 * psi_dot
    e3 = e2 + theta_dot
    e4 = e3 + theta_R_dot
    e5 = e1 * e4
    e6 = simdmath.cos(phi)
    e7 = simdmath.cos(theta)
    e8 = simdmath.sin(theta)
    e9 = e6 * psi_dot
    e10 = e7 * e9 + e8 * phi_dot
    e11 = e10 * e7
    e12 = e7 * phi_dot - e8 * e9
    e13 = e11 * e6 - e12 * e6 * e8 + e5
    e14 = e1 * r_R
    e15 = e4 * e6
    e16 = simdmath.cos(psi)
    e17 = e16 * e8
    e18 = e0 * e7
    e19 = e1 * e18 + e17
    e20 = e0 * e8
    e21 = -e1 * e20 + e16 * e7
    e22 = -e0 * e15 + e10 * e19 + e12 * e21
    e23 = e6 * r_R
    e24 = e13 * e23
    e25 = e15 * e16
    e26 = e16 * e7
    e27 = -e0 * e8 + e1 * e26
    e28 = -e27
    e29 = e1 * e17 + e18
    e30 = e2 * e6
    e31 = (
        e14
        * (
              -e1 * e11 + e1 * e12 * e8 + e1 * e6 * psi_dot - e30 * (e7 * e7) - e30 * (e8 * e8)
              + e4 * e6
          )
    )
    e32 = (e6 * e6) * psi_dot
    e33 = e2 * e8
    e34 = e10 * e6
    e35 = e12 * e6
    e36 = e2 * e7
    e37 = -e29
    e38 = simdmath.cos(delta)
    e39 = e38 * e6
    e40 = e0 * e39
    e41 = simdmath.cos(lam)
    e42 = simdmath.sin(delta)
    e43 = e41 * e42
    e44 = simdmath.sin(lam)
    e45 = e19 * e42 * e44 - e21 * e43 - e40
    e46 = e3 * e38
    e47 = delta_dot * e41 + e10
    e48 = e42 * e44
    e49 = e47 * e48
    e50 = delta_dot * e44 + e12
    e51 = -e43 * e50 + e46 + e49 + theta_F_dot
    e52 = e48 * e6
    e53 = 1.0 - e38
    e54 = e41 * e44 * e53
    e55 = e21 * e54
    e56 = (e41 * e41)
    e57 = e38 + e53 * e56
    e58 = e0 * e52 + e19 * e57 + e55
    e59 = e3 * e42
    e60 = -e44 * e59 + e47 * e57 + e50 * e54
    e61 = e43 * e6
    e62 = (e44 * e44)
    e63 = e38 + e53 * e62
    e64 = -e0 * e61 + e19 * e54 + e21 * e63
    e65 = e41 * e59 + e47 * e54 + e50 * e63
    e66 = e45 * e51 + e58 * e60 + e64 * e65
    e67 = e1 * e38
    e68 = e52 * e7
    e69 = e61 * e8 + e67 + e68
    e70 = (e69 * e69)
    e71 = 1.0 - e70
    e72 = math.sqrt(e71)
    e73 = e72 * r_F
    e74 = (1.0 / e72)
    e75 = e1 * e42
    e76 = e41 * e75
    e77 = e6 * e7
    e78 = e54 * e77
    e79 = e63 * e8
    e80 = -e6 * e79 + e76 + e78
    e81 = e44 * e75
    e82 = e6 * e8
    e83 = e54 * e82
    e84 = e57 * e6 * e7 - e81 - e83
    e85 = r_F * (e51 * e69 + e60 * e84 + e65 * e80)
    e86 = e74 * e85
    e87 = e69 * e86
    e88 = -e16 * e67 - e17 * e61 - e26 * e52
    e89 = e7 * e81
    e90 = e76 * e8
    e91 = e38 * e6 - e89 - e90
    e92 = e16 * e39
    e93 = e28 * e48
    e94 = -e29 * e43 + e92 + e93
    e95 = e86 * e94
    e96 = 2.0 * e38 * e6 - 2.0 * e89 - 2.0 * e90
    e97 = 0.5 * e70 * e85 / e71**(1.5)
    e98 = e94 * e97
    e99 = e16 * e61
    e100 = e28 * e54 + e29 * e63 + e99
    e101 = e16 * e52
    e102 = e29 * e54
    e103 = -e101 + e102 + e28 * e57
    e104 = e69 * e74 * r_F
    e105 = 0.5 * e104 * (e100 * e65 + e103 * e60 + e51 * e94)
    e106 = -e33 * e43 - e36 * e48 + e38 * e6 * psi_dot
    e107 = e2 * e79 - e36 * e54 + e43 * e9
    e108 = e57 * e7
    e109 = e1 * e41 * e44 * e53 * e8 * psi_dot - e108 * e2 - e48 * e9
    e110 = (
        e106 * e69 + e107 * e80 + e109 * e84 + e51 * e91
        + e60 * (-e1 * e108 + e1 * e41 * e44 * e53 * e8 - e52)
        + e65 * (-e1 * e54 * e7 + e1 * e79 + e61)
    )
    e111 = e104 * e94
    e112 = e54 * e6
    e113 = e29 * e48
    e114 = e113 - e27 * e43
    e115 = e52 * e8
    e116 = -e115 + e41 * e42 * e6 * e7
    e117 = -2.0 * e115 + 2.0 * e41 * e42 * e6 * e7
    e118 = -e10
    e119 = -e118 * e43 + e12 * e42 * e44
    e120 = e118 * e63 + e12 * e54
    e121 = e118 * e54 + e12 * e57
    e122 = (
        e116 * e51 + e119 * e69 + e120 * e80 + e121 * e84 + e60 * (-e57 * e82 - e78)
        + e65 * (-e63 * e77 - e83)
    )
    e123 = e27 * e54
    e124 = e44 * e7
    e125 = e41 * e8
    e126 = e124 * e39 + e125 * e39 - e75
    e127 = e42 * e6
    e128 = e38 * e41
    e129 = -e127 * e16 - e128 * e29 + e28 * e38 * e44
    e130 = 2.0 * e39
    e131 = e124 * e130 + e125 * e130 - 2.0 * e75
    e132 = -e128 * e50 + e38 * e44 * e47 - e59
    e133 = -e42
    e134 = e133 + e42 * e62
    e135 = e134 * e50 + e41 * e46 + e41 * e49
    e136 = e133 + e42 * e56
    e137 = e136 * e47 + e41 * e48 * e50 - e44 * e46
    e138 = (
        e126 * e51 + e132 * e69 + e135 * e80 + e137 * e84
        + e60 * (-e115 * e41 + e136 * e6 * e7 - e44 * e67)
        + e65 * (-e134 * e82 + e41 * e67 + e41 * e68)
    )
    e139 = e27 * e42 * e44 - e37 * e43 - e92
    e140 = e0 * e67 + e18 * e52 + e20 * e61
    e141 = e45 * e86
    e142 = e45 * e97
    e143 = e104 * e45
    e144 = e21 * e48
    e145 = -e19
    e146 = e144 - e145 * e43
    e147 = e0 * e127 - e128 * e21 + e19 * e38 * e44
    out[:, :] = 0.0
    out[0, 0] = -e0 * e13 * e14 + e22 * e23
    out[0, 1] = (
        -e14 * (e10 * e28 + e12 * e29 + e25) + e16 * e24 + e16 * e31
        + e23 * (e16 * e32 - e16 * e5 + e17 * e35 - e26 * e34 - e28 * e36 + e29 * e33)
    )
    out[1, 0] = e1 * e13 * e16 * r_R - e23 * (e10 * e27 + e12 * e37 - e25)
    out[1, 1] = (
        e0 * e24 + e0 * e31 + e14 * e22
        - e23 * (-e0 * e32 + e0 * e5 + e18 * e34 - e19 * e36 - e20 * e35 + e21 * e33)
    )
    out[2, 0] = e45 * e87 + e66 * e73
    out[2, 1] = (
        -e105 * e96 + e110 * e111
        + e73
          * (
                e100 * e107 + e103 * e109 + e106 * e94 + e51 * e88
                + e60 * (e112 * e17 + e16 * e81 - e26 * e57 * e6)
                + e65 * (-e112 * e26 + e16 * e6 * e63 * e8 - e16 * e76)
            )
         + e87 * e88 + e91 * e95 + e96 * e98
    )
    out[2, 2] = (
        -e105 * e117 + e111 * e122 + e114 * e87 + e116 * e95 + e117 * e98
        + e73
          * (
                e100 * e120 + e103 * e121 + e114 * e51 + e119 * e94 + e60 * (e123 + e29 * e57)
                + e65 * (e102 + e27 * e63)
            )
    )
    out[2, 4] = (
        -e105 * e131 + e111 * e138 + e126 * e95 + e129 * e87 + e131 * e98
        + e73
          * (
                e100 * e135 + e103 * e137 + e129 * e51 + e132 * e94
                + e60 * (e113 * e41 + e136 * e28 - e44 * e92)
                + e65 * (e134 * e29 + e41 * e92 + e41 * e93)
            )
    )
    out[3, 0] = (
        -e139 * e87
        - e73 * (e139 * e51 + e60 * (e101 + e27 * e57 + e37 * e54) + e65 * (e123 + e37 * e63 - e99))
    )
    out[3, 1] = (
        -e110 * e143 - e140 * e87 - e141 * e91 - e142 * e96 + 0.5 * e66 * e69 * e74 * e96 * r_F
        - e73
          * (
                e106 * e45 + e107 * e64 + e109 * e58 + e140 * e51
                + e60 * (e0 * e57 * e6 * e7 - e0 * e81 - e112 * e20)
                + e65 * (e0 * e76 + e112 * e18 - e20 * e6 * e63)
            )
    )
    out[3, 2] = (
        -e116 * e141 - e117 * e142 + 0.5 * e117 * e66 * e69 * e74 * r_F - e122 * e143 - e146 * e87
        - e73
          * (
                e119 * e45 + e120 * e64 + e121 * e58 + e146 * e51 + e60 * (e145 * e54 + e21 * e57)
                + e65 * (e145 * e63 + e55)
            )
    )
    out[3, 4] = (
        -e126 * e141 - e131 * e142 + 0.5 * e131 * e66 * e69 * e74 * r_F - e138 * e143 - e147 * e87
        - e73
          * (
                e132 * e45 + e135 * e64 + e137 * e58 + e147 * e51
                + e60 * (e136 * e19 + e144 * e41 + e40 * e44)
                + e65 * (e134 * e21 + e19 * e41 * e48 - e40 * e41)
            )
    )


@njit(cache=True)
def h_v(t, q, v, p, out):
    psi, phi, theta, delta = q[0], q[1], q[2], q[4]
    lam, r_R, r_F = p[2], p[3], p[4]
    e0 = simdmath.cos(psi)
    e1 = e0 * r_R
    e2 = simdmath.sin(phi)
    e3 = (e2 * e2)
    e4 = simdmath.sin(theta)
    e5 = simdmath.cos(phi)
    e6 = (e5 * e5)
    e7 = simdmath.cos(theta)
    e8 = e3 + (e4 * e4) * e6 + e6 * (e7 * e7)
    e9 = e2 * e5
    e10 = simdmath.sin(psi)
    e11 = e10 * e7
    e12 = e0 * e4
    e13 = e11 + e12 * e2
    e14 = e4 * e5
    e15 = -e0 * e2 * e7 + e10 * e4
    e16 = e5 * e7
    e17 = e5 * r_R
    e18 = e1 * e3 + e1 * e6
    e19 = e0 * e7 - e10 * e2 * e4
    e20 = e11 * e2 + e12
    e21 = e10 * r_R
    e22 = e21 * e3 + e21 * e6
    e23 = simdmath.cos(delta)
    e24 = simdmath.sin(lam)
    e25 = simdmath.sin(delta)
    e26 = e24 * e25
    e27 = simdmath.cos(lam)
    e28 = e25 * e27
    e29 = e14 * e28 + e16 * e26 + e2 * e23
    e30 = (e29 * e29)
    e31 = e2 * e25
    e32 = 1.0 - e23
    e33 = e24 * e27 * e32
    e34 = (e24 * e24) * e32
    e35 = e23 + e34
    e36 = -e14 * e35 + e16 * e33 + e27 * e31
    e37 = (e27 * e27) * e32
    e38 = e23 + e37
    e39 = -e14 * e33 - e24 * e31 + e38 * e5 * e7
    e40 = e30 + (e36 * e36) + (e39 * e39)
    e41 = e23 * e5
    e42 = e0 * e41 - e13 * e28 + e15 * e26
    e43 = e29 * e42
    e44 = math.sqrt(1.0 - e30)
    e45 = r_F / e44
    e46 = e43 * e45
    e47 = e0 * e5
    e48 = e13 * e35 + e15 * e33 + e28 * e47
    e49 = e13 * e33 + e15 * e38 - e26 * e47
    e50 = e44 * r_F
    e51 = e26 * e4 - e28 * e7
    e52 = e33 * e4 + e35 * e7
    e53 = e33 * e7 + e38 * e4
    e54 = e29 * e51 + e36 * e52 + e39 * e53
    e55 = e23 * e29 - e26 * e39 + e28 * e36
    e56 = e24 * e35 + e24 * e37
    e57 = e27 * e34 + e27 * e38
    e58 = e36 * e56 + e39 * e57
    e59 = e30 * e45
    e60 = -e10 * e41 - e19 * e28 + e20 * e24 * e25
    e61 = e29 * e60
    e62 = e45 * e61
    e63 = e10 * e5
    e64 = e19 * e33 + e20 * e38 + e26 * e63
    e65 = e19 * e35 + e20 * e33 - e28 * e63
    out[:, :] = 0.0
    out[0, 0] = e1 * e2 * e8 + e17 * (e0 * e9 - e13 * e14 + e15 * e16)
    out[0, 1] = e17 * (e13 * e7 + e15 * e4)
    out[0, 2] = e18
    out[0, 3] = e18
    out[0, 6] = 1.0
    out[1, 0] = e10 * e2 * e8 * r_R - e17 * (-e10 * e9 - e14 * e19 + e20 * e5 * e7)
    out[1, 1] = -e17 * (e19 * e7 + e20 * e4)
    out[1, 2] = e22
    out[1, 3] = e22
    out[1, 7] = 1.0
    out[2, 0] = e40 * e46 + e50 * (e36 * e48 + e39 * e49 + e43)
    out[2, 1] = e46 * e54 + e50 * (e42 * e51 + e48 * e52 + e49 * e53)
    out[2, 2] = e46 * e55 + e50 * (e23 * e42 - e26 * e49 + e28 * e48)
    out[2, 4] = e46 * e58 + e50 * (e48 * e56 + e49 * e57)
    out[2, 5] = e42 * e50 + e42 * e59
    out[2, 9] = 1.0
    out[3, 0] = -e40 * e62 - e50 * (e36 * e65 + e39 * e64 + e61)
    out[3, 1] = -e50 * (e51 * e60 + e52 * e65 + e53 * e64) - e54 * e62
    out[3, 2] = -e50 * (e23 * e60 - e26 * e64 + e28 * e65) - e55 * e62
    out[3, 4] = -e50 * (e56 * e65 + e57 * e64) - e58 * e62
    out[3, 5] = -e50 * e60 - e59 * e60
    out[3, 10] = 1.0


@njit(cache=True)
def energy(t, q, v, p):
    # Jacobi integral vᵀ ∂L/∂v − L
    psi, phi, theta, delta, z_r, z_f = q[0], q[1], q[2], q[4], q[8], q[11]
    psi_dot = v[0]
    phi_dot = v[1]
    theta_dot = v[2]
    theta_R_dot = v[3]
    delta_dot = v[4]
    theta_F_dot = v[5]
    x_r_dot = v[6]
    y_r_dot = v[7]
    z_r_dot = v[8]
    x_f_dot = v[9]
    y_f_dot = v[10]
    z_f_dot = v[11]
    w = p[0]
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
    e6 = (x_f_dot * x_f_dot)
    e7 = (y_f_dot * y_f_dot)
    e8 = (z_f_dot * z_f_dot)
    e9 = 0.5 * m_F
    e10 = (x_r_dot * x_r_dot)
    e11 = (y_r_dot * y_r_dot)
    e12 = (z_r_dot * z_r_dot)
    e13 = 0.5 * m_R
    e14 = 2.0 * e1 + 2.0 * theta_dot
    e15 = simdmath.sin(theta)
    e16 = e15 * phi_dot
    e17 = simdmath.cos(theta)
    e18 = simdmath.cos(phi)
    e19 = e18 * psi_dot
    e20 = e17 * e19
    e21 = e16 + e20
    e22 = e17 * phi_dot
    e23 = e15 * e19
    e24 = e22 - e23
    e25 = 0.5 * I_Rxx
    e26 = simdmath.cos(delta)
    e27 = e2 * e26
    e28 = simdmath.sin(delta)
    e29 = simdmath.cos(lam)
    e30 = delta_dot * e29 + e21
    e31 = simdmath.sin(lam)
    e32 = e30 * e31
    e33 = e28 * e32
    e34 = delta_dot * e31 + e24
    e35 = e29 * e34
    e36 = e28 * e35
    e37 = e27 + e33 - e36
    e38 = 0.5 * I_Hyy
    e39 = e37 + theta_F_dot
    e40 = 0.5 * I_Fyy
    e41 = 2.0 * e27 + 2.0 * e33 - 2.0 * e36
    e42 = e15 * e18
    e43 = r_R + z_B
    e44 = e17 * e18
    e45 = r_F + z_H
    e46 = e0 * e28
    e47 = e31 * e46
    e48 = 1.0 - e26
    e49 = e31 * e48
    e50 = e29 * e49
    e51 = e42 * e50
    e52 = (e29 * e29)
    e53 = e26 + e48 * e52
    e54 = -w + x_H
    e55 = e29 * e46
    e56 = e44 * e50
    e57 = (e31 * e31)
    e58 = e26 + e48 * e57
    e59 = e2 * e28
    e60 = e29 * e59
    e61 = e29 * e32 * e48
    e62 = e34 * e58
    e63 = e60 + e61 + e62
    e64 = e31 * e59
    e65 = e35 * e49
    e66 = e30 * e53
    e67 = -e64 + e65 + e66
    e68 = 0.5 * I_Fxx
    e69 = e0 * e15
    e70 = e0 * e17
    e71 = phi_dot * (-e43 * e70 + e69 * x_B)
    e72 = theta_dot * (-e42 * e43 - e44 * x_B)
    e73 = e71 + e72 + z_r_dot
    e74 = simdmath.cos(psi)
    e75 = e15 * e74
    e76 = e18 * x_B
    e77 = e17 * e74
    e78 = phi_dot * (-e18 * e43 * e77 + e75 * e76)
    e79 = simdmath.sin(psi)
    e80 = e15 * e79
    e81 = -e0 * e80 + e17 * e74
    e82 = e17 * e79
    e83 = e0 * e82 + e75
    e84 = psi_dot * (e43 * e83 + e81 * x_B)
    e85 = e0 * e77 - e80
    e86 = e0 * e75 + e82
    e87 = theta_dot * (e43 * e86 + e85 * x_B)
    e88 = e78 + e84 + e87 + y_r_dot
    e89 = phi_dot * (e17 * e18 * e43 * e79 - e76 * e80)
    e90 = -e86
    e91 = psi_dot * (e43 * e85 + e90 * x_B)
    e92 = -e83
    e93 = theta_dot * (e43 * e81 + e92 * x_B)
    e94 = e89 + e91 + e93 + x_r_dot
    e95 = 0.5 * m_B
    e96 = theta_dot * (e45 * (-e42 * e53 - e56) + e54 * (-e44 * e58 - e51))
    e97 = e0 * e26
    e98 = e28 * e31
    e99 = e29 * e98
    e100 = -e28
    e101 = e100 + e28 * e52
    e102 = e100 + e28 * e57
    e103 = (
        delta_dot
        * (
              e45 * (e101 * e17 * e18 - e31 * e97 - e42 * e99)
              + e54 * (-e102 * e42 + e29 * e97 + e44 * e99)
          )
    )
    e104 = e18 * e28
    e105 = e104 * e31
    e106 = e104 * e29
    e107 = (
        phi_dot
        * (
              e45 * (e0 * e15 * e29 * e31 * e48 - e105 - e53 * e70)
              + e54 * (e106 - e50 * e70 + e58 * e69)
          )
    )
    e108 = e103 + e107 + e96 + z_f_dot
    e109 = e18 * e50
    e110 = (
        phi_dot
        * (
              e45 * (e109 * e75 - e18 * e53 * e77 + e47 * e74)
              + e54 * (-e109 * e77 + e15 * e18 * e58 * e74 - e55 * e74)
          )
    )
    e111 = e50 * e85
    e112 = theta_dot * (e45 * (e111 + e53 * e86) + e54 * (e50 * e86 + e58 * e85))
    e113 = e18 * e26
    e114 = e113 * e74
    e115 = -e85
    e116 = (
        delta_dot
        * (
              e45 * (e101 * e115 - e114 * e31 + e86 * e99)
              + e54 * (e102 * e86 + e114 * e29 + e115 * e99)
          )
    )
    e117 = e29 * e81
    e118 = e117 * e49
    e119 = (
        psi_dot
        * (e45 * (e105 * e79 + e118 + e53 * e83) + e54 * (-e106 * e79 + e50 * e83 + e58 * e81))
    )
    e120 = e110 + e112 + e116 + e119 + y_f_dot
    e121 = (
        phi_dot
        * (
              e45 * (-e109 * e80 + e17 * e18 * e53 * e79 - e47 * e79)
              + e54 * (e109 * e82 - e18 * e58 * e80 + e55 * e79)
          )
    )
    e122 = theta_dot * (e45 * (e50 * e92 + e53 * e81) + e54 * (e118 + e58 * e92))
    e123 = e113 * e79
    e124 = (
        delta_dot
        * (
              e45 * (e101 * e83 + e117 * e98 + e123 * e31)
              + e54 * (e102 * e81 - e123 * e29 + e83 * e99)
          )
    )
    e125 = (
        psi_dot
        * (e45 * (e105 * e74 + e50 * e90 + e53 * e85) + e54 * (-e106 * e74 + e111 + e58 * e90))
    )
    e126 = e121 + e122 + e124 + e125 + x_f_dot
    e127 = 0.5 * m_H
    return (
        -e127 * ((e108 * e108) + (e120 * e120) + (e126 * e126))
        + e127
          * (
                e108 * (2.0 * e103 + 2.0 * e107 + 2.0 * e96 + 2.0 * z_f_dot)
                + e120 * (2.0 * e110 + 2.0 * e112 + 2.0 * e116 + 2.0 * e119 + 2.0 * y_f_dot)
                + e126 * (2.0 * e121 + 2.0 * e122 + 2.0 * e124 + 2.0 * e125 + 2.0 * x_f_dot)
            )
         - e13 * (e10 + e11 + e12) + e13 * (2.0 * e10 + 2.0 * e11 + 2.0 * e12) + e14 * e2 * e3
        - (e2 * e2) * e3 + 0.5 * e21 * (I_Bxz * e24 + I_Bzz * e21)
        + 0.5 * e24 * (I_Bxx * e24 + I_Bxz * e21) - e25 * ((e21 * e21) + (e24 * e24))
        + e25 * (e21 * (2.0 * e16 + 2.0 * e20) + e24 * (2.0 * e22 - 2.0 * e23)) - (e37 * e37) * e38
        + e37 * e38 * e41 - (e39 * e39) * e40 + e39 * e40 * (e41 + 2.0 * theta_F_dot)
        - (e4 * e4) * e5 + e4 * e5 * (e14 + 2.0 * theta_R_dot)
        + 0.5 * e63 * (I_Hxx * e63 + I_Hxz * e67) + 0.5 * e67 * (I_Hxz * e63 + I_Hzz * e67)
        - e68 * ((e63 * e63) + (e67 * e67))
        + e68
          * (e63 * (2.0 * e60 + 2.0 * e61 + 2.0 * e62) + e67 * (-2.0 * e64 + 2.0 * e65 + 2.0 * e66))
         - e9 * (e6 + e7 + e8) + e9 * (2.0 * e6 + 2.0 * e7 + 2.0 * e8)
        - e95 * ((e73 * e73) + (e88 * e88) + (e94 * e94))
        + e95
          * (
                e73 * (2.0 * e71 + 2.0 * e72 + 2.0 * z_r_dot)
                + e88 * (2.0 * e78 + 2.0 * e84 + 2.0 * e87 + 2.0 * y_r_dot)
                + e94 * (2.0 * e89 + 2.0 * e91 + 2.0 * e93 + 2.0 * x_r_dot)
            )
         - g
        * (
              m_B * (-e42 * x_B + e43 * e44 + z_r) + m_F * z_f
              + m_H * (e45 * (e17 * e18 * e53 - e47 - e51) + e54 * (-e42 * e58 + e55 + e56) + z_f)
              + m_R * z_r
          )
    )


def reference_state(p):
    w, r_R, r_F, speed = p[0], p[3], p[4], p[26]
    return np.array(
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -r_R, w, 0.0, -r_F, 0.0, 0.0, 0.0, -speed / r_R,
         0.0, -speed / r_F, speed, 0.0, 0.0, speed, 0.0, 0.0],
        dtype=np.float64,
    )


model = stabdae.Model(
    "bicycle_redundant",
    n=12,
    m=5,
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
    coordinates=["psi", "phi", "theta", "theta_R", "delta", "theta_F", "x_r", "y_r", "z_r", "x_f", "y_f", "z_f"],
    coordinate_units=["rad", "rad", "rad", "rad", "rad", "rad", "m", "m", "m", "m", "m", "m"],
    constraint_units=["m", "m", "m", "m", "m", "m s-1", "m s-1", "m s-1", "m s-1"],
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
