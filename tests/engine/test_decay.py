"""The in-kernel decay measurement's pieces (``stabdae.engine.decay``): the ladder and
its envelope points, the fits, the one-step map's bins and γ, the logarithm, and
the estimator over stored traces against NumPy."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

import stabdae
from conftest import load_scene
from stabdae._codes import Verdict
from stabdae.engine import decay


def test_measures_of_stored_traces_match_numpy():
    """Initial, largest and final norm of traces with stops (inf, NaN) are NumPy's over
    the leading finite samples; a stopped trace gets no β and the reason "stopped"."""
    from stabdae.engine import decay

    norms = np.random.default_rng(0).random((40, 30))
    norms[3, 10:] = np.nan
    norms[5, 7], norms[5, 8:] = np.inf, np.nan
    meas = decay.measure_traces(norms, np.linspace(0.0, 1.0, 30))
    for j in range(40):
        row = norms[j]
        n = int(np.argmin(np.isfinite(row))) if not np.isfinite(row).all() else row.size
        assert meas["initial"][j] == row[0]
        assert meas["largest"][j] == row[:n].max()
        assert meas["final"][j] == row[n - 1]
    assert meas["reason"][3] == decay.R_STOPPED and np.isnan(meas["beta"][3])


@pytest.mark.parametrize("below", [None, 0, 3])
def test_ladder_records_are_the_right_envelope(below):
    """The ladder's points are, level by level, the last sample on that level, and exactly
    those of them that no later sample exceeds (the right envelope), in time order.  The
    scan may stop at the lowest level visited (``lowest``, as a member's end passes it:
    the same points) and reads no level below the one given (``below`` levels above the
    lowest visited: the points of the levels below are left out)."""
    import struct

    from stabdae.engine import decay

    rng = np.random.default_rng(4)
    v = np.exp(-np.linspace(0, 12, 700) + 2.0 * rng.standard_normal(700))
    v[-1] = v.min() * 1e-3  # the last sample, on the envelope, on the lowest level
    lt, lv, base = decay.ladders(1)
    rt, ry = np.empty(decay.NBINS), np.empty(decay.NBINS)
    decay.ladder_clear(lt, 0)
    base[0] = decay.ladder_base(v[0])
    bits = lambda x: struct.unpack("<q", struct.pack("<d", x))[0]  # noqa: E731
    level = [min(max((bits(x) >> 49) - base[0], 0), decay.NBINS - 1) for x in v]
    for i, x in enumerate(v):
        lt[0, level[i]], lv[0, level[i]] = float(i), x
    lowest = 0 if below is None else min(level) + below
    assert lowest < decay.NBINS - 100  # (the full scan's 512 levels are not all visited)
    n = decay.records(lt, lv, 0, rt, ry, *(() if below is None else (lowest,)))
    # from the highest level visited down (as a member's end passes it): the same points
    rt2, ry2 = np.empty(decay.NBINS), np.empty(decay.NBINS)
    n2 = decay.records(lt, lv, 0, rt2, ry2, lowest, decay.ladder_top(lt, 0))
    assert n2 == n and rt2[:n].tolist() == rt[:n].tolist() and ry2[:n].tolist() == ry[:n].tolist()
    last_on_level = {lev: i for i, lev in enumerate(level) if lev >= lowest}
    kept = list(last_on_level.values())
    expect = sorted(i for i in kept if v[i] > max((v[q] for q in kept if q > i), default=0.0))
    assert rt[:n].tolist() == [float(i) for i in expect]
    np.testing.assert_array_equal(ry[:n], np.log(v[expect]))
    if below == 3:  # the lowest level's point, the last sample, is left out
        assert expect[-1] < v.size - 1


def test_a_members_start_clears_its_ladder_from_the_level_given():
    """:func:`decay.begin` clears the levels from ``clear_from`` up (a member's run
    leaves none below its lowest level written) and leaves those below as they are; with
    no level given, all of them."""
    lt, lv, base = decay.ladders(1)
    meas = np.zeros((1, decay.NCOLS))
    codes = np.zeros((1, decay.NCODES), dtype=np.int64)
    for clear_from in (0, 5, 300, decay.NBINS - 1):
        lt[0] = 7.0
        decay.begin(lt, lv, base, meas, codes, 0, 0, 1e-3, 1e-3, clear_from)
        start = decay.NBINS - 1 - decay.ladder.ABOVE
        expect = np.where(np.arange(decay.NBINS) < clear_from, 7.0, -1.0)
        expect[start] = 0.0  # the initial norm's level, at time 0
        np.testing.assert_array_equal(lt[0, : decay.NBINS], expect)
    lt[0] = 7.0
    decay.begin(lt, lv, base, meas, codes, 0, 0, 1e-3, 1e-3)
    assert (lt[0, : decay.NBINS] <= 0.0).all()


def test_ladder_top_is_the_highest_level_visited():
    """:func:`decay.ladder_top` is the highest level with a time (−1 for none), as NumPy
    finds it: on rows visited at random above and below the initial level, only below it
    (the scan's second part), only at the bottom or the top level, on the initial level
    alone, and on none."""
    start = decay.NBINS - 1 - decay.ladder.ABOVE
    rng = np.random.default_rng(8)
    rows = [rng.choice(decay.NBINS, size=k, replace=False) for k in (1, 5, 40, 300)]
    rows += [rng.choice(start, size=k, replace=False) for k in (1, 7, 200)]
    rows += [np.array([0]), np.array([decay.NBINS - 1]), np.array([start]), np.array([], int)]
    lt, lv, base = decay.ladders(len(rows))
    for j, visited in enumerate(rows):
        decay.ladder_clear(lt, j)
        lt[j, visited] = rng.random(visited.size)
        lt[j, decay.NBINS] = 1.0  # the spare column (a non-finite norm's) is no level
    for j, visited in enumerate(rows):
        assert decay.ladder_top(lt, j) == (visited.max() if visited.size else -1), visited


def test_map_gamma_is_the_largest_product_on_the_envelope():
    """γ of a member measured by its one-step map, taken over every visited level in one
    branch-free pass, is ``max ‖g‖e^{βt}`` over the right envelope's points on the levels
    from the cut up (:func:`decay.records`, the definition), and the latest time is that
    of the envelope: on a noisy decay with rises (points that are not on the envelope) and
    a zero norm (none), at rates below, at and above the decay's; from a cut below the
    ladder (none of it left out), and over fewer levels than a vector holds; with norms of
    order one and of order 1e-6 (at the two lower rates every product then below one:
    the logarithms all negative); and on a plateau, a decay at the rate itself within
    1e-4, where the first pass's logarithms (within 1e-4) order the products otherwise
    than the exact ones."""
    import struct

    rng = np.random.default_rng(11)
    t = np.linspace(0.0, 6.0, 900)
    bits = lambda x: struct.unpack("<q", struct.pack("<d", x))[0]  # noqa: E731
    for scale, noise in ((1.0, 0.7), (1e-6, 0.7), (1e-3, 1e-4)):
        v = scale * np.exp(-2.0 * t + noise * rng.standard_normal(t.size))
        v[450] = 0.0
        lt, lv, base = decay.ladders(1)
        decay.ladder_clear(lt, 0)
        base[0] = decay.ladder_base(v[0])
        level = [min(max((bits(x) >> 49) - base[0], 0), decay.NBINS - 1) for x in v]
        for i, x in enumerate(v):
            lt[0, level[i]], lv[0, level[i]] = t[i], x
        top = max(level)
        scratch = np.empty(decay.NBINS)
        for lo in (-3, 0, min(level) + 40, top - 60, top - 5, top):  # a tail of a few levels
            above = {lev: i for i, lev in enumerate(level) if lev >= lo}  # last visit per level
            later_max = np.maximum.accumulate(v[::-1])[::-1]  # the largest from each sample on
            env = [i for i in above.values()
                   if v[i] > 0 and (i == v.size - 1 or later_max[i + 1] < v[i])]  # fmt: skip
            for beta in (0.5, 2.0, 7.0):
                gamma, t_end = decay.onestep._map_gamma(lt, lv, 0, lo, top, beta, scratch)
                expect = max(v[i] * math.exp(beta * t[i]) for i in env)
                assert gamma == pytest.approx(expect, rel=1e-14), (scale, noise, lo, beta)
                assert t_end == max(t[i] for i in above.values())


def test_log2_biased_is_within_its_bound():
    """The first pass's logarithm is ``log2 x + 1023`` within ``LOG2_BOUND`` over the
    normal floats: random ones over the whole range, and the ends of its mantissa's
    interval, where a fitted polynomial strays most."""
    from stabdae.engine.decay.ladder import LOG2_BOUND, log2_biased

    rng = np.random.default_rng(5)
    x = np.concatenate([np.exp2(rng.uniform(-1022.0, 1023.0, 20_000)),
                        np.exp2(rng.integers(-1022, 1023, 200).astype(float)),
                        [np.nextafter(2.0, 0.0), 1.5, 1.0 + 2.0**-52, 2.2250738585072014e-308,
                         np.finfo(float).max]])  # fmt: skip
    err = np.array([log2_biased(float(v)) for v in x]) - (np.log2(x) + 1023.0)
    assert np.abs(err).max() <= LOG2_BOUND
    assert np.abs(err).max() > 0.25 * LOG2_BOUND  # the bound is not loose past use


def test_map_bins_hold_the_pairs_before_the_first_fall_below_each():
    """The one-step map's sums of bin ``b`` are those of the pairs whose first state came
    before the member's level first fell below bin ``b`` (the transient above it; their
    number exactly, since the sums of the last pairs are below the others' roundoff), also
    when the residual comes back above it (a floor's jitter): on a block of two members,
    one decaying with rises and one that jumps several bins at once, against the sums
    taken pair by pair.  Every bin is written by the member's start (those above its
    initial level) or its falls, down to the lowest it reached, which its end writes and
    from which the bins below it are read (as :func:`decay.map_estimate` reads them):
    none read keeps what a slot held before (NaN)."""
    B, ng = 2, 2

    @njit
    def run(G):  # G[k, l, j]: the residual of member j at measured state k
        S = decay.map_buffers(B, ng, 1)
        S[:] = np.nan  # a previous member's sums
        lt, lv, base = decay.ladders(B)
        Dv, P, A = np.zeros((ng, B)), np.zeros((ng, B)), np.zeros((10, B))
        gn, dn, gr = np.zeros(B), np.zeros(B), np.zeros(ng)
        low, nlev = np.zeros(B, np.int64), np.zeros(B, np.int64)
        wmax, dmax = np.full(B, -np.inf), np.full(B, -np.inf)
        active = np.ones(B, np.bool_)
        for k in range(G.shape[0]):
            Dv[:, :] = G[k]
            decay.difference_norms(Dv, gr, gn, dn)
            if k == 0:
                for j in range(B):
                    base[j] = decay.ladder_base(dn[j])
                    low[j] = decay.ladder_level(dn[j], base[j]) >> decay.MAP_SHIFT
                    decay.map_begin(S, j, low[j])
            decay.pairs_pooled(Dv, P, A, 1.0 if k > 0 else 0.0, 1)
            changed = decay.block_levels(gn, dn, base, low, nlev, wmax, dmax)
            if changed != 0:
                decay.bin_flush(S, A, nlev, low, changed, 1, 0)
            for j in range(B):
                lt[j, nlev[j]] = float(k)
                lv[j, nlev[j]] = dn[j]
        decay.end_flush(S, A, low, active, 1, 0)
        return S, base, low

    rng = np.random.default_rng(2)
    K = 400
    decay_ = np.exp(-np.linspace(0.0, 40.0, K))
    decay_[300:] = decay_[299] * np.exp(3.0 * rng.standard_normal(100))  # a jittering floor
    jump = np.exp(-np.linspace(0.0, 30.0, K))
    jump[200:] *= 1e-6  # six decades at once: several bins crossed by one state
    phase = rng.uniform(0, 2 * np.pi, (K, 1))
    G = np.empty((K, ng, B))
    for j, amp in enumerate((decay_, jump)):
        G[:, 0, j] = amp * np.cos(phase[:, 0] + j)
        G[:, 1, j] = amp * np.sin(phase[:, 0] + j)
    S, base, low = run(G)
    bits = lambda x: np.frombuffer(np.float64(x).tobytes(), np.int64)[0]  # noqa: E731
    for j in range(B):
        norm = np.abs(G[:, :, j]).max(axis=1)
        level = np.array([min(max((bits(x) >> 49) - base[j], 0), decay.NBINS - 1) for x in norm])
        bins = level >> decay.MAP_SHIFT
        crossed = 0
        for b in range(decay.MAP_BINS):
            below = np.nonzero(bins < b)[0]
            first_below = below[0] if below.size else K
            if b <= bins[0]:
                crossed += first_below < K
            # pairs (g_k, g_k+1) with k < first_below (the last one ends below the bin)
            n = min(first_below, K - 1)
            p, q = G[:n, :, j], G[1:n + 1, :, j]
            if first_below == 0 or b > bins[0]:  # the member started below bin b: none
                p, q = p[:0], q[:0]
            expect = [p[:, 0] @ p[:, 0], p[:, 0] @ p[:, 1], p[:, 0] @ p[:, 1], p[:, 1] @ p[:, 1],
                      q[:, 0] @ p[:, 0], q[:, 0] @ p[:, 1], q[:, 1] @ p[:, 0], q[:, 1] @ p[:, 1],
                      0.0, 0.0, float(len(p))]  # fmt: skip
            np.testing.assert_allclose(S[j, max(b, low[j])], expect, rtol=1e-12, atol=0,
                                       err_msg=f"member {j}, bin {b}")  # fmt: skip
        assert crossed >= 8  # the test crosses bins, several at once for member 1


@pytest.mark.parametrize("c0", [1.0, 0.1, -0.3])
def test_fitted_rate_of_exact_decays(c0):
    """β of exact traces ``|c0 + c1 t| e^{−βt}`` (a repeated eigenvalue's prefactor, its
    zero crossing before the window for c0 < 0), ``e^{−βt}`` and ``e^{−βt}`` times an
    oscillation, each on a floor of seeded noise: the true β within 1 %; γ the smallest
    prefactor of ``e^{−βt}`` over the transient."""
    from stabdae.engine import decay

    beta, c1 = 10.0, 10.0
    t = np.arange(4001) * 0.001  # the floor from t ≈ 2: the last fifth lies on it
    rng = np.random.default_rng(2)
    floor = 1e-9 * (1.0 + 0.5 * rng.random((3, t.size)))
    traces = np.stack([
        np.abs(c0 + c1 * t) * np.exp(-beta * t),
        np.exp(-beta * t),
        np.exp(-beta * t) * (1.2 + np.cos(15.0 * t)),
    ]) + floor  # fmt: skip
    meas = decay.measure_traces(traces, t)
    got, gamma = meas["beta"], meas["gamma"]
    np.testing.assert_allclose(got, beta, rtol=0.01)
    assert meas["fit_kind"][2] == decay.K_OSCILLATING
    assert np.all(meas["floor"] < 1.5e-9) and np.all(meas["floor"] > 1e-9)
    for j in range(3):  # γ e^{−βt} bounds the trace where it lies above 1000 × its floor
        above = traces[j] > 1000 * meas["floor"][j]
        assert np.all(traces[j, above] <= gamma[j] * np.exp(-got[j] * t[above]) * 1.2)
        assert np.any(traces[j, above] >= gamma[j] * np.exp(-got[j] * t[above]) / 1.2)


@pytest.mark.parametrize("c0", [1.0, 0.1, -0.3])
def test_refined_shift_gives_the_repeated_eigenvalue_rate(c0):
    """On ``|c0 + c1 t| e^{−βt}`` with a floor at 1e-13, the ``ν log(t + s)`` fit with its
    shift refined (Brent's method) recovers β to 0.2 %."""
    from stabdae.engine import decay

    t = np.arange(4001) * 0.001
    floor = 1e-13 * (1.0 + 0.5 * np.random.default_rng(2).random(t.size))
    trace = np.abs(c0 + 10.0 * t) * np.exp(-10.0 * t) + floor
    meas = decay.measure_traces(trace[None, :], t)
    assert meas["fit_kind"][0] == decay.K_POLYNOMIAL
    assert abs(meas["beta"][0] / 10.0 - 1) < 0.002


def test_log_normal_is_the_library_logarithm_to_an_ulp():
    """The branch-free logarithm the fits use (so that their loops vectorize) agrees with
    the C library's to one unit in the last place over the whole normal range, and is
    exact at 1."""
    from numba import njit

    from stabdae.engine import decay

    @njit
    def logs(x, out):
        for i in range(x.shape[0]):
            out[i] = decay.log_normal(x[i])

    rng = np.random.default_rng(7)
    x = np.concatenate([np.exp(rng.uniform(-708.0, 709.0, 200_000)),
                        rng.uniform(0.5, 2.0, 200_000), 1.0 + rng.uniform(-1e-6, 1e-6, 10_000),
                        [1.0, 2.0, 0.5, np.sqrt(0.5), np.sqrt(2.0), 2.2250738585072014e-308,
                         1.7976931348623157e308]])  # fmt: skip
    got = np.empty_like(x)
    logs(x, got)
    ref = np.log(x)
    assert (got[x == 1.0] == 0.0).all()
    nz = ref != 0.0
    assert (np.abs(got - ref)[nz] <= np.spacing(np.abs(ref[nz]))).all()


@pytest.mark.parametrize("shift", [0.05, 2.0])
def test_log_prefactor_fit_recovers_an_exact_model(shift):
    """``log ‖g‖ = c − βt + ν log(t + s)`` sampled without noise: the fit at that shift
    returns its β to 1e-9 and a zero sum of squares."""
    from stabdae.engine import decay

    t = np.linspace(0.3, 1.5, 40)
    y = 0.7 - 9.5 * t + 1.0 * np.log(t + shift)
    rt, ry, a, b, lg = decay.scratch()
    rt[:40], ry[:40] = t, y
    beta, sse = decay.fit._fit_with_log(rt, ry, 0, 40, shift, a, b, lg,
                                    decay.fit._shift_free_sums(rt, ry, 0, 40))
    assert abs(beta - 9.5) < 1e-9 and sse < 1e-20


@pytest.mark.parametrize("hint", [2.0, 2.3, 1e-3, 40.0, math.nan])
def test_log_prefactor_search_from_a_hint_finds_the_grids_minimum(hint):
    """The prediction's shift search starts at the measured member's shift: from a hint
    near the true shift (2.0) it finds the exact model's β; from a hint far off (the
    minimum on its bracket's edge) it falls back to the whole grid, as with no hint."""
    from stabdae.engine import decay

    t = np.linspace(0.3, 1.5, 40)
    y = 0.7 - 9.5 * t + 1.0 * np.log(t + 2.0)
    rt, ry, a, b, lg = decay.scratch()
    rt[:40], ry[:40] = t, y
    beta, sse, shift = decay.fit._fit_polynomial(rt, ry, 0, 40, 0.03, a, b, lg, hint)
    grid = decay.fit._fit_polynomial(rt, ry, 0, 40, 0.03, a, b, lg)
    assert abs(beta - 9.5) < 1e-6 and abs(shift - 2.0) < 1e-3
    assert abs(beta - grid[0]) < 1e-6


def test_envelope_logarithms_are_the_librarys():
    """The envelope's log norms (a vectorized logarithm over the row): within an ulp of
    numpy's on normal norms; a row with a zero norm (−inf) or one below the normal floats
    takes the library's log for every point."""
    from stabdae.engine import decay

    lt, lv, _ = decay.ladders(3)
    rt, ry = np.empty(decay.NBINS), np.empty(decay.NBINS)
    k = np.arange(40)
    for j, last in enumerate([None, 0.0, 1e-310]):
        v = np.geomspace(1e3, 1e-200, 40)  # a decay: level 139 - k visited last at time k
        if last is not None:
            v[-1] = last
        lt[j, :] = -1.0
        lt[j, 139 - k] = k
        lv[j, 139 - k] = v
        n = decay.records(lt, lv, j, rt, ry)
        assert n == 40 and (rt[:n] == k).all()
        with np.errstate(divide="ignore"):
            ref = np.log(v)
        if last is None:
            assert (np.abs(ry[:n] - ref) <= np.spacing(np.abs(ref))).all()
        else:
            assert (ry[:n] == ref).all()
            assert ry[n - 1] == (-np.inf if last == 0.0 else math.log(1e-310))


def test_log_prefactor_fit_outside_the_normal_range_is_least_squares():
    """A shift that puts t + s below the normal floats (t from 0, s = 1e-310) takes the
    library's logarithm: the fit is then numpy's least squares on the same columns."""
    from stabdae.engine import decay

    t = np.linspace(0.0, 1.0, 30)
    y = 0.3 - 4.0 * t + 0.01 * np.sin(7.0 * t)
    rt, ry, a, b, lg = decay.scratch()
    rt[:30], ry[:30] = t, y
    beta, sse = decay.fit._fit_with_log(rt, ry, 0, 30, 1e-310, a, b, lg,
                                    decay.fit._shift_free_sums(rt, ry, 0, 30))
    X = np.column_stack([np.ones(30), -t, np.log(t + 1e-310)])
    coef, res = np.linalg.lstsq(X, y, rcond=None)[:2]
    assert abs(beta - coef[1]) < 1e-9 * abs(coef[1])
    assert abs(sse - res[0]) < 1e-6 * res[0]


def test_no_transient_or_growth_gives_no_rate_and_says_why():
    """A trace that sits on its floor, and one that grows, get β = NaN with their
    reasons, never a fitted number.  A trace that falls below its start and then rises
    with its own floor over the last three fifths (a member's deviation that the scheme
    couples to the motion) decayed, as its verdict says: no transient, never "not
    decaying"."""
    from stabdae.engine import decay

    t = np.arange(2001) * 1e-3
    flat = 1e-6 * (1.0 + 0.5 * np.random.default_rng(3).random(t.size))
    growing = 1e-6 * np.exp(3.0 * t)
    rising_floor = np.maximum(np.exp(-10.0 * t), 0.02 + 0.2 * t)
    meas = decay.measure_traces(np.stack([flat, growing, rising_floor]), t)
    assert np.isnan(meas["beta"]).all()
    assert meas["reason"][0] == decay.R_NO_TRANSIENT
    assert meas["reason"][1] == decay.R_NOT_DECAYING
    assert decay.grows(*(rising_floor[(400 * w):(400 * w + 401)].max() for w in (2, 3, 4)))
    assert meas["reason"][2] == decay.R_NO_TRANSIENT


def test_a_prediction_is_stepped_from_its_own_members_alpha():
    """:func:`decay.predict` for a member fitted by its envelope steps ``g_{k+1} = R g_k``
    from its own row of the perturbations: two members along the two eigenvectors of an
    ``R`` with rates 10 and 40 get those rates (a prediction from another row would give
    the other's)."""
    from stabdae.engine.decay import record as rec

    h, nsteps = 1e-3, 400
    V = np.array([[1.0, 1.0], [-10.0, -40.0]])  # eigenvectors (f, ḟ) of the modes
    R = V @ np.diag(np.exp(-h * np.array([10.0, 40.0]))) @ np.linalg.inv(V)
    alphas = (1e-3 * V.T).copy()  # row i along mode i
    lt, lv, base = decay.ladders(2)
    meas = np.full((2, decay.NCOLS), np.nan)
    codes = np.zeros((2, decay.NCODES), np.int64)
    rt, ry, a, b, lg = decay.scratch()
    got = []
    for row in (1, 0):
        codes[row, rec.I_REASON] = decay.R_FITTED
        codes[row, rec.I_KIND] = decay.K_EXPONENTIAL
        meas[row, rec.C_FIT_START], meas[row, rec.C_FIT_END] = 0.02, 0.3
        decay.predict(R, alphas, row, nsteps, h, lt, lv, base, meas, codes, row, row, rt, ry,
                      a, b, lg, np.empty(2), np.empty(2), 0.0)  # fmt: skip
        got.append(meas[row, rec.C_BETA_PRED])
    np.testing.assert_allclose(got, [40.0, 10.0], rtol=1e-6)


def test_fitted_map_is_read_in_the_groups_of_the_law_spectrum():
    """A Jordan block ``[[λ, 1], [0, λ]]`` perturbed by ``δ`` in its corner splits into
    ``λ ± √δ``; read in the group of the law's double eigenvalue its radius is
    ``√|det| = √(λ² − δ)``, off by ``O(δ)``, where the largest eigenvalue is off by
    ``√δ``.  A simple eigenvalue is its group alone (an over-damped law's two rates stay
    apart), and without the law's spectrum the radius is the ``CLUSTER`` rule's."""
    from stabdae.engine.decay import grouped_radius_of, reference_logs, spectral_radius_of

    lam, delta = 0.99, 1e-8
    fitted = np.array([[lam, 1.0], [delta, lam]])
    ref = reference_logs(np.array([[lam, 1.0], [0.0, lam]]))
    assert ref[0] == pytest.approx(math.log(lam), rel=1e-12) and math.isnan(ref[1])
    got = grouped_radius_of(fitted, ref)
    assert got == pytest.approx(math.sqrt(lam * lam - delta), rel=1e-14)
    assert abs(got - lam) < 1e-8 < abs(max(np.abs(np.linalg.eigvals(fitted))) - lam)
    # 3 × 3: the double eigenvalue beside a simple, faster one
    big = np.zeros((3, 3))
    big[:2, :2] = fitted
    big[2, 2] = 0.5
    ref3 = reference_logs(np.array([[lam, 1.0, 0.0], [0.0, lam, 0.0], [0.0, 0.0, 0.5]]))
    assert grouped_radius_of(big, ref3) == pytest.approx(math.sqrt(lam * lam - delta),
                                                         rel=1e-12)  # fmt: skip
    # over-damped: two simple eigenvalues, each its own group: the larger, exactly
    apart = np.array([[0.99 + 1e-9, 0.0], [0.0, 0.9]])
    ref2 = reference_logs(np.diag([0.99, 0.9]))
    assert grouped_radius_of(apart, ref2) == pytest.approx(0.99 + 1e-9, rel=1e-14)
    none = np.full(1, np.nan)
    assert grouped_radius_of(fitted, none) == spectral_radius_of(fitted)


def test_member_rates_at_a_double_eigenvalue():
    """Critically damped ω = 10 with Euler at τ = 1e-4 (``R(τÃ)`` a Jordan block),
    members from 1e-3 to 1e-1: each member's β from its one-step map within 1 % of
    ``−ln ρ/τ`` for at least 98.5 % of them (a fitted map's double eigenvalue, split by a
    perturbation δ of the map by √δ, read as the pair's geometric mean; 58 of 512 were
    off by more than 1 % when the larger of the pair was read)."""
    ds = stabdae.ensemble(load_scene("pendulum"), stabdae.baumgarte(10, 1), "euler", 1e-4,
                          5.0, members=512, radius=(1e-3, 1e-1), seed=1,
                          traces="none")  # fmt: skip
    ratio = ds.beta.values / float(ds.beta_theory_discrete)
    assert np.mean(np.abs(ratio - 1) <= 0.01) >= 0.985


def test_a_floor_rising_with_the_motion_is_no_growth():
    """The double pendulum under Euler (τ = 1e-4, 5 s): each member's deviation from the
    reference trajectory decays by two decades or more, then rises again as its chaotic
    motion drifts from the reference's, and its floor with it.  That late rise is no
    growth that keeps the member from its one-step map, whose window may reach down to
    ``LOW_MARGIN`` times the floor (the forcing there enters the least-squares fit
    weighted by ``‖g_k‖²``): every member 10× above its floor gets a β, the law's rate
    −ln ρ(R)/τ to 1 % (about 60 % did with the window ending 30× above the floor, and the
    rest were said not to decay although their verdicts said they decayed)."""
    model = load_scene("double_pendulum")
    ds = stabdae.ensemble(model, stabdae.baumgarte(10.0, 1.0), "euler", 1e-4, 5.0,
                          members=128, radius=(1e-3, 1e-1), seed=1)  # fmt: skip
    above = ds.alpha0_norm.values >= 10.0 * ds.residual_floor.values
    ratio = ds.beta_ratio.values[above]
    assert above.sum() >= 40 and (ds.verdict.values[above] == Verdict.STABLE).all()
    np.testing.assert_allclose(ratio, 1.0, atol=0.01)


def _generator_rate(A, G, steps, pm, h_ref=0.01):
    """The generator fit's rate (:func:`decay.map_estimate`'s ``gen_h`` path) of the
    residuals ``G`` (one row per accepted state) a step of ``steps`` apart."""
    from scipy.linalg import expm

    from stabdae.engine.decay import onestep

    ng = G.shape[1]
    acc = np.zeros((1, decay.generator_width(ng, pm)))
    g0 = G[:1].copy()
    for k, h in enumerate(steps):
        decay.generator_add(acc, 0, g0, G[k + 1][:, None].copy(), h, pm)
    np.testing.assert_array_equal(g0[0], G[-1])  # the last state carried to the next pair
    ref = decay.reference_logs(expm(h_ref * A))
    rho, pairs = onestep._generator_radius(acc[:, None, :].copy(), 0, ng, pm, 0, ref, h_ref)
    assert pairs == len(steps)
    return -math.log(rho) / h_ref


@pytest.mark.parametrize("case", ["critical", "under", "over", "pooled-two-and-h", "full"])
def test_generator_fit_gives_the_rate_of_an_exact_flow(case):
    """Pairs of the exact flow ``g(t + h) = e^{hA} g(t)`` over uneven steps (``h|λ|``
    from 0.1 to 0.3 for ``A``'s largest eigenvalue): the generator fit's rate is
    ``−max Re λ(A)`` to the (2, 2) Padé form's ``|λ| (h|λ|)⁴/720`` (1.1e-5 ``|λ|``),
    where the trapezoidal fit alone (``A p = d/h``, no Padé sweep) is off by
    ``h² Re λ³/12``: 8e-4 ``|λ|`` and more at the critically and under-damped laws.
    Pooled: the law's 2 × 2 block on every ``(f_i, ḟ_i)`` and a rate on every ``h_j``
    (a critically damped law's double eigenvalue read as its pair's mean); full: any
    stable matrix."""
    from scipy.linalg import expm

    rng = np.random.default_rng(7)

    def baumgarte(omega, xi, m, k, kh=3.0):
        A = np.zeros((2 * m + k, 2 * m + k))
        A[:m, m:2 * m] = np.eye(m)
        A[m:2 * m, :m] = -omega**2 * np.eye(m)
        A[m:2 * m, m:2 * m] = -2 * xi * omega * np.eye(m)
        A[2 * m:, 2 * m:] = -kh * np.eye(k)
        return A

    A, pm = {"critical": (baumgarte(10.0, 1.0, 1, 0), 1),
             "under": (baumgarte(10.0, 0.3, 1, 0), 1),
             "over": (baumgarte(10.0, 2.0, 1, 0), 1),
             "pooled-two-and-h": (baumgarte(8.0, 1.0, 2, 1, kh=2.0), 2),
             "full": (np.array([[-3.0, 1.0, 0.2], [-4.0, -5.0, 0.5],
                                         [0.3, 0.1, -6.0]]), -1)}[case]  # fmt: skip
    beta = -np.linalg.eigvals(A).real.max()
    fastest = np.abs(np.linalg.eigvals(A)).max()
    steps = rng.uniform(0.1, 0.3, 40) / fastest
    G = [rng.standard_normal(A.shape[0])]
    for h in steps:
        G.append(expm(h * A) @ G[-1])
    got = _generator_rate(A, np.array(G), steps, pm)
    assert abs(got - beta) <= fastest * 0.3**4 / 720, (got, beta)


def test_pooled_end_is_the_general_one_and_refuses_other_sums():
    """The fixed-step kernel ends a pooled law's members with
    :func:`decay.map_estimate_pooled`, compiled without reference counting: on pooled sums
    of exact pairs ``g_{k+1} = R g_k`` it writes what :func:`decay.map_estimate` writes,
    bit for bit (β = −ln ρ(R)/τ); given a full map's sums or a generator's, which it
    cannot fit, it raises instead of giving a rate."""
    R = np.array([[0.95, 0.01], [-0.4, 0.9]])
    rng = np.random.default_rng(3)
    p = rng.standard_normal((2, 40))
    q = R @ p
    sums = [p[0] @ p[0], p[0] @ p[1], p[0] @ p[1], p[1] @ p[1], q[0] @ p[0], q[0] @ p[1],
            q[1] @ p[0], q[1] @ p[1], 0.0, 0.0, 40.0]  # fmt: skip
    pooled = np.empty((1, decay.MAP_BINS, 11))
    pooled[0, :] = sums
    lt, lv, _ = decay.ladders(1)
    decay.ladder_clear(lt, 0)
    for b in range(300, 432):  # a decay over 16 octaves, 1/8 octave per 0.01
        lt[0, b] = (431 - b) * 0.01
        lv[0, b] = 2.0 ** ((b - 431) / 8)
    ref = decay.reference_logs(R)
    tau = 1e-3

    def run(fn, S, pm, gen_h=0.0):
        meas = np.full((1, decay.NCOLS), np.nan)
        meas[0, decay.C_D2:decay.C_D4 + 1] = 0.0
        codes = np.zeros((1, decay.NCODES), np.int64)
        rt, ry = np.empty(decay.NBINS), np.empty(decay.NBINS)
        top = decay.ladder_top(lt, 0)
        ok = fn(S, 0, 2, pm, lt, lv, 0, meas, codes, 0, tau, rt, ry, ref, top, 0, gen_h)
        return ok, meas, codes

    general, variant = run(decay.map_estimate, pooled, 1), run(decay.map_estimate_pooled, pooled, 1)
    assert general[0] and variant[0]
    np.testing.assert_array_equal(variant[1], general[1])
    np.testing.assert_array_equal(variant[2], general[2])
    rho = np.abs(np.linalg.eigvals(R)).max()
    assert abs(general[1][0, decay.C_BETA] / (-math.log(rho) / tau) - 1) < 1e-9
    full = np.zeros((1, decay.MAP_BINS, 2 * 2 * 2 + 1))
    assert not run(decay.map_estimate, full, -1)[0]  # (no pairs: no rate)
    with pytest.raises(AssertionError, match="full one-step map"):
        run(decay.map_estimate_pooled, full, -1)
    with pytest.raises(AssertionError, match="generator"):
        run(decay.map_estimate_pooled, pooled, 1, gen_h=tau)


@pytest.mark.parametrize("shape", [(1000, 1), (1000, 2), (999, 7), (0, 3), (5, 30)])
def test_row_reductions_are_numpys(shape):
    """The members' per-row reductions written column by column (``alpha0_norm``, the
    finite initial states, the blown-up statuses) give numpy's reductions along the rows,
    NaN and the infinities included."""
    from stabdae import _measures as M

    rng = np.random.default_rng(shape[0] + shape[1])
    a = rng.standard_normal(shape) * 10.0 ** rng.integers(-300, 300, shape)
    if a.shape[0]:
        for value in (np.nan, np.inf, -np.inf, -0.0):
            a[rng.integers(0, shape[0]), rng.integers(0, shape[1])] = value
    np.testing.assert_array_equal(M.row_max_abs(a), np.max(np.abs(a), axis=1))
    np.testing.assert_array_equal(M.rows_finite(a), np.isfinite(a).all(axis=1))
    status = rng.integers(-3, 9, shape[0]).astype(np.int8)
    np.testing.assert_array_equal(M.blown_up(status),
                                  np.isin(status, [int(s) for s in M._BLOWN_UP]))
