"""Where a model function raised inside a compiled kernel.

An exception raised in ``@njit`` code reaches Python with its message alone: numba keeps
no time, no state and no name of the function that raised.  When a kernel raises, the
driver replays the run to the step that raised (the same kernel from the last stored
sample, storing every step) and calls the model's functions as Python at the state that
step starts from, so that the message names the function, the time and the state.
"""

from __future__ import annotations

import numpy as np

from ._model import _PIECES, ModelError, _call_signature

__all__ = ["first_raising_member", "model_raised", "replay_fixed", "stage_finder",
           "which_function"]


def _vector(x) -> str:
    return np.array2string(np.asarray(x), precision=6, max_line_width=10**6)


def which_function(model, t: float, x, p) -> tuple[str, BaseException] | None:
    """The first model function that raises as Python at ``(t, x)``, with what it raised."""
    n = model.n
    q, v = np.array(x[:n], dtype=float), np.array(x[n:], dtype=float)
    for piece, fn in model.functions.items():
        pattern, shape_of, _ = _PIECES[piece]
        out = np.zeros(shape_of(model.n, model.m, model.k))
        args = (float(t), q.copy(), p) if pattern == "tqp" else (float(t), q.copy(), v.copy(), p)
        try:
            with np.errstate(all="ignore"):
                getattr(fn, "py_func", fn)(*args, out)
        except Exception as exc:  # the user's function, whatever it raises
            return piece, exc
    return None


def replay_fixed(run, x0, t0: float, tau: float, nsteps: int, save_every: int, stored_x,
                 ng: int):  # fmt: skip
    """``(t, x)`` at the start of the step that raises.  ``run(x, t, steps, every, out_x,
    out_g, out_e)`` is the single-trajectory kernel; ``stored_x`` holds the samples the
    raising run wrote (NaN after it stopped).  From the last of them the kernel runs again
    storing every step, and raises at the same step.  None when the replay does not
    raise."""
    good = np.flatnonzero(np.isfinite(stored_x).all(axis=1))
    k = int(good[-1]) if good.size else 0
    x_k = np.array(stored_x[k] if good.size else x0, dtype=float)
    t_k = t0 + k * save_every * tau
    steps = max(1, min(save_every, nsteps - k * save_every))
    out_x = np.full((steps + 1, x_k.size), np.nan)
    out_g = np.full((steps + 1, ng), np.nan)
    out_e = np.full(steps + 1, np.nan)
    try:
        run(x_k, t_k, steps, 1, out_x, out_g, out_e)
    except Exception:  # raised again: the last step stored is the one the raise ended
        rows = np.flatnonzero(np.isfinite(out_x).all(axis=1))
        j = int(rows[-1]) if rows.size else 0
        return t_k + j * tau, (out_x[j] if rows.size else x_k)
    return None


def first_raising_member(run, x0s, t0: float, tau: float, nsteps: int, ng: int):
    """``(t, x, member)`` of the first member whose trajectory raises, each run alone
    with ``run`` (the single-trajectory kernel) over the ensemble's steps; None when none
    does."""
    every = max(1, nsteps // 64)
    nsave = nsteps // every + 1
    for i, x0 in enumerate(x0s):
        out_x = np.full((nsave, x0.size), np.nan)
        try:
            run(np.array(x0, dtype=float), t0, nsteps, every, out_x,
                np.full((nsave, ng), np.nan), np.full(nsave, np.nan))  # fmt: skip
        except Exception:
            where = replay_fixed(run, x0, t0, tau, nsteps, every, out_x, ng)
            return None if where is None else (*where, i)
    return None


def stage_finder(model, bound, multiplier: str, scheme, tau: float, p):
    """``find(t, x)``: ``(i, t_i, x_i)`` of the first stage whose evaluation raises in the
    fixed step of size ``tau`` from ``(t, x)`` (None when none does).  It runs the compiled
    step with the first ``j`` stages of the tableau for ``j = 1, 2, …``: the same
    arithmetic as the full step up to stage ``j``, whose argument is left in the scratch
    ``xs`` when it raises."""
    from .engine.rhs import kernels_for
    from .engine.rk.steps import stepper_for

    def find(t, x):
        step = stepper_for(model, bound, multiplier).step
        ws = kernels_for(model, bound, multiplier).make_workspace()
        A, b, c = scheme.A, scheme.b, scheme.c
        for j in range(1, b.size + 1):
            xs = np.zeros(x.size)
            try:
                step(np.array(x, dtype=float), float(t), float(tau), p, bound.matrix,
                     bound.scalars, np.ascontiguousarray(A[:j, :j]), b[:j].copy(),
                     c[:j].copy(), ws, np.zeros((j, x.size)), xs)  # fmt: skip
            except Exception:
                return j - 1, float(t + c[j - 1] * tau), xs
        return None

    return find


def model_raised(who: str, model, p, exc: BaseException, where, find_stage=None) -> ModelError:
    """The error to raise for ``exc`` from a kernel: ``where`` is ``(t, x)`` of the step it
    started from (None where the replay could not find it), or ``(t, x, whose)`` with
    ``whose`` naming the trajectory ("member 3"); ``find_stage`` (:func:`stage_finder`)
    looks inside the step where no function raises at its start."""
    what = f"{type(exc).__name__}: {exc}"
    if where is None:
        return ModelError(f"{who}: a function of model {model.name!r} raised {what} inside "
                          "the compiled kernel (the replay did not find the step)")
    t, x, *member = where
    whose = f" ({member[0]})" if member else ""
    found = which_function(model, t, x, p)
    n = model.n
    state = f"t = {t:g}, q = {_vector(x[:n])}, v = {_vector(x[n:])}"
    if found is not None:
        piece, raised = found
        return ModelError(f"{who}: {model.name}'s {_call_signature(piece)} raised "
                          f"{type(raised).__name__}: {raised} at {state}{whose}")
    stage = find_stage(t, np.asarray(x, dtype=float)) if find_stage is not None else None
    found = None if stage is None else which_function(model, stage[1], stage[2], p)
    if found is not None:
        piece, raised = found
        i, t_i, x_i = stage
        return ModelError(f"{who}: {model.name}'s {_call_signature(piece)} raised "
                          f"{type(raised).__name__}: {raised} at t = {t_i:g}, "
                          f"q = {_vector(x_i[:n])}, v = {_vector(x_i[n:])}: stage {i + 1} "
                          f"of the step from {state}{whose}")
    return ModelError(f"{who}: a function of model {model.name!r} raised {what} during the "
                      f"step from {state}{whose}, at one of its stages (every function runs "
                      "at that state itself)")
