"""Explicit Runge–Kutta schemes of the paper's §5, as validated Butcher tableaus.

* Euler (5.1): ``x_{k+1} = x_k + τ v(x_k, t_k)``.
* The two-stage family (5.4)–(5.7) with parameters ``a`` (the paper's α) and ``σ``::

      x̄       = x_k + a τ v(x_k, t_k)
      x_{k+1} = x_k + τ [(1 − σ) v(x_k, t_k) + σ v(x̄, t_k + a τ)]

  second order iff ``2aσ = 1`` (midpoint: σ = 1, a = ½; Heun: σ = ½, a = 1).  (5.5) as
  printed drops a τ on the second term; (5.9) has it, and so does this code.
* Classical fourth-order Runge–Kutta, for reference solutions.

Each scheme is a tableau ``(A, b, c)`` whose invariants (``Σb = 1``, ``A.sum(1) = c``,
strictly lower-triangular ``A``, order conditions up to the declared order) are asserted
once, when it is defined.  The compiled stepper reads the tableau as runtime arrays, so a
new scheme never recompiles a kernel.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

__all__ = ["Scheme", "euler", "two_stage", "midpoint", "heun", "rk4", "as_scheme"]


class SchemeError(ValueError):
    """A Butcher tableau that breaks its invariants, or an unknown scheme name."""


@dataclass(frozen=True, eq=False)
class Scheme:
    """An explicit Runge–Kutta scheme.

    Attributes
    ----------
    name : str
    A : float64[s, s]
        Strictly lower-triangular coefficients.
    b : float64[s]
        Weights.
    c : float64[s]
        Nodes, ``c = A.sum(1)``.
    order : int
        Classical order, verified against the order conditions at construction.
    params : dict
        The parameters that define it (``a``, ``sigma`` for the two-stage family).
    """

    name: str
    A: np.ndarray
    b: np.ndarray
    c: np.ndarray
    order: int
    params: dict

    def __post_init__(self):
        A, b, c = (np.array(x, dtype=np.float64) for x in (self.A, self.b, self.c))
        s = b.shape[0]
        if A.shape != (s, s) or c.shape != (s,):
            raise SchemeError(
                f"scheme {self.name!r}: tableau shapes must be A (s, s), b (s,), c (s,); got "
                f"A {A.shape}, b {b.shape}, c {c.shape}"
            )
        if np.any(np.triu(A) != 0):
            raise SchemeError(f"scheme {self.name!r}: A must be strictly lower triangular")
        if not math.isclose(b.sum(), 1.0, abs_tol=1e-14):
            raise SchemeError(f"scheme {self.name!r}: weights must sum to 1, got {b.sum()}")
        if not np.allclose(A.sum(axis=1), c, atol=1e-14):
            raise SchemeError(f"scheme {self.name!r}: rows of A must sum to c")
        got = _tableau_order(A, b, c)
        if got != self.order:
            raise SchemeError(
                f"scheme {self.name!r}: declared order {self.order} but the order conditions "
                f"hold up to order {got}"
            )
        for arr in (A, b, c):
            arr.setflags(write=False)
        object.__setattr__(self, "A", A)
        object.__setattr__(self, "b", b)
        object.__setattr__(self, "c", c)

    @property
    def stages(self) -> int:
        return self.b.shape[0]

    def stability_polynomial(self) -> np.ndarray:
        """Coefficients ``[1, b·1, b·A1, b·A²1, …]`` of ``R(z) = Σ_j γ_j z^j`` (ascending).

        For an explicit scheme ``R(z) = 1 + z bᵀ(I − zA)⁻¹ 1`` is a polynomial of degree s.
        """
        s = self.stages
        coeffs = [1.0]
        v = np.ones(s)
        for _ in range(s):
            coeffs.append(float(self.b @ v))
            v = self.A @ v
        return np.array(coeffs)

    def attrs(self) -> dict:
        out = {"scheme": self.name, "scheme_order": self.order, **self.params}
        if self.name not in _BY_NAME and self.name != "two_stage":  # a user's tableau
            out.update(scheme_A=self.A.ravel(), scheme_b=self.b, scheme_c=self.c)
        return out

    def __repr__(self) -> str:
        extra = "".join(f", {k}={v}" for k, v in self.params.items())
        return f"Scheme({self.name!r}, order={self.order}{extra})"


def _tableau_order(A, b, c, max_order: int = 5) -> int:
    """Highest order ≤ 5 whose Butcher order conditions hold to 1e-12 (one per rooted
    tree: 1, 1, 2, 4, 9 conditions for orders 1 … 5)."""
    e = np.ones_like(b)
    Ac = A @ c
    conds = {
        1: [b @ e - 1.0],
        2: [b @ c - 1 / 2],
        3: [b @ c**2 - 1 / 3, b @ (A @ c) - 1 / 6],
        4: [
            b @ c**3 - 1 / 4,
            b @ (c * (A @ c)) - 1 / 8,
            b @ (A @ c**2) - 1 / 12,
            b @ (A @ (A @ c)) - 1 / 24,
        ],
        5: [
            b @ c**4 - 1 / 5,
            b @ (c**2 * Ac) - 1 / 10,
            b @ (c * (A @ c**2)) - 1 / 15,
            b @ (c * (A @ Ac)) - 1 / 30,
            b @ (Ac * Ac) - 1 / 20,
            b @ (A @ c**3) - 1 / 20,
            b @ (A @ (c * Ac)) - 1 / 40,
            b @ (A @ (A @ c**2)) - 1 / 60,
            b @ (A @ (A @ Ac)) - 1 / 120,
        ],
    }
    order = 0
    for p in range(1, max_order + 1):
        if all(abs(x) < 1e-12 for x in conds[p]):
            order = p
        else:
            break
    return order


def euler() -> Scheme:
    """Explicit Euler (5.1), order 1."""
    return Scheme("euler", [[0.0]], [1.0], [0.0], 1, {})


def two_stage(a: float, sigma: float, *, name: str | None = None) -> Scheme:
    """The two-stage family (5.4)–(5.7) with parameters ``a`` (paper: α) and ``σ``.

    Second order iff ``2aσ = 1``; otherwise first order and a ``UserWarning`` says so.

    Examples
    --------
    >>> two_stage(0.5, 1.0).order      # the midpoint rule
    2
    """
    try:
        a, sigma = float(a), float(sigma)
    except (TypeError, ValueError):
        raise SchemeError(
            f"two_stage: a and sigma must be real numbers, got {a!r}, {sigma!r}"
        ) from None
    if not (math.isfinite(a) and math.isfinite(sigma)):
        raise SchemeError(f"two_stage: a and sigma must be finite, got a={a}, sigma={sigma}")
    if sigma != 0.0 and a == 0.0:
        raise SchemeError("two_stage: a = 0 with sigma ≠ 0 evaluates the same stage twice")
    order = 2 if math.isclose(2 * a * sigma, 1.0, rel_tol=0, abs_tol=1e-12) else 1
    if order == 1:
        warnings.warn(
            f"two_stage(a={a}, sigma={sigma}): 2·a·σ = {2 * a * sigma:g} ≠ 1, so the scheme is "
            "only first order (see (5.9)–(5.13))",
            UserWarning,
            stacklevel=2,
        )
    return Scheme(
        name or "two_stage",
        [[0.0, 0.0], [a, 0.0]],
        [1.0 - sigma, sigma],
        [0.0, a],
        order,
        {"a": a, "sigma": sigma},
    )


def midpoint() -> Scheme:
    """Two-stage scheme with σ = 1, a = ½ (explicit midpoint rule), order 2."""
    return two_stage(0.5, 1.0, name="midpoint")


def heun() -> Scheme:
    """Two-stage scheme with σ = ½, a = 1 (Heun's method), order 2."""
    return two_stage(1.0, 0.5, name="heun")


def rk3() -> Scheme:
    """Kutta's third-order method (Hairer, Nørsett & Wanner I, II.1, Table 1.1): ``c = (0, ½,
    1)``, ``b = (1/6, 2/3, 1/6)``."""
    return Scheme("rk3", [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [-1.0, 2.0, 0.0]],
                  [1 / 6, 2 / 3, 1 / 6], [0.0, 0.5, 1.0], 3, {})  # fmt: skip


def heun3() -> Scheme:
    """Heun's third-order method (Hairer, Nørsett & Wanner I, II.1, Table 1.1): ``c = (0,
    ⅓, ⅔)``, ``b = (¼, 0, ¾)``."""
    return Scheme("heun3", [[0.0, 0.0, 0.0], [1 / 3, 0.0, 0.0], [0.0, 2 / 3, 0.0]],
                  [0.25, 0.0, 0.75], [0.0, 1 / 3, 2 / 3], 3, {})  # fmt: skip


def rk4() -> Scheme:
    """The classical fourth-order Runge–Kutta scheme."""
    A = [[0, 0, 0, 0], [0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 1, 0]]
    return Scheme("rk4", A, [1 / 6, 1 / 3, 1 / 3, 1 / 6], [0, 0.5, 0.5, 1], 4, {})


#: Dormand–Prince 5(4): nodes, coefficients, the fifth-order weights and the embedded
#: fourth-order weights (Hairer, Nørsett & Wanner, Solving ODEs I, Table II.5.2)
_DP_C = [0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0]
_DP_A = [
    [0, 0, 0, 0, 0, 0, 0],
    [1 / 5, 0, 0, 0, 0, 0, 0],
    [3 / 40, 9 / 40, 0, 0, 0, 0, 0],
    [44 / 45, -56 / 15, 32 / 9, 0, 0, 0, 0],
    [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0, 0, 0],
    [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0, 0],
    [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0],
]
_DP_B = [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84, 0]
_DP_B_HAT = [5179 / 57600, 0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40]


def dopri5() -> Scheme:
    """Dormand–Prince 5(4), order 5 (the first-same-as-last 7-stage tableau).

    As a fixed-step scheme it is an ordinary fifth-order method; with
    :func:`stabdae.integrate_adaptive` its embedded fourth-order weights
    (:func:`dopri5_embedded_weights`) estimate the local error for step-size control.
    """
    return Scheme("dopri5", _DP_A, _DP_B, _DP_C, 5, {})


def dopri5_embedded_weights() -> np.ndarray:
    """The embedded fourth-order weights b̂ of :func:`dopri5` (order checked on import)."""
    return np.array(_DP_B_HAT)


_BY_NAME = {"euler": euler, "midpoint": midpoint, "rk2": midpoint, "heun": heun, "rk3": rk3,
            "kutta3": rk3, "heun3": heun3, "rk4": rk4, "dopri5": dopri5}  # fmt: skip


def from_tableau(spec: dict, name: str = "custom") -> Scheme:
    """A :class:`Scheme` from a mapping with ``A`` (s × s, strictly lower triangular), ``b``,
    ``c`` and its ``order`` (checked against the order conditions), as study files and
    ``stabdae integrate --tableau`` give it."""
    missing = [k for k in ("A", "b", "c", "order") if k not in spec]
    if missing:
        raise SchemeError(f"a tableau needs A, b, c and order; missing {missing}")
    try:
        A = np.array(spec["A"], dtype=float)
        b = np.array(spec["b"], dtype=float)
        c = np.array(spec["c"], dtype=float)
    except (TypeError, ValueError):
        raise SchemeError("a tableau's A, b and c must be arrays of numbers") from None
    return Scheme(str(spec.get("name", name)), A, b, c, int(spec["order"]), {})


def as_scheme(scheme, **params) -> Scheme:
    """A :class:`Scheme` from a scheme or a name (``euler``, ``rk2``/``midpoint``, ``heun``,
    ``two_stage`` with ``a`` and ``sigma``, ``rk4``)."""
    if isinstance(scheme, Scheme):
        return scheme
    if isinstance(scheme, str):
        key = scheme.lower()
        if key in ("two_stage", "rk2") and params:
            return two_stage(params.get("a", 0.5), params.get("sigma", 1.0))
        if key == "two_stage":
            raise SchemeError(
                "scheme 'two_stage' needs its parameters a and sigma (two_stage(a, sigma), or "
                "a and sigma beside the name)"
            )
        if key in _BY_NAME:
            if params:  # a fixed scheme would silently ignore them
                raise SchemeError(
                    f"scheme {scheme!r} has no parameters, got {sorted(params)}: a and sigma "
                    "belong to 'two_stage' (or 'rk2', the two-stage family)"
                )
            return _BY_NAME[key]()
        raise SchemeError(
            f"unknown scheme {scheme!r}; known: {sorted(set(_BY_NAME) | {'two_stage'})}"
        )
    if callable(scheme) and getattr(scheme, "__module__", "") == __name__:
        raise SchemeError(
            f"scheme: got the function stabdae.{scheme.__name__}; call it "
            f"(stabdae.{scheme.__name__}(...)) or pass the name {scheme.__name__!r}"
        )
    raise SchemeError(f"scheme must be a Scheme or a name, got {type(scheme).__name__}")


# the embedded weights must be a fourth-order (and not fifth-order) companion of b
assert _tableau_order(np.array(_DP_A), np.array(_DP_B_HAT), np.array(_DP_C)) == 4
