"""Models from a symbolic Lagrangian: derive every piece with sympy and write a model file.

Hand-deriving ``γ``, ``f_accel`` and the Jacobians is where model files go wrong.  A
*spec* names the coordinates, the Lagrangian ``L(q, q̇, t)``, the holonomic constraints
``f(q, t)`` and the nonholonomic constraints ``h(q, q̇, t)``; :class:`System` derives

* ``M = ∂²L/∂q̇²`` (omitted when it is the identity),
* ``γ = (∂²L/∂q̇∂q) q̇ + ∂²L/∂q̇∂t − ∂L/∂q − Q`` so that ``M q̈ = Fᵀλ − γ`` is
  ``d/dt ∂L/∂q̇ − ∂L/∂q = Q + Fᵀλ`` (the paper's (3.3); ``Q`` optional non-conservative forces),
* ``f_q``, ``f_t``, and ``f_accel = ∂ḟ/∂q q̇ + ∂ḟ/∂t`` with ``ḟ = f_q q̇ + f_t``, so that
  ``f̈ = f_q q̈ + f_accel``,
* ``h_q``, ``h_v``, ``h_t``,
* the energy (Jacobi integral) ``E = q̇ᵀ ∂L/∂q̇ − L``,

or, for a spec that gives a kinematic map ``q̇ = T(q, t) v`` (quasi-velocities: a rigid
body's angular velocity beside its quaternion) and its Lagrangian in ``v``, the equations
in ``v`` (Hamel's form, below) and ``f_accel = (d/dt (f_q T)) v + d/dt f_t``,

and :meth:`System.source` writes them as a model file of ``@njit`` functions, each with
its common subexpressions eliminated, in the same shape as the hand-written scenes of
``kernels/``.  From the command line: ``stabdae generate SPEC.py -o kernels/NAME.py``.

Example
-------
>>> import sympy as sp
>>> from stabdae.symbolic import System, coordinates
>>> (x, y), (xd, yd) = coordinates("x y")
>>> g, l = sp.symbols("g l")
>>> system = System("pendulum", q=[x, y], v=[xd, yd],
...                 lagrangian=(xd**2 + yd**2) / 2 - g * y,
...                 holonomic=[x**2 + y**2 - l**2],
...                 params={g: 9.81, l: 1.0},
...                 reference_state=[0, -l, 1, 0])
>>> pieces = system.derive()
>>> pieces["f_accel"]
Matrix([[2*x_dot**2 + 2*y_dot**2]])
"""

from __future__ import annotations

import hashlib
import keyword
import re
import runpy
import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

try:
    import mpmath
    import sympy as sp
    from sympy.printing.pycode import PythonCodePrinter
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError(
        "stabdae.symbolic needs sympy: pip install 'stabdae[symbolic]'"
    ) from exc

from ._model import _PIECES
from ._version import __version__

__all__ = ["System", "SymbolicError", "coordinates", "t", "generate", "load_spec"]

#: the time symbol specs use by default
t = sp.Symbol("t")

#: names the generated functions use for their own arguments and modules
_RESERVED = {"t", "q", "v", "p", "out", "math", "np", "njit", "stabdae", "simdmath", "model",
             "reference_state", "mass", "forces", "f", "f_q", "f_t", "f_accel", "h",
             "h_q", "h_v", "h_t", "energy", "kinematics"}  # fmt: skip
_WIDTH = 100
_SPACED = re.compile(r"\s*((?<!\*)\*(?!\*)|/)\s*")


class SymbolicError(ValueError):
    """A spec that cannot become a model (wrong symbols, velocity-dependent mass, …)."""


def coordinates(names: str | Sequence[str], velocity_suffix: str = "_dot"):
    """Coordinate symbols and their velocity symbols.

    Parameters
    ----------
    names : str or sequence of str
        ``"x y z"`` or ``["x", "y", "z"]``.
    velocity_suffix : str
        Appended to each name for the velocity symbol (``x_dot``).

    Returns
    -------
    q, v : tuple of sympy.Symbol
        The coordinates and the velocities, in the same order.
    """
    if isinstance(names, str):
        names = names.replace(",", " ").split()
    q = tuple(sp.Symbol(str(n)) for n in names)
    v = tuple(sp.Symbol(f"{n}{velocity_suffix}") for n in names)
    return q, v


