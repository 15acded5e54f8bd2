"""The verdict, the stability class, the growth predicate, the ensemble's verdict, the
roundoff level and the measurement stride against their plain-Python references
(``tests/reference/verdicts.py``, written from the documented definitions): truth tables
over a lattice where every comparison ties somewhere, property tests (hypothesis, a fixed
number of derandomized examples) over random members, and closed forms."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from reference import verdicts as ref
from stabdae import _measures
from stabdae._ensemble import measure_stride
from stabdae.engine import decay

#: values where the rules' comparisons tie (1.5 × 2 = 3, 3 × 3 = 9, 10 × 0.1 = 1 …),
#: the unmeasured fifth (−inf) and a stop's NaN
LATTICE = [0.0, 0.1, 0.5, 1.0, 1.5, 2.0, 3.0, 4.5, 9.0, 27.0, 1e3, math.inf, -math.inf,
           math.nan]  # fmt: skip
#: statuses: ran, each blow-up, not placed / out of steps
STATUSES = [0, 0, 0, 1, 2, 3, 4, 5, 6, 7]

value = st.one_of(st.sampled_from(LATTICE), st.floats(0.0, 1e4, allow_subnormal=False))
positive = st.one_of(st.sampled_from([0.1, 0.5, 1.0, 1.5, 2.0, 3.0]),
                     st.floats(1e-3, 1e3, allow_subnormal=False))  # fmt: skip


def test_growth_predicate_truth_table():
    """``grows`` over every triple of a lattice with ties (1.5 × 2 = 3): rising by 1.5
    from the third fifth to the fifth, never falling in between; scalars and arrays."""
    grid = [0.0, 1.0, 1.5, 2.0, 3.0, 4.0, math.nan]
    triples = np.array(list(itertools.product(grid, repeat=3)))
    with np.errstate(invalid="ignore"):
        got = decay.grows(triples[:, 0], triples[:, 1], triples[:, 2])
    want = [ref.grows(*t) for t in triples]
    assert got.tolist() == want
    # the middle condition matters: up by 1.5 overall, but down in the middle fifth
    assert not decay.grows(1.0, 3.0, 2.0) and decay.grows(1.0, 1.5, 2.0)
    # counted by hand over the finite values: d2 = 0: 20 (any d3 ≤ d4 > 0), 1: 12 (d4 ≥ 2),
    # 1.5: 7 (d4 ≥ 3), 2: 3 (d4 = 4), 3 and 4: none
    assert sum(want) == 42


def test_ensemble_verdict_truth_table():
    """The ensemble's verdict for every count of 10 members (stable, unstable, undecided
    summing to the members that ran) at q = 0, 0.1, 0.25, 0.5: the fraction stable at
    least 1 − q, or unstable above q, ties included; nothing ran: undecided."""
    seen = set()
    for q in (0.0, 0.1, 0.25, 0.5):
        for n in (0, 4, 10):
            for s in range(n + 1):
                for u in range(n - s + 1):
                    got = _measures.ensemble_verdict(n, s, u, q)
                    assert got == ref.ensemble_verdict(n, s, u, q), (q, n, s, u)
                    seen.add(got)
    assert seen == {_measures.V_STABLE, _measures.V_UNSTABLE, _measures.V_UNDECIDED}


def _near(x: float) -> list[float]:
    """``x`` and its neighbours a rounding away: where a comparison with it flips."""
    return [x, x * (1 + 1e-12), x * (1 - 1e-12)] if math.isfinite(x) else [x]


@st.composite
def members(draw):
    """Members with random settings, their values drawn from the lattice, random floats,
    or the rule's own thresholds for those settings and their neighbours (the noise
    level, the allowed deviation, the law's peak, growth by exactly 1.5)."""
    n = draw(st.integers(1, 24))
    finite = value.filter(lambda x: not math.isinf(x))
    # any band, or a floor that rises over the last three fifths (where a deviation that
    # rises with it is the floor's variation)
    band = draw(st.none() | st.lists(finite, min_size=5, max_size=5)
                | st.tuples(finite, positive).map(lambda xr: [xr[0]] * 3
                                                  + [xr[0] * (1 + xr[1])] * 2))  # fmt: skip
    theory = draw(st.booleans())
    bounds = draw(st.lists(positive, min_size=5, max_size=5)) if theory else None
    rho = draw(st.sampled_from([0.5, 0.999, 1.0, 1.5]) | st.floats(0.0, 2.0)) if theory \
        else math.nan
    epsilon = draw(positive)
    # roundoff also at ε and beside it (whether the motion's leaving ε is roundoff's)
    roundoff = draw(st.sampled_from([0.0, 0.01, 0.1] + _near(epsilon)) | st.floats(0.0, 1.0))
    b = [0.0 if band is None or math.isnan(x) else x for x in (band or [0.0] * 5)]
    noise = [ref.FLOOR_BAND * x + ref.ROUNDOFF_MARGIN * roundoff for x in b]
    cols = {c: np.empty(n) for c in ("initial", "d2", "d3", "d4", "largest", "w2", "w3",
                                     "w4")}  # fmt: skip
    peaks = []
    for j in range(n):
        d0 = draw(value | st.sampled_from(_near(noise[0])))
        marks = _near(noise[0]) + _near(noise[4]) + _near(d0)
        if theory:
            marks += _near(ref.TRANSIENT_SLACK * bounds[4] * d0 + noise[4])
            marks += _near(ref.TRANSIENT_SLACK * bounds[4] * d0
                           + ref.ROUNDOFF_MARGIN * roundoff)  # fmt: skip
            peaks += _near(ref.TRANSIENT_SLACK * max(bounds) * d0 + max(noise))
        d4 = draw(value | st.sampled_from(marks))
        rise = ref.GROWTH * max(1.0, b[4] / b[2] if b[2] > 0 and b[4] > 0 else 1.0)
        d3 = draw(value | st.sampled_from(_near(d4) + _near(d4 / ref.GROWTH)))
        d2 = draw(value | st.sampled_from(_near(d3) + _near(d4 / ref.GROWTH)
                                          + _near(d4 / rise)))  # fmt: skip
        w4 = draw(value | st.sampled_from(_near(epsilon)))
        w3 = draw(value | st.sampled_from(_near(ref.STILL_DECAYING * w4)))
        w2 = draw(value | st.sampled_from(_near(ref.STILL_DECAYING * w3)))
        largest = draw(value | st.sampled_from(_near(epsilon)))
        for c, x in zip(cols, (d0, d2, d3, d4, largest, w2, w3, w4)):
            cols[c][j] = x
    status = np.array(draw(st.lists(st.sampled_from(STATUSES), min_size=n, max_size=n)),
                      dtype=np.int8)  # fmt: skip
    divergence = draw(st.sampled_from([math.inf, 1.0, 3.0, 9.0] + peaks) | st.floats(1e-3, 1e3))
    # the unperturbed run: mostly none or fine, else blown up, out of steps, or above ε
    motion = draw(st.sampled_from([None, (0, math.nan), (0, math.nan), (3, math.nan),
                                   (4, math.nan), (7, math.nan), (0, 0.5)]))  # fmt: skip
    return cols, status, band, bounds, rho, divergence, roundoff, epsilon, motion


