"""``stabdae run``: a study's grid of ensembles, resumable and lossless.

Each grid point is one :func:`stabdae.ensemble` with the study's seed (the same α⁰ targets
at every point: common random numbers, so that differences across the grid are the
parameters' and not the sample's).  Its table of arrays is kept as soon as it is done
and written, with the others that finished since, in a chunk of ``OUT.nc.parts``
(:mod:`.store`: at most every couple of seconds, atomically, its checksum recorded); a
run that is stopped and started again with the same command (``--force`` included)
skips the points already there.  When every point is in, they make one dataset, written
once to ``OUT.nc`` (atomically), and the parts are removed.  Nothing depends on where a
point ran (in-process, or on dask workers), so the dataset is the same either way.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
import re
import socket
import sys
import time
import warnings
from pathlib import Path

import netCDF4
import numpy as np
import xarray as xr

from .._boundary import boundary
from .._ensemble import ensemble_table
from .._ensemble_dataset import Table
from .._integrate import IntegrationWarning
from .._loading import local_sources
from .._schema import append_history, utc_now, write_netcdf
from .._version import __version__
from ..engine.cache import function_fingerprint, library_fingerprint
from ..engine.crash import guard
from ..engine.jit import compile_seconds
from .report import summary
from .spec import Study, StudyError, load_study, members_text, most_members
from .store import Manifest, Store, clear, file_kind, regular_file, stack
from .theory import axis_units, for_study

__all__ = ["run_study", "run_point", "combine"]

#: attributes that say when/how fast, not what, and the parts' bookkeeping: left out of
#: the study dataset
_VOLATILE = ("wall_sample_s", "wall_integrate_s", "wall_dataset_s", "wall_compile_s",
             "created_at", "history", "threads", "stabdae_run_key", "grid_point")  # fmt: skip
#: the volatile attributes that time a point's own work (its sampling and integration)
_WORK = ("wall_sample_s", "wall_integrate_s")


def axis_name(canon: str, all_names) -> str:
    """Dataset name of a sweep axis: ``tau``, ``omega``, ``g``, ``A_0_1`` (prefixed with
    the section where two sections share a key)."""
    section, key = canon.split(".", 1)
    key = key.replace("[", "_").replace(",", "_").replace("]", "")
    keys = [c.split(".", 1)[1] for c in all_names]
    if keys.count(canon.split(".", 1)[1]) > 1:
        return f"{section}_{key}"
    return key


def run_point(study: Study, values: dict, threads=None, progress=None) -> Table:
    """The ensemble at one grid point, on the study's common sample grid (with
    ``[search]``: the boundary search at that point), as a table of arrays (with the
    wall times of its sampling and integration, :data:`_VOLATILE`)."""
    s = study.setup(values)
    ens = study.ensemble
    if study.search is not None:
        return search_point(study, s, threads, progress)
    # stopped members: the study's summary counts them; one crash guard for the point's
    # kernels (each kernel call's own, inside it, then costs nothing)
    with warnings.catch_warnings(), guard("ensemble"):
        warnings.simplefilter("ignore", IntegrationWarning)
        table = ensemble_table(study.model, s["law"], s["scheme"], s["tau"], s["t_end"],
                               members=ens["members"], radius=tuple(ens["radius"]),
                               seed=ens["seed"], save_dt=s["save_dt"], params=s["params"],
                               epsilon=s["epsilon"], divergence=s["divergence"],
                               block=ens["block"], threads=threads, progress=progress,
                               states=ens["states"])  # fmt: skip
    if s["stride"] > 1:  # a step spans several samples: NaN between the steps
        stride = s["stride"]
        time_ = table.coords["time"]
        t = time_.values
        nsave = (t.size - 1) * stride + 1
        times = t[0] + (np.arange(nsave) / stride) * float(t[1] - t[0])
        dims, norms, attrs = table.data["residual_norm"]
        full = np.full((norms.shape[0], nsave), np.nan, dtype=norms.dtype)
        full[:, ::stride] = norms
        table.data["residual_norm"] = (dims, full, attrs)
        table.coords["time"] = xr.Variable("time", times, time_.attrs)
    return table


def search_point(study: Study, s: dict, threads=None, progress=None) -> Table:
    """The boundary search (:func:`stabdae.boundary`) at one grid point."""
    ens, search = study.ensemble, study.search
    ds = boundary(study.model, s["law"], s["scheme"], tau=search["tau"], rtol=search["rtol"],
                  q=search["q"], members=ens["members"],
                  search_members=search["search_members"], steps=search["steps"],
                  t_end=search["t_end"], radius=tuple(ens["radius"]), seed=ens["seed"],
                  params=s["params"], epsilon=s["epsilon"], divergence=s["divergence"],
                  block=ens["block"], threads=threads,
                  progress=progress if callable(progress) else False,
                  confidence=search.get("confidence"))  # fmt: skip
    return Table.from_dataset(ds)


def _fingerprint(study: Study) -> str:
    """The run key: everything that decides a grid point's numbers — the study file (its
    parameters, law, scheme, run and grid), the ensemble settings as run (``--members``),
    the model file and the modules of its folder that it imports, the model's functions
    with the helpers and values they read (wherever those live), and the library (its
    source, numba's version, FMA)."""
    h = hashlib.sha256(study.text)
    h.update(json.dumps(study.ensemble, sort_keys=True).encode())
    h.update(__version__.encode())
    h.update(library_fingerprint().encode())
    for path, data in _sources(study).items():
        h.update(path.name.encode() + b"\0" + data)
    # the model's functions as the kernels are keyed: helpers they call wherever those
    # live, and the values of the globals and module attributes they read
    model = study.model
    pieces = sorted({**model.functions, "energy": model.energy,
                     "outputs": model.outputs}.items())  # fmt: skip
    # The model's own module name is where it was loaded from, not what it computes: a
    # scene is stabdae.scenes.NAME from a wheel and a file's module from a source tree,
    # and a dask worker may have either.  Its source is in the key by content.
    own = {getattr(getattr(fn, "py_func", fn), "__module__", None) for _, fn in pieces}
    own.discard(None)
    for piece, fn in pieces:
        text = function_fingerprint(fn) if fn is not None else None
        for name in own:
            text = text and text.replace(name + ".", "<model>.")
        h.update(f"{piece}={text}".encode())
    return h.hexdigest()


def _sources(study: Study) -> dict:
    """The model's source files' bytes as the study read them (read now for a study made
    without :func:`load_study`)."""
    if study.model_sources or study.model_file is None:
        return study.model_sources
    return local_sources(study.model_file)


def output_path(study: Study, output=None) -> Path:
    """Where the study's dataset goes: ``output`` (a file, or a folder — an existing one or
    one written with a trailing slash — which gets ``<study>.nc``), else the study's
    ``[output] path``, else ``results/<study>.nc``."""
    if output is not None and "\0" in str(output):
        raise StudyError(f"stabdae run: the output path (-o) contains a NUL character: "
                         f"{str(output)!r}")  # fmt: skip
    if output is None:
        if study.output_refused:
            raise StudyError(study.output_refused)
        return study.output or Path("results") / f"{study.path.stem}.nc"
    out = Path(output)
    if out.is_dir() or str(output).endswith(("/", "\\")):
        return out / f"{study.path.stem}.nc"
    return out


def _is_stabdae_dataset(path: Path) -> bool:
    try:  # the global attributes' names only (xarray would decode every variable's)
        with netCDF4.Dataset(path) as nc:
            return "stabdae_version" in nc.ncattrs()
    except Exception:  # not NetCDF, or unreadable
        return False


def run_study(study, output=None, *, force: bool = False, members: int | None = None,
              workers: int | None = None, scheduler: str | None = None, progress: bool = True,
              threads: int | None = None, log=print,
              trust_model: bool = False) -> Path:  # fmt: skip
    """Run every grid point of ``study`` (a :class:`Study` or a path) and write the dataset.

    Returns the output path.  Raises ``FileExistsError`` when the output exists and
    ``force`` is false (``force`` replaces it).  Resumes from ``OUTPUT.parts`` when they
    carry this run's key, from whatever folder the study is named: parts of the same study
    file written under another key (the study file, its model or the library changed) are
    discarded, and each part is checked before use (it opens, carries the run key and its
    own grid point, and matches the checksum recorded when it was written; otherwise it is
    computed again).  Parts of another study file are an error, which ``force`` turns into
    discarding them.  Only files a stabdae run wrote are ever removed: an ``OUTPUT.parts``
    folder without a run's manifest is refused, ``force`` or not.
    """
    if not isinstance(study, Study):
        study = load_study(study, members=members, trust_model=trust_model)
    out = output_path(study, output)
    if out.exists() and not force:
        raise FileExistsError(f"{out} exists; pass --force to overwrite it")
    if out.exists() and not _is_stabdae_dataset(out):
        raise FileExistsError(f"{out} exists and is not a stabdae dataset; it is not replaced "
                              "(give another output with -o)")  # fmt: skip
    parts = out.with_name(out.name + ".parts")
    if os.path.lexists(parts) and (parts.is_symlink() or not parts.is_dir()):
        # before any computing: a link would put the parts, and their removal, elsewhere
        raise FileExistsError(f"{parts} is {file_kind(parts)}, not a folder of a run's parts; "
                              "it is left as it is: move it away or give another output "
                              "with -o")  # fmt: skip
    stamp = _fingerprint(study)
    log(study.describe())
    existed = parts.exists() and any(p.name != "lock" for p in parts.iterdir())
    if existed and Manifest.read(parts) is None:  # before the lock: create nothing there
        raise FileExistsError(
            f"{parts} exists and was not written by a stabdae run (it has no readable "
            f"{Manifest.NAME}); it is left as it is: move it away or give another output "
            "with -o"
        )
    try:
        parts.mkdir(parents=True, exist_ok=True)
        lock = _lock(parts)  # first: nothing below may remove another live run's files
    except PermissionError as exc:  # before any computing: nothing is lost
        raise PermissionError(f"cannot write in {out.parent} ({exc.strerror}); give an "
                              "output folder you can write with -o") from None  # fmt: skip
    try:
        for orphan in out.parent.glob(f".{out.name}.*.tmp"):  # left by a killed write
            if regular_file(orphan):
                orphan.unlink(missing_ok=True)
        old = Manifest.read(parts) if existed else None
        if old is not None and old.fingerprint != stamp:
            if old.study == str(study.path.resolve()):
                log(f"the study file, its model or the library changed since {parts} was "
                    "written: starting over")  # fmt: skip
            elif force:
                log(f"--force: discarding the parts of {old.study} in {parts}")
            else:
                raise FileExistsError(
                    f"{parts} holds a run of a different study ({old.study}); pass --force "
                    "to discard it"
                )
            clear(parts)
            old = None
        manifest = old or Manifest(parts, stamp, str(study.path.resolve()))
        return _run_locked(study, out, parts, manifest, workers, scheduler, progress,
                           threads, log)  # fmt: skip
    finally:
        lock.unlink(missing_ok=True)
        if parts.exists() and not any(parts.iterdir()):
            parts.rmdir()


def _lock(parts: Path) -> Path:
    """Take ``parts/lock`` for this process; refuse when a live process holds it (two runs
    writing one output would remove each other's parts), take over a dead one's."""
    lock = parts / "lock"
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            if not regular_file(lock):  # a FIFO would block the read below
                raise FileExistsError(f"{lock} is {file_kind(lock)}, not the lock a run "
                                      "writes; it is left as it is: move it away or give "
                                      "another output with -o") from None  # fmt: skip
            try:
                pid = int(lock.read_text().split()[0])
            except (OSError, ValueError, IndexError):
                pid = None
            if pid is not None and pid != os.getpid() and _alive(pid):
                raise FileExistsError(
                    f"{parts} is being written by another stabdae run (process {pid}); wait "
                    f"for it to finish, or remove {lock} if that process is gone"
                ) from None
            lock.unlink(missing_ok=True)  # left by a run that died
            continue
        with os.fdopen(fd, "w") as f:
            f.write(f"{os.getpid()} {socket.gethostname()}\n")
        return lock
    raise FileExistsError(f"could not take {lock}")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process
        return True
    return True


def _run_locked(study, out, parts, manifest, workers, scheduler, progress, threads,
                log) -> Path:  # fmt: skip
    manifest.save()
    points = list(study.points())
    store = Store(manifest)
    store.resume(len(points), log)
    todo = [(i, values) for i, (_, values) in enumerate(points) if i not in store.tables]
    if len(todo) < len(points):
        log(f"resuming: {len(points) - len(todo)} of {len(points)} grid points already done")
    start, compiling = time.perf_counter(), compile_seconds()
    bar = _Progress(len(points), len(points) - len(todo), _work_per_point(study), progress)
    work = [0.0]  # the points' sampling and integration, in seconds

    def done(i: int, table: Table) -> None:
        work[0] += sum(float(table.attrs.get(k, 0.0)) for k in _WORK)
        for key in _VOLATILE:
            table.attrs.pop(key, None)
        store.add(i, table)
        bar.point_done(_members_used(table))

    finished = False
    try:
        if workers or scheduler:
            _run_dask(study, todo, done, workers, scheduler, manifest.fingerprint)
        else:
            for i, values in todo:
                report = bar.note if study.search is not None else bar.members
                done(i, run_point(study, values, threads=threads, progress=report))
        finished = True
    finally:  # the points done are written whatever stopped the run (a kill aside)
        bar.close()
        if not finished:
            store.flush()
    try:
        ds = combine(study, [store.tables[i] for i in range(len(points))])
        if not study.setup()["law"].is_constant and study.search is None:
            ds = _with_path_theory(study, ds)
        ds.attrs["wall_run_s"] = time.perf_counter() - start
        write_netcdf(ds, out)
    except BaseException:
        # the last points go to the store only when the dataset could not be written
        # (a full disk, Ctrl-C): a run again resumes from them
        store.flush()
        raise
    clear(parts)
    left = sorted(p.name for p in parts.iterdir() if p.name != "lock") if parts.is_dir() else []
    log(summary(ds))
    if left:  # files no run wrote (a FIFO under a chunk's name, a user's): theirs to remove
        shown = ", ".join(left[:5]) + (f" and {len(left) - 5} more" if len(left) > 5 else "")
        log(f"{parts} is left in place: it holds {shown}, which no run wrote")
    wall, compiled = time.perf_counter() - start, compile_seconds() - compiling
    timing = ""
    if todo and not (workers or scheduler):  # (on workers, the times are theirs)
        # the points' own times leave compiling out; it is counted once, here
        timing = (f" ({len(todo)} grid points in {wall:.2f} s: sampling and integration "
                  f"{work[0]:.2f} s, compiling or loading compiled code {compiled:.2f} s, "
                  f"the rest {wall - work[0] - compiled:.2f} s)")  # fmt: skip
    log(f"dataset written to {out}{timing}")
    return out


def _with_path_theory(study: Study, ds: xr.Dataset) -> xr.Dataset:
    """State-dependent laws: the discrete conditions of Theorems 6/7 along the reference
    trajectory at every grid point (:func:`.theory.for_study`)."""
    th = for_study(study)
    names = list(study.axes)
    th = th.rename({n: axis_name(n, names) for n in names})
    keep = [v for v in th.data_vars if v.startswith("path_")]
    return ds.assign({v: th[v].assign_coords({d: ds[d] for d in th[v].dims}) for v in keep})


def _run_dask(study, todo, done, workers, scheduler, stamp):
    from dask.distributed import Client, LocalCluster, as_completed

    if scheduler:
        try:  # waits dask's distributed.comm.timeouts.connect (30 s unless configured)
            client, cluster = Client(scheduler), None
        except OSError as exc:
            raise OSError(f"could not reach the dask scheduler at {scheduler} ({exc}); the "
                          "grid points done so far are kept") from None
    else:
        cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1,
                               processes=True, dashboard_address=None)  # fmt: skip
        client = Client(cluster)
    try:
        # the study as this process read and accepted it, sent once to every worker: a
        # worker never reads the study file (an edit during the run would mix versions)
        shipped = client.scatter(shipment(study, stamp), broadcast=True)
        futures = {client.submit(_remote_point, shipped, values, pure=False): i
                   for i, values in todo}  # fmt: skip
        for fut in as_completed(futures):
            key, table = fut.result()
            if key != stamp:
                raise StudyError(
                    f"stabdae run: a dask worker computed grid point {futures[fut]} under "
                    f"another run key ({key[:12]}…, this run's {stamp[:12]}…): its stabdae, "
                    "numba or the model's helpers differ from this process's; its result is "
                    "not used (the grid points done so far are kept)"
                )
            done(futures[fut], table)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def shipment(study: Study, stamp: str) -> dict:
    """What a dask worker needs to run the study's grid points: the parsed study (without
    its model), the run key, and the model: a built-in scene by name, a model file by the
    bytes of it and of the modules of its folder it imports, with the module name this
    process loaded it under."""
    model_file = study.model_file
    files, scene = {}, None
    from .._loading import scene_dir

    if model_file is not None and model_file.parent == scene_dir().resolve():
        scene = model_file.stem
    elif model_file is not None:
        home = model_file.parent
        for path, data in _sources(study).items():
            try:
                files[path.relative_to(home).as_posix()] = data
            except ValueError:  # outside its folder: the worker finds it as this one does
                continue
    origin = getattr(study.model, "_origin", None)
    module = getattr(study.model, "_module", None)
    return {"study": dataclasses.replace(study, model=None), "key": stamp, "scene": scene,
            "files": files, "main": None if model_file is None else model_file.name,
            "module": module, "attribute": origin[1] if origin else "model"}  # fmt: skip


