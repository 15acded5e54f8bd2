"""``stabdae run``: a study's grid of ensembles, resumable and lossless.

Each grid point is one :func:`stabdae.ensemble` with the study's seed (the same α⁰ targets
at every point: common random numbers, so that differences across the grid are the
parameters' and not the sample's).  Its dataset is written, atomically, to
``OUT.nc.parts/point-<i>.nc`` as soon as it is done, its checksum recorded beside it; a
run that is killed and started again with the same command (``--force`` included) skips
the points already there.  When every point is in,
they are combined into ``OUT.nc`` (written atomically) and the parts are removed.
Nothing depends on where a point ran (in-process, or on dask workers), so the dataset is
the same either way.
"""

from __future__ import annotations

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

import numpy as np
import xarray as xr

from .._boundary import boundary
from .._ensemble import ensemble
from .._integrate import IntegrationWarning
from .._loading import file_sha256, local_imports
from .._schema import append_history, utc_now, write_netcdf
from .._version import __version__
from ..engine.cache import function_fingerprint, library_fingerprint
from .report import summary
from .spec import Study, StudyError, load_study
from .theory import axis_units, for_study

__all__ = ["run_study", "run_point", "combine"]

#: attributes that say when/how fast, not what, and the parts' bookkeeping: left out of
#: the study dataset
_VOLATILE = ("wall_sample_s", "wall_integrate_s", "wall_dataset_s", "created_at", "history",
             "threads", "stabdae_run_key", "grid_point")  # fmt: skip


def axis_name(canon: str, all_names) -> str:
    """Dataset name of a sweep axis: ``tau``, ``omega``, ``g``, ``A_0_1`` (prefixed with
    the section where two sections share a key)."""
    section, key = canon.split(".", 1)
    key = key.replace("[", "_").replace(",", "_").replace("]", "")
    keys = [c.split(".", 1)[1] for c in all_names]
    if keys.count(canon.split(".", 1)[1]) > 1:
        return f"{section}_{key}"
    return key


def run_point(study: Study, values: dict, threads=None, progress=None) -> xr.Dataset:
    """The ensemble at one grid point, on the study's common sample grid (with
    ``[search]``: the boundary search at that point)."""
    s = study.setup(values)
    ens = study.ensemble
    if study.search is not None:
        return search_point(study, s, threads, progress)
    with warnings.catch_warnings():  # stopped members: the study's summary counts them
        warnings.simplefilter("ignore", IntegrationWarning)
        ds = ensemble(study.model, s["law"], s["scheme"], s["tau"], s["t_end"],
                      members=ens["members"], radius=tuple(ens["radius"]), seed=ens["seed"],
                      save_dt=s["save_dt"], params=s["params"], epsilon=s["epsilon"],
                      divergence=s["divergence"], block=ens["block"], threads=threads,
                      progress=progress, states=ens["states"])  # fmt: skip
    if s["stride"] > 1:  # a step spans several samples: NaN between the steps
        stride = s["stride"]
        t0 = float(ds.time[0])
        nsave = (ds.sizes["time"] - 1) * stride + 1
        times = t0 + (np.arange(nsave) / stride) * float(ds.time[1] - ds.time[0])
        full = np.full((ds.sizes["trace"], nsave), np.nan, dtype=ds.residual_norm.dtype)
        full[:, ::stride] = ds.residual_norm.values
        attrs = ds.residual_norm.attrs
        ds = ds.drop_vars("residual_norm").assign_coords(time=("time", times, ds.time.attrs))
        ds["residual_norm"] = (("trace", "time"), full, attrs)
    for key in _VOLATILE:
        ds.attrs.pop(key, None)
    return ds


def search_point(study: Study, s: dict, threads=None, progress=None) -> xr.Dataset:
    """The boundary search (:func:`stabdae.boundary`) at one grid point."""
    ens, search = study.ensemble, study.search
    ds = boundary(study.model, s["law"], s["scheme"], tau=search["tau"], rtol=search["rtol"],
                  q=search["q"], members=ens["members"],
                  search_members=search["search_members"], steps=search["steps"],
                  t_end=search["t_end"], radius=tuple(ens["radius"]), seed=ens["seed"],
                  params=s["params"], epsilon=s["epsilon"], divergence=s["divergence"],
                  block=ens["block"], threads=threads,
                  progress=progress if callable(progress) else False)  # fmt: skip
    for key in _VOLATILE:
        ds.attrs.pop(key, None)
    return ds


