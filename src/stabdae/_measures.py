"""What an ensemble reports: each member's verdict with its reason, its class, and the
summaries with their uncertainty.

Per member a *verdict* (:func:`verdict`): ``stable``, ``unstable`` or ``undecided``, with
the reason.  It is read on the member's deviation from the reference trajectory (the
unperturbed motion, ``α⁰ = 0``), whose own residual is the truncation floor: a floor
that varies, or grows with the motion, is the same for every member up to the floor's
variation from state to state, and is no instability.  Where ``Ã`` is constant the
discrete theory referees: with ``ρ(R(τÃ)) < 1`` a member is stable while its deviation
stays within the law's transient bound ``sup_k ‖R^k‖∞ ‖α⁰‖∞`` (plus the floor band) and
is called unstable only where it left that bound and grew, or blew up where the bound
does not reach the divergence threshold.  Where a run cannot tell, the verdict is
``undecided``, never a guess.

Per member also a *stability class*, what happened to its raw residual:

``decayed``
    stable, fell below where it started and stayed within ε;
``overshoot``
    as ``decayed``, but above ε on the way: the law's own transient (a critically damped
    law's ``‖e^{Ãt}‖∞`` peaks near ``ω/e``); ``overshoot`` (largest / initial norm) is
    stored beside the law's ``sup_k ‖R(τÃ)^k‖∞``;
``at floor``
    stable, started within reach of the scheme's floor and stayed there, within ε;
``floor above epsilon``
    stable, settled on a floor (the scheme's local error at this step) above ε: a
    property of the step size, not an instability;
``growing``
    unstable, not stopped;
``diverged``
    stopped by the divergence threshold, a non-finite state or a singular ``S``;
``undecided``
    ran to the end, but the run cannot tell;
``not run``
    not placed, or an adaptive member that ran out of steps.

*Bounded* (Definition 2 of the paper) is stable with the largest norm within ε.  The
fractions come with Wilson 95 % intervals, the median decay rate with an exact
distribution-free interval from order statistics, and every summary with the counts
behind it.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy import special  # not scipy.stats: importing it costs more than a study's grid

from ._codes import (
    ProbeStage,
    RadiusReason,
    StabilityClass,
    Status,
    TauStarReason,
    Verdict,
    VerdictReason,
    messages,
)
from .engine import decay

#: class codes of ``stability_class`` (:class:`stabdae._codes.StabilityClass`)
DECAYED, OVERSHOOT, AT_FLOOR, FLOOR_ABOVE_EPSILON, GROWING, DIVERGED, NOT_RUN, UNDECIDED = (
    int(c) for c in StabilityClass)
CLASSES = tuple(c.message for c in StabilityClass)
STABLE = (DECAYED, OVERSHOOT, AT_FLOOR, FLOOR_ABOVE_EPSILON)
#: the normal quantile of the 95 % intervals
Z95 = 1.959963984540054

#: codes of a boundary search's ``tau_star_reason`` (:class:`stabdae._codes.TauStarReason`)
BRACKETED, LOW_END_FAILS, HIGH_END_STABLE, CONFIRM_FAILS, PROBE_UNDECIDED = (
    int(TauStarReason.BRACKETED), int(TauStarReason.LOW_END_FAILS),
    int(TauStarReason.HIGH_END_STABLE), int(TauStarReason.CONFIRM_FAILS),
    int(TauStarReason.UNDECIDED))
LOW_END_MOTION, BRACKETED_BY_MOTION = (int(TauStarReason.LOW_END_MOTION),
                                       int(TauStarReason.BRACKETED_BY_MOTION))
TAU_STAR_REASONS = messages(TauStarReason)
#: a boundary search's probe stages (``probe_stage``, :class:`stabdae._codes.ProbeStage`)
ENDS, GUIDED, BISECTION, CONFIRM = (int(c) for c in ProbeStage)
STAGES = messages(ProbeStage)

#: how far above the roundoff it can build up a rising residual must be to be growth
ROUNDOFF_MARGIN = 10.0
#: codes of ``verdict`` (:class:`stabdae._codes.Verdict`) and ``verdict_reason``
V_STABLE, V_UNSTABLE, V_UNDECIDED = (int(c) for c in Verdict)
VERDICTS = messages(Verdict)
VERDICT_REASONS = messages(VerdictReason)
#: codes of ``stability_radius_reason`` (:class:`stabdae._codes.RadiusReason`)
RADIUS_REASONS = messages(RadiusReason)
#: a deviation within this many times the reference trajectory's own residual (its
#: truncation floor, over the same fifth of the run) is the floor's variation from member
#: to member (the floor depends on the state, and a chaotic motion takes each member's
#: state away from the reference's), not a sign of the law
FLOOR_BAND = 10.0
#: a member of a law with ``ρ < 1`` is held to ``TRANSIENT_SLACK`` times the linear
#: bound ``sup ‖R^k‖∞ ‖α⁰‖∞`` (the residual follows ``g_{k+1} = R g_k`` up to terms of
#: second order in ``α⁰``)
TRANSIENT_SLACK = 2.0

_BLOWN_UP = (Status.DIVERGED, Status.NONFINITE_STATE, Status.SINGULAR_S, Status.MASS_NOT_SPD)
_BLOWN_UP_CODES = frozenset(int(s) for s in _BLOWN_UP)


def blown_up(status: np.ndarray) -> np.ndarray:
    """Whether each member's status is one of a blow-up (``np.isin`` of the four codes,
    compared one by one: ``np.isin``'s own work took 80 µs on 10⁴ members)."""
    out = status == int(_BLOWN_UP[0])
    for code in _BLOWN_UP[1:]:
        out |= status == int(code)
    return out


