"""Every integer code stabdae returns or stores, each with one message: the table.

A family of codes is an :class:`enum.IntEnum` whose members are declared with their
message, ``NAME = value, "message"``.  The kernels return and store the integers (they
read them as plain ints, ``int(Status.OK)``); the drivers, the summaries, the warnings,
the dataset's CF attributes (``flag_values``/``flag_meanings``, :func:`flag_attrs`) and
the schema page all read the messages from here, so that a code has one meaning
everywhere.  The values are part of the dataset schema: they never change meaning; a new
code takes a new value.

Families: :class:`Status` (a right-hand side's evaluation or a member's integration),
:class:`BetaReason` (why a member has a decay rate or not), :class:`FitKind` (which fit
gave it), :class:`StabilityClass` (a member's class), :class:`Verdict` and
:class:`VerdictReason` (a member's verdict and why), :class:`DecisionReason` (a
sequentially run cell's decision), :class:`RadiusReason` (how δ* is known),
:class:`TauStarReason` (how a boundary search ended), :class:`ProbeStage` (a boundary
search's probes) and :class:`LawKind` (how the right-hand side evaluates the law:
compile-time, never stored).

To add a code: a member with the next free value and its message in its family.  The
flag attributes and the schema page follow; a kernel that returns it compares with
``int(Family.NAME)``.
"""

from __future__ import annotations

import re
from enum import IntEnum

__all__ = ["BetaReason", "DecisionReason", "FitKind", "LawKind", "ProbeStage", "ProfileReason",
           "Status",
           "StabilityClass", "TauStarReason", "RadiusReason", "Verdict", "VerdictReason",
           "flag_attrs"]  # fmt: skip


class _Codes(IntEnum):
    """A family of codes: ``NAME = value, "message"``."""

    def __new__(cls, value: int, message: str):
        member = int.__new__(cls, value)
        member._value_ = value
        member.message = message
        return member

    @property
    def flag_meaning(self) -> str:
        """The CF ``flag_meanings`` word: the message up to its first colon or bracket,
        non-alphanumerics as underscores."""
        head = self.message.split(":")[0].split(" (")[0]
        return re.sub(r"[^0-9a-zA-Z]+", "_", head).strip("_")


class Status(_Codes):
    """Outcome of a right-hand-side evaluation or of one member's integration.

    Kernels never raise: every right-hand-side evaluation and every integration returns
    one of these, and the Python wrapper turns a non-zero code into a warning, an error or
    a per-member flag (variable ``status``)."""

    #: finished normally
    OK = 0, "ok"
    #: ``S = F M⁻¹ Fᵀ`` is singular or not finite: redundant or degenerate constraints (3.11)
    SINGULAR_S = 1, ("singular constraint matrix S = F M^-1 F^T (redundant or degenerate "
                     "constraints) in the multiplier equation (3.11)")
    #: the mass matrix is not symmetric positive definite (or not finite)
    MASS_NOT_SPD = 2, "mass matrix is not symmetric positive definite"
    #: the state became non-finite (NaN or inf) during a step
    NONFINITE_STATE = 3, "state became non-finite (NaN or inf)"
    #: the residual norm exceeded the divergence threshold
    DIVERGED = 4, "residual norm exceeded the divergence threshold"
    #: the initial state could not be placed at the requested perturbation
    SAMPLING_FAILED = 5, "initial perturbation could not be reached by Gauss-Newton"
    #: adaptive integration: the step size fell below roundoff of the time
    STEP_TOO_SMALL = 6, ("adaptive step size fell below roundoff of the time (stiff, "
                         "singular or non-finite right-hand side)")
    #: adaptive integration: the step budget (max_steps) was used up
    MAX_STEPS = 7, "adaptive integration used up max_steps"
    #: a study's grid point run until decided stopped before this member (its row is
    #: padding, up to the most members any grid point ran)
    NOT_NEEDED = 8, "not run: its grid point was decided with fewer members"

    @property
    def description(self) -> str:
        return self.message

    @property
    def flag_meaning(self) -> str:
        return self.name.lower()

    @property
    def short(self) -> str:
        """The few words a summary warning counts members by."""
        return _STATUS_SHORT[self]


_STATUS_SHORT = {
    Status.OK: "ok",
    Status.SINGULAR_S: "singular S",
    Status.MASS_NOT_SPD: "mass matrix not SPD",
    Status.NONFINITE_STATE: "non-finite state",
    Status.DIVERGED: "diverged",
    Status.SAMPLING_FAILED: "not placed (sampling failed)",
    Status.STEP_TOO_SMALL: "step too small",
    Status.MAX_STEPS: "max_steps used up",
    Status.NOT_NEEDED: "not needed",
}


class BetaReason(_Codes):
    """Why a member has a fitted decay rate, or why not (``beta_reason``)."""

    FITTED = 0, "fitted"
    NO_TRANSIENT = 1, "no transient: under a decade of decay above the floor"
    STOPPED = 2, "stopped"
    NOT_DECAYING = 3, "not decaying"