def _fingerprint(study: Study) -> str:
    """The run key: everything that decides a grid point's numbers — the study file (its
    parameters, law, scheme, run and grid), the ensemble settings as run (``--members``),
    the model file and the modules of its folder that it imports, the model's functions
    with the helpers and values they read (wherever those live), and the library (its
    source, numba's version, FMA)."""
    h = hashlib.sha256(study.path.read_bytes())
    h.update(json.dumps(study.ensemble, sort_keys=True).encode())
    h.update(__version__.encode())
    h.update(library_fingerprint().encode())
    if study.model_file is not None:
        for path in local_imports(study.model_file):
            h.update(path.name.encode() + b"\0" + path.read_bytes())
    # the model's functions as the kernels are keyed: helpers they call wherever those
    # live, and the values of the globals and module attributes they read
    model = study.model
    for piece, fn in sorted({**model.functions, "energy": model.energy}.items()):
        h.update(f"{piece}={function_fingerprint(fn) if fn is not None else None}".encode())
    return h.hexdigest()


def _part_ok(path: Path, index: int, manifest) -> str | None:
    """Why the part file of grid point ``index`` cannot be used (None when it can): it
    must open, carry this run's key and its own grid point, and match the checksum
    recorded when it was written."""
    try:
        with xr.open_dataset(path) as part:
            key, point = part.attrs.get("stabdae_run_key"), part.attrs.get("grid_point")
            part.load()
    except Exception as exc:  # a truncated, empty or foreign file: any reader error
        return f"unreadable ({type(exc).__name__})"
    if key != manifest.fingerprint:
        return "written by another run"
    if point != index:
        return f"holds grid point {point}"
    if not manifest.matches(path):
        return "does not match its recorded checksum"
    return None


def output_path(study: Study, output=None) -> Path:
    """Where the study's dataset goes: ``output`` (a file, or a folder — an existing one or
    one written with a trailing slash — which gets ``<study>.nc``), else the study's
    ``[output] path``, else ``results/<study>.nc``."""
    if output is None:
        if study.output_refused:
            raise StudyError(study.output_refused)
        return study.output or Path("results") / f"{study.path.stem}.nc"
    out = Path(output)
    if out.is_dir() or str(output).endswith(("/", "\\")):
        return out / f"{study.path.stem}.nc"
    return out