def row_max_abs(a: np.ndarray) -> np.ndarray:
    """``np.max(np.abs(a), axis=1)`` for a 2-D ``a`` of at least one column (NaN where a
    row has one), column by column: over a few columns numpy's reduction along rows took
    360 µs on 10⁴ rows of 2."""
    out = np.abs(a[:, 0])
    for c in range(1, a.shape[1]):
        np.maximum(out, np.abs(a[:, c]), out=out)
    return out


def rows_finite(a: np.ndarray) -> np.ndarray:
    """``np.isfinite(a).all(axis=1)`` for a 2-D ``a``, column by column (as
    :func:`row_max_abs`)."""
    out = np.ones(a.shape[0], dtype=bool)
    for c in range(a.shape[1]):
        out &= np.isfinite(a[:, c])
    return out


def classify(meas: decay.Record, status: np.ndarray, epsilon: float,
             verdicts: np.ndarray) -> np.ndarray:  # fmt: skip
    """The stability class of each member (int8, codes of :data:`CLASSES`) from its
    measurement record ``meas`` and its verdict (:func:`verdict`): a stable member is
    ``decayed``, ``overshoot``, ``at floor`` or ``floor above epsilon`` by its raw
    residual against ``epsilon``; an unstable one ``diverged`` (stopped) or ``growing``;
    an undecided one that ran ``undecided`` (``diverged`` where the divergence threshold
    stopped it)."""
    initial, largest = meas["initial"], meas["largest"]
    w2, w3, w4 = meas["w2"], meas["w3"], meas["w4"]
    with np.errstate(invalid="ignore"):
        fell = w4 < initial
        within = largest <= epsilon
        # settled: the raw residual no longer falls a factor per fifth (it is on its floor)
        still = (w2 >= decay.STILL_DECAYING * w3) & (w3 >= decay.STILL_DECAYING * w4)
        floor_high = ~still & (w4 > epsilon)
    cls = np.full(status.shape, AT_FLOOR, dtype=np.int8)
    cls[fell & within] = DECAYED
    cls[fell & ~within] = OVERSHOOT
    cls[floor_high] = FLOOR_ABOVE_EPSILON
    cls[verdicts == V_UNSTABLE] = GROWING
    cls[verdicts == V_UNDECIDED] = UNDECIDED
    blown = blown_up(status)
    cls[blown] = DIVERGED
    cls[(status != 0) & ~blown] = NOT_RUN
    return cls


