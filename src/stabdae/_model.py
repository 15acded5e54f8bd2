"""The model interface: a constrained Lagrangian system as a set of ``@njit`` functions.

A model declares only the pieces its system has (the paper's §§1–3):

=========== ============================ ========= ==========================================
piece       signature                    ``out``   when
=========== ============================ ========= ==========================================
mass        ``mass(t, q, p, out)``       (n, n)    omit for identity mass
forces      ``forces(t, q, v, p, out)``  (n,)      always: γ of (3.3), ``M v̇ = Fᵀλ − γ``
f           ``f(t, q, p, out)``          (m,)      m > 0
f_q         ``f_q(t, q, p, out)``        (m, n)    m > 0
f_t         ``f_t(t, q, p, out)``        (m,)      time-dependent holonomic constraints only
f_accel     ``f_accel(t, q, v, p, out)`` (m,)      m > 0: ``(d/dt f_q) v + d/dt f_t``
h           ``h(t, q, v, p, out)``       (k,)      k > 0 nonholonomic constraints
h_q, h_v    ``(t, q, v, p, out)``        (k, n)    k > 0
h_t         ``h_t(t, q, v, p, out)``     (k,)      time-dependent nonholonomic only
kinematics  ``kinematics(t, q, p, out)`` (n, n)    quasi-velocities only: T of ``q̇ = T v``
energy      ``energy(t, q, v, p)``       float     optional, for drift diagnostics
=========== ============================ ========= ==========================================

Without ``kinematics`` the velocities are the coordinates' derivatives, ``q̇ = v``.  With
it they are quasi-velocities (a rigid body's angular velocity in its body frame beside a
unit quaternion, :mod:`stabdae.rigid`): ``q̇ = T(q, t) v``, ``mass`` and ``forces`` are
those of the equations written in ``v`` (``M v̇ = Fᵀλ − γ``, the gyroscopic terms in γ),
``f_q`` is still ``∂f/∂q`` and ``h_q`` ``∂h/∂q`` (the library takes F's holonomic rows as
``f_q T`` and the velocity products as ``h_q T v``), and ``f_accel`` is the derivative
of ``ḟ = f_q T v + f_t`` along the motion at fixed v: ``(d/dt (f_q T)) v + d/dt f_t``.
T is square, so the state stays ``x = (q, v)`` of size 2n; :meth:`Model.check` compares
``f_accel`` with finite differences of ``ḟ`` along ``q̇ = T v``.
"""

from __future__ import annotations

import functools
import hashlib
import math
import traceback
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numba
import numpy as np
from numba.core.dispatcher import Dispatcher

from ._check import check_model
from .engine.jit import is_njit, python_function

__all__ = ["Model", "ModelError"]


#: the longest parameter or output name: NetCDF names are at most 256 bytes, and a
#: name becomes variables and attributes with a prefix or suffix of its own
MAX_NAME = 200


class ModelError(ValueError):
    """A model's functions disagree with its declared sizes, or are not usable."""


#: piece -> (argument pattern, output shape as a function of (n, m, k), size that governs it)
_PIECES: dict[str, tuple[str, Callable[[int, int, int], tuple[int, ...]], str]] = {
    "mass": ("tqp", lambda n, m, k: (n, n), "n"),
    "forces": ("tqvp", lambda n, m, k: (n,), "n"),
    "f": ("tqp", lambda n, m, k: (m,), "m"),
    "f_q": ("tqp", lambda n, m, k: (m, n), "m, n"),
    "f_t": ("tqp", lambda n, m, k: (m,), "m"),
    "f_accel": ("tqvp", lambda n, m, k: (m,), "m"),
    "h": ("tqvp", lambda n, m, k: (k,), "k"),
    "h_q": ("tqvp", lambda n, m, k: (k, n), "k, n"),
    "h_v": ("tqvp", lambda n, m, k: (k, n), "k, n"),
    "h_t": ("tqvp", lambda n, m, k: (k,), "k"),
    "kinematics": ("tqp", lambda n, m, k: (n, n), "n"),
}
_UNSET = object()
#: pieces whose structural zeros the sparse right-hand side uses
_PATTERNED = ("mass", "f_q", "h_q", "h_v")
_HOLONOMIC = ("f", "f_q", "f_t", "f_accel")
_NONHOLONOMIC = ("h", "h_q", "h_v", "h_t")
_REQUIRED_IF_M = ("f", "f_q", "f_accel")
_REQUIRED_IF_K = ("h", "h_q", "h_v")

# Marks output entries a function did not write.  Arithmetic on model data does not land
# on this exact value, and unlike NaN it cannot be confused with a computed non-finite.
_UNWRITTEN = -7.0e307


