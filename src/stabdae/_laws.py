"""Constraint-perturbation laws ``ġ = Ã g`` (the paper's (2.1)–(2.2), (3.9)).

A law supplies the r × (m + r) matrix ``A`` of (3.9); the full matrix of the residual
law is

    Ã = | 0    I_m  0   |      (first block row: d/dt f = ḟ holds by definition)
        | A10  A11  A12 |
        | A20  A21  A22 |

Constant laws (``baumgarte``, ``matrix``, ``none``) reach the compiled kernel as a runtime
array, so sweeping ω, ξ or any entry of ``A`` never recompiles; ``theorem5`` and user laws
are evaluated at the current state inside the kernel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba.core.dispatcher import Dispatcher

from ._codes import LawKind
from ._model import Model, ModelError, probe_output
from .engine.jit import is_njit

__all__ = [
    "Law", "BoundLaw", "baumgarte", "matrix", "theorem5", "none", "user", "acpr", "as_law",
]



class LawError(ValueError):
    """A law does not fit the model it is applied to."""


@dataclass(frozen=True)
class BoundLaw:
    """A law specialised to one model: what the kernel needs.

    Attributes
    ----------
    code : int
        Compile-time kind, a :class:`~stabdae._codes.LawKind` (constant, Theorem 5, user,
        Ascher–Chin–Petzold–Reich, constant of scalar blocks).
    matrix : float64[:, :]
        Constant ``A`` (r × (m + r)) for constant laws; ``L`` (k × k) for Theorem 5; an
        unused 1×1 array for user laws.
    scalars : float64[:]
        Runtime scalars: the gain ``k`` for Theorem 5.
    fn : Dispatcher or None
        The user's ``A(t, x, p, out)``.
    """

    law: Law
    code: int
    matrix: np.ndarray
    scalars: np.ndarray
    fn: Dispatcher | None = None


class Law:
    """Base class of constraint-perturbation laws."""

    #: name stored in dataset attributes
    kind: str = "law"

    @property
    def is_constant(self) -> bool:
        return True

    def A(self, model: Model) -> np.ndarray:
        """The r × (m + r) matrix ``A`` of (3.9) for ``model`` (constant laws only)."""
        raise NotImplementedError

    def bind(self, model: Model) -> BoundLaw:
        A = np.ascontiguousarray(self.A(model))
        factors = _scalar_blocks(A, model.m, model.k)
        if factors is not None:
            return BoundLaw(self, int(LawKind.SCALAR_BLOCKS), factors, np.zeros(1))
        return BoundLaw(self, int(LawKind.CONSTANT), A, np.zeros(1))

    def A_tilde(self, model: Model, x=None, t=None, p=None) -> np.ndarray:
        """The full (2m + k) × (2m + k) matrix ``Ã`` of (3.9).

        For state-dependent laws it is evaluated at ``x`` (default: the reference state).
        """
        return full_matrix(model, self.A(model))

    def attrs(self) -> dict:
        """Flat description for dataset attributes."""
        return {"law": self.kind}

    def __str__(self) -> str:
        items = ", ".join(f"{k}={v}" for k, v in self.attrs().items() if k != "law")
        return f"{self.kind}({items})"


def full_matrix(model: Model, A: np.ndarray) -> np.ndarray:
    """Ã of (3.9) from the r × (m + r) matrix ``A``."""
    m, ng = model.m, model.n_residual
    At = np.zeros((ng, ng))
    At[:m, m : 2 * m] = np.eye(m)
    At[m:, :] = A
    return At


@dataclass(frozen=True, repr=False)
class Baumgarte(Law):
    """Baumgarte's stabilization: ``f̈ = −2ξω ḟ − ω² f``, ``ḣ = −k h``."""

    omega: float | None = None
    xi: float = 1.0
    k: float | None = None
    kind: str = field(default="baumgarte", init=False)

    def A(self, model: Model) -> np.ndarray:
        m, k = model.m, model.k
        if m and self.omega is None:
            raise LawError(
                f"baumgarte: model {model.name!r} has m={m} holonomic constraints; give omega"
            )
        if k and self.k is None:
            raise LawError(
                f"baumgarte: model {model.name!r} has k={k} nonholonomic constraints; "
                "give the gain k (ḣ = −k h)"
            )
        if not k and self.k is not None:  # a gain that would act on nothing, silently
            raise LawError(
                f"baumgarte: model {model.name!r} has no nonholonomic constraints (k = 0), "
                f"so the gain k = {self.k:g} has nothing to act on; leave k out"
            )
        A = np.zeros((m + k, 2 * m + k))
        if m:
            A[:m, :m] = -(self.omega**2) * np.eye(m)
            A[:m, m : 2 * m] = -2.0 * self.xi * self.omega * np.eye(m)
        if k:
            A[m:, 2 * m :] = -self.k * np.eye(k)
        return A

    def attrs(self) -> dict:
        out = {"law": self.kind, "xi": self.xi}
        if self.omega is not None:
            out["omega"] = self.omega
        if self.k is not None:
            out["k"] = self.k
        return out


