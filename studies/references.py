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