class Model:
    """A constrained Lagrangian system written as ``@njit`` functions.

    Parameters
    ----------
    name : str
        Short identifier, used in messages and dataset attributes.
    n : int
        Number of generalized coordinates ``q``; the state is ``x = (q, v)`` of size 2n.
    m : int, default 0
        Number of holonomic constraints ``f(q, t) = 0``.
    k : int, default 0
        Number of nonholonomic constraints ``h(q, v, t) = 0``.
    params : mapping of str to float
        Named physical parameters, in the order of the vector ``p`` the functions read.
    reference_state : callable ``p -> x*`` or array of shape (2n,)
        A consistent state ``x* = (q*, v*)`` with ``g(x*, t0) = 0``.
    coordinates : sequence of str, optional
        Names of the n coordinates (default ``q0, q1, …``).
    coordinate_units : str or sequence of str, optional
        UDUNITS units of each coordinate (default ``"1"``); velocities get
        ``"<unit> s-1"``.
    constraint_units : str or sequence of str, optional
        UDUNITS units of each constraint function: the m entries of ``f``, then the k of
        ``h`` (default ``"1"``, dimensionless); ``ḟ`` gets ``"<unit> s-1"``.  Datasets
        label the residual components, and the norms of the residual, with them.
    energy_units : str, optional
        UDUNITS units of energy (default ``"1"``): of ``energy``, and the numerator of the
        multipliers' units (λ is energy per constraint unit).
    mass, forces, f, f_q, f_t, f_accel, h, h_q, h_v, h_t, energy : numba dispatchers
        The pieces of the model; see the module docstring for signatures.  ``forces`` is
        required; the constraint pieces follow from ``m`` and ``k``; ``mass`` (identity
        when absent), ``f_t``, ``h_t`` (scleronomic when absent) and ``energy`` are optional.
    kinematics : numba dispatcher ``kinematics(t, q, p, out)``, optional
        The kinematic map T (n × n) of quasi-velocities, ``q̇ = T(q, t) v`` (module
        docstring); absent, ``q̇ = v``.  A model with a map takes the dense right-hand side.
    velocities : sequence of str, optional
        Names of the n velocities (default ``<coordinate>_dot``; name them where they are
        quasi-velocities, ``omega_x`` beside a quaternion's ``p0 … p3``).
    velocity_units : str or sequence of str, optional
        Their UDUNITS units (default each coordinate's per second).
    t0 : float, default 0.0
        Time at which ``reference_state`` is consistent.
    sparsity : {"detect", "sparse", "dense"} or mapping, default "detect"
        The structural zeros of ``mass``, ``f_q``, ``h_q`` and ``h_v``: found by
        evaluating them at the reference state and four random states (``"detect"``; the
        sparse right-hand side is used where it saves at least half the work and the mass
        matrix is diagonal or absent), found and always used (``"sparse"``), or none
        (``"dense"``).  A mapping declares patterns (boolean arrays of ``out``'s shape)
        for some pieces; the others are found.  ``model.patterns`` holds them,
        :meth:`check` verifies them.
    outputs : numba dispatcher ``outputs(t, q, v, p, out)``, optional
        Derived quantities of a state (a steer angle from redundant coordinates, a contact
        force's direction): ``out`` of shape ``(len(output_names),)``.  Trajectories store
        each at every sample, as a variable of its own name; ensembles store each at every
        member's final state, ``<name>_final``.
    output_names : sequence of str
        Their names (identifiers, not those of a dataset's own variables); required with
        ``outputs``.
    output_units : str or sequence of str, optional
        Their UDUNITS units (default ``"1"``).
    scales : sequence of float, optional
        The typical size of each state component, shape (2n,) (or (n,): each coordinate's,
        its velocity's the same per second), in the coordinates' units: adaptive steps
        with ``atol="scales"`` take ``atol = rtol · scales``, one per component, and
        :meth:`check` draws its velocities at these sizes.

    Raises
    ------
    ModelError
        If a piece is missing, superfluous, not ``@njit``, writes an output of the wrong
        shape, or returns a non-finite value at the reference state, or if the reference
        state is not consistent.  Every message names the function, the shape expected and
        the shape got.

    Notes
    -----
    At construction every supplied function is called at the reference state as plain
    Python (so that an out-of-bounds write raises instead of corrupting memory; a function
    that does not run as Python is compiled with bounds checks instead), and the sparsity
    patterns are found the same way.  Numba compiles each function when it is first
    needed: by :meth:`evaluate` and :meth:`check` (a function that does not compile is
    named there) and inside the kernels, which compile their own copies of the pieces, so
    that loading a model of thousands of operations takes a second, not the minutes its
    functions would take to compile twice.  Derivatives are not checked here; use
    :meth:`check`.
    """

    def __init__(
        self,
        name: str,
        n: int,
        m: int = 0,
        k: int = 0,
        *,
        params: Mapping[str, float] | None = None,
        reference_state: Callable[[np.ndarray], np.ndarray] | np.ndarray,
        forces: Dispatcher,
        mass: Dispatcher | None = None,
        f: Dispatcher | None = None,
        f_q: Dispatcher | None = None,
        f_t: Dispatcher | None = None,
        f_accel: Dispatcher | None = None,
        h: Dispatcher | None = None,
        h_q: Dispatcher | None = None,
        h_v: Dispatcher | None = None,
        h_t: Dispatcher | None = None,
        energy: Dispatcher | None = None,
        kinematics: Dispatcher | None = None,
        velocities: Sequence[str] | None = None,
        velocity_units: Sequence[str] | str | None = None,
        coordinates: Sequence[str] | None = None,
        coordinate_units: Sequence[str] | str | None = None,
        constraint_units: Sequence[str] | str | None = None,
        energy_units: str = "1",
        t0: float = 0.0,
        description: str = "",
        sparsity: str | Mapping[str, np.ndarray] = "detect",
        scales: Sequence[float] | None = None,
        outputs: Dispatcher | None = None,
        output_names: Sequence[str] | None = None,
        output_units: Sequence[str] | str | None = None,
    ):
        self._args = {key: value for key, value in locals().items()
                      if key not in ("self", "__class__")}  # for :meth:`replace`
        self.name = str(name)
        self.n, self.m, self.k = (self._count(v, s) for v, s in ((n, "n"), (m, "m"), (k, "k")))
        if self.n < 1:
            raise ModelError(f"Model {self.name!r}: n must be at least 1, got {n}")
        if self.m + self.k < 1:
            raise ModelError(
                f"Model {self.name!r}: a model needs at least one constraint (m + k ≥ 1); "
                f"got m={m}, k={k}"
            )
        if self.m + self.k > self.n:
            raise ModelError(
                f"Model {self.name!r}: r = m + k = {self.m + self.k} constraints on n = {self.n} "
                "coordinates; the constraint matrix F (r×n) cannot have full row rank when r > n"
            )
        self.t0 = float(t0)
        self.description = description
        self.params = self._validate_params(params)
        self.coordinates = self._validate_names(coordinates)
        self.coordinate_units = self._validate_units(coordinate_units, self.n, "coordinate_units",
                                                     "n")
        self.velocities = (tuple(f"{c}_dot" for c in self.coordinates) if velocities is None
                           else self._validate_names(velocities, "velocities"))
        if set(self.velocities) & set(self.coordinates):
            raise ModelError(f"Model {self.name!r}: velocity names repeat coordinate names: "
                             f"{sorted(set(self.velocities) & set(self.coordinates))}")
        self.velocity_units = (
            tuple(_per_second(u) for u in self.coordinate_units) if velocity_units is None
            else self._validate_units(velocity_units, self.n, "velocity_units", "n"))
        self.constraint_units = self._validate_units(constraint_units, self.m + self.k,
                                                     "constraint_units", "r = m + k")
        self.energy_units = str(energy_units)
        self.scales = self._validate_scales(scales)

        given = dict(
            mass=mass, forces=forces, f=f, f_q=f_q, f_t=f_t, f_accel=f_accel,
            h=h, h_q=h_q, h_v=h_v, h_t=h_t, kinematics=kinematics,
        )  # fmt: skip
        self._check_presence(given)
        self.functions: dict[str, Dispatcher] = {}
        for piece, fn in given.items():
            if fn is not None:
                self.functions[piece] = self._require_njit(piece, fn)
        self.energy = self._require_njit("energy", energy) if energy is not None else None
        self.outputs = self._require_njit("outputs", outputs) if outputs is not None else None
        self.output_names, self.output_units = self._validate_outputs(
            outputs, output_names, output_units)  # fmt: skip
        self._derived_loop = None

        p = self.default_params()
        self._reference = reference_state
        x_ref = self.reference_state(p)
        outputs = self._probe_all(x_ref, p)
        self._check_consistent(x_ref, p)
        self.patterns = self._sparsity(sparsity, x_ref, p, outputs)
        if self.kinematic and self._sparsity_mode == "sparse":
            raise ModelError(f"Model {self.name!r}: sparsity='sparse' is not available with a "
                             "kinematic map (F's rows f_q T fill in): use 'detect' or "
                             "'dense'")  # fmt: skip
        self._structure = _UNSET  # sparse_structure(), made when first asked for
        self._kernel_cache: dict = {}

    # ----------------------------------------------------------------- properties
    @property
    def r(self) -> int:
        """Number of rows of ``F``: ``m + k``."""
        return self.m + self.k

    @property
    def n_residual(self) -> int:
        """Number of residual components ``g = (f, ḟ, h)``: ``2m + k``."""
        return 2 * self.m + self.k

    @property
    def has_mass(self) -> bool:
        return "mass" in self.functions

    @property
    def time_dependent(self) -> bool:
        """True when the constraints depend explicitly on time (``f_t`` or ``h_t`` given)."""
        return "f_t" in self.functions or "h_t" in self.functions

    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(self.params)

    @property
    def kinematic(self) -> bool:
        """True when the velocities are quasi-velocities, ``q̇ = T(q, t) v``."""
        return "kinematics" in self.functions

    @property
    def state_names(self) -> list[str]:
        return list(self.coordinates) + list(self.velocities)

    @functools.cached_property  # (the declarations are fixed at construction)
    def state_units(self) -> list[str]:
        return list(self.coordinate_units) + list(self.velocity_units)

    @functools.cached_property  # (the declarations are fixed at construction)
    def component_units(self) -> list[str]:
        """Units of the residual components ``(f, ḟ, h)``."""
        f_units = list(self.constraint_units[: self.m])
        return f_units + [_per_second(u) for u in f_units] + list(self.constraint_units[self.m:])

    @property
    def multiplier_names(self) -> list[str]:
        """The constraint each multiplier λ belongs to: ``f_i``, then ``h_j``."""
        return [f"f_{i}" for i in range(self.m)] + [f"h_{j}" for j in range(self.k)]

    @functools.cached_property  # (the declarations are fixed at construction)
    def multiplier_units(self) -> list[str]:
        """Units of λ: energy per constraint unit (``Fᵀλ`` is a generalized force); a
        velocity constraint's row of F is ∂h/∂v, so there per constraint unit and second."""
        from ._schema import units_quotient

        cu = self.constraint_units
        return ([units_quotient(self.energy_units, u) for u in cu[: self.m]]
                + [units_quotient(self.energy_units, f"{u} s") for u in cu[self.m:]])  # fmt: skip

    @functools.cached_property  # (the declarations are fixed at construction)
    def acceleration_units(self) -> list[str]:
        from ._schema import units_quotient

        return [units_quotient(u, "s2") for u in self.coordinate_units]

    @property
    def component_names(self) -> list[str]:
        """Labels of the residual components: ``f_i``, ``fdot_i``, ``h_i``."""
        return (
            [f"f_{i}" for i in range(self.m)]
            + [f"fdot_{i}" for i in range(self.m)]
            + [f"h_{i}" for i in range(self.k)]
        )

    def __repr__(self) -> str:
        pieces = ", ".join(self.functions) + (", energy" if self.energy is not None else "")
        return (
            f"Model({self.name!r}, n={self.n}, m={self.m}, k={self.k}, "
            f"params={dict(self.params)}, pieces=[{pieces}])"
        )

    def replace(self, **changes) -> Model:
        """A new model with the same arguments as this one but ``changes``, e.g.
        ``model.replace(sparsity="dense")``; it is validated like any model."""
        unknown = set(changes) - set(self._args)
        if unknown:
            raise ModelError(
                f"Model.replace: {sorted(unknown)} are not arguments of Model; arguments: "
                f"{sorted(self._args)}"
            )
        return Model(**{**self._args, **changes})

    # ----------------------------------------------------------------- parameters
    def default_params(self) -> np.ndarray:
        """The parameter vector ``p`` with the model's default values."""
        return np.array(list(self.params.values()), dtype=np.float64)

    def param_vector(self, values: Mapping[str, float] | np.ndarray | None = None) -> np.ndarray:
        """The vector ``p``: defaults overridden by ``values`` (a mapping or a full vector)."""
        p = self.default_params()
        if values is None:
            return p
        if isinstance(values, Mapping):
            for key, val in values.items():
                if key not in self.params:
                    raise ModelError(
                        f"Model {self.name!r}: unknown parameter {key!r}; "
                        f"known parameters: {list(self.params)}"
                    )
                p[self.param_names.index(key)] = _finite_float(val, f"parameter {key!r}")
            return p
        arr = np.asarray(values, dtype=np.float64)
        if arr.shape != p.shape:
            raise ModelError(
                f"Model {self.name!r}: parameter vector must have shape {p.shape} "
                f"({list(self.params)}), got {arr.shape}"
            )
        if not np.all(np.isfinite(arr)):
            raise ModelError(f"Model {self.name!r}: parameter vector has non-finite entries")
        return np.ascontiguousarray(arr)

    def reference_state(self, p: np.ndarray | None = None) -> np.ndarray:
        """The consistent state ``x* = (q*, v*)`` for parameters ``p`` (shape (2n,))."""
        p = self.default_params() if p is None else p
        ref = self._reference
        x = np.asarray(ref(p) if callable(ref) else ref, dtype=np.float64)
        if x.shape != (2 * self.n,):
            raise ModelError(
                f"Model {self.name!r}: reference_state must have shape (2n,) = ({2 * self.n},) "
                f"for n={self.n}, got {x.shape}"
            )
        x = x.copy()
        if not np.all(np.isfinite(x)):
            raise ModelError(f"Model {self.name!r}: reference_state has non-finite entries: {x}")
        return x

    # ----------------------------------------------------------------- evaluation
    def evaluate(self, piece: str, t: float, x: np.ndarray, p: np.ndarray | None = None):
        """Call one piece at ``(t, x)`` and return a new array (Python-side helper).

        Absent optional pieces evaluate to their neutral value (identity mass, zero
        ``f_t``/``h_t``).  Not for hot loops.
        """
        return self._value(piece, t, x, p, python=False)

    def _value(self, piece: str, t: float, x: np.ndarray, p, python: bool):
        """:meth:`evaluate`, compiled or (``python=True``, at construction) as Python."""
        p = self.default_params() if p is None else p
        q, v = np.ascontiguousarray(x[: self.n]), np.ascontiguousarray(x[self.n :])
        call = _call_python if python else self._call_named
        if piece == "energy":
            if self.energy is None:
                raise ModelError(f"Model {self.name!r} has no energy function")
            return float(call("energy", self.energy, float(t), q, v, p))
        if piece not in _PIECES:
            raise ModelError(f"unknown model piece {piece!r}; pieces: {list(_PIECES)}")
        pattern, shape_of, _ = _PIECES[piece]
        shape = shape_of(self.n, self.m, self.k)
        fn = self.functions.get(piece)
        if fn is None:
            if piece in ("mass", "kinematics"):
                return np.eye(self.n)
            return np.zeros(shape)
        out = np.zeros(shape)
        args = (float(t), q, p) if pattern == "tqp" else (float(t), q, v, p)
        call(piece, fn, *args, out)
        return out

    def _call_named(self, piece: str, fn, *args):
        """The compiled ``fn(*args)``; a function numba cannot compile is named."""
        from numba.core.errors import NumbaError

        try:
            return _call_compiled(fn, *args)
        except NumbaError as exc:
            shapes = ", ".join(f"{np.shape(a)}" for a in args if isinstance(a, np.ndarray))
            raise ModelError(
                f"Model {self.name!r}: {_call_signature(piece)} failed to compile with "
                f"float64 scalars and C-contiguous float64 arrays (of shapes {shapes}): "
                f"{_first_lines(exc)}"
            ) from exc

    def residual(self, x: np.ndarray, t: float | None = None, p: np.ndarray | None = None):
        """The residual ``g = (f, ḟ, h)`` of (3.2) at state ``x``, shape (2m + k,)."""
        return self._residual(x, t, p, python=False)

    def _residual(self, x, t, p, python: bool) -> np.ndarray:
        t = self.t0 if t is None else t
        v = np.asarray(x, dtype=np.float64)[self.n :]
        parts = []

        def value(piece):
            return self._value(piece, t, x, p, python)

        if self.m:
            qdot = value("kinematics") @ v if self.kinematic else v
            parts += [value("f"), value("f_q") @ qdot + value("f_t")]
        if self.k:
            parts.append(value("h"))
        return np.concatenate(parts)

    def consistent_state(self, fixed=None, *, guess=None, params=None, t=None,
                         tol: float = 1e-13) -> np.ndarray:  # fmt: skip
        """A state on the constraint manifold with the components in ``fixed`` held (by
        name or index) and the rest solved for by Newton's method: the positions from
        ``f = 0``, then the velocities from ``ḟ = 0`` and ``h = 0``.  Refuses, naming them,
        unknowns the constraints leave free and constraints the held values contradict.
        See :func:`stabdae._consistent.consistent_state`."""
        from ._consistent import consistent_state

        return consistent_state(self, fixed, guess=guess, params=params, t=t, tol=tol)

    def check(self, params=None, *, states: int = 3, radius: float = 1e-2, seed: int = 0,
              rtol: float = 1e-6, velocity=None):  # fmt: skip
        """Compare the derivative pieces with finite differences (:func:`._check.check_model`:
        what is compared, at which states, and the report it returns)."""
        return check_model(self, params, states=states, radius=radius, seed=seed, rtol=rtol,
                           velocity=velocity)  # fmt: skip

    # ----------------------------------------------------------------- validation
    def _validate_outputs(self, outputs, names, units) -> tuple[tuple, tuple]:
        if outputs is None:
            if names is not None or units is not None:
                raise ModelError(f"Model {self.name!r}: output_names and output_units go "
                                 "with outputs=, which is not given")  # fmt: skip
            return (), ()
        from ._schema import reserved_names

        if names is None or isinstance(names, str) or len(names) == 0:
            raise ModelError(f"Model {self.name!r}: outputs needs output_names, a list of "
                             f"one name per output; got {names!r}")  # fmt: skip
        for nm in names:
            if not isinstance(nm, str):  # str(None) would make a variable None_final
                raise ModelError(f"Model {self.name!r}: output_names must be strings, got "
                                 f"{nm!r} in {list(names)}")  # fmt: skip
        names = tuple(names)
        taken = reserved_names()
        for nm in names:
            if len(nm) > MAX_NAME:
                raise ModelError(f"Model {self.name!r}: output name {nm[:40]!r}… has {len(nm)} "
                                 f"characters: at most {MAX_NAME} (it names NetCDF "
                                 "variables)")  # fmt: skip
            if not nm.isidentifier():
                raise ModelError(f"Model {self.name!r}: output name {nm!r} is not an "
                                 "identifier (letters, digits and _)")  # fmt: skip
            if nm in taken or f"{nm}_final" in taken or nm in self.coordinates:
                raise ModelError(f"Model {self.name!r}: output name {nm!r} is a dataset's "
                                 "own variable or coordinate; choose another")  # fmt: skip
        if len(set(names)) != len(names):
            raise ModelError(f"Model {self.name!r}: output_names repeat a name: {names}")
        units = self._validate_units(units, len(names), "output_units", "len(output_names)")
        return names, tuple(units)

    def _validate_scales(self, scales) -> np.ndarray | None:
        if scales is None:
            return None
        try:
            arr = np.array(scales, dtype=np.float64)
        except (TypeError, ValueError):
            raise ModelError(f"Model {self.name!r}: scales must be numbers, one per state "
                             f"component, shape (2n,) = ({2 * self.n},) or one per "
                             f"coordinate, (n,) = ({self.n},); got {scales!r}") from None
        if arr.shape == (self.n,):
            arr = np.concatenate([arr, arr])
        if arr.shape != (2 * self.n,):
            raise ModelError(f"Model {self.name!r}: scales must have shape (2n,) = "
                             f"({2 * self.n},) or (n,) = ({self.n},); got {arr.shape}")
        bad = np.flatnonzero(~(np.isfinite(arr) & (arr > 0)))
        if bad.size:
            names = [self.state_names[i] for i in bad]
            raise ModelError(f"Model {self.name!r}: scales must be positive and finite; "
                             f"{', '.join(names)} are {arr[bad].tolist()}")
        return arr

    def _count(self, value, symbol: str) -> int:
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
            raise ModelError(
                f"Model {self.name!r}: {symbol} must be a non-negative integer, got {value!r}"
            )
        return int(value)

    def _validate_params(self, params) -> dict[str, float]:
        if params is None:
            return {}
        if not isinstance(params, Mapping):
            raise ModelError(
                f"Model {self.name!r}: params must be a mapping of names to floats, "
                f"got {type(params).__name__}"
            )
        for key in params:  # they become NetCDF attribute names (model_param_<name>)
            if not (isinstance(key, str) and key.isidentifier()):
                raise ModelError(
                    f"Model {self.name!r}: parameter names must be identifiers (letters, "
                    f"digits and _, not starting with a digit), got {key!r}"
                )
            if len(key) > MAX_NAME:
                raise ModelError(f"Model {self.name!r}: parameter name {key[:40]!r}… has "
                                 f"{len(key)} characters: at most {MAX_NAME} (it names a "
                                 "NetCDF attribute)")  # fmt: skip
        return {str(k): _finite_float(v, f"parameter {k!r}") for k, v in params.items()}

    def _validate_names(self, coordinates, what: str = "coordinates") -> tuple[str, ...]:
        if coordinates is None:
            return tuple(f"q{i}" for i in range(self.n))
        if isinstance(coordinates, str):
            raise ModelError(f"Model {self.name!r}: {what} must be a sequence of n={self.n} "
                             f"names, got the string {coordinates!r}")  # fmt: skip
        names = tuple(str(c) for c in coordinates)
        if len(names) != self.n:
            raise ModelError(
                f"Model {self.name!r}: {what} must name the n={self.n} {what}, "
                f"got {len(names)}: {list(names)}"
            )
        if len(set(names)) != len(names):
            one = "coordinate" if what == "coordinates" else "velocity"
            raise ModelError(f"Model {self.name!r}: {one} names repeat: {list(names)}")
        return names

    def _validate_units(self, units, count: int, what: str, size: str) -> tuple[str, ...]:
        if units is None:
            return ("1",) * count
        if isinstance(units, str):
            return (units,) * count
        out = tuple(str(u) for u in units)
        if len(out) != count:
            raise ModelError(
                f"Model {self.name!r}: {what} must have {size}={count} entries, got {len(out)}"
            )
        return out

    def _check_presence(self, given: dict) -> None:
        where = f"Model {self.name!r}"
        if given["forces"] is None:
            raise ModelError(f"{where}: forces(t, q, v, p, out) is required (γ of (3.3))")
        for piece in _HOLONOMIC:
            if self.m == 0 and given[piece] is not None:
                raise ModelError(
                    f"{where}: {piece} is given but m=0; declare the number of holonomic "
                    "constraints m, or drop the function"
                )
        for piece in _NONHOLONOMIC:
            if self.k == 0 and given[piece] is not None:
                raise ModelError(
                    f"{where}: {piece} is given but k=0; declare the number of nonholonomic "
                    "constraints k, or drop the function"
                )
        if self.m:
            missing = [p for p in _REQUIRED_IF_M if given[p] is None]
            if missing:
                raise ModelError(f"{where}: m={self.m} holonomic constraints need {missing}")
        if self.k:
            missing = [p for p in _REQUIRED_IF_K if given[p] is None]
            if missing:
                raise ModelError(f"{where}: k={self.k} nonholonomic constraints need {missing}")

    def _require_njit(self, piece: str, fn) -> Dispatcher:
        if is_njit(fn):
            return fn
        kind = "a plain Python function" if callable(fn) else f"a {type(fn).__name__}"
        raise ModelError(
            f"Model {self.name!r}: {piece} must be an @njit function (a numba dispatcher), "
            f"got {kind}; decorate it with @numba.njit"
        )

    def _probe_all(self, x: np.ndarray, p: np.ndarray) -> dict:
        q, v = x[: self.n].copy(), x[self.n :].copy()
        t = self.t0
        outputs = self._probe_at(t, x, p, compiled=False)
        if "mass" in outputs:
            self._check_symmetric(outputs["mass"])
        if self.energy is not None:
            self._probe_energy(t, q, v, p)
        if self.outputs is not None:
            probe_output(f"Model {self.name!r}: outputs(t, q, v, p, out)", self.outputs,
                         (float(t), np.ascontiguousarray(q), np.ascontiguousarray(v), p),
                         (len(self.output_names),), "one per output_names",
                         compiled=False)  # fmt: skip
        return outputs

    def derived(self, x, t=None, params=None) -> np.ndarray:
        """The model's derived ``outputs`` at the states ``x`` (shape (2n,) or (N, 2n)) and
        times ``t`` (a number or one per state; default ``t0``): shape (len(output_names),)
        or (N, len(output_names)); NaN for a state that is not finite."""
        if self.outputs is None:
            raise ModelError(f"Model {self.name!r} declares no outputs (Model(..., "
                             "outputs=..., output_names=[...]))")  # fmt: skip
        X = np.atleast_2d(np.asarray(x, dtype=np.float64))
        if X.ndim != 2 or X.shape[1] != 2 * self.n:
            raise ValueError(f"{self.name}.derived: x must have shape (2n,) or (N, 2n) with "
                             f"2n = {2 * self.n}; got {np.shape(x)}")  # fmt: skip
        T = np.broadcast_to(np.asarray(self.t0 if t is None else t, dtype=np.float64),
                            (X.shape[0],)).copy()  # fmt: skip
        p = self.param_vector(params)
        out = np.full((X.shape[0], len(self.output_names)), np.nan)
        if self._derived_loop is None:
            self._derived_loop = _derived_loop_for(self.outputs)
        self._derived_loop(T, np.ascontiguousarray(X), self.n, p, out)
        return out[0] if np.ndim(x) == 1 else out

    # ----------------------------------------------------------------- sparsity
    def _sparsity(self, sparsity, x_ref, p, outputs) -> dict | None:
        """The structural patterns of ``mass``, ``f_q``, ``h_q``, ``h_v`` (declared, or
        found by :meth:`_detect`), or None for ``sparsity="dense"``."""
        self._sparsity_mode = "detect"
        self._declared: tuple[str, ...] = ()
        declared = {}
        named = isinstance(sparsity, str) and sparsity in ("detect", "dense", "sparse")
        if not (named or isinstance(sparsity, Mapping)):
            got = repr(sparsity) if isinstance(sparsity, str) else type(sparsity).__name__
            raise ModelError(
                f"Model {self.name!r}: sparsity must be 'detect', 'dense', 'sparse' or a "
                f"mapping of {list(_PATTERNED)} to boolean arrays, got {got}"
            )
        if isinstance(sparsity, str):
            if sparsity == "dense":
                self._sparsity_mode = "dense"
                return None
            self._sparsity_mode = sparsity
        elif isinstance(sparsity, Mapping):
            for piece, pattern in sparsity.items():
                if piece not in _PATTERNED or piece not in self.functions:
                    raise ModelError(
                        f"Model {self.name!r}: sparsity declares a pattern for {piece!r}, "
                        f"which is not one of the model's pieces "
                        f"{[q for q in _PATTERNED if q in self.functions]}"
                    )
                shape = _PIECES[piece][1](self.n, self.m, self.k)
                arr = np.asarray(pattern)
                if arr.shape != shape:
                    raise ModelError(
                        f"Model {self.name!r}: the sparsity pattern of {_call_signature(piece)} "
                        f"must have the shape of out, {shape}, got {arr.shape}"
                    )
                declared[piece] = arr.astype(bool)
        patterns = self._detect(x_ref, p)
        for piece, pattern in declared.items():
            outside = (outputs[piece] != 0) & ~pattern
            if outside.any():
                i = tuple(int(j) for j in np.argwhere(outside)[0])
                raise ModelError(
                    f"Model {self.name!r}: {_call_signature(piece)} writes "
                    f"out{list(i)} = {outputs[piece][i]!r} at the reference state, an "
                    "entry its declared sparsity pattern marks structurally zero"
                )
            # a structural zero holds everywhere: the states the detection visits too (a
            # kernel built on a wrong pattern drops a term and runs on without a word)
            seen = self._detect_states(x_ref)
            for t, x in zip(*seen):
                with np.errstate(all="ignore"):
                    value = self._value(piece, t, x, p, python=True)
                outside = (value != 0) & ~pattern
                if outside.any():
                    i = tuple(int(j) for j in np.argwhere(outside)[0])
                    raise ModelError(
                        f"Model {self.name!r}: {_call_signature(piece)} writes "
                        f"out{list(i)} = {float(value[i])!r} at t = {t:g}, x = "
                        f"{np.array2string(x, precision=6, max_line_width=10**6)}, an entry its "
                        "declared sparsity pattern marks structurally zero (it must be zero "
                        "at every state)"
                    )
            patterns[piece] = pattern
        self._declared = tuple(declared)
        return patterns

    def _detect(self, x_ref, p, states: int = 4, seed: int = 0) -> dict:
        """An entry is structurally zero when it is exactly zero at the reference state
        and at ``states`` random states around it (displaced by 1e-3 and 0.3 of each
        coordinate's scale, at random times when the model depends on time)."""
        ts, xs = self._detect_states(x_ref, states, seed)
        patterns = {}
        for piece in _PATTERNED:
            if piece not in self.functions:
                continue
            pattern = None
            for x, t in zip(xs, ts):
                with np.errstate(all="ignore"):
                    nz = self._value(piece, t, x, p, python=True) != 0  # NaN: non-zero
                pattern = nz if pattern is None else pattern | nz
            patterns[piece] = pattern
        return patterns

    def _detect_states(self, x_ref, states: int = 4, seed: int = 0):
        """``(times, states)`` of the detection: the reference state and ``states`` random
        ones around it (displaced by 1e-3 and 0.3 of each coordinate's scale, in turn)."""
        rng = np.random.default_rng(seed)
        scale = np.maximum(1.0, np.abs(x_ref))
        xs, ts = [x_ref], [self.t0]
        for i in range(states):
            radius = 1e-3 if i % 2 == 0 else 0.3
            xs.append(x_ref + radius * scale * rng.standard_normal(x_ref.shape))
            ts.append(self.t0 + (rng.uniform(0.0, 1.0) if self.time_dependent else 0.0))
        return ts, xs

    def sparse_structure(self):
        """The index lists of the sparse right-hand side (:mod:`stabdae.engine.sparsity`),
        or None where the dense one is used: ``sparsity="dense"``, a mass matrix that is
        not diagonal, or (``sparsity="detect"`` or declared patterns) a structure that
        saves less than half the dense path's multiply-adds."""
        if self._structure is not _UNSET:
            return self._structure
        from .engine.sparsity import dense_cost, sparse_cost, structure

        st = None
        # a kinematic map fills F's holonomic rows (f_q T): the dense path
        pats = None if self.kinematic else self.patterns
        diagonal = not self.has_mass or (
            pats is not None and not (pats["mass"] & ~np.eye(self.n, dtype=bool)).any())
        if pats is not None and diagonal:
            F = np.zeros((self.r, self.n), dtype=bool)
            if self.m:
                F[: self.m] = pats["f_q"]
            if self.k:
                F[self.m:] = pats["h_v"]
            st = structure(F, pats.get("h_q"))
            if self._sparsity_mode != "sparse" and 2 * sparse_cost(st) > dense_cost(self.n,
                                                                                  self.r):
                st = None
        self._structure = st
        return st

    def structure_key(self) -> str:
        """What the compiled sparse right-hand side depends on: the patterns."""
        h = hashlib.sha1()
        for piece in _PATTERNED:
            if self.patterns is not None and piece in self.patterns:
                pat = self.patterns[piece]
                h.update(f"{piece}{pat.shape}".encode() + np.packbits(pat).tobytes())
        return h.hexdigest()[:16]

    def _probe_at(self, t: float, x: np.ndarray, p: np.ndarray, where: str = "",
                  compiled: bool = True) -> dict:  # fmt: skip
        """Run every piece at ``(t, x)`` through :func:`probe_output` (first as Python, with
        NumPy's bounds checks, then compiled unless ``compiled=False``); returns the
        outputs by piece.  ``where`` is added to the messages ("at check state 3")."""
        q, v = np.ascontiguousarray(x[: self.n]), np.ascontiguousarray(x[self.n :])
        outputs = {}
        for piece, fn in self.functions.items():
            pattern, shape_of, governs = _PIECES[piece]
            args = (float(t), q, p) if pattern == "tqp" else (float(t), q, v, p)
            outputs[piece] = probe_output(
                f"Model {self.name!r}: {_call_signature(piece)}{where}",
                fn, args, shape_of(self.n, self.m, self.k),
                f"{governs} from n={self.n}, m={self.m}, k={self.k}", compiled=compiled,
            )  # fmt: skip
        return outputs

    def _check_symmetric(self, M: np.ndarray) -> None:
        """The kernels factor M by L D Lᵀ from its lower triangle alone: an asymmetric
        mass matrix would be read as another, symmetric one."""
        tol = 1e-12 * max(float(np.abs(M).max()), np.finfo(float).tiny)
        bad = np.argwhere(np.abs(M - M.T) > tol)
        if bad.size:
            i, j = (int(k) for k in bad[bad[:, 0] > bad[:, 1]][0])
            raise ModelError(
                f"Model {self.name!r}: mass(t, q, p, out) is not symmetric at the reference "
                f"state: out[{i}, {j}] = {float(M[i, j])!r} but out[{j}, {i}] = "
                f"{float(M[j, i])!r} (the "
                "mass matrix is symmetric; only its lower triangle would be read)"
            )

    def _probe_energy(self, t, q, v, p) -> None:
        try:
            e = _call_python("energy", self.energy, t, q, v, p)
        except Exception as exc:
            raise ModelError(
                f"Model {self.name!r}: energy(t, q, v, p) failed at the reference state: "
                f"{_first_lines(exc)}"
            ) from exc
        if not isinstance(e, (float, int, np.floating, np.integer)) or isinstance(e, bool):
            raise ModelError(
                f"Model {self.name!r}: energy(t, q, v, p) must return a float (shape ()), "
                f"got {type(e).__name__} of shape {np.shape(e)}"
            )
        if not math.isfinite(e):
            raise ModelError(
                f"Model {self.name!r}: energy(t, q, v, p) returned {e} at the reference state"
            )

    def _check_consistent(self, x: np.ndarray, p: np.ndarray) -> None:
        g = self._residual(x, self.t0, p, python=True)
        scale = max(1.0, float(np.max(np.abs(x))))
        tol = 1e-9 * scale
        if np.max(np.abs(g)) > tol:
            bad = {name: float(val) for name, val in zip(self.component_names, g) if abs(val) > tol}
            raise ModelError(
                f"Model {self.name!r}: reference_state is not on the constraint manifold at "
                f"t0={self.t0}: residual components above {tol:.1e}: {bad}"
                + self._missing_time_derivative_hint(x, p)
            )

    def _missing_time_derivative_hint(self, x: np.ndarray, p: np.ndarray) -> str:
        """When the constraints change with t but the model declares no f_t / h_t: the
        likely cause of an inconsistent ḟ or h, named."""
        dt = 1e-6 * max(1.0, abs(self.t0))
        moved = (self._residual(x, self.t0 + dt, p, python=True)
                 - self._residual(x, self.t0, p, python=True))  # fmt: skip
        hints = []
        if self.m and "f_t" not in self.functions and np.abs(moved[: self.m]).max() > 0:
            hints.append("f changes with t but the model gives no f_t(t, q, p, out) (∂f/∂t, "
                         "also part of f_accel)")  # fmt: skip
        if self.k and "h_t" not in self.functions and np.abs(moved[2 * self.m:]).max() > 0:
            hints.append("h changes with t but the model gives no h_t(t, q, v, p, out)")
        return "; " + "; ".join(hints) if hints else ""


