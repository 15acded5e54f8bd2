"""One member's measurement: begun at its initial residual, observed at every measured
step, finished with its fit (envelope or one-step map) and its linear prediction."""

from __future__ import annotations

import math

from numba import njit

from ..jit import variant
from .fit import MIN_DECADES, STILL_DECAYING, estimate, grows, refit
from .ladder import (
    NBINS,
    ladder_base,
    ladder_clear,
    ladder_clear_from,
    ladder_level,
    ladder_top,
    records,
)
from .onestep import map_estimate, map_estimate_pooled
from .record import (
    C_BETA,
    C_BETA_PRED,
    C_D2,
    C_D3,
    C_D4,
    C_FINAL,
    C_FIT_END,
    C_FIT_START,
    C_FLOOR,
    C_GAMMA,
    C_INITIAL,
    C_LARGEST,
    C_SHIFT,
    C_W0,
    C_W4,
    I_FLOOR_REACHED,
    I_KIND,
    I_POINTS,
    I_REASON,
    K_MAP,
    K_NONE,
    NCODES,
    NCOLS,
    R_FITTED,
    R_NO_TRANSIENT,
    R_NOT_DECAYING,
    R_STOPPED,
)


# --------------------------------------------------------------------- per member
# The functions here that allocate nothing (all but finish_with_map, whose map estimate
# may) are compiled without numba's reference counting (``_nrt=False``): a separately
# compiled function otherwise takes and drops a reference to each array argument, two
# atomic operations per array per call, for every member.  Such a function cannot call
# one that allocates.
@njit(cache=True, forceinline=True)  # once per accepted step: a call with four arrays
def observe(lt, lv, base, meas, j, row, t, v, d, window):  # costs as much as the step
    """Step time ``t`` (from the start) of member ``row`` (ladder row ``j``), in fifth
    ``window`` of the run: ``v`` its residual norm (the largest per fifth is kept), ``d``
    the norm whose decay is measured (the ladder's; ``v`` itself, or the distance of the
    residual from a reference trajectory's).  Non-finite norms are left out."""
    if v < math.inf:
        c = C_W0 + window
        if not (meas[row, c] >= v):
            meas[row, c] = v
    if d < math.inf:
        b = ladder_level(d, base[j])
        lt[j, b] = t
        lv[j, b] = d
        if window >= 2:
            c = C_D2 + window - 2
            if not (meas[row, c] >= d):
                meas[row, c] = d


@njit(cache=True, _nrt=False)
def begin(lt, lv, base, meas, codes, j, row, g0, d0, clear_from=0):
    """Start member ``row`` on ladder row ``j`` with its initial norms (as
    :func:`observe`'s); every column of its record is written here or at its end.
    ``clear_from``: no level of the row below it holds a time (the ladder is cleared
    from there up: a member's run writes the levels from its lowest one up, and the
    clear of all ``NBINS`` levels, 4 kB outside the first-level cache, was most of a
    member's start)."""
    ladder_clear_from(lt, j, clear_from)
    base[j] = ladder_base(d0)
    for c in range(NCOLS):
        meas[row, c] = math.nan
    for c in range(NCODES):
        codes[row, c] = 0
    for w in range(5):
        meas[row, C_W0 + w] = -math.inf
    for w in range(3):
        meas[row, C_D2 + w] = -math.inf
    meas[row, C_INITIAL] = g0
    observe(lt, lv, base, meas, j, row, 0.0, g0, d0, 0)


@njit(cache=True, _nrt=False)
def finish(lt, lv, meas, codes, j, row, final, stopped, dt, rt, ry, a, b, lg, noise=0.0):
    """Member ``row``'s measures from ladder row ``j`` at the end of its run (``final``:
    the norm at its last state; ``stopped``: it did not run to the end; ``noise``: the
    run's roundoff level, :func:`.fit.gamma_of`)."""
    still = summarize(meas, codes, row, final, stopped)
    if not stopped:
        fit_envelope(lt, lv, meas, codes, j, row, still, dt, rt, ry, a, b, lg, 0,
                     ladder_top(lt, j), noise)  # fmt: skip


@njit(cache=True)
def finish_with_map(lt, lv, S, meas, codes, j, row, final, stopped, ng, pm, base_j, lowest, dt, rt,
                    ry, a, b, lg, ref, gen_h=0.0, floor_min=0.0, envelope=True,
                    low_bin=0, noise=0.0):  # fmt: skip
    """:func:`finish` for a member with one-step map sums ``S`` (:func:`map_estimate`,
    ``dt`` the time between the map's pairs; ``lowest`` a level below which ladder row
    ``j`` has no point; ``ref`` the law's spectrum, :func:`reference_logs`; ``gen_h > 0``:
    ``S`` holds a generator's sums, and ``floor_min`` the least floor; ``low_bin`` the
    bin whose sums those below it hold; :func:`map_estimate`):
    β from the map where it has one, else from the envelope (unless not ``envelope``:
    then none, with the reason ``no transient``).  A member whose largest norms grow
    (:func:`grows`) gets the map only when the envelope does not find it growing (it may
    decay first, which the map would read), so its envelope is fitted first; unless the
    last fifth's largest norm lies a decade (``MIN_DECADES``) or more below the start:
    then the rise is the floor's, moving with the motion."""
    still = summarize(meas, codes, row, final, stopped)
    if stopped:
        return
    top = ladder_top(lt, j)  # (for the map and the envelope: found once)
    # a late rise a decade or more below the start is the floor moving with the motion
    # (the member drifting from the reference), not growth: the map reads the transient
    # before it
    drift = meas[row, C_D4] * 10.0**MIN_DECADES <= meas[row, C_INITIAL]
    if grows(meas[row, C_D2], meas[row, C_D3], meas[row, C_D4]) and not drift:
        fit_envelope(lt, lv, meas, codes, j, row, still, dt, rt, ry, a, b, lg, lowest, top,
                     noise)  # fmt: skip
        if codes[row, I_REASON] != R_NOT_DECAYING:
            map_estimate(S, j, ng, pm, lt, lv, base_j, meas, codes, row, dt, rt, ry, ref,
                         top, lowest, gen_h, floor_min, low_bin, noise)  # fmt: skip
    elif not map_estimate(S, j, ng, pm, lt, lv, base_j, meas, codes, row, dt, rt, ry, ref,
                          top, lowest, gen_h, floor_min, low_bin, noise):  # fmt: skip
        if envelope:
            fit_envelope(lt, lv, meas, codes, j, row, still, dt, rt, ry, a, b, lg, lowest, top,
                         noise)  # fmt: skip
        else:
            codes[row, I_POINTS] = 0
            codes[row, I_KIND] = K_NONE
            codes[row, I_REASON] = R_NO_TRANSIENT


