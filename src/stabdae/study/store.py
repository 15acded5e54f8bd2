"""A study's store: the grid points' tables (:class:`~stabdae._ensemble_dataset.Table`),
kept in memory as they finish and written to ``OUT.nc.parts`` in chunks, from which a run
that was stopped resumes; and the one dataset made of them all (:func:`combine`).

Why chunks of plain arrays and not a NetCDF file per grid point (or a zarr store written
region by region): a grid point's NetCDF part cost about 100 ms to write and 50 ms to
read back (HDF5's cost per variable, ~60 variables), more than its ensemble on the main
study; a store written region by region needs every writer to reach one file system,
which a dask cluster's workers need not share with the process that runs the study.
Here only that process writes: the workers return their tables, and a chunk is written
at most every :data:`FLUSH_SECONDS` (and when the run stops, for any reason but a kill)
with ``numpy.savez``, atomically (a temporary file renamed into place), its SHA-256 and
grid points recorded in the manifest (``study.json``), which is itself replaced
atomically.  When every grid point is done, the last of them go to the chunks only if
the dataset cannot be written (its write is the one that matters then).  A kill loses
at most the grid points since the last chunk; a chunk whose
bytes differ from the recorded checksum, or that cannot be read, is computed again.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import re
import stat
import time
from pathlib import Path

import numpy as np
import xarray as xr

from .._ensemble_dataset import NOT_RUN, Table
from .._loading import file_sha256
from .._schema import cf_dataset, deferred_interrupt

#: the longest time finished grid points wait in memory before they are written (the
#: environment variable ``STABDAE_FLUSH_SECONDS`` sets another; 0: a chunk per point)
FLUSH_SECONDS = 2.0


def _flush_seconds() -> float:
    text = os.environ.get("STABDAE_FLUSH_SECONDS")
    if text is None:
        return FLUSH_SECONDS
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value >= 0.0:
        raise ValueError(f"STABDAE_FLUSH_SECONDS={text!r}: expected a number of seconds ≥ 0")
    return value


#: the only names a chunk can have: :meth:`Store.flush` makes them, and a manifest's
#: entry of any other name (``../notes.txt``, an absolute path) is not a chunk
CHUNK_NAME = re.compile(r"chunk-(0|[1-9][0-9]{0,17})\.npz")


def regular_file(path: Path) -> bool:
    """Whether ``path`` is a regular file itself (not a link, a FIFO, a device or a
    folder): the only kind of file a parts folder is read from or removed from.  A link
    could lead out of the folder; a FIFO would block the run on its first read."""
    try:
        return stat.S_ISREG(os.lstat(path).st_mode)
    except OSError:
        return False


def file_kind(path: Path) -> str:
    """What ``path`` is, in words, for a message."""
    try:
        mode = os.lstat(path).st_mode
    except OSError:
        return "missing"
    for test, word in ((stat.S_ISLNK, "a symbolic link"), (stat.S_ISFIFO, "a FIFO"),
                       (stat.S_ISDIR, "a folder"), (stat.S_ISSOCK, "a socket"),
                       (stat.S_ISCHR, "a device"), (stat.S_ISBLK, "a device")):  # fmt: skip
        if test(mode):
            return word
    return "a regular file" if stat.S_ISREG(mode) else "not a regular file"


def _shown(name) -> str:
    """A manifest entry's name as a message shows it: a crafted one may be megabytes."""
    text = repr(name)
    return text if len(text) <= 240 else text[:239] + "…"


