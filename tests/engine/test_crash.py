"""The crash message's signal handler: installed by the first guard, kept after it, and
never saved as its own predecessor (which would loop on a crash instead of dying)."""

from __future__ import annotations

import ctypes
import signal

import pytest

from stabdae.engine import crash


@pytest.mark.skipif(not crash._enabled(), reason="Linux with the JIT only")
def test_the_handler_stays_after_a_guard_and_hands_on_to_the_one_before():
    before = signal.getsignal(signal.SIGSEGV)
    with crash.guard("first"):
        handler = crash._state["handler"][0].address
    try:
        for sig in crash._SIGNALS:  # kept, with the message for a later crash
            assert crash._still_ours(*crash._state["handler"])
        assert b"after a compiled kernel of stabdae ran in it (first)" in crash._MESSAGE.value
        with crash.guard("second"):  # again: the saved actions are still those from before
            assert b"second crashed inside a compiled kernel" in crash._MESSAGE.value
        for sig in crash._SIGNALS:
            saved = ctypes.c_size_t.from_buffer(crash._OLD[sig]).value
            assert saved != handler, f"signal {sig}: the handler saved as its own predecessor"
        assert signal.SIGABRT in crash._SIGNALS
    finally:
        crash._restore()
    assert signal.getsignal(signal.SIGSEGV) == before
    assert not crash._still_ours(*crash._state["handler"])