class System:
    """A constrained Lagrangian system given symbolically.

    Parameters
    ----------
    name : str
        The model's name.
    q, v : sequence of sympy.Symbol, length n
        Generalized coordinates and their velocities (see :func:`coordinates`).
    lagrangian : sympy expression
        ``L(q, v, t)``; its Hessian in ``v`` must not depend on ``v``.
    holonomic : sequence of sympy expressions, optional
        ``f(q, t) = 0`` (m entries); no velocities.
    nonholonomic : sequence of sympy expressions, optional
        ``h(q, v, t) = 0`` (k entries).
    params : mapping of sympy.Symbol (or str) to float
        Physical parameters with default values, in the order of the vector ``p``.
    reference_state : sequence of 2n expressions in the parameters
        A consistent state ``x* = (q*, v*)`` at ``t0``.
    forces : sequence of n sympy expressions, optional
        Non-conservative generalized forces ``Q(q, v, t)`` (default none); with a
        kinematic map, those conjugate to ``v`` (a body's torque in its body frame).
    kinematics : n × n sympy matrix of (q, t), optional
        A kinematic map ``q̇ = T(q, t) v``: ``v`` are then quasi-velocities and the
        Lagrangian is written in them, ``L*(q, v, t) = L(q, T v, t)``.  The equations
        of motion in ``v`` are Hamel's: with ``W = T⁻¹`` and ``p* = ∂L*/∂v``,
        ``d/dt p*_k + Σ_{i,r,j} T_ik p*_r (∂W_ri/∂q_j − ∂W_rj/∂q_i) q̇_j
        + Σ_{i,r} T_ik p*_r ∂W_ri/∂t − Σ_i T_ik ∂L*/∂q_i = Q_k + (Fᵀλ)_k`` (the Lagrange
        equations in ``q`` multiplied by ``Tᵀ``), so that ``γ`` holds the gyroscopic
        terms.  The generated model declares ``kinematics`` and names its velocities
        after ``v``.
    energy : sympy expression, bool, default True
        ``True`` derives the Jacobi integral ``vᵀ ∂L/∂v − L``; an expression is used as
        given; ``False`` omits the energy function.
    t : sympy.Symbol, default :data:`stabdae.symbolic.t`
        The time symbol used in the expressions.
    coordinate_units : sequence of str, optional
        UDUNITS units of the coordinates, passed to :class:`stabdae.Model`.
    constraint_units : sequence of str, optional
        UDUNITS units of the holonomic, then the nonholonomic constraint functions, passed
        to :class:`stabdae.Model`.
    energy_units : str, optional
        UDUNITS units of the energy function, passed to :class:`stabdae.Model`.
    t0 : float, default 0.0
        Time at which the reference state is consistent.
    description : str, optional
        One paragraph or more for the generated file's docstring.
    simplify : bool, default True
        Apply ``sympy.simplify`` to every derived entry (slow for large systems; with
        ``False`` entries are only expanded, or kept as derived).
    expand : bool, default False
        ``False`` keeps the derivatives as the product and chain rules build them, and the
        generated code shares their common subexpressions.  ``True`` expands every derived
        entry into a sum of products, which for a mechanism in minimal coordinates, whose
        constraints are nested functions of the angles, grows as a power of the
        coordinates (a chain of 5 links whose tip is held at a distance from a pin: 7309
        operations in 97 s expanded, against 654 in under a second kept; the Whipple
        bicycle in 8 coordinates: 409,233 operations in six minutes, against 6569 in
        6 s).  On the shipped specs the kept form never has more operations (andrews: 315
        against 463).  Entries that are zero only after cancelling are found by
        evaluating them in 50-digit arithmetic at random states and parameters, and left
        out.

    Raises
    ------
    SymbolicError
        When an expression uses a symbol that is neither a coordinate, a velocity, time nor
        a parameter, when counts disagree, when ``f`` contains velocities, or when the mass
        matrix depends on the velocities.  Messages name the offending piece and symbol.
    """

    def __init__(
        self,
        name: str,
        *,
        q: Sequence,
        v: Sequence,
        lagrangian,
        holonomic: Sequence = (),
        nonholonomic: Sequence = (),
        params: Mapping | None = None,
        reference_state: Sequence,
        forces: Sequence | None = None,
        kinematics=None,
        energy=True,
        t: sp.Symbol = t,
        coordinate_units: Sequence[str] | None = None,
        constraint_units: Sequence[str] | None = None,
        energy_units: str | None = None,
        t0: float = 0.0,
        description: str = "",
        simplify: bool = True,
        expand: bool = False,
    ):
        self.name = str(name)
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", self.name):
            raise SymbolicError(f"System: name must be an identifier, got {name!r}")
        self.q = tuple(_as_symbol(s, "q") for s in q)
        self.v = tuple(_as_symbol(s, "v") for s in v)
        self.n = len(self.q)
        if self.n < 1 or len(self.v) != self.n:
            raise SymbolicError(
                f"System {self.name!r}: q and v must have the same length ≥ 1, got "
                f"{len(self.q)} coordinates and {len(self.v)} velocities"
            )
        self.t = t
        self.params = {
            (sp.Symbol(k) if isinstance(k, str) else k): float(val)
            for k, val in (params or {}).items()
        }
        self.L = sp.sympify(lagrangian)
        self.f = sp.Matrix([sp.sympify(e) for e in holonomic])
        self.h = sp.Matrix([sp.sympify(e) for e in nonholonomic])
        self.m, self.k = len(self.f), len(self.h)
        if self.m + self.k < 1:
            raise SymbolicError(f"System {self.name!r}: no constraints (holonomic and "
                                "nonholonomic are both empty)")  # fmt: skip
        self.Q = sp.Matrix([sp.sympify(e) for e in forces]) if forces is not None else None
        if self.Q is not None and len(self.Q) != self.n:
            raise SymbolicError(f"System {self.name!r}: forces must have n = {self.n} "
                                f"entries, got {len(self.Q)}")  # fmt: skip
        self.T = None if kinematics is None else sp.Matrix(kinematics)
        if self.T is not None and self.T.shape != (self.n, self.n):
            raise SymbolicError(f"System {self.name!r}: kinematics must be an n × n = "
                                f"{self.n} × {self.n} matrix, got {self.T.shape}")
        self.x_ref = [sp.sympify(e) for e in reference_state]
        if len(self.x_ref) != 2 * self.n:
            raise SymbolicError(
                f"System {self.name!r}: reference_state must have 2n = {2 * self.n} entries "
                f"(q then v), got {len(self.x_ref)}"
            )
        self.energy_spec = energy
        self.coordinate_units = list(coordinate_units) if coordinate_units else None
        self.constraint_units = list(constraint_units) if constraint_units else None
        self.energy_units = None if energy_units is None else str(energy_units)
        self.t0 = float(t0)
        self.description = textwrap.dedent(description).strip()
        self.simplify = bool(simplify)
        self.expand = bool(expand)
        #: operations of each generated function after common subexpressions (filled by
        #: :meth:`source`)
        self.operations: dict[str, int] = {}
        self._validate_symbols()
        self._derived = None

    # ------------------------------------------------------------------ validation
    def _validate_symbols(self) -> None:
        names = [str(s) for s in (*self.q, *self.v, *self.params, self.t)]
        dup = sorted({x for x in names if names.count(x) > 1})
        if dup:
            raise SymbolicError(f"System {self.name!r}: symbol names used twice among "
                                f"coordinates, velocities, parameters and time: {dup}")  # fmt: skip
        q_set, v_set, p_set = set(self.q), set(self.v), set(self.params)
        allowed = q_set | v_set | p_set | {self.t}

        def check(expr, where, allow):
            bad = sorted(str(s) for s in expr.free_symbols - allow)
            if bad:
                raise SymbolicError(
                    f"System {self.name!r}: {where} uses {', '.join(map(repr, bad))}, which "
                    f"is not among the symbols it may depend on ({_names(allow)})"
                )

        check(self.L, "lagrangian", allowed)
        for i, e in enumerate(self.f):
            check(e, f"holonomic[{i}] (f(q, t) must not contain velocities)",
                  q_set | p_set | {self.t})  # fmt: skip
        for i, e in enumerate(self.h):
            check(e, f"nonholonomic[{i}]", allowed)
        if self.Q is not None:
            for i, e in enumerate(self.Q):
                check(e, f"forces[{i}]", allowed)
        for i, e in enumerate(self.x_ref):
            check(e, f"reference_state[{i}] (parameters only)", p_set)
        if self.T is not None:
            for (i, j), e in np.ndenumerate(np.array(self.T.tolist(), dtype=object)):
                check(sp.sympify(e), f"kinematics[{i}, {j}] (T(q, t): no velocities)",
                      q_set | p_set | {self.t})
        if self.energy_spec not in (True, False):
            check(sp.sympify(self.energy_spec), "energy", allowed)

    # ------------------------------------------------------------------ derivation
    def _clean(self, expr):
        if self.expand:
            expr = sp.expand(expr)
        if expr == 0 or not self.simplify:
            return expr
        return sp.simplify(expr)

    def derive(self) -> dict[str, sp.Matrix | sp.Expr]:
        """Every piece of the model as sympy matrices (absent pieces left out).

        Returns
        -------
        dict
            Keys among ``mass, forces, f, f_q, f_t, f_accel, h, h_q, h_v, h_t, energy``;
            values are ``sympy.Matrix`` (n×n, n, m, m×n, …) and an expression for energy.
            ``mass`` is absent when it is the identity, ``f_t``/``h_t`` when zero.
        """
        if self._derived is not None:
            return self._derived
        q, v, t_ = sp.Matrix(self.q), sp.Matrix(self.v), self.t
        clean = self._clean
        p_v = sp.Matrix([sp.diff(self.L, s) for s in self.v])  # ∂L/∂v
        M = self._cancel(p_v.jacobian(v).applyfunc(clean))
        moving = sorted({str(s) for s in M.free_symbols & set(self.v)})
        if moving:
            raise SymbolicError(
                f"System {self.name!r}: the mass matrix ∂²L/∂v² depends on the velocities "
                f"{moving}; stabdae models need M(q, t) (L quadratic in the velocities)"
            )
        # d/dt ∂L/∂v = M v̇ + (∂p_v/∂q) v + ∂p_v/∂t;  γ is everything but M v̇, minus ∂L/∂q.
        # The velocity terms are one derivative along (v, 1) per entry rather than a row of
        # n partial derivatives dotted with v: the same values, and the nested sums of a
        # Lagrangian in joint angles stay sums instead of growing a term per coordinate.
        L_q = sp.Matrix([sp.diff(self.L, s) for s in self.q])
        if self.T is None:
            gamma = self._along(p_v) - L_q
        else:
            gamma = self._hamel(p_v, L_q)
        if self.Q is not None:
            gamma -= self.Q
        out: dict = {}
        if M != sp.eye(self.n):
            out["mass"] = M
        out["forces"] = gamma.applyfunc(clean)
        if self.m:
            f_q = self.f.jacobian(q)
            f_t = self.f.diff(t_)
            out["f"] = self.f.applyfunc(clean)
            out["f_q"] = self._cancel(f_q.applyfunc(clean))
            f_t = self._cancel(f_t.applyfunc(clean))
            if any(e != 0 for e in f_t):
                out["f_t"] = f_t
            if self.T is None:
                # (∂ḟ/∂q) v + ∂ḟ/∂t is f's second derivative along (v, 1)
                out["f_accel"] = self._along(self.f, order=2).applyfunc(clean)
            else:
                # ḟ = f_q T v + f_t, then its derivative along (T v, 1) at fixed v
                out["f_accel"] = self._along(self._along(self.f)).applyfunc(clean)
        if self.k:
            out["h"] = self.h.applyfunc(clean)
            out["h_q"] = self._cancel(self.h.jacobian(q).applyfunc(clean))
            out["h_v"] = self._cancel(self.h.jacobian(v).applyfunc(clean))
            h_t = self._cancel(self.h.diff(t_).applyfunc(clean))
            if any(e != 0 for e in h_t):
                out["h_t"] = h_t
        if self.T is not None:
            out["kinematics"] = self._cancel(self.T.applyfunc(clean))
        if self.energy_spec is True:
            # (with a kinematic map the same integral: vᵀ ∂L*/∂v = q̇ᵀ ∂L/∂q̇)
            # vᵀ ∂L/∂v is the derivative of L(q, (1 + ε) v, t) at ε = 0: one derivative of
            # L instead of n, sharing L's own subexpressions
            eps = sp.Dummy("eps")
            scaled = self.L.xreplace({s: (1 + eps) * s for s in self.v})
            out["energy"] = clean(sp.diff(scaled, eps).xreplace({eps: 0}) - self.L)
        elif self.energy_spec is not False:
            out["energy"] = clean(sp.sympify(self.energy_spec))
        self._derived = out
        return out

    def _cancel(self, matrix: sp.Matrix, points: int = 3, digits: int = 50) -> sp.Matrix:
        """``matrix`` with its entries that are zero only after cancelling set to 0.

        With ``expand=True`` the expansion has found the algebraic cancellations, and
        nothing is tested.  Kept as the derivative rules build them, an entry that cancels
        (a rolling wheel's slip, which does not depend on the frame's pitch,
        differentiated by the pitch) would be computed to roundoff, and a model's
        structural zeros (its sparsity, which the kernels exploit) would then hold only at
        some states.  An entry is zero when it evaluates to less than 1e-30 in 50-digit
        arithmetic at ``points`` random states, times and parameters (each parameter within
        20 % of its value, or near 1 where it is 0): a randomized identity test, since an
        analytic entry that is not identically zero vanishes only on a set of measure
        zero.  Where an entry is undefined at a drawn state, nothing is set to zero."""
        if self.expand:
            return matrix
        where = [i for i, e in enumerate(matrix) if e != 0]
        if not where:
            return matrix
        symbols = [*self.q, *self.v, self.t, *self.params]
        evaluate = sp.lambdify(symbols, [matrix[i] for i in where], modules="mpmath", cse=True)
        rng = np.random.default_rng(20261127)
        zero = np.ones(len(where), dtype=bool)
        with mpmath.workdps(digits):
            for _ in range(points):
                values = [mpmath.mpf(float(u)) for u in rng.uniform(-1.0, 1.0, 2 * self.n + 1)]
                for value in self.params.values():
                    spread = 1.0 + 0.2 * rng.uniform(-1.0, 1.0)
                    values.append(mpmath.mpf(value * spread if value else spread))
                try:
                    got = evaluate(*values)
                except (ArithmeticError, ValueError, TypeError):
                    return matrix  # a state where an entry is undefined: decide nothing
                zero &= np.array([abs(g) < mpmath.mpf(10) ** -30 for g in got])
        if not zero.any():
            return matrix
        out = matrix.copy()
        for i, z in zip(where, zero):
            if z:
                out[i] = sp.S.Zero
        return out

    def _qdot(self) -> list:
        """``q̇`` in the velocities: ``v``, or ``T v`` with a kinematic map."""
        if self.T is None:
            return list(self.v)
        return list(self.T * sp.Matrix(self.v))

    def _hamel(self, p_v: sp.Matrix, L_q: sp.Matrix) -> sp.Matrix:
        """γ of the equations in quasi-velocities (the ``kinematics`` parameter): the
        derivative of ``p* = ∂L*/∂v`` along the motion without ``M v̇``, the Hamel terms
        of ``W = T⁻¹``, minus ``Tᵀ ∂L*/∂q``."""
        T, n = self.T, self.n
        W = T.inv().applyfunc(sp.simplify if self.simplify else sp.expand)
        qdot = self._qdot()
        hamel = []
        for k in range(n):
            term = sp.S.Zero
            for i in range(n):
                if T[i, k] == 0:
                    continue
                inner = sp.S.Zero
                for r in range(n):
                    if p_v[r] == 0:
                        continue
                    rot = sum(((sp.diff(W[r, i], self.q[j]) - sp.diff(W[r, j], self.q[i]))
                               * qdot[j] for j in range(n)), sp.S.Zero)
                    inner += p_v[r] * (rot + sp.diff(W[r, i], self.t))
                term += T[i, k] * inner
            hamel.append(term)
        return self._along(p_v) + sp.Matrix(hamel) - T.T * L_q

    def _along(self, expr: sp.Matrix, order: int = 1) -> sp.Matrix:
        """The ``order``-th derivative of ``expr(q, ·, t)`` along ``(q̇, 1)``: entries of
        ``d^k/dε^k expr(q + ε q̇, ·, t + ε)`` at ε = 0 (the velocities left in ``expr`` are
        held; ``q̇ = v``, or ``T v`` at the base point with a kinematic map)."""
        eps = sp.Dummy("eps")
        shift = {s: s + eps * w for s, w in zip(self.q, self._qdot())}
        shift[self.t] = self.t + eps
        return expr.xreplace(shift).applyfunc(lambda e: sp.diff(e, eps, order).xreplace({eps: 0}))

    # ------------------------------------------------------------------ code
    def source(self, spec: str | Path | None = None) -> str:
        """The model file's text.

        Parameters
        ----------
        spec : path, optional
            The spec file this system came from; its name and SHA-256 go into the header
            so that a stale generated file can be detected.
        """
        pieces = self.derive()
        names = _LocalNames(self)
        code = []
        for piece, expr in pieces.items():
            text, self.operations[piece] = _function(piece, expr, names, self.T is not None)
            code.append(text)
        code.append(self._reference_function(names))
        imports = _IMPORTS
        if not any(re.search(r"(?<![.\w])math\.", c) for c in code):
            imports = imports.replace("import math\n\n", "")
        if not any("simdmath." in c for c in code):
            imports = imports.replace("\nfrom stabdae import simdmath", "")
        params = "\n".join(textwrap.wrap("p = [" + ", ".join(str(s) for s in self.params) + "]",
                                         _WIDTH - 2, initial_indent="# ",
                                         subsequent_indent="#     "))  # fmt: skip
        blocks = [self._header(spec), imports + "\n\n" + params, *code,
                  self._model_call(pieces)]  # fmt: skip
        return "\n\n\n".join(blocks).rstrip() + "\n"

    def write(self, path: str | Path, spec: str | Path | None = None) -> Path:
        """Write :meth:`source` to ``path`` (parent folders created)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        text = self.source(spec)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(path)
        return path

    def _header(self, spec) -> str:
        lines = [self.description or f"{self.name} (generated model)", ""]
        lines += ["    L = " + _wrap_plain(sp.sstr(self.L), 8)]
        for i, e in enumerate(self.f):
            lines.append(f"    f[{i}] = " + _wrap_plain(sp.sstr(e), 8) + " = 0")
        for i, e in enumerate(self.h):
            lines.append(f"    h[{i}] = " + _wrap_plain(sp.sstr(e), 8) + " = 0")
        if self.Q is not None:
            lines.append("    Q = " + _wrap_plain(sp.sstr(list(self.Q)), 8))
        lines.append("")
        how = f"stabdae {__version__} (stabdae.symbolic), sympy {sp.__version__}"
        if spec is not None:
            spec = Path(spec)
            shown = spec.as_posix() if not spec.is_absolute() else spec.name
            digest = hashlib.sha256(spec.read_bytes()).hexdigest()
            lines.append(f"Generated by `stabdae generate {shown}`")
            lines.append(f"with {how}.  Spec SHA-256: {digest[:16]}")
        else:
            lines.append(f"Generated by {how}.")
        lines.append("Edit the spec and regenerate rather than editing this file.")
        body = "\n".join(lines).replace('"""', "'''").replace("\\", "\\\\")
        return f'"""{body}\n"""'

    def _reference_function(self, names: _LocalNames) -> str:
        entries = [names.code(e) for e in self.x_ref]
        used = set().union(*(e.free_symbols for e in self.x_ref)) if self.x_ref else set()
        body = names.unpack(used, q=False, v=False) + [
            "return np.array(",
            *_wrap_list(entries, 8),
            "    dtype=np.float64,",
            ")",
        ]
        return "def reference_state(p):\n" + "\n".join("    " + b for b in body)

    def _model_call(self, pieces: dict) -> str:
        args = [_quote(self.name), f"n={self.n}"]
        if self.m:
            args.append(f"m={self.m}")
        if self.k:
            args.append(f"k={self.k}")
        entries = [f"{_quote(str(s))}: {val!r}" for s, val in self.params.items()]
        params = "params={" + ", ".join(entries) + "}"
        if len(params) + 5 > _WIDTH:
            params = "params={\n" + "".join(f"        {e},\n" for e in entries) + "    }"
        args.append(params)
        args.append("reference_state=reference_state")
        args.append("coordinates=[" + ", ".join(_quote(str(s)) for s in self.q) + "]")
        if self.T is not None:  # quasi-velocities: named as the spec names them
            args.append("velocities=[" + ", ".join(_quote(str(s)) for s in self.v) + "]")
        for name in ("coordinate_units", "constraint_units"):
            units = getattr(self, name)
            if units:
                args.append(f"{name}=[" + ", ".join(map(_quote, units)) + "]")
        if self.energy_units is not None:  # (also without an energy: λ is energy/constraint)
            args.append(f"energy_units={_quote(self.energy_units)}")
        args += [f"{piece}={piece}" for piece in pieces]
        if self.t0:
            args.append(f"t0={self.t0!r}")
        args.append("description=__doc__")
        return "model = stabdae.Model(\n" + "".join(f"    {a},\n" for a in args) + ")"


