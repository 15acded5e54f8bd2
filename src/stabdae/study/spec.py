"""Study files: TOML in, a validated :class:`Study` out — before anything compiles or
runs.

Every error names the file and the key (``study.toml: [run] tau: must be positive, got
-0.001``).  Sweep axes are named by their key; an unqualified name is looked up in
``[run]``, ``[law]``, ``[scheme]`` and the model's parameters, and must be unambiguous
(``law.k`` or ``model.k`` otherwise).  Entries of a constant matrix law are swept as
``"A[i,j]"`` (indices into the r × (m + r) matrix ``A``).
"""

from __future__ import annotations

import itertools
import math
import os
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._laws import Law, LawError, baumgarte, matrix, none, theorem5
from .._loading import load_model, local_sources, model_file
from .._model import Model, ModelError
from .._schemes import Scheme, SchemeError, as_scheme, from_tableau
from .._sequential import Sequential
from .._validate import block, ensemble_bytes, fits_in_memory, fixed_time_grid, seed

__all__ = ["Study", "StudyError", "load_study"]


class StudyError(ValueError):
    """A study file that cannot be run as written."""


_SECTIONS = {
    "model": {"file": str, "params": dict},
    "law": {"kind": str, "omega": float, "xi": float, "k": float, "A": list, "L": list},
    "scheme": {"name": str, "a": float, "sigma": float, "A": list, "b": list, "c": list,
               "order": int},
    "run": {"t_end": float, "tau": float, "save_dt": float, "epsilon": float,
            "divergence": float},  # fmt: skip
    "ensemble": {"members": (int, dict), "radius": (list, float), "seed": int, "block": int,
                 "states": bool},
    "sweep": None,  # names checked against the other sections
    "search": {"tau": dict, "q": float, "search_members": int, "steps": int,
               "t_end": float, "confidence": float},  # fmt: skip
    "output": {"path": str},
}
_REQUIRED = {"model": ("file",), "law": ("kind",), "run": ("t_end", "tau")}
#: what a boundary search needs of [run] (τ is searched; the run length is the search's)
_REQUIRED_SEARCH = {"model": ("file",), "law": ("kind",)}
_LAW_KEYS = {"baumgarte": {"omega", "xi", "k"}, "matrix": {"A"}, "theorem5": {"k", "L"},
             "none": set()}  # fmt: skip
_SWEEPABLE_RUN = ("tau",)
_MATRIX_ENTRY = re.compile(r"^(?:law\.)?A\[(\d+)\s*,\s*(\d+)\]$")


