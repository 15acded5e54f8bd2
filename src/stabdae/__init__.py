"""stabdae: stability of the constraint manifold of constrained Lagrangian systems under
numerical integration, after R. G. Mukharlyamov's constraint-perturbation equations.

The public API is exactly what this module re-exports, plus the submodules
:mod:`stabdae.theory`, :mod:`stabdae.symbolic`, :mod:`stabdae.simdmath` and
:mod:`stabdae.plots`.  The floors
below it: :mod:`stabdae.engine` (compiled), the drivers and definitions here,
:mod:`stabdae.study` (study files, runs, command line).
"""

# _vector_width first: numba's CPU features are fixed by the first compiled function
from . import _vector_width  # noqa: F401, I001
from .engine.checked_cache import checked_library_caches

# before any module of the library decorates a function with cache=True
checked_library_caches()

from . import theory  # noqa: E402, F401
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
from ._version import __version__

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