# --------------------------------------------------------------------- helpers

def probe_output(where: str, fn: Dispatcher, args: tuple, shape: tuple, governs: str,
                 compiled: bool = True) -> np.ndarray:  # fmt: skip
    """Call ``fn(*args, out)`` once as Python and (``compiled``) once compiled; check shape
    and finiteness.

    ``where`` names the function in messages ("Model 'x': f(t, q, p, out)"), ``governs``
    says which sizes fix ``shape``.  Running the Python version first means an
    out-of-bounds write raises ``IndexError`` instead of corrupting memory; the compiled
    call then compiles the function for the argument types the kernels use.
    Returns the output of the compiled call, or without it of the Python one.
    """
    out = np.full(shape, _UNWRITTEN)
    try:
        python_function(fn)(*args, out)
    except (IndexError, ValueError) as exc:
        got = _written_shape(python_function(fn), args, shape)
        if got is None:  # fails on a larger buffer too: not a shape problem
            out = _probe_boundscheck(where, fn, args, shape, governs)
        else:
            raise ModelError(
                f"{where} writes outside out: expected shape {shape} ({governs}), got {got} "
                f"({type(exc).__name__}: {exc})"
            ) from exc
    except Exception:
        # Not runnable as plain Python (numba-only features): probe a bounds-checked
        # compilation of the same source instead.
        out = _probe_boundscheck(where, fn, args, shape, governs)
    unwritten = out == _UNWRITTEN
    if unwritten.any():
        got = _extent(~unwritten) if (~unwritten).any() else "nothing written"
        raise ModelError(
            f"{where} did not write every entry of out: expected shape {shape} ({governs}), "
            f"got {got}; unwritten entries {_index_list(unwritten)}"
        )
    if not np.all(np.isfinite(out)):
        raise ModelError(
            f"{where} returned non-finite values at the reference state at entries "
            f"{_index_list(~np.isfinite(out))}: {out.tolist()}"
        )
    if not compiled:
        return out
    result = np.zeros(shape)
    try:
        _call_compiled(fn, *args, result)
    except Exception as exc:  # numba typing errors come in many classes
        raise ModelError(
            f"{where} failed to compile or run with float64 scalars and C-contiguous float64 "
            f"arrays (out of shape {shape}): {_first_lines(exc)}"
        ) from exc
    return result