class Manifest:
    """``OUTPUT.parts/study.json``: the run key, the study file (resolved) and, for every
    chunk written, its SHA-256 and grid points, so that a chunk altered afterwards is
    computed again.  Only the process that runs the study writes it.

    A manifest is read as data: an entry whose name is not one :meth:`Store.flush`
    makes (:data:`CHUNK_NAME`) is left out, and said in ``refused``, so that no name in
    it can lead outside the folder."""

    NAME = "study.json"

    def __init__(self, parts: Path, fingerprint: str, study: str, chunks=None, refused=()):
        self.parts, self.fingerprint, self.study = parts, fingerprint, study
        self.chunks = dict(chunks or {})
        self.refused = list(refused)

    @classmethod
    def read(cls, parts: Path):
        """The manifest in ``parts``, or None when there is none a stabdae run wrote (or
        ``study.json`` is not a regular file)."""
        path = parts / cls.NAME
        if not regular_file(path):
            return None
        try:
            raw = json.loads(path.read_text())
            chunks, refused = {}, []
            for k, v in raw.get("chunks", {}).items():
                if not (isinstance(k, str) and CHUNK_NAME.fullmatch(k)):
                    refused.append(_shown(k))
                    continue
                chunks[k] = {"sha256": str(v["sha256"]),
                             "points": [int(i) for i in v["points"]]}  # fmt: skip
            return cls(parts, str(raw["fingerprint"]), str(raw["study"]), chunks, refused)
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            return None

    def save(self) -> None:
        text = json.dumps({"fingerprint": self.fingerprint, "study": self.study,
                           "chunks": self.chunks}, sort_keys=True)  # fmt: skip
        tmp = self.parts / f".{self.NAME}.tmp"
        # a kill leaves the old or the new one
        _write_whole(tmp, self.parts / self.NAME, text.encode(), "the run's manifest")


#: what a run writes in ``OUTPUT.parts`` (and :func:`clear` removes; ``point-*.nc``: the
#: parts of earlier versions, one NetCDF file per grid point)
_OURS = ("chunk-*.npz", ".chunk-*.tmp", Manifest.NAME, f".{Manifest.NAME}.tmp", "point-*.nc",
         ".point-*.tmp")  # fmt: skip


def clear(parts: Path) -> None:
    """Remove what stabdae wrote in ``parts`` (its chunks, manifest and temporary files:
    regular files of those names), nothing else."""
    for pattern in _OURS:
        for path in parts.glob(pattern):
            if regular_file(path):
                path.unlink()


class Store:
    """The finished grid points' tables, by grid point, and the chunks they are written
    in (:data:`FLUSH_SECONDS`)."""

    def __init__(self, manifest: Manifest):
        self.manifest = manifest
        self.tables: dict[int, Table] = {}
        self._pending: list[int] = []
        self._flushed = time.monotonic()
        self._every = _flush_seconds()
        numbers = [_chunk_number(name) for name in manifest.chunks]
        self._next = max(numbers, default=-1) + 1

    def resume(self, npoints: int, log) -> None:
        """Read the chunks the manifest records; a chunk that cannot be used is removed
        (its grid points are computed again, and ``log`` says why), and so is any chunk
        file the manifest does not record (written when a kill came before the
        manifest)."""
        parts = self.manifest.parts
        for name in self.manifest.refused:
            log(f"{parts / Manifest.NAME}: the entry {name} is not the name of a chunk a "
                "run writes: ignored (nothing of that name is opened or removed)")  # fmt: skip
        for path in parts.glob("chunk-*.npz"):
            if path.name not in self.manifest.chunks and regular_file(path):
                path.unlink()
        for name, entry in sorted(self.manifest.chunks.items()):
            path = parts / name
            why = None
            if not os.path.lexists(path):
                why = "is missing"
            elif not regular_file(path):
                # never opened, never removed: a link may lead anywhere, a FIFO blocks
                points = ", ".join(map(str, entry["points"]))
                log(f"grid points {points}: {path} is {file_kind(path)}, not a chunk a run "
                    "writes: left as it is, and its points computed again")  # fmt: skip
                del self.manifest.chunks[name]
                continue
            elif file_sha256(path) != entry["sha256"]:
                why = "does not match its recorded checksum"
            else:
                try:
                    tables = _unpack(path, self.manifest.fingerprint)
                except Exception as exc:  # any reader error: a damaged or foreign file
                    why = f"unreadable ({type(exc).__name__}: {exc})"
                else:
                    if sorted(tables) != entry["points"] or max(tables, default=0) >= npoints:
                        why = "holds other grid points than recorded"
            if why is not None:
                points = ", ".join(map(str, entry["points"]))
                log(f"grid points {points}: {name} {why}: computing them again")
                path.unlink(missing_ok=True)
                del self.manifest.chunks[name]
                continue
            self.tables.update(tables)
        self.manifest.save()

    def add(self, index: int, table: Table) -> None:
        """Grid point ``index`` is done: kept, and written with the others waiting once
        the last chunk is :data:`FLUSH_SECONDS` old."""
        self.tables[index] = table
        self._pending.append(index)
        if time.monotonic() - self._flushed >= self._every:
            self.flush()

    def flush(self) -> None:
        """Write the grid points waiting as one chunk and record it."""
        self._flushed = time.monotonic()
        if not self._pending:
            return
        with deferred_interrupt():  # a chunk and its record, whole or not at all
            points = sorted(self._pending)
            buffer = io.BytesIO()
            np.savez(buffer, **_pack({i: self.tables[i] for i in points},
                                     self.manifest.fingerprint))  # fmt: skip
            data = buffer.getvalue()
            parts = self.manifest.parts
            while os.path.lexists(parts / f"chunk-{self._next}.npz"):  # one left alone
                self._next += 1
            name = f"chunk-{self._next}.npz"
            tmp = parts / f".{name}.tmp"
            _write_whole(tmp, parts / name, data,
                         f"grid points {', '.join(map(str, points))} (they are computed again "
                         "by the same command once there is room; the chunks written before "
                         "are kept)")  # fmt: skip
            self.manifest.chunks[name] = {"sha256": _sha256(data), "points": points}
            self.manifest.save()
            self._next += 1
            self._pending.clear()


