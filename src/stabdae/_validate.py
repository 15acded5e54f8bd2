"""Argument validation of the public drivers, in one place.

Every validator takes the value and the name of the function the user called (``who``)
and returns the cleaned value; every error message starts with that name and says what
was expected and what came::

    ensemble: tau must be positive and finite, got -0.001

Errors raised by the model, law or scheme constructors on the way are re-raised with the
caller's name in front, as the same exception type.  Nothing here runs per step.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ._codes import LawKind
from ._laws import Law, LawError, as_law, bind_law
from ._model import Model, ModelError
from ._schemes import EmbeddedPair, Scheme, SchemeError, as_scheme, embedded_pair
from .engine.rhs import MULTIPLIERS, PROJECTIONS

__all__ = [
    "block", "bound_law", "choice", "count", "dtype", "fixed_time_grid", "initial_state",
    "initial_states",
    "law", "model", "multiplier", "params", "positive", "projection", "radius", "real",
    "sample_times", "scheme", "seed", "span", "whole_multiple",
]  # fmt: skip


def _prefixed(exc: Exception, who: str) -> Exception:
    """``exc`` again, of the same type, with ``who: `` in front of its message."""
    msg = str(exc)
    if msg.startswith(f"{who}:"):
        return exc
    try:
        return type(exc)(f"{who}: {msg}")
    except TypeError:  # an exception type with another constructor
        return ValueError(f"{who}: {msg}")


def model(value, who: str) -> Model:
    if not isinstance(value, Model):
        raise TypeError(f"{who}: model must be a stabdae.Model (see stabdae.load_model), got "
                        f"{type(value).__name__}")  # fmt: skip
    return value


def law(value, who: str, example: str = "stabdae.baumgarte(omega=10.0, xi=1.0)") -> Law:
    if value is None:
        raise ValueError(f"{who}: give a law, e.g. {example}")
    try:
        return as_law(value)
    except LawError as exc:
        raise _prefixed(exc, who) from None


def bound_law(value: Law, model_: Model, who: str):
    """The law bound to the model (its matrix checked against the model's sizes)."""
    try:
        return bind_law(value, model_)
    except (LawError, ModelError) as exc:
        raise _prefixed(exc, who) from None


def scheme(value, who: str, default: str | None = None) -> Scheme:
    try:
        return as_scheme(default if value is None else value)
    except SchemeError as exc:
        raise _prefixed(exc, who) from None


def pair(value, who: str) -> EmbeddedPair:
    """The embedded pair for adaptive steps: ``"dopri5"`` (the default) or ``"dop853"``."""
    try:
        return embedded_pair("dopri5" if value is None else value, who)
    except SchemeError as exc:
        raise _prefixed(exc, who) from None


def params(model_: Model, values, who: str) -> np.ndarray:
    """The parameter vector ``p`` of ``model_`` with ``values`` applied."""
    try:
        return model_.param_vector(values)
    except ModelError as exc:
        raise _prefixed(exc, who) from None


def _float(value, name: str, who: str) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{who}: {name} must be a real number, got {value!r}") from None


def real(value, name: str, who: str) -> float:
    out = _float(value, name, who)
    if not math.isfinite(out):
        raise ValueError(f"{who}: {name} must be finite, got {value!r}")
    return out


def positive(value, name: str, who: str) -> float:
    out = _float(value, name, who)
    if not (math.isfinite(out) and out > 0):
        raise ValueError(f"{who}: {name} must be positive and finite, got {value!r}")
    return out


def tolerances(rtol, atol, who: str, size: int, scales=None):
    """The adaptive steps' ``(rtol, atol, as_given)``, one rule for every caller: ``rtol``
    positive and finite and at least 100 machine epsilons (below it the error estimate is
    roundoff, and the step size would shrink without end); ``atol`` a positive finite
    number or one per state component (shape ``(size,)`` = (2n,), as SciPy's
    ``solve_ivp`` takes it), or ``"scales"``: ``rtol`` times the model's ``scales``;
    returned as an array of ``size`` either way, and as given (a float, or the array)
    for the dataset."""
    rtol = positive(rtol, "rtol", who)
    if isinstance(atol, str):
        if atol != "scales":
            raise ValueError(f"{who}: atol must be a number, one per state component, or "
                             f"'scales'; got {atol!r}")
        if scales is None:
            raise ValueError(f"{who}: atol='scales' takes rtol times the model's scales, and "
                             "the model declares none (Model(..., scales=...))")
        atol = rtol * np.asarray(scales, dtype=float)
    if np.ndim(atol) == 0:
        given = positive(atol, "atol", who)
        vector = np.full(size, given)
    else:
        vector = _real_array(atol, who, "atol")
        if vector.shape != (size,):
            raise ValueError(f"{who}: atol must be a number or one per state component, "
                             f"shape (2n,) = ({size},); got shape {vector.shape}")
        bad = np.flatnonzero(~(np.isfinite(vector) & (vector > 0)))
        if bad.size:
            raise ValueError(f"{who}: atol must be positive and finite in every component; "
                             f"components {bad.tolist()} are {vector[bad].tolist()}")
        given = vector.copy()
    if rtol < 100 * np.finfo(float).eps:
        raise ValueError(
            f"{who}: rtol = {rtol:g} is below 100 machine epsilons "
            f"({100 * np.finfo(float).eps:.1e}); the error estimate is roundoff"
        )
    return rtol, np.ascontiguousarray(vector), given


def count(value, name: str, who: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{who}: {name} must be a positive integer, got {value!r}")
    return int(value)


#: stack a block of the ensemble kernel may take for its two copies of the states
#: (worker threads get 8 MiB by default; the rest is the member slot's own buffers)
BLOCK_STACK_BYTES = 2**20


def block(value, n: int, who: str, name: str = "block", copies: int = 2) -> int:
    """Members per lockstep block: a positive integer whose states fit the thread's stack
    (``copies`` copies of 2n doubles per member: two for fixed steps, four for the
    adaptive lanes)."""
    value = count(value, name, who)
    per_member = copies * 2 * n * 8 + 8
    most = BLOCK_STACK_BYTES // per_member
    if value > most:
        raise ValueError(
            f"{who}: {name} = {value} needs {value * per_member / 2**20:.1f} MiB of thread "
            f"stack for the block's states ({copies} copies of 2n = {2 * n} doubles per "
            f"member); at most {most} for this model (the default is as fast)"
        )
    return value


#: what an ensemble keeps per member besides its traces, over-estimated (measured with
#: tracemalloc at 1e5 members: 390 bytes on the pendulum, 470 on the double pendulum): the
#: states x0, x_final and the kernel's copies (8 n doubles), α⁰ and the per-block residual
#: rows (4 ng), and some 48 scalars of measurement and verdict
def ensemble_bytes(n: int, ng: int, members: int, traced: int, samples: int,
                   itemsize: int) -> int:  # fmt: skip
    """Memory an ensemble of ``members`` members needs, ``traced`` of them storing
    ``samples`` residual norms of ``itemsize`` bytes (twice: the kernel's and the
    dataset's)."""
    return 8 * (8 * n + 4 * ng + 48) * members + 2 * itemsize * traced * samples


def available_memory() -> int | None:
    """Bytes of memory available to a new allocation (``MemAvailable``), or the physical
    memory where that is not reported; None where neither is known."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return None


def fits_in_memory(nbytes: int, what: str, who: str, advice: str) -> None:
    """Refuse up front, with the figures, what would not fit in the memory available (the
    operating system would kill the process part-way instead)."""
    free = available_memory()
    if free is not None and nbytes > free:
        raise MemoryError(f"{who}: {what} needs about {nbytes / 2**30:.3g} GiB, more than "
                          f"the {free / 2**30:.3g} GiB of memory available; {advice}")


def seed(value, who: str) -> int:
    """A seed that the dataset can store (and a later run repeat): a non-negative integer."""
    if isinstance(value, np.random.Generator):
        raise TypeError(
            f"{who}: seed must be a non-negative integer, got a numpy Generator: the dataset "
            "stores the seed so that the run can be repeated (draw the initial states with "
            "stabdae.sample_perturbations(..., seed=generator) and pass them as x0 instead)"
        )
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise ValueError(f"{who}: seed must be a non-negative integer, got {value!r}")
    if value > MAX_SEED:  # the dataset's attribute is a 64-bit integer
        raise ValueError(f"{who}: seed must be at most 2**64 - 1 = {MAX_SEED} (the dataset "
                         f"stores it as a 64-bit integer), got {value}")  # fmt: skip
    return int(value)


#: the most fixed steps a run takes (a billion steps of the smallest model take hours;
#: far more only comes from a tau given in error, e.g. 1e-300)
MAX_STEPS = 10**12

#: the largest seed: the dataset's ``seed`` attribute is an unsigned 64-bit integer
MAX_SEED = 2**64 - 1


def choice(value, name: str, options, who: str):
    if value not in options:
        raise ValueError(f"{who}: {name} must be one of {tuple(options)}, got {value!r}")
    return value


def span(t0: float, t_end, who: str) -> float:
    """``t_end − t0``, positive and finite."""
    try:
        out = float(t_end) - t0
    except (TypeError, ValueError):
        raise ValueError(f"{who}: t_end must be a real number, got {t_end!r}") from None
    if not (math.isfinite(out) and out > 0):
        raise ValueError(f"{who}: t_end must be after t0 = {t0:g}, got t_end = {t_end!r}")
    return out


def whole_multiple(total: float, unit: float, total_name: str, unit_name: str,
                   who: str) -> int:  # fmt: skip
    """``total / unit`` when it is a whole number (to 1e-9 relative), else an error that
    gives the nearest values that are."""
    count_ = round(total / unit)
    if count_ < 1 or abs(count_ * unit - total) > 1e-9 * max(total, unit):
        lo, hi = max(1, math.floor(total / unit)), max(1, math.ceil(total / unit))
        near = f"{lo * unit:g}" if lo == hi else f"{lo * unit:g} or {hi * unit:g}"
        raise ValueError(
            f"{who}: {total_name} = {total:g} must be a whole multiple of {unit_name} = "
            f"{unit:g} (fixed steps; samples on the step grid); nearest: {near}"
        )
    return count_


def fixed_time_grid(span_: float, tau: float, save_dt, who: str, *,
                    default_samples: int | None = None) -> tuple[int, int]:  # fmt: skip
    """``(steps, steps between stored samples)`` of a fixed-step run over ``span_``.

    ``save_dt=None`` stores every step, or about ``default_samples`` samples when given
    (the largest spacing that divides the steps)."""
    nsteps = whole_multiple(span_, tau, "t_end - t0", "tau", who)
    if nsteps > MAX_STEPS:
        raise ValueError(f"{who}: t_end - t0 = {span_:g} in steps of tau = {tau:g} is "
                         f"{nsteps:.3g} steps: at most {MAX_STEPS:.0e} (a larger tau)")  # fmt: skip
    if save_dt is None:
        if default_samples is None:
            return nsteps, 1
        every = max(1, nsteps // default_samples)
        while nsteps % every:
            every -= 1
        return nsteps, every
    every = whole_multiple(positive(save_dt, "save_dt", who), tau, "save_dt", "tau", who)
    if nsteps % every:
        raise ValueError(
            f"{who}: t_end - t0 = {span_:g} must be a whole multiple of save_dt = {save_dt:g}"
        )
    return nsteps, every


def sample_times(t0: float, t_end: float, save_dt, who: str) -> np.ndarray:
    """Sample times after ``t0`` of an adaptive run: every ``save_dt``, the last one at
    ``t_end`` (only ``t_end`` when ``save_dt`` is None)."""
    if save_dt is None:
        return np.array([t_end])
    save_dt = positive(save_dt, "save_dt", who)
    n = max(1, int(math.ceil((t_end - t0) / save_dt - 1e-9)))
    out = np.minimum(t0 + save_dt * np.arange(1, n + 1), t_end)
    out[-1] = t_end
    return out


def _real_array(value, who: str, what: str) -> np.ndarray:
    """``value`` as a float64 array; complex numbers refused (a cast would drop their
    imaginary parts), as anything that is not numbers."""
    if np.iscomplexobj(value):
        raise ValueError(f"{who}: {what} must be real numbers, got complex values")
    try:
        return np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{who}: {what} must be an array of numbers, got "
                         f"{type(value).__name__}") from None  # fmt: skip


def initial_state(model_: Model, x0, p, who: str) -> np.ndarray:
    """``x0`` as a finite float64 (2n,) array; the reference state when None."""
    if x0 is None:
        x0 = model_.reference_state(p)
    x0 = _real_array(x0, who, "x0")
    if x0.shape != (2 * model_.n,):
        raise ValueError(
            f"{who}: x0 must have shape (2n,) = ({2 * model_.n},) for model {model_.name!r}, "
            f"got {x0.shape}"
        )
    if not np.all(np.isfinite(x0)):
        raise ValueError(f"{who}: x0 has non-finite entries")
    return x0


def initial_states(model_: Model, x0, who: str) -> np.ndarray:
    """``x0`` as a C-contiguous float64 (members, 2n) array (rows may be non-finite: those
    members get a status)."""
    x0 = _real_array(x0, who, "x0")
    if x0.ndim != 2 or x0.shape[1] != 2 * model_.n or x0.shape[0] < 1:
        raise ValueError(
            f"{who}: x0 must have shape (members, 2n) = (M, {2 * model_.n}) for model "
            f"{model_.name!r}, got {x0.shape}"
        )
    return np.ascontiguousarray(x0)


def radius(value, who: str) -> tuple[float, float]:
    """``(low, high)`` of a radius given as a number or a pair of positive numbers."""
    try:
        vals = np.atleast_1d(np.asarray(value, dtype=np.float64))
    except (TypeError, ValueError):
        vals = np.array([np.nan])
    if vals.shape not in ((1,), (2,)) or not np.all(np.isfinite(vals)) or np.any(vals <= 0):
        raise ValueError(
            f"{who}: radius must be a positive number or a pair (low, high) of positive "
            f"numbers, got {value!r}"
        )
    low, high = float(vals[0]), float(vals[-1])
    if low > high:
        raise ValueError(f"{who}: radius low = {low:g} exceeds high = {high:g}")
    return low, high


def multiplier(value, bound, who: str) -> str:
    choice(value, "multiplier", MULTIPLIERS, who)
    if bound.code == LawKind.ACPR and value != "ldl":
        raise LawError(
            f"{who}: the acpr correction uses the L D Lᵀ factor of S; multiplier must be "
            f"'ldl', got {value!r}"
        )
    return value


def projection(value, who: str) -> tuple[int, float]:
    """``(sweeps, tolerance)`` of a ``projection`` argument (None, "post" or "full")."""
    if value not in PROJECTIONS:
        raise ValueError(f"{who}: projection must be None, 'post' or 'full', got {value!r}")
    return PROJECTIONS[value]


def dtype(value, name: str, options, who: str) -> np.dtype:
    choice(str(value), name, tuple(options), who)
    return np.dtype(str(value))

