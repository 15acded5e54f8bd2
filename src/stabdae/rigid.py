"""Rigid bodies: orientation as a unit quaternion, velocities in the body frame.

A body's orientation is a quaternion ``p = (p0, p1, p2, p3)`` (scalar first) with the
holonomic constraint ``|p|² = 1``; its velocity is its angular velocity ω in the body
frame, a quasi-velocity: ``ṗ = ½ p ⊗ (0, ω)``.  That map is 4 × 3 and preserves ``|p|``
exactly, so the norm's derivative ``ḟ = 2 pᵀṗ`` would vanish identically and no law could
act on a drifting norm.  Here the body has four velocities ``(w, ω)`` instead::

    ṗ = ½ p ⊗ (w, ω) = ½ L(p) (w, ω),      L(p) = | p0 −p1 −p2 −p3 |
                                                   | p1  p0 −p3  p2 |
                                                   | p2  p3  p0 −p1 |
                                                   | p3 −p2  p1  p0 |

``w`` is the norm's rate (``d|p|²/dt = |p|² w``); the constraint ``f = |p|² − 1`` has the
row ``f_q T = (|p|², 0, 0, 0)``, ``ḟ = |p|² w`` and ``f_accel = |p|² w²``, so its
multiplier acts on ``w`` alone and the law ``ġ = Ã g`` drives ``(f, ḟ)`` to zero like any
other constraint's (the norm is never renormalized by hand: that would hide the drift a
study measures).  ``w`` takes any positive inertia in the mass matrix (its value changes
the multiplier, not the motion); the body's ω block is its inertia in the body frame, and
the gyroscopic terms ``ω × Iω`` go into ``forces``.  Orientation is ``p/|p|``
(:func:`rotation`), so the rotational motion is a rigid body's off the manifold too.

The functions are ``@njit`` helpers to call from a model's own functions (``kinematics``,
``f``, ``f_q``, ``f_accel``, ``forces``, ``energy``); ``kernels/heavy_top.py`` and
``kernels/free_body.py`` are models built on them.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# the compiled floor first: it installs the library's checked on-disk caches, whose format
# this module's cached functions must be written in whichever module imports them first
from . import engine  # noqa: F401

__all__ = [
    "angular_momentum", "norm", "norm_accel", "norm_row", "quaternion_about",
    "quaternion_map", "rotation", "rotations", "vertical",
]


@njit(cache=True)
def quaternion_map(q, i, out):
    """Write ``½ L(p)`` for ``p = q[i:i+4]`` into ``out[i:i+4, i:i+4]``: the block of the
    kinematic map ``ṗ = ½ p ⊗ (w, ω)`` over the velocities ``v[i:i+4] = (w, ω)``."""
    p0, p1, p2, p3 = 0.5 * q[i], 0.5 * q[i + 1], 0.5 * q[i + 2], 0.5 * q[i + 3]
    out[i, i], out[i, i + 1], out[i, i + 2], out[i, i + 3] = p0, -p1, -p2, -p3
    out[i + 1, i], out[i + 1, i + 1], out[i + 1, i + 2], out[i + 1, i + 3] = p1, p0, -p3, p2
    out[i + 2, i], out[i + 2, i + 1], out[i + 2, i + 2], out[i + 2, i + 3] = p2, p3, p0, -p1
    out[i + 3, i], out[i + 3, i + 1], out[i + 3, i + 2], out[i + 3, i + 3] = p3, -p2, p1, p0


@njit(cache=True)
def norm(q, i):
    """The norm constraint ``|p|² − 1`` of ``p = q[i:i+4]``."""
    return q[i] * q[i] + q[i + 1] * q[i + 1] + q[i + 2] * q[i + 2] + q[i + 3] * q[i + 3] - 1.0


@njit(cache=True)
def norm_row(q, i, out, row):
    """``∂(|p|² − 1)/∂q`` into row ``row`` of ``out`` (the quaternion's columns; the
    caller writes the others)."""
    for c in range(4):
        out[row, i + c] = 2.0 * q[i + c]


@njit(cache=True)
def norm_accel(q, v, i):
    """``f_accel`` of the norm constraint: ``(d/dt (f_q T)) v = |p|² w²`` with ``w = v[i]``."""
    return (norm(q, i) + 1.0) * v[i] * v[i]


@njit(cache=True)
def rotation(q, i, R):
    """The rotation matrix (body to world) of the orientation ``p/|p|``, ``p = q[i:i+4]``,
    into the 3 × 3 ``R``."""
    p0, p1, p2, p3 = q[i], q[i + 1], q[i + 2], q[i + 3]
    s = 1.0 / (p0 * p0 + p1 * p1 + p2 * p2 + p3 * p3)
    R[0, 0] = (p0 * p0 + p1 * p1 - p2 * p2 - p3 * p3) * s
    R[0, 1] = 2.0 * (p1 * p2 - p0 * p3) * s
    R[0, 2] = 2.0 * (p1 * p3 + p0 * p2) * s
    R[1, 0] = 2.0 * (p1 * p2 + p0 * p3) * s
    R[1, 1] = (p0 * p0 - p1 * p1 + p2 * p2 - p3 * p3) * s
    R[1, 2] = 2.0 * (p2 * p3 - p0 * p1) * s
    R[2, 0] = 2.0 * (p1 * p3 - p0 * p2) * s
    R[2, 1] = 2.0 * (p2 * p3 + p0 * p1) * s
    R[2, 2] = (p0 * p0 - p1 * p1 - p2 * p2 + p3 * p3) * s


@njit(cache=True)
def vertical(q, i):
    """The world's ``e_z`` in the body frame, ``Rᵀ e_z = (R₂₀, R₂₁, R₂₂)``, of the
    orientation ``p/|p|`` (a tuple: what a gravity torque needs, without an array)."""
    p0, p1, p2, p3 = q[i], q[i + 1], q[i + 2], q[i + 3]
    s = 1.0 / (p0 * p0 + p1 * p1 + p2 * p2 + p3 * p3)
    return (2.0 * (p1 * p3 - p0 * p2) * s, 2.0 * (p2 * p3 + p0 * p1) * s,
            (p0 * p0 - p1 * p1 - p2 * p2 + p3 * p3) * s)


def quaternion_about(axis, angle: float) -> np.ndarray:
    """The unit quaternion of a rotation by ``angle`` about ``axis`` (world = body at 0)."""
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    return np.concatenate([[np.cos(0.5 * angle)], np.sin(0.5 * angle) * a])


def rotations(x, i: int = 0) -> np.ndarray:
    """The rotation matrices (body to world) of the orientations ``p/|p|`` of states ``x``
    (shape (2n,) or (..., 2n)), the quaternion at ``q[i:i+4]``: shape (..., 3, 3).
    Python-side, for analysis (SciPy's rotations; in a model's functions
    :func:`rotation`)."""
    from scipy.spatial.transform import Rotation

    X = np.asarray(x, dtype=np.float64)
    p = X[..., i : i + 4].reshape(-1, 4)
    R = Rotation.from_quat(p[:, [1, 2, 3, 0]]).as_matrix()  # SciPy's scalar last
    return R.reshape(X.shape[:-1] + (3, 3))


def angular_momentum(x, inertia, i: int = 0) -> np.ndarray:
    """The angular momentum in the world frame, ``R(p) I ω``, of states ``x`` (shape
    (2n,) or (..., 2n)) with the quaternion at ``q[i:i+4]`` and ``(w, ω)`` at
    ``v[i:i+4]``; ``inertia`` the 3 × 3 body-frame inertia (about the point the
    momentum is taken about)."""
    X = np.asarray(x, dtype=np.float64)
    n = X.shape[-1] // 2
    w = X[..., n + i + 1 : n + i + 4]
    inertia = np.asarray(inertia, dtype=np.float64)
    return np.einsum("...ij,jk,...k->...i", rotations(X, i), inertia, w)