#: the studies a worker process has loaded, by run key (each worker loads one once)
_LOADED: dict = {}


def _remote_point(shipped: dict, values: dict):
    """One grid point on a dask worker: ``(the worker's run key, table)``."""
    key = shipped["key"]
    if key not in _LOADED:
        _LOADED[key] = _worker_study(shipped)
    study, worker_key = _LOADED[key]
    return worker_key, run_point(study, values, threads=1)


def _worker_study(shipped: dict):
    """The shipped study with its model loaded here (a scene by name; a model file from
    the shipped bytes, written to a folder of this process's), and its run key as this
    worker computes it."""
    import tempfile

    from .._loading import load_as, load_model

    study = shipped["study"]
    if shipped["scene"] is not None:
        model = load_model(shipped["scene"])
        model_file = study.model_file
    else:
        home = Path(tempfile.mkdtemp(prefix="stabdae-worker-"))
        for name, data in shipped["files"].items():
            target = home.joinpath(*name.split("/"))
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
        model_file = home / shipped["main"]
        model = load_as(model_file, shipped["module"], shipped["attribute"])
    study = dataclasses.replace(study, model=model, model_file=model_file)
    return study, _fingerprint(study)


def combine(study: Study, tables: list[Table]) -> xr.Dataset:
    """The study dataset from its grid points' tables (C order over the sweep axes):
    every variable gains the sweep axes."""
    names = list(study.axes)
    dims = [axis_name(n, names) for n in names]
    if not names:
        ds = tables[0].to_dataset()
    elif any("probe" in _dims_of(t) for t in tables):
        ds = _combine_searches(study, [t.to_dataset() for t in tables], dims)
    else:
        ds = stack(tables, {d: study.axes[n] for n, d in zip(names, dims)})
    if names:
        for n, d in zip(names, dims):
            ds[d].attrs.update(long_name=f"swept {n}", units=axis_units(n))
        for n in names:  # a swept value is a coordinate now, not an attribute
            ds.attrs.pop(n.split(".", 1)[1], None)
    for key in _VOLATILE:
        ds.attrs.pop(key, None)
    ds.attrs["study"] = study.path.name
    ds.attrs["swept"] = ", ".join(names) if names else "nothing"
    ds.attrs["created_at"] = utc_now()
    what = "boundary searches" if study.search is not None else "grid points"
    append_history(ds.attrs, f"stabdae run {study.path.name}: {len(tables)} {what} of "
                   f"{members_text(study.ensemble['members'])} combined")  # fmt: skip
    return ds


