"""One trajectory of the stabilized equations with a fixed-step explicit Runge–Kutta scheme."""

from __future__ import annotations

import math
import warnings
from collections import namedtuple

import numpy as np
import xarray as xr
from numba import njit

from ._cache import kernel_key, keyed_cache
from ._dataset import model_coords, provenance, variable
from ._fma import fma
from ._laws import as_law, bind_law
from ._model import Model
from ._rhs import MULTIPLIERS, PROJECTIONS, kernels_for
from ._schemes import as_scheme
from ._status import Status, status_flag_attrs

__all__ = ["integrate", "IntegrationWarning"]

_NONFINITE = int(Status.NONFINITE_STATE)


class IntegrationWarning(RuntimeWarning):
    """An integration stopped early; the dataset holds everything up to that step."""


Stepper = namedtuple("Stepper", "step integrate")


def stepper_for(model: Model, bound, multiplier: str = "ldl") -> Stepper:
    """The compiled RK step and single-trajectory loop for ``model`` under the law's kind
    (memoized on the model)."""
    key = ("stepper", bound.code, bound.fn, multiplier)
    cache = model._kernel_cache
    if key not in cache:
        cache[key] = _build_stepper(kernels_for(model, bound, multiplier))
    return cache[key]


def integrator_for(model: Model, bound, multiplier: str = "ldl"):
    """The compiled single-trajectory loop for ``model`` under the law's kind."""
    return stepper_for(model, bound, multiplier).integrate


def initial_state(model: Model, x0, p, who: str) -> np.ndarray:
    """``x0`` as a finite float64 (2n,) array; the reference state when None."""
    if x0 is None:
        x0 = model.reference_state(p)
    x0 = np.array(x0, dtype=np.float64)
    if x0.shape != (2 * model.n,):
        raise ValueError(
            f"{who}: x0 must have shape (2n,) = ({2 * model.n},) for model {model.name!r}, "
            f"got {x0.shape}"
        )
    if not np.all(np.isfinite(x0)):
        raise ValueError(f"{who}: x0 has non-finite entries")
    return x0


def check_multiplier(multiplier, who: str) -> str:
    if multiplier not in MULTIPLIERS:
        raise ValueError(f"{who}: multiplier must be one of {MULTIPLIERS}, got {multiplier!r}")
    return multiplier


def projection_setting(projection, who: str) -> tuple[int, float]:
    """``(sweeps, tolerance)`` of a ``projection`` argument (None, "post" or "full")."""
    if projection not in PROJECTIONS:
        raise ValueError(
            f"{who}: projection must be None, 'post' or 'full', got {projection!r}"
        )
    return PROJECTIONS[projection]


def sample_writer(K):
    """``save(j, t, x, p, ws, g, out_x, out_g, out_e)``: state, residual and energy at ``t``
    into row ``j`` of the outputs (inlined into the single-trajectory loops)."""
    residual, energy = K.residual, K.energy
    N2, ng = 2 * K.n, K.ng

    @njit(forceinline=True)
    def save(j, t, x, p, ws, g, out_x, out_g, out_e):
        residual(t, x, p, ws, g)
        for l in range(N2):
            out_x[j, l] = x[l]
        for l in range(ng):
            out_g[j, l] = g[l]
        out_e[j] = energy(t, x, p, ws)

    return save


def _build_stepper(K):
    rhs, make_workspace, project = K.rhs, K.make_workspace, K.project
    save = sample_writer(K)
    N2, ng = 2 * K.n, K.ng

    @njit(error_model="numpy")
    def step(x, t, tau, p, law_mat, law_scal, tab_a, tab_b, tab_c, ws, stages, xs):
        """One explicit RK step, ``x`` updated in place; returns a status code.

        ``stages`` (s × 2n) and ``xs`` (2n) are scratch.  On a non-zero status ``x`` is
        left as it was before the step.
        """
        s = tab_b.shape[0]
        for i in range(s):
            for l in range(N2):
                acc = x[l]
                for j in range(i):
                    if tab_a[i, j] != 0.0:  # as the ensemble kernel, which compiles them out
                        acc = fma(tau * tab_a[i, j], stages[j, l], acc)
                xs[l] = acc
            st = rhs(t + tab_c[i] * tau, xs, p, law_mat, law_scal, ws, stages[i])
            if st != 0:
                return st
        for l in range(N2):
            acc = -0.0  # the exact identity of +, so the first term is taken as it is
            for i in range(s):
                if tab_b[i] != 0.0:
                    acc = fma(tab_b[i], stages[i, l], acc)
            xs[l] = fma(tau, acc, x[l])
            if not math.isfinite(xs[l]):
                return _NONFINITE
        for l in range(N2):
            x[l] = xs[l]
        return 0

    @njit(error_model="numpy")
    def integrate_kernel(x0, t0, tau, nsteps, save_every, p, law_mat, law_scal,
                         tab_a, tab_b, tab_c, sweeps, tol, out_x, out_g, out_e):  # fmt: skip
        """Integrate from ``x0`` for ``nsteps`` steps, saving every ``save_every`` steps;
        after each step, ``sweeps > 0`` projects the state (``K.project``).

        Writes sample ``j`` (time ``t0 + j·save_every·τ``) into ``out_x[j]``, ``out_g[j]``
        and ``out_e[j]``; samples after a failure are left untouched.  Returns
        ``(status, steps completed)``.
        """
        ws = make_workspace()
        stages = np.empty((tab_b.shape[0], N2))
        xs = np.empty(N2)
        g = np.empty(ng)
        x = x0.copy()
        j = 0
        t = t0
        for i in range(nsteps + 1):
            if i > 0:
                st = step(x, t, tau, p, law_mat, law_scal, tab_a, tab_b, tab_c, ws, stages, xs)
                if st != 0:
                    return st, i - 1
                t = t0 + i * tau  # from the step count, not accumulated
                if sweeps > 0:
                    st = project(t, x, p, ws, sweeps, tol)
                    if st != 0:
                        return st, i - 1
            if i % save_every == 0:
                save(j, t, x, p, ws, g, out_x, out_g, out_e)
                j += 1
        return 0, nsteps

    keyed_cache(step, kernel_key(K.key, "step"))
    keyed_cache(integrate_kernel, kernel_key(K.key, "integrate"))
    return Stepper(step, integrate_kernel)