_IMPORTS = ("import math\n\nimport numpy as np\nfrom numba import njit\n\nimport stabdae\n"
            "from stabdae import simdmath")

def _signature(piece: str) -> str:
    """Arguments of a generated function, from the model's table of pieces."""
    if piece == "energy":
        return "t, q, v, p"
    return ", ".join(_PIECES[piece][0]) + ", out"


def _is_matrix(piece: str) -> bool:
    return len(_PIECES[piece][1](1, 1, 1)) == 2

_COMMENTS = {
    "mass": "M = ∂²L/∂v²",
    "forces": "γ = (∂²L/∂v∂q) v + ∂²L/∂v∂t − ∂L/∂q − Q, so that M v̇ = Fᵀλ − γ  (3.3)",
    "f_accel": "f̈ = f_q v̇ + f_accel:  ∂ḟ/∂q v + ∂ḟ/∂t with ḟ = f_q v + f_t",
    "energy": "Jacobi integral vᵀ ∂L/∂v − L",
}
#: the same for a model with a kinematic map q̇ = T v
_KINEMATIC_COMMENTS = {
    **_COMMENTS,
    "forces": "γ: Hamel's equations in v, so that M v̇ = Fᵀλ − γ with q̇ = T v",
    "f_accel": "f̈ = f_q T v̇ + f_accel:  (d/dt (f_q T)) v + d/dt f_t along q̇ = T v",
    "kinematics": "T of q̇ = T v",
}