@njit(cache=True, _nrt=False)
def fit_envelope(lt, lv, meas, codes, j, row, still, dt, rt, ry, a, b, lg, lowest=0,
                 top=NBINS - 1, noise=0.0):  # fmt: skip
    """β and γ of member ``row`` from the envelope of ladder row ``j`` (:func:`estimate`;
    ``still``: the run ended while it was decaying; ``lowest``, ``top``: no level below
    the one or above the other was visited; ``noise``: the run's roundoff level)."""
    n = records(lt, lv, j, rt, ry, lowest, top)
    estimate(rt, ry, n, meas[row, C_D4], still, dt, a, b, lg, meas[row], codes[row], noise)


@njit(cache=True, _nrt=False)
def summarize(meas, codes, row, final, stopped):
    """Member ``row``'s columns other than the fit at the end of its run (``final``: the
    norm at its last state; ``stopped``: it did not run to the end; then the fit's
    columns say so).  Returns whether the measured norm was still decaying at the end."""
    out = meas[row]
    out[C_FINAL] = final
    largest = -math.inf
    for w in range(5):
        if out[C_W0 + w] == -math.inf:
            out[C_W0 + w] = math.nan
        else:
            largest = max(largest, out[C_W0 + w])
    out[C_LARGEST] = largest if largest > -math.inf else math.nan
    out[C_FLOOR] = out[C_W4]
    # whether the measured norm is still falling at the end
    still = (out[C_D2] >= STILL_DECAYING * out[C_D3]
             and out[C_D3] >= STILL_DECAYING * out[C_D4])  # fmt: skip
    code = codes[row]
    code[I_FLOOR_REACHED] = 0 if still else 1
    if stopped:
        for c in (C_BETA, C_GAMMA, C_FIT_START, C_FIT_END, C_SHIFT):
            out[c] = math.nan
        code[I_POINTS] = 0
        code[I_KIND] = K_NONE
        code[I_REASON] = R_STOPPED
    return still


@njit(cache=True, _nrt=False)
def predict(R, alphas, i_alpha, nsteps, h, lt, lv, base, meas, codes, j, row, rt, ry, a, b, lg,
            g, gn, rho_R):  # fmt: skip
    """Member ``row``'s predicted rate: ``g_{k+1} = R g_k`` from ``g_0 = alphas[i_alpha]``
    (the row read in place: a view of a shared array is a reference count taken and
    dropped, two atomic operations on a cache line every thread writes) over the
    steps up to its fit window's end, through ladder row ``j``, fitted over the measured
    window with the measured kind; ``−ln ρ(R)/h`` for a member measured by its one-step
    map (``rho_R``: :func:`.onestep.spectral_radius_of` ``R``, taken once for all).
    ``g``, ``gn`` are scratch of the residual's size.  Returns the lowest level of the
    ladder row it wrote (``NBINS``: none; the row is then as it was, or cleared)."""
    out = meas[row]
    out[C_BETA_PRED] = math.nan
    if codes[row, I_REASON] != R_FITTED:
        return NBINS
    if codes[row, I_KIND] == K_MAP:  # the map fitted to g_{k+1} = R g_k is R itself
        out[C_BETA_PRED] = -math.log(rho_R) / h
        return NBINS
    ng = alphas.shape[1]
    ladder_clear(lt, j)
    nrm = 0.0
    for i in range(ng):
        g[i] = alphas[i_alpha, i]
        nrm = max(nrm, abs(g[i]))
    base[j] = ladder_base(nrm)
    t_hi = out[C_FIT_END]
    last = min(nsteps, int(math.ceil(t_hi / h - 1e-9)) + 1)
    lowest = NBINS  # the lowest level written
    for k in range(last + 1):
        if k > 0:
            nrm = 0.0
            for r in range(ng):
                s = 0.0
                for c in range(ng):
                    s += R[r, c] * g[c]
                gn[r] = s
            for r in range(ng):
                g[r] = gn[r]
                nrm = max(nrm, abs(gn[r]))
        if nrm < math.inf:
            lev = ladder_level(nrm, base[j])
            lt[j, lev] = k * h
            lv[j, lev] = nrm
            lowest = min(lowest, lev)
    n = records(lt, lv, j, rt, ry, lowest)
    out[C_BETA_PRED] = refit(rt, ry, n, out[C_FIT_START], t_hi, codes[row, I_KIND], h, a, b, lg,
                             out[C_SHIFT])  # fmt: skip
    return lowest


#: :func:`finish_with_map` for the pooled one-step map of fixed steps, compiled without
#: reference counting (:func:`.onestep.map_estimate_pooled`)
finish_with_map_pooled = njit(cache=True, _nrt=False)(
    variant(finish_with_map, "finish_with_map_pooled", map_estimate=map_estimate_pooled))
