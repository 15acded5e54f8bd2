"""A message, instead of a bare "Segmentation fault", when a compiled kernel crashes.

A model function that writes outside its ``out`` array at a state that ``Model()`` and
``model.check()`` did not try (they run every function as Python and bounds-checked)
corrupts memory in a compiled kernel, or makes the process die of a segmentation fault
with nothing said.  Checking every index in the kernels costs their speed, so the
default runs unchecked; from the first kernel called under :func:`guard`, a handler of
SIGSEGV, SIGBUS and SIGABRT writes what happened and what to do to stderr and then hands
the signal to the handler that was there before (Python's ``faulthandler``, if enabled,
then prints the Python stack; otherwise the process dies as before).  The process is not
saved: the memory may already be corrupt.  A write outside an array on the heap is often
found only later, when the C library frees a block near it and aborts ("malloc():
unaligned tcache chunk detected"), after the kernel returned: the handler therefore stays
after the guard, saying that a kernel ran earlier rather than that one crashed.

The handler calls only ``write``, ``strlen`` and ``sigaction`` (async-signal-safe); it is a
few lines of LLVM IR compiled by llvmlite once per process under the first guard, with the
addresses it writes from (this process's) as constants.  What it reads lies in pages of
their own, outside the C library's heap, the message's read-only between guards: a model
that writes past an array on the heap corrupts that array's neighbours there, and a
message held among them came out as the bytes the model wrote, or not at all, when the C
library then aborted.  Linux only; elsewhere, or with ``STABDAE_CRASH_MESSAGE=off``,
nothing is installed.
"""

from __future__ import annotations

import contextlib
import ctypes
import mmap
import os
import signal
import sys
import threading

__all__ = ["guard"]

#: a fault, and glibc's abort when it finds its heap corrupt ("malloc(): unaligned tcache
#: chunk detected"): a write outside an array often surfaces as the second, later
_SIGNALS = tuple(getattr(signal, name) for name in ("SIGSEGV", "SIGBUS", "SIGABRT")
                 if hasattr(signal, name))
#: glibc's struct sigaction is 152 bytes on x86-64 and aarch64: room to spare
_ACTION_BYTES = 256
_FLAGS_OFFSET = 8 + 128  # after sa_handler and the 1024-bit sa_mask
_SA_ONSTACK = 0x08000000

_LOCK = threading.Lock()
#: ``lingering``: the handler stays installed after the outermost guard, with the message
#: of :func:`_after_message` (corrupted memory is often found later, at a free)
_state = {"depth": 0, "handler": None, "failed": False, "lingering": False}
_PAGE = mmap.PAGESIZE
#: the message, and the actions saved and installed, each in an anonymous mapping of its
#: own (``mmap``: not on the C library's heap, where a model's stray writes land)
_TEXT = mmap.mmap(-1, _PAGE)
_ACTIONS = mmap.mmap(-1, _PAGE)
_MESSAGE = (ctypes.c_char * _PAGE).from_buffer(_TEXT)
_OLD = {sig: (ctypes.c_char * _ACTION_BYTES).from_buffer(_ACTIONS, i * _ACTION_BYTES)
        for i, sig in enumerate(_SIGNALS)}  # fmt: skip
_NEW = (ctypes.c_char * _ACTION_BYTES).from_buffer(_ACTIONS, len(_SIGNALS) * _ACTION_BYTES)


def _message(who: str) -> bytes:
    return (
        f"\nstabdae: {who} crashed inside a compiled kernel (a segmentation fault, a bus "
        "error, or the C library's abort on corrupted memory): most likely a model or law function read or wrote outside its arrays at a "
        "state that Model() and model.check() did not try.  Run it again with "
        "NUMBA_BOUNDSCHECK=1 in the environment: it then stops with an IndexError that "
        "names the function, the time and the state.  (The grid points a study has "
        "finished are kept: the same command resumes.)\n"
    ).encode()[: len(_MESSAGE) - 1]


def _after_message(who: str) -> bytes:
    return (
        f"\nstabdae: the process crashed (a segmentation fault, a bus error, or the C "
        f"library's abort on corrupted memory) after a compiled kernel of stabdae ran in it "
        f"({who}): if nothing else in it runs compiled code, most likely a model or law "
        "function wrote outside its arrays at a state that Model() and model.check() did "
        "not try, and the memory it corrupted was found later.  Run it again with "
        "NUMBA_BOUNDSCHECK=1 in the environment: it then stops with an IndexError that "
        "names the function, the time and the state.  (The grid points a study has "
        "finished are kept: the same command resumes.)\n"
    ).encode()[: len(_MESSAGE) - 1]


def _enabled() -> bool:
    from numba import config

    off = os.environ.get("STABDAE_CRASH_MESSAGE", "").strip().lower() in ("0", "off", "no")
    return sys.platform.startswith("linux") and not off and not config.DISABLE_JIT


def _libc_functions():
    libc = ctypes.CDLL(None)

    def fn(name, restype, *argtypes):
        f = getattr(libc, name)
        f.argtypes, f.restype = list(argtypes), restype
        return f

    size_t = ctypes.c_size_t
    return {"write": fn("write", ctypes.c_ssize_t, ctypes.c_int, size_t, size_t),
            "strlen": fn("strlen", size_t, size_t),
            "sigaction": fn("sigaction", ctypes.c_int, ctypes.c_int, size_t, size_t),
            "mprotect": fn("mprotect", ctypes.c_int, size_t, size_t, ctypes.c_int)}