class _Printer(PythonCodePrinter):
    """Python code for numba: ``math.`` functions, floats written as floats."""

    def __init__(self, rename: dict):
        super().__init__({"fully_qualified_modules": True, "standard": "python3"})
        self._rename = rename

    def _print_Symbol(self, expr):
        return self._rename.get(expr, super()._print_Symbol(expr))

    def _print_Integer(self, expr):
        return f"{int(expr)}.0"

    def _print_Rational(self, expr):
        return repr(float(expr))  # correctly rounded, as p.0 / q.0 would be

    def _print_Float(self, expr):
        return repr(float(expr))

    # the sine and cosine that vectorize with the ensemble kernel's member loop (a call to
    # the C library's would run one lane at a time)
    def _print_sin(self, expr):
        return f"simdmath.sin({self._print(expr.args[0])})"

    def _print_cos(self, expr):
        return f"simdmath.cos({self._print(expr.args[0])})"

    def _print_Pow(self, expr, rational=False):
        base, e = expr.as_base_exp()
        if not e.is_Integer:
            return super()._print_Pow(expr, rational=rational)
        k = int(e)
        prec = sp.printing.precedence.PRECEDENCE
        b = self.parenthesize(base, prec["Mul"] + 1 if abs(k) <= 3 else prec["Pow"] + 1)
        # x*x, x*x*x: exact and fast, as in the hand-written scenes; integer powers beyond
        # (parenthesized, since the caller judges precedence as for a power: x/(y*y))
        power = "(" + " * ".join([b] * abs(k)) + ")" if abs(k) <= 3 else f"{b}**{abs(k)}"
        if k > 0:
            return power
        return "(1.0 / " + (b if abs(k) == 1 else power) + ")"