def _dims_of(table: Table) -> set:
    return {d for dims, _, _ in table.data.values()
            for d in ((dims,) if isinstance(dims, str) else dims)}  # fmt: skip


def _combine_searches(study: Study, pts: list[xr.Dataset], dims: list[str]) -> xr.Dataset:
    """Boundary searches take different numbers of probes: padded with NaN to the most,
    then concatenated along the grid."""
    size = max(p.sizes["probe"] for p in pts)
    pts = [p.reindex(probe=np.arange(size)) for p in pts]
    stacked = xr.concat(pts, dim="point", coords="minimal", compat="override",
                        combine_attrs="drop_conflicts", join="override")  # fmt: skip
    index = np.array([idx for idx, _ in study.points()])
    ds = stacked.assign_coords(
        {d: ("point", study.axes[n][index[:, k]]) for k, (n, d) in enumerate(zip(study.axes, dims))}
    )
    if len(dims) == 1:
        ds = ds.swap_dims(point=dims[0])
    else:
        ds = ds.set_index(point=dims).unstack("point")
    return ds.transpose(*dims, ...)


def _members_used(table: Table) -> int | None:
    """The members a grid point ran (None where the table does not say: a search)."""
    entry = table.data.get("members_used")
    if entry is not None:
        return int(np.asarray(entry[1]))
    entry = table.data.get("status")
    return None if entry is None or "member" not in entry[0] else int(np.shape(entry[1])[0])