@dataclass(frozen=True)
class Motion:
    """How the unperturbed run (``α⁰ = 0``, the reference trajectory) went: its status
    (a :class:`~stabdae._codes.Status` code, 0: it ran to the end), the time it stopped
    (NaN: it did not, or the time is not known), and the first time its residual
    exceeded ε (NaN: never; ``by_fifth``: known only as the end of the fifth of the run
    in which it did).

    Where it blew up or left ε the scheme is unstable on the motion itself: no member can
    stay within ε (Definition 2 of the paper asks that of every member), and the
    reference's residual, which the members' deviations are read against, is no floor.
    :func:`verdict` then calls every member that ran unstable, with one reason, unless
    the run's residual can reach ε by roundoff alone (:meth:`leaves_epsilon`)."""

    status: int = 0
    stopped_at: float = math.nan
    exceeds_at: float = math.nan
    by_fifth: bool = False
    epsilon: float = math.inf

    @property
    def unstable(self) -> bool:
        return self.status in _BLOWN_UP_CODES or math.isfinite(self.exceeds_at)

    def leaves_epsilon(self, roundoff: float) -> bool:
        """Whether the motion is unstable beyond what roundoff explains: it blew up, or its
        residual exceeded ε where ε lies above ``roundoff``, the size roundoff builds up
        in the residual by the end of the run (states that grow without bound carry a
        roundoff that grows with them: its reaching ε says that the arithmetic, not the
        scheme, cannot hold the motion within ε)."""
        return self.status in _BLOWN_UP_CODES or (math.isfinite(self.exceeds_at)
                                                  and not roundoff >= self.epsilon)

    @classmethod
    def of_rows(cls, times, norms, epsilon: float) -> Motion:
        """From the reference's residual norms ``norms`` at ``times``, a run to the end."""
        over = np.flatnonzero(~(np.asarray(norms, dtype=float) <= epsilon))
        return cls(exceeds_at=float(times[over[0]]) if over.size else math.nan,
                   epsilon=float(epsilon))

    @classmethod
    def of_run(cls, status: int, stopped_at: float, band, t0: float, t_end: float,
               epsilon: float) -> Motion:  # fmt: skip
        """From a run's status, the time it stopped and its largest residual per fifth
        (``band``; zeros where it stopped)."""
        over = np.flatnonzero(~(np.asarray(band, dtype=float) <= epsilon))
        if int(status) != 0 or not over.size:
            return cls(int(status), float(stopped_at) if int(status) else math.nan,
                       epsilon=float(epsilon))
        return cls(exceeds_at=t0 + (int(over[0]) + 1) * (t_end - t0) / 5.0, by_fifth=True,
                   epsilon=float(epsilon))

    @classmethod
    def of_dataset(cls, ds) -> Motion:
        """From an ensemble's dataset (its ``reference_*`` variables; a stable motion where
        it has none)."""
        if "reference_status" not in ds:
            return cls()
        return cls(int(ds["reference_status"]), float(ds["reference_stop_time"]),
                   float(ds["reference_exceeds_epsilon_time"]))  # fmt: skip

    def describe(self, epsilon: float) -> str:
        """What happened, in the words of a summary (empty where the motion is stable)."""
        if not self.unstable:
            return ""
        if self.status in _BLOWN_UP_CODES:
            when = (f"at t = {self.stopped_at:.6g}" if math.isfinite(self.stopped_at)
                    else "before the end")  # fmt: skip
            return f"the unperturbed run diverges {when} ({Status(self.status).short})"
        word = "by" if self.by_fifth else "at"
        return (f"the unperturbed run's residual exceeds epsilon = {epsilon:g} {word} "
                f"t = {self.exceeds_at:.6g}")


