"""The compiled floor: everything that runs inside Numba, and nothing else.

Modules here take arrays, scalars and tuples, allocate nothing per step and return status
codes instead of raising.  They import NumPy and Numba but never xarray, and never
validate user input (the drivers one floor up do, once):

* :mod:`.fma`, :mod:`.linalg` — fused multiply-add, allocation-free L D Lᵀ;
* :mod:`.workspace` — the right-hand side's buffers, declared once by name, built on the
  heap (one trajectory) or on the stack (a block of the ensemble kernel);
* :mod:`.rhs` — the stabilized right-hand side (3.1), (3.11) for one model and law kind;
* :mod:`.steps` — the fixed-step Runge–Kutta step and single-trajectory loop;
* :mod:`.adaptive` — the embedded-pair loop (one trajectory, and per member of an ensemble);
* :mod:`.ensemble` — the block-lockstep ensemble kernel (structure of arrays);
* :mod:`.sampler` — placing initial states at prescribed constraint perturbations;
* :mod:`.decay` — the decay-rate fit of stored residual traces;
* :mod:`.threads` — running ``nogil`` kernels over chunks of members on a thread pool;
* :mod:`.cache` — per-model memo of the compiled closures and their on-disk cache.
"""
