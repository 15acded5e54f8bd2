"""The compiled floor: everything that runs inside Numba, and nothing else.

Modules here take arrays, scalars and tuples, allocate nothing per step and return status
codes instead of raising.  They import NumPy and Numba but never xarray, never a module of
the floors above (not even for annotations), and never validate user input (the drivers
one floor up do, once).  By role:

* :mod:`.jit`, :mod:`.fma`, :mod:`.source`, :mod:`.emit` — whether the JIT runs (and
  functions compiled without wrappers for compiled callers), the fused multiply-add,
  generated source registered for tracebacks, straight-line code compiled without
  numba's typing of each statement;
* :mod:`.linalg`, :mod:`.sparsity` — allocation-free L D Lᵀ (looped, and written out for
  a model's sizes and patterns); the sparse right-hand side's index lists;
* :mod:`.workspace` — the right-hand side's buffers, declared once by name, built on the
  heap (one trajectory) or on the stack (a member slot of the ensemble kernel);
* :mod:`.rhs` — the stabilized right-hand side (3.1), (3.11) for one model and law kind;
* :mod:`.rk` — explicit Runge–Kutta steps: :mod:`.rk.steps` (the fixed step, looped and
  generated, side by side), :mod:`.rk.control` (step-size control of the embedded pairs),
  :mod:`.rk.adaptive` (the adaptive loop of one trajectory and its generated attempt);
* :mod:`.ensemble` — the ensemble kernels: :mod:`.ensemble.groups` (their arguments in
  named groups), :mod:`.ensemble.block` (fixed steps, blocks of members in lockstep) and
  :mod:`.ensemble.lanes` (adaptive steps, members on lanes);
* :mod:`.decay` — the in-kernel measurement of the decay rate: :mod:`.decay.record`,
  :mod:`.decay.ladder`, :mod:`.decay.fit`, :mod:`.decay.member`, :mod:`.decay.onestep`,
  :mod:`.decay.traces`;
* :mod:`.sampler` — placing initial states at prescribed constraint perturbations;
* :mod:`.threads` — running ``nogil`` kernels over chunks of members on a thread pool;
* :mod:`.crash` — what is printed when a compiled kernel crashes (segmentation fault, abort);
* :mod:`.cache` — the compile spec (:class:`.cache.Spec`), the per-model memo of the
  compiled closures and their on-disk cache;
* :mod:`.checked_cache` — numba's on-disk cache read as data: a JSON index, and each entry's
  key and checksum checked before it is unpickled (the kernel cache's and the library's own
  ``cache=True`` functions');
* :mod:`.ahead` — a new model's sampler compiled into that cache by a helper process while
  this one compiles the ensemble kernel;
* :mod:`.vector_width` — the SIMD width numba compiles for, chosen when this package is
  first imported.
"""

# vector_width first: numba's CPU features are fixed by the first compiled function; then
# the checked caches, before any of the library's modules decorates a function
from . import vector_width  # noqa: F401, I001
from .checked_cache import checked_library_caches

checked_library_caches()