@dataclass(frozen=True, repr=False, eq=False)
class MatrixLaw(Law):
    """Any constant matrix ``A`` (r × (m + r)), or the full ``Ã`` ((2m + k) square)."""

    matrix: np.ndarray
    kind: str = field(default="matrix", init=False)

    def A(self, model: Model) -> np.ndarray:
        A = self.matrix
        r, ng, m = model.r, model.n_residual, model.m
        if A.shape == (r, ng):
            return A.copy()
        if A.shape == (ng, ng) and ng != r:
            top = np.zeros((m, ng))
            top[:, m : 2 * m] = np.eye(m)
            if not np.array_equal(A[:m], top):
                raise LawError(
                    f"matrix: a full Ã of shape {A.shape} must have first block row "
                    f"[0, I_{m}, 0] (d/dt f = ḟ by definition, (3.9)); got {A[:m].tolist()}"
                )
            return A[m:].copy()
        raise LawError(
            f"matrix: A must have shape (r, m + r) = ({r}, {ng}) for model {model.name!r} "
            f"(m={m}, k={model.k}), or the full Ã of shape ({ng}, {ng}); got {A.shape}"
        )

    def attrs(self) -> dict:
        return {"law": self.kind, "A": self.matrix.ravel().tolist()}


@dataclass(frozen=True, repr=False)
class NoStabilization(Law):
    """``A = 0``: the index-1 equations ``f̈ = 0, ḣ = 0`` with no feedback (drift)."""

    kind: str = field(default="none", init=False)

    def A(self, model: Model) -> np.ndarray:
        return np.zeros((model.r, model.n_residual))


@dataclass(frozen=True, repr=False, eq=False)
class Theorem5(Law):
    """Theorem 5's law for nonholonomic systems: ``ḣ = −k W(x) L h`` with ``W = h_v h_vᵀ``."""

    gain: float
    L: np.ndarray | None = None
    kind: str = field(default="theorem5", init=False)

    @property
    def is_constant(self) -> bool:
        return False

    def _L(self, model: Model) -> np.ndarray:
        if model.m:
            raise LawError(
                f"theorem5: the law is for nonholonomic constraints only (m = 0); model "
                f"{model.name!r} has m={model.m}"
            )
        k = model.k
        L = np.eye(k) if self.L is None else self.L
        if L.shape != (k, k):
            raise LawError(
                f"theorem5: L must have shape (k, k) = ({k}, {k}) for model {model.name!r}, "
                f"got {L.shape}"
            )
        if not np.allclose(L, L.T) or np.linalg.eigvalsh(0.5 * (L + L.T)).min() <= 0:
            raise LawError(f"theorem5: L must be symmetric positive definite, got {L.tolist()}")
        return np.ascontiguousarray(L)

    def A(self, model: Model) -> np.ndarray:
        raise LawError(
            "theorem5: A = −k W(x) L depends on the state; use A_tilde(model, x) to evaluate it"
        )

    def bind(self, model: Model) -> BoundLaw:
        return BoundLaw(self, int(LawKind.THEOREM5), self._L(model), np.array([self.gain]))

    def A_tilde(self, model: Model, x=None, t=None, p=None) -> np.ndarray:
        L = self._L(model)
        p = model.default_params() if p is None else p
        x = model.reference_state(p) if x is None else np.asarray(x, float)
        hv = model.evaluate("h_v", model.t0 if t is None else t, x, p)
        return -self.gain * (hv @ hv.T) @ L

    def attrs(self) -> dict:
        out = {"law": self.kind, "k": self.gain}
        if self.L is not None:
            out["L"] = self.L.ravel().tolist()
        return out


