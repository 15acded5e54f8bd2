"""One trajectory of the stabilized equations with a fixed-step explicit Runge–Kutta scheme."""

from __future__ import annotations

import math
import warnings

import numpy as np
import xarray as xr

from . import _validate as check
from . import theory
from ._codes import Status
from ._model import Model
from ._raised import model_raised, replay_fixed, stage_finder
from ._schema import trajectory_dataset
from .engine.crash import guard
from .engine.rk.steps import integrator_for, multipliers_for

__all__ = ["integrate", "IntegrationWarning"]


class IntegrationWarning(RuntimeWarning):
    """An integration stopped early; the dataset holds everything up to that step."""


def integrate(
    model: Model,
    x0=None,
    law=None,
    scheme="rk4",
    tau: float = 1e-3,
    t_end: float = 1.0,
    save_dt: float | None = None,
    *,
    params=None,
    t0: float | None = None,
    multiplier: str = "ldl",
    projection: str | None = None,
    with_multipliers: bool = False,
    divergence: float | None = None,
) -> xr.Dataset:
    """Integrate one trajectory of the stabilized equations (3.1), (3.11).

    Parameters
    ----------
    model : Model
    x0 : array (2n,), optional
        Initial state ``(q, v)``; default the model's reference state.  It need not be
        consistent: the residual ``g(x0)`` then decays (or not) according to the law.
    law : Law or @njit function
        Constraint-perturbation law (``baumgarte(...)``, ``matrix(A)``, ``theorem5(...)``,
        ``none()``, or a user ``A(t, x, p, out)``).
    scheme : Scheme or str, default "rk4"
        ``"euler"``, ``"midpoint"``/``"rk2"``, ``"heun"``, ``"rk4"`` or a :class:`Scheme`.
    tau : float
        Fixed step size τ.
    t_end : float
        Final time; ``t_end − t0`` must be a whole multiple of ``tau``.
    save_dt : float, optional
        Spacing of stored samples, a whole multiple of ``tau`` dividing the interval
        (default: every step).
    params : mapping or array, optional
        Physical parameters overriding the model's defaults.
    t0 : float, optional
        Initial time (default ``model.t0``).
    multiplier : {"ldl", "lstsq"}
        How λ is solved from (3.11): ``"ldl"`` factorizes ``S`` and stops with status
        ``SINGULAR_S`` when it is singular (redundant constraints); ``"lstsq"`` takes the
        minimum-norm least-squares λ (pseudo-inverse of ``S``) and keeps integrating.
    divergence : float, optional
        Residual norm above which the trajectory is reported diverged (status
        ``DIVERGED``, with an :class:`IntegrationWarning`; the samples after the first one
        above it are NaN).  Default: 1000 times the initial residual, at least 1 (a
        residual of the model's own size), and for a constant ``Ã`` at least 1000 times
        the law's transient bound ``sup_k ‖R(τÃ)^k‖∞ ‖g(x0)‖∞``.
    with_multipliers : bool, default False
        Also store the multipliers λ of (3.11) (``multiplier(time, constraint)``, with
        ``M v̇ = Fᵀλ − γ``) and the accelerations ``acceleration(time, coordinate)`` at the
        stored samples, for comparison with published λ and index-2 references.
    projection : {None, "post", "full"}
        After each step: ``"post"`` applies one post-stabilization sweep
        ``x ← x − D (G D)⁻¹ g(x)`` (positions, then velocities; Ascher et al.'s block
        form), ``"full"`` repeats the sweeps until the residual stops shrinking (at most 8):
        coordinate projection onto the manifold.  Usually combined with ``none()``.

    Returns
    -------
    xarray.Dataset
        ``x(time, state)``, ``residual(time, component)``, ``residual_norm(time)``
        (max-norm, as in the paper), ``energy(time)`` when the model has one, and a
        ``status`` attribute.  If the integration stops early (singular ``S``, non-finite
        state, …) an :class:`IntegrationWarning` says why and when; the samples before the
        failure are kept and later ones are NaN.

    Examples
    --------
    >>> import stabdae
    >>> model = stabdae.load_model("pendulum")
    >>> ds = stabdae.integrate(model, None, stabdae.baumgarte(10.0, 1.0), "rk4", 1e-3, 2.0, 0.01)
    """
    who = "integrate"
    model = check.model(model, who)
    law = check.law(law, who)
    scheme = check.scheme(scheme, who)
    p = check.params(model, params, who)
    t0 = model.t0 if t0 is None else check.real(t0, "t0", who)
    tau = check.positive(tau, "tau", who)
    nsteps, save_every = check.fixed_time_grid(check.span(t0, t_end, who), tau, save_dt, who)
    x0 = check.initial_state(model, x0, p, who)
    bound = check.bound_law(law, model, who)
    multiplier = check.multiplier(multiplier, bound, who)
    sweeps, tol = check.projection(projection, who)

    kernel = integrator_for(model, bound, multiplier)
    nsave = nsteps // save_every + 1
    out_x = np.full((nsave, 2 * model.n), np.nan)
    out_g = np.full((nsave, model.n_residual), np.nan)
    out_e = np.full(nsave, np.nan)

    def run(x_start, t_start, steps, every, ox, og, oe):
        return kernel(x_start, t_start, tau, steps, every, p, bound.matrix, bound.scalars,
                      scheme.A, scheme.b, scheme.c, sweeps, tol, ox, og, oe)  # fmt: skip

    try:
        with guard(who):
            status, done = run(x0, t0, nsteps, save_every, out_x, out_g, out_e)
    except Exception as exc:  # a model function raised: say which, when and where
        where = replay_fixed(run, x0, t0, tau, nsteps, save_every, out_x, model.n_residual)
        find = stage_finder(model, bound, multiplier, scheme, tau, p)
        raise model_raised(who, model, p, exc, where, find) from exc
    status = Status(status)
    if status == Status.OK:  # a trajectory that ran to the end, but far off its manifold
        norms = np.abs(out_g).max(axis=1)
        level = _divergence(model, law, scheme, tau, nsteps, norms[0], divergence, who)
        over = np.flatnonzero(~(norms <= level))
        if over.size:
            first = int(over[0])
            status, done = Status.DIVERGED, first * save_every
            for arr in (out_x, out_g, out_e):
                arr[first + 1:] = np.nan
    if status != Status.OK:
        warnings.warn(
            f"integrate({model.name}): stopped at step {done} (t = {t0 + done * tau:g}) of "
            f"{nsteps}: {status.description}; samples up to there are kept, later ones are NaN",
            IntegrationWarning,
            stacklevel=2,
        )
    times = t0 + tau * save_every * np.arange(nsave)
    return trajectory_dataset(
        model, p, law, scheme, times, out_x, out_g, out_e, status, done,
        dict(tau=tau, t0=t0, t_end=t0 + nsteps * tau, save_dt=tau * save_every, steps=nsteps,
             multiplier=multiplier, projection=str(projection).lower()),
        action="integrate",
        multipliers=_multipliers(model, bound, multiplier, times, out_x, p)
        if with_multipliers else None,
    )  # fmt: skip


def _divergence(model, law, scheme, tau, nsteps, g0, divergence, who) -> float:
    """The divergence threshold of one trajectory (``integrate``'s ``divergence``)."""
    if divergence is not None:
        return check.positive(divergence, "divergence", who)
    g0 = float(g0) if np.isfinite(g0) else 0.0
    level = max(1.0, 1e3 * g0)
    if law.is_constant:
        R = theory.step_matrix(np.asarray(law.A_tilde(model), dtype=float), scheme, tau)
        peak = theory.power_norms(R, nsteps)[0]
        if math.isfinite(peak):
            level = max(level, 1e3 * peak * g0)
    return level


def _multipliers(model, bound, multiplier, times, xs, p):
    """``(λ, v̇)`` at the stored states (NaN where a state is not finite)."""
    lam = np.full((xs.shape[0], model.r), np.nan)
    acc = np.full((xs.shape[0], model.n), np.nan)
    multipliers_for(model, bound, multiplier)(np.ascontiguousarray(times), xs, p,
                                              bound.matrix, bound.scalars, lam, acc)  # fmt: skip
    return lam, acc