def _write_whole(tmp: Path, target: Path, data: bytes, what: str) -> None:
    """``data`` to ``target`` through ``tmp`` (renamed into place); a write that fails (a
    full disk) leaves no temporary file and says what was not written, and where."""
    try:
        tmp.write_bytes(data)
        os.replace(tmp, target)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        reason = exc.strerror or str(exc)
        raise OSError(f"could not write {what} to {target} ({reason})") from None


def _chunk_number(name: str) -> int:
    try:
        return int(name.removeprefix("chunk-").removesuffix(".npz"))
    except ValueError:
        return -1


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


# --------------------------------------------------------------------- chunk files
def _pack(tables: dict[int, Table], fingerprint: str) -> dict:
    """The arrays of a chunk: each variable's (``d/<name>``) and coordinate's
    (``c/<name>``) values of all its tables stacked along a first axis (one array per
    name: ``numpy.savez`` costs about 0.1 ms per array); where their shapes differ, one
    flat array of them all (``r/d/<name>``) and each table's shape in ``meta``; per
    table (``<k>/d/<name>``, ``k`` the table's place in the chunk) where their types
    differ; and
    ``meta``: the run key, the grid points and, per table, the dimensions and attributes
    (JSON, as bytes)."""
    arrays = {}
    meta = {"fingerprint": fingerprint, "points": list(tables), "tables": [], "shapes": {}}
    group = list(tables.values())
    for kind, items in (("d", lambda t: {k: v[1] for k, v in t.data.items()}),
                        ("c", lambda t: {k: v.values for k, v in t.coords.items()})):
        columns: dict[str, list] = {}
        for table in group:
            for name, values in items(table).items():
                columns.setdefault(name, []).append(_plain(values))
        for name, column in columns.items():
            whole = len(column) == len(group)
            if whole and len({(a.shape, a.dtype.str) for a in column}) == 1:
                arrays[f"{kind}/{name}"] = np.stack(column)
            elif whole and len({a.dtype.str for a in column}) == 1:
                # shapes differ (grid points decided after different numbers of members):
                # one flat array and each table's shape
                arrays[f"r/{kind}/{name}"] = np.concatenate([a.ravel() for a in column])
                meta["shapes"][f"{kind}/{name}"] = [list(a.shape) for a in column]
            else:
                for k, a in enumerate(column):
                    arrays[f"{k}/{kind}/{name}"] = a
    # each variable's attributes once (the first table's), and per table only those that
    # differ from them (the JSON of every table's own was most of a chunk's cost)
    shared = {"d": {k: v[2] for k, v in group[0].data.items()},
              "c": {k: dict(v.attrs) for k, v in group[0].coords.items()}}  # fmt: skip
    meta["shared"] = {kind: {k: _jsonable(a) for k, a in d.items()} for kind, d in shared.items()}
    meta["shared_attrs"] = _jsonable(group[0].attrs)

    def own(kind, name, attrs):
        return None if _same_attrs(shared[kind].get(name), attrs) else _jsonable(attrs)

    for table in group:
        meta["tables"].append({
            "data": {name: [_dims(dims), own("d", name, attrs)]
                     for name, (dims, _, attrs) in table.data.items()},
            "coords": {name: [list(var.dims), own("c", name, dict(var.attrs))]
                       for name, var in table.coords.items()},
            "attrs": {k: _jsonable(v) for k, v in table.attrs.items()
                      if not (k in group[0].attrs and _same(group[0].attrs[k], v))},
            "absent": [k for k in group[0].attrs if k not in table.attrs],
        })  # fmt: skip
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    return arrays