@given(members())
def test_verdict_and_class_are_the_references(case):
    """Every member's verdict, reason and class is the reference's, for random members
    (lattice values with ties, the rule's thresholds and their neighbours, the unmeasured
    −inf, NaN, every status), with and without the theory, ρ on both sides of 1, any floor
    band, divergence threshold and roundoff, and an unperturbed run that ran, blew up,
    ran out of steps or left ε."""
    cols, status, band, bounds, rho, divergence, roundoff, epsilon, motion = case
    v, r = _measures.verdict(cols, status, band, None if bounds is None else np.array(bounds),
                             rho=rho, divergence=divergence, roundoff=roundoff,
                             motion=None if motion is None
                             else _measures.Motion(motion[0], math.nan, motion[1],
                                                   epsilon=epsilon))  # fmt: skip
    cls = _measures.classify(cols, status, epsilon, v)
    for j in range(status.size):
        want_v, want_r = ref.verdict(cols["initial"][j], cols["d2"][j], cols["d3"][j],
                                     cols["d4"][j], status[j], band, bounds, rho, divergence,
                                     roundoff, *(motion or (0, math.nan)), epsilon)  # fmt: skip
        assert (v[j], r[j]) == (want_v, want_r), j
        want_c = ref.stability_class(cols["initial"][j], cols["largest"][j], cols["w2"][j],
                                     cols["w3"][j], cols["w4"][j], status[j], epsilon,
                                     want_v)  # fmt: skip
        assert cls[j] == want_c, j


# ------------------------------------------------------------------ roundoff level
U = np.finfo(float).eps / 2.0


def test_roundoff_level_of_a_moving_constraint_in_closed_form():
    """``g = q − c t`` (a constraint that moves with time): each state's level is
    ``u (|q| + |c t|)``, the median over the states; without its time term it would be
    ``u |q|``, far below at a late time."""
    c, t = 3.0, 100.0

    def rows(X, at):
        return (X[:, :1] - c * at).copy()

    states = np.array([[0.5, 7.0], [2.0, -1.0], [-4.0, 0.0]])
    # in units of u (pytest.approx's default absolute tolerance, 1e-12, would pass any
    # level of a few u)
    got = _measures.roundoff_level(rows, states, t) / U
    assert got == pytest.approx(float(np.median(np.abs(states[:, 0]) + abs(c * t))), rel=1e-8)
    assert _measures.roundoff_level(rows, states, 0.0) / U == pytest.approx(2.0, rel=1e-8)


@given(st.lists(st.lists(st.floats(-50.0, 50.0), min_size=3, max_size=3), min_size=1,
                max_size=9),
       st.floats(0.0, 1e3))  # fmt: skip
