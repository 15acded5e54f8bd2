"""Sequential decisions on an ensemble: members run in batches until the unstable fraction
is known to lie at most ``q`` or above it at a stated confidence.

The design is a group-sequential one with a fixed error budget spent over a known
schedule of looks (Lan and DeMets, "Discrete sequential boundaries for clinical trials",
Biometrika 70(3), 1983; here the budget is spent evenly, a Bonferroni split):

* looks after ``batch``, ``2 batch``, ``4 batch``, … members, up to ``max`` (``L`` looks:
  doubling keeps ``L`` near ``log₂(max / batch)``, so that each look keeps most of the
  budget);
* at each look, exact one-sided Clopper–Pearson bounds (Clopper and Pearson, "The use of
  confidence or fiducial limits illustrated in the case of the binomial", Biometrika
  26(4), 1934; :func:`scipy.special.betaincinv`), each side at level ``(1 − confidence) /
  (2L)``: the lower bound on the count of *unstable* members, the upper bound on the
  count of members *not stable* (unstable or undecided: a member the run cannot judge is
  counted against either decision).  By the union bound, all of them hold together at
  every look with probability at least ``confidence``, however the looks end: the
  guarantee survives optional stopping, and a wrong decision has probability at most
  ``1 − confidence``;
* the cell is *stable* (at most ``q`` unstable) when the upper bound is at most ``q``,
  *unstable* when the lower bound is above ``q``; it stops *undecided* when its members'
  own verdicts are undecided too often for either (the share of members not stable is
  above ``q`` and the share of unstable ones at most ``q``, both at the look's level),
  when the interval is narrower than ``tolerance``, or when ``max`` is reached.

The fractions are of the members that *ran*.  A member that could not be placed at its
perturbation (the sampler's Gauss–Newton did not reach it) or ran out of adaptive steps
has no verdict, and counting it as unstable or undecided would let a sampling limit pass
for a property of the scheme.  Leaving such members out is sound only while they are few:
the whole ensemble's unstable fraction lies within their share of the ran members' (it
is ``p (1 − s) + s u`` for a share ``s`` not run, ``u`` of them unstable).  So a decision
stands only where at most ``max_not_run`` of the members did not run; above that share
the cell looks again, and it stops *undecided* (reason ``not_run``) once the share's
own lower bound at the look's level is above ``max_not_run``, or at ``max``.

Members are the same at every look and at every grid point (:func:`.engine.sampler.
draw_alphas`: member ``i`` is a function of the seed and ``i``), so a cell's numbers do
not depend on the batches it was run in, only on how many members it ran.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy import special

from ._codes import DecisionReason, Verdict

#: the keys of a sequential ``members`` (in Python a mapping or :class:`Sequential`; in a
#: study file ``[ensemble] members = { ... }``)
KEYS = ("confidence", "q", "max", "batch", "tolerance", "max_not_run")
#: the fewest members of a first look (the roundoff level is read on the first 16)
MIN_BATCH = 16


@dataclass(frozen=True)
class Sequential:
    """Members of an ensemble run until its cell is decided (see the module's text).

    Parameters
    ----------
    confidence : float
        The probability, at least, that every interval reported at every look covers the
        true unstable fraction together; a wrong decision has probability at most
        ``1 − confidence``.  Default 0.95.
    q : float
        The unstable fraction that separates *stable* (at most ``q``) from *unstable*.
        Default 0.05.
    max : int
        The most members run (the last look).  Default 1024.
    batch : int
        The members of the first look (at least 16); each later look doubles them.
        Default 64.
    tolerance : float, optional
        Stop, undecided, once the interval is narrower than this (an estimate, not a
        decision, is then what the cell gives).  Default: none.
    max_not_run : float
        The largest share of members not run (not placed at their perturbation, or out of
        adaptive steps) that a decision accepts (see the module's text).  Default 0.01.
    """

    confidence: float = 0.95
    q: float = 0.05
    max: int = 1024
    batch: int = 64
    tolerance: float | None = None
    max_not_run: float = 0.01

    @classmethod
    def of(cls, value, who: str) -> Sequential:
        """``value`` (a :class:`Sequential` or a mapping of its fields) checked."""
        if isinstance(value, Sequential):
            value = {k: getattr(value, k) for k in KEYS}
        unknown = sorted(set(value) - set(KEYS))
        if unknown:
            raise ValueError(f"{who}: members has no key {', '.join(map(repr, unknown))}; "
                             f"its keys: {', '.join(KEYS)}")  # fmt: skip
        v = {**{k: getattr(cls, k) for k in KEYS}, **value}
        for key in ("confidence", "q"):
            x = v[key]
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not 0.0 < x < 1.0:
                raise ValueError(f"{who}: members {key} must be a number between 0 and 1 "
                                 f"(exclusive), got {x!r}")  # fmt: skip
        x = v["max_not_run"]
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not 0.0 <= x < 1.0:
            raise ValueError(f"{who}: members max_not_run must be a number in [0, 1), got "
                             f"{x!r}")  # fmt: skip
        for key, least in (("max", 1), ("batch", MIN_BATCH)):
            x = v[key]
            if isinstance(x, bool) or not isinstance(x, int) or x < least:
                raise ValueError(f"{who}: members {key} must be an integer of at least "
                                 f"{least}, got {x!r}")  # fmt: skip
        if v["batch"] > v["max"]:
            raise ValueError(f"{who}: members batch ({v['batch']}) must not exceed max "
                             f"({v['max']})")  # fmt: skip
        tol = v["tolerance"]
        if tol is not None and (isinstance(tol, bool) or not isinstance(tol, (int, float))
                                or not 0.0 < tol <= 1.0):  # fmt: skip
            raise ValueError(f"{who}: members tolerance must be a number in (0, 1], got "
                             f"{tol!r}")  # fmt: skip
        return cls(float(v["confidence"]), float(v["q"]), int(v["max"]), int(v["batch"]),
                   None if tol is None else float(tol), float(v["max_not_run"]))  # fmt: skip

    def looks(self) -> list[int]:
        """The members run by each look: ``batch``, doubling, up to ``max``."""
        out = [self.batch]
        while out[-1] < self.max:
            out.append(min(self.max, 2 * out[-1]))
        return out

    @property
    def side_level(self) -> float:
        """Each one-sided bound's level at each look: ``(1 − confidence) / (2L)``."""
        return (1.0 - self.confidence) / (2 * len(self.looks()))

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in KEYS if getattr(self, k) is not None}


def bounds(k: int, n: int, level: float) -> tuple[float, float]:
    """Exact one-sided Clopper–Pearson bounds of a fraction from ``k`` of ``n``, each side
    at ``level`` (the two-sided interval of confidence ``1 − 2 level``, as
    :meth:`scipy.stats.binomtest`'s ``proportion_ci(method="exact")``): the quantiles of
    the beta distributions ``B(k, n − k + 1)`` and ``B(k + 1, n − k)``, by
    :func:`scipy.special.betaincinv` (a hundredth of the time of the root search)."""
    low = 0.0 if k == 0 else float(special.betaincinv(k, n - k + 1, level))
    high = 1.0 if k == n else float(special.betaincinv(k + 1, n - k, 1.0 - level))
    return low, high


@dataclass(frozen=True)
class Decision:
    """A cell's decision at a look: ``verdict`` (a :class:`Verdict` code; None: look
    again), its ``reason`` (:class:`DecisionReason`), and the interval of the unstable
    fraction ``[low, high]`` (``low`` from the unstable members, ``high`` from those not
    stable)."""

    verdict: int | None
    reason: int
    low: float
    high: float


def decide(plan: Sequential, n: int, unstable: int, not_stable: int, last: bool,
           not_run: int = 0) -> Decision:
    """The decision after ``n`` members that ran, ``unstable`` of them unstable and
    ``not_stable`` unstable or undecided, beside ``not_run`` members that did not run
    (``last``: no look follows)."""
    share = not_run / (n + not_run) if n + not_run else 0.0
    if n == 0:
        return Decision(int(Verdict.UNDECIDED), int(DecisionReason.NOT_RUN), math.nan,
                        math.nan)  # fmt: skip
    d = _decide_ran(plan, n, unstable, not_stable, last)
    if share <= plan.max_not_run or d.verdict == int(Verdict.UNDECIDED):
        return d
    # too many not run for a decision: look again while more members may bring the share
    # down, and stop undecided once its own lower bound is above the limit
    low = bounds(not_run, n + not_run, plan.side_level)[0]
    final = last or low > plan.max_not_run
    return Decision(int(Verdict.UNDECIDED) if final else None, int(DecisionReason.NOT_RUN),
                    d.low, d.high)  # fmt: skip


def _decide_ran(plan: Sequential, n: int, unstable: int, not_stable: int,
                last: bool) -> Decision:
    a = plan.side_level
    (low, unstable_high), (not_stable_low, high) = bounds(unstable, n, a), bounds(not_stable, n, a)
    if high <= plan.q:
        return Decision(int(Verdict.STABLE), int(DecisionReason.STABLE), low, high)
    if low > plan.q:
        return Decision(int(Verdict.UNSTABLE), int(DecisionReason.UNSTABLE), low, high)
    undecided = int(Verdict.UNDECIDED)
    if not_stable_low > plan.q and unstable_high <= plan.q:
        return Decision(undecided, int(DecisionReason.MEMBERS_UNDECIDED), low, high)
    if plan.tolerance is not None and high - low <= plan.tolerance:
        return Decision(undecided, int(DecisionReason.WITHIN_TOLERANCE), low, high)
    if last:
        return Decision(undecided, int(DecisionReason.MAX_REACHED), low, high)
    return Decision(None, int(DecisionReason.MAX_REACHED), low, high)

