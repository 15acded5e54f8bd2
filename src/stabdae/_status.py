"""Status codes returned by the compiled kernels.

Kernels never raise: every right-hand-side evaluation and every integration returns one
of these integers, and the Python wrapper turns a non-zero code into a warning, an error
or a per-member flag.  The values are part of the dataset schema (variable ``status``),
so they never change meaning.
"""

from __future__ import annotations

from enum import IntEnum


class Status(IntEnum):
    """Outcome of a right-hand-side evaluation or of one member's integration."""

    #: finished normally
    OK = 0
    #: ``S = F M⁻¹ Fᵀ`` is singular or not finite: redundant or degenerate constraints (3.11)
    SINGULAR_S = 1
    #: the mass matrix is not symmetric positive definite (or not finite)
    MASS_NOT_SPD = 2
    #: the state became non-finite (NaN or inf) during a step
    NONFINITE_STATE = 3
    #: the residual norm exceeded the divergence threshold
    DIVERGED = 4
    #: the initial state could not be placed at the requested perturbation
    SAMPLING_FAILED = 5
    #: adaptive integration: the step size fell below roundoff of the time
    STEP_TOO_SMALL = 6
    #: adaptive integration: the step budget (max_steps) was used up
    MAX_STEPS = 7

    @property
    def description(self) -> str:
        return _DESCRIPTIONS[self]


_DESCRIPTIONS = {
    Status.OK: "ok",
    Status.SINGULAR_S: "singular constraint matrix S = F M^-1 F^T (redundant or degenerate "
    "constraints) in the multiplier equation (3.11)",
    Status.MASS_NOT_SPD: "mass matrix is not symmetric positive definite",
    Status.NONFINITE_STATE: "state became non-finite (NaN or inf)",
    Status.DIVERGED: "residual norm exceeded the divergence threshold",
    Status.SAMPLING_FAILED: "initial perturbation could not be reached by Gauss-Newton",
    Status.STEP_TOO_SMALL: "adaptive step size fell below roundoff of the time (stiff, "
    "singular or non-finite right-hand side)",
    Status.MAX_STEPS: "adaptive integration used up max_steps",
}


def status_flag_attrs() -> dict:
    """CF ``flag_values``/``flag_meanings`` attributes for a status variable."""
    return {
        "flag_values": [int(s) for s in Status],
        "flag_meanings": " ".join(s.name.lower() for s in Status),
    }