def _derived_loop_for(fn: Dispatcher):
    """A compiled loop of ``fn(t_i, q_i, v_i, p, out_i)`` over the rows of a state array
    (rows with a non-finite entry left as they are: NaN)."""

    @numba.njit
    def loop(T, X, n, p, out):
        for i in range(X.shape[0]):
            if np.all(np.isfinite(X[i])):
                fn(T[i], X[i, :n].copy(), X[i, n:].copy(), p, out[i])

    return loop


def _call_python(piece: str, fn: Dispatcher, *args):
    """``fn(*args)`` as plain Python; one that only runs compiled (numba-only features)
    runs compiled."""
    try:
        return python_function(fn)(*args)
    except Exception:
        return _call_compiled(fn, *args)


def _call_compiled(fn: Dispatcher, *args):
    """``fn(*args)``; an entry of numba's on-disk cache that refers to a module this
    process cannot import (the file was loaded under another name when it was cached) is
    passed over: the function compiles instead, and is not cached in this process."""
    from numba.core.caching import NullCache

    try:
        return fn(*args)
    except ModuleNotFoundError:
        if isinstance(getattr(fn, "_cache", None), NullCache):
            raise
        fn._cache = NullCache()
        return fn(*args)
    except Exception as exc:
        # a damaged entry of numba's on-disk cache (a truncated or overwritten file): the
        # model is not at fault; clear the entry and compile
        cache = getattr(fn, "_cache", None)
        if cache is None or isinstance(cache, NullCache) or not _raised_in_numba_cache(exc):
            raise
        where = getattr(cache, "cache_path", "numba's cache folder")
        cache.flush()
        warnings.warn(
            f"numba's on-disk cache entry of {getattr(fn, '__name__', fn)} in {where} was "
            f"damaged ({type(exc).__name__}: {exc}); it was cleared and the function "
            "compiled again",
            RuntimeWarning, stacklevel=3,
        )  # fmt: skip
        return fn(*args)