def _set_message(text: bytes, libc) -> None:
    """The handler's message, in its page, which is read-only again after the write (a
    stray write there faults, and the handler still has its message)."""
    at = ctypes.addressof(_MESSAGE)
    if libc["mprotect"](at, _PAGE, mmap.PROT_READ | mmap.PROT_WRITE) != 0:
        return  # (not writable: the message before stays)
    _MESSAGE.value = text
    libc["mprotect"](at, _PAGE, mmap.PROT_READ)


class _Handler:
    """The machine code of the handler (LLVM IR compiled by llvmlite's MCJIT, kept alive
    with its engine) and its address."""

    def __init__(self, engine, address: int):
        self.engine, self.address = engine, address


def _compile_handler():
    """``handler(sig)``: ``write(2, message, strlen(message))``, then ``sigaction(sig,
    <the handler before ours>, NULL)``.  Written in LLVM IR with this process's addresses
    as constants (libc's functions, the message, the saved actions): compiling it takes
    milliseconds, where a numba ``cfunc`` first set up numba's whole compiler (tenths of
    a second per process, and it cannot be cached: the addresses are this process's)."""
    import llvmlite.binding as llvm
    import llvmlite.ir as ir

    libc = _libc_functions()
    i8p, i32, i64 = ir.IntType(8).as_pointer(), ir.IntType(32), ir.IntType(64)
    module = ir.Module(name="stabdae_crash")
    fn = ir.Function(module, ir.FunctionType(ir.VoidType(), [i32]), name="stabdae_crash")
    b = ir.IRBuilder(fn.append_basic_block())

    def address(value: int):
        return ir.Constant(i64, value)

    def callee(name, ret, *args):
        at = ctypes.cast(libc[name], ctypes.c_void_p).value
        return b.inttoptr(address(at), ir.FunctionType(ret, list(args)).as_pointer())

    text = b.inttoptr(address(ctypes.addressof(_MESSAGE)), i8p)
    length = b.call(callee("strlen", i64, i8p), [text])
    b.call(callee("write", i64, i32, i8p, i64), [ir.Constant(i32, 2), text, length])
    sig = fn.args[0]
    # the handler before ours takes over; the faulting instruction runs again on return
    old = address(ctypes.addressof(_OLD[_SIGNALS[-1]]))
    for each in _SIGNALS[:-1]:
        old = b.select(b.icmp_signed("==", sig, ir.Constant(i32, int(each))),
                       address(ctypes.addressof(_OLD[each])), old)  # fmt: skip
    b.call(callee("sigaction", i32, i32, i8p, i8p),
           [sig, b.inttoptr(old, i8p), ir.Constant(i8p, None)])  # fmt: skip
    b.ret_void()
    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    parsed = llvm.parse_assembly(str(module))
    parsed.verify()
    machine = llvm.Target.from_default_triple().create_target_machine()
    engine = llvm.create_mcjit_compiler(parsed, machine)
    engine.finalize_object()
    return _Handler(engine, engine.get_function_address("stabdae_crash")), libc


def _install(who: str) -> None:
    if _state["handler"] is None:
        _state["handler"] = _compile_handler()
    handler, libc = _state["handler"]
    c_sigaction = libc["sigaction"]
    _set_message(_message(who), libc)
    if _state["lingering"] and _still_ours(handler, libc):
        return  # installed since an earlier guard: the actions saved then stay the ones before
    ctypes.memset(_NEW, 0, _ACTION_BYTES)
    ctypes.memmove(_NEW, ctypes.byref(ctypes.c_size_t(handler.address)), 8)
    flags = ctypes.c_int(_SA_ONSTACK)  # on faulthandler's stack, where it has set one up
    ctypes.memmove(ctypes.addressof(_NEW) + _FLAGS_OFFSET, ctypes.byref(flags), 4)
    for sig in _SIGNALS:
        if c_sigaction(int(sig), ctypes.addressof(_NEW), ctypes.addressof(_OLD[sig])) != 0:
            raise OSError(f"sigaction({int(sig)}) failed")


def _still_ours(handler, libc) -> bool:
    """Whether every signal's action is still this handler (nobody replaced it since)."""
    now = (ctypes.c_char * _ACTION_BYTES)()
    for sig in _SIGNALS:
        if libc["sigaction"](int(sig), 0, ctypes.addressof(now)) != 0:
            return False
        if ctypes.c_size_t.from_buffer(now).value != handler.address:
            return False
    return True


def _linger(who: str) -> None:
    """After the outermost guard: the handler stays, saying that a kernel ran earlier
    (heap corruption is often detected only at a later free, outside any kernel)."""
    _set_message(_after_message(who), _state["handler"][1])
    _state["lingering"] = True


def _restore() -> None:
    """Put back the actions from before the first guard (for tests)."""
    c_sigaction = _state["handler"][1]["sigaction"]
    for sig in _SIGNALS:
        c_sigaction(int(sig), ctypes.addressof(_OLD[sig]), 0)
    _state["lingering"] = False


@contextlib.contextmanager
def guard(who: str):
    """While the body runs (the outermost guard only), a crash in a compiled kernel
    prints what happened and what to do before the process dies.  A context manager
    around the kernel calls, not a decorator of the public functions: a wrapper's frame
    would shift every warning's ``stacklevel`` off the caller's line."""
    entered = False
    with _LOCK:
        if _state["depth"] == 0 and not _state["failed"] and _enabled():
            try:
                _install(who)
                entered = True
            except Exception:  # no libc, no LLVM target: run without the message
                _state["failed"] = True
        elif _state["depth"] > 0:
            entered = True
        if entered:
            _state["depth"] += 1
    try:
        yield
    finally:
        if entered:
            with _LOCK:
                _state["depth"] -= 1
                if _state["depth"] == 0:
                    _linger(who)
