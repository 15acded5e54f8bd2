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

    L = -K*(-l0 + sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 +
        (a*cos(psi)/2 - e*cos(psi) + x1/2)**2))**2/2 - K*(-l0 + sqrt((h/2 - s + z2/2)**2 +
        (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2))**2/2 -
        g*m_ball*z1 - g*m_ball*z2 - g*m_rod*(h + z1)/2 - g*m_rod*(h + z2)/2 - g*m_slider*s +
        m_ball*(x1_dot**2 + y1_dot**2 + z1_dot**2)/2 + m_ball*(x2_dot**2 + y2_dot**2 +
        z2_dot**2)/2 + m_rod*(a**2*psi_dot**2*sin(psi)**2 + a**2*psi_dot**2*cos(psi)**2 -
        a*psi_dot*x1_dot*sin(psi) + a*psi_dot*y1_dot*cos(psi) + x1_dot**2 + y1_dot**2 +
        z1_dot**2)/6 + m_rod*(a**2*psi_dot**2*sin(psi)**2 + a**2*psi_dot**2*cos(psi)**2 +
        a*psi_dot*x2_dot*sin(psi) - a*psi_dot*y2_dot*cos(psi) + x2_dot**2 + y2_dot**2 +
        z2_dot**2)/6 + m_slider*s_dot**2/2 + psi_dot**2*(J_shaft + J_slider)/2
    f[0] = -L**2 + (-h + z1)**2 + (-a*sin(psi) + y1)**2 + (-a*cos(psi) + x1)**2 = 0
    f[1] = -L**2 + (-h + z2)**2 + (a*sin(psi) + y2)**2 + (a*cos(psi) + x2)**2 = 0
    f[2] = -x1*sin(psi) + y1*cos(psi) = 0
    f[3] = -x2*sin(psi) + y2*cos(psi) = 0
    Q = [-C*((-a*sin(psi) + 2*e*sin(psi))*(a*cos(psi)/2 - e*cos(psi) + x1/2)/2 + (a*cos(psi) -
        2*e*cos(psi))*(a*sin(psi)/2 - e*sin(psi) + y1/2)/2)*(psi_dot*((-a*sin(psi) +
        2*e*sin(psi))*(a*cos(psi)/2 - e*cos(psi) + x1/2)/2 + (a*cos(psi) -
        2*e*cos(psi))*(a*sin(psi)/2 - e*sin(psi) + y1/2)/2)/sqrt((h/2 - s + z1/2)**2 +
        (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) +
        s_dot*(-h/2 + s - z1/2)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2
        + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) + x1_dot*(a*cos(psi)/4 - e*cos(psi)/2 +
        x1/4)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 -
        e*cos(psi) + x1/2)**2) + y1_dot*(a*sin(psi)/4 - e*sin(psi)/2 + y1/4)/sqrt((h/2 - s +
        z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) +
        x1/2)**2) + z1_dot*(h/4 - s/2 + z1/4)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 -
        e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2))/sqrt((h/2 - s + z1/2)**2
        + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) -
        C*((a*sin(psi) - 2*e*sin(psi))*(-a*cos(psi)/2 + e*cos(psi) + x2/2)/2 + (-a*cos(psi) +
        2*e*cos(psi))*(-a*sin(psi)/2 + e*sin(psi) + y2/2)/2)*(psi_dot*((a*sin(psi) -
        2*e*sin(psi))*(-a*cos(psi)/2 + e*cos(psi) + x2/2)/2 + (-a*cos(psi) +
        2*e*cos(psi))*(-a*sin(psi)/2 + e*sin(psi) + y2/2)/2)/sqrt((h/2 - s + z2/2)**2 +
        (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) +
        s_dot*(-h/2 + s - z2/2)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) +
        y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) + x2_dot*(-a*cos(psi)/4 +
        e*cos(psi)/2 + x2/4)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 +
        (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) + y2_dot*(-a*sin(psi)/4 + e*sin(psi)/2 +
        y2/4)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2
        + e*cos(psi) + x2/2)**2) + z2_dot*(h/4 - s/2 + z2/4)/sqrt((h/2 - s + z2/2)**2 +
        (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) +
        x2/2)**2))/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 +
        (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2), -C*(-h/2 + s - z1/2)*(psi_dot*((-a*sin(psi) +
        2*e*sin(psi))*(a*cos(psi)/2 - e*cos(psi) + x1/2)/2 + (a*cos(psi) -
        2*e*cos(psi))*(a*sin(psi)/2 - e*sin(psi) + y1/2)/2)/sqrt((h/2 - s + z1/2)**2 +
        (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) +
        s_dot*(-h/2 + s - z1/2)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2
        + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) + x1_dot*(a*cos(psi)/4 - e*cos(psi)/2 +
        x1/4)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 -
        e*cos(psi) + x1/2)**2) + y1_dot*(a*sin(psi)/4 - e*sin(psi)/2 + y1/4)/sqrt((h/2 - s +
        z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) +
        x1/2)**2) + z1_dot*(h/4 - s/2 + z1/4)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 -
        e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2))/sqrt((h/2 - s + z1/2)**2
        + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) -
        C*(-h/2 + s - z2/2)*(psi_dot*((a*sin(psi) - 2*e*sin(psi))*(-a*cos(psi)/2 + e*cos(psi) +
        x2/2)/2 + (-a*cos(psi) + 2*e*cos(psi))*(-a*sin(psi)/2 + e*sin(psi) + y2/2)/2)/sqrt((h/2
        - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) +
        x2/2)**2) + s_dot*(-h/2 + s - z2/2)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 +
        e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) + x2_dot*(-a*cos(psi)/4
        + e*cos(psi)/2 + x2/4)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2
        + (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) + y2_dot*(-a*sin(psi)/4 + e*sin(psi)/2 +
        y2/4)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2
        + e*cos(psi) + x2/2)**2) + z2_dot*(h/4 - s/2 + z2/4)/sqrt((h/2 - s + z2/2)**2 +
        (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) +
        x2/2)**2))/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 +
        (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2), -C*(a*cos(psi)/4 - e*cos(psi)/2 +
        x1/4)*(psi_dot*((-a*sin(psi) + 2*e*sin(psi))*(a*cos(psi)/2 - e*cos(psi) + x1/2)/2 +
        (a*cos(psi) - 2*e*cos(psi))*(a*sin(psi)/2 - e*sin(psi) + y1/2)/2)/sqrt((h/2 - s +
        z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) +
        x1/2)**2) + s_dot*(-h/2 + s - z1/2)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 -
        e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) + x1_dot*(a*cos(psi)/4 -
        e*cos(psi)/2 + x1/4)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 +
        (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) + y1_dot*(a*sin(psi)/4 - e*sin(psi)/2 +
        y1/4)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 -
        e*cos(psi) + x1/2)**2) + z1_dot*(h/4 - s/2 + z1/4)/sqrt((h/2 - s + z1/2)**2 +
        (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) +
        x1/2)**2))/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 +
        (a*cos(psi)/2 - e*cos(psi) + x1/2)**2), -C*(a*sin(psi)/4 - e*sin(psi)/2 +
        y1/4)*(psi_dot*((-a*sin(psi) + 2*e*sin(psi))*(a*cos(psi)/2 - e*cos(psi) + x1/2)/2 +
        (a*cos(psi) - 2*e*cos(psi))*(a*sin(psi)/2 - e*sin(psi) + y1/2)/2)/sqrt((h/2 - s +
        z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) +
        x1/2)**2) + s_dot*(-h/2 + s - z1/2)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 -
        e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) + x1_dot*(a*cos(psi)/4 -
        e*cos(psi)/2 + x1/4)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 +
        (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) + y1_dot*(a*sin(psi)/4 - e*sin(psi)/2 +
        y1/4)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 -
        e*cos(psi) + x1/2)**2) + z1_dot*(h/4 - s/2 + z1/4)/sqrt((h/2 - s + z1/2)**2 +
        (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) +
        x1/2)**2))/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 +
        (a*cos(psi)/2 - e*cos(psi) + x1/2)**2), -C*(h/4 - s/2 + z1/4)*(psi_dot*((-a*sin(psi) +
        2*e*sin(psi))*(a*cos(psi)/2 - e*cos(psi) + x1/2)/2 + (a*cos(psi) -
        2*e*cos(psi))*(a*sin(psi)/2 - e*sin(psi) + y1/2)/2)/sqrt((h/2 - s + z1/2)**2 +
        (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) +
        s_dot*(-h/2 + s - z1/2)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2
        + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2) + x1_dot*(a*cos(psi)/4 - e*cos(psi)/2 +
        x1/4)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 -
        e*cos(psi) + x1/2)**2) + y1_dot*(a*sin(psi)/4 - e*sin(psi)/2 + y1/4)/sqrt((h/2 - s +
        z1/2)**2 + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) +
        x1/2)**2) + z1_dot*(h/4 - s/2 + z1/4)/sqrt((h/2 - s + z1/2)**2 + (a*sin(psi)/2 -
        e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2))/sqrt((h/2 - s + z1/2)**2
        + (a*sin(psi)/2 - e*sin(psi) + y1/2)**2 + (a*cos(psi)/2 - e*cos(psi) + x1/2)**2),
        -C*(-a*cos(psi)/4 + e*cos(psi)/2 + x2/4)*(psi_dot*((a*sin(psi) -
        2*e*sin(psi))*(-a*cos(psi)/2 + e*cos(psi) + x2/2)/2 + (-a*cos(psi) +
        2*e*cos(psi))*(-a*sin(psi)/2 + e*sin(psi) + y2/2)/2)/sqrt((h/2 - s + z2/2)**2 +
        (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) +
        s_dot*(-h/2 + s - z2/2)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) +
        y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) + x2_dot*(-a*cos(psi)/4 +
        e*cos(psi)/2 + x2/4)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 +
        (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) + y2_dot*(-a*sin(psi)/4 + e*sin(psi)/2 +
        y2/4)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2
        + e*cos(psi) + x2/2)**2) + z2_dot*(h/4 - s/2 + z2/4)/sqrt((h/2 - s + z2/2)**2 +
        (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) +
        x2/2)**2))/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 +
        (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2), -C*(-a*sin(psi)/4 + e*sin(psi)/2 +
        y2/4)*(psi_dot*((a*sin(psi) - 2*e*sin(psi))*(-a*cos(psi)/2 + e*cos(psi) + x2/2)/2 +
        (-a*cos(psi) + 2*e*cos(psi))*(-a*sin(psi)/2 + e*sin(psi) + y2/2)/2)/sqrt((h/2 - s +
        z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) +
        x2/2)**2) + s_dot*(-h/2 + s - z2/2)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 +
        e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) + x2_dot*(-a*cos(psi)/4
        + e*cos(psi)/2 + x2/4)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2
        + (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) + y2_dot*(-a*sin(psi)/4 + e*sin(psi)/2 +
        y2/4)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2
        + e*cos(psi) + x2/2)**2) + z2_dot*(h/4 - s/2 + z2/4)/sqrt((h/2 - s + z2/2)**2 +
        (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) +
        x2/2)**2))/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 +
        (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2), -C*(h/4 - s/2 + z2/4)*(psi_dot*((a*sin(psi) -
        2*e*sin(psi))*(-a*cos(psi)/2 + e*cos(psi) + x2/2)/2 + (-a*cos(psi) +
        2*e*cos(psi))*(-a*sin(psi)/2 + e*sin(psi) + y2/2)/2)/sqrt((h/2 - s + z2/2)**2 +
        (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) +
        s_dot*(-h/2 + s - z2/2)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) +
        y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) + x2_dot*(-a*cos(psi)/4 +
        e*cos(psi)/2 + x2/4)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 +
        (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2) + y2_dot*(-a*sin(psi)/4 + e*sin(psi)/2 +
        y2/4)/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2
        + e*cos(psi) + x2/2)**2) + z2_dot*(h/4 - s/2 + z2/4)/sqrt((h/2 - s + z2/2)**2 +
        (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 + (-a*cos(psi)/2 + e*cos(psi) +
        x2/2)**2))/sqrt((h/2 - s + z2/2)**2 + (-a*sin(psi)/2 + e*sin(psi) + y2/2)**2 +
        (-a*cos(psi)/2 + e*cos(psi) + x2/2)**2)]