@dataclass(frozen=True, repr=False)
class UserLaw(Law):
    """A state-dependent law ``A(t, x, p, out)`` written as an ``@njit`` function."""

    fn: Dispatcher
    kind: str = field(default="user", init=False)

    @property
    def is_constant(self) -> bool:
        return False

    def A(self, model: Model) -> np.ndarray:
        raise LawError("user law: A depends on the state; use A_tilde(model, x) to evaluate it")

    def _evaluate(self, model: Model, x, t, p) -> np.ndarray:
        shape = (model.r, model.n_residual)
        return probe_output(
            f"user law {getattr(self.fn, '__name__', 'A')}(t, x, p, out)",
            self.fn, (float(t), np.ascontiguousarray(x, dtype=float), p), shape,
            f"(r, m + r) from m={model.m}, k={model.k}",
        )  # fmt: skip

    def bind(self, model: Model) -> BoundLaw:
        p = model.default_params()
        self._evaluate(model, model.reference_state(p), model.t0, p)
        return BoundLaw(self, int(LawKind.USER), np.zeros((1, 1)), np.zeros(1), self.fn)

    def A_tilde(self, model: Model, x=None, t=None, p=None) -> np.ndarray:
        p = model.default_params() if p is None else p
        x = model.reference_state(p) if x is None else x
        return full_matrix(model, self._evaluate(model, x, model.t0 if t is None else t, p))

    def attrs(self) -> dict:
        return {"law": self.kind, "function": getattr(self.fn, "__name__", "?")}


@dataclass(frozen=True, repr=False)
class ACPR(Law):
    """Ascher–Chin–Petzold–Reich stabilization of the index-1 equations (the end of the paper's §3).

    ``ẋ = ẋ₁(x) − γ_s D (G D)⁻¹ g(x)`` where ``ẋ₁`` is the right-hand side with ``A = 0``
    and ``D (G D)⁻¹`` is taken in the block form of Ascher et al. for mechanical systems:
    ``δq = M⁻¹f_qᵀ (f_q M⁻¹f_qᵀ)⁻¹ f`` and ``δv = M⁻¹Fᵀ S⁻¹ (ḟ, h)``.  The residual then
    obeys ``ġ = −γ_s (I + N(x)) g`` with ``N`` strictly lower block-triangular (the
    ``∂ḟ/∂q δq`` and ``∂h/∂q δq`` terms): every eigenvalue is ``−γ_s``, but it is not a
    law ``ġ = Ã g`` with a constant ``Ã``.
    """

    gamma: float
    kind: str = field(default="acpr", init=False)

    @property
    def is_constant(self) -> bool:
        return False

    def A(self, model: Model) -> np.ndarray:
        raise LawError(
            "acpr: the residual obeys ġ = −γ_s (I + N(x)) g, not a law ġ = Ã g of (3.9)"
        )

    def A_tilde(self, model: Model, x=None, t=None, p=None) -> np.ndarray:
        return self.A(model)

    def bind(self, model: Model) -> BoundLaw:
        return BoundLaw(self, int(LawKind.ACPR), np.zeros((model.r, model.n_residual)),
                        np.array([self.gamma]))  # fmt: skip

    def attrs(self) -> dict:
        return {"law": self.kind, "gamma": self.gamma}


# --------------------------------------------------------------------- constructors
def _real(value, what: str, *, positive: bool = False, nonneg: bool = False) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise LawError(f"{what} must be a real number, got {value!r}") from None
    if not math.isfinite(out):
        raise LawError(f"{what} must be finite, got {value!r}")
    if positive and out <= 0:
        raise LawError(f"{what} must be positive, got {value!r}")
    if nonneg and out < 0:
        raise LawError(f"{what} must be non-negative, got {value!r}")
    return out


