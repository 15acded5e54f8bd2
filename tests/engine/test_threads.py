"""The thread pool that runs compiled kernels over chunks of work items."""

from __future__ import annotations

import threading
import time

import pytest

from stabdae.engine.threads import run_chunks


def test_chunks_cover_every_item_once_and_report_progress():
    seen = []
    lock = threading.Lock()
    reports = []

    def kernel(lo, hi):
        with lock:
            seen.extend(range(lo, hi))

    run_chunks(kernel, 1000, threads=2, progress=lambda done, n: reports.append((done, n)))
    assert sorted(seen) == list(range(1000))
    assert [d for d, _ in reports] == sorted(d for d, _ in reports)
    assert reports[-1] == (1000, 1000)


def test_a_failing_chunk_raises_and_nothing_runs_on_after_the_call():
    """The error reaches the caller; chunks not started are cancelled and those running
    finish before ``run_chunks`` returns (the pool is kept between calls)."""
    running = []
    finished = []

    def kernel(lo, hi):
        if hi == 0:
            return
        running.append(lo)
        if lo == 0:
            raise ValueError("chunk 0 failed")
        time.sleep(0.01)
        finished.append(lo)

    with pytest.raises(ValueError, match="chunk 0 failed"):
        run_chunks(kernel, 64, threads=2)
    after = (len(running), len(finished))
    time.sleep(0.05)
    assert (len(running), len(finished)) == after
    assert len(running) == len(finished) + 1  # every started chunk but the failed one ended
    # the pool still works
    out = []
    run_chunks(lambda lo, hi: out.extend(range(lo, hi)), 10, threads=2)
    assert sorted(out) == list(range(10))


@pytest.mark.parametrize(
    "items, threads", [(157, 2), (1563, 2), (1000, 16), (5, 4), (1, 2), (40, 1)]
)
def test_chunks_shrink_towards_the_end(items, threads):
    """Consecutive ranges over every item; none larger than an equal share of
    ``threads × 8`` chunks, and with more than one thread each at most half a thread's
    share of what is left (down to one item), so that the last ones are short."""
    from stabdae.engine.threads import _chunks

    chunks = _chunks(items, threads)
    assert chunks[0][0] == 0 and chunks[-1][1] == items
    assert all(a[1] == b[0] for a, b in zip(chunks, chunks[1:]))
    cap = -(-items // (threads * 8))
    for lo, hi in chunks:
        assert 1 <= hi - lo <= cap
        if threads > 1:
            assert hi - lo <= max(1, (items - lo) // (2 * threads))
    if threads > 1 and items > 2 * threads:
        assert chunks[-1][1] - chunks[-1][0] == 1


def test_the_calling_thread_works_and_reports_and_a_workers_error_reaches_it():
    """The calling thread takes chunks itself (a future per chunk cost about as much as a
    small call's work) and is the only one to report progress; an error in a chunk a
    worker runs stops the calling thread's chunks and is raised there, after every
    running chunk has ended."""
    caller = threading.get_ident()
    ran_by, reporters, after, started, failed_at = [], set(), [], [], []

    def kernel(lo, hi):
        if hi == 0:
            return
        ran_by.append(threading.get_ident())
        if threading.get_ident() != caller:
            failed_at.append(time.perf_counter())
            raise RuntimeError(f"worker chunk {lo} failed")
        started.append(time.perf_counter())
        time.sleep(0.02)  # the worker takes a chunk while the caller works on this one
        after.append(lo)

    with pytest.raises(RuntimeError, match="worker chunk"):
        run_chunks(kernel, 40, threads=2, progress=lambda d, n: reporters.add(
            threading.get_ident()))
    assert caller in ran_by and any(t != caller for t in ran_by)
    assert reporters <= {caller}
    # the caller takes no chunk after the worker's error, but for one it may have taken
    # as the error came
    assert failed_at and sum(t > failed_at[0] for t in started) <= 1
    ended = len(after)
    time.sleep(0.05)
    assert len(after) == ended
    reports = []
    run_chunks(lambda lo, hi: None, 10, threads=2, progress=lambda d, n: reports.append(
        threading.get_ident()))
    assert set(reports) == {caller}