def test_roundoff_level_is_the_references(states, t):
    """Two components, ``g = (x0² + x1² − 1, x2 − sin t · x0)``: the library's central
    differences (forward in time: their error grows with ``t``) against the exact
    derivatives of the reference, at random states."""
    states = np.array(states)

    def rows(X, at):
        return np.column_stack([X[:, 0] ** 2 + X[:, 1] ** 2 - 1.0,
                                X[:, 2] - math.sin(at) * X[:, 0]])

    def grad_x(x, at):
        return np.array([[2 * x[0], 2 * x[1], 0.0], [-math.sin(at), 0.0, 1.0]])

    def grad_t(x, at):
        return np.array([0.0, -math.cos(at) * x[0]])

    got = _measures.roundoff_level(rows, states, t)
    want = ref.roundoff_level(grad_x, grad_t, states, t)
    assert got == pytest.approx(want, rel=1e-2, abs=U * 1e-6)


# ------------------------------------------------------------------ measurement stride
@pytest.mark.parametrize("r, theta, want", [
    (0.99, 0.0, 19),            # |ln 0.99| = 0.01005: ⌊19.9⌋
    (math.exp(-0.011), 0.0, 18),  # ⌊18.2⌋
    (1.0, 0.06, 3),             # a pure rotation by 0.06 rad: ⌊3.33⌋
    (math.exp(-0.027), 0.036, 4),  # |−0.027 + 0.036i| = 0.045: ⌊4.44⌋
    (0.999, 1e-3, 32),          # slower than a fifth over 32 steps: capped
    (0.5, 0.0, 1),              # faster than a fifth per step: every step
    (1.0, 0.0, 32),             # nothing moves
])  # fmt: skip
def test_stride_of_an_under_damped_map_in_closed_form(r, theta, want):
    """``R`` with eigenvalues ``r e^{±iθ}``: the stride is ``⌊0.2 / |ln r + iθ|⌋`` within
    [1, 32], rotation counted with decay."""
    R = r * np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    assert measure_stride(np.kron(np.eye(2), R)) == want
    assert measure_stride(np.zeros((0, 0))) == 1  # a law that is not constant


@given(st.lists(st.floats(-1.5, 1.5), min_size=4, max_size=9))
def test_stride_is_the_references(entries):
    """Random 2×2 and 3×3 maps: eigenvalues real or complex, negative (``|ln λ|``
    counts the half turn), zero."""
    n = 3 if len(entries) == 9 else 2
    R = np.array(entries[: n * n]).reshape(n, n)
    lam = np.linalg.eigvals(R)
    want = ref.measure_stride(lam)
    got = measure_stride(R)
    if want != got:  # a quotient within rounding of a whole number: either is right
        change = max(abs(np.log(lam.astype(complex))))
        assert abs(0.2 / change - round(0.2 / change)) < 1e-9
        assert abs(got - want) == 1


# ------------------------------------------------------------------ summaries
@given(st.lists(st.tuples(st.sampled_from([0, 1, 2]), st.integers(0, 7),
                          st.sampled_from([0.5, 1.0, 2.0, math.nan]),
                          st.sampled_from([1e-4, 1e-3, 1e-2, 1e-1])),
                min_size=1, max_size=30))  # fmt: skip
def test_summaries_count_what_they_name(rows):
    """Every count and fraction of the summaries from its definition, member by member:
    run (class not ``not run``), stable / unstable / undecided / bounded (stable with the
    largest ≤ ε) among those that ran, diverged and growing by class, β where finite;
    the fractions over the members that ran; the δ* reason's text is its code's."""
    verdicts = np.array([r[0] for r in rows], dtype=np.int8)
    cls = np.array([r[1] for r in rows], dtype=np.int8)
    largest = np.array([r[2] for r in rows])
    alpha = np.array([r[3] for r in rows])
    meas = {"largest": largest, "beta": np.where(np.isnan(largest), np.nan, 1.0 / alpha)}
    eps = 1.0
    out, why = _measures.summaries(meas, verdicts, None, cls, alpha, eps)
    ran = [c != _measures.NOT_RUN for c in cls]
    n = sum(ran)
    want = {
        "members_run": n,
        "members_stable": sum(r and v == 0 for r, v in zip(ran, verdicts)),
        "members_unstable": sum(r and v == 1 for r, v in zip(ran, verdicts)),
        "members_undecided": sum(r and v == 2 for r, v in zip(ran, verdicts)),
        "members_bounded": sum(r and v == 0 and x <= eps
                               for r, v, x in zip(ran, verdicts, largest)),
        "members_diverged": sum(c == _measures.DIVERGED for c in cls),
        "members_growing": sum(c == _measures.GROWING for c in cls),
        "members_with_beta": sum(not math.isnan(x) for x in largest),
    }  # fmt: skip
    assert {k: out[k] for k in want} == want
    for name in ("stable", "unstable", "undecided", "bounded"):
        frac = want["members_" + name] / n if n else math.nan
        assert out["fraction_" + name] == pytest.approx(frac, nan_ok=True)
    assert why == _measures.RADIUS_REASONS[out["stability_radius_reason"]]