@dataclass
class Study:
    """A validated study.  ``axes`` maps each swept name (canonical: ``run.tau``,
    ``law.omega``, ``law.A[1,0]``, ``scheme.a``, ``model.g``) to its values."""

    path: Path
    model: Model
    params: dict
    law: dict
    scheme: dict
    run: dict
    ensemble: dict
    axes: dict = field(default_factory=dict)
    output: Path | None = None
    #: a boundary search (``[search]``): ``tau`` = (low, high), ``rtol``, ``q``,
    #: ``search_members``, ``steps`` or ``t_end``; None for a grid of ensembles
    search: dict | None = None
    #: the model's file (resolved), whose content, with what it imports from its own
    #: folder, keys a run's parts
    model_file: Path | None = None
    #: what validation changed and the user should know (printed with the description)
    notes: list = field(default_factory=list)
    #: why ``output`` may not be written (it lies outside the study's folder and the
    #: current one), or None
    output_refused: str | None = None
    #: the study file's bytes as read and validated: the run key is made of them, not of
    #: the file as it may be by the time a grid point runs
    text: bytes = b""
    #: the model file's bytes and those of the modules of its folder it imports, read
    #: right after the model was loaded (:func:`stabdae._loading.local_sources`): the run
    #: key and the dask workers' model are made of them
    model_sources: dict = field(default_factory=dict)

    # ----------------------------------------------------------------- grid
    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(v) for v in self.axes.values())

    @property
    def size(self) -> int:
        return int(np.prod(self.shape)) if self.axes else 1

    def points(self):
        """``(index tuple, {axis: value})`` for every grid point, C order."""
        names = list(self.axes)
        for idx in itertools.product(*(range(len(v)) for v in self.axes.values())):
            yield idx, {n: float(self.axes[n][i]) for n, i in zip(names, idx)}

    def setup(self, values: dict | None = None) -> dict:
        """Everything one grid point needs: ``params``, ``law``, ``scheme``, ``tau``,
        ``t_end``, ``save_dt``, ``epsilon``, ``divergence``."""
        values = values or {}
        params = dict(self.params)
        law = dict(self.law)
        scheme = dict(self.scheme)
        run = dict(self.run)
        A = None if law.get("A") is None else np.array(law["A"], dtype=float)
        for name, val in values.items():
            section, key = name.split(".", 1)
            if section == "model":
                params[key] = val
            elif section == "run":
                run[key] = val
            elif section == "scheme":
                scheme[key] = val
            elif (m := _MATRIX_ENTRY.match(name)) is not None:
                A[int(m.group(1)), int(m.group(2))] = val
            else:
                law[key] = val
        save_dt, stride = run.get("save_dt"), 1
        if save_dt is not None and run["tau"] > save_dt * (1 + 1e-12):
            stride = round(run["tau"] / save_dt)  # a step spans several samples
            save_dt = run["tau"]
        return {
            "params": params,
            "law": _make_law(law, A),
            "scheme": _make_scheme(scheme),
            "tau": run["tau"],
            "t_end": run["t_end"],
            "save_dt": save_dt,
            "stride": stride,
            "epsilon": run.get("epsilon"),
            "divergence": run.get("divergence"),
        }

    def describe(self) -> str:
        axes = ", ".join(f"{k} ({len(v)})" for k, v in self.axes.items()) or "none"
        head = (f"study {self.path.name}: model {self.model.name}, law {self.law['kind']}, "
                f"scheme {self.scheme.get('name', 'rk2')}, "
                f"{members_text(self.ensemble['members'])} × {self.size} grid points; "
                f"swept: {axes}")  # fmt: skip
        if self.search is not None:
            s = self.search
            head += (f"; searched: tau in [{s['tau'][0]:g}, {s['tau'][1]:g}] to rtol "
                     f"{s['rtol']:g} " + (
                         f"(probes of {s['search_members']} members, confirmed with "
                         f"{self.ensemble['members']})" if s.get("confidence") is None else
                         f"(each probe decided at its share of confidence "
                         f"{s['confidence']:g}, {s['search_members']} … "
                         f"{self.ensemble['members']} members)"))  # fmt: skip
        return "\n".join([head, *self.notes])


def most_members(members) -> int:
    """The most members a grid point runs: ``members``, or a sequential plan's ``max``."""
    return int(members["max"] if isinstance(members, dict) else members)


def members_text(members) -> str:
    """``members`` in words: "256 members", or "64 … 1024 members until decided (q = …,
    confidence …)"."""
    if not isinstance(members, dict):
        return f"{members} members"
    return (f"{members['batch']} … {members['max']} members until decided (q = "
            f"{members['q']:g} at confidence {members['confidence']:g})")


def _make_law(law: dict, A) -> Law:
    kind = law["kind"]
    if kind == "baumgarte":
        return baumgarte(law.get("omega"), law.get("xi", 1.0), law.get("k"))
    if kind == "matrix":
        return matrix(A)
    if kind == "theorem5":
        return theorem5(law["k"], law.get("L"))
    return none()


def _make_scheme(scheme: dict) -> Scheme:
    if any(k in scheme for k in ("A", "b", "c", "order")):  # the user's own tableau
        return from_tableau(scheme, name=scheme.get("name", "custom"))
    name = scheme.get("name", "rk2")
    params = {k: scheme[k] for k in ("a", "sigma") if k in scheme}
    return as_scheme(name, **params)