def _work_per_point(study: Study) -> int:
    """A grid point's work in member runs: its ensemble's members, or for a boundary
    search the members of the probes it is expected to run (the bracket's ends, two
    beside the spectral limit, the bisection from the whole bracket down to ``rtol``,
    each of ``search_members``, and the full ensemble's confirmation), so that the bar
    moves, and its time left is estimated, per probe (:meth:`_Progress.note`)."""
    members = most_members(study.ensemble["members"])
    if study.search is None:
        return members
    s = study.search
    lo, hi = s["tau"]
    halvings = math.ceil(math.log2(max(math.log(hi / lo) / math.log1p(s["rtol"]), 1.0)))
    return (4 + halvings) * int(s["search_members"]) + members


class _Progress:
    """A progress bar over the members run (tqdm when installed, else a line on stderr per
    point); silent when ``enabled`` is false.

    The bar counts the members that ran, and its total is the members run so far plus, for
    each grid point still to run, the mean members of the points done in this run (before
    the first: ``members``, the most a point may run, :func:`_work_per_point`); a point
    run until decided usually stops well before its ``max``, so the total shrinks as the
    points show how many they need.  Its rate (and the time left) is measured from the
    first members done: before them it reads "compiling", with no rate."""

    def __init__(self, points: int, done: int, members: int, enabled: bool):
        self.points, self.done, self.members_total = points, done, members
        self.enabled = enabled and points > 0
        self._bar = None
        self._run = 0  # members run by the points done in this run
        self._finished = 0  # points done in this run
        if self.enabled:
            try:
                from tqdm import tqdm

                # the first chunk waits for the kernels to compile (or load from the cache)
                self._bar = tqdm(total=(points - done) * members, unit="member",
                                 desc="stabdae run (compiling)", file=sys.stderr,
                                 dynamic_ncols=True)  # fmt: skip
            except ImportError:
                self._bar = None
                print("stabdae run: compiling the kernels (first use only) …", file=sys.stderr)
        self._last = 0  # members run so far by the point running now
        self._started = time.perf_counter()
        self._compiling = True

    def _show(self, n: int, total: int | None = None):
        if self._bar is not None:
            if total is not None:
                self._bar.total = max(total, n)
            self._bar.update(n - self._bar.n)

    def members(self, done: int, total: int):
        """``done`` members of the point running now have run."""
        if self._compiling:
            self._compiling = False
            if self._bar is not None:
                seconds = time.perf_counter() - self._started
                self._bar.set_description(f"stabdae run (kernels ready in {seconds:.0f} s)")
                # the rate and time left from here on: the clock restarts, and what is
                # done so far (the first chunk, which waited for the compiler) is its start
                self._bar.reset(total=self._bar.total)
                self._bar.n = self._bar.last_print_n = self._bar.initial = self._run + done
                self._bar.refresh()
                self._last = done
                return
        self._last = max(self._last, done)
        self._show(self._run + self._last)

    def note(self, text: str):
        """A line from a boundary search (each probe): its members count on the bar."""
        if self._compiling:
            self.members(0, self.members_total)
        run = re.search(r" of (\d+) members", text)
        if run is not None:
            self.members(self._last + int(run.group(1)), 0)
        if self._bar is not None:
            self._bar.set_postfix_str(text.removeprefix("boundary: "), refresh=False)
        elif self.enabled:
            print(f"stabdae run: {text}", file=sys.stderr)

    def point_done(self, used: int | None = None):
        """A grid point is done, after ``used`` members (None: those reported)."""
        self.done += 1
        self._finished += 1
        self._run += self._last if used is None else int(used)
        self._last = 0
        left = self.points - self.done
        self._show(self._run, self._run + round(left * self._run / self._finished))
        if self._bar is not None:
            self._bar.set_postfix_str(f"grid point {self.done}/{self.points}")
        elif self.enabled:
            print(f"stabdae run: grid point {self.done}/{self.points} done", file=sys.stderr)

    def close(self):
        if self._bar is not None:
            self._bar.close()