class _LocalNames:
    """Local variable names for the symbols, and unpacking lines for a function."""

    def __init__(self, system: System):
        self.system = system
        taken = set(_RESERVED)
        self.rename: dict = {system.t: "t"}
        self.source: dict = {}
        for kind, symbols in (("q", system.q), ("v", system.v), ("p", system.params)):
            for i, s in enumerate(symbols):
                name = str(s)
                if (not name.isidentifier() or not name.isascii() or keyword.iskeyword(name)
                        or name in taken):  # fmt: skip
                    name = f"{kind}{i}_"
                taken.add(name)
                self.rename[s] = name
                self.source[s] = f"{kind}[{i}]"
        self.taken = taken
        self.printer = _Printer(self.rename)

    def fresh(self, base: str) -> str:
        """A local name of none of the symbols (``base``, else ``base_``, …)."""
        name = base
        while name in self.taken or name in _RESERVED:
            name += "_"
        self.taken.add(name)
        return name

    def cse_symbols(self):
        prefix = "e"
        while any(n.startswith(prefix) and n[len(prefix):].isdigit() for n in self.taken):
            prefix += "_"
        return sp.numbered_symbols(prefix)

    def code(self, expr) -> str:
        expr = sp.sympify(expr)
        if expr.is_Number:
            return repr(float(expr))
        # fractions as floats (0.5*x, not (1/2)*x), then spaces around * and / as in the
        # hand-written scenes
        expr = expr.replace(
            lambda e: e.is_Mul and e.args[0].is_Rational and not e.args[0].is_Integer,
            lambda e: sp.Float(e.args[0], 17) * sp.Mul(*e.args[1:]),
        )
        text = self.printer.doprint(expr)
        return _SPACED.sub(lambda m: f" {m.group(1)} ", text)

    def unpack(self, used, q=True, v=True) -> list[str]:
        lines = []
        for kind, symbols in (("q", self.system.q), ("v", self.system.v),
                              ("p", self.system.params)):  # fmt: skip
            if (kind == "q" and not q) or (kind == "v" and not v):
                continue
            chosen = [s for s in symbols if s in used]
            if not chosen:
                continue
            lhs = ", ".join(self.rename[s] for s in chosen)
            rhs = ", ".join(self.source[s] for s in chosen)
            line = f"{lhs} = {rhs}"
            if len(line) + 4 > _WIDTH:
                for s in chosen:
                    lines.append(f"{self.rename[s]} = {self.source[s]}")
            else:
                lines.append(line)
        return lines


