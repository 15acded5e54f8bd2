"""The on-disk cache's file format, as data: a JSON index (never unpickled) and data
files headed by their key and a SHA-256 checksum, checked before their compiled code is
unpickled (:class:`_CheckedCacheFile`).  The kernel cache (:mod:`.cache`) writes it, and
so do the library's own ``@njit(cache=True)`` functions in numba's cache folders
(:func:`checked_library_caches`), so that a damaged or crafted entry in either is
compiled again with one warning that names it.

This module imports nothing of the library's: :mod:`stabdae` installs the library's
checked caches before the first of its modules decorates a function.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import pickle
import re
import warnings

try:  # numba's caching classes are private: without them kernels compile in memory
    from numba.core.caching import (
        CompileResultCacheImpl,
        FunctionCache,
        IndexDataCacheFile,
        _CacheLocator,
    )
except ImportError:  # pragma: no cover - exercised by a test that hides the module
    CompileResultCacheImpl = FunctionCache = IndexDataCacheFile = _CacheLocator = object
    CACHING_API = False
else:
    CACHING_API = True

__all__ = ["CACHING_API", "checked_library_caches"]

_WARNED: set[str] = set()


def _warn_file_once(message: str, key: str | None = None) -> None:
    """Warn once per file (``key``) or kind of message."""
    kind = key or message.split(" (", 1)[0]
    if kind not in _WARNED:
        _WARNED.add(kind)
        warnings.warn(f"stabdae: {message}", RuntimeWarning, stacklevel=3)


class _CheckedCacheFile(IndexDataCacheFile):
    """numba's index and data files as data: the index is JSON (never unpickled), and
    each data file is headed by what it is: the cache's key, its entry's name, the
    signature it was compiled for and the SHA-256 of those and of the compiled code.  A
    data file that does not match (damaged, cut short, or another entry's swapped in) is
    refused before anything in it is unpickled, so it is compiled again and rewritten,
    never run.  An index in another format (numba's own pickle, an older stabdae's) is
    not read at all: it is as if there were none, and the next save replaces it."""

    _MAGIC = b"stabdae kernel cache entry 2\n"
    _INDEX_MAGIC = b"stabdae kernel cache index 1\n"

    def __init__(self, cache_path, filename_base, source_stamp):  # noqa: D107
        super().__init__(cache_path, filename_base, source_stamp)
        self._entry_name = re.compile(re.escape(filename_base) + r"\.[1-9][0-9]{0,8}\.nbc")
        self._signature = ""

    def _stamp(self) -> str:
        stamp = self._source_stamp
        return stamp if isinstance(stamp, str) else repr(stamp)

    def _digest(self, name: str, payload: bytes) -> str:
        h = hashlib.sha256(self._stamp().encode())
        h.update(b"\x00" + name.encode() + b"\x00" + self._signature.encode() + b"\x00")
        h.update(payload)
        return h.hexdigest()

    def _read_index(self) -> dict:
        """The index's entries (signature text → data file name); raises
        :class:`_EntryMismatch` naming the file when it is ours but damaged."""
        try:
            with open(self._index_path, "rb") as f:
                raw = f.read()
        except FileNotFoundError:
            return {}
        if not raw.startswith(self._INDEX_MAGIC):
            return {}  # another writer's format: never unpickled, replaced on save
        try:
            doc = json.loads(raw[len(self._INDEX_MAGIC):].decode())
            entries = doc["entries"]
            fresh = doc["numba"] == self._version and doc["stamp"] == self._stamp()
            if not (isinstance(entries, dict) and all(
                    isinstance(k, str) and isinstance(v, str) and self._entry_name.fullmatch(v)
                    for k, v in entries.items())):  # fmt: skip
                raise ValueError("entries that are not this function's data files")
        except (ValueError, KeyError, TypeError, UnicodeDecodeError) as exc:
            raise _EntryMismatch(f"the cache index {self._index_path} is damaged "
                                 f"({type(exc).__name__}: {exc})") from None  # fmt: skip
        return entries if fresh else {}

    def _load_index(self):
        return self._read_index()

    def _save_index(self, overloads):
        text = json.dumps({"numba": self._version, "stamp": self._stamp(),
                           "entries": overloads}, sort_keys=True)  # fmt: skip
        with self._open_for_write(self._index_path) as f:
            f.write(self._INDEX_MAGIC + text.encode())

    def save(self, key, data):
        try:
            overloads = self._read_index()
        except _EntryMismatch:  # a damaged index is replaced
            overloads = {}
        self._signature = repr(key)
        name = overloads.get(self._signature)
        if name is None:
            taken = set(overloads.values())
            name = next(self._data_name(i) for i in itertools.count(1)
                        if self._data_name(i) not in taken)  # fmt: skip
            overloads[self._signature] = name
            self._save_index(overloads)
        self._save_data(name, data)

    def load(self, key):
        self._signature = repr(key)
        name = self._read_index().get(self._signature)
        if name is None:
            return None
        try:
            return self._load_data(name)
        except FileNotFoundError:  # removed while the index still named it
            return None

    def _save_data(self, name, data):
        payload = self._dump(data)
        head = f"{self._stamp()} {name} {self._digest(name, payload)}\n".encode()
        with self._open_for_write(self._data_path(name)) as f:
            f.write(self._MAGIC + head + payload)

    def _load_data(self, name):
        path = self._data_path(name)
        with open(path, "rb") as f:
            raw = f.read()
        head, _, payload = raw[len(self._MAGIC):].partition(b"\n")
        want = f"{self._stamp()} {name} {self._digest(name, payload)}".encode()
        if not raw.startswith(self._MAGIC) or head != want:
            raise _EntryMismatch(f"the cache entry {path} does not match its recorded key "
                                 "and checksum (damaged, or another kernel's)")  # fmt: skip
        return pickle.loads(payload)


class _EntryMismatch(Exception):
    pass


class _CheckedFunctionCache(FunctionCache):
    """numba's cache of the library's own ``@njit(cache=True)`` functions (where numba
    puts it), in the checked format of :class:`_CheckedCacheFile`: a damaged entry is
    compiled again with one warning that names it, instead of an unpickling error on
    every later run."""

    def __init__(self, py_func):  # noqa: D107
        super().__init__(py_func)
        self._cache_file = _CheckedCacheFile(
            cache_path=self._cache_path, filename_base=self._impl.filename_base,
            source_stamp=self._impl.locator.get_source_stamp())  # fmt: skip

    def load_overload(self, sig, target_context):
        try:
            return super().load_overload(sig, target_context)
        except Exception as exc:
            _warn_file_once(f"numba's on-disk cache entry of {self._py_func.__qualname__} could "
                       f"not be loaded ({type(exc).__name__}: {exc}); compiling it again",
                       key=f"{self._cache_path}/{self._impl.filename_base}")  # fmt: skip
            return None

    def save_overload(self, sig, data):
        try:
            super().save_overload(sig, data)
        except Exception as exc:
            _warn_file_once(f"a compiled function could not be written to numba's cache "
                       f"{self._cache_path} ({type(exc).__name__}: {exc}); it runs, compiled "
                       "in memory")  # fmt: skip


def checked_library_caches() -> None:
    """Give the library's own ``cache=True`` functions (those of ``stabdae.*`` modules, not
    the scenes, which are model files) the checked cache of :class:`_CheckedFunctionCache`.

    numba builds a function's cache when it is decorated (``Dispatcher.enable_caching``),
    so this wraps that method once, before the first library module is imported; every
    other function (a user's model, another library's) keeps numba's own cache and
    format.  Without numba's private caching API it does nothing."""
    from numba.core.dispatcher import Dispatcher

    plain = Dispatcher.enable_caching
    if not CACHING_API or getattr(plain, "_stabdae_checked", False):
        return

    def enable_caching(self):
        module = getattr(self.py_func, "__module__", None) or ""
        if module.startswith("stabdae.") and not module.startswith("stabdae.scenes."):
            self._cache = _CheckedFunctionCache(self.py_func)
        else:
            plain(self)

    enable_caching._stabdae_checked = True
    Dispatcher.enable_caching = enable_caching
