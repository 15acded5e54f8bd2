"""The per-member measurement record: its columns, the reasons a member has no β
and the kinds of fit, by name and code."""

from __future__ import annotations

#: columns of the per-member measurement array (``measures``)
COLUMNS = ("beta", "gamma", "floor", "initial", "largest", "final", "w0", "w1", "w2", "w3",
           "w4", "fit_start", "fit_end", "fit_points", "reason", "fit_kind", "shift",
           "floor_reached", "beta_predicted", "d2", "d3", "d4")  # fmt: skip
(C_BETA, C_GAMMA, C_FLOOR, C_INITIAL, C_LARGEST, C_FINAL, C_W0, C_W1, C_W2, C_W3, C_W4,
 C_FIT_START, C_FIT_END, C_POINTS, C_REASON, C_KIND, C_SHIFT, C_FLOOR_REACHED,
 C_BETA_PRED, C_D2, C_D3, C_D4) = range(len(COLUMNS))  # fmt: skip
NCOLS = len(COLUMNS)

#: reason codes of ``beta_reason``
R_FITTED, R_NO_TRANSIENT, R_STOPPED, R_NOT_DECAYING = 0, 1, 2, 3
REASONS = {
    R_FITTED: "fitted",
    R_NO_TRANSIENT: "no transient: under a decade of decay above the floor",
    R_STOPPED: "stopped",
    R_NOT_DECAYING: "not decaying",
}
#: kinds of fit (``fit_kind``)
K_NONE, K_EXPONENTIAL, K_POLYNOMIAL, K_OSCILLATING, K_MAP = 0, 1, 2, 3, 4
KINDS = {K_NONE: "none", K_EXPONENTIAL: "exponential",
         K_POLYNOMIAL: "exponential with polynomial prefactor",
         K_OSCILLATING: "oscillating (level times regressed on levels)",
         K_MAP: "one-step map (spectral radius of the fitted g_k -> g_k+1)"}  # fmt: skip
