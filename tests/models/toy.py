"""A unit pendulum written inline, for tests that break one of its pieces.

(The scene `kernels/pendulum.py` reads g and l from p; this one hard-codes them so that a
test can swap a single function without touching parameters.)
"""

from __future__ import annotations

import numpy as np
from numba import njit

import stabdae


@njit
def forces(t, q, v, p, out):
    out[0] = 0.0
    out[1] = 9.81


@njit
def f(t, q, p, out):
    out[0] = q[0] * q[0] + q[1] * q[1] - 1.0


@njit
def f_q(t, q, p, out):
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]


@njit
def f_accel(t, q, v, p, out):
    out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1])


X_REF = np.array([0.0, -1.0, 1.0, 0.0])


def unit_pendulum(name: str = "toy", **overrides) -> stabdae.Model:
    """The unit pendulum with any piece or argument replaced."""
    kwargs = dict(n=2, m=1, reference_state=X_REF, forces=forces, f=f, f_q=f_q, f_accel=f_accel)
    kwargs.update(overrides)
    return stabdae.Model(name, **kwargs)
