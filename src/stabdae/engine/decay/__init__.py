"""Decay rate, prefactor and floor of each member's residual, measured at every step.

A member's ``‖g‖∞`` first decays at the rate of the law (continuous: ``−max Re λ(Ã)``;
discrete: ``−ln ρ(R(τÃ))/τ``) and then settles on a floor set by the scheme's local error
(the paper's §5).  The kernels measure it where the step evaluates the residual, not on
the stored samples (the fixed-step kernel every ``s``-th step, over which no mode of the
law changes by more than a tenth: :func:`stabdae._ensemble.measure_stride`), with O(1)
work per step and a fixed amount of memory per member (a *ladder*):

* the norm's level on a log scale of ``LEVELS_PER_OCTAVE`` levels per octave (read from
  the float's exponent and leading mantissa bits: no logarithm per step), over
  ``NBINS`` levels from ``2^-54`` to about ``940`` times the member's initial norm;
* per level, the time and value of the *last* step at which the norm lay on it.

From the ladder the estimator reads the right envelope of the whole trace at step
resolution: the last sample on a level is a point of the envelope (no later sample is as
large) exactly when no higher level was visited later (:func:`records`).  These points,
one per level, are what the decay rate of an oscillating residual is read from, and they
are the samples of a monotone one.  Also per member: the largest norm over each fifth of
the run (``W0 … W4``); ``W4``, the largest over the last fifth, is the *floor*.

The estimator (:func:`estimate`), per member, at the end of its run:

1. the transient: the envelope points from the start until the envelope first comes
   within a margin of the floor (1000, 100, then ``FLOOR_MARGIN`` = 30 when that leaves
   too little: the floor is a forced response that bends the trace well above its own
   level), or all of them when the run ended while the residual was still decaying (each
   of the last three fifths at least ``STILL_DECAYING`` times below the one before);
2. the fit window: the transient after its first ``LEAD_FRACTION`` of decades, where
   faster modes have died out.  It must span a decade (``MIN_DECADES``) with
   ``MIN_POINTS`` points; otherwise β is NaN with the reason ``no transient``;
3. fits ``log ‖g‖ ≈ a − β t`` and ``log ‖g‖ ≈ a − β t + ν log(t + s)`` by least squares
   (``s`` by a grid search refined by Brent's method) and keeps the better.  The
   ``ν log(t + s)`` term absorbs the polynomial prefactor of repeated eigenvalues:
   critically damped Baumgarte decays like ``|c0 + c1 t| e^{−ωt}`` (the schemes'
   ``R(τÃ)`` is then a Jordan block, ``‖g_k‖ ~ |a + bk| ρ^k``).  When neither fits the
   points to ``SMOOTH_RMS`` in the logarithm, the residual oscillates (under-damped laws):
   the envelope is then ``e^{−βt}`` times a periodic function, and the time of each level
   regressed on the level (``t ≈ a − log ‖g‖ / β``, levels equally spaced) has a bias that
   falls like the square of the number of periods in the window;
4. ``γ = max ‖g(t)‖ e^{βt}`` over the transient's envelope points, the smallest prefactor
   with ``‖g(t)‖ ≤ γ e^{−βt}`` there (the largest of a trace is always on its envelope).

A member that stopped, or whose envelope does not fall, gets ``β = γ = NaN`` and a reason
(:data:`REASONS`), never a fitted number.

Where a constant law gives one (:mod:`.onestep`), the rate is read from the one-step map
fitted to the residual's pairs (fixed steps) or from the generator fitted to its accepted
steps (adaptive ones), with the envelope's fit as the fallback.

:func:`predict` runs a member's linear prediction ``g_{k+1} = R g_k`` from its own
``α⁰`` (``R = R(τÃ)`` for fixed steps, ``e^{Ãh}`` for adaptive ones) through the same
ladder and fits it over the same time window with the same kind of fit, so that what the
estimator does to a window cancels in the ratio of measured to predicted rate.

The package, by role (each module's docstring says more):

* :mod:`.record` — the measurement record's columns by name and kind, reasons and
  kinds of fit;
* :mod:`.ladder` — levels from a float's bits, the ladder and its envelope points;
* :mod:`.fit` — the window and the fits of the envelope; the growth predicate;
* :mod:`.member` — one member's begin, observe, finish and prediction;
* :mod:`.onestep` — the one-step map's sums, flushes and spectral radius; the
  generator's sums and rate for adaptive steps;
* :mod:`.traces` — the estimator over stored traces.
"""

from .fit import (  # noqa: F401
    BRENT_TOL,
    FLOOR_MARGIN,
    GROWTH,
    LEAD_FRACTION,
    MIN_DECADES,
    MIN_POINTS,
    N_SHIFTS,
    SMOOTH_RMS,
    STILL_DECAYING,
    estimate,
    grows,
    refit,
)
from .ladder import (  # noqa: F401
    ABOVE,
    LEVELS_PER_OCTAVE,
    NBINS,
    float_bits,
    float_from_bits,
    ladder_base,
    ladder_clear,
    ladder_level,
    ladder_top,
    ladders,
    log_normal,
    records,
    scratch,
    trailing_zeros,
)
from .member import (  # noqa: F401
    begin,
    finish,
    finish_with_map,
    finish_with_map_pooled,
    fit_envelope,
    observe,
    predict,
    summarize,
)
from .onestep import (  # noqa: F401
    CLUSTER,
    GENERATOR_SWEEPS,
    LOW_MARGIN,
    MAP_BINS,
    MAP_MARGIN,
    MAP_MAX_NG,
    MAP_RANK_TOL,
    MAP_SHIFT,
    MAP_STILL_DECAYING,
    bin_flush,
    block_levels,
    difference_norms,
    end_flush,
    flushes_for,
    full_rows,
    generator_add,
    generator_store,
    generator_width,
    grouped_radius_of,
    map_begin,
    map_buffers,
    map_estimate,
    map_estimate_pooled,
    map_width,
    pairs_full_for,
    pairs_pooled,
    reference_logs,
    spectral_radius_of,
    window_flush,
    windows_flush,
)
from .record import (  # noqa: F401
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
    C_W1,
    C_W2,
    C_W3,
    C_W4,
    COLUMNS,
    FLOATS,
    I_FLOOR_REACHED,
    I_KIND,
    I_POINTS,
    I_REASON,
    INTEGERS,
    K_EXPONENTIAL,
    K_MAP,
    K_NONE,
    K_OSCILLATING,
    K_POLYNOMIAL,
    KINDS,
    NCODES,
    NCOLS,
    R_FITTED,
    R_NO_TRANSIENT,
    R_NOT_DECAYING,
    R_STOPPED,
    REASONS,
    Record,
)
from .traces import (  # noqa: F401
    measure_traces,
)