class FitKind(_Codes):
    """Which fit gave a member's decay rate (``fit_kind``)."""

    NONE = 0, "none"
    EXPONENTIAL = 1, "exponential"
    POLYNOMIAL = 2, "exponential with polynomial prefactor"
    OSCILLATING = 3, "oscillating (level times regressed on levels)"
    MAP = 4, ("one-step map (spectral radius of the fitted g_k -> g_k+1; on adaptive steps, "
              "its generator: the largest real part of the fitted A in dg/dt = A g)")


class StabilityClass(_Codes):
    """A member's stability class (``stability_class``)."""

    DECAYED = 0, "decayed"
    OVERSHOOT = 1, "overshoot"
    AT_FLOOR = 2, "at_floor"
    FLOOR_ABOVE_EPSILON = 3, "floor_above_epsilon"
    GROWING = 4, "growing"
    DIVERGED = 5, "diverged"
    NOT_RUN = 6, "not_run"
    #: ran to the end, but the run cannot tell stable from unstable (``verdict_reason``)
    UNDECIDED = 7, "undecided"


class RadiusReason(_Codes):
    """How δ*, the stability radius, is known (``stability_radius_reason``): a censored
    statistic where the sample does not bracket it."""

    BRACKETED = 0, "bracketed: between the largest all-stable |alpha0| and the smallest not"
    ABOVE_SAMPLE = 1, ("> largest sampled: every decided member stable; "
                       "stability_radius_low is the largest |alpha0| sampled")
    BELOW_SAMPLE = 2, ("< smallest sampled: no member stable below the smallest unstable; "
                       "stability_radius_high is its |alpha0|")
    NO_MEMBER = 3, "no decided member: every member undecided or not run"


class ProfileReason(_Codes):
    """How the bracket of δ* from a radial profile is known (``delta_star_reason``,
    :func:`stabdae.radial_profile`)."""

    BRACKETED = 0, ("bracketed: every bin up to delta_star_low is shown stable often "
                    "enough, the bin that ends at delta_star_high is shown not to be")
    ABOVE_SAMPLE = 1, ("above the sample: every bin is shown stable often enough; "
                       "delta_star_low is the largest radius binned")
    BELOW_SAMPLE = 2, ("below the sample: the first bin is shown not stable often enough; "
                       "delta_star_high is its top")
    OPEN_ABOVE = 3, ("open above: no bin above delta_star_low is shown either way (more "
                     "members, or fewer bins, narrow it)")
    OPEN_BELOW = 4, ("open below: the first bins are shown neither way, a later one not "
                     "stable often enough (more members, or fewer bins, narrow it)")


class Verdict(_Codes):
    """A member's verdict (``verdict``): what the run shows, judged against the law's
    theory where ``Ã`` is constant; *undecided* where the run cannot tell."""

    STABLE = 0, "stable"
    UNSTABLE = 1, "unstable"
    UNDECIDED = 2, "undecided"


class VerdictReason(_Codes):
    """Why a member has its verdict (``verdict_reason``).  The deviation is the distance
    of the member's residual from the reference trajectory's; the floor band is
    ``FLOOR_BAND`` times the reference trajectory's own residual (its truncation floor)
    over the same fifth of the run; the law's bound is ``sup ‖R(τÃ)^k‖∞ · ‖α⁰‖∞`` over
    that fifth (``TRANSIENT_SLACK`` times)."""

    DECAYED = 0, "decayed: the deviation ended below its start"
    WITHIN_BOUND = 1, ("within the law's bound: the deviation stayed under the law's "
                       "transient bound plus the floor band (rho < 1)")
    BLEW_UP = 2, "blew up: diverged, non-finite state or singular S"
    GREW = 3, "grew: the deviation rose over the last three fifths, above the floor band"
    BEYOND_BOUND = 4, ("grew beyond the law's bound: rho < 1, but the deviation rose above "
                       "the law's transient bound plus the floor band")
    STOPPED_IN_TRANSIENT = 5, ("stopped by the divergence threshold inside the law's "
                               "transient bound (rho < 1): raise divergence")
    IN_FLOOR_BAND = 6, ("in the floor band: the deviation never rose above the reference "
                        "trajectory's floor band, and the law has no theory to referee")
    TOO_SHORT = 7, "too short: the deviation neither ended below its start nor grew"
    ABOVE_BOUND = 8, ("above the law's bound but not growing (rho < 1): the run does not "
                      "follow the linear law")
    DECAYED_RHO_ABOVE_ONE = 9, ("decayed over this run, though rho >= 1: a growing mode may "
                                "not have been excited above the floor yet")
    NOT_RUN = 10, "not run: not placed, or out of steps"
    ROSE_BELOW_START = 11, ("rose again below its start (rho < 1): the deviation left the "
                            "law's bound and rose over the last three fifths, but stayed "
                            "below where it started: the floor of a motion that has left "
                            "the reference's, which this run cannot tell from slow growth")
    MOTION_UNSTABLE = 12, ("unstable on the motion itself: the unperturbed run (alpha0 = 0) "
                           "diverges or its residual leaves epsilon, so no member can stay "
                           "within epsilon (the dataset's reference_stop_time and "
                           "reference_exceeds_epsilon_time say when)")
    ROSE_IN_FLOOR_BAND = 13, ("rose in the floor band (rho < 1): the deviation grew over the "
                              "last three fifths past its start and past the law's bound, "
                              "but stayed within the reference trajectory's floor band: this "
                              "run cannot tell growth from the floor's variation")


