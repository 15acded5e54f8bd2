"""``model.check()``: derivative pieces against finite differences, mass matrix SPD.

What is compared (central differences, step ``h = ε^{1/3} max(1, |x_j|)``):

========== ==============================================================
f_q        ∂f/∂q
f_t        ∂f/∂t (zero when the model declares no f_t)
f_accel    d/dt (f_q T v + f_t) along q̇ = T v at fixed v (T = I without a kinematic
           map): ``(d/dt (f_q T)) v + d/dt f_t``
h_q, h_v   ∂h/∂q, ∂h/∂v
h_t        ∂h/∂t (zero when the model declares no h_t)
mass       symmetric to 1e-12 relative, and positive definite
kinematics T (n × n) invertible: its condition number below 1e12
sparsity   every non-zero of mass, f_q, h_q, h_v inside the pattern the model
           declared or detected (the sparse right-hand side reads nothing else)
========== ==============================================================

A piece fails when ``max |analytic − finite difference| > rtol · max(max |fd|, max
|analytic|) + noise``: relative to the piece's own size at that state (a term that is small
in the model's units is checked as strictly as a large one), ``noise`` the finite
differences' own roundoff, ``100 ε^{2/3}`` times the size of the values differenced.

The states: the reference state, and ``states`` random ones whose coordinates lie within
``radius`` (relative) of the reference's and whose velocities are drawn at the scale of
the motion: ``velocity`` per second (default: the model's declared velocity ``scales``, else the
reference's largest speed, or, at rest, its largest coordinate per second), around the
reference's.  A velocity-squared
term of ``f_accel`` is then of the size of the others, and a wrong sign in it shows at
every random state (at a reference at rest it is zero whatever its sign).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # model.check() calls in here: the model module imports this one
    from ._model import Model

_EPS3 = np.finfo(float).eps ** (1 / 3)


@dataclass(frozen=True)
class CheckRow:
    piece: str
    state: int
    error: float
    tolerance: float
    detail: str = ""

    @property
    def ok(self) -> bool:
        return self.error <= self.tolerance


@dataclass
class CheckReport:
    """Result of :meth:`Model.check`: one row per piece and state."""

    model: str
    rtol: float
    states: np.ndarray
    rows: list[CheckRow] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return all(r.ok for r in self.rows)

    @property
    def failures(self) -> list[str]:
        """Names of the pieces that disagree at some state, in order of first failure."""
        out: list[str] = []
        for r in self.rows:
            if not r.ok and r.piece not in out:
                out.append(r.piece)
        return out

    def __str__(self) -> str:
        lines = [
            f"model {self.model!r}: derivatives against central finite differences "
            f"at {len(self.states)} states (state 0 = reference), rtol = {self.rtol:g}",
            f"{'piece':<10} {'state':>5} {'max error':>11} {'tolerance':>11}  result",
        ]
        for r in self.rows:
            verdict = "ok" if r.ok else "DISAGREES"
            extra = f"  ({r.detail})" if r.detail else ""
            lines.append(
                f"{r.piece:<10} {r.state:>5} {r.error:>11.3e} {r.tolerance:>11.3e}  "
                f"{verdict}{extra}"
            )
        if self.ok:
            lines.append("all pieces agree")
        else:
            lines.append(f"pieces that disagree: {', '.join(self.failures)}")
        return "\n".join(lines)

    def raise_if_failed(self) -> None:
        if not self.ok:
            raise AssertionError(str(self))


def _steps(vec: np.ndarray) -> np.ndarray:
    return _EPS3 * np.maximum(1.0, np.abs(vec))


def _jacobian(fun, vec: np.ndarray) -> np.ndarray:
    """Central-difference Jacobian of ``fun`` at ``vec`` (columns = variables)."""
    hs = _steps(vec)
    cols = []
    for j, hj in enumerate(hs):
        up, dn = vec.copy(), vec.copy()
        up[j] += hj
        dn[j] -= hj
        cols.append((fun(up) - fun(dn)) / (2 * hj))
    return np.stack(cols, axis=-1)


def _scalar_derivative(fun, s: float) -> np.ndarray:
    h = _EPS3 * max(1.0, abs(s))
    return (fun(s + h) - fun(s - h)) / (2 * h)


#: the finite differences' roundoff allowed: this many ``ε^{2/3}`` times the size of the
#: values differenced (central differences with ``h = ε^{1/3}``: ``ε |F| / h``)
_NOISE = 100.0 * _EPS3 * _EPS3


def velocity_scale(x_ref: np.ndarray, n: int, velocity=None) -> np.ndarray:
    """Each velocity component's scale for the check's random states: ``velocity`` (a
    number or one per coordinate) where given, else the reference's largest speed, or at
    rest its largest coordinate per second (1 where both are zero)."""
    if velocity is not None:
        scale = np.broadcast_to(np.asarray(velocity, dtype=float), (n,)).copy()
        if not (np.all(np.isfinite(scale)) and np.all(scale >= 0)):
            raise ValueError(f"check: velocity must be finite and ≥ 0, got {velocity!r}")
        return scale
    speed = float(np.max(np.abs(x_ref[n:]), initial=0.0))
    size = float(np.max(np.abs(x_ref[:n]), initial=0.0))
    return np.full(n, speed if speed > 0 else (size if size > 0 else 1.0))


def check_model(model: Model, params=None, *, states=3, radius=1e-2, seed=0, rtol=1e-6,
                velocity=None):  # fmt: skip
    """Compare every derivative piece of ``model`` with finite differences.

    Parameters
    ----------
    params : mapping or array, optional
        Physical parameters (default: the model's).
    states : int
        Number of random states near the reference state, checked besides it.
    radius : float
        Relative size of the random displacement of those states' coordinates.
    velocity : float or array (n,), optional
        Scale of those states' velocities, per second (default: the reference state's
        largest speed, or its largest coordinate when it is at rest).
    seed : int
        Seed of the random states.
    rtol : float
        Tolerance, relative to each piece's size at the state (plus the finite
        differences' roundoff).

    Returns
    -------
    CheckReport
        ``report.ok`` is True when every piece agrees; ``str(report)`` is a table and
        ``report.failures`` names the pieces that disagree.
    """
    who = f"{model.name}.check"
    rtol = _positive(rtol, "rtol", who)
    radius = _positive(radius, "radius", who)
    if isinstance(states, bool) or not isinstance(states, (int, np.integer)) or states < 0:
        raise ValueError(f"{who}: states must be a non-negative integer, got {states!r}")
    p = model.param_vector(params)
    rng = np.random.default_rng(seed)
    x_ref = model.reference_state(p)
    xs = [x_ref]
    ts = [model.t0]
    n = model.n
    scale = np.maximum(1.0, np.abs(x_ref))
    if velocity is None and model.scales is not None:
        velocity = model.scales[n:]
    vscale = velocity_scale(x_ref, n, velocity)
    for _ in range(states):
        x = x_ref + radius * scale * rng.standard_normal(x_ref.shape)
        x[n:] = x_ref[n:] + vscale * rng.standard_normal(n)
        xs.append(x)
        ts.append(model.t0 + (rng.uniform(0.0, 1.0) if model.time_dependent else 0.0))
    report = CheckReport(model.name, rtol, np.array(xs))
    for i, (x, t) in enumerate(zip(xs, ts)):
        _check_state(model, report, i, x, t, p)
    return report


def _positive(value, name: str, who: str) -> float:
    # The drivers' rule (stabdae._validate.positive), restated: that module binds laws to
    # models, and the model module imports this one.
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{who}: {name} must be a real number, got {value!r}") from None
    if not (math.isfinite(out) and out > 0):
        raise ValueError(f"{who}: {name} must be positive and finite, got {value!r}")
    return out


def _check_state(model: Model, report: CheckReport, i: int, x, t: float, p) -> None:
    """Append the rows of state ``i`` to ``report``; first every piece runs there as
    Python, with NumPy's bounds checks: a write outside ``out`` that the reference state
    did not reach raises a ModelError naming the piece and the state, instead of corrupting
    memory in the compiled kernels."""
    model._probe_at(t, x, p, f" at check state {i}")
    n, ev = model.n, model.evaluate
    q, v = x[:n], x[n:]

    def add(piece, analytic, fd, values, detail=""):
        """A row: ``values`` the size of what the finite difference differenced."""
        analytic, fd = np.asarray(analytic), np.asarray(fd)
        err = float(np.max(np.abs(analytic - fd))) if analytic.size else 0.0
        mag = max(float(np.max(np.abs(fd), initial=0.0)),
                  float(np.max(np.abs(analytic), initial=0.0)))  # fmt: skip
        tol = report.rtol * mag + _NOISE * float(values)
        report.rows.append(CheckRow(piece, i, err, tol, detail))

    def size(a) -> float:
        return float(np.max(np.abs(np.asarray(a)), initial=0.0))

    def with_q(qq):
        return np.concatenate([qq, v])

    def with_v(vv):
        return np.concatenate([q, vv])

    if model.m:
        f0 = size(ev("f", t, x, p))
        add("f_q", ev("f_q", t, x, p), _jacobian(lambda qq: ev("f", t, with_q(qq), p), q), f0)
        add("f_t", ev("f_t", t, x, p), _scalar_derivative(lambda s: ev("f", s, x, p), t), f0,
            "" if "f_t" in model.functions else "model declares none")  # fmt: skip

        T0 = ev("kinematics", t, x, p)  # the identity without a kinematic map

        def moved(s):  # the state at s along the motion q(s) = q + (s − t) T v, v fixed
            return np.concatenate([q + (s - t) * (T0 @ v), v])

        def fdot(s):  # ḟ = f_q T v + f_t there (T v is v exactly where T = I)
            xx = moved(s)
            return ev("f_q", s, xx, p) @ (ev("kinematics", s, xx, p) @ v) + ev("f_t", s, xx, p)

        def terms_at(s):  # ḟ's terms, not ḟ itself (near zero on the manifold)
            xx = moved(s)
            Ts = np.abs(ev("kinematics", s, xx, p))
            return size(np.abs(ev("f_q", s, xx, p)) @ Ts @ np.abs(v)) + size(ev("f_t", s, xx, p))

        # their roundoff, at the states differenced (where a structural zero at x, such as
        # a quaternion's at the identity, does not hold)
        h = _EPS3 * max(1.0, abs(t))
        terms = terms_at(t) if not model.kinematic else max(terms_at(t - h), terms_at(t + h))
        add("f_accel", ev("f_accel", t, x, p), _scalar_derivative(fdot, t), terms)
    if model.k:
        h0 = size(ev("h", t, x, p))
        add("h_q", ev("h_q", t, x, p), _jacobian(lambda qq: ev("h", t, with_q(qq), p), q), h0)
        add("h_v", ev("h_v", t, x, p), _jacobian(lambda vv: ev("h", t, with_v(vv), p), v), h0)
        add("h_t", ev("h_t", t, x, p), _scalar_derivative(lambda s: ev("h", s, x, p), t), h0,
            "" if "h_t" in model.functions else "model declares none")  # fmt: skip
    for piece, pattern in (model.patterns or {}).items():
        value = ev(piece, t, x, p)
        outside = np.abs(np.where(pattern, 0.0, value))
        outside[np.isnan(value) & ~pattern] = np.inf
        worst = float(outside.max(initial=0.0))
        detail = f"{piece}: every non-zero inside its pattern"
        if worst > 0:
            entry = [int(j) for j in np.unravel_index(int(np.argmax(outside)), outside.shape)]
            how = "declared" if piece in model._declared else "detected at construction"
            detail = (f"{piece} out{entry} = {float(value[tuple(entry)])!r}, an entry its "
                      f"sparsity pattern ({how}) marks structurally zero")
        report.rows.append(CheckRow("sparsity", i, worst, 0.0, detail))
    if model.kinematic:
        sv = np.linalg.svd(ev("kinematics", t, x, p), compute_uv=False)
        cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf
        report.rows.append(CheckRow("kinematics", i, cond, 1e12,
                                    f"condition number of T {cond:.3e}"))  # fmt: skip
    if model.has_mass:
        M = ev("mass", t, x, p)
        asym = float(np.max(np.abs(M - M.T)))
        mag = max(1.0, float(np.max(np.abs(M))))
        report.rows.append(CheckRow("mass", i, asym, 1e-12 * mag, "symmetry"))
        lam_min = float(np.linalg.eigvalsh(0.5 * (M + M.T)).min())
        verdict = "positive definite" if lam_min > 0 else "NOT positive definite"
        report.rows.append(
            CheckRow("mass", i, 0.0 if lam_min > 0 else 1.0, 0.0,
                     f"smallest eigenvalue {lam_min:.3e}: {verdict}")
        )  # fmt: skip
