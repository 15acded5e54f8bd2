"""The one-step map ``g_k -> g_{k+1}`` fitted by least squares from binned pairs of
residuals (pooled per constraint block, or full for small residuals); the decay rate
from its spectral radius and the prefactor from the ladder."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..fma import fma
from ..jit import internal, variant
from ..workspace import stack1
from .fit import FLOOR_MARGIN, GAMMA_MARGIN, MIN_DECADES, MIN_POINTS
from .ladder import (
    _TINY,
    LEVELS_PER_OCTAVE,
    LOG2_BOUND,
    NBINS,
    START_LEVEL,
    float_bits,
    float_from_bits,
    ladder_level,
    log2_biased,
    log_normal,
    trailing_zeros,
)
from .record import (
    C_BETA,
    C_D2,
    C_D3,
    C_D4,
    C_FIT_END,
    C_FIT_START,
    C_GAMMA,
    C_INITIAL,
    C_SHIFT,
    C_W0,
    I_KIND,
    I_POINTS,
    I_REASON,
    K_MAP,
    R_FITTED,
)

#: the one-step map is fitted for residuals of at most this many components (its sums
#: take 2 ng² numbers per bin and member)
MAP_MAX_NG = 12
#: its pairs are binned by the ladder level of ``‖g_k‖`` in bins of ``2^MAP_SHIFT``
#: levels (two octaves)
MAP_SHIFT = 4
MAP_BINS = NBINS >> MAP_SHIFT
#: eigenvalues of a fitted map whose rates differ by less than this fraction count as
#: one repeated eigenvalue (:func:`_cluster_radius`); the rate read is then off by at most
#: half of it
CLUSTER = 0.02
#: directions of the whitened pairs with less than this fraction of the largest's sum
#: of squares are left out of the fit (no transient moves there: what is seen there is
#: the floor's motion)
MAP_RANK_TOL = 1e-12
#: the pairs used lie above this many times the floor (then ``FLOOR_MARGIN``, then
#: ``LOW_MARGIN``)
MAP_MARGIN = 100.0
#: the one-step map's and the generator's window may reach down to this many times the
#: floor (after ``MAP_MARGIN`` and ``FLOOR_MARGIN``): what is left there is the forcing
#: of the member's distance from the reference by the motion (the scheme's local errors
#: along two trajectories; on adaptive steps, also steps that fall apart from the
#: reference's), which enters the least-squares fit weighted by ``‖g_k‖²``: the
#: transient's top sets the fit, and the forcing moves the rate by about ``floor / top``
LOW_MARGIN = 10.0
#: all pairs are used when the largest norm fell from each of the last three fifths to
#: the next, by this factor from the third to the fifth: the run ended inside the
#: transient, where the largest norm of the last fifth is no floor (the map needs no
#: window that ends above a floor, so a slower fall than the envelope's
#: ``STILL_DECAYING`` suffices)
MAP_STILL_DECAYING = 2.0


# --------------------------------------------------------------------- one-step map
@njit(cache=True)
def map_buffers(rows, ng, pm):
    """The one-step map's sums for ``rows`` members at a time: per member and bin ``b``
    the sums of the pairs' outer products and their number (:func:`map_width` columns)
    over the pairs ``(g_k, g_{k+1})`` with ``g_k`` before the member's measured norm
    first fell below bin ``b`` (below ladder level ``b · 2^MAP_SHIFT``): the pairs of the
    transient above that level, none of the floor's once the floor lies below it.

    (Binned by when rather than by each pair's level, so that a member adds to its bins
    once per bin crossed: a residual on its floor moves between levels at random, and
    a member that moved its sums at every change of bin did so at every few measured
    states, about a fifth of the measurement's cost on the pendulum.)

    Not cleared: every bin a member's end reads is written for that member, by its
    start (:func:`map_begin`, those above its initial bin), its falls
    (:func:`bin_flush`) or its end (:func:`end_flush`, the lowest bin it reached, from
    which the end reads the bins below it).  (Zeroed, they were 180 kB written for a
    block of 64 pooled members at every call of the kernel on a chunk of blocks: 26 calls
    for 10⁴ members on two threads.)"""
    return np.empty((rows, MAP_BINS, map_width(ng, pm)))


@njit(cache=True)
def map_width(ng, pm):
    """The one-step map's sums per bin.

    With ``pm ≥ 0`` the law acts alike on each of the ``pm`` holonomic constraints (one
    2 × 2 block on every ``(f_i, ḟ_i)``) and on each nonholonomic one (one number on
    every ``h_j``): the pairs of all constraints are pooled into one 2 × 2 and one 1 × 1
    fit (11 sums).  Otherwise the full ``ng × ng`` map is fitted (``2 ng² + 1`` sums),
    for residuals of at most ``MAP_MAX_NG`` components (none above)."""
    if pm >= 0:
        return 11
    return 2 * ng * ng + 1 if ng <= MAP_MAX_NG else 0


@njit(cache=True, _nrt=False)
def map_begin(S, j, low):
    """Slot ``j``'s sums for a new member, whose initial level is in bin ``low``: those
    of the bins above it cleared (no pair comes before a fall below them).  Those down
    to the lowest it reaches are written before the member's end (:func:`bin_flush`,
    :func:`end_flush`); the end reads the bins below that one from it."""
    for b in range(low + 1, S.shape[1]):
        for c in range(S.shape[2]):
            S[j, b, c] = 0.0


def full_rows(ng: int) -> int:
    """The rows of the full one-step map's running sums (:func:`pairs_full`) for a residual
    of ``ng`` components: Σ p pᵀ's upper triangle, Σ p' pᵀ, the count; 1 when
    ``ng > MAP_MAX_NG`` (no full map)."""
    return ng * (ng + 1) // 2 + ng * ng + 1 if ng <= MAP_MAX_NG else 1


# The decay measurement of a block of members in lockstep (the ensemble kernel's): what
# :func:`observe` and the one-step map's sums do member by member, here for the whole block
# at once, in loops over its members (structure of arrays, member index innermost: they
# vectorize), with the scattered writes deferred:
#
# * the ladder: each member's level (``block_levels``, vectorized), then the time and norm
#   written on it (by the kernel, a scatter);
# * the one-step map: the pairs' running sums in ``A`` (a row per sum, the symmetric
#   ``Σ p pᵀ`` once), copied to the member's row of ``S`` for each bin its level goes below
#   for the first time (``bin_flush``: a scalar loop over the members whose bit is set in
#   the mask ``block_levels`` returns; a member crosses each bin once, where a flush at
#   every change of bin came at every few measured states of a residual on its floor), and
#   at the end for the lowest bin it reached (``end_flush``: the bins below hold the same
#   sums, read from that one);
# * the largest norms of the current fifth of the run in ``wmax`` and ``dmax``, written to
#   the member's row when the fifth ends or the member stops (``windows_flush``).
#
# The ladder is :func:`observe`'s; bin ``b`` of the map's sums holds the pairs whose first
# state came before the member's level first went below bin ``b`` (:func:`map_buffers`).
# The block's size, the residual's and the constraints' come from the arrays' shapes and
# the arguments, not from a closure: a closure per model was compiled on its own at each
# new model's first ensemble (about a second in all).  Compiled once for every model
# (cached) and inlined into the kernel, whose buffers have constant shapes.  (The
# ladder's scatter is written in the kernel itself, and the full map's pairs and flushes
# are closures, :func:`pairs_full_for` and :func:`flushes_for`: optimized on their own
# over unknown sizes first, the scatter lost its vectorization and the copies their
# unrolling, and the kernels were measurably slower: studies/README.md.)


@njit(cache=True, forceinline=True, error_model="numpy")
def difference_norms(Dv, gr, gn, dn):
    """The block's residuals ``Dv`` (``g``, one column per slot) made ``g − gr``; their
    norms ``‖g‖∞`` into ``gn`` and ``‖g − gr‖∞`` into ``dn``."""
    ng, B = Dv.shape
    for j in range(B):
        gn[j] = 0.0
        dn[j] = 0.0
    for l in range(ng):
        r = gr[l]
        for j in range(B):
            g = Dv[l, j]
            d = g - r
            Dv[l, j] = d
            gn[j] = max(gn[j], abs(g))
            dn[j] = max(dn[j], abs(d))


@njit(cache=True, forceinline=True, error_model="numpy")
def pairs_pooled(Dv, P, A, w, pm):
    """The pairs (``P``: the previous measured residuals, ``Dv``: the current; their first
    ``2 pm`` rows ``(f, ḟ)``, ``pm`` the holonomic constraints) added with weight ``w`` (0:
    no previous one yet) to the pooled sums (10 rows: Σ p pᵀ's 3, Σ p' pᵀ's 4 over
    ``p = (f_i, ḟ_i)``, Σ h², Σ h' h, the count); then ``P = Dv``."""
    ng, B = Dv.shape
    for i in range(pm):
        for j in range(B):
            a0 = P[i, j]
            a1 = P[pm + i, j]
            c0 = Dv[i, j]
            c1 = Dv[pm + i, j]
            A[0, j] += w * (a0 * a0)
            A[1, j] += w * (a0 * a1)
            A[2, j] += w * (a1 * a1)
            A[3, j] += w * (c0 * a0)
            A[4, j] += w * (c0 * a1)
            A[5, j] += w * (c1 * a0)
            A[6, j] += w * (c1 * a1)
    for i in range(2 * pm, ng):
        for j in range(B):
            A[7, j] += w * (P[i, j] * P[i, j])
            A[8, j] += w * (Dv[i, j] * P[i, j])
    for j in range(B):
        A[9, j] += w
    for l in range(ng):
        for j in range(B):
            P[l, j] = Dv[l, j]


@njit(cache=True, forceinline=True, error_model="numpy")
def block_levels(gn, dn, base, low, nlev, wmax, dmax):
    """The block's norms ``gn`` (of ``g``) and ``dn`` (measured) at a state: the largest of
    the fifth, each slot's ladder level into ``nlev`` (``NBINS``, the ladder's spare
    column, for a non-finite norm, which :func:`observe` leaves out); returns a mask of
    the slots whose level went below ``low``, the lowest of the map's bins they had
    reached (at most 64 slots)."""
    changed = 0
    for j in range(gn.shape[0]):
        v = gn[j]
        wm = wmax[j]
        wmax[j] = v if (v < math.inf and not (wm >= v)) else wm
        d = dn[j]
        ok = d < math.inf
        dm = dmax[j]
        dmax[j] = d if (ok and not (dm >= d)) else dm
        b = ladder_level(d, base[j])
        nlev[j] = b if ok else NBINS
        lower = ok and (b >> MAP_SHIFT) < low[j]
        changed |= (1 if lower else 0) << j
    return changed


@njit(cache=True, forceinline=True, _nrt=False)
def _store(S, A, j, bin_, pooled, full):
    """Slot ``j``'s sums so far as those of its bin ``bin_`` (``pooled ≥ 0``: the pooled
    map's; else the full map's of ``full`` components, none when 0)."""
    if pooled >= 0:
        S[j, bin_, 0] = A[0, j]
        S[j, bin_, 1] = A[1, j]
        S[j, bin_, 2] = A[1, j]
        S[j, bin_, 3] = A[2, j]
        for c in range(4):
            S[j, bin_, 4 + c] = A[3 + c, j]
        S[j, bin_, 8] = A[7, j]
        S[j, bin_, 9] = A[8, j]
        S[j, bin_, 10] = A[9, j]
    elif full:
        c = 0
        for r in range(full):
            for q in range(r, full):
                S[j, bin_, r * full + q] = A[c, j]
                if q != r:
                    S[j, bin_, q * full + r] = A[c, j]
                c += 1
        for r in range(full * full):
            S[j, bin_, full * full + r] = A[c, j]
            c += 1
        S[j, bin_, 2 * full * full] = A[c, j]


@njit(cache=True, error_model="numpy", _nrt=False)
def bin_flush(S, A, nlev, low, mask, pooled, full):
    """The slots of the set bits of ``mask``, whose level went below the lowest bin they
    had reached: their sums so far (the pair just added, from a state above, included)
    become those of each bin passed, down to the new one's, which is then the lowest
    (``pooled``, ``full``: :func:`_store`)."""
    while mask != 0:
        j = trailing_zeros(mask)
        mask &= mask - 1
        nb = nlev[j] >> MAP_SHIFT
        for b in range(nb + 1, low[j] + 1):
            _store(S, A, j, b, pooled, full)
        low[j] = nb


@njit(cache=True, error_model="numpy", _nrt=False)
def end_flush(S, A, low, active, pooled, full):
    """At the end of the run: each running slot's sums as those of the lowest bin it
    reached, ``low[j]`` (zero when no state was measured).  The bins below hold the same
    sums and are not written: the member's end reads bin ``max(b, low[j])`` for bin ``b``
    (:func:`map_estimate`'s ``low_bin``)."""
    for j in range(low.shape[0]):
        if active[j]:
            _store(S, A, j, low[j], pooled, full)


@njit(cache=True, error_model="numpy", _nrt=False)
def windows_flush(meas, wmax, dmax, window, active, lo, cnt):
    """The largest norms of fifth ``window`` so far to the rows of the running members;
    then cleared."""
    for j in range(cnt):
        if active[j]:
            window_flush(meas, wmax, dmax, window, j, lo + j)
    for j in range(wmax.shape[0]):
        wmax[j] = -math.inf
        dmax[j] = -math.inf


@njit(cache=True, forceinline=True, error_model="numpy", _nrt=False)
def window_flush(meas, wmax, dmax, window, j, row):
    """Slot ``j``'s largest norms of fifth ``window`` so far to its member's row ``row``
    (kept in the slot: a largest norm flushed twice is the same largest norm).  Each
    member's are flushed when the fifth ends (:func:`windows_flush`), or before it
    stops."""
    c = C_W0 + window
    if wmax[j] > -math.inf and not (meas[row, c] >= wmax[j]):
        meas[row, c] = wmax[j]
    if window >= 2:
        c = C_D2 + window - 2
        if dmax[j] > -math.inf and not (meas[row, c] >= dmax[j]):
            meas[row, c] = dmax[j]


def pairs_full_for(B: int, ng: int):
    """As :func:`pairs_pooled` for the full map of ``ng`` components over blocks of ``B``
    slots, ``pairs(Dv, P, A, w)`` (``A``: :func:`full_rows` rows): Σ p pᵀ (upper
    triangle), Σ p' pᵀ, the count.  A closure over the sizes, compiled per kernel that
    uses it: sized by its arrays and optimized on its own, its 2 ng² short loops each
    checked their arrays for overlap at run time (slower; studies/README.md has the
    figures)."""

    @internal(forceinline=True, error_model="numpy")
    def pairs_full(Dv, P, A, w):
        c = 0
        for r in range(ng):
            for q in range(r, ng):
                for j in range(B):
                    A[c, j] += w * (P[r, j] * P[q, j])
                c += 1
        for r in range(ng):
            for q in range(ng):
                for j in range(B):
                    A[c, j] += w * (Dv[r, j] * P[q, j])
                c += 1
        for j in range(B):
            A[c, j] += w
        for l in range(ng):
            for j in range(B):
                P[l, j] = Dv[l, j]

    return pairs_full


def flushes_for(FULL: int):
    """``(bin_flush, end_flush)`` for a kernel whose one-step map is the full one of
    ``FULL`` components: closures over it (the full map's copy of a slot's sums, sized
    at run time in :func:`bin_flush`, was slower than this unrolled one with a full law
    matrix).  For ``FULL = 0`` (the pooled
    map, or none) :func:`bin_flush` and :func:`end_flush` themselves, compiled once for
    every model.  Both take ``(…, pooled, full)`` as those do."""
    if not FULL:
        return bin_flush, end_flush

    @internal(forceinline=True)
    def _store_full(S, A, j, bin_):
        c = 0
        for r in range(FULL):
            for q in range(r, FULL):
                S[j, bin_, r * FULL + q] = A[c, j]
                if q != r:
                    S[j, bin_, q * FULL + r] = A[c, j]
                c += 1
        for r in range(FULL * FULL):
            S[j, bin_, FULL * FULL + r] = A[c, j]
            c += 1
        S[j, bin_, 2 * FULL * FULL] = A[c, j]

    @internal(error_model="numpy")
    def bin_flush_full(S, A, nlev, low, mask, pooled, full):
        while mask != 0:
            j = trailing_zeros(mask)
            mask &= mask - 1
            nb = nlev[j] >> MAP_SHIFT
            for b in range(nb + 1, low[j] + 1):
                _store_full(S, A, j, b)
            low[j] = nb

    @internal(error_model="numpy")
    def end_flush_full(S, A, low, active, pooled, full):
        for j in range(low.shape[0]):
            if active[j]:
                _store_full(S, A, j, low[j])

    return bin_flush_full, end_flush_full


# (the radii that allocate nothing, and γ's pass: compiled without reference counting,
# as the member's functions, :mod:`.member`)
@njit(cache=True, _nrt=False)
def _cluster_radius(moduli, n):
    """The largest modulus, or the geometric mean of those within ``CLUSTER`` of it in
    rate (``ln`` of the modulus): a repeated eigenvalue (a Jordan block, as critically
    damped laws give) splits by the square root of a perturbation of the matrix, its
    mean by the perturbation itself."""
    top = 0.0
    for i in range(n):
        top = max(top, moduli[i])
    if not (top > 0.0) or top == math.inf:
        return top
    width = CLUSTER * abs(math.log(top))
    logs = 0.0
    count = 0
    for i in range(n):
        if moduli[i] > 0.0 and math.log(top / moduli[i]) <= width:
            logs += math.log(moduli[i])
            count += 1
    return math.exp(logs / count)


#: eigenvalues of the law's one-step map ``R`` whose ``ln`` moduli differ by less than
#: this (relative) are one repeated eigenvalue (:func:`reference_logs`)
SAME_MODULUS = 1e-6
#: a law's one-step map within this (relative to its diagonal) of a multiple of the
#: identity is one (:func:`reference_logs`): a fitted map constrained to ``c I`` is then
#: off by at most about this much
SCALAR_MAP = 1e-9


@njit(cache=True)
def _scalar_log(R):
    """``ln |c|`` where ``R`` is ``c I`` (within ``SCALAR_MAP``) with ``c ≠ 0``, else NaN."""
    n = R.shape[0]
    c = 0.0
    for i in range(n):
        c += R[i, i]
    c /= n
    if not (abs(c) > 0.0) or not math.isfinite(c):
        return math.nan
    for i in range(n):
        for q in range(n):
            if abs(R[i, q] - (c if i == q else 0.0)) > SCALAR_MAP * abs(c):
                return math.nan
    return math.log(abs(c))


@njit(cache=True)
def reference_logs(R):
    """The distinct ``ln |λ|`` of the eigenvalues of the law's one-step map ``R`` (NaN
    entries past the distinct ones; none for an empty ``R`` or a zero eigenvalue's
    ``−inf``): the groups a fitted map's eigenvalues are read in (:func:`_grouped`).

    Where ``R`` is a multiple ``c I`` of the identity (within ``SCALAR_MAP``), the one
    entry ``ln |c|``, without padding: the fits then take ``R̂ = ĉ I``
    (:func:`is_scalar_law`).  Every member's residual then keeps the direction of its
    ``α⁰``, so its pairs span one direction and a general fit reads the floor's motion
    across it as a second mode (the midpoint rule at ``τω = 1``, ``ξ = 1``: ``R = I/2``,
    and the general 2 × 2 fit read rates from 0.3 to 2.8 times the law's)."""
    n = R.shape[0]
    out = np.full(max(n, 1), math.nan)
    if n == 0:
        return out
    for i in range(n):
        for q in range(n):
            if not math.isfinite(R[i, q]):
                return out
    if n > 1:
        x = _scalar_log(R)
        if x == x:
            one = np.empty(1)
            one[0] = x
            return one
    lam = np.linalg.eigvals(R.astype(np.complex128))
    count = 0
    for i in range(n):
        m = abs(lam[i])
        if not (m > 0.0):
            continue
        x = math.log(m)
        new = True
        for c in range(count):
            if abs(x - out[c]) <= SAME_MODULUS * max(abs(x), 1e-300):
                new = False
        if new:
            out[count] = x
            count += 1
    return out


@njit(cache=True)
def is_scalar_law(ref):
    """Whether ``ref`` (:func:`reference_logs`) is that of a law whose one-step map is a
    multiple of the identity (one finite entry, as only such a map of size > 1, or one
    of size 1, gives)."""
    return ref.shape[0] == 1 and math.isfinite(ref[0])


@njit(cache=True, _nrt=False)
def _grouped(moduli, n, ref):
    """The rate a fitted map's eigenvalue moduli give, read in the groups of the law's
    spectrum ``ref`` (:func:`reference_logs`): each modulus joins the group of the nearest
    ``ln |λ|`` of ``R``, and the radius is the geometric mean of the moduli in the group
    of the largest ``ln |λ|`` that has any.  A repeated eigenvalue of ``R`` (a Jordan
    block, as a critically damped law gives) splits under a perturbation ``δ`` of the
    fitted map by ``√δ``, its group's mean (the cluster's determinant) by ``δ``; a simple
    eigenvalue is its group alone.  Without ``ref`` (a law that is not constant), the
    moduli within ``CLUSTER`` of the largest in rate (:func:`_cluster_radius`)."""
    if ref.shape[0] == 0 or not (ref[0] == ref[0]):
        return _cluster_radius(moduli, n)
    for i in range(n):
        if not (moduli[i] > 0.0) or moduli[i] == math.inf:
            return _cluster_radius(moduli, n)
    best = -1
    for i in range(n):
        g = _nearest(math.log(moduli[i]), ref)
        if best < 0 or ref[g] > ref[best]:
            best = g
    logs = 0.0
    count = 0
    for i in range(n):  # (each modulus's group found again: no array to keep them in)
        x = math.log(moduli[i])
        if _nearest(x, ref) == best:
            logs += x
            count += 1
    return math.exp(logs / count)


@njit(cache=True, forceinline=True, _nrt=False)
def _nearest(x, ref):
    """The index of the entry of ``ref`` (:func:`reference_logs`) nearest ``x``."""
    g = 0
    for c in range(ref.shape[0]):
        if ref[c] == ref[c] and abs(x - ref[c]) < abs(x - ref[g]):
            g = c
    return g


@njit(cache=True, _nrt=False)
def _radius2_grouped(r00, r01, r10, r11, ref):
    """``ρ`` of the fitted 2 × 2 map ``[[r00, r01], [r10, r11]]`` read in the groups of
    the law's spectrum (:func:`_grouped`); :func:`_radius2` without it."""
    if ref.shape[0] == 0 or not (ref[0] == ref[0]):
        return _radius2(r00, r01, r10, r11)
    half = 0.5 * (r00 + r11)
    det = r00 * r11 - r01 * r10
    disc = half * half - det
    if not (disc == disc) or not math.isfinite(half):
        return math.nan
    m = stack1(2)
    if disc < 0.0:  # a complex pair: one modulus
        m[0] = math.sqrt(det)
        m[1] = m[0]
    else:
        m[0] = abs(half + math.sqrt(disc))
        m[1] = abs(half - math.sqrt(disc))
    return _grouped(m, 2, ref)


@njit(cache=True, _nrt=False)
def _radius2(r00, r01, r10, r11):
    """:func:`spectral_radius_of` of the 2 × 2 matrix ``[[r00, r01], [r10, r11]]`` in
    closed form, without arrays (NaN for non-finite entries)."""
    half = 0.5 * (r00 + r11)
    det = r00 * r11 - r01 * r10
    disc = half * half - det
    if disc < 0.0:
        return math.sqrt(det)
    big = abs(half + math.sqrt(disc))
    small = abs(half - math.sqrt(disc))
    if big < small:
        big, small = small, big
    if not (big > 0.0) or big == math.inf or not (small > 0.0):
        return big
    if math.log(big / small) <= CLUSTER * abs(math.log(big)):  # as _cluster_radius
        return math.sqrt(big * small)
    return big


@njit(cache=True)
def spectral_radius_of(R):
    """``ρ(R)`` of a small real matrix (closed form up to 2 × 2), where eigenvalues of
    nearly the same modulus count as one repeated eigenvalue (:func:`_cluster_radius`):
    the rate an ensemble measures from a fitted map, and the one a finite run shows."""
    n = R.shape[0]
    if n == 1:
        return abs(R[0, 0])
    if n == 2:
        return _radius2(R[0, 0], R[0, 1], R[1, 0], R[1, 1])
    moduli = _moduli(R)
    return math.nan if moduli.size == 0 else _cluster_radius(moduli, n)


@njit(cache=True)
def grouped_radius_of(R, ref):
    """:func:`spectral_radius_of` of a fitted map, its eigenvalues read in the groups of
    the law's spectrum ``ref`` (:func:`_grouped`)."""
    n = R.shape[0]
    if n == 2:
        return _radius2_grouped(R[0, 0], R[0, 1], R[1, 0], R[1, 1], ref)
    if n == 1:
        return abs(R[0, 0])
    moduli = _moduli(R)
    return math.nan if moduli.size == 0 else _grouped(moduli, n, ref)


@njit(cache=True)
def _moduli(R):
    """The moduli of ``R``'s eigenvalues; empty where ``R`` has a non-finite entry."""
    n = R.shape[0]
    for i in range(n):
        for q in range(n):
            if not math.isfinite(R[i, q]):
                return np.empty(0)
    # complex input: numba's real eigvals refuses complex eigenvalues
    lam = np.linalg.eigvals(R.astype(np.complex128))
    moduli = np.empty(n)
    for i in range(n):
        moduli[i] = abs(lam[i])
    return moduli


@njit(cache=True, _nrt=False)
def _pooled_radius(S, j, first, ref):
    """``ρ`` of the pooled fits (:func:`map_buffers`): the larger of the 2 × 2 map of
    the ``(f_i, ḟ_i)`` pairs and the 1 × 1 map of the ``h_j``, each where it has data,
    from the pairs of bin ``first`` (those before the level first fell below it); the
    number of pairs."""
    s = stack1(11)
    for c in range(11):
        s[c] = S[j, first, c] if first < S.shape[1] else 0.0
    if is_scalar_law(ref):  # R̂ = ĉ I over the pairs of both blocks
        den = s[0] + s[3] + s[8]
        rho = abs(s[4] + s[7] + s[9]) / den if den > 0.0 else math.nan
        return rho, s[10]
    rho = -1.0
    det = s[0] * s[3] - s[1] * s[2]
    if s[0] > 0.0 and s[3] > 0.0 and abs(det) > 1e-14 * s[0] * s[3]:  # S1 S0⁻¹
        rho = _radius2_grouped((s[4] * s[3] - s[5] * s[2]) / det,
                               (s[5] * s[0] - s[4] * s[1]) / det,
                               (s[6] * s[3] - s[7] * s[2]) / det,
                               (s[7] * s[0] - s[6] * s[1]) / det, ref)  # fmt: skip
    if s[8] > 0.0:
        rho = max(rho, abs(s[9] / s[8]))
    return (rho if rho >= 0.0 else math.nan), s[10]


@njit(cache=True)
def _spanned(S0, S1, S2):
    """``S0 = Σ p pᵀ`` whitened (each component scaled to unit sum of squares), with
    ``S1`` and ``S2`` (sums over the same pairs, ``Σ u pᵀ``; ``S2`` may be ``S1``, scaled
    once) alike, in place; and the directions the pairs span: the eigenvalues of the
    whitened ``S0`` at least ``MAP_RANK_TOL`` of its largest, with their eigenvectors
    (none where it is zero).

    Baumgarte's law acts alike on every constraint, so the residual of m constraints moves
    in a plane of its 2m dimensions, and a fit over all of them gives the remaining
    directions the floor's dynamics."""
    ng = S0.shape[0]
    w = np.zeros(ng)
    for r in range(ng):
        if S0[r, r] > 0.0:
            w[r] = 1.0 / math.sqrt(S0[r, r])
    for r in range(ng):
        for q in range(ng):
            S0[r, q] *= w[r] * w[q]
            S1[r, q] *= w[r] * w[q]
            if S2 is not S1:
                S2[r, q] *= w[r] * w[q]
    lam, U = np.linalg.eigh(S0)
    top = lam[ng - 1]
    if not (top > 0.0):
        return np.empty(0), np.empty((ng, 0))
    keep = 0
    for i in range(ng):
        if lam[i] >= MAP_RANK_TOL * top:
            keep += 1
    return lam[ng - keep:].copy(), np.ascontiguousarray(U[:, ng - keep:])


@njit(cache=True)
def _map_radius(S, j, ng, first, ref):
    """``ρ`` of the least-squares one-step map ``R̂ = S1 S0⁻¹`` from bin ``first`` of
    slot ``j`` (the pairs before its level first fell below that bin), on the directions
    its pairs span, and the number of pairs; NaN with fewer than ``2 ng`` pairs."""
    S0 = np.zeros((ng, ng))
    S1 = np.zeros((ng, ng))
    pairs = 0.0
    if first < S.shape[1]:
        c = 0
        for r in range(ng):
            for q in range(ng):
                S0[r, q] = S[j, first, c]
                c += 1
        for r in range(ng):
            for q in range(ng):
                S1[r, q] = S[j, first, c]
                c += 1
        pairs = S[j, first, c]
    if is_scalar_law(ref) and pairs >= 1.0:  # R̂ = ĉ I
        num = 0.0
        den = 0.0
        for r in range(ng):
            num += S1[r, r]
            den += S0[r, r]
        return (abs(num) / den if den > 0.0 else math.nan), pairs
    if pairs < 2.0 * ng:
        return math.nan, pairs
    lam, V = _spanned(S0, S1, S1)
    keep = lam.shape[0]
    if keep == 0:
        return math.nan, pairs
    # R̂ on that subspace: (Vᵀ S1 V)(Vᵀ S0 V)⁻¹, Vᵀ S0 V the kept eigenvalues
    Rr = np.ascontiguousarray(V.T) @ S1 @ V
    for q in range(keep):
        for r in range(keep):
            Rr[r, q] /= lam[q]
    return grouped_radius_of(Rr, ref), pairs


@njit(cache=True, error_model="numpy", _nrt=False)
def _map_gamma(lt, lv, j, lo, top, beta, w):
    """``γ = max ‖g(t)‖ e^{βt}`` over the envelope's points on levels ``lo … top`` of
    ladder row ``j``, and the latest time on them (``β > 0``; ``w``: scratch of
    ``NBINS``).

    Taken over every visited level, not only the envelope's: a level's last visit that
    is not on the envelope has a higher level visited later, whose larger norm at a later
    time gives a larger product (β > 0), so the maximum is the same.  Without the
    envelope's running comparison, as the largest ``ln ‖g‖ + βt`` (the exponential taken
    once, of the largest: it is monotone), in two passes.  The first, branch-free, which
    LLVM vectorizes whole, takes ``log2 ‖g‖ + βt/ln 2`` within ``LOG2_BOUND``
    (:func:`.ladder.log2_biased`), positive, so that its maximum is an integer maximum of
    the bits (as is the latest time's: a visited level's time is ≥ 0, an unvisited one's
    −1, whose bits are negative).  The second takes the exact ``ln ‖g‖ + βt``
    (:func:`log_normal`) on the levels that came within twice the bound of the first's
    largest only (between the first and the last of them): the largest exact one is
    among them.  (A zero or subnormal norm, where
    neither logarithm holds, is left out: a zero's product is zero, and a subnormal one,
    below 1e-308, lies on the ladder's bottom level, far under any transient.)

    The levels are indexed unsigned: numba wraps a negative index around, and an index
    that may be negative (``lo`` is not known to be ≥ 0) turns every load of the
    vectorized loop into a gather (several times the time of the whole pass)."""
    lo = max(lo, 0)
    ltj = lt[j]
    lvj = lv[j]
    n = top + 1 - lo
    rate = beta / math.log(2.0)
    best = float_bits(0.0)
    latest = float_bits(-1.0)
    for i in range(n):
        b = np.uint64(lo + i)
        t = ltj[b]
        v = lvj[b]
        ok = (t >= 0.0) & (v >= _TINY) & (v < math.inf)
        x = fma(rate, t, log2_biased(v)) if ok else 0.0
        w[np.uint64(i)] = x
        best = max(best, float_bits(x))
        latest = max(latest, float_bits(t))
    if best == float_bits(0.0):
        return 0.0, float_from_bits(latest)
    rough = float_from_bits(best)
    # (the margin past 2 LOG2_BOUND: the roundoff of keys up to ~10³)
    cut = rough - 2.0 * LOG2_BOUND - 1e-12 * rough
    # the first and last of those levels, in a scan without branches (a loop that tested
    # each level in turn took a third of the function's time)
    first = n
    last = -1
    for i in range(n):
        near = w[np.uint64(i)] >= cut
        first = min(first, i if near else n)
        last = max(last, i if near else -1)
    top_w = -math.inf
    for i in range(first, last + 1):
        if w[np.uint64(i)] >= cut:
            b = np.uint64(lo + i)
            top_w = max(top_w, log_normal(lvj[b]) + beta * ltj[b])
    return math.exp(top_w), float_from_bits(latest)


@njit(cache=True)
def map_estimate(S, j, ng, pm, lt, lv, base_j, meas, codes, row, tau, rt, ry, ref, top,
                 lowest=0, gen_h=0.0, floor_min=0.0, low_bin=0, noise=0.0):  # fmt: skip
    """β of member ``row`` from its one-step map, replacing the envelope's fit.

    The residual's pairs ``(g_k, g_{k+1})``, all of them when the run ended while it was
    still decaying (``MAP_STILL_DECAYING``), else those from its start until its level
    first fell below ``MAP_MARGIN`` (then ``FLOOR_MARGIN``, then ``LOW_MARGIN``)
    times its floor (rounded up to a bin of :func:`map_buffers`; for a member that rose
    above its start, at most to the start's bin, which holds the rise), give ``R̂`` by
    least squares; ``β = −ln ρ(R̂)/τ``.
    ``ref``: the law's spectrum (:func:`reference_logs`; NaN: none), in whose groups the
    fitted map's eigenvalues are read (:func:`_grouped`).
    For a residual that follows ``g_{k+1} = R g_k`` this is ``−ln ρ(R)/τ`` exactly,
    whatever the window, the modes' mix or a repeated eigenvalue's polynomial prefactor,
    where a fit of the norm's envelope over a short transient is biased.  The pairs must
    span a decade (``MIN_DECADES``) above the cut; a member without such pairs, or whose
    map is singular or has ``ρ ≥ 1``, is left to the envelope's fit
    (:func:`fit_envelope`).
    ``lowest``: no level below it was visited (γ's pass starts there).  ``gen_h > 0``:
    ``S`` holds the sums of the generator (adaptive steps, :func:`generator_add`), read
    on the scale of a step ``gen_h`` (``ref``'s); ``β = −max Re λ(Â)``.  ``floor_min``:
    the least floor the cut is taken from (an adaptive member's distance from the
    reference has a floor of its own, the local errors of steps that fall apart from the
    reference's, which its last fifth may not show).  ``low_bin``: the lowest bin the
    member's level went below, whose sums are those of every bin below it too (read from
    it: :func:`end_flush`).  ``top``: the highest level visited (:func:`.ladder.ladder_top`).
    Returns whether it gave β."""
    if S.shape[2] == 0:
        return False
    floor = max(meas[row, C_D4], floor_min)
    still = (meas[row, C_D2] > meas[row, C_D3] > meas[row, C_D4]
             and meas[row, C_D2] >= MAP_STILL_DECAYING * meas[row, C_D4])  # fmt: skip
    per_decade = LEVELS_PER_OCTAVE * math.log2(10.0) * MIN_DECADES
    for margin in (-1.0, MAP_MARGIN, FLOOR_MARGIN, LOW_MARGIN):
        if margin < 0.0:  # still decaying: the last fifth's largest norm is no floor
            if not still:
                continue
            cut = 0
        elif floor > 0.0:
            cut = ladder_level(margin * floor, base_j) + 1
        else:
            cut = 0
        if top - cut < per_decade:
            continue
        first = (cut + (1 << MAP_SHIFT) - 1) >> MAP_SHIFT  # bins wholly above the cut
        # (the bins below low_bin hold its sums; those above the start's hold none, the
        # start being the first fall below them, so that the pairs of a member that rose
        # above its start and fell back are read from the start's bin, which ends at most
        # a bin below the cut)
        read = min(max(first, low_bin), START_LEVEL >> MAP_SHIFT)
        if gen_h > 0.0:
            rho, pairs = _generator_radius(S, j, ng, pm, read, ref, gen_h)
            # too few steps above this cut: a lower one has more
            if pairs < MIN_POINTS:
                continue
        else:
            rho, pairs = (_pooled_radius(S, j, read, ref) if pm >= 0
                          else _map_radius(S, j, ng, read, ref))  # fmt: skip
        if not (rho < 1.0 and rho > 0.0):
            return False
        beta = -math.log(rho) / (gen_h if gen_h > 0.0 else tau)
        lo_g = max(first << MAP_SHIFT, lowest)
        if noise > 0.0:  # γ from the transient: not from the levels roundoff reaches
            cut = min(ladder_level(GAMMA_MARGIN * noise, base_j) + 1, top - per_decade)
            lo_g = min(max(lo_g, cut), top)
        gamma, t_end = _map_gamma(lt, lv, j, lo_g, top, beta, ry)
        # the start is a point of the transient whose level a later visit may hold
        gamma = max(gamma, meas[row, C_INITIAL])
        meas[row, C_BETA] = beta
        meas[row, C_GAMMA] = gamma
        meas[row, C_FIT_START] = 0.0
        meas[row, C_FIT_END] = t_end
        meas[row, C_SHIFT] = math.nan
        codes[row, I_POINTS] = pairs
        codes[row, I_KIND] = K_MAP
        codes[row, I_REASON] = R_FITTED
        return True
    return False


# --------------------------------------------------------------------- the generator
# Adaptive steps have no one-step map: each step has its own length.  What all of them
# share is the generator ``A`` of ``ġ = A g``, which a step of length ``h`` maps by
# ``e^{hA}``.  Its (2, 2) Padé form ``(I − hA/2 + h²A²/12) g_{k+1} = (I + hA/2 +
# h²A²/12) g_k`` (exact to ``O((h‖A‖)⁵)`` per step) gives, with ``p = (g_k + g_{k+1})/2``
# and ``d = g_{k+1} − g_k``,
#
#     A p = d/h + (h/12) A² d,
#
# linear in ``A`` but for the ``A²`` term: ``A`` is fitted by least squares with it taken
# from the previous iterate (``GENERATOR_SWEEPS`` sweeps from the trapezoidal fit
# ``A p = d/h``, whose rates are low by ``(hβ)²/12``), from three running sums per bin:
# ``Σ p pᵀ``, ``Σ (d/h) pᵀ`` and ``Σ h d pᵀ``.  The rates are ``Re λ(Â)``; the bins are
# the one-step map's (:func:`map_buffers`: the pairs before the member's level first fell
# below each bin), and so is the window (:func:`map_estimate`).  The pairs are of the
# member's distance from the reference trajectory's residual, as the one-step map's: the
# integrator's local errors hold the residual itself on a floor that moves with the
# motion, the same for every member whose steps the motion, not its transient, sets.

#: sweeps of the Padé correction of the generator's fit (each multiplies the error of the
#: trapezoidal fit's ``(hβ)²/12`` by about another ``(hβ)²/12``; the third is past
#: roundoff for ``hβ < 0.5``)
GENERATOR_SWEEPS = 3


@njit(cache=True)
def generator_width(ng, pm):
    """The generator's sums per bin.  Pooled (``pm ≥ 0`` holonomic constraints, as
    :func:`map_width`): over ``p = (f_i, ḟ_i)`` ``Σ p pᵀ``'s 3, ``Σ (d/h) pᵀ``'s 4 and ``Σ h
    d pᵀ``'s 4, the three of the ``h_j`` and the count (15).  Else the full ``ng × ng``
    sums and the count (none above ``MAP_MAX_NG`` components)."""
    if pm >= 0:
        return 15
    return 3 * ng * ng + 1 if ng <= MAP_MAX_NG else 0


@njit(cache=True)
def generator_add(A, j, G0, G1, h, pm):
    """The pair of slot ``j``'s residuals ``G0[j]`` (the accepted state before) and
    ``G1[:, j]`` (the new one), a step ``h`` apart, added to its running sums ``A[j]``
    (:func:`generator_width`); then ``G0[j] = G1[:, j]``.  (Once per accepted step of
    every member: one division, no array view.)"""
    ng = G0.shape[1]
    W = A.shape[1]
    if W == 0:
        return
    ih = 1.0 / h
    if pm >= 0:
        for i in range(pm):
            p0 = 0.5 * (G0[j, i] + G1[i, j])
            p1 = 0.5 * (G0[j, pm + i] + G1[pm + i, j])
            d0 = G1[i, j] - G0[j, i]
            d1 = G1[pm + i, j] - G0[j, pm + i]
            y0, y1, z0, z1 = d0 * ih, d1 * ih, h * d0, h * d1
            A[j, 0] += p0 * p0
            A[j, 1] += p0 * p1
            A[j, 2] += p1 * p1
            A[j, 3] += y0 * p0
            A[j, 4] += y0 * p1
            A[j, 5] += y1 * p0
            A[j, 6] += y1 * p1
            A[j, 7] += z0 * p0
            A[j, 8] += z0 * p1
            A[j, 9] += z1 * p0
            A[j, 10] += z1 * p1
        for i in range(2 * pm, ng):
            p = 0.5 * (G0[j, i] + G1[i, j])
            d = G1[i, j] - G0[j, i]
            A[j, 11] += p * p
            A[j, 12] += d * ih * p
            A[j, 13] += h * d * p
    else:
        n2 = ng * ng
        for r in range(ng):
            pr = 0.5 * (G0[j, r] + G1[r, j])
            dr = G1[r, j] - G0[j, r]
            yr, zr = dr * ih, h * dr
            for c in range(ng):
                pc = 0.5 * (G0[j, c] + G1[c, j])
                A[j, r * ng + c] += pr * pc
                A[j, n2 + r * ng + c] += yr * pc
                A[j, 2 * n2 + r * ng + c] += zr * pc
    A[j, W - 1] += 1.0
    for l in range(ng):
        G0[j, l] = G1[l, j]


@njit(cache=True)
def generator_store(S, A, j, first, last):
    """Slot ``j``'s running sums so far as those of bins ``first … last``."""
    for b in range(first, last + 1):
        for c in range(A.shape[1]):
            S[j, b, c] = A[j, c]


@njit(cache=True)
def _generator2(s, ref, h):
    """``ρ`` equivalent ``e^{h max Re λ(Â)}`` of the pooled generator's sums ``s``
    (:func:`generator_width`), read in the groups of the law's spectrum ``ref`` (on the
    scale of a step ``h``: :func:`reference_logs` of ``e^{hÃ}``); −1 where neither block
    has data."""
    rho = -1.0
    det = s[0] * s[2] - s[1] * s[1]
    if s[0] > 0.0 and s[2] > 0.0 and abs(det) > 1e-14 * s[0] * s[2]:
        # P⁻¹ (symmetric) and Â = (Y + Â² Z / 12) P⁻¹, Y = [[s3, s4], [s5, s6]], Z = s7…s10
        i00, i01, i11 = s[2] / det, -s[1] / det, s[0] / det
        y00, y01, y10, y11 = s[3], s[4], s[5], s[6]
        a00 = y00 * i00 + y01 * i01
        a01 = y00 * i01 + y01 * i11
        a10 = y10 * i00 + y11 * i01
        a11 = y10 * i01 + y11 * i11
        for _ in range(GENERATOR_SWEEPS):
            q00 = a00 * a00 + a01 * a10
            q01 = a00 * a01 + a01 * a11
            q10 = a10 * a00 + a11 * a10
            q11 = a10 * a01 + a11 * a11
            c00 = y00 + (q00 * s[7] + q01 * s[9]) / 12.0
            c01 = y01 + (q00 * s[8] + q01 * s[10]) / 12.0
            c10 = y10 + (q10 * s[7] + q11 * s[9]) / 12.0
            c11 = y11 + (q10 * s[8] + q11 * s[10]) / 12.0
            a00 = c00 * i00 + c01 * i01
            a01 = c00 * i01 + c01 * i11
            a10 = c10 * i00 + c11 * i01
            a11 = c10 * i01 + c11 * i11
        half = 0.5 * (a00 + a11)
        disc = half * half - (a00 * a11 - a01 * a10)
        if not (disc == disc) or not math.isfinite(half):
            return math.nan
        mod = stack1(2)
        if disc < 0.0:  # a complex pair: one real part
            mod[0] = math.exp(h * half)
            mod[1] = mod[0]
        else:
            mod[0] = math.exp(h * (half + math.sqrt(disc)))
            mod[1] = math.exp(h * (half - math.sqrt(disc)))
        rho = _grouped(mod, 2, ref)
    if s[11] > 0.0:
        a = s[12] / s[11]
        for _ in range(GENERATOR_SWEEPS):
            a = (s[12] + a * a * s[13] / 12.0) / s[11]
        rho = max(rho, math.exp(h * a))
    return rho


@njit(cache=True)
def _generator_full(s, ng, ref, h):
    """As :func:`_generator2` for the full sums of ``ng`` components, on the directions
    the pairs span (whitened, as :func:`_map_radius`); NaN where they span none."""
    n2 = ng * ng
    P = np.empty((ng, ng))
    Y = np.empty((ng, ng))
    Z = np.empty((ng, ng))
    for r in range(ng):
        for c in range(ng):
            P[r, c] = s[r * ng + c]
            Y[r, c] = s[n2 + r * ng + c]
            Z[r, c] = s[2 * n2 + r * ng + c]
    lam, V = _spanned(P, Y, Z)
    keep = lam.shape[0]
    if keep == 0:
        return math.nan
    Vt = np.ascontiguousarray(V.T)
    Yr = Vt @ Y @ V
    Zr = Vt @ Z @ V
    Ar = Yr.copy()
    for r in range(keep):
        for c in range(keep):
            Ar[r, c] = Yr[r, c] / lam[c]
    for _ in range(GENERATOR_SWEEPS):
        C = Yr + (Ar @ Ar) @ Zr / 12.0
        for r in range(keep):
            for c in range(keep):
                Ar[r, c] = C[r, c] / lam[c]
    for r in range(keep):
        for c in range(keep):
            if not math.isfinite(Ar[r, c]):
                return math.nan
    ev = np.linalg.eigvals(Ar.astype(np.complex128))
    mod = np.empty(keep)
    for i in range(keep):
        mod[i] = math.exp(h * ev[i].real)
    return _grouped(mod, keep, ref)


@njit(cache=True)
def _generator_radius(S, j, ng, pm, first, ref, h):
    """``ρ`` equivalent of slot ``j``'s generator from bin ``first`` (:func:`_generator2`
    or :func:`_generator_full`) and the number of pairs; NaN with too few pairs (a
    parameter per unknown)."""
    W = S.shape[2]
    if first >= S.shape[1]:
        return math.nan, 0.0
    s = S[j, first]
    pairs = s[W - 1]
    if pm >= 0:
        if pairs < 4.0:
            return math.nan, pairs
        rho = _generator2(s, ref, h)
        return (rho if rho >= 0.0 else math.nan), pairs
    if pairs < 2.0 * ng:
        return math.nan, pairs
    return _generator_full(s, ng, ref, h), pairs


# --------------------------------------------------------------------- pooled ends
# The fixed-step kernel of a law whose map is pooled (``pm ≥ 0``, no generator) ends its
# members with variants of :func:`map_estimate` and :func:`.member.finish_with_map`
# compiled without reference counting: the full map's and the generator's radii, which
# allocate, are out of their reach (in their place, functions that raise).  The
# reference-counted functions took and dropped a reference to each of their array
# arguments at every member's end.


@njit(cache=True, _nrt=False)
def _full_radius_unavailable(S, j, ng, first, ref):
    # (raised behind a test numba cannot fold, so that the function has a return type)
    if j >= 0:
        raise AssertionError("map_estimate_pooled: a full one-step map (pm < 0) needs "
                             "map_estimate")  # fmt: skip
    return math.nan, 0.0


@njit(cache=True, _nrt=False)
def _generator_radius_unavailable(S, j, ng, pm, first, ref, h):
    if j >= 0:  # (as above)
        raise AssertionError("map_estimate_pooled: a generator's sums (gen_h > 0) need "
                             "map_estimate")  # fmt: skip
    return math.nan, 0.0


map_estimate_pooled = njit(cache=True, _nrt=False)(
    variant(map_estimate, "map_estimate_pooled", _map_radius=_full_radius_unavailable,
            _generator_radius=_generator_radius_unavailable))  # fmt: skip
map_estimate_pooled.__doc__ = """:func:`map_estimate` for the pooled map of fixed steps
(``pm ≥ 0``, ``gen_h = 0``), compiled without reference counting; other sums raise."""