def _positive(value, name: str) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"integrate: {name} must be a real number, got {value!r}") from None
    if not (math.isfinite(out) and out > 0):
        raise ValueError(f"integrate: {name} must be positive and finite, got {value!r}")
    return out


def _whole_multiple(total: float, unit: float, total_name: str, unit_name: str) -> int:
    count = round(total / unit)
    if count < 1 or abs(count * unit - total) > 1e-9 * max(total, unit):
        lo, hi = max(1, math.floor(total / unit)), math.ceil(total / unit)
        raise ValueError(
            f"integrate: {total_name} = {total:g} must be a whole multiple of {unit_name} = "
            f"{unit:g} (fixed steps; samples on the step grid); nearest: {lo * unit:g} or "
            f"{hi * unit:g}"
        )
    return count


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
    if not isinstance(model, Model):
        raise TypeError(f"integrate: model must be a stabdae.Model, got {type(model).__name__}")
    if law is None:
        raise ValueError("integrate: give a law, e.g. stabdae.baumgarte(omega=10.0, xi=1.0)")
    law = as_law(law)
    scheme = as_scheme(scheme)
    p = model.param_vector(params)
    t0 = model.t0 if t0 is None else float(t0)
    tau = _positive(tau, "tau")
    span = float(t_end) - t0
    if not (math.isfinite(span) and span > 0):
        raise ValueError(f"integrate: t_end must be after t0 = {t0}, got t_end = {t_end!r}")
    nsteps = _whole_multiple(span, tau, "t_end - t0", "tau")
    save_dt = tau if save_dt is None else _positive(save_dt, "save_dt")
    save_every = _whole_multiple(save_dt, tau, "save_dt", "tau")
    if nsteps % save_every:
        raise ValueError(
            f"integrate: t_end - t0 = {span:g} must be a whole multiple of save_dt = {save_dt:g}"
        )
    x0 = initial_state(model, x0, p, "integrate")

    multiplier = check_multiplier(multiplier, "integrate")
    sweeps, tol = projection_setting(projection, "integrate")
    bound = bind_law(law, model)
    kernel = integrator_for(model, bound, multiplier)
    nsave = nsteps // save_every + 1
    out_x = np.full((nsave, 2 * model.n), np.nan)
    out_g = np.full((nsave, model.n_residual), np.nan)
    out_e = np.full(nsave, np.nan)
    status, done = kernel(
        x0, t0, tau, nsteps, save_every, p, bound.matrix, bound.scalars,
        scheme.A, scheme.b, scheme.c, sweeps, tol, out_x, out_g, out_e,
    )  # fmt: skip
    status = Status(status)
    if status != Status.OK:
        warnings.warn(
            f"integrate({model.name}): stopped at step {done} (t = {t0 + done * tau:g}) of "
            f"{nsteps}: {status.description}; samples up to there are kept, later ones are NaN",
            IntegrationWarning,
            stacklevel=2,
        )
    times = t0 + tau * save_every * np.arange(nsave)
    return _trajectory_dataset(
        model, p, law, scheme, times, out_x, out_g, out_e, status, done,
        dict(tau=tau, t0=t0, t_end=t0 + nsteps * tau, save_dt=save_dt, steps=nsteps,
             multiplier=multiplier, projection=str(projection).lower()),
    )  # fmt: skip


def _trajectory_dataset(model, p, law, scheme, times, xs, gs, es, status, done, run):
    coords = model_coords(model, times)
    data = {
        "x": variable(
            ("time", "state"), xs, "state x = (q, v)", "mixed (see state_units)",
        ),  # fmt: skip
        "residual": variable(
            ("time", "component"), gs, "constraint residual g = (f, fdot, h) (3.2)",
            "1", comment="in the units of each constraint function",
        ),  # fmt: skip
        "residual_norm": variable(
            "time", np.max(np.abs(gs), axis=1), "max-norm of the constraint residual", "1"
        ),
    }
    if model.energy is not None:
        data["energy"] = variable("time", es, "energy (model's energy function)", "model units")
    attrs = provenance(model, p, law, scheme, **run)
    attrs.update(status=int(status), status_name=status.name.lower(), steps_completed=done)
    attrs.update({f"status_{k}": v for k, v in status_flag_attrs().items()})
    return xr.Dataset(data, coords=coords, attrs=attrs)