class DecisionReason(_Codes):
    """Why a cell run member by member until decided (``decision_reason``) has its
    decision: the interval ``[fraction_unstable_low, fraction_unstable_high]`` at the
    cell's confidence against ``q``."""

    STABLE = 0, "stable: the interval's upper end is at most q"
    UNSTABLE = 1, "unstable: the interval's lower end is above q"
    MAX_REACHED = 2, "max members reached: the interval still contains q"
    MEMBERS_UNDECIDED = 3, ("members undecided: more than q of the members are not judged "
                            "stable, and no more than q unstable (their verdict_reason says "
                            "why)")
    WITHIN_TOLERANCE = 4, ("within tolerance: the interval is narrower than the tolerance "
                           "and contains q")
    NOT_RUN = 5, ("members not run: more than max_not_run of the members could not be "
                  "placed at their perturbation (or ran out of steps), so what the members "
                  "that ran decide need not hold for the whole ensemble (their status says "
                  "why)")


class TauStarReason(_Codes):
    """How a boundary search ended (``tau_star_reason``)."""

    BRACKETED = 0, "bracketed"
    LOW_END_FAILS = 1, "not stable at the bracket's low end"
    HIGH_END_STABLE = 2, "stable at the bracket's high end"
    CONFIRM_FAILS = 3, "the full ensemble is not stable above the bracket's low end"
    UNDECIDED = 4, ("a probe could not decide (too many members undecided): tau_star_low "
                    "and tau_star_high are the last decided bracket, not narrowed to rtol")
    LOW_END_MOTION = 5, ("unstable on the motion itself at the bracket's low end: the "
                         "unperturbed run diverges or leaves epsilon there")
    BRACKETED_BY_MOTION = 6, ("bracketed; at tau_star_high the scheme is unstable on the "
                              "motion itself (the unperturbed run diverges or leaves "
                              "epsilon), not only on the perturbations")


class ProbeStage(_Codes):
    """The stage of a boundary search a probe belongs to (``probe_stage``)."""

    ENDS = 0, "bracket ends"
    GUIDED = 1, "beside the spectral limit"
    BISECTION = 2, "bisection"
    CONFIRM = 3, "full ensemble"


class LawKind(_Codes):
    """How the stabilized right-hand side evaluates a law's ``Ã``: a kernel is compiled per
    kind (a law binds to one, :mod:`stabdae._laws`); never stored in a dataset.

    Adding a law kind: a member here; its branch in ``stabdae.engine.rhs`` (how ``A g`` is
    formed from the bound law's run-time ``matrix`` and ``scalars``, or from its compiled
    function: nothing else reaches the kernel); a ``Law`` in ``stabdae._laws`` whose
    ``bind`` returns ``BoundLaw(self, int(LawKind.X), matrix, scalars[, fn])`` and whose
    ``A_tilde`` gives the full ``Ã`` (the theory and the tests' NumPy right-hand side
    read it); its keys in study files (``stabdae.study.spec``); a test of ``ġ = Ã g``
    against the exact solution or the NumPy reference right-hand side."""

    CONSTANT = 0, "a constant A, given as a run-time matrix"
    THEOREM5 = 1, "Theorem 5's A22 = -k W(x) L with W = h_v h_v^T (no holonomic constraint)"
    USER = 2, "a user function A(t, x, p, out) evaluated in the kernel"
    ACPR = 3, ("A = 0 plus the correction -gamma_s D (G D)^-1 g of Ascher, Chin, Petzold "
               "and Reich")
    #: a constant A whose blocks are multiples of the identity (Baumgarte's), given by its
    #: three factors (f, ḟ, h) as a 1 × 3 matrix: the same sums as CONSTANT without their
    #: zero terms (bound so only for the sparse path)
    SCALAR_BLOCKS = 4, "a constant A of scalar blocks, given by its three factors"


def flag_attrs(codes: type[_Codes]) -> dict:
    """CF ``flag_values`` and ``flag_meanings`` of a code variable of the family ``codes``."""
    return {"flag_values": [int(c) for c in codes],
            "flag_meanings": " ".join(c.flag_meaning for c in codes)}  # fmt: skip


def messages(codes: type[_Codes]) -> dict[int, str]:
    """``{code: message}`` of a family."""
    return {int(c): c.message for c in codes}
