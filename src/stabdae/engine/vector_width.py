"""The width of the SIMD vectors the compiled kernels are vectorized for.

The ensemble kernel's member loop is vectorized by LLVM, and on a CPU with AVX-512 LLVM
prefers 256-bit vectors for most Intel models (a tuning choice made for the first
AVX-512 Xeons, whose clock dropped under 512-bit instructions): four members per
instruction where the registers hold eight.  512-bit vectors make the ensemble kernels
faster per member on such machines (the benchmarks' notes give the figures), and their
results are the same bits: lanes are members, and without fast-math flags LLVM changes
neither the operations of a lane nor their order.

So, when the host has AVX-512, the first import of the compiled floor (:mod:`stabdae.engine`,
imported by the first use of a model, a law or a driver) asks numba for 512-bit vectors by
adding ``-prefer-256-bit`` to the CPU features numba compiles for.  numba has one set of
CPU features per process, so the choice also applies to the other functions numba
compiles in that process (their results are the same bits too; their cached machine code
is keyed by the features and compiles once more).  It is made only:

* when numba's CPU target is not yet in use (no ``@njit`` function compiled before the
  library's first use: numba fixes its features with the first);
* when the user set neither ``NUMBA_CPU_NAME`` nor ``NUMBA_CPU_FEATURES`` (their choice
  stands);
* unless ``STABDAE_VECTOR_WIDTH=256`` (or ``default``) asks to leave numba's choice, for
  a CPU that slows down under 512-bit instructions.

:data:`PREFER_512` records what happened; every dataset reports it (attribute
``prefer_512_bit_vectors``).
"""

from __future__ import annotations

import os

__all__ = ["PREFER_512", "choose"]

_FEATURE = "-prefer-256-bit"


def choose(environ=os.environ) -> bool:
    """Ask numba for 512-bit vectors where that is possible and wanted (see the module's
    text); whether numba's features now prefer them."""
    from numba import config
    from numba.core.codegen import get_host_cpu_features
    from numba.core.registry import cpu_target

    current = config.CPU_FEATURES or ""
    if _FEATURE in current.split(","):
        return True
    wanted = environ.get("STABDAE_VECTOR_WIDTH", "512").strip().lower()
    if wanted in ("256", "default", "off", "0", "false"):
        return False
    if environ.get("NUMBA_CPU_NAME") or environ.get("NUMBA_CPU_FEATURES"):
        return False
    if "_toplevel_target_context" in vars(cpu_target):  # numba's features are fixed
        return False
    try:
        features = get_host_cpu_features()
    except Exception:  # features unknown on this host: leave numba's choice
        return False
    if "+avx512f" not in features.split(","):
        return False
    config.CPU_FEATURES = features + "," + _FEATURE
    return True


#: whether numba compiles for 512-bit vectors in this process (see the module's text)
PREFER_512 = choose()
