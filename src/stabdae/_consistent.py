"""``model.consistent_state(...)``: a state on the constraint manifold with chosen
coordinates and velocities held, the rest solved for by Newton's method.

Two systems, one after the other: the positions from ``f(q, t) = 0`` in the coordinates
not held, then the velocities from ``ḟ = f_q T v + f_t = 0`` (T the model's kinematic
map, the identity without one) and ``h(q, v, t) = 0`` in the velocities not held.  Each is solved by Gauss–Newton steps (least squares on the free
unknowns, so that redundant but consistent constraints are allowed) from the starting
state; a system whose free unknowns the constraints do not determine (under-determined)
is refused before anything is solved, naming the unknowns left free, and one whose
residual does not reach the tolerance (the held values contradict a constraint, or no
real solution exists near the start) is refused naming the constraints that stay away
from zero.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import math
import warnings

import numpy as np

if TYPE_CHECKING:  # the model module imports this one
    from ._model import Model

#: Gauss–Newton iterations per system at most (converged ones take 3–6)
MAX_ITERATIONS = 50


def consistent_state(model: Model, fixed=None, *, guess=None, params=None, t=None,
                     tol: float = 1e-13) -> np.ndarray:  # fmt: skip
    """A consistent state ``x = (q, v)`` with the values in ``fixed`` held.

    Parameters
    ----------
    fixed : mapping
        State components to hold, by name (a coordinate, as ``model.coordinates``, or a
        velocity, as ``model.velocities``: ``<name>_dot`` unless the model names them) or
        index into ``x``, to their values.  Every other component is an unknown.
    guess : array (2n,), optional
        Where Newton's method starts (default: the reference state); it picks the branch
        where the constraints have several solutions (a mechanism's assembly modes).
    params : mapping or array, optional
        Physical parameters (default: the model's).
    t : float, optional
        Time (default ``model.t0``).
    tol : float
        The largest residual accepted, times ``max(1, |x|∞)²`` (the roundoff of a
        constraint quadratic in the coordinates): ``|f|, |ḟ|, |h| ≤ tol · max(1, |x|∞)²``.

    Returns
    -------
    numpy.ndarray, shape (2n,)

    Raises
    ------
    ValueError
        A name or index that is not a state component; the unknowns not determined by
        the constraints (fix more of them: they are named); no consistent state with the
        held values (the constraints that stay away from zero are named, with their
        residuals).
    """
    who = f"{model.name}.consistent_state"
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.integer, np.floating)) \
            or not (math.isfinite(tol) and tol > 0):  # NaN compared false: nothing refused
        raise ValueError(f"{who}: tol must be a positive finite number, got {tol!r}")
    n = model.n
    p = model.param_vector(params)
    t = model.t0 if t is None else float(t)
    x = model.reference_state(p) if guess is None else _state(guess, n, who)
    held = _held(model, fixed, who)
    for i, value in held.items():
        x[i] = value
    scale = max(1.0, float(np.max(np.abs(x))))
    limit = tol * scale * scale
    names = model.state_names
    free_q = [i for i in range(n) if i not in held]
    free_v = [n + i for i in range(n) if n + i not in held]

    if model.m:
        def positions(xx):
            return model.evaluate("f", t, xx, p), model.evaluate("f_q", t, xx, p)

        x = _solve(x, free_q, positions, [f"f_{i}" for i in range(model.m)], names, limit,
                   who, "coordinates", held)  # fmt: skip
    else:
        _nothing_determines(free_q, names, who, "coordinates", "holonomic constraint")

    if model.m or model.k:
        def velocities(xx):
            res, jac = [], []
            if model.m:  # F's holonomic rows along the kinematic map: f_q T
                fq = model.evaluate("f_q", t, xx, p) @ model.evaluate("kinematics", t, xx, p)
                res.append(fq @ xx[n:] + model.evaluate("f_t", t, xx, p))
                jac.append(fq)
            if model.k:
                res.append(model.evaluate("h", t, xx, p))
                jac.append(model.evaluate("h_v", t, xx, p))
            return np.concatenate(res), np.vstack(jac)

        rows = [f"fdot_{i}" for i in range(model.m)] + [f"h_{j}" for j in range(model.k)]
        shifted = [i - n for i in free_v]  # the Jacobians' columns are the velocities
        x = _solve(x, free_v, velocities, rows, names, limit, who, "velocities", held,
                   columns=shifted)  # fmt: skip
    else:
        _nothing_determines(free_v, names, who, "velocities", "constraint")
    return x


def _state(guess, n: int, who: str) -> np.ndarray:
    x = np.array(guess, dtype=np.float64)
    if x.shape != (2 * n,):
        raise ValueError(f"{who}: guess must have shape (2n,) = ({2 * n},), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{who}: guess has non-finite entries")
    return x


def _held(model: Model, fixed, who: str) -> dict[int, float]:
    if fixed is None:
        return {}
    if not isinstance(fixed, Mapping):
        raise ValueError(f"{who}: fixed must be a mapping of state components (names or "
                         f"indices) to values, got {type(fixed).__name__}")  # fmt: skip
    names = model.state_names
    out, given = {}, {}
    for key, value in fixed.items():
        if isinstance(key, str):
            if key not in names:
                raise ValueError(f"{who}: {key!r} is not a state component; they are "
                                 f"{', '.join(names)}")  # fmt: skip
            i = names.index(key)
        elif isinstance(key, (int, np.integer)) and not isinstance(key, bool) \
                and 0 <= key < 2 * model.n:
            i = int(key)
        else:
            raise ValueError(f"{who}: {key!r} is not a state component (a name of "
                             f"model.state_names or an index 0 … {2 * model.n - 1})")  # fmt: skip
        if i in out:
            raise ValueError(f"{who}: {names[i]} is held twice, as {given[i]!r} = "
                             f"{out[i]!r} and as {key!r} = {value!r}: give it once")  # fmt: skip
        given[i] = key
        try:
            value = float(value)
        except (TypeError, ValueError):  # complex, text, an array: one real number each
            raise ValueError(f"{who}: the value held for {names[i]} must be a real number, "
                             f"got {value!r}") from None  # fmt: skip
        if not np.isfinite(value):
            raise ValueError(f"{who}: the value held for {names[i]} is not finite: {value}")
        out[i] = value
    return out


def _nothing_determines(free, names, who, what, kind):
    if free:
        raise ValueError(
            f"{who}: no {kind} determines the {what} {', '.join(names[i] for i in free)}: "
            "hold them (fixed=...)"
        )


def _solve(x, free, system, rows, names, limit, who, what, held, columns=None):
    """Gauss–Newton on the components ``free`` of ``x`` for ``system(x) = (residual,
    Jacobian over all coordinates or velocities)`` (``columns``: the Jacobian's columns of
    ``free``, default ``free`` itself)."""
    columns = free if columns is None else columns
    x = x.copy()
    res, jac = system(x)
    _determined(jac[:, columns], free, names, who, what)
    for _ in range(MAX_ITERATIONS):
        if np.max(np.abs(res), initial=0.0) <= 0.1 * limit:
            break
        step = np.linalg.lstsq(jac[:, columns], -res, rcond=None)[0]
        x[free] += step
        res, jac = system(x)
        if np.max(np.abs(step), initial=0.0) <= 1e-16 * max(1.0, float(np.max(np.abs(x)))):
            break
    worst = np.abs(res)
    if not np.all(np.isfinite(x)) or np.max(worst, initial=0.0) > limit:
        bad = [f"{rows[r]} = {res[r]:.3g}" for r in np.argsort(-worst) if worst[r] > limit]
        why = ", ".join(names[i] for i in sorted(held)) or "nothing"
        raise ValueError(
            f"{who}: no consistent state near the start with the values held ({why}): the "
            f"constraints {', '.join(bad)} stay away from zero (tolerance {limit:.1e}); "
            "they contradict the held values, or have no solution near the guess"
        )
    _determined(jac[:, columns], free, names, who, what)
    _conditioned(jac, columns, free, names, who, what)
    return x


#: a solution is called ill-determined (and warned of) when the constraint Jacobian in the
#: unknowns solved for has a singular value below this fraction of the whole Jacobian's
#: largest: an error of δ in a held value or a constraint then moves it by δ / that
#: fraction or more (a mechanism at or next to a singular configuration)
ILL_CONDITIONED = 1e-6


def _conditioned(jac, columns, free, names, who, what):
    """Warn when the solution for ``free`` is ill-determined (:data:`ILL_CONDITIONED`)."""
    if not free or not jac.size:
        return
    whole = float(np.linalg.norm(jac, 2))
    small = float(np.linalg.svd(jac[:, columns], compute_uv=False)[-1])
    if whole > 0 and small < ILL_CONDITIONED * whole:
        warnings.warn(
            f"{who}: the constraints barely determine the {what} solved for "
            f"({', '.join(names[i] for i in free)}): the smallest singular value of their "
            f"Jacobian in them is {small:.2g}, {small / whole:.1e} of the largest: a "
            "singular configuration, where a small change of the held values moves the "
            "solution far; hold other components, or move away from it",
            RuntimeWarning, stacklevel=5)  # fmt: skip


def _determined(J, free, names, who, what):
    """Refuse a system whose Jacobian ``J`` over the unknowns ``free`` has a null space:
    those unknowns are not determined (name them: the components of the null space)."""
    if not free:
        return
    s, vt = (np.linalg.svd(J)[1:] if J.shape[0] else (np.zeros(0), np.eye(len(free))))
    top = float(s[0]) if s.size else 0.0
    rank = int(np.sum(s > 1e-10 * top)) if top > 0 else 0
    if rank < len(free):
        null = vt[rank:]
        loose = [free[c] for c in np.flatnonzero(np.max(np.abs(null), axis=0) > 1e-8)]
        raise ValueError(
            f"{who}: the constraints determine {rank} of the {len(free)} {what} not held; "
            f"hold {len(free) - rank} more of {', '.join(names[i] for i in loose)} "
            "(fixed=...)"
        )