def baumgarte(omega: float | None = None, xi: float = 1.0, k: float | None = None) -> Law:
    """Baumgarte's law: ``A10 = −ω² I``, ``A11 = −2ξω I``, ``A22 = −k I`` (the paper's ref. [7]).

    Parameters
    ----------
    omega : float
        Natural frequency ω > 0 of the holonomic residual (needed when m > 0).
    xi : float, default 1.0
        Damping ratio ξ ≥ 0 (1 is critical damping).
    k : float
        Decay rate of the nonholonomic residual (needed when k > 0).

    Examples
    --------
    >>> law = baumgarte(omega=10.0, xi=1.0)
    """
    return Baumgarte(
        None if omega is None else _real(omega, "baumgarte: omega", positive=True),
        _real(xi, "baumgarte: xi", nonneg=True),
        None if k is None else _real(k, "baumgarte: k", nonneg=True),
    )


def matrix(A) -> Law:
    """A constant law given by its r × (m + r) matrix ``A`` (or the full ``Ã``)."""
    arr = np.array(A, dtype=np.float64)
    if arr.ndim != 2:
        raise LawError(f"matrix: A must be a 2-d array, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise LawError("matrix: A has non-finite entries")
    arr.setflags(write=False)
    return MatrixLaw(arr)


def theorem5(k: float, L=None) -> Law:
    """Theorem 5's law ``ḣ = −k W(x) L h``, ``W = h_v h_vᵀ`` (nonholonomic only, m = 0).

    Parameters
    ----------
    k : float
        Gain ``k > 0`` (the theorem's ``k₀`` when constant).
    L : array (k, k), optional
        Constant symmetric positive definite weight (default identity).
    """
    gain = _real(k, "theorem5: k", positive=True)
    if L is not None:
        L = np.array(L, dtype=np.float64)
        if L.ndim != 2 or L.shape[0] != L.shape[1]:
            raise LawError(f"theorem5: L must be a square matrix, got shape {L.shape}")
        L.setflags(write=False)
    return Theorem5(gain, L)


def none() -> Law:
    """No stabilization, ``A = 0``: ``f̈ = 0``, ``ḣ = 0`` (the residual drifts)."""
    return NoStabilization()


def acpr(gamma: float) -> Law:
    """The stabilization of Ascher, Chin, Petzold and Reich with gain ``γ_s > 0``.

    ``ẋ = ẋ₁(x) − γ_s D (G D)⁻¹ g(x)`` on the index-1 equations (``A = 0``); see
    :class:`ACPR`.  Needs ``multiplier="ldl"``.

    Examples
    --------
    >>> law = acpr(50.0)
    """
    return ACPR(_real(gamma, "acpr: gamma", positive=True))


def user(fn: Dispatcher) -> Law:
    """A state-dependent law ``A(t, x, p, out)``; ``out`` has shape (r, m + r)."""
    if not is_njit(fn):
        raise LawError(
            "user law: A(t, x, p, out) must be an @njit function (a numba dispatcher), got "
            f"{'a plain Python function' if callable(fn) else type(fn).__name__}"
        )
    return UserLaw(fn)


def as_law(law) -> Law:
    """Accept a :class:`Law` or a bare ``@njit`` function (taken as a user law)."""
    if isinstance(law, Law):
        return law
    if isinstance(law, Dispatcher) or callable(law):
        return user(law)
    raise LawError(
        f"law must be a stabdae law (baumgarte, matrix, theorem5, none, acpr, user) or an @njit "
        f"function A(t, x, p, out); got {type(law).__name__}"
    )


def _scalar_blocks(A: np.ndarray, m: int, k: int) -> np.ndarray | None:
    """``[[a_f, a_ḟ, a_h]]`` when ``A = [[a_f I, a_ḟ I, 0], [0, 0, a_h I]]``, else None."""
    a = np.zeros(3)
    expected = np.zeros_like(A)
    if m:
        a[0], a[1] = A[0, 0], A[0, m]
        expected[:m, :m] = a[0] * np.eye(m)
        expected[:m, m:2 * m] = a[1] * np.eye(m)
    if k:
        a[2] = A[m, 2 * m]
        expected[m:, 2 * m:] = a[2] * np.eye(k)
    return a.reshape(1, 3) if np.array_equal(A, expected) else None


def bind_law(law, model: Model) -> BoundLaw:
    try:
        return as_law(law).bind(model)
    except LawError:
        raise
    except ModelError as exc:
        raise LawError(str(exc)) from exc
