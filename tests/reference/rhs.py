"""The stabilized right-hand side (3.1), (3.11) in plain NumPy, from docs/theory.md:

    γ = forces,  F = [f_q; h_v],  c = (f_accel; h_q v + h_t),  g = (f, f_q v + f_t, h)
    Y = M⁻¹Fᵀ,  z = M⁻¹γ,  S = F Y,  s = c − F z
    S λ = A g − s,   v̇ = Y λ − z,   q̇ = v

and with a kinematic map ``q̇ = T v``: ``F = [f_q T; h_v]``, ``c = (f_accel; h_q T v +
h_t)``, ``g = (f, f_q T v + f_t, h)`` and ``q̇ = T v`` (T the identity without one).

with ``A`` the law's r × (m + r) matrix, the last r rows of ``Ã``.  Dense solves, no
structure: a different computation of the same numbers."""

from __future__ import annotations

import numpy as np


def stabilized_rhs(model, law, t: float, x: np.ndarray, p=None) -> np.ndarray:
    """``ẋ = (v, v̇)`` of ``model`` under ``law`` at ``(t, x)``."""
    p = model.default_params() if p is None else np.asarray(p, float)
    n, m = model.n, model.m
    v = x[n:]
    ev = lambda piece: model.evaluate(piece, t, x, p)  # noqa: E731
    M = ev("mass")
    gamma = ev("forces")
    T = ev("kinematics")  # the identity without a kinematic map
    qdot = T @ v
    F = np.vstack([ev("f_q") @ T, ev("h_v")])
    c = np.concatenate([ev("f_accel"), ev("h_q") @ qdot + ev("h_t")])
    g = np.concatenate([ev("f"), ev("f_q") @ qdot + ev("f_t"), ev("h")])
    A = law.A_tilde(model, x, t, p)[m:, :]
    Y = np.linalg.solve(M, F.T)
    z = np.linalg.solve(M, gamma)
    S = F @ Y
    s = c - F @ z
    lam = np.linalg.solve(S, A @ g - s)
    return np.concatenate([qdot, Y @ lam - z])