Generated by `stabdae generate kernels/specs/flyball_governor.py`
with stabdae 0.1.0 (stabdae.symbolic), sympy 1.14.0.  Spec SHA-256: d2a29acb5e5e752d
Edit the spec and regenerate rather than editing this file.
"""


import math

import numpy as np
from numba import njit

import stabdae
from stabdae import simdmath

# p = [m_rod, m_ball, m_slider, J_shaft, J_slider, g, K, C, l0, L, h, a, e]


@njit(cache=True)
def mass(t, q, p, out):
    # M = ∂²L/∂v²
    psi = q[0]
    m_rod, m_ball, m_slider, J_shaft, J_slider, a = p[0], p[1], p[2], p[3], p[4], p[11]
    e0 = simdmath.sin(psi)
    e1 = 2.0 * (a * a)
    e2 = simdmath.cos(psi)
    e3 = 0.3333333333333333 * m_rod
    e4 = 0.16666666666666666 * a * m_rod
    e5 = e0 * e4
    e6 = e2 * e4
    e7 = e3 + m_ball
    out[:, :] = 0.0
    out[0, 0] = J_shaft + J_slider + e3 * ((e0 * e0) * e1 + e1 * (e2 * e2))
    out[0, 2] = -e5
    out[0, 3] = e6
    out[0, 5] = e5
    out[0, 6] = -e6
    out[1, 1] = m_slider
    out[2, 2] = e7
    out[3, 3] = e7
    out[4, 4] = e7
    out[5, 5] = e7
    out[6, 6] = e7
    out[7, 7] = e7
    out[2, 0] = out[0, 2]
    out[3, 0] = out[0, 3]
    out[5, 0] = out[0, 5]
    out[6, 0] = out[0, 6]


@njit(cache=True)
def forces(t, q, v, p, out):
    # γ = (∂²L/∂v∂q) v + ∂²L/∂v∂t − ∂L/∂q − Q, so that M v̇ = Fᵀλ − γ  (3.3)
    psi, s, x1, y1, z1, x2, y2, z2 = q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7]
    psi_dot = v[0]
    s_dot = v[1]
    x1_dot = v[2]
    y1_dot = v[3]
    z1_dot = v[4]
    x2_dot = v[5]
    y2_dot = v[6]
    z2_dot = v[7]
    m_rod = p[0]
    m_ball = p[1]
    m_slider = p[2]
    g = p[5]
    K = p[6]
    C = p[7]
    l0 = p[8]
    p10_ = p[10]
    a = p[11]
    e = p[12]
    e0 = 0.5 * p10_ - s
    e1 = e0 + 0.5 * z2
    e2 = simdmath.sin(psi)
    e3 = e * e2
    e4 = a * e2
    e5 = 0.5 * e4
    e6 = e3 - e5 + 0.5 * y2
    e7 = simdmath.cos(psi)
    e8 = e * e7
    e9 = a * e7
    e10 = 0.5 * e9
    e11 = -e10 + e8 + 0.5 * x2
    e12 = math.sqrt((e1 * e1) + (e11 * e11) + (e6 * e6))
    e13 = (1.0 / e12)
    e14 = -2.0 * e * e2 + e4
    e15 = -2.0 * e8 + e9
    e16 = e13 * (0.5 * e11 * e14 - 0.5 * e15 * e6)
    e17 = K * (e12 - l0)
    e18 = e0 + 0.5 * z1
    e19 = -e3 + e5 + 0.5 * y1
    e20 = e10 - e8 + 0.5 * x1
    e21 = math.sqrt((e18 * e18) + (e19 * e19) + (e20 * e20))
    e22 = (1.0 / e21)
    e23 = e22 * (-0.5 * e14 * e20 + 0.5 * e15 * e19)
    e24 = K * (e21 - l0)
    e25 = -e1 * e13
    e26 = 0.25 * p10_ - 0.5 * s
    e27 = e13 * (e26 + 0.25 * z2)
    e28 = 0.25 * e9
    e29 = 0.5 * e8
    e30 = e13 * (-e28 + e29 + 0.25 * x2)
    e31 = 0.25 * e4
    e32 = 0.5 * e3
    e33 = e13 * (-e31 + e32 + 0.25 * y2)
    e34 = C * (e16 * psi_dot + e25 * s_dot + e27 * z2_dot + e30 * x2_dot + e33 * y2_dot)
    e35 = -e18 * e22
    e36 = e22 * (e26 + 0.25 * z1)
    e37 = e22 * (e28 - e29 + 0.25 * x1)
    e38 = e22 * (e31 - e32 + 0.25 * y1)
    e39 = C * (e23 * psi_dot + e35 * s_dot + e36 * z1_dot + e37 * x1_dot + e38 * y1_dot)
    e40 = 0.16666666666666666 * m_rod * (psi_dot * psi_dot)
    e41 = e40 * e9
    e42 = e4 * e40
    e43 = g * m_ball + 0.5 * g * m_rod
    out[0] = e16 * e17 + e16 * e34 + e23 * e24 + e23 * e39
    out[1] = e17 * e25 + e24 * e35 + e25 * e34 + e35 * e39 + g * m_slider
    out[2] = e24 * e37 + e37 * e39 - e41
    out[3] = e24 * e38 + e38 * e39 - e42
    out[4] = e24 * e36 + e36 * e39 + e43
    out[5] = e17 * e30 + e30 * e34 + e41
    out[6] = e17 * e33 + e33 * e34 + e42
    out[7] = e17 * e27 + e27 * e34 + e43


@njit(cache=True)
def f(t, q, p, out):
    psi, x1, y1, z1, x2, y2, z2 = q[0], q[2], q[3], q[4], q[5], q[6], q[7]
    L, p10_, a = p[9], p[10], p[11]
    e0 = -(L * L)
    e1 = simdmath.sin(psi)
    e2 = a * e1
    e3 = simdmath.cos(psi)
    e4 = a * e3
    out[0] = (
        e0 + ((-e2 + y1) * (-e2 + y1)) + ((-e4 + x1) * (-e4 + x1)) + ((-p10_ + z1) * (-p10_ + z1))
    )
    out[1] = e0 + ((e2 + y2) * (e2 + y2)) + ((e4 + x2) * (e4 + x2)) + ((-p10_ + z2) * (-p10_ + z2))
    out[2] = -e1 * x1 + e3 * y1
    out[3] = -e1 * x2 + e3 * y2


@njit(cache=True)
def f_q(t, q, p, out):
    psi, x1, y1, z1, x2, y2, z2 = q[0], q[2], q[3], q[4], q[5], q[6], q[7]
    p10_, a = p[10], p[11]
    e0 = simdmath.sin(psi)
    e1 = a * e0
    e2 = simdmath.cos(psi)
    e3 = a * e2
    e4 = 2.0 * e3
    e5 = 2.0 * e1
    e6 = 2.0 * p10_
    e7 = -e0
    out[:, :] = 0.0
    out[0, 0] = 2.0 * a * e0 * (-e3 + x1) - e4 * (-e1 + y1)
    out[0, 2] = -e4 + 2.0 * x1
    out[0, 3] = -e5 + 2.0 * y1
    out[0, 4] = -e6 + 2.0 * z1
    out[1, 0] = e4 * (e1 + y2) - e5 * (e3 + x2)
    out[1, 5] = e4 + 2.0 * x2
    out[1, 6] = e5 + 2.0 * y2
    out[1, 7] = -e6 + 2.0 * z2
    out[2, 0] = -e0 * y1 - e2 * x1
    out[2, 2] = e7
    out[2, 3] = e2
    out[3, 0] = -e0 * y2 - e2 * x2
    out[3, 5] = e7
    out[3, 6] = e2


@njit(cache=True)
def f_accel(t, q, v, p, out):
    # f̈ = f_q v̇ + f_accel:  ∂ḟ/∂q v + ∂ḟ/∂t with ḟ = f_q v + f_t
    psi, x1, y1, x2, y2 = q[0], q[2], q[3], q[5], q[6]
    psi_dot = v[0]
    x1_dot = v[2]
    y1_dot = v[3]
    z1_dot = v[4]
    x2_dot = v[5]
    y2_dot = v[6]
    z2_dot = v[7]
    a = p[11]
    e0 = simdmath.sin(psi)
    e1 = a * e0
    e2 = e1 * psi_dot
    e3 = simdmath.cos(psi)
    e4 = a * e3
    e5 = e4 * psi_dot
    e6 = 2.0 * (psi_dot * psi_dot)
    e7 = e1 * e6
    e8 = e4 * e6
    e9 = 2.0 * e3
    e10 = 2.0 * e0
    e11 = e3 * psi_dot
    out[0] = (
        e7 * (-e1 + y1) + e8 * (-e4 + x1) + 2.0 * (z1_dot * z1_dot)
        + 2.0 * ((e2 + x1_dot) * (e2 + x1_dot)) + 2.0 * ((e5 - y1_dot) * (e5 - y1_dot))
    )
    out[1] = (
        -e7 * (e1 + y2) - e8 * (e4 + x2) + 2.0 * (z2_dot * z2_dot)
        + 2.0 * ((e2 - x2_dot) * (e2 - x2_dot)) + 2.0 * ((e5 + y2_dot) * (e5 + y2_dot))
    )
    out[2] = psi_dot * (e0 * psi_dot * x1 - e10 * y1_dot - e11 * y1 - e9 * x1_dot)
    out[3] = psi_dot * (e0 * psi_dot * x2 - e10 * y2_dot - e11 * y2 - e9 * x2_dot)


@njit(cache=True)
def energy(t, q, v, p):
    # Jacobi integral vᵀ ∂L/∂v − L
    psi, s, x1, y1, z1, x2, y2, z2 = q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7]
    psi_dot = v[0]
    s_dot = v[1]
    x1_dot = v[2]
    y1_dot = v[3]
    z1_dot = v[4]
    x2_dot = v[5]
    y2_dot = v[6]
    z2_dot = v[7]
    m_rod = p[0]
    m_ball = p[1]
    m_slider = p[2]
    J_shaft = p[3]
    J_slider = p[4]
    g = p[5]
    K = p[6]
    l0 = p[8]
    p10_ = p[10]
    a = p[11]
    e = p[12]
    e0 = g * m_ball
    e1 = 0.5 * g * m_rod
    e2 = (psi_dot * psi_dot)
    e3 = (x1_dot * x1_dot)
    e4 = (y1_dot * y1_dot)
    e5 = (z1_dot * z1_dot)
    e6 = e3 + e4 + e5
    e7 = 0.5 * m_ball
    e8 = (x2_dot * x2_dot)
    e9 = (y2_dot * y2_dot)
    e10 = (z2_dot * z2_dot)
    e11 = e10 + e8 + e9
    e12 = 2.0 * e3 + 2.0 * e4 + 2.0 * e5
    e13 = 2.0 * e10 + 2.0 * e8 + 2.0 * e9
    e14 = simdmath.cos(psi)
    e15 = a * psi_dot
    e16 = e14 * e15
    e17 = e16 * y1_dot
    e18 = simdmath.sin(psi)
    e19 = e15 * e18
    e20 = e19 * x1_dot
    e21 = (a * a) * e2
    e22 = (e14 * e14) * e21
    e23 = (e18 * e18) * e21
    e24 = e22 + e23
    e25 = 0.16666666666666666 * m_rod
    e26 = e19 * x2_dot
    e27 = e16 * y2_dot
    e28 = 0.5 * p10_ - s
    e29 = e * e18
    e30 = 0.5 * a
    e31 = e18 * e30
    e32 = e * e14
    e33 = e14 * e30
    e34 = 0.5 * K
    e35 = 2.0 * e22 + 2.0 * e23
    return (
        e0 * z1 + e0 * z2 + e1 * (p10_ + z1) + e1 * (p10_ + z2) - e11 * e7 + e12 * e7 + e13 * e7
        + 0.5 * e2 * (J_shaft + J_slider) - e25 * (e11 + e24 + e26 - e27)
        + e25 * (e12 + 2.0 * e17 - 2.0 * e20 + e35) + e25 * (e13 + 2.0 * e26 - 2.0 * e27 + e35)
        - e25 * (e17 - e20 + e24 + e6)
        + e34
          * (
                (
                    -l0
                    + math.sqrt(
                          ((e28 + 0.5 * z1) * (e28 + 0.5 * z1))
                          + ((-e29 + e31 + 0.5 * y1) * (-e29 + e31 + 0.5 * y1))
                          + ((-e32 + e33 + 0.5 * x1) * (-e32 + e33 + 0.5 * x1))
                      )
                )
                 * (
                    -l0
                    + math.sqrt(
                          ((e28 + 0.5 * z1) * (e28 + 0.5 * z1))
                          + ((-e29 + e31 + 0.5 * y1) * (-e29 + e31 + 0.5 * y1))
                          + ((-e32 + e33 + 0.5 * x1) * (-e32 + e33 + 0.5 * x1))
                      )
                )
            )
         + e34
        * (
              (
                  -l0
                  + math.sqrt(
                        ((e28 + 0.5 * z2) * (e28 + 0.5 * z2))
                        + ((e29 - e31 + 0.5 * y2) * (e29 - e31 + 0.5 * y2))
                        + ((e32 - e33 + 0.5 * x2) * (e32 - e33 + 0.5 * x2))
                    )
              )
               * (
                  -l0
                  + math.sqrt(
                        ((e28 + 0.5 * z2) * (e28 + 0.5 * z2))
                        + ((e29 - e31 + 0.5 * y2) * (e29 - e31 + 0.5 * y2))
                        + ((e32 - e33 + 0.5 * x2) * (e32 - e33 + 0.5 * x2))
                    )
              )
          )
         - e6 * e7 + g * m_slider * s + 0.5 * m_slider * (s_dot * s_dot)
    )


def reference_state(p):
    L, p10_, a = p[9], p[10], p[11]
    return np.array(
        [0.0, 0.5, 0.8660254037844387 * L + a, 0.0, -0.49999999999999994 * L + p10_,
         -0.8660254037844387 * L - a, 0.0, -0.49999999999999994 * L + p10_, 6.283185307179586, 0.0,
         0.0, 5.441398092702654 * L + 6.283185307179586 * a, 0.0, 0.0,
         -5.441398092702654 * L - 6.283185307179586 * a, 0.0],
        dtype=np.float64,
    )


model = stabdae.Model(
    "flyball_governor",
    n=8,
    m=4,
    params={
        "m_rod": 0.3,
        "m_ball": 5.0,
        "m_slider": 3.0,
        "J_shaft": 5e-06,
        "J_slider": 0.005,
        "g": 9.81,
        "K": 800000.0,
        "C": 40000.0,
        "l0": 0.5,
        "L": 1.0,
        "h": 1.0,
        "a": 0.05,
        "e": 0.05,
    },
    reference_state=reference_state,
    coordinates=["psi", "s", "x1", "y1", "z1", "x2", "y2", "z2"],
    coordinate_units=["rad", "m", "m", "m", "m", "m", "m", "m"],
    constraint_units=["m2", "m2", "m", "m"],
    energy_units="J",
    mass=mass,
    forces=forces,
    f=f,
    f_q=f_q,
    f_accel=f_accel,
    energy=energy,
    description=__doc__,
)