def _is_stabdae_dataset(path: Path) -> bool:
    try:
        with xr.open_dataset(path) as ds:
            return "stabdae_version" in ds.attrs
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
    stamp = _fingerprint(study)
    log(study.describe())
    existed = parts.exists() and any(p.name != "lock" for p in parts.iterdir())
    if existed and _Manifest.read(parts) is None:  # before the lock: create nothing there
        raise FileExistsError(
            f"{parts} exists and was not written by a stabdae run (it has no readable "
            f"{_Manifest.NAME}); it is left as it is: move it away or give another output "
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
            orphan.unlink(missing_ok=True)
        old = _Manifest.read(parts) if existed else None
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
            _clear(parts)
            old = None
        manifest = old or _Manifest(parts, stamp, str(study.path.resolve()))
        return _run_locked(study, out, parts, manifest, workers, scheduler, progress,
                           threads, log)  # fmt: skip
    finally:
        lock.unlink(missing_ok=True)
        if parts.exists() and not any(parts.iterdir()):
            parts.rmdir()


class _Manifest:
    """``OUTPUT.parts/study.json``: the run key, the study file (resolved) and the SHA-256
    of every part as it was written, so that a part altered afterwards is computed again.
    Only the process that runs the study writes it (dask workers return datasets)."""

    NAME = "study.json"

    def __init__(self, parts: Path, fingerprint: str, study: str, digests=None):
        self.parts, self.fingerprint, self.study = parts, fingerprint, study
        self.digests = dict(digests or {})

    @classmethod
    def read(cls, parts: Path):
        """The manifest in ``parts``, or None when there is none a stabdae run wrote."""
        try:
            raw = json.loads((parts / cls.NAME).read_text())
            return cls(parts, str(raw["fingerprint"]), str(raw["study"]),
                       {str(k): str(v) for k, v in raw.get("parts", {}).items()})  # fmt: skip
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            return None

    def save(self) -> None:
        text = json.dumps({"fingerprint": self.fingerprint, "study": self.study,
                           "parts": self.digests}, sort_keys=True)  # fmt: skip
        tmp = self.parts / f".{self.NAME}.tmp"
        tmp.write_text(text)
        os.replace(tmp, self.parts / self.NAME)  # a kill leaves the old or the new one

    def write(self, ds: xr.Dataset, index: int) -> None:
        """Write grid point ``index``'s part and record its checksum."""
        path = self.parts / f"point-{index}.nc"
        write_netcdf(_keyed(ds, index, self.fingerprint), path)
        self.digests[path.name] = file_sha256(path)
        self.save()

    def matches(self, path: Path) -> bool:
        return self.digests.get(path.name) == file_sha256(path)


def _clear(parts: Path) -> None:
    """Remove what stabdae wrote in ``parts`` (its points, manifest and temporary files),
    nothing else."""
    for pattern in ("point-*.nc", _Manifest.NAME, ".point-*.tmp", f".{_Manifest.NAME}.tmp"):
        for path in parts.glob(pattern):
            if path.is_file():
                path.unlink()


def _lock(parts: Path) -> Path:
    """Take ``parts/lock`` for this process; refuse when a live process holds it (two runs
    writing one output would remove each other's parts), take over a dead one's."""
    lock = parts / "lock"
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
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
    todo = []
    for i, (_, values) in enumerate(points):
        part = parts / f"point-{i}.nc"
        if part.exists():
            why = _part_ok(part, i, manifest)
            if why is None:
                continue
            log(f"grid point {i}: {part.name} {why}: computing it again")
            part.unlink()
        todo.append((i, values))
    if len(todo) < len(points):
        log(f"resuming: {len(points) - len(todo)} of {len(points)} grid points already done")
    start = time.perf_counter()
    bar = _Progress(len(points), len(points) - len(todo), _work_per_point(study), progress)
    try:
        if workers or scheduler:
            _run_dask(study, todo, manifest, workers, scheduler, bar)
        else:
            for i, values in todo:
                report = bar.note if study.search is not None else bar.members
                manifest.write(run_point(study, values, threads=threads, progress=report), i)
                bar.point_done()
    finally:
        bar.close()
    ds = combine(study, parts, len(points))
    if not study.setup()["law"].is_constant and study.search is None:
        ds = _with_path_theory(study, ds)
    ds.attrs["wall_run_s"] = time.perf_counter() - start
    write_netcdf(ds, out)
    _clear(parts)
    log(summary(ds))
    log(f"dataset written to {out}")
    return out


def _with_path_theory(study: Study, ds: xr.Dataset) -> xr.Dataset:
    """State-dependent laws: the discrete conditions of Theorems 6/7 along the reference
    trajectory at every grid point (:func:`.theory.for_study`)."""
    th = for_study(study)
    names = list(study.axes)
    th = th.rename({n: axis_name(n, names) for n in names})
    keep = [v for v in th.data_vars if v.startswith("path_")]
    return ds.assign({v: th[v].assign_coords({d: ds[d] for d in th[v].dims}) for v in keep})


def _keyed(ds: xr.Dataset, index: int, stamp: str) -> xr.Dataset:
    """A grid point's dataset marked with its index and the run key, as its part file."""
    ds.attrs.update(stabdae_run_key=stamp, grid_point=index)
    return ds


def _run_dask(study, todo, manifest, workers, scheduler, bar):
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
        # an absolute path: the workers may run in another folder
        path, members = str(study.path.resolve()), study.ensemble["members"]
        futures = {client.submit(_remote_point, path, members, values, pure=False): i
                   for i, values in todo}  # fmt: skip
        for fut in as_completed(futures):
            i = futures[fut]
            manifest.write(fut.result(), i)
            bar.point_done()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _remote_point(path, members, values):
    # the process that runs the study has loaded and accepted its model already
    study = load_study(path, members=members, trust_model=True)
    return run_point(study, values, threads=1)


def combine(study: Study, parts: Path, npoints: int) -> xr.Dataset:
    """The study dataset from its per-point parts: every variable gains the sweep axes."""
    names = list(study.axes)
    pts = []
    for i in range(npoints):
        with xr.open_dataset(parts / f"point-{i}.nc") as f:
            pts.append(f.load())
    if "probe" in pts[0].dims:  # searches take different numbers of probes: pad with NaN
        size = max(p.sizes["probe"] for p in pts)
        pts = [p.reindex(probe=np.arange(size)) for p in pts]
    first = pts[0]
    if not names:
        ds = first
    else:
        dims = [axis_name(n, names) for n in names]
        stacked = xr.concat(pts, dim="point", coords="minimal", compat="override",
                            combine_attrs="drop_conflicts", join="override")  # fmt: skip
        index = np.array([idx for idx, _ in study.points()])
        ds = stacked.assign_coords(
            {d: ("point", study.axes[n][index[:, k]]) for k, (n, d) in enumerate(zip(names, dims))}
        )
        if len(dims) == 1:
            ds = ds.swap_dims(point=dims[0])
        else:
            ds = ds.set_index(point=dims).unstack("point")
        ds = ds.transpose(*dims, ...)
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
    append_history(ds.attrs, f"stabdae run {study.path.name}: {npoints} {what} of "
                   f"{study.ensemble['members']} members combined")  # fmt: skip
    return ds


def _work_per_point(study: Study) -> int:
    """A grid point's work in member runs: its ensemble's members, or for a boundary
    search the members of the probes it is expected to run (the bracket's ends, two
    beside the spectral limit, the bisection from the whole bracket down to ``rtol``,
    each of ``search_members``, and the full ensemble's confirmation), so that the bar
    moves, and its time left is estimated, per probe (:meth:`_Progress.note`)."""
    members = int(study.ensemble["members"])
    if study.search is None:
        return members
    s = study.search
    lo, hi = s["tau"]
    halvings = math.ceil(math.log2(max(math.log(hi / lo) / math.log1p(s["rtol"]), 1.0)))
    return (4 + halvings) * int(s["search_members"]) + members


class _Progress:
    """A progress bar over grid points and their work in member runs
    (:func:`_work_per_point`; tqdm when installed, else a line on stderr per point);
    silent when ``enabled`` is false."""

    def __init__(self, points: int, done: int, members: int, enabled: bool):
        self.points, self.done, self.members_total = points, done, members
        self.enabled = enabled and points > 0
        self._bar = None
        if self.enabled:
            try:
                from tqdm import tqdm

                # the first chunk waits for the kernels to compile (or load from the cache)
                self._bar = tqdm(total=points * members, initial=done * members,
                                 unit="member", desc="stabdae run (compiling)",
                                 file=sys.stderr, dynamic_ncols=True)  # fmt: skip
            except ImportError:
                self._bar = None
                print("stabdae run: compiling the kernels (first use only) …", file=sys.stderr)
        self._last = 0
        self._started = time.perf_counter()
        self._compiling = True

    def members(self, done: int, total: int):
        if self._compiling:
            self._compiling = False
            if self._bar is not None:
                seconds = time.perf_counter() - self._started
                self._bar.set_description(f"stabdae run (kernels ready in {seconds:.0f} s)")
        if self._bar is not None:
            self._bar.update(done - self._last)
            self._last = done

    def note(self, text: str):
        """A line from a boundary search (each probe): its members count on the bar, up
        to the point's share less one (the rest when the point is done)."""
        if self._compiling:
            self.members(0, self.members_total)
        run = re.search(r" of (\d+) members", text)
        if run is not None:
            self.members(min(self._last + int(run.group(1)), self.members_total - 1), 0)
        if self._bar is not None:
            self._bar.set_postfix_str(text.removeprefix("boundary: "), refresh=False)
        elif self.enabled:
            print(f"stabdae run: {text}", file=sys.stderr)

    def point_done(self):
        self.done += 1
        if self._bar is not None:
            self._bar.update(self.members_total - self._last)
            self._bar.set_postfix_str(f"grid point {self.done}/{self.points}")
        elif self.enabled:
            print(f"stabdae run: grid point {self.done}/{self.points} done", file=sys.stderr)
        self._last = 0

    def close(self):
        if self._bar is not None:
            self._bar.close()