def _unpack(path: Path, fingerprint: str) -> dict[int, Table]:
    """The tables of a chunk written by :func:`_pack` under the run key ``fingerprint``."""
    with np.load(path, allow_pickle=False) as npz:
        meta = json.loads(npz["meta"].tobytes().decode())
        if meta["fingerprint"] != fingerprint:
            raise ValueError("written by another run")
        stacked = {key: npz[key] for key in npz.files if key[:2] in ("d/", "c/")}
        for key, shapes in meta.get("shapes", {}).items():
            flat = npz[f"r/{key}"]
            ends = np.cumsum([math.prod(shape) for shape in shapes])
            stacked[key] = [part.reshape(shape) for part, shape
                            in zip(np.split(flat, ends[:-1]), shapes)]  # fmt: skip

        def values(kind, name, k):
            key = f"{kind}/{name}"
            return np.asarray(stacked[key][k]) if key in stacked else npz[f"{k}/{key}"]

        shared = meta["shared"]

        def attrs_of(kind, name, own):
            return _from_json(shared[kind][name] if own is None else own)

        out = {}
        for k, (i, entry) in enumerate(zip(meta["points"], meta["tables"])):
            data = {name: (tuple(dims), values("d", name, k), attrs_of("d", name, own))
                    for name, (dims, own) in entry["data"].items()}  # fmt: skip
            coords = {name: xr.Variable(tuple(dims), values("c", name, k),
                                        attrs_of("c", name, own))
                      for name, (dims, own) in entry["coords"].items()}  # fmt: skip
            attrs = {**_from_json(meta["shared_attrs"]),
                     **{k: _from_json(v) for k, v in entry["attrs"].items()}}
            for key in entry["absent"]:
                del attrs[key]
            out[int(i)] = Table(data, coords, attrs)
    return out


def _dims(dims) -> list:
    return [dims] if isinstance(dims, str) else list(dims)


def _plain(values) -> np.ndarray:
    """``values`` as an array ``numpy.load`` reads without pickle (text as unicode)."""
    arr = np.asarray(values)
    return arr.astype(str) if arr.dtype.hasobject else arr


def _jsonable(value):
    """Attribute values as JSON, numpy types tagged with their dtype so that they come
    back as they were (floats in JSON are exact: Python writes the shortest repr that
    reads back to the same double)."""
    if isinstance(value, dict):
        return {"__dict__": {str(k): _jsonable(v) for k, v in value.items()}}
    if isinstance(value, np.ndarray):
        return {"__ndarray__": value.tolist(), "dtype": value.dtype.str}
    if isinstance(value, np.generic):
        return {"__scalar__": value.item(), "dtype": value.dtype.str}
    if isinstance(value, (list, tuple)):
        return {"__list__": [_jsonable(v) for v in value], "tuple": isinstance(value, tuple)}
    return value


def _from_json(value):
    if isinstance(value, dict):
        if "__dict__" in value:
            return {k: _from_json(v) for k, v in value["__dict__"].items()}
        if "__ndarray__" in value:
            return np.array(value["__ndarray__"], dtype=np.dtype(value["dtype"]))
        if "__scalar__" in value:
            return np.dtype(value["dtype"]).type(value["__scalar__"])
        if "__list__" in value:
            items = [_from_json(v) for v in value["__list__"]]
            return tuple(items) if value["tuple"] else items
    return value


