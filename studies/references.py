"""Published reference solutions used by the hard-case tests and studies/work_precision.

The Test Set for IVP Solvers (F. Mazzia, C. Magherini et al., University of Bari;
https://archimede.uniba.it/~testset/), problems "andrews" (reference at t = 0.03 computed
with PSIDE at tolerance 1e-14; Ex_andrews.f, subroutine solut) and "caraxis" (t = 3;
Ex_car.f).  Only the entries stabdae's state has are kept: Andrews' seven positions
(the Test Set's y(1..7)), the car axis' four positions and four velocities.
"""

import numpy as np

#: Test Set reference positions of Andrews' mechanism at t = 0.03 (y(1..7) of andsoln)
ANDREWS_T003 = np.array([
    0.1581077119629904e2, -0.1575637105984298e2, 0.4082224013073101e-1,
    -0.5347301163226948e0, 0.5244099658805304e0, 0.5347301163226948e0,
    0.1048080741042263e1,
])  # fmt: skip
#: the rest of andsoln at t = 0.03: velocities y(8..14), accelerations y(15..21) and the
#: multipliers y(22..27).  The Test Set writes M q'' = f(q, q') - G^T lambda; stabdae writes
#: M v' = F^T lambda - gamma with gamma = -f, so its lambda is minus these.
#: The accelerations and multipliers agree with the ones the index-1 equations give at the
#: published (q, q') to about 6 significant digits only (the positions have 9.6 in common
#: with an accurate integration): compare them to that level.
ANDREWS_T003_VELOCITY = np.array([
    0.1139920302151208e4, -0.1424379294994111e4, 0.1103291221937134e2,
    0.1929337464421385e2, 0.5735699284790808e0, -0.1929337464421385e2,
    0.3231791658026955e0,
])  # fmt: skip
ANDREWS_T003_ACCELERATION = np.array([
    -0.2463176316945196e5, 0.5185037701610329e5, 0.3241025686413781e6,
    0.5667493645176213e6, 0.1674362929479361e5, -0.5667493645176222e6,
    0.9826520791458422e4,
])  # fmt: skip
ANDREWS_T003_LAMBDA = np.array([
    0.1991753333731910e3, -0.2975531228015052e2, 0.2306654119098399e2,
    0.3145271365475927e2, 0.2264249232082739e2, 0.1161740700019673e2,
])  # fmt: skip
#: Test Set reference of the car axis at t = 3: positions, then velocities (carsoln)
CAR_AXIS_T3 = np.array([
    0.4934557842755629e-1, 0.4969894602303324e0, 0.1041742524885400e1,
    0.3739110272652214e0, -0.7705836840321485e-1, 0.7446866596327776e-2,
    0.1755681574942899e-1, 0.7703410437794031e0,
])  # fmt: skip


def digits(x, ref) -> float:
    """Significant correct digits, the Test Set's scd: −log10 of the largest relative
    error over the components."""
    return float(-np.log10(np.max(np.abs(np.asarray(x) - ref) / np.abs(ref))))