def _raised_in_numba_cache(exc: BaseException) -> bool:
    """Was ``exc`` raised while numba loaded an entry of its on-disk cache?"""
    frames = traceback.extract_tb(exc.__traceback__)
    return any(Path(f.filename).name == "caching.py" and "numba" in f.filename for f in frames)


def _probe_boundscheck(where, fn, args, shape, governs) -> np.ndarray:
    from numba import njit

    checked = njit(boundscheck=True)(python_function(fn))
    out = np.full(shape, _UNWRITTEN)
    try:
        checked(*args, out)
    except IndexError as exc:
        raise ModelError(
            f"{where} writes outside out: expected shape {shape} ({governs}) ({exc})"
        ) from exc
    except Exception as exc:
        raise ModelError(f"{where} failed at the reference state: {_first_lines(exc)}") from exc
    return out

def _per_second(unit: str) -> str:
    return "s-1" if unit == "1" else f"{unit} s-1"


def _finite_float(value, what: str) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ModelError(f"{what} must be a real number, got {value!r}") from None
    if not math.isfinite(out):
        raise ModelError(f"{what} must be finite, got {value!r}")
    return out


def _call_signature(piece: str) -> str:
    pattern = _PIECES[piece][0]
    return f"{piece}({', '.join(pattern)}, out)"


def _extent(mask: np.ndarray) -> tuple[int, ...]:
    """Shape of the smallest leading block that contains every True entry of ``mask``."""
    idx = np.argwhere(mask)
    return tuple(int(i) + 1 for i in idx.max(axis=0))


def _written_shape(py_func, args, shape) -> str | None:
    """Shape a function writes, found by calling it on an enlarged buffer (None if that
    call fails too)."""
    padded = np.full(tuple(s + 8 for s in shape), _UNWRITTEN)
    try:
        py_func(*args, padded)
    except Exception:
        return None
    written = padded != _UNWRITTEN
    if not written.any():
        return "nothing written"
    got = _extent(written)
    if got == padded.shape:
        return "a shape that follows out.shape"
    return str(got)


def _index_list(mask: np.ndarray) -> str:
    idx = [tuple(int(j) for j in i) for i in np.argwhere(mask)]
    if len(idx) > 6:
        return f"{idx[:6]} … ({len(idx)} in all)"
    return str(idx)


def _first_lines(exc: BaseException, n: int = 6) -> str:
    lines = [ln for ln in str(exc).splitlines() if ln.strip()]
    return f"{type(exc).__name__}: " + " | ".join(lines[:n])