# --------------------------------------------------------------------- loading
def load_study(path, *, members: int | None = None, trust_model: bool = False) -> Study:
    """Read and validate a study file (nothing is compiled).

    ``[model] file`` must be a built-in scene or a model file in the study's folder (or
    below it, links resolved): loading a model file runs it, and a study file is data that
    may come from anyone.  ``trust_model=True`` (``--trust-model``) lifts that."""
    path = Path(path)
    where = path.name
    if not path.is_file():
        raise StudyError(f"{path}: no such study file")
    try:
        text = path.read_bytes()
        raw = tomllib.loads(text.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise StudyError(f"{path}: not a text file in UTF-8 (byte {exc.start} is "
                         f"{text[exc.start:exc.start + 1]!r}); a study file is TOML, which is "
                         "UTF-8") from None  # fmt: skip
    except tomllib.TOMLDecodeError as exc:
        raise StudyError(f"{where}: not valid TOML: {exc}") from None
    except RecursionError:
        raise StudyError(f"{where}: not valid TOML: nested too deeply") from None

    def fail(key: str, msg: str):
        raise StudyError(f"{where}: {key}: {msg}")

    for section in raw:
        if section not in _SECTIONS:
            fail(f"[{section}]", f"unknown section; known: {', '.join(_SECTIONS)}")
        if not isinstance(raw[section], dict):
            fail(section, "must be a table ([section])")
    for section, keys in _SECTIONS.items():
        if keys is None:
            continue
        for key, val in raw.get(section, {}).items():
            if key not in keys:
                fail(f"[{section}] {key}", f"unknown key; known: {', '.join(keys)}")
            raw[section][key] = _typed(val, keys[key], f"[{section}] {key}", fail)
    searching = "search" in raw
    for section, keys in (_REQUIRED_SEARCH if searching else _REQUIRED).items():
        for key in keys:
            if key not in raw.get(section, {}):
                fail(f"[{section}] {key}", "missing (required)")

    # model
    mfile = raw["model"]["file"]
    source = path.parent / mfile if mfile.endswith(".py") else mfile
    if mfile.endswith(".py") and not Path(source).is_file():
        fail("[model] file", f"no such model file: {source}")
    if mfile.endswith(".py") and not trust_model:
        # loading a model file runs it: a study file (data, perhaps someone else's) may
        # name code in its own folder, or a built-in scene, and nothing else unasked
        home = path.parent.resolve()
        real = Path(source).resolve()
        if not real.is_relative_to(home):
            via = "" if Path(os.path.abspath(source)) == real else f" (through a link, to {real})"
            fail("[model] file", f"{mfile} lies outside the study's folder {home}{via}; a "
                 "model file is code and loading it runs it: move it beside the study, or "
                 "pass --trust-model (load_study(..., trust_model=True)) to run it")  # fmt: skip
    try:
        model = load_model(source)
    except ModelError as exc:
        fail("[model] file", str(exc).removeprefix("load_model: "))
    params = dict(model.params)
    for key, val in raw["model"].get("params", {}).items():
        if key not in params:
            fail(f"[model] params.{key}", f"model {model.name!r} has no parameter {key!r}; "
                 f"its parameters: {', '.join(params) or 'none'}")  # fmt: skip
        params[key] = _typed(val, float, f"[model] params.{key}", fail)
        if not math.isfinite(params[key]):
            fail(f"[model] params.{key}", f"must be finite, got {params[key]}")

    # law
    law = dict(raw["law"])
    kind = law["kind"]
    if kind not in _LAW_KEYS:
        fail("[law] kind", f"unknown law {kind!r}; known: {', '.join(_LAW_KEYS)}")
    for key in law:
        if key != "kind" and key not in _LAW_KEYS[kind]:
            fail(f"[law] {key}", f"not a parameter of the {kind!r} law "
                 f"(its parameters: {', '.join(sorted(_LAW_KEYS[kind])) or 'none'})")  # fmt: skip
    for key in ("omega", "k"):
        if key in law and not law[key] > 0:
            fail(f"[law] {key}", f"must be positive, got {law[key]}")
    if kind == "baumgarte" and "omega" in law and model.m == 0:
        fail("[law] omega", f"model {model.name!r} has no holonomic constraints (m = 0)")
    if kind == "baumgarte" and "k" in law and model.k == 0:
        fail("[law] k", f"model {model.name!r} has no nonholonomic constraints (k = 0)")
    if "xi" in law and not law["xi"] >= 0:
        fail("[law] xi", f"must be non-negative, got {law['xi']}")

    # scheme (two_stage may take a and sigma from the sweep alone)
    scheme = dict(raw.get("scheme", {}))
    swept = {k.removeprefix("scheme.") for k in raw.get("sweep", {})}
    if not (str(scheme.get("name", "")).lower() == "two_stage" and swept & {"a", "sigma"}):
        try:
            _make_scheme(scheme)
        except SchemeError as exc:
            fail("[scheme] name", str(exc))

    # search
    search = _search(raw.get("search"), fail) if searching else None
    if searching:
        raw.setdefault("run", {})
        raw["run"].setdefault("tau", search["tau"][0])
        raw["run"].setdefault("t_end", model.t0 + search["tau"][0])
        if any(k in ("tau", "run.tau") for k in raw.get("sweep", {})):
            fail("[sweep] tau", "is searched in [search]; sweep the other parameters")

    # run
    run = dict(raw["run"])
    for key in ("t_end", "tau", "save_dt", "epsilon", "divergence"):
        if key in run and not (math.isfinite(run[key]) and run[key] > 0):
            fail(f"[run] {key}", f"must be positive and finite, got {run[key]}")

    # ensemble
    ens = {"members": 1024, "radius": [1e-6, 1e-2], "seed": 0, "block": 64, "states": False}
    ens.update(raw.get("ensemble", {}))
    if members is not None:
        ens["members"] = members
    if isinstance(ens["members"], dict):  # run until decided (one plan for every point)
        if searching:
            fail("[ensemble] members", "a boundary search runs its probes with a number of "
                 "members: give an integer")  # fmt: skip
        try:
            ens["members"] = Sequential.of(ens["members"], "load_study").as_dict()
        except ValueError as exc:
            fail("[ensemble] members", str(exc).removeprefix("load_study: members "))
    elif ens["members"] < 1:
        fail("[ensemble] members", f"must be at least 1, got {ens['members']}")
    most = most_members(ens["members"])
    try:  # before any grid point: refused up front, not killed part-way
        fits_in_memory(ensemble_bytes(model.n, model.n_residual, most, 0, 0, 4),
                       f"{most} members per grid point", "load_study",
                       "run fewer members")  # fmt: skip
    except MemoryError as exc:
        fail("[ensemble] members", str(exc).removeprefix("load_study: "))
    radius = ens["radius"]
    radius = [radius, radius] if isinstance(radius, float) else radius
    if len(radius) != 2 or not all(isinstance(r, (int, float)) for r in radius):
        fail("[ensemble] radius", f"must be a number or [low, high], got {ens['radius']}")
    radius = [float(r) for r in radius]
    if not (0 < radius[0] <= radius[1] and math.isfinite(radius[1])):
        fail("[ensemble] radius", f"needs 0 < low <= high, got {radius}")
    ens["radius"] = radius
    try:
        seed(ens["seed"], "study")
    except ValueError as exc:
        fail("[ensemble] seed", str(exc).removeprefix("study: seed "))
    try:
        block(ens["block"], model.n, "study", "block")
    except ValueError as exc:
        fail("[ensemble] block", str(exc).removeprefix("study: "))

    # sweep
    notes: list[str] = []
    axes = {}
    for name, spec in raw.get("sweep", {}).items():
        canon = _canonical(name, model, law, scheme, fail)
        values = _axis_values(spec, f"[sweep] {name}", fail)
        if canon in axes:
            fail(f"[sweep] {name}", f"sweeps {canon} twice")
        axes[canon] = values
        _check_axis(canon, values, f"[sweep] {name}", fail)
        size = math.prod(len(v) for v in axes.values())
        if size > MAX_POINTS:
            fail("[sweep]", f"{size:.3g} grid points: at most {MAX_POINTS} (one ensemble each)")

    if "run.tau" not in axes and "save_dt" in run and run["tau"] > run["save_dt"] * (1 + 1e-12):
        ratio = run["tau"] / run["save_dt"]
        if abs(ratio - round(ratio)) > 1e-9 * ratio:  # the samples would leave save_dt's grid
            lo, hi = math.floor(ratio) * run["save_dt"], math.ceil(ratio) * run["save_dt"]
            fail("[run] tau", f"{run['tau']:g} is larger than save_dt = {run['save_dt']:g} "
                 f"and not a whole multiple of it, so its steps miss the sample grid; "
                 f"nearest: {lo:g} or {hi:g}")  # fmt: skip
        notes.append(f"note: tau = {run['tau']:g} is larger than save_dt = "
                     f"{run['save_dt']:g}: samples every {run['save_dt']:g}, one in "
                     f"{round(ratio)} on a step, the others NaN")  # fmt: skip
    for key in ("a", "sigma"):  # the base point of a two-stage sweep: its first value
        if f"scheme.{key}" in axes:
            scheme.setdefault(key, float(axes[f"scheme.{key}"][0]))

    if "run.tau" in axes:
        span = run["t_end"] - model.t0
        if "save_dt" not in run:
            run["save_dt"] = span / 200.0
        asked = axes["run.tau"]
        axes["run.tau"] = snap_taus(asked, run["save_dt"], span, fail)
        run["tau"] = float(axes["run.tau"][0])
        moved = [f"{a:g} → {b:g}" for a, b in zip(asked, axes["run.tau"])
                 if abs(a - b) > 1e-12 * a]  # fmt: skip
        if moved:
            notes.append(f"note: swept tau moved onto the sample grid (save_dt = "
                         f"{run['save_dt']:g}, every step a divisor of it or a multiple that "
                         f"divides t_end): {', '.join(moved)}")  # fmt: skip

    output = raw.get("output", {}).get("path")
    if output is not None and ("\0" in output or not output.strip()):
        fail("[output] path", f"must be a file path without NUL characters, got {output!r}")
    refused = None
    if output is not None:  # a study file is data: it writes beneath its folder or here
        target = Path(os.path.normpath(path.parent.resolve() / output))
        real = target.resolve()  # a link on the way leads where it leads
        bases = (path.parent.resolve(), Path.cwd().resolve())
        if not all(any(t.is_relative_to(base) and t != base for base in bases)
                   for t in (target, real)):  # fmt: skip
            via = "" if real == target else f", which a link leads to {real}"
            # refused where it would be used: an output given by the caller replaces it
            refused = (f"{where}: [output] path: must lie beneath the study's folder or the "
                       f"current one, got {output!r}{via} (give another place with stabdae "
                       f"run -o)")  # fmt: skip
    the_file = model_file(source)
    study = Study(path=path, model=model, params=params, law=law, scheme=scheme, run=run,
                  ensemble=ens, axes=axes,
                  output=None if output is None
                  else Path(os.path.normpath(path.parent / output)),
                  model_file=the_file, notes=notes, search=search,
                  output_refused=refused, text=text,
                  model_sources={} if the_file is None else local_sources(the_file))  # fmt: skip
    if searching:
        return study  # τ is what the search finds: no time grid to check

    # every grid point must build (law shapes, time grid): try them all, cheaply
    for _, values in study.points():
        label = ", ".join(f"{k} = {v:g}" for k, v in values.items()) or "the base point"
        try:
            s = study.setup(values)
            bound_law = s["law"]
            bound_law.bind(model) if bound_law.is_constant else None
            _check_time_grid(s["tau"], s["t_end"] - model.t0, s["save_dt"])
        except (LawError, SchemeError, ValueError, IndexError) as exc:
            raise StudyError(f"{where}: at {label}: {exc}") from None
    return study


def _search(raw: dict, fail) -> dict:
    """``[search] tau = { bisect = [low, high], rtol = 1e-3 }`` with ``q``,
    ``search_members``, ``steps`` or ``t_end``, and ``confidence``, checked."""
    spec = raw.get("tau")
    if spec is None:
        fail("[search] tau", "missing: give tau = { bisect = [low, high], rtol = 1e-3 }")
    for key in spec:
        if key not in ("bisect", "rtol"):
            fail(f"[search] tau.{key}", "unknown key; known: bisect, rtol")
    ends = spec.get("bisect")
    if not (isinstance(ends, list) and len(ends) == 2
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in ends)):
        fail("[search] tau.bisect", f"must be [low, high], got {ends!r}")
    lo, hi = float(ends[0]), float(ends[1])
    if not (0 < lo < hi and math.isfinite(hi)):
        fail("[search] tau.bisect", f"needs 0 < low < high, got {ends!r}")
    rtol = _typed(spec.get("rtol", 1e-3), float, "[search] tau.rtol", fail)
    if not 1e-9 <= rtol <= 1.0:
        fail("[search] tau.rtol", f"must lie in [1e-9, 1], got {rtol:g}")
    q = raw.get("q", 0.0)
    if not 0.0 <= q < 1.0:
        fail("[search] q", f"the allowed unstable fraction must lie in [0, 1), got {q:g}")
    n = raw.get("search_members", 64)
    if n < 1:
        fail("[search] search_members", f"must be at least 1, got {n}")
    if "steps" in raw and "t_end" in raw:
        fail("[search] t_end", "give steps or t_end, not both")
    if raw.get("steps", 1) < 1:
        fail("[search] steps", f"must be at least 1, got {raw['steps']}")
    if "t_end" in raw and not (math.isfinite(raw["t_end"]) and raw["t_end"] > 0):
        fail("[search] t_end", f"must be positive and finite, got {raw['t_end']}")
    confidence = raw.get("confidence")
    if confidence is not None:
        if not 0.0 < confidence < 1.0:
            fail("[search] confidence", f"must lie between 0 and 1, got {confidence:g}")
        if not q > 0.0:
            fail("[search] confidence", "needs q above 0 (no number of members shows a "
                 "fraction to be 0): give q, e.g. q = 0.05")  # fmt: skip
    return {"tau": (lo, hi), "rtol": rtol, "q": float(q), "search_members": n,
            "steps": raw.get("steps"), "t_end": raw.get("t_end"), "confidence": confidence}