def _function(piece: str, expr, names: _LocalNames, kinematic: bool = False) -> tuple[str, int]:
    """One ``@njit`` function: unpacking, common subexpressions, then the outputs; and its
    number of operations (``sympy.count_ops`` of the subexpressions and the outputs)."""
    if piece == "energy":
        targets, entries = [None], [expr]
    else:
        M = expr
        targets, entries = [], []
        matrix = _is_matrix(piece)
        for i in range(M.shape[0]):
            for j in range(M.shape[1]):
                if piece == "mass" and j < i:
                    continue  # symmetric: the lower triangle is copied below
                targets.append(f"out[{i}, {j}]" if matrix else f"out[{i}]")
                entries.append(M[i, j])
    symbols = names.cse_symbols()
    nonzero = [(tg, e) for tg, e in zip(targets, entries) if e != 0]
    replacements, reduced = sp.cse([e for _, e in nonzero], symbols=symbols, order="canonical")
    used = set()
    for e in [*reduced, *(r for _, r in replacements)]:
        used |= e.free_symbols
    body = names.unpack(used)
    for sym, value in replacements:
        names.rename[sym] = str(sym)  # the printer reads the same mapping
        body.extend(_assignments(str(sym), names.code(value)))
    reduced_of = dict(zip([tg for tg, _ in nonzero], reduced))
    if piece == "energy":
        code = names.code(reduced[0])
        if len(_split_top(code)) > _TERMS:
            total = names.fresh("total")
            body.extend(_assignments(total, code))
            code = total
        body.append(_assign("return", code, op=""))
    else:
        zeros = any(e == 0 for e in entries)
        if zeros and len(targets) > 1 and matrix:
            body.append("out[:, :] = 0.0")
            targets = [tg for tg in targets if tg in reduced_of]
        for tg in targets:
            body.extend(_assignments(tg, names.code(reduced_of[tg]) if tg in reduced_of
                                     else "0.0"))  # fmt: skip
        if piece == "mass":
            n = M.shape[0]
            for i in range(n):
                for j in range(i):
                    if M[j, i] != 0 or not zeros:
                        body.append(f"out[{i}, {j}] = out[{j}, {i}]")
    comments = _KINEMATIC_COMMENTS if kinematic else _COMMENTS
    comment = [f"# {comments[piece]}"] if piece in comments else []
    lines = comment + body
    ops = sum(sp.count_ops(e) for e in [*reduced, *(r for _, r in replacements)])
    return (f"@njit(cache=True)\ndef {piece}({_signature(piece)}):\n"
            + "\n".join("    " + ln for ln in "\n".join(lines).splitlines()), int(ops))  # fmt: skip


