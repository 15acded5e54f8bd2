"""stabdae: stability of the constraint manifold of constrained Lagrangian systems under
numerical integration, after R. G. Mukharlyamov's constraint-perturbation equations.

The public API is exactly what this module re-exports, plus the submodules
:mod:`stabdae.theory`, :mod:`stabdae.symbolic`, :mod:`stabdae.simdmath`,
:mod:`stabdae.rigid` and :mod:`stabdae.plots`.  The floors
below it: :mod:`stabdae.engine` (compiled), the drivers and definitions here,
:mod:`stabdae.study` (study files, runs, command line).
"""

import importlib
from typing import TYPE_CHECKING

from ._version import __version__

# The names are imported on first use (PEP 562), so that ``import stabdae`` and the command
# line start without numba, SciPy and xarray (``stabdae --version`` imports none of them).
# The compiled floor's first import (stabdae.engine) fixes numba's CPU features and
# installs the library's checked caches, before any of the library's modules decorates.
_EXPORTS = {
    "integrate_adaptive": "_adaptive",
    "boundary": "_boundary",
    "Status": "_codes",
    "ensemble": "_ensemble",
    "sample_perturbations": "_ensemble",
    "balanced_gain": "_gains",
    "gain_floor": "_gains",
    "IntegrationWarning": "_integrate",
    "integrate": "_integrate",
    "Law": "_laws",
    "LawError": "_laws",
    "acpr": "_laws",
    "baumgarte": "_laws",
    "matrix": "_laws",
    "none": "_laws",
    "theorem5": "_laws",
    "user": "_laws",
    "load_model": "_loading",
    "scene_names": "_loading",
    "Model": "_model",
    "ModelError": "_model",
    "paired_difference": "_profile",
    "radial_profile": "_profile",
    "open_dataset": "_schema",
    "write_netcdf": "_schema",
    "Scheme": "_schemes",
    "SchemeError": "_schemes",
    "dop853": "_schemes",
    "dopri5": "_schemes",
    "euler": "_schemes",
    "heun": "_schemes",
    "heun3": "_schemes",
    "midpoint": "_schemes",
    "rk3": "_schemes",
    "rk4": "_schemes",
    "two_stage": "_schemes",
    "Sequential": "_sequential",
}
_SUBMODULES = frozenset({"engine", "plots", "rigid", "simdmath", "study", "symbolic",
                         "theory"})

if TYPE_CHECKING:  # what the names are, for type checkers and the API reference
    from . import theory
    from ._adaptive import integrate_adaptive
    from ._boundary import boundary
    from ._codes import Status
    from ._ensemble import ensemble, sample_perturbations
    from ._gains import balanced_gain, gain_floor
    from ._integrate import IntegrationWarning, integrate
    from ._laws import Law, LawError, acpr, baumgarte, matrix, none, theorem5, user
    from ._loading import load_model, scene_names
    from ._model import Model, ModelError
    from ._profile import paired_difference, radial_profile
    from ._schema import open_dataset, write_netcdf
    from ._schemes import (
        Scheme,
        SchemeError,
        dop853,
        dopri5,
        euler,
        heun,
        heun3,
        midpoint,
        rk3,
        rk4,
        two_stage,
    )
    from ._sequential import Sequential


__all__ = [
    "IntegrationWarning",
    "Law",
    "LawError",
    "Model",
    "ModelError",
    "Scheme",
    "SchemeError",
    "Sequential",
    "Status",
    "__version__",
    "acpr",
    "balanced_gain",
    "baumgarte",
    "boundary",
    "dop853",
    "dopri5",
    "ensemble",
    "euler",
    "gain_floor",
    "heun",
    "heun3",
    "integrate",
    "integrate_adaptive",
    "load_model",
    "matrix",
    "midpoint",
    "none",
    "open_dataset",
    "paired_difference",
    "radial_profile",
    "rk3",
    "rk4",
    "sample_perturbations",
    "scene_names",
    "theorem5",
    "theory",
    "two_stage",
    "user",
    "write_netcdf",
]


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is not None:
        value = getattr(importlib.import_module("." + module, __name__), name)
    elif name in _SUBMODULES:
        value = importlib.import_module("." + name, __name__)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__) | _SUBMODULES)
