"""A new model's sampler compiled in a second process while this one compiles its ensemble
kernel.

numba compiles under one lock per process, so a model's first ensemble compiles its two
kernels one after the other: the perturbation sampler (seconds, for a coupled mechanism)
and then the ensemble kernel (several times that).  Both are cached on disk under keys
that depend only on the model's source and the library (:mod:`.cache`), so a second Python
process that loads the same model file and places one member compiles the same sampler
and writes it to the cache; this process meanwhile compiles the ensemble kernel, then
loads the sampler from the cache.  The compiled code is the same, so are the results.

It is started only when it can gain: the model was loaded from a file
(:func:`stabdae.load_model`), the kernel cache is on, at least two CPUs are usable, and
neither kernel is compiled in this process or cached.  If the helper fails, or is still
running when waited for as long as the kernel took to compile (it is then stopped), the
sampler is compiled here, as without it.
``STABDAE_COMPILE_AHEAD=0`` switches it off.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys

from .cache import _KeyedCache, cache_dir
from .jit import JIT

__all__ = ["ENV", "enabled", "on_disk", "sampler_ahead"]

#: the environment variable that switches the helper process off ("0", "off", "false")
ENV = "STABDAE_COMPILE_AHEAD"
#: how long :meth:`Ahead.join` waits by default (seconds)
WAIT_S = 300.0

#: the helper yields a shared CPU to this process, whose compiling is the one waited for
_CHILD = (
    "import os\n"
    "if hasattr(os, 'nice'):\n"
    "    os.nice(10)\n"
    "import sys, stabdae\n"
    "model = stabdae.load_model(sys.argv[1], sys.argv[2])\n"
    "stabdae.sample_perturbations(model, 1, threads=1)\n"
)


def _usable_cpus() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def enabled() -> bool:
    """Whether a helper process may compile ahead: switched on, with the kernel cache (its
    only way to hand the code over) and two usable CPUs."""
    if os.environ.get(ENV, "1").strip().lower() in ("0", "off", "false", "no"):
        return False
    return JIT and cache_dir() is not None and _usable_cpus() >= 2


def on_disk(dispatcher) -> bool:
    """Whether ``dispatcher`` has compiled code in the kernel cache (for its key)."""
    cache = getattr(dispatcher, "_cache", None)
    if not isinstance(cache, _KeyedCache):
        return False
    try:
        return bool(cache._cache_file._load_index())
    except Exception:  # an unreadable index: as if nothing were cached
        return False


class Ahead:
    """A helper process compiling a model's sampler into the kernel cache."""

    def __init__(self, proc: subprocess.Popen):
        self._proc = proc

    def join(self, timeout: float = WAIT_S) -> bool:
        """Wait for the helper; whether it finished cleanly (if not, and it still runs
        after ``timeout`` seconds, it is stopped)."""
        try:
            return self._proc.wait(timeout) == 0
        except subprocess.TimeoutExpired:
            self.stop()
            return False

    def stop(self) -> None:
        if self._proc.poll() is None:
            self._proc.kill()
            with contextlib.suppress(Exception):
                self._proc.wait(10)


def sampler_ahead(model, sampler, kernel) -> Ahead | None:
    """Start compiling ``sampler`` (``model``'s) in a helper process while this one is
    about to compile ``kernel``; None where it cannot gain (see the module's text)."""
    origin = getattr(model, "_origin", None)
    if origin is None or not enabled():
        return None
    if (sampler.signatures or kernel.signatures or not isinstance(
            getattr(sampler, "_cache", None), _KeyedCache) or on_disk(sampler)
            or on_disk(kernel)):  # fmt: skip
        return None
    env = dict(os.environ, **{ENV: "0"})
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)  # this process's stabdae
    try:
        proc = subprocess.Popen([sys.executable, "-c", _CHILD, *origin], env=env,
                                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)  # fmt: skip
    except OSError:  # no interpreter to start (embedded Python, limits): compile here
        return None
    return Ahead(proc)