#: top-level terms of a sum per statement: an expanded derivation's sums run to thousands
#: of terms, an expression as deep, past what Python compiles at its default recursion
#: limit (a loaded model file is compiled by Python first)
_TERMS = 64


def _assignments(target: str, code: str) -> list[str]:
    """``target = code``, a long sum as partial sums into ``target`` of at most
    :data:`_TERMS` terms each, in the order written (``t = a + b``, ``t = t - c``): the
    same operations in the same order, so the same numbers."""
    parts = _split_top(code)
    if len(parts) <= _TERMS:
        return [_assign(target, code)]
    lines = [_assign(target, "".join(parts[:_TERMS]))]
    for k in range(_TERMS, len(parts), _TERMS):
        lines.append(_assign(target, target + "".join(parts[k:k + _TERMS])))
    return lines


def _assign(target: str, code: str, op: str = " =") -> str:
    """``target = code`` within the line width, broken inside parentheses if needed."""
    head = f"{target}{op} "
    if len(head) + len(code) + 4 <= _WIDTH:
        return head + code
    inner = "\n".join("    " + ln for ln in _break(code, 8))
    return f"{head}(\n{inner}\n)"


def _break(code: str, indent: int) -> list[str]:
    """Lines of ``code`` (inside parentheses, so newlines are free) that fit the width:
    split at top-level ``+``/``−``, then ``*``/``/``, then inside a call's parentheses."""
    room = _WIDTH - indent
    if len(code) <= room:
        return [code]
    for ops in ((" + ", " - "), (" * ", " / ")):
        parts = _split_top(code, ops)
        if len(parts) > 1:
            lines, cur = [], ""
            for part in parts:
                if cur and len(cur) + len(part) > room:
                    lines.append(cur)
                    cur = part.lstrip()
                else:
                    cur += part
                if len(cur) > room:  # one long operand: break it on its own lines
                    op = ""
                    for o in ops:
                        if cur.startswith(o.strip() + " "):
                            op, cur = o.strip() + " ", cur[len(o.strip()) + 1 :]
                    sub = _break(cur, indent + len(op))
                    lines.append(op + sub[0])
                    lines.extend(" " * len(op) + ln for ln in sub[1:])
                    cur = ""
            if cur:
                lines.append(cur)
            return lines
    opening = code.find("(")
    if opening >= 0 and code.endswith(")") and _closing(code, opening) == len(code) - 1:
        inner = _break(code[opening + 1 : -1], indent + 4)
        return [code[: opening + 1], *("    " + ln for ln in inner), ")"]
    return [code]


