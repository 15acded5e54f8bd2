"""Running a compiled ``nogil`` kernel over chunks of members on a pool of threads.

The ensemble and sampling kernels are plain ``@njit(nogil=True)`` functions over a range
of work items (blocks of members), not ``parallel=True`` functions: numba's parfor
machinery about doubles their compile time (figures in ``studies/README.md``), and chunks
driven from Python give progress reports and a clean stop on
Ctrl-C between chunks.  Work items never share outputs, so the numbers do not depend on
the thread count or on which thread ran which chunk.
"""

from __future__ import annotations

import itertools
import os
import threading
from concurrent.futures import ThreadPoolExecutor, wait

import numba

from .crash import guard

__all__ = ["default_threads", "run_chunks"]


def default_threads() -> int:
    """Threads used by default: numba's setting (``NUMBA_NUM_THREADS``, else the cores)."""
    return max(1, int(numba.get_num_threads()))


def _chunks(items: int, threads: int, per_thread: int = 8) -> list[tuple[int, int]]:
    """Consecutive ranges covering ``range(items)``: about ``per_thread`` per thread, and
    towards the end smaller ones (each at most 1/(2·threads) of what is left, down to one
    item), so that the threads run out of work at nearly the same time (with equal chunks
    the last one kept one thread busy alone)."""
    cap = max(1, -(-items // (threads * per_thread)))
    out, lo = [], 0
    while lo < items:
        size = min(cap, max(1, (items - lo) // (2 * threads))) if threads > 1 else cap
        out.append((lo, min(items, lo + size)))
        lo += size
    return out


def run_chunks(kernel, items: int, *, threads: int | None = None, progress=None,
               who: str = "ensemble") -> None:
    """Call ``kernel(lo, hi)`` for consecutive ranges covering ``range(items)``.

    ``kernel`` must release the GIL (a ``nogil`` dispatcher called with arguments bound by
    the caller) and do nothing for an empty range: ``kernel(0, 0)`` runs first, alone, so
    that compilation (or loading from the cache) happens once, and then every chunk runs
    on the pool.  ``progress(done, items)`` is called from the calling thread after each
    chunk.
    """
    if items <= 0:
        return
    with guard(who):  # a crash inside says what happened (.crash)
        threads = default_threads() if threads is None else max(1, int(threads))
        threads = min(threads, items, os.cpu_count() or threads)
        chunks = _chunks(items, threads)
        done = 0
        if threads == 1:
            for lo, hi in chunks:
                kernel(lo, hi)
                done += hi - lo
                if progress is not None:
                    progress(done, items)
            return
        kernel(0, 0)
        _run_shared(kernel, chunks, threads, progress, items)


def _run_shared(kernel, chunks, threads: int, progress, items: int) -> None:
    """The chunks taken in turn by the calling thread and ``threads − 1`` workers of the
    pool, each taking the next chunk not yet taken when it is free (the calling thread
    works too: a future per chunk, each handed to the pool and waited for, cost about
    as much as a small call's work).  ``progress`` is called from the calling thread
    after each chunk it runs and once at the end.  A chunk that raises, or an interrupt
    of the calling thread, stops every thread before its next chunk; the chunks running
    end before this returns, and the error is raised (the calling thread's own where it
    has one, else a worker's)."""
    taken = itertools.count()  # ``next`` is atomic: each chunk is taken once
    lock = threading.Lock()
    state = {"done": 0, "stop": False}

    def work(report):
        while not state["stop"]:
            i = next(taken)
            if i >= len(chunks):
                return
            lo, hi = chunks[i]
            try:
                kernel(lo, hi)
            except BaseException:
                state["stop"] = True
                raise
            with lock:
                state["done"] += hi - lo
                done = state["done"]
            if report is not None:
                report(done, items)

    pool = _pool(threads - 1)
    helpers = [pool.submit(work, None) for _ in range(threads - 1)]
    try:
        work(progress)
        for fut in helpers:
            fut.result()
    except BaseException:
        state["stop"] = True
        wait(helpers)  # nothing of this call runs on after it has returned
        raise
    if progress is not None:
        progress(items, items)


_POOLS: dict[int, ThreadPoolExecutor] = {}
_POOLS_LOCK = threading.Lock()


def _pool(threads: int) -> ThreadPoolExecutor:
    """The process's pool of ``threads`` workers, started on first use and kept: starting
    one per call costs more than a small call's work, and an ensemble makes two such
    calls."""
    with _POOLS_LOCK:
        pool = _POOLS.get(threads)
        if pool is None:
            pool = _POOLS[threads] = ThreadPoolExecutor(
                max_workers=threads, thread_name_prefix=f"stabdae{threads}"
            )
        return pool
