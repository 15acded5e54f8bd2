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
(:func:`stabdae.load_model`), the kernel cache is on, a CPU is idle beside this process
(:func:`idle_cpu`: on a machine other work keeps busy the helper would take this
process's CPU time, not add its own), and neither kernel is compiled in this process or
cached.  If the helper
fails, or is still running a quarter of the kernel's compile time after the kernel is
ready (it is then stopped), the sampler is compiled here, as without it: the most the
helper can cost is that quarter.  The wait counts as compiling
(:func:`.jit.compile_seconds`).  ``STABDAE_COMPILE_AHEAD=0`` switches it off;
``STABDAE_COMPILE_AHEAD=always`` starts it whatever the load and waits for it as long as
the kernel took (a helper slowed by the load may still finish; at the cost of that wait).
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time

from .cache import _KeyedCache, cache_dir
from .jit import JIT

__all__ = ["ENV", "WAIT_SHARE", "busy_cpus", "enabled", "idle_cpu", "on_disk", "sampler_ahead",
           "wait_share"]

#: the environment variable that switches the helper process off ("0", "off", "false"), or
#: on whatever the machine's load ("always")
ENV = "STABDAE_COMPILE_AHEAD"
#: how long :meth:`Ahead.join` waits by default (seconds)
WAIT_S = 300.0
#: the longest wait for a helper still running when the kernel is ready, as a share of
#: the kernel's compile time (the sampler compiles in a fraction of the kernel's time)
WAIT_SHARE = 0.25

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


#: how long the machine's CPU counters are watched to tell the other work's share (s)
WATCH_S = 0.1


def _cpu_times() -> tuple[int, int]:
    """(all, idle) clock ticks of the machine's CPUs since boot (Linux's /proc/stat)."""
    with open("/proc/stat") as fh:
        ticks = [int(v) for v in fh.readline().split()[1:9]]
    return sum(ticks), ticks[3] + ticks[4]  # idle and waiting for I/O


def busy_cpus() -> float:
    """How many CPUs other work keeps busy now: the machine's busy share over
    :data:`WATCH_S` seconds while this process sleeps, times its CPUs (not the load
    average, which still counts this user's own run of a minute ago); where there are no
    such counters, the one-minute load average."""
    try:
        total0, idle0 = _cpu_times()
        time.sleep(WATCH_S)
        total1, idle1 = _cpu_times()
    except (OSError, ValueError, IndexError):  # pragma: no cover - not Linux
        try:
            return os.getloadavg()[0]
        except (AttributeError, OSError):
            return 0.0
    total = total1 - total0
    if total <= 0:
        return 0.0
    return (1.0 - (idle1 - idle0) / total) * (os.cpu_count() or 1)


def idle_cpu(cpus: int | None = None, busy: float | None = None) -> bool:
    """Whether a CPU is idle beside this process: at least two usable, and the CPUs other
    work keeps busy (:func:`busy_cpus`) leave more than one and a half of them, one for
    this process's own compiling and most of one for the helper's."""
    cpus = _usable_cpus() if cpus is None else cpus
    if cpus < 2:
        return False
    busy = busy_cpus() if busy is None else busy
    return cpus - busy >= 1.5


def _setting() -> str:
    return os.environ.get(ENV, "1").strip().lower()


def wait_share() -> float:
    """How long to wait for a helper still running when the kernel is ready, as a share
    of the kernel's compile time: :data:`WAIT_SHARE`, or 1 where it is started always."""
    return 1.0 if _setting() == "always" else WAIT_SHARE


def enabled() -> bool:
    """Whether a helper process may compile ahead: switched on, with the kernel cache (its
    only way to hand the code over) and two usable CPUs (whether one is idle now is asked
    last, :func:`sampler_ahead`: it takes a tenth of a second)."""
    if _setting() in ("0", "off", "false", "no"):
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
    if _setting() != "always" and not idle_cpu():
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