# --------------------------------------------------------------------- the dataset
def _same(a, b) -> bool:
    """Whether two attribute values are equal (arrays element by element, NaN equal to
    NaN), as xarray's ``drop_conflicts`` compares them."""
    if a is b:
        return True
    if type(a) is type(b) and isinstance(a, (str, int, bool)):
        return a == b
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (a != a and b != b)
    try:
        return bool(np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True))
    except TypeError:  # not numbers
        try:
            return bool(np.all(np.asarray(a) == np.asarray(b)))
        except Exception:  # different shapes or types
            return False


def _same_attrs(a: dict | None, b: dict) -> bool:
    return a is not None and a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)


def common_attrs(many: list[dict]) -> dict:
    """The attributes that no two of ``many`` give different values (xarray's
    ``combine_attrs="drop_conflicts"``): each name's first value, unless another differs."""
    out, dropped = {}, set()
    for attrs in many:
        for key, val in attrs.items():
            if key in dropped:
                continue
            if key not in out:
                out[key] = val
            elif not _same(out[key], val):
                del out[key]
                dropped.add(key)
    return out


def _padded_sizes(tables: list[Table]) -> dict:
    """The dimensions whose sizes differ between the tables (grid points run until
    decided ran different numbers of members): ``{dim: (largest size, its table)}``."""
    seen: dict = {}
    for i, t in enumerate(tables):
        for vdims, values, _ in t.data.values():
            for d, n in zip(_dims(vdims), np.shape(values)):
                seen.setdefault(d, {})[i] = n
    out = {}
    for d, per in seen.items():
        if len(set(per.values())) > 1:
            owner = max(per, key=per.get)
            out[d] = (per[owner], owner)
    return out


def _column(name: str, vdims: tuple, values: list, sizes: dict) -> np.ndarray:
    """The tables' ``values`` of one variable stacked on a new first axis, each padded to
    ``sizes`` along its dimensions: NaN for real numbers, a member's not-run code
    (:data:`.._ensemble_dataset.NOT_RUN`) or 0 for integers."""
    shapes = {v.shape for v in values}
    if len(shapes) == 1 and not any(d in sizes for d in vdims):
        return np.stack(values)
    shape = tuple(sizes[d][0] if d in sizes else n for d, n in zip(vdims, values[0].shape))
    dtype = np.result_type(*values)
    fill = np.nan if dtype.kind in "fc" else NOT_RUN.get(name, 0)
    out = np.full((len(values), *shape), fill, dtype=dtype)
    for k, v in enumerate(values):
        out[(k, *(slice(0, n) for n in v.shape))] = v
    return out


def stack(tables: list[Table], axes: dict[str, np.ndarray]) -> xr.Dataset:
    """One dataset of the grid's tables (C order over ``axes``, dimension name → values):
    every variable gains the axes as its leading dimensions; the coordinates are the first
    table's, the attributes those all tables share (:func:`common_attrs`).  Two axes or
    more are sorted by value, as xarray's unstacking of the grid does."""
    dims = tuple(axes)
    shape = tuple(len(v) for v in axes.values())
    first = tables[0]
    sizes = _padded_sizes(tables)
    data = {}
    for name, (vdims, _, _) in first.data.items():
        vd = tuple(_dims(vdims))
        column = _column(name, vd, [np.asarray(t.data[name][1]) for t in tables], sizes)
        attrs = common_attrs([t.data[name][2] for t in tables])
        data[name] = xr.Variable(dims + vd, column.reshape(shape + column.shape[1:]),
                                 attrs)  # fmt: skip
    coords = dict(first.coords)
    for d, (_, owner) in sizes.items():  # the coordinates of the longest
        for k, c in tables[owner].coords.items():
            if d in c.dims:
                coords[k] = c
    for d, values in axes.items():
        coords[d] = xr.Variable(d, np.asarray(values))
    ds = cf_dataset(data, coords=coords, attrs=common_attrs([t.attrs for t in tables]))
    if len(dims) > 1 and any(np.any(np.diff(np.asarray(v)) <= 0) for v in axes.values()):
        ds = ds.sortby(list(dims))
    return ds
