"""The paper's Theorems 3–7 as computations on matrices.

Continuous time

* :func:`continuous` — Theorem 3: eigenvalues of ``Ã``; decay rate ``−max Re λ(Ã)``.
* :func:`lyapunov` — Theorem 4: ``2V = αᵀLα``; Sylvester's criterion on the *symmetric part*
  ``Q = −(LÃ + ÃᵀL)/2`` (the paper writes ``−LÃ``; its definiteness is what ``V̇ < 0``
  needs, since ``αᵀ(LÃ)α`` only sees the symmetric part); with no ``L`` given,
  ``L`` solves the continuous Lyapunov equation ``ÃᵀL + LÃ = −I``.
* :func:`theorem5` — Theorem 5 (nonholonomic, ``m = 0``): ``λ_min(W)`` with ``W = h_v h_vᵀ``
  over given states, ``l₁``, ``l_m``, the proven ``β = k₀ λ_min(W) l₁²/l_m`` beside the
  paper's printed ``β = k₀ w₀ l₁²/l_m`` (``w₀ = √λ_min(W)``; the two differ when
  ``w₀ ≠ 1``: ``L = I``, ``W = wI`` decays exactly as ``e^{−kwt}``), ``γ``.

Discrete time

* :func:`step_matrix` — the residual recursion's matrix: ``E + τA`` (Euler, (5.1)),
  ``E + τA + τ²/2 (A² + Ȧ)`` (two-stage with ``2aσ = 1``, (5.13)), and for any other
  explicit scheme its stability polynomial ``R(τÃ)``.
* :func:`discrete` — Theorems 6 and 7 for a constant law: ``R``, its spectral radius,
  max-norm (the paper's norm), 2-norm and its norm in the weight ``P = X^{1/2}`` of the
  discrete Lyapunov equation ``RᵀXR − X = −I``; the largest τ for which each condition
  holds (:func:`tau_limit`, by bisection).
* :func:`along_path` — the same along a given trajectory, for state-dependent laws (``Ȧ``
  by central differences along the path), and the floor ``ε`` that condition 4 implies
  from the one-step remainder measured along the path.

A leaf: this module computes on matrices and on trajectories it is given; it samples,
integrates and formats nothing (the study layer, :mod:`stabdae.study.theory`, does).

Why the weighted norm: with ``m > 0`` the first block row of ``E + τÃ`` is
``[I, τI, 0]``, so its max-norm (and 2-norm) is ``≥ 1 + τ`` for every ``τ > 0``; the
iteration contracts in *some* norm iff ``ρ(R) < 1``, and ``P`` above is one such norm:
``‖R‖_P² = 1 − 1/λ_max(X)``.
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import xarray as xr
from numba import njit

from ._laws import Law, Theorem5, as_law
from ._model import Model
from ._schema import cf_dataset, component_coords, provenance, schema_variable, variable
from ._schemes import as_scheme

__all__ = [
    "continuous",
    "lyapunov",
    "step_matrix",
    "spectral_radius",
    "spectral_radius_of",
    "transient_peak",
    "forced_gain",
    "power_norms",
    "eigenvalues",
    "weighted_norm",
    "discrete",
    "tau_limit",
    "recommend_gain",
    "condition4",
    "theorem5",
    "along_path",
    "predictions",
]


# --------------------------------------------------------------------- Theorem 3
def continuous(A_tilde) -> dict:
    """Theorem 3: eigenvalues of ``Ã``, the decay rate ``β = −max Re λ`` and whether every
    eigenvalue lies in the open left half-plane."""
    A_tilde = _square(A_tilde, "continuous")
    lam = np.linalg.eigvals(A_tilde)
    beta = float(-lam.real.max())
    return {"eigenvalues": lam, "beta": beta, "stable": bool(beta > 0)}


# --------------------------------------------------------------------- Theorem 4
def lyapunov(A_tilde, L=None) -> dict:
    """Theorem 4: the Lyapunov function ``2V = αᵀLα`` for ``α̇ = Ãα``.

    Returns ``L`` (given, or solving ``ÃᵀL + LÃ = −I``), the symmetric part
    ``Q = −(LÃ + ÃᵀL)/2`` of ``−LÃ``, its leading principal minors, whether Sylvester's
    criterion holds for ``L`` and ``Q`` (so ``V > 0``, ``V̇ < 0``), and the rate it proves:
    ``‖α(t)‖₂ ≤ √(l_m/l₁) ‖α₀‖₂ e^{−βt}`` with ``β = λ_min(Q)/l_m``.
    """
    A_tilde = _square(A_tilde, "lyapunov")
    n = A_tilde.shape[0]
    if L is None:
        try:
            L = sla.solve_continuous_lyapunov(A_tilde.T, -np.eye(n))
        except (np.linalg.LinAlgError, ValueError):
            L = np.full((n, n), np.nan)
        L = 0.5 * (L + L.T)
    else:
        L = np.array(L, dtype=float)
        if L.shape != (n, n):
            raise ValueError(f"lyapunov: L must have shape {(n, n)} like Ã, got {L.shape}")
    Q = -0.5 * (L @ A_tilde + A_tilde.T @ L)
    finite = bool(np.all(np.isfinite(L)))
    minors_L = _leading_minors(L) if finite else np.full(n, np.nan)
    minors_Q = _leading_minors(Q) if finite else np.full(n, np.nan)
    holds = finite and bool(np.all(minors_L > 0) and np.all(minors_Q > 0))
    if holds:
        lL = np.linalg.eigvalsh(L)
        beta = float(np.linalg.eigvalsh(Q).min() / lL.max())
        amp = float(math.sqrt(lL.max() / lL.min()))
    else:
        beta, amp = math.nan, math.nan
    return {"L": L, "Q": Q, "minors_L": minors_L, "minors_Q": minors_Q, "holds": holds,
            "beta": beta, "gamma_factor": amp}  # fmt: skip


def _leading_minors(M) -> np.ndarray:
    return np.array([np.linalg.det(M[: i + 1, : i + 1]) for i in range(M.shape[0])])


# --------------------------------------------------------------------- Theorems 6, 7
def step_matrix(A_tilde, scheme, tau: float, A_dot=None) -> np.ndarray:
    """The matrix of the residual recursion ``g_{k+1} ≈ R g_k`` for one step ``tau``.

    Euler: ``E + τA``.  Two-stage schemes with ``2aσ = 1``: ``E + τA + τ²/2 (A² + Ȧ)``
    ((5.13); ``A_dot`` defaults to 0, a constant law).  Any other explicit scheme: its
    stability polynomial ``R(τÃ)`` (``Ȧ`` not included).
    """
    scheme = as_scheme(scheme)
    A = _square(A_tilde, "step_matrix")
    n = A.shape[0]
    E = np.eye(n)
    coeffs = scheme.stability_polynomial()
    if scheme.stages == 1:
        return E + tau * A
    if scheme.stages == 2 and math.isclose(coeffs[2], 0.5, abs_tol=1e-14):
        Ad = np.zeros_like(A) if A_dot is None else np.asarray(A_dot, dtype=float)
        return E + tau * A + 0.5 * tau * tau * (A @ A + Ad)
    out = np.zeros_like(A)
    power = E
    for c in coeffs:
        out = out + c * power
        power = power @ (tau * A)
    return out


def _expm(A) -> np.ndarray:
    """``e^A`` of a small matrix by scaling and squaring of its Taylor series (the scaled
    matrix has ∞-norm ≤ 1, where 24 terms leave under 1e-25).  Matrix products only:
    LAPACK's solves, which ``scipy.linalg.expm`` uses, wake the BLAS library's threads,
    and those spin for a while afterwards on the cores an ensemble is about to use."""
    A = np.asarray(A, dtype=float)
    norm = float(np.abs(A).sum(axis=1).max()) if A.size else 0.0
    if not math.isfinite(norm):
        raise ValueError("_expm: the matrix has a non-finite entry")
    squarings = max(0, math.ceil(math.log2(norm))) if norm > 1.0 else 0
    X = A / 2.0**squarings
    out = np.eye(A.shape[0])
    term = np.eye(A.shape[0])
    for k in range(1, 25):
        term = term @ X / k
        out = out + term
    for _ in range(squarings):
        out = out @ out
    return out


def spectral_radius(R) -> float:
    """``max |λ(R)|`` of a matrix (for ``R(τÃ)`` of a constant law
    :func:`spectral_radius_of` is exact where this loses digits to a defective
    eigenvalue)."""
    return float(np.max(np.abs(np.linalg.eigvals(R))))


#: computed eigenvalues closer than this (relative to the largest) are one multiple
#: eigenvalue: a defective one comes out spread by about √ε, far above roundoff
_CLUSTER_RTOL = 1e-6


def transient_peak(R, max_steps: int = 100_000) -> float:
    """``sup_k ‖R^k‖∞``: how far the linear residual recursion ``g_{k+1} = R g_k`` can
    carry a perturbation above its start (1 for a contraction in the max-norm; near
    ``ω/e``-fold growth of ``‖e^{Ãt}‖`` for critically damped Baumgarte at small steps);
    ``inf`` when the powers grow past ``1e12`` (``ρ(R) ≥ 1``).  The powers ``k ≤ max_steps``
    are taken until they fall below a millionth of the peak."""
    return power_norms(R, max_steps)[0]


def forced_gain(R, max_steps: int = 100_000) -> float:
    """``Σ_k ‖R^k‖∞`` over ``k < max_steps``: how far errors of size 1 put in at every step
    (roundoff, a local error) can accumulate in the residual recursion
    ``g_{k+1} = R g_k + e_k``; ``inf`` when the powers grow past ``1e12`` (``ρ(R) ≥ 1``).
    The sum stops when a term falls below a millionth of it."""
    return power_norms(R, max_steps)[1]


def power_norms(R, max_steps: int = 100_000) -> tuple[float, float]:
    """``(transient_peak(R), forced_gain(R))`` from one walk over the powers of ``R`` (each
    with its own stopping rule): near ``ρ = 1`` the walk is thousands of matrix products."""
    R = np.ascontiguousarray(R, dtype=float)
    if R.ndim != 2 or R.shape[0] != R.shape[1]:
        raise ValueError(f"power_norms: R must be a square matrix, got shape {R.shape}")
    # (an ensemble asks twice for the same matrix: its threshold and its gain)
    return _power_norms_of(R.shape[0], R.tobytes(), int(max_steps))


@functools.lru_cache(maxsize=64)
def _power_norms_of(n: int, data: bytes, max_steps: int) -> tuple[float, float]:
    peak, total = _power_walk(np.frombuffer(data).reshape(n, n).copy(), max_steps)
    return float(peak), float(total)


def fifth_bounds(R, nsteps: int) -> np.ndarray:
    """``sup ‖R^k‖∞`` over each fifth of the steps ``k = 0 … nsteps`` (step ``k`` in fifth
    ``min(4, ⌊5k / nsteps⌋)``, as an ensemble's measurement counts them): the law's own
    transient bound, ``‖R^k α⁰‖∞ ≤ ‖R^k‖∞ ‖α⁰‖∞``, over the part of the run a verdict
    reads.  A fifth past the powers' underflow to zero is 0; past their overflow, inf."""
    R = np.ascontiguousarray(R, dtype=float)
    if R.ndim != 2 or R.shape[0] != R.shape[1]:
        raise ValueError(f"fifth_bounds: R must be a square matrix, got shape {R.shape}")
    return _fifth_walk(R, max(int(nsteps), 1))


@njit(cache=True)
def _next_power(R, P, Q):
    """``P ← R P`` (``Q`` scratch); returns ``‖P‖∞`` of the new power."""
    n = R.shape[0]
    for r in range(n):
        for c in range(n):
            s = 0.0
            for q in range(n):
                s += R[r, q] * P[q, c]
            Q[r, c] = s
    nrm = 0.0
    for r in range(n):
        row = 0.0
        for c in range(n):
            P[r, c] = Q[r, c]
            row += abs(Q[r, c])
        nrm = max(nrm, row)
    return nrm


@njit(cache=True)
def _fifth_walk(R, nsteps):
    n = R.shape[0]
    P = np.eye(n)
    Q = np.empty((n, n))
    sup = np.zeros(5)
    sup[0] = 1.0  # ‖R⁰‖ = 1
    for k in range(1, nsteps + 1):
        nrm = _next_power(R, P, Q)
        w = min(4, (5 * k) // nsteps)
        if not nrm <= 1e300:  # overflow (or NaN): unbounded from here on
            for v in range(w, 5):
                sup[v] = math.inf
            break
        sup[w] = max(sup[w], nrm)
        if nrm == 0.0:  # nilpotent, or underflowed: every later power is zero
            break
    return sup


@njit(cache=True)
def _power_walk(R, max_steps):
    # compiled: a walk of thousands of small products cost milliseconds in numpy
    n = R.shape[0]
    P = np.eye(n)
    Q = np.empty((n, n))
    peak, total = 1.0, 1.0  # ‖R⁰‖ = 1 starts the sum; the peak runs over k ≥ 1
    peak_open, total_open = max_steps >= 1, max_steps > 1
    k = 0
    while peak_open or total_open:
        k += 1
        nrm = _next_power(R, P, Q)
        if not nrm <= 1e12:
            peak = math.inf if peak_open else peak
            total = math.inf if total_open else total
            break
        if peak_open:
            peak = max(peak, nrm)
            peak_open = not nrm < 1e-6 * peak and k < max_steps
        if total_open:
            total += nrm
            total_open = not nrm < 1e-6 * total and k + 1 < max_steps
    return peak, total


def eigenvalues(A_tilde) -> np.ndarray:
    """Eigenvalues of ``Ã`` with every cluster of a multiple eigenvalue replaced by its
    mean.  A defective eigenvalue (critically damped Baumgarte: a Jordan block) is computed
    with errors of order √ε; the mean of its cluster, the trace of its invariant subspace
    over the multiplicity, is accurate to roundoff."""
    A = _square(A_tilde, "eigenvalues")
    lam = np.linalg.eigvals(A).astype(complex)
    if lam.size == 0:
        return lam
    tol = _CLUSTER_RTOL * max(float(np.abs(lam).max()), np.finfo(float).tiny)
    out = lam.copy()
    done = np.zeros(lam.size, dtype=bool)
    for i in range(lam.size):
        if done[i]:
            continue
        members = (~done) & (np.abs(lam - lam[i]) <= tol)
        out[members] = lam[members].mean()
        done |= members
    return out


def spectral_radius_of(A_tilde, scheme, tau: float) -> float:
    """``ρ(R(τÃ))`` of a constant law from the eigenvalues of ``Ã``: ``max |R(τλ)|`` with
    ``R`` the scheme's stability polynomial (the spectral mapping theorem)."""
    coeffs = as_scheme(scheme).stability_polynomial()
    z = tau * eigenvalues(A_tilde)
    return float(np.abs(np.polynomial.polynomial.polyval(z, coeffs)).max())


def _spectral_limit(A, scheme, tau_max: float) -> float:
    """The largest τ with ``|R(τλ)| < 1`` on ``(0, τ)`` for every eigenvalue λ of ``Ã``:
    the smallest positive root of the real polynomial ``|R(τλ)|² − 1`` in τ (0 when it is
    positive just after τ = 0, ``inf`` when it has no root up to ``tau_max``)."""
    c = as_scheme(scheme).stability_polynomial()
    best = math.inf
    for lam in eigenvalues(A):
        a = c * lam ** np.arange(c.size)  # R(τλ) = Σ a_k τ^k
        b = np.convolve(a, np.conj(a)).real  # |R(τλ)|² = Σ b_n τ^n
        size = np.convolve(np.abs(a), np.abs(a))  # the terms' magnitude, for roundoff
        b[0] -= 1.0  # (= 0: R(0) = 1)
        b[np.abs(b) <= 64 * np.finfo(float).eps * size] = 0.0
        nz = np.flatnonzero(b)
        if nz.size == 0:  # |R| ≡ 1 (λ = 0): never below 1
            return 0.0
        low = nz[0]
        if b[low] > 0:  # above 1 right after τ = 0
            return 0.0
        roots = np.roots(b[low:][::-1])  # b_low + b_{low+1} τ + … with τ^low divided out
        real = roots[(np.abs(roots.imag) <= 1e-9 * np.abs(roots)) & (roots.real > 0)].real
        if real.size:
            best = min(best, float(real.min()))
    return math.inf if best > tau_max else best


def lyapunov_weight(R):
    """``P = X^{1/2}`` with ``RᵀXR − X = −I``, or ``None`` when no SPD ``X`` exists
    (``ρ(R) ≥ 1``)."""
    if not np.all(np.isfinite(R)) or spectral_radius(R) >= 1.0:
        return None
    return _weight(R, np.eye(R.shape[0]))


def weighted_norm(R, P=None) -> float:
    """``‖R‖_P = ‖P R P⁻¹‖₂``; ``P`` from :func:`lyapunov_weight` of ``R`` itself when not
    given (then it is below 1 exactly when ``ρ(R) < 1``; ``inf`` when no weight exists)."""
    if P is None:
        P = lyapunov_weight(R)
        if P is None:
            return math.inf
    return float(np.linalg.norm(P @ R @ np.linalg.inv(P), 2))


#: condition name -> function R -> value that must be below 1
CONDITIONS = {
    "spectral": spectral_radius,
    "max_norm": lambda R: float(np.abs(R).sum(axis=1).max()),
    "two_norm": lambda R: float(np.linalg.norm(R, 2)),
    "weighted_norm": weighted_norm,
}


def tau_limit(A_tilde, scheme, condition: str = "spectral", *, tau_max: float | None = None,
              rtol: float = 1e-10) -> float:  # fmt: skip
    """The largest τ such that the condition (value of :data:`CONDITIONS` below 1) holds
    for every step size in ``(0, τ]``, by bracketing and bisection.

    0 when it fails for arbitrarily small τ (e.g. the max-norm condition when ``m > 0``);
    ``inf`` when it holds up to ``tau_max`` (default ``1e6 / max|λ(Ã)|``).
    """
    if condition not in CONDITIONS:
        raise ValueError(f"tau_limit: condition must be one of {tuple(CONDITIONS)}, got "
                         f"{condition!r}")  # fmt: skip
    fn = CONDITIONS[condition]
    scheme = as_scheme(scheme)
    A = _square(A_tilde, "tau_limit")
    lam = np.abs(np.linalg.eigvals(A)).max()
    scale = 1.0 / lam if lam > 0 else 1.0
    tau_max = 1e6 * scale if tau_max is None else tau_max
    if condition in ("spectral", "weighted_norm"):
        # ‖R‖_P < 1 in R's own discrete-Lyapunov weight exactly when ρ(R) < 1; both limits
        # are a root of |R(τλ)|² = 1, found as a polynomial root rather than by bisection
        # (which a nearly undamped law defeats: |R(iy)| = 1 − O(y⁶) rounds to 1)
        limit = _spectral_limit(A, scheme, tau_max)
        # within rtol on the side where the condition holds (|R| = 1 at the root itself);
        # there |R| may round to 1 when the limit is tiny (ξ → 0 for Euler: 2ξ/ω)
        return limit * (1.0 - rtol) if math.isfinite(limit) else limit

    def holds(tau):
        return fn(step_matrix(A, scheme, tau)) < 1.0

    # scan up from a tiny step by factors of 2 for the first failure
    tau = 1e-8 * scale
    if not holds(tau):
        return 0.0
    good = tau
    while True:
        tau = 2.0 * good
        if tau > tau_max:
            return math.inf
        if not holds(tau):
            bad = tau
            break
        good = tau
    while bad - good > rtol * good:
        mid = 0.5 * (good + bad)
        if holds(mid):
            good = mid
        else:
            bad = mid
    return good


#: the weights :func:`condition4` tries: the discrete-Lyapunov weights of ``R/θ`` for
#: ``θ = ρ + (1 − ρ) s`` over this many ``s`` geometric in ``[1e-4, 1]``, each with the
#: identity and with ``R``'s balancing scaling on the right-hand side
WEIGHT_THETAS = 48


def floor_weights(R):
    """Candidate weights ``P`` (``q = ‖R‖_P < 1`` in each) for the floor of Theorems 6/7:
    ``P = X^{1/2}`` with ``(R/θ)ᵀ X (R/θ) − X = −D²`` for ``θ`` between ``ρ(R)`` and 1
    (:data:`WEIGHT_THETAS` values) and ``D`` the identity or the diagonal scaling that
    balances ``R`` (:func:`scipy.linalg.matrix_balance`: components of different sizes,
    as ``f`` and ``ḟ`` under a stiff gain, weighed alike).  ``θ = 1`` with ``D = I`` is the
    weight of ``RᵀXR − X = −I``.  Smaller ``θ`` brings ``q`` down towards ``ρ``
    (``q ≤ θ``), at the price of a worse-conditioned ``P``; which is best depends on the
    remainders."""
    n = R.shape[0]
    rho = spectral_radius(R)
    if not np.all(np.isfinite(R)) or rho >= 1.0:
        return []
    _, (T, _) = sla.matrix_balance(R, permute=False, separate=True)
    T = np.asarray(T, dtype=float)
    scalings = [np.ones(n)]
    if np.all(np.isfinite(T)) and np.all(T > 0) and not np.allclose(T, 1.0):
        scalings.append(1.0 / T)
    out = []
    for theta in rho + (1.0 - rho) * np.geomspace(1e-4, 1.0, WEIGHT_THETAS):
        for d in scalings:
            P = _weight(R / theta, np.diag(d * d))
            if P is not None:
                out.append(P)
    return out


def _weight(R, Q):
    """``X^{1/2}`` with ``RᵀXR − X = −Q`` (``Q`` SPD), or None."""
    try:
        with warnings.catch_warnings():  # ρ → 1 makes X large and ill-conditioned
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            X = sla.solve_discrete_lyapunov(R.T, Q)
    except (np.linalg.LinAlgError, ValueError):
        return None
    X = 0.5 * (X + X.T)
    w, V = np.linalg.eigh(X)
    if not (np.all(np.isfinite(w)) and w.min() > 0):
        return None
    return (V * np.sqrt(w)) @ V.T


def condition4(R, residuals, weight: str = "best") -> dict:
    """Theorems 6/7 with condition 4 for a constant step matrix ``R`` on a trajectory's
    residuals ``g_k`` (rows, every step): ``q = ‖R‖_P`` in a weight ``P``; the remainders
    ``e_k = g_{k+1} − R g_k`` the steps actually made; the floor
    ``ε = ‖P⁻¹‖₂ max_k ‖P e_k‖₂ / (1 − q)`` and the bound's start ``‖P⁻¹‖₂ ‖P g₀‖₂``, so
    that ``‖g_k‖∞ ≤ max(start, ε)``.  ``ε = inf`` when ``ρ(R) ≥ 1`` (no weight with
    ``q < 1``).

    The theorems hold in every norm in which ``R`` contracts, so the weight is ours to
    choose: ``weight="best"`` (default) takes, of :func:`floor_weights`, the one with the
    smallest ``ε``; ``"lyapunov"`` the weight of ``RᵀXR − X = −I`` alone, which under a
    stiff gain weighs ``ḟ`` like ``f`` and leaves ``q`` near 1 where ``ρ`` is far below
    it (the pendulum at ω = 300, τω = 1.5: ``ρ = 0.63``, ``q = 0.999998``)."""
    R = np.asarray(R, dtype=float)
    g = np.asarray(residuals, dtype=float)
    if g.ndim != 2 or g.shape[1] != R.shape[0]:
        raise ValueError(f"condition4: residuals must be (steps, {R.shape[0]}), got shape "
                         f"{g.shape}")  # fmt: skip
    if weight not in ("best", "lyapunov"):
        raise ValueError(f"condition4: weight must be 'best' or 'lyapunov', got {weight!r}")
    if weight == "lyapunov":
        P = lyapunov_weight(R)
        weights = [] if P is None else [P]
    else:
        weights = floor_weights(R)
    if not weights:
        return {"q": math.inf, "epsilon": math.inf, "start": math.inf,
                "remainder": math.nan, "weight": None}  # fmt: skip
    e = g[1:] - g[:-1] @ R.T
    best = None
    for P in weights:
        q = weighted_norm(R, P)
        if not q < 1.0:
            continue
        Pinv = float(np.linalg.norm(np.linalg.inv(P), 2))
        worst = float(np.linalg.norm(e @ P.T, axis=1).max()) if len(e) else 0.0
        eps = Pinv * worst / (1.0 - q)
        if best is None or eps < best["epsilon"]:
            best = {"q": q, "epsilon": eps, "start": Pinv * float(np.linalg.norm(P @ g[0])),
                    "weight": P}  # fmt: skip
    if best is None:
        return {"q": math.inf, "epsilon": math.inf, "start": math.inf,
                "remainder": math.nan, "weight": None}  # fmt: skip
    best["remainder"] = float(np.abs(e).max()) if len(e) else 0.0
    return best


def recommend_gain(scheme, tau: float) -> dict:
    """The gains that make the residual recursion contract fastest for a scheme and step:
    the Baumgarte ``(ω, ξ)`` of a holonomic block ``f̈ + 2ξωḟ + ω²f = 0`` and the ``k`` of
    a first-order block ``ḣ = −kh`` minimizing ``ρ(R(τÃ))``.

    Deadbeat where the stability polynomial ``R`` allows it (Yoon, Howe & Greenwood,
    J. Mech. Des. 1995): the eigenvalues of ``τÃ`` placed on roots of ``R`` with negative
    real part make ``R(τÃ)`` nilpotent — a complex pair ``z, z̄`` (``ω = |z|/τ``,
    ``ξ = −Re z/|z|``) or two real roots annihilate the block's residual in one step, a
    double real root (a Jordan block, ``ξ = 1``) in two.  Among deadbeat choices the one
    with the fewest steps, then the smallest ``ω`` (the gentlest gain).  A first-order
    block is deadbeat at a negative real root; without one (the midpoint rule, RK4),
    ``k`` minimizes ``|R(−kτ)|``.  Where no root qualifies, ``(ω, ξ)`` minimizes ``ρ``
    numerically.

    Returns ``omega``, ``xi``, ``rho_holonomic``, ``steps_holonomic`` (steps to
    annihilate, 0 when not deadbeat), ``k``, ``rho_first_order``, ``steps_first_order``.
    """
    scheme = as_scheme(scheme)
    tau = float(tau)
    if not (math.isfinite(tau) and tau > 0):
        raise ValueError(f"recommend_gain: tau must be positive and finite, got {tau!r}")
    c = scheme.stability_polynomial()
    R = np.polynomial.Polynomial(c)
    roots = R.roots() if c.size > 1 else np.array([])
    tol = 1e-9 * max(1.0, float(np.abs(roots).max(initial=0.0)))
    left = roots[roots.real < -tol]
    real = np.sort(left[np.abs(left.imag) <= tol].real)[::-1]  # nearest 0 first
    pairs = left[left.imag > tol]
    candidates = []  # (steps, ω τ, ξ)
    for z in pairs:
        candidates.append((1, abs(z), -z.real / abs(z)))
    for i, z1 in enumerate(real):
        for z2 in real[i + 1:]:
            r = math.sqrt(z1 * z2)
            candidates.append((1, r, -(z1 + z2) / (2.0 * r)))
        if abs(R.deriv()(z1)) > tol:  # a simple root: the Jordan block is nilpotent of order 2
            candidates.append((2, -z1, 1.0))
    out = {}
    if candidates:
        steps, wt, xi = min(candidates)
        out.update(omega=float(wt) / tau, xi=float(xi), steps_holonomic=steps)
    else:
        from scipy.optimize import minimize

        def rho(v):
            return _block_rho(c, math.exp(v[0]), v[1])

        best = min((minimize(rho, [math.log(w), x], method="Nelder-Mead",
                             options={"xatol": 1e-10, "fatol": 1e-14})
                    for w in (0.5, 1.0, 2.0) for x in (0.5, 1.0, 1.5)),
                   key=lambda r: r.fun)  # fmt: skip
        out.update(omega=math.exp(best.x[0]) / tau, xi=float(best.x[1]), steps_holonomic=0)
    out["rho_holonomic"] = _block_rho(c, out["omega"] * tau, out["xi"])
    if real.size:
        out.update(k=float(-real[0]) / tau, steps_first_order=1)
    else:
        from scipy.optimize import minimize_scalar

        # |R(−x)| on the real axis; its minimum lies within the real stability interval
        grid = np.linspace(0.0, 8.0, 8001)
        vals = np.abs(R(-grid))
        x0 = grid[int(np.argmin(vals))]
        res = minimize_scalar(lambda x: abs(R(-x)), bounds=(max(0.0, x0 - 1e-3), x0 + 1e-3),
                              method="bounded", options={"xatol": 1e-12})  # fmt: skip
        out.update(k=float(res.x) / tau, steps_first_order=0)
    out["rho_first_order"] = float(abs(R(-out["k"] * tau)))
    return out


def _block_rho(c, wt, xi) -> float:
    """``ρ(R(τÃ))`` of one Baumgarte block with ``ωτ = wt`` and damping ``xi``."""
    lam = np.roots([1.0, 2.0 * xi * wt, wt * wt])
    return float(np.abs(np.polynomial.polynomial.polyval(lam, c)).max())


@dataclass
class Discrete:
    """Theorems 6/7 for one constant law, scheme and τ (see :func:`discrete`)."""

    R: np.ndarray
    spectral_radius: float
    norm_max: float
    norm_2: float
    norm_weighted: float
    weight: np.ndarray | None
    tau_limits: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {"spectral_radius": self.spectral_radius, "norm_max": self.norm_max,
                "norm_2": self.norm_2, "norm_weighted": self.norm_weighted,
                **{f"tau_limit_{k}": v for k, v in self.tau_limits.items()}}  # fmt: skip


def discrete(A_tilde, scheme, tau: float, *, limits: bool = True) -> Discrete:
    """Theorems 6 and 7 for a constant law: ``R`` (:func:`step_matrix`), ``ρ(R)``,
    ``‖R‖∞`` (the paper's norm), ``‖R‖₂``, ``‖R‖_P`` with the discrete-Lyapunov weight, and
    (``limits=True``) the largest τ for which each of them is below 1."""
    A = _square(A_tilde, "discrete")
    R = step_matrix(A, scheme, tau)
    P = lyapunov_weight(R)
    out = Discrete(
        R=R,
        spectral_radius=spectral_radius_of(A, scheme, tau),
        norm_max=CONDITIONS["max_norm"](R),
        norm_2=CONDITIONS["two_norm"](R),
        norm_weighted=math.inf if P is None else weighted_norm(R, P),
        weight=P,
    )
    if limits:
        out.tau_limits = {c: tau_limit(A, scheme, c) for c in CONDITIONS}
    return out


# --------------------------------------------------------------------- Theorem 5
def theorem5(model: Model, law, states, *, t=None, params=None) -> dict:
    """Theorem 5's constants for the law ``ḣ = −k W(x) L h`` over the given states.

    Parameters
    ----------
    states : array (N, 2n)
        States at which ``W = h_v h_vᵀ`` is evaluated (visited by an ensemble, or sampled
        near the manifold); ``λ_min(W)`` is the minimum over them.

    Returns
    -------
    dict with ``k0``, ``lambda_min_W``, ``w0 = √λ_min(W)`` (the printed condition
    ``αᵀWα ≥ w₀²‖α‖²``), ``l1``, ``lm``, ``beta_proven = k₀ λ_min(W) l₁²/l_m``,
    ``beta_printed = k₀ w₀ l₁²/l_m`` and ``gamma_factor = √(l_m/l₁)`` (``γ = ‖g(x₀)‖·that``).
    """
    law = as_law(law)
    if not isinstance(law, Theorem5):
        raise TypeError(f"theorem5: the law must be stabdae.theorem5(...), got {law}")
    L = law._L(model)
    p = model.param_vector(params)
    t = model.t0 if t is None else float(t)
    states = np.atleast_2d(np.asarray(states, dtype=float))
    states = states[np.all(np.isfinite(states), axis=1)]
    lam_min = math.inf
    for x in states:
        hv = model.evaluate("h_v", t, x, p)
        lam_min = min(lam_min, float(np.linalg.eigvalsh(hv @ hv.T).min()))
    lL = np.linalg.eigvalsh(L)
    l1, lm = float(lL.min()), float(lL.max())
    k0 = float(law.gain)
    w0 = math.sqrt(max(lam_min, 0.0))
    return {"k0": k0, "lambda_min_W": lam_min, "w0": w0, "l1": l1, "lm": lm,
            "beta_proven": k0 * lam_min * l1 * l1 / lm,
            "beta_printed": k0 * w0 * l1 * l1 / lm,
            "gamma_factor": math.sqrt(lm / l1), "states": int(states.shape[0])}  # fmt: skip


def bound_held(times, norms, alpha0_norm, beta: float, gamma_factor: float, floor, *,
               rtol: float = 1e-6, floor_factor: float = 10.0) -> np.ndarray:  # fmt: skip
    """Per member: did ``‖α(t)‖ ≤ γ e^{−β(t − t₀)} + floor`` (``γ = gamma_factor·‖α⁰‖``) hold
    at every stored sample where the bound is above ``floor_factor ×`` the member's
    residual floor?

    The theorem is about the exact flow.  The numerical residual carries the scheme's
    truncation error, whose level is the member's floor: it is added to the bound, and
    samples where the bound itself has fallen near that floor are not judged (any decaying
    bound fails there).  ``rtol`` absorbs the float32 storage of the norms.
    """
    norms = np.asarray(norms, dtype=float)
    t = np.asarray(times, dtype=float) - float(times[0])
    bound = (gamma_factor * np.asarray(alpha0_norm, float))[:, None] * np.exp(-beta * t)[None]
    fl = np.nan_to_num(np.asarray(floor, float), nan=0.0)[:, None]
    judged = bound > floor_factor * fl
    ok = ~judged | ~np.isfinite(norms) | (norms <= bound * (1.0 + rtol) + fl)
    return ok.all(axis=1)


# --------------------------------------------------------------------- along a path
def along_path(model: Model, law, scheme, trajectory: xr.Dataset, *, params=None,
               weight=None) -> xr.Dataset:  # fmt: skip
    """Theorems 6/7 along one trajectory (state-dependent laws, or a constant law with the
    nonlinear remainder).

    Parameters
    ----------
    model, law, scheme
        The trajectory's model, law and scheme.
    trajectory : xarray.Dataset
        A trajectory of :func:`stabdae.integrate` with that law and scheme, every step
        stored (``save_dt = tau``): its states ``x_k`` and residuals ``g_k``.
    params : mapping or array, optional
        The parameters it was integrated with.
    weight : array, optional
        The weight ``P`` of the norm (default: from the discrete Lyapunov equation of
        ``R_0``).

    Returns
    -------
    xarray.Dataset
        Per step: the spectral radius, the max-, 2- and weighted norm of ``R_k``, the
        remainder and the residual norm; the scalars ``q``, ``epsilon`` and
        ``bound_start``.

    Notes
    -----
    Per step ``k``: ``A_k = A(x_k)``; ``Ȧ_k`` by central differences along the path; ``R_k``
    (:func:`step_matrix`); its spectral radius, max-, 2- and weighted norm (``P`` from the
    discrete Lyapunov equation of ``R_0`` unless ``weight`` is given — one norm for the
    whole path, as the theorems need); the remainder ``e_k = g_{k+1} − R_k g_k`` actually
    made by the step (the ``τ²/2 g⁽²⁾`` of Theorem 6, the ``R⁽³⁾`` of Theorem 7).

    Scalars: ``q = max_k ‖R_k‖_P``; when ``q < 1`` the floor of condition 4,
    ``ε = max_k ‖P e_k‖₂ / (1 − q)``, converted to the max-norm with ``‖P⁻¹‖₂``, so that
    Theorems 6/7 give ``‖g_k‖∞ ≤ max(‖P⁻¹‖₂‖P g₀‖₂, ε)``.
    """
    law = as_law(law)
    scheme = as_scheme(scheme)
    tau = float(trajectory.attrs.get("tau", math.nan))
    save_dt = float(trajectory.attrs.get("save_dt", math.nan))
    if not (math.isfinite(tau) and math.isclose(save_dt, tau, rel_tol=1e-12)):
        raise ValueError(
            "along_path: the trajectory must come from stabdae.integrate with every step "
            f"stored (save_dt = tau); got tau = {tau:g}, save_dt = {save_dt:g}"
        )
    p = model.param_vector(params)
    xs, gs, ts = trajectory.x.values, trajectory.residual.values, trajectory.time.values
    ok = np.all(np.isfinite(xs), axis=1) & np.all(np.isfinite(gs), axis=1)
    N = int(ok.sum())
    As = np.stack([_A_tilde(law, model, xs[k], ts[k], p) for k in range(N)])
    Adot = np.zeros_like(As)
    if N >= 3:
        Adot[1:-1] = (As[2:] - As[:-2]) / (2.0 * tau)
        Adot[0], Adot[-1] = (As[1] - As[0]) / tau, (As[-1] - As[-2]) / tau
    Rs = np.stack([step_matrix(As[k], scheme, tau, Adot[k]) for k in range(N)])
    P = lyapunov_weight(Rs[0]) if weight is None else np.asarray(weight, float)
    rho = np.array([spectral_radius(R) for R in Rs])
    nmax = np.array([CONDITIONS["max_norm"](R) for R in Rs])
    n2 = np.array([CONDITIONS["two_norm"](R) for R in Rs])
    nw = np.array([math.inf if P is None else weighted_norm(R, P) for R in Rs])
    rem = np.full(N, np.nan)
    remP = np.full(N, np.nan)
    for k in range(N - 1):
        e = gs[k + 1] - Rs[k] @ gs[k]
        rem[k] = np.abs(e).max()
        if P is not None:
            remP[k] = np.linalg.norm(P @ e)
    q = float(nw[: max(N - 1, 1)].max())
    if P is not None and q < 1.0:
        Pinv = float(np.linalg.norm(np.linalg.inv(P), 2))
        eps = Pinv * float(np.nanmax(remP)) / (1.0 - q)
        start = Pinv * float(np.linalg.norm(P @ gs[0]))
    else:
        eps, start = math.inf, math.inf
    values = {"spectral_radius": rho, "norm_max": nmax, "norm_2": n2, "norm_weighted": nw,
              "remainder": rem, "residual_norm": np.abs(gs[:N]).max(axis=1), "q": q,
              "epsilon": eps, "bound_start": start}  # fmt: skip
    data = {name: schema_variable(name, val, model, dims=("step",) if np.ndim(val) else (),
                                  key=f"path_{name}")
            for name, val in values.items()}  # fmt: skip
    attrs = provenance(model, p, law, scheme, "theory.along_path: Theorems 6/7 along a "
                       "trajectory", tau=tau)  # fmt: skip
    coords = {"step": variable("step", np.arange(N), "step index k", "1"),
              "time": variable("step", ts[:N], "time", "s"), **component_coords(model)}  # fmt: skip
    return cf_dataset(data, coords=coords, attrs=attrs)


def _A_tilde(law: Law, model: Model, x, t, p) -> np.ndarray:
    if law.is_constant:
        return law.A_tilde(model)
    return law.A_tilde(model, x, t, p)


# --------------------------------------------------------------------- summary
def predictions(model: Model, law, scheme, tau: float, *, limits: bool = False) -> dict:
    """Scalars the ensemble dataset stores beside its measurements, for a constant law:
    Theorem 3's ``beta_theory``, ``beta_theory_discrete = −ln ρ(R)/τ``, ``spectral_radius``,
    ``norm_max`` (the paper's norm of ``R``), ``norm_weighted`` and ``norm_condition``
    (1 when the weighted-norm condition holds)."""
    law = as_law(law)
    A = np.ascontiguousarray(law.A_tilde(model), dtype=np.float64)
    Ab, bb, cb = (np.ascontiguousarray(v, dtype=np.float64) for v in (scheme.A, scheme.b, scheme.c))
    key = (A.shape, A.tobytes(), Ab.shape, Ab.tobytes(), bb.tobytes(), cb.tobytes(),
           float(tau), bool(limits))  # fmt: skip
    hit = _PREDICTIONS.get(key)
    if hit is None:
        hit = _PREDICTIONS[key] = _predictions(A, scheme, tau, limits)
        while len(_PREDICTIONS) > 256:  # a sweep over τ and A: keep the latest
            _PREDICTIONS.pop(next(iter(_PREDICTIONS)))
    return dict(hit)


#: predictions by (Ã, tableau, τ): an ensemble of the same law and step repeats them (a
#: Lyapunov solve and eigenvalues each time, comparable to a short ensemble's integration)
_PREDICTIONS: dict = {}


def _predictions(A, scheme, tau, limits) -> dict:
    d = discrete(A, scheme, tau, limits=limits)
    rho = d.spectral_radius
    out = {
        "beta_theory": continuous(A)["beta"],
        "beta_theory_discrete": -math.log(rho) / tau if rho > 0 else math.inf,
        "spectral_radius": rho,
        "norm_max": d.norm_max,
        "norm_weighted": d.norm_weighted,
        "norm_condition": np.int8(d.norm_weighted < 1.0),
    }
    if limits:
        out.update({f"tau_limit_{k}": v for k, v in d.tau_limits.items()})
    return out


def _square(A, who: str) -> np.ndarray:
    A = np.asarray(A, dtype=float)
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise ValueError(f"{who}: Ã must be a square matrix, got shape {A.shape}")
    return A