def _typed(val, kind, key, fail):
    kinds = kind if isinstance(kind, tuple) else (kind,)
    for k in kinds:
        if k is float and isinstance(val, (int, float)) and not isinstance(val, bool):
            return float(val)
        if k is int and isinstance(val, int) and not isinstance(val, bool):
            return val
        if k in (str, dict, list, bool) and isinstance(val, k):
            return val
    names = " or ".join({float: "a number", int: "an integer", str: "a string",
                         dict: "a table", list: "an array", bool: "true or false"}[k]
                        for k in kinds)  # fmt: skip
    fail(key, f"must be {names}, got {type(val).__name__} {val!r}")


def _canonical(name: str, model: Model, law: dict, scheme: dict, fail) -> str:
    if _MATRIX_ENTRY.match(name):
        if law["kind"] != "matrix":
            fail(f"[sweep] {name}", "matrix entries can only be swept with [law] kind = 'matrix'")
        m = _MATRIX_ENTRY.match(name)
        return f"law.A[{m.group(1)},{m.group(2)}]"
    if "." in name:
        section, key = name.split(".", 1)
        ok = {"run": key in _SWEEPABLE_RUN, "law": key in _LAW_KEYS[law["kind"]] - {"A", "L"},
              "scheme": key in ("a", "sigma"), "model": key in model.params}.get(section)
        if not ok:
            fail(f"[sweep] {name}", _sweepable_list(model, law))
        return name
    hits = []
    if name in _SWEEPABLE_RUN:
        hits.append(f"run.{name}")
    if name in _LAW_KEYS[law["kind"]] - {"A", "L"}:
        hits.append(f"law.{name}")
    if name in ("a", "sigma"):
        hits.append(f"scheme.{name}")
    if name in model.params:
        hits.append(f"model.{name}")
    if not hits:
        fail(f"[sweep] {name}", _sweepable_list(model, law))
    if len(hits) > 1:
        fail(f"[sweep] {name}", f"ambiguous: write one of {', '.join(hits)}")
    return hits[0]


