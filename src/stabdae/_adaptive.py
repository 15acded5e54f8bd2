"""Adaptive steps with an embedded pair (Dormand–Prince 5(4), DOP853) for one trajectory.

For reference solutions and work–precision comparisons: the stabilized right-hand side
(3.1), (3.11) integrated with local error control (the loop: :mod:`.engine.rk.adaptive`).
"""

from __future__ import annotations

import warnings

import numpy as np

from . import _validate as check
from ._codes import Status
from ._integrate import IntegrationWarning, _multipliers
from ._model import Model
from ._schema import trajectory_dataset
from .engine.crash import guard
from .engine.rk.adaptive import adaptive_for

__all__ = ["integrate_adaptive"]


def integrate_adaptive(
    model: Model,
    x0=None,
    law=None,
    t_end: float = 1.0,
    *,
    scheme="dopri5",
    rtol: float = 1e-8,
    atol=1e-10,
    save_dt: float | None = None,
    first_step: float | None = None,
    max_steps: int = 10_000_000,
    params=None,
    t0: float | None = None,
    multiplier: str = "ldl",
    projection: str | None = None,
    with_multipliers: bool = False,
):
    """Integrate one trajectory of the stabilized equations with adaptive steps.

    Parameters
    ----------
    model : Model
    x0 : array (2n,), optional
        Initial state (default the model's reference state).
    law : Law
        Constraint-perturbation law, as for :func:`stabdae.integrate` (``none()`` gives the
        index-1 equations).
    t_end : float
        Final time.
    scheme : {"dopri5", "dop853"} or Scheme
        The embedded pair: Dormand–Prince 5(4) (7 stages, the last one reused), or
        Hairer's DOP853 (order 8 with fifth- and third-order error estimates, 12 stages and
        one more evaluation at the new state, reused as the next step's first), cheaper
        per digit at tight tolerances.
    rtol, atol : float, or for ``atol`` array of shape (2n,)
        Relative and absolute local error tolerances (RMS norm over the state's
        components of ``error_l / (atol_l + rtol·|x_l|)``); ``atol`` a number, or one per
        component of ``x = (q, v)`` where their scales differ (as SciPy's ``solve_ivp``
        takes it): a component near zero needs an ``atol`` below its own scale, and one
        number small enough for the smallest component makes every other one take steps
        it does not need.  ``atol="scales"``: ``rtol`` times the model's declared
        ``scales``.
    save_dt : float, optional
        Spacing of the stored samples (the last one at ``t_end``); steps end exactly on
        them.  Default: only ``t0`` and ``t_end``.
    first_step : float, optional
        Initial step (default: chosen from the tolerances and ``ẋ``, ``ẍ``).
    max_steps : int
        Accepted plus rejected steps before giving up (status ``MAX_STEPS``).
    params : mapping or array, optional
    t0 : float, optional
    multiplier : {"ldl", "lstsq"}
        As for :func:`stabdae.integrate`: ``"lstsq"`` integrates redundant constraints.
    with_multipliers : bool, default False
        Also store the multipliers λ of (3.11) (``multiplier(time, constraint)``, with
        ``M v̇ = Fᵀλ − γ``) and the accelerations ``acceleration(time, coordinate)`` at the
        stored samples, for comparison with published λ and index-2 references.
    projection : {None, "post", "full"}
        As for :func:`stabdae.integrate`, after each accepted step (costs one more
        right-hand-side evaluation per step: the first-same-as-last stage is lost).

    Returns
    -------
    xarray.Dataset
        As :func:`stabdae.integrate`, with attributes ``method`` (the pair's name), ``rtol``,
        ``atol``, ``steps_accepted``, ``steps_rejected`` and ``rhs_evaluations``.

    Examples
    --------
    >>> import stabdae
    >>> model = stabdae.load_model("pendulum")
    >>> ds = stabdae.integrate_adaptive(model, None, stabdae.none(), 1.0, rtol=1e-10,
    ...                                 atol=1e-12)
    """
    who = "integrate_adaptive"
    model = check.model(model, who)
    law = check.law(law, who, "stabdae.none() or stabdae.baumgarte(omega=10.0, xi=1.0)")
    rtol, atol, atol_given = check.tolerances(rtol, atol, who, 2 * model.n, model.scales)
    p = check.params(model, params, who)
    t0 = model.t0 if t0 is None else check.real(t0, "t0", who)
    check.span(t0, t_end, who)
    save_times = check.sample_times(t0, float(t_end), save_dt, who)
    h0 = -1.0 if first_step is None else check.positive(first_step, "first_step", who)
    max_steps = check.count(max_steps, "max_steps", who)
    x0 = check.initial_state(model, x0, p, who)
    bound = check.bound_law(law, model, who)
    multiplier = check.multiplier(multiplier, bound, who)
    sweeps, tol = check.projection(projection, who)
    pair = check.pair(scheme, who)
    scheme = pair.scheme

    kernel = adaptive_for(model, bound, multiplier)
    nsave = save_times.shape[0] + 1
    out_x = np.full((nsave, 2 * model.n), np.nan)
    out_g = np.full((nsave, model.n_residual), np.nan)
    out_e = np.full(nsave, np.nan)
    counts = np.zeros(3, dtype=np.int64)
    with guard(who):
        status, written = kernel(
            x0, t0, save_times, p, bound.matrix, bound.scalars, scheme.A, scheme.b, pair.error,
            scheme.c, pair.combined, pair.error_order, rtol, atol, h0, int(max_steps), sweeps,
            tol, out_x, out_g, out_e, counts,
        )  # fmt: skip
    status = Status(status)
    if status != Status.OK:
        hint = ""
        if status == Status.STEP_TOO_SMALL and multiplier == "ldl" and model.m + model.k > 1:
            # near a configuration where the constraints lose rank, S is ill-conditioned
            # and the error estimate never settles; the pseudo-inverse passes such points
            hint = ("; if the constraints lose rank there (a singular position of the "
                    "mechanism), multiplier='lstsq' integrates through it")
        warnings.warn(
            f"integrate_adaptive({model.name}): stopped after {int(counts[0])} accepted steps "
            f"({written - 1} of {nsave - 1} samples): {status.description}{hint}; samples up "
            "to there are kept, later ones are NaN",
            IntegrationWarning,
            stacklevel=2,
        )
    times = np.concatenate([[t0], save_times])
    ds = trajectory_dataset(
        model, p, law, scheme, times, out_x, out_g, out_e, status, int(counts[0]),
        dict(method=pair.name, rtol=rtol, atol=atol_given, t0=t0, t_end=float(t_end),
             steps=int(counts[0]), multiplier=multiplier,
             projection=str(projection).lower()),
        action="integrate_adaptive",
        multipliers=_multipliers(model, bound, multiplier, times, out_x, p)
        if with_multipliers else None,
    )  # fmt: skip
    ds.attrs.update(
        steps_accepted=int(counts[0]), steps_rejected=int(counts[1]),
        rhs_evaluations=int(counts[2]),
    )  # fmt: skip
    return ds