def _closing(code: str, opening: int) -> int:
    depth = 0
    for i in range(opening, len(code)):
        if code[i] == "(":
            depth += 1
        elif code[i] == ")":
            depth -= 1
            if depth == 0:
                return i
    return -1


def _split_top(code: str, ops=(" + ", " - ")) -> list[str]:
    """Split before the operators in ``ops`` that sit outside every parenthesis."""
    parts, depth, start, i = [], 0, 0, 0
    while i < len(code):
        ch = code[i]
        if ch in "([":
            depth += 1
        elif ch in ")]":
            depth -= 1
        elif depth == 0 and code.startswith(ops, i) and i > start:
            parts.append(code[start:i])
            start = i
            i += 3
            continue
        i += 1
    parts.append(code[start:])
    return parts


def _wrap_list(entries: list[str], indent: int) -> list[str]:
    lines, cur = [], "["
    for i, e in enumerate(entries):
        item = e + ("," if i < len(entries) - 1 else "],")
        if len(cur) + len(item) + indent + 1 > _WIDTH and cur != "[":
            lines.append(cur.rstrip())
            cur = " "
        cur += item + " "
    lines.append(cur.rstrip())
    return ["    " + ln for ln in lines]


def _wrap_plain(text: str, indent: int) -> str:
    return ("\n" + " " * indent).join(textwrap.wrap(text, _WIDTH - indent - 4)) or text


def _as_symbol(s, what):
    s = sp.Symbol(s) if isinstance(s, str) else s
    if not isinstance(s, sp.Symbol):
        raise SymbolicError(f"System: {what} entries must be sympy Symbols, got {s!r}")
    return s


def _quote(text: str) -> str:
    """A string literal in double quotes, as the hand-written scenes write them."""
    text = str(text)
    return f'"{text}"' if '"' not in text and "\\" not in text else repr(text)


def _names(symbols) -> str:
    return ", ".join(sorted(str(s) for s in symbols))


def load_spec(path: str | Path) -> System:
    """Run a spec file and return its :class:`System`.

    The file must define exactly one module-level ``System`` (by convention ``system``).
    """
    path = Path(path)
    if not path.is_file():
        raise SymbolicError(f"generate: no such spec file: {path}")
    try:
        namespace = runpy.run_path(str(path), run_name=f"stabdae_spec_{path.stem}")
    except SymbolicError:
        raise
    except Exception as exc:  # the spec's own error, in one line with its place
        from ._loading import file_error

        raise SymbolicError(f"generate: {file_error(path, exc)}") from exc
    found = {k: v for k, v in namespace.items() if isinstance(v, System)}
    if "system" in found:
        return found["system"]
    if len(found) != 1:
        raise SymbolicError(
            f"generate: {path} must define one stabdae.symbolic.System (named 'system'); "
            f"found {len(found)}" + (f": {sorted(found)}" if found else "")
        )
    return next(iter(found.values()))


def generate(spec: str | Path, output: str | Path) -> Path:
    """Derive the spec file's system and write the model file ``output``.

    Parameters
    ----------
    spec : path
        A Python file defining ``system = stabdae.symbolic.System(...)``.
    output : path
        Where to write the model file.

    Returns
    -------
    Path
        ``output``.
    """
    system = load_spec(spec)
    return system.write(output, spec=spec)
