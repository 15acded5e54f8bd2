"""The paper's Theorems 3–7 as computations (DESIGN §4–5).

Continuous time

* :func:`continuous` — Theorem 3: eigenvalues of ``Ã``; decay rate ``−max Re λ(Ã)``.
* :func:`lyapunov` — Theorem 4: ``2V = αᵀLα``; Sylvester's criterion on the *symmetric part*
  ``Q = −(LÃ + ÃᵀL)/2`` (the paper writes ``−LÃ``, DESIGN §4 note); with no ``L`` given,
  ``L`` solves the continuous Lyapunov equation ``ÃᵀL + LÃ = −I``.
* :func:`theorem5` — Theorem 5 (nonholonomic, ``m = 0``): ``λ_min(W)`` with ``W = h_v h_vᵀ``
  over given states, ``l₁``, ``l_m``, the proven ``β = k₀ λ_min(W) l₁²/l_m`` beside the
  paper's printed ``β = k₀ w₀ l₁²/l_m`` (``w₀ = √λ_min(W)``, DESIGN §4 note), ``γ``.

Discrete time

* :func:`step_matrix` — the residual recursion's matrix: ``E + τA`` (Euler, (5.1)),
  ``E + τA + τ²/2 (A² + Ȧ)`` (two-stage with ``2aσ = 1``, (5.13)), and for any other
  explicit scheme its stability polynomial ``R(τÃ)``.
* :func:`discrete` — Theorems 6 and 7 for a constant law: ``R``, its spectral radius,
  max-norm (the paper's norm), 2-norm and its norm in the weight ``P = X^{1/2}`` of the
  discrete Lyapunov equation ``RᵀXR − X = −I``; the largest τ for which each condition
  holds (:func:`tau_limit`, by bisection).
* :func:`along_path` — the same along a trajectory, for state-dependent laws (``Ȧ`` by
  central differences along the path), and the floor ``ε`` that condition 4 implies from
  the one-step remainder measured along the path.

Why the weighted norm: with ``m > 0`` the first block row of ``E + τÃ`` is
``[I, τI, 0]``, so its max-norm (and 2-norm) is ``≥ 1 + τ`` for every ``τ > 0``; the
iteration contracts in *some* norm iff ``ρ(R) < 1``, and ``P`` above is one such norm:
``‖R‖_P² = 1 − 1/λ_max(X)``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import xarray as xr

from ._laws import Law, as_law
from ._model import Model
from ._schemes import as_scheme

__all__ = [
    "continuous",
    "lyapunov",
    "step_matrix",
    "spectral_radius",
    "weighted_norm",
    "discrete",
    "tau_limit",
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


def spectral_radius(R) -> float:
    return float(np.max(np.abs(np.linalg.eigvals(R))))


def lyapunov_weight(R):
    """``P = X^{1/2}`` with ``RᵀXR − X = −I``, or ``None`` when no SPD ``X`` exists
    (``ρ(R) ≥ 1``)."""
    n = R.shape[0]
    if not np.all(np.isfinite(R)) or spectral_radius(R) >= 1.0:
        return None
    try:
        with warnings.catch_warnings():  # ρ → 1 makes X large and ill-conditioned
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            X = sla.solve_discrete_lyapunov(R.T, np.eye(n))
    except (np.linalg.LinAlgError, ValueError):
        return None
    X = 0.5 * (X + X.T)
    w, V = np.linalg.eigh(X)
    if not (np.all(np.isfinite(w)) and w.min() > 0):
        return None
    return (V * np.sqrt(w)) @ V.T


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
    fn = CONDITIONS[condition]
    scheme = as_scheme(scheme)
    A = _square(A_tilde, "tau_limit")
    lam = np.abs(np.linalg.eigvals(A)).max()
    scale = 1.0 / lam if lam > 0 else 1.0
    tau_max = 1e6 * scale if tau_max is None else tau_max

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
        spectral_radius=spectral_radius(R),
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
    from ._laws import Theorem5

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
def along_path(model: Model, law, scheme, tau: float, t_end: float, x0=None, *,
               params=None, weight=None) -> xr.Dataset:  # fmt: skip
    """Theorems 6/7 along one trajectory (state-dependent laws, or a constant law with the
    nonlinear remainder).

    The trajectory is integrated with the scheme itself, every step saved.  Per step
    ``k``: ``A_k = A(x_k)``; ``Ȧ_k`` by central differences along the path; ``R_k``
    (:func:`step_matrix`); its spectral radius, max-, 2- and weighted norm (``P`` from the
    discrete Lyapunov equation of ``R_0`` unless ``weight`` is given — one norm for the
    whole path, as the theorems need); the remainder ``e_k = g_{k+1} − R_k g_k`` actually
    made by the step (the ``τ²/2 g⁽²⁾`` of Theorem 6, the ``R⁽³⁾`` of Theorem 7).

    Scalars: ``q = max_k ‖R_k‖_P``; when ``q < 1`` the floor of condition 4,
    ``ε = max_k ‖P e_k‖₂ / (1 − q)``, converted to the max-norm with ``‖P⁻¹‖₂``, so that
    Theorems 6/7 give ``‖g_k‖∞ ≤ max(‖P⁻¹‖₂‖P g₀‖₂, ε)``.
    """
    from ._integrate import integrate

    law = as_law(law)
    scheme = as_scheme(scheme)
    ds = integrate(model, x0, law, scheme, tau, t_end, tau, params=params)
    p = model.param_vector(params)
    xs, gs, ts = ds.x.values, ds.residual.values, ds.time.values
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
    step = np.arange(N)
    out = xr.Dataset(
        {
            "spectral_radius": ("step", rho, {"long_name": "spectral radius of R_k", "units": "1"}),
            "norm_max": ("step", nmax, {"long_name": "max-norm of R_k", "units": "1"}),
            "norm_2": ("step", n2, {"long_name": "2-norm of R_k", "units": "1"}),
            "norm_weighted": ("step", nw, {"long_name": "norm of R_k in the path weight P",
                                           "units": "1"}),
            "remainder": ("step", rem, {"long_name": "max-norm of g_{k+1} - R_k g_k",
                                        "units": "1"}),
            "residual_norm": ("step", np.abs(gs[:N]).max(axis=1),
                              {"long_name": "max-norm of g along the path", "units": "1"}),
            "q": ((), q, {"long_name": "max_k of the weighted norm of R_k", "units": "1"}),
            "epsilon": ((), eps, {"long_name": "floor implied by condition 4 (max-norm)",
                                  "units": "1"}),
            "bound_start": ((), start, {"long_name": "|P^-1| |P g0|: the bound's start",
                                        "units": "1"}),
        },
        coords={"step": step, "time": ("step", ts[:N], {"units": "s"})},
        attrs={"tau": tau, "scheme": scheme.name, "law": str(law), "model": model.name},
    )  # fmt: skip
    return out


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


#: predictions by (Ã, tableau, τ): an ensemble of the same law and step repeats them
#: (0.7 ms, a Lyapunov solve and eigenvalues, against a 0.1 s run of 10⁴ members)
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



# --------------------------------------------------------------------- a study's grid
def for_study(study, *, path_steps: int = 2000) -> xr.Dataset:
    """The theorems' predictions at every grid point of a study (``stabdae theory``).

    Constant laws: Theorems 3, 4, 6/7 from ``Ã`` alone, nothing integrated.  Theorem 5
    laws: ``λ_min(W)`` over a sampled neighbourhood of the manifold (the study's
    perturbations placed around ``x*``, and the reference trajectory) and the discrete
    conditions along the reference trajectory (its first ``path_steps`` steps).
    """
    from ._ensemble import sample_perturbations
    from ._integrate import integrate

    model = study.model
    names = list(study.axes)
    shape = study.shape
    cols: dict[str, np.ndarray] = {}

    def put(name, idx, value):
        if name not in cols:
            cols[name] = np.full(shape, np.nan)
        cols[name][idx] = value

    neighbourhood = None
    per_law: dict = {}
    for idx, values in study.points():
        s = study.setup(values)
        law, scheme, tau = s["law"], s["scheme"], s["tau"]
        p = model.param_vector(s["params"])
        if law.is_constant:
            A = law.A_tilde(model)
            # what depends on Ã (and the scheme) alone is computed once per distinct law,
            # not at every τ of the grid: the τ limits are four bisections each
            key = (A.tobytes(), A.shape, scheme.name, tuple(sorted(scheme.params.items())))
            if key not in per_law:
                c, ly = continuous(A), lyapunov(A)
                per_law[key] = {
                    "beta_theory": c["beta"], "lyapunov_holds": float(ly["holds"]),
                    "beta_lyapunov": ly["beta"],
                    **{f"tau_limit_{k}": tau_limit(A, scheme, k) for k in CONDITIONS},
                }  # fmt: skip
            for k, v in per_law[key].items():
                put(k, idx, v)
            d = discrete(A, scheme, tau, limits=False)
            rho = d.spectral_radius
            put("beta_theory_discrete", idx, -math.log(rho) / tau if rho > 0 else math.inf)
            for k, v in d.as_dict().items():
                put(k, idx, v)
            put("norm_condition", idx, float(d.norm_weighted < 1.0))
        else:
            if neighbourhood is None or any(n.startswith("model.") for n in names):
                x_ref = model.reference_state(p)
                ens = sample_perturbations(model, study.ensemble["members"],
                                           study.ensemble["radius"], study.ensemble["seed"],
                                           params=p)[0]  # fmt: skip
                traj = integrate(model, x_ref, law, scheme, tau, s["t_end"], s["save_dt"],
                                 params=p).x.values  # fmt: skip
                neighbourhood = np.concatenate([ens, traj])
            c5 = theorem5(model, law, neighbourhood, params=p)
            for k in ("lambda_min_W", "beta_proven", "beta_printed", "gamma_factor"):
                put(f"theorem5_{k}", idx, c5[k])
            t_path = min(s["t_end"], model.t0 + path_steps * tau)
            t_path = model.t0 + tau * max(2, round((t_path - model.t0) / tau))
            path = along_path(model, law, scheme, tau, t_path, None, params=p)
            put("path_spectral_radius_max", idx, float(path.spectral_radius.max()))
            put("path_norm_weighted_max", idx, float(path.q))
            put("path_epsilon", idx, float(path.epsilon))
    data = {k: (names, v, {"long_name": _LONG.get(k, k), "units": _UNITS.get(k, "1")})
            for k, v in cols.items()}  # fmt: skip
    ds = xr.Dataset(data, coords={n: (n, v) for n, v in study.axes.items()})
    ds.attrs.update(model=model.name, law=study.law["kind"], scheme=study.setup()["scheme"].name,
                    study=str(study.path))  # fmt: skip
    return ds


_LONG = {
    "beta_theory": "continuous decay rate -max Re eig(A~) (Theorem 3)",
    "lyapunov_holds": "Theorem 4: Sylvester's criterion on L and the symmetric part of -LA~",
    "beta_lyapunov": "rate proven by the Lyapunov function, lambda_min(Q)/l_m",
    "beta_theory_discrete": "discrete decay rate -ln rho(R)/tau",
    "spectral_radius": "spectral radius of R(tau A~)",
    "norm_max": "max-norm of R (the paper's norm; Theorems 6, 7)",
    "norm_2": "2-norm of R",
    "norm_weighted": "norm of R in the discrete-Lyapunov weight",
    "norm_condition": "weighted-norm condition holds",
    "tau_limit_spectral": "largest tau with rho(R) < 1",
    "tau_limit_max_norm": "largest tau with max-norm of R < 1",
    "tau_limit_two_norm": "largest tau with 2-norm of R < 1",
    "tau_limit_weighted_norm": "largest tau with the weighted norm of R < 1",
}
_UNITS = {"beta_theory": "s-1", "beta_lyapunov": "s-1", "beta_theory_discrete": "s-1",
          "tau_limit_spectral": "s", "tau_limit_max_norm": "s", "tau_limit_two_norm": "s",
          "tau_limit_weighted_norm": "s", "theorem5_beta_proven": "s-1",
          "theorem5_beta_printed": "s-1"}  # fmt: skip


def format_table(ds: xr.Dataset, columns=None) -> str:
    """A readable table of :func:`for_study`'s dataset, one row per grid point."""
    columns = columns or [v for v in ("spectral_radius", "norm_max", "norm_weighted",
                                      "norm_condition", "beta_theory", "beta_theory_discrete",
                                      "lyapunov_holds", "tau_limit_spectral",
                                      "theorem5_lambda_min_W", "theorem5_beta_proven",
                                      "theorem5_beta_printed", "path_spectral_radius_max",
                                      "path_norm_weighted_max", "path_epsilon")
                          if v in ds]  # fmt: skip
    short = {"spectral_radius": "rho(R)", "norm_max": "|R|max", "norm_weighted": "|R|P",
             "norm_condition": "cond", "beta_theory": "beta", "beta_theory_discrete":
             "beta_disc", "lyapunov_holds": "Lyap", "tau_limit_spectral": "tau_lim",
             "theorem5_lambda_min_W": "lmin(W)", "theorem5_beta_proven": "b_proven",
             "theorem5_beta_printed": "b_printed", "path_spectral_radius_max": "rho_path",
             "path_norm_weighted_max": "q_path", "path_epsilon": "eps_path"}  # fmt: skip
    return grid_table(ds, columns, short, flags=("norm_condition", "lyapunov_holds"),
                      precise=("norm_weighted", "spectral_radius", "path_norm_weighted_max"))


def grid_table(ds: xr.Dataset, columns, short: dict, *, flags=(), precise=()) -> str:
    """One row per grid point of ``ds`` (its swept dimensions first, then ``columns``,
    headed by ``short`` names): ``flags`` as yes/no, ``precise`` with 6 digits (the ones
    that decide "< 1"), the rest with 4."""
    dims = list(ds[columns[0]].dims)
    flat = ds[columns].stack(point=dims) if dims else ds[columns].expand_dims(point=[0])
    head = [d.split(".", 1)[-1] for d in dims] + [short.get(c, c) for c in columns]
    rows = []
    for i in range(flat.sizes["point"]):
        row = [f"{float(flat[d].values[i]):.4g}" for d in dims]
        for c in columns:
            v = float(flat[c].values[i])
            if c in flags:
                row.append("yes" if v == 1 else "no")
            else:
                row.append(f"{v:.6g}" if c in precise else f"{v:.4g}")
        rows.append(row)
    width = [max(len(h), *(len(r[j]) for r in rows)) for j, h in enumerate(head)]
    lines = ["  ".join(h.rjust(w) for h, w in zip(head, width))]
    lines += ["  ".join(x.rjust(w) for x, w in zip(r, width)) for r in rows]
    return "\n".join(lines)
