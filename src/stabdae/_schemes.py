"""Explicit Runge–Kutta schemes of the paper's §5, as validated Butcher tableaus.

* Euler (5.1): ``x_{k+1} = x_k + τ v(x_k, t_k)``.
* The two-stage family (5.4)–(5.7) with parameters ``a`` (the paper's α) and ``σ``::

      x̄       = x_k + a τ v(x_k, t_k)
      x_{k+1} = x_k + τ [(1 − σ) v(x_k, t_k) + σ v(x̄, t_k + a τ)]

  second order iff ``2aσ = 1`` (midpoint: σ = 1, a = ½; Heun: σ = ½, a = 1).  (5.5) as
  printed drops a τ on the second term; (5.9) has it, and so does this code.
* Classical fourth-order Runge–Kutta, for reference solutions; Dormand–Prince 5(4) and
  Hairer's DOP853 (order 8), fixed-step or with their embedded error estimates
  (:class:`EmbeddedPair`) for adaptive steps.

Each scheme is a tableau ``(A, b, c)`` whose invariants (``Σb = 1``, ``A.sum(1) = c``,
strictly lower-triangular ``A``, Butcher's order conditions for every rooted tree up to
the declared order, and not beyond it) are asserted when it is made; an embedded pair
checks its error estimates' orders the same way.  The single-trajectory loops read the
tableau as run-time arrays, so a new scheme compiles nothing there; the ensemble kernel is
compiled once per pattern of zero, unit and other coefficients (per number of stages for
schemes of three stages or more on models of six coordinates or more).
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass

import numpy as np

__all__ = ["Scheme", "EmbeddedPair", "euler", "two_stage", "midpoint", "heun", "rk4", "dopri5",
           "dop853", "embedded_pair", "as_scheme", "tableau_order"]


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
        got = tableau_order(A, b)
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
        if not self._builtin():  # a user's tableau: the name alone does not say what it is
            out.update(scheme_A=self.A.ravel(), scheme_b=self.b, scheme_c=self.c)
        return out

    def _builtin(self) -> bool:
        """Is this the built-in scheme its name says (the same coefficients)?"""
        if self.name == "two_stage" and {"a", "sigma"} <= set(self.params):
            with warnings.catch_warnings():  # its first-order warning was given already
                warnings.simplefilter("ignore", UserWarning)
                ref = two_stage(self.params["a"], self.params["sigma"])
        else:
            ref = _BY_NAME[self.name]() if self.name in _BY_NAME else None
        return ref is not None and all(np.array_equal(getattr(self, k), getattr(ref, k))
                                       for k in ("A", "b", "c"))  # fmt: skip

    def __repr__(self) -> str:
        extra = "".join(f", {k}={v}" for k, v in self.params.items())
        return f"Scheme({self.name!r}, order={self.order}{extra})"


def rooted_trees(max_order: int) -> dict[int, list[tuple]]:
    """The rooted trees with up to ``max_order`` nodes, by order: a tree is the tuple of
    its root's subtrees, each listed once per copy, in a canonical order.  Their numbers
    1, 1, 2, 4, 9, 20, 48, 115, 286 for orders 1 … 9 are those of Butcher's order
    conditions (Hairer, Nørsett & Wanner I, Table II.2.1)."""
    by = {1: [()]}

    def grow(rem, bound, acc, found):  # subtrees in non-increasing (order, index): each once
        if rem == 0:
            found.append(tuple(acc))
            return
        for q in range(min(rem, bound[0]), 0, -1):
            top = len(by[q]) - 1 if q < bound[0] else bound[1]
            for i in range(top, -1, -1):
                grow(rem - q, (q, i), acc + [by[q][i]], found)

    for p in range(2, max_order + 1):
        by[p] = []
        grow(p - 1, (p - 1, len(by[p - 1]) - 1), [], by[p])
    return by


_TREES = rooted_trees(9)


def _order_of(tree) -> int:
    return 1 + sum(_order_of(sub) for sub in tree)


def _density(tree) -> int:
    """γ(t): the tree's order times the densities of the root's subtrees."""
    return _order_of(tree) * math.prod(_density(sub) for sub in tree)


def tableau_order(A, b, max_order: int = 9, tol: float = 1e-12) -> int:
    """The highest order ≤ ``max_order`` (at most 9) whose Butcher order conditions
    ``bᵀ Φ(t) = 1 / γ(t)`` hold to ``tol`` for every rooted tree ``t`` of that order and
    below; ``Φ(t)`` is the product over the root's subtrees of ``A Φ(subtree)`` (one per
    stage), ``Φ`` of the single node is 1 (Hairer, Nørsett & Wanner I, Theorem II.2.13).
    The nodes enter as ``A 1``, which :class:`Scheme` ties to its ``c``."""
    A = np.asarray(A, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if not 1 <= max_order <= 9:
        raise ValueError(f"tableau_order: max_order must lie in 1 … 9, got {max_order}")
    memo: dict = {}

    def phi(tree):
        if tree not in memo:
            v = np.ones_like(b)
            for sub in tree:
                v = v * (A @ phi(sub))
            memo[tree] = v
        return memo[tree]

    order = 0
    for p in range(1, max_order + 1):
        if all(abs(b @ phi(t) - 1.0 / _density(t)) < tol for t in _TREES[p]):
            order = p
        else:
            break
    return order


@functools.cache  # immutable; checking DOP853's 286 order conditions takes milliseconds
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


@functools.cache
def midpoint() -> Scheme:
    """Two-stage scheme with σ = 1, a = ½ (explicit midpoint rule), order 2."""
    return two_stage(0.5, 1.0, name="midpoint")


@functools.cache
def heun() -> Scheme:
    """Two-stage scheme with σ = ½, a = 1 (Heun's method), order 2."""
    return two_stage(1.0, 0.5, name="heun")


@functools.cache
def rk3() -> Scheme:
    """Kutta's third-order method (Hairer, Nørsett & Wanner I, II.1, Table 1.1): ``c = (0, ½,
    1)``, ``b = (1/6, 2/3, 1/6)``."""
    return Scheme("rk3", [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [-1.0, 2.0, 0.0]],
                  [1 / 6, 2 / 3, 1 / 6], [0.0, 0.5, 1.0], 3, {})  # fmt: skip


@functools.cache
def heun3() -> Scheme:
    """Heun's third-order method (Hairer, Nørsett & Wanner I, II.1, Table 1.1): ``c = (0,
    ⅓, ⅔)``, ``b = (¼, 0, ¾)``."""
    return Scheme("heun3", [[0.0, 0.0, 0.0], [1 / 3, 0.0, 0.0], [0.0, 2 / 3, 0.0]],
                  [0.25, 0.0, 0.75], [0.0, 1 / 3, 2 / 3], 3, {})  # fmt: skip


@functools.cache
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


@functools.cache
def dopri5() -> Scheme:
    """Dormand–Prince 5(4), order 5 (the first-same-as-last 7-stage tableau).

    As a fixed-step scheme it is an ordinary fifth-order method; with
    :func:`stabdae.integrate_adaptive` its embedded fourth-order weights estimate the local
    error for step-size control (:func:`embedded_pair`).
    """
    return Scheme("dopri5", _DP_A, _DP_B, _DP_C, 5, {})


#: DOP853 (Hairer, Nørsett & Wanner I, II.10; the coefficients of Hairer's code DOP853, as
#: published with its sources): nodes and the non-zero A[i, j] of the twelve stages, the
#: eighth-order weights (stage 13, at c = 1 with A's row = the weights, is ẋ at the new
#: state and serves only the error estimates), and the two error estimators: weights
#: ``b − b̂`` of an embedded fifth-order (E5) and third-order (E3) formula over the
#: thirteen stages
_D8_C = [0.0, 0.526001519587677318785587544488e-01, 0.789002279381515978178381316732e-01,
         0.118350341907227396726757197510, 0.281649658092772603273242802490,
         0.333333333333333333333333333333, 0.25, 0.307692307692307692307692307692,
         0.651282051282051282051282051282, 0.6, 0.857142857142857142857142857142, 1.0]
_D8_A = {
    (1, 0): 5.26001519587677318785587544488e-2,
    (2, 0): 1.97250569845378994544595329183e-2, (2, 1): 5.91751709536136983633785987549e-2,
    (3, 0): 2.95875854768068491816892993775e-2, (3, 2): 8.87627564304205475450678981324e-2,
    (4, 0): 2.41365134159266685502369798665e-1, (4, 2): -8.84549479328286085344864962717e-1,
    (4, 3): 9.24834003261792003115737966543e-1,
    (5, 0): 3.7037037037037037037037037037e-2, (5, 3): 1.70828608729473871279604482173e-1,
    (5, 4): 1.25467687566822425016691814123e-1,
    (6, 0): 3.7109375e-2, (6, 3): 1.70252211019544039314978060272e-1,
    (6, 4): 6.02165389804559606850219397283e-2, (6, 5): -1.7578125e-2,
    (7, 0): 3.70920001185047927108779319836e-2, (7, 3): 1.70383925712239993810214054705e-1,
    (7, 4): 1.07262030446373284651809199168e-1, (7, 5): -1.53194377486244017527936158236e-2,
    (7, 6): 8.27378916381402288758473766002e-3,
    (8, 0): 6.24110958716075717114429577812e-1, (8, 3): -3.36089262944694129406857109825,
    (8, 4): -8.68219346841726006818189891453e-1, (8, 5): 2.75920996994467083049415600797e1,
    (8, 6): 2.01540675504778934086186788979e1, (8, 7): -4.34898841810699588477366255144e1,
    (9, 0): 4.77662536438264365890433908527e-1, (9, 3): -2.48811461997166764192642586468,
    (9, 4): -5.90290826836842996371446475743e-1, (9, 5): 2.12300514481811942347288949897e1,
    (9, 6): 1.52792336328824235832596922938e1, (9, 7): -3.32882109689848629194453265587e1,
    (9, 8): -2.03312017085086261358222928593e-2,
    (10, 0): -9.3714243008598732571704021658e-1, (10, 3): 5.18637242884406370830023853209,
    (10, 4): 1.09143734899672957818500254654, (10, 5): -8.14978701074692612513997267357,
    (10, 6): -1.85200656599969598641566180701e1, (10, 7): 2.27394870993505042818970056734e1,
    (10, 8): 2.49360555267965238987089396762, (10, 9): -3.0467644718982195003823669022,
    (11, 0): 2.27331014751653820792359768449, (11, 3): -1.05344954667372501984066689879e1,
    (11, 4): -2.00087205822486249909675718444, (11, 5): -1.79589318631187989172765950534e1,
    (11, 6): 2.79488845294199600508499808837e1, (11, 7): -2.85899827713502369474065508674,
    (11, 8): -8.87285693353062954433549289258, (11, 9): 1.23605671757943030647266201528e1,
    (11, 10): 6.43392746015763530355970484046e-1,
}  # fmt: skip
_D8_B = [5.42937341165687622380535766363e-2, 0.0, 0.0, 0.0, 0.0,
         4.45031289275240888144113950566, 1.89151789931450038304281599044,
         -5.8012039600105847814672114227, 3.1116436695781989440891606237e-1,
         -1.52160949662516078556178806805e-1, 2.01365400804030348374776537501e-1,
         4.47106157277725905176885569043e-2]  # fmt: skip
_D8_E5 = [0.1312004499419488073250102996e-1, 0.0, 0.0, 0.0, 0.0,
          -0.1225156446376204440720569753e1, -0.4957589496572501915214079952,
          0.1664377182454986536961530415e1, -0.3503288487499736816886487290,
          0.3341791187130174790297318841, 0.8192320648511571246570742613e-1,
          -0.2235530786388629525884427845e-1, 0.0]  # fmt: skip
#: E3 = b − b̂₃ with the third-order weights b̂₃ non-zero at stages 1, 9 and 12 only
_D8_E3 = [w - d for w, d in zip(_D8_B + [0.0], [0.244094488188976377952755905512] + [0.0] * 7
                                 + [0.733846688281611857341361741547, 0.0, 0.0,
                                    0.220588235294117647058823529412e-1, 0.0])]  # fmt: skip


def _d8_matrix() -> list:
    A = [[0.0] * 12 for _ in range(12)]
    for (i, j), v in _D8_A.items():
        A[i][j] = v
    return A


@functools.cache
def dop853() -> Scheme:
    """Hairer's DOP853, order 8 (Hairer, Nørsett & Wanner I, II.10), as a fixed-step
    scheme: its twelve stages and eighth-order weights.  With adaptive steps
    (``scheme="dop853"`` in :func:`stabdae.integrate_adaptive` and ``ensemble(rtol=…)``)
    a thirteenth evaluation at the new state, reused as the next step's first stage,
    feeds the embedded fifth- and third-order error estimates."""
    return Scheme("dop853", _d8_matrix(), _D8_B, _D8_C, 8, {})


@dataclass(frozen=True, eq=False)
class EmbeddedPair:
    """A scheme with embedded error estimates, for adaptive steps.

    Attributes
    ----------
    scheme : Scheme
        The scheme that advances the state (s stages).
    error : float64[2, s_e]
        Error weights ``b − b̂`` of one or two embedded formulas over ``s_e`` stages:
        ``s_e = s`` when the last stage is already ẋ at the new state (first same as last,
        Dormand–Prince 5(4)), ``s_e = s + 1`` when that evaluation is added for the
        estimate (DOP853); it is the next step's first stage either way.  The second row
        is zero for a single estimate.
    embedded_orders : tuple of int
        Orders of the embedded formulas, checked against the order conditions.
    error_order : int
        ``q`` in the step factor ``0.9 err^{−1/(q+1)}`` and the first-step choice.
    combined : bool
        The error norm of DOP853 (Hairer's code):
        ``err = ‖e₅‖² / √(‖e₅‖² + 0.01 ‖e₃‖²)`` with RMS norms of the two estimates;
        otherwise the RMS norm of the single estimate.
    """

    scheme: Scheme
    error: np.ndarray
    embedded_orders: tuple
    error_order: int
    combined: bool

    def __post_init__(self):
        sc = self.scheme
        s = sc.stages
        E = np.atleast_2d(np.array(self.error, dtype=np.float64))
        if E.shape[0] == 1:
            E = np.vstack([E, np.zeros_like(E)])
        s_e = E.shape[1]
        if E.shape[0] != 2 or s_e not in (s, s + 1):
            raise SchemeError(f"pair {sc.name!r}: error weights must be (2, s) or (2, s + 1) "
                              f"for s = {s} stages, got {E.shape}")  # fmt: skip
        # the tableau over s_e stages, the last one ẋ at the new state
        A = np.zeros((s_e, s_e))
        A[:s, :s] = sc.A
        b = np.append(sc.b, 0.0) if s_e > s else sc.b
        if s_e > s:
            A[s, :s] = sc.b
        elif not (np.array_equal(A[s - 1], sc.b) and sc.c[s - 1] == 1.0):
            raise SchemeError(f"pair {sc.name!r}: error weights over the s stages need the "
                              "last stage to be ẋ at the new state (A's last row = b, c = 1)")
        for row, want in zip(E, self.embedded_orders):
            got = tableau_order(A, b - row)
            if got != want:
                raise SchemeError(f"pair {sc.name!r}: an embedded formula of declared order "
                                  f"{want} satisfies the order conditions up to {got}")
        E.setflags(write=False)
        object.__setattr__(self, "error", E)

    @property
    def name(self) -> str:
        return self.scheme.name


@functools.cache
def _pair(name: str) -> EmbeddedPair:
    if name == "dopri5":
        return EmbeddedPair(dopri5(), np.array(_DP_B) - np.array(_DP_B_HAT), (4,), 4, False)
    return EmbeddedPair(dop853(), [_D8_E5, _D8_E3], (5, 3), 7, True)


def embedded_pair(scheme, who: str = "embedded_pair") -> EmbeddedPair:
    """The embedded pair of ``"dopri5"`` or ``"dop853"`` (a name or the :class:`Scheme`)."""
    name = scheme.name if isinstance(scheme, Scheme) else str(scheme).lower()
    if name in ("dopri5", "dop853"):
        return _pair(name)
    raise SchemeError(f"{who}: adaptive steps need an embedded pair, 'dopri5' (Dormand–Prince "
                      f"5(4)) or 'dop853' (Hairer's 8(5,3)); got {name!r}")


_BY_NAME = {"euler": euler, "midpoint": midpoint, "rk2": midpoint, "heun": heun, "rk3": rk3,
            "kutta3": rk3, "heun3": heun3, "rk4": rk4, "dopri5": dopri5,
            "dop853": dop853}  # fmt: skip


def from_tableau(spec: dict, name: str = "custom") -> Scheme:
    """A :class:`Scheme` from a mapping with ``A`` (s × s, strictly lower triangular), ``b``,
    ``c`` and its ``order`` (checked against the order conditions), as study files and
    ``stabdae integrate --tableau`` give it."""
    missing = [k for k in ("A", "b", "c", "order") if k not in spec]
    if missing:
        raise SchemeError(f"a tableau needs A, b, c and order; missing {missing}")
    for key in spec:
        if key not in ("A", "b", "c", "order", "name"):
            hint = " (they belong to the two-stage family, 'two_stage')" \
                if key in ("a", "sigma") else ""  # fmt: skip
            raise SchemeError(f"a tableau is its A, b and c: {key!r} would change "
                              f"nothing{hint}")  # fmt: skip
    label = str(spec.get("name", name))
    if label.lower() in _BY_NAME or label.lower() == "two_stage":
        raise SchemeError(f"{label.lower()!r} is the name of a built-in scheme; give your "
                          "tableau a name of its own")  # fmt: skip
    try:
        A = np.array(spec["A"], dtype=float)
        b = np.array(spec["b"], dtype=float)
        c = np.array(spec["c"], dtype=float)
    except (TypeError, ValueError):
        raise SchemeError("a tableau's A, b and c must be arrays of numbers") from None
    order = spec["order"]
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 1:
        raise SchemeError(f"{label}: tableau order must be a positive integer (the order of "
                          f"accuracy the tableau claims), got {order!r}")  # fmt: skip
    return Scheme(label, A, b, c, int(order), {})


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