def _sweepable_list(model, law) -> str:
    names = ["tau", *sorted(_LAW_KEYS[law["kind"]] - {"A", "L"}), "a", "sigma",
             *model.params]  # fmt: skip
    if law["kind"] == "matrix":
        names.append("A[i,j]")
    return f"not a sweepable parameter; sweepable here: {', '.join(names)}"


#: values per sweep axis, and grid points in all, a study may have (checked before any array
#: is built: a grid of 1e10 points cannot be run, and would not be noticed until late)
MAX_AXIS = 100_000
MAX_POINTS = 1_000_000


def _axis_values(spec, key, fail) -> np.ndarray:
    if isinstance(spec, list):
        if not spec or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                               for v in spec):  # fmt: skip
            fail(key, f"must be a non-empty array of numbers, got {spec!r}")
        values = np.array(spec, dtype=float)
    elif isinstance(spec, dict):
        if len(spec) != 1 or next(iter(spec)) not in ("linspace", "logspace"):
            fail(key, f"must be an array or {{ linspace = [a, b, n] }} / "
                 f"{{ logspace = [a, b, n] }}, got {spec!r}")  # fmt: skip
        how, args = next(iter(spec.items()))
        if not (isinstance(args, list) and len(args) == 3 and isinstance(args[2], int)
                and args[2] >= 1 and all(isinstance(a, (int, float)) for a in args[:2])):
            fail(key, f"{how} needs [start, stop, count] with an integer count, got {args!r}")
        a, b, n = float(args[0]), float(args[1]), args[2]
        if n > MAX_AXIS:
            fail(key, f"{how} of {n} values: at most {MAX_AXIS} per axis")
        if how == "logspace":
            if not (a > 0 and b > 0):
                fail(key, f"logspace needs positive ends (the values themselves), got {args!r}")
            values = np.geomspace(a, b, n)
        else:
            values = np.linspace(a, b, n)
    else:
        fail(key, f"must be an array or a linspace/logspace table, got {spec!r}")
    if not np.all(np.isfinite(values)):
        fail(key, "values must be finite")
    if len(np.unique(values)) != len(values):
        fail(key, f"values repeat: {values.tolist()}")
    return values