def verdict(meas: decay.Record, status: np.ndarray, floor_band=None, bounds=None,
            rho: float = math.nan, divergence: float = math.inf,
            roundoff: float = 0.0, motion: Motion | None = None
            ) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Each member's verdict and its reason (int8 codes of :data:`VERDICTS` and
    :data:`VERDICT_REASONS`).

    Read on the member's *deviation*, the distance of its residual from the reference
    trajectory's (``d2 … d4`` of ``meas``: its largest over the last three fifths of the
    run; the residual itself where there is no reference), against its start ``d0``
    (``meas["initial"]``) and:

    * ``floor_band``: per fifth of the run, the reference trajectory's largest residual
      (its truncation floor; 5 numbers, None: unknown, taken as 0).  The deviation from
      member to member of a floor that depends on the state lies within ``FLOOR_BAND``
      times it, together with ``ROUNDOFF_MARGIN`` times ``roundoff``;
    * ``bounds``: per fifth, ``sup ‖R(τÃ)^k‖∞`` over its steps, and ``rho = ρ(R(τÃ))``,
      where ``Ã`` is constant (:func:`stabdae.theory.fifth_bounds`): the law's theory,
      which then referees.

    With the theory and ``ρ < 1``: *stable* where the deviation over the last fifth lies
    within ``TRANSIENT_SLACK`` times the law's bound plus the floor band, unless it rose
    over the last three fifths past its start and past the law's bound alone, by more
    than ``GROWTH`` times what the reference's floor rose over the same fifths (then
    *undecided*: growth inside the floor band cannot be told from the floor's variation;
    a grown member is never stable); *unstable* only
    where it blew up past what the bound allows, or rose over the last three fifths
    (:func:`stabdae.engine.decay.grows`) beyond the bound and past its own start (a rise
    that stays below the start is the floor of a motion that has left the reference's:
    a member knocked into a faster motion carries a floor of its own);
    otherwise *undecided*.  With
    ``ρ ≥ 1``: *unstable* where it blew up or grew; a member that decayed is undecided
    (the growing mode may lie under the floor).  Without the theory: *unstable* where it
    blew up, or grew above the floor band and its start; *stable* where it ended below
    its start; *undecided* otherwise (in the floor band, or the run too short).

    ``motion`` (:class:`Motion`): where the unperturbed run itself blew up or left ε,
    every member that ran is *unstable* on the motion itself, whatever its deviation
    (unless ``ρ ≥ 1``: there the law's growing mode takes the reference with it; and
    unless ``roundoff`` alone reaches ε, :meth:`Motion.leaves_epsilon`)."""
    R_ = VerdictReason
    d0 = np.asarray(meas["initial"], dtype=float)
    d2, d3, d4 = (np.asarray(meas[c], dtype=float) for c in ("d2", "d3", "d4"))
    band = np.zeros(5) if floor_band is None else np.asarray(floor_band, dtype=float)
    noise = FLOOR_BAND * np.nan_to_num(band, nan=0.0) + ROUNDOFF_MARGIN * roundoff
    theory_known = bounds is not None and math.isfinite(rho)
    with np.errstate(invalid="ignore", over="ignore"):
        # growth is resolved only where each of the last three fifths holds a measured
        # state (a run of a few steps leaves them empty: -inf)
        resolved = np.isfinite(d2) & np.isfinite(d3) & np.isfinite(d4)
        grew = resolved & decay.grows(d2, d3, d4) & (d4 > noise[4])
        ended_low = d4 < d0
        if theory_known:
            allowed = TRANSIENT_SLACK * np.asarray(bounds, dtype=float)[4] * d0 + noise[4]
            peak = TRANSIENT_SLACK * float(np.max(bounds)) * d0 + float(noise.max())
            within = d4 <= allowed
    verdict = np.full(status.shape, V_UNDECIDED, dtype=np.int8)
    reason = np.full(status.shape, int(R_.TOO_SHORT), dtype=np.int8)

    def put(mask, v, r):
        verdict[mask] = v
        reason[mask] = int(r)

    if theory_known and rho < 1.0:
        put(~within & ~grew, V_UNDECIDED, R_.ABOVE_BOUND)
        with np.errstate(invalid="ignore"):
            past_start = d4 > d0
        put(~within & grew & past_start, V_UNSTABLE, R_.BEYOND_BOUND)
        put(~within & grew & ~past_start, V_UNDECIDED, R_.ROSE_BELOW_START)
        put(within & ~ended_low, V_STABLE, R_.WITHIN_BOUND)
        put(within & ended_low, V_STABLE, R_.DECAYED)
        # a deviation that rose past the law's bound alone and past its start, faster
        # than the reference's floor rose over the same fifths, has grown, though the
        # floor band may still hold it (a floor's variation from member to member, the
        # floor's dependence on the state times the member's offset from the reference's,
        # rises with the floor itself)
        floor_rise = band[4] / band[2] if band[2] > 0.0 and band[4] > 0.0 else 1.0
        with np.errstate(invalid="ignore"):
            law_bound = (TRANSIENT_SLACK * np.asarray(bounds, dtype=float)[4] * d0
                         + ROUNDOFF_MARGIN * roundoff)  # fmt: skip
            rose = (resolved & decay.grows(d2, d3, d4) & past_start & (d4 > law_bound)
                    & (d4 > decay.GROWTH * max(1.0, floor_rise) * d2))  # fmt: skip
        put(within & rose, V_UNDECIDED, R_.ROSE_IN_FLOOR_BAND)
    elif theory_known:
        # ρ ≥ 1: the reference trajectory's own residual grows with the law's growing
        # mode, so it is no floor; growth past the member's start is evidence enough
        with np.errstate(invalid="ignore"):
            grew = resolved & decay.grows(d2, d3, d4) & ((d4 > d0) | (d4 > noise[4]))
        put(ended_low & ~grew, V_UNDECIDED, R_.DECAYED_RHO_ABOVE_ONE)
        put(grew, V_UNSTABLE, R_.GREW)
    else:
        with np.errstate(invalid="ignore"):
            in_band = (d0 <= noise[0]) & (d4 <= noise[4])
        put(in_band, V_UNDECIDED, R_.IN_FLOOR_BAND)
        put(ended_low & ~grew, V_STABLE, R_.DECAYED)
        with np.errstate(invalid="ignore"):
            put(grew & (d4 > d0), V_UNSTABLE, R_.GREW)
    blown = blown_up(status)
    put(blown, V_UNSTABLE, R_.BLEW_UP)
    if theory_known and rho < 1.0:
        # the divergence threshold stopped a transient the law allows: no evidence
        with np.errstate(invalid="ignore"):
            excused = (status == int(Status.DIVERGED)) & (divergence <= peak)
        put(excused, V_UNDECIDED, R_.STOPPED_IN_TRANSIENT)
    if (motion is not None and motion.leaves_epsilon(roundoff)
            and not (theory_known and rho >= 1.0)):
        # (with ρ ≥ 1 the law's own growing mode takes the reference with it: the law,
        # not the motion, is unstable, and the members say so by their own growth)
        put((status == 0) | blown, V_UNSTABLE, R_.MOTION_UNSTABLE)
    put((status != 0) & ~blown, V_UNDECIDED, R_.NOT_RUN)
    return verdict, reason


def roundoff_level(residual_rows, states, t: float) -> float:
    """The size roundoff gives the residual at these states: the median over the states of
    ``u · max_c (Σ_i |∂g_c/∂x_i · x_i| + |∂g_c/∂t · t|)`` (``u`` the unit roundoff), each
    term the change of ``g`` when one entry of the state (or the time) moves by one
    rounding, by central differences.  ``residual_rows(X, t)`` evaluates ``g`` at every row
    of ``X``."""
    states = np.asarray(states, dtype=float)
    if states.size == 0:
        return 0.0
    h = 1e-6
    u = np.finfo(float).eps / 2.0
    states = np.atleast_2d(states)
    S, n2 = states.shape
    rows = 2 * n2 + 1  # per state: ± each entry, then the state itself
    X = np.repeat(states, rows, axis=0).reshape(S, rows, n2)
    idx = np.arange(n2)
    X[:, 2 * idx, idx] += h * states
    X[:, 2 * idx + 1, idx] -= h * states
    # every state's rows in one call (each call is a trip to the threads)
    G = residual_rows(X.reshape(S * rows, n2), t).reshape(S, rows, -1)
    if t != 0.0:
        Gt = residual_rows(np.ascontiguousarray(X[:, -1]), t * (1.0 + h))
    terms = np.abs(G[:, 0:-1:2] - G[:, 1:-1:2]).sum(axis=1) / (2.0 * h)  # (S, components)
    if t != 0.0:
        terms = terms + np.abs(Gt - G[:, -1]) / h
    finite = np.isfinite(terms).all(axis=1)
    if not finite.any():
        return 0.0
    levels = terms[finite].max(axis=1) if terms.shape[1] else np.zeros(int(finite.sum()))
    return u * float(np.median(levels))


def wilson(successes: int, n: int) -> tuple[float, float]:
    """Wilson's 95 % score interval of a fraction (NaN for ``n = 0``)."""
    if n == 0:
        return math.nan, math.nan
    p = successes / n
    z2 = Z95 * Z95
    centre = (p + z2 / (2 * n)) / (1 + z2 / n)
    half = Z95 * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / (1 + z2 / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def median_interval(values, level: float = 0.95) -> tuple[float, float, float, float]:
    """The median of the finite values with its distribution-free interval from order
    statistics, and that interval's exact coverage: ``(median, low, high, coverage)``.

    ``[v_(r), v_(n+1−r)]`` (1-based order statistics) covers the median of any
    continuous distribution with probability ``1 − 2 P(B ≤ r − 1)``, ``B ~ Bin(n, 1/2)``
    (:func:`scipy.special.bdtr`); ``r`` is the largest rank with coverage at least
    ``level``.  Where even ``[min, max]`` covers less (``n ≤ 5`` at 95 %), that is the
    interval, with its lower coverage; NaN for no values."""
    v = np.sort(np.asarray(values, dtype=float)[np.isfinite(values)])
    n = v.size
    if n == 0:
        return math.nan, math.nan, math.nan, math.nan
    # from the sorted values, as np.median takes it (the mean of the middle two for an
    # even n), without its second pass over them
    h = n // 2
    med = float(v[h]) if n % 2 else float((v[h - 1] + v[h]) / 2.0)
    k, coverage = _median_rank(n, float(level))
    return med, float(v[k - 1]), float(v[n - k]), coverage


@functools.lru_cache(maxsize=1024)
def _median_rank(n: int, level: float) -> tuple[int, float]:
    """The rank ``r`` of :func:`median_interval` for ``n`` values and its coverage (they
    depend on ``n`` and ``level`` only: a study asks for the same few again and again)."""
    r = np.arange(1, n // 2 + 1)
    cover = 1.0 - 2.0 * special.bdtr(r - 1, n, 0.5)
    ok = np.flatnonzero(cover >= level)
    k = int(r[ok[-1]]) if ok.size else 1
    return k, float(1.0 - 2.0 * special.bdtr(k - 1, n, 0.5)) if n > 1 else 0.0


def stability_radius(alpha_norm, stable, decided) -> tuple[float, float, float, int]:
    """δ* with its bracket: ``(δ*, low, high, reason)`` (reason: a code of
    :data:`RADIUS_REASONS`), over the members with a verdict (``decided``: stable or
    unstable).  ``high`` is the smallest ``‖α⁰‖`` of an unstable member, ``low`` the
    largest below it (every member up to ``low`` was stable); δ* is their geometric
    mean.  Where the sample does not bracket it, δ* is censored: NaN, with the side the
    sample bounds it from (``low``: it is above the largest sampled; ``high``: below the
    smallest unstable)."""
    a, ok = np.asarray(alpha_norm)[decided], np.asarray(stable)[decided]
    if a.size == 0:
        return math.nan, math.nan, math.nan, int(RadiusReason.NO_MEMBER)
    if ok.all():
        return math.nan, float(a.max()), math.nan, int(RadiusReason.ABOVE_SAMPLE)
    high = float(a[~ok].min())
    below = a[a < high]
    if below.size == 0:
        return math.nan, math.nan, high, int(RadiusReason.BELOW_SAMPLE)
    low = float(below.max())
    return math.sqrt(low * high), low, high, int(RadiusReason.BRACKETED)


def flags(meas, verdicts, epsilon):
    """Per member: ``(stable, bounded)``, bounded being stable and within ε at every step
    (Definition 2)."""
    stable = verdicts == V_STABLE
    with np.errstate(invalid="ignore"):
        return stable, stable & (meas["largest"] <= epsilon)


def summaries(meas, verdicts, reasons, cls, alpha_norm, epsilon) -> tuple[dict, str]:
    """The ensemble's scalar summaries with their intervals and counts, and why δ* is
    what it is."""
    ran = cls != NOT_RUN
    stable, bounded = flags(meas, verdicts, epsilon)
    n = int(ran.sum())
    beta = meas["beta"]
    out = {"members_run": n, "members_stable": int((stable & ran).sum()),
           "members_unstable": int(((verdicts == V_UNSTABLE) & ran).sum()),
           "members_undecided": int(((verdicts == V_UNDECIDED) & ran).sum()),
           "members_bounded": int((bounded & ran).sum()),
           "members_diverged": int((cls == DIVERGED).sum()),
           "members_growing": int((cls == GROWING).sum()),
           "members_with_beta": int(np.isfinite(beta).sum())}  # fmt: skip
    for name in ("stable", "unstable", "undecided", "bounded"):
        k = out["members_" + name]
        out["fraction_" + name] = k / n if n else math.nan
        out[f"fraction_{name}_low"], out[f"fraction_{name}_high"] = wilson(k, n)
    (out["beta_median"], out["beta_median_low"], out["beta_median_high"],
     out["beta_median_coverage"]) = median_interval(beta)  # fmt: skip
    decided = ran & (verdicts != V_UNDECIDED)
    delta, low, high, why = stability_radius(alpha_norm, stable, decided)
    out.update(stability_radius=delta, stability_radius_low=low, stability_radius_high=high,
               stability_radius_reason=why)  # fmt: skip
    return out, RADIUS_REASONS[why]


def ensemble_verdict(n_run: int, n_stable: int, n_unstable: int, q: float = 0.0) -> int:
    """The verdict on a whole ensemble (a code of :data:`VERDICTS`): stable where at
    least ``1 − q`` of the members that ran are stable, unstable where more than ``q``
    are unstable, undecided otherwise (or where none ran)."""
    if n_run == 0:
        return V_UNDECIDED
    if n_stable >= (1.0 - q) * n_run:
        return V_STABLE
    if n_unstable > q * n_run:
        return V_UNSTABLE
    return V_UNDECIDED


def not_run_text(status, ran) -> str:
    """The members that did not run, counted by their status:
    ``"12 not placed (sampling failed)"``."""
    codes, counts = np.unique(np.asarray(status)[~ran], return_counts=True)
    return ", ".join(f"{c} {Status(int(k)).short}" for k, c in zip(codes, counts))


def verdict_summary(verdicts, reasons, ran, motion: str = "", status=None) -> str:
    """One line a user reads first: the counts of each verdict, the undecided and the
    unstable by reason (``motion``: what happened to the unperturbed run where the
    scheme is unstable on the motion itself, :meth:`Motion.describe`), and the members
    that did not run by their ``status``."""
    n = int(ran.sum())
    parts = []
    for v, name in VERDICTS.items():
        sel = ran & (verdicts == v)
        k = int(sel.sum())
        text = f"{k} {name}"
        if k and v != V_STABLE:
            why = np.unique(reasons[sel], return_counts=True)
            text += " (" + "; ".join(
                f"{c} {VERDICT_REASONS[int(r)].split(':')[0]}"
                + (f": {motion}" if motion and int(r) == int(VerdictReason.MOTION_UNSTABLE)
                   else "")
                for r, c in zip(*why)) + ")"  # fmt: skip
        parts.append(text)
    tail = ""
    if status is not None and n < ran.size:
        tail = f"; {ran.size - n} of {ran.size} did not run ({not_run_text(status, ran)})"
    return f"of {n} members that ran: " + ", ".join(parts) + tail