def snap_taus(taus, save_dt: float, span: float, fail=None) -> np.ndarray:
    """Step sizes moved onto the common sample grid of a τ sweep.

    Every grid point stores the residual at the same times ``t0 + j·save_dt``, so each τ
    becomes ``save_dt / K`` (``K = ⌈save_dt/τ⌉``: never larger than asked) when
    ``τ ≤ save_dt``, and ``L·save_dt`` (the largest ``L ≤ τ/save_dt`` that divides the
    number of samples; samples between steps are NaN) when it is larger.
    """
    nsave = round(span / save_dt)
    if abs(nsave * save_dt - span) > 1e-9 * span:
        msg = f"t_end - t0 = {span:g} must be a whole multiple of save_dt = {save_dt:g}"
        if fail:
            fail("[run] save_dt", msg)
        raise ValueError(msg)
    out = []
    for tau in taus:
        if tau <= save_dt * (1 + 1e-12):
            out.append(save_dt / math.ceil(save_dt / tau - 1e-9))
        else:
            L = max(1, math.floor(tau / save_dt + 1e-9))
            while nsave % L:
                L -= 1
            out.append(L * save_dt)
    out = np.array(out)
    if len(np.unique(out)) != len(out) and fail:
        fail("[sweep] tau", f"values {np.asarray(taus).tolist()} land on repeated step sizes "
             f"{out.tolist()} on the sample grid save_dt = {save_dt:g}; use fewer values or "
             "a larger save_dt")  # fmt: skip
    return out


def _check_axis(canon, values, key, fail):
    positive = {"run.tau", "law.omega", "law.k"}
    if canon in positive and not np.all(values > 0):
        fail(key, f"values must be positive, got {values.tolist()}")
    if canon == "law.xi" and not np.all(values >= 0):
        fail(key, f"values must be non-negative, got {values.tolist()}")


def _check_time_grid(tau, span, save_dt):
    """The fixed-step grid of one grid point, as :func:`stabdae.ensemble` will check it."""
    if not span > 0:
        raise ValueError(f"t_end must be after t0, got a span of {span:g}")
    fixed_time_grid(span, tau, save_dt, "[run]")
