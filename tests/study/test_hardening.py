"""A study file and a parts folder are data: neither makes stabdae import, open or delete
a file that the user did not name, and a half-edited study never mixes into a run."""

from __future__ import annotations

import json
import os
import sys
import textwrap
from pathlib import Path

import pytest

import stabdae
from stabdae.study.cli import main
from stabdae.study.run import run_study
from stabdae.study.spec import StudyError, load_study

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from conftest import same_data  # noqa: E402
from conftest import study_file as shared_study  # noqa: E402

STUDY = """
[model]
file = "{file}"

[law]
kind = "baumgarte"
omega = 10.0
xi = 1.0

[run]
t_end = 0.05
tau = 1e-2
save_dt = 0.05

[ensemble]
members = 4
radius = [1e-6, 1e-3]
seed = 1
block = 4

[sweep]
tau = [1e-2, 5e-3]
"""


def study_file(folder: Path, file="pendulum", name="study.toml") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(textwrap.dedent(STUDY.format(file=file)))
    return path


# ------------------------------------------------------------------ [model] file
def _tripwire(folder: Path) -> tuple[Path, Path]:
    """A Python file without ``.py`` in its import name's reach, which leaves a mark when
    it runs: (the file's path without its suffix, the mark)."""
    folder.mkdir(parents=True, exist_ok=True)
    mark = folder / "ran"
    code = folder / "evil.py"
    code.write_text(f"open({str(mark)!r}, 'w').write('ran')\n")
    return folder / "evil", mark


@pytest.mark.parametrize("form", ["absolute", "relative", "dotted"])
def test_a_scene_name_in_a_study_file_is_a_name_never_a_path(tmp_path, capsys, form):
    """The extension-less form of ``[model] file`` names a built-in scene; a path in it
    (absolute, or climbing out of the scenes folder) was joined onto the scenes folder and
    imported: the file ran from ``theory`` and ``run``.  Now it is refused, names the key,
    and nothing runs."""
    stem, mark = _tripwire(tmp_path / "elsewhere")
    scenes = stabdae._loading.scene_dir()
    given = {"absolute": str(stem),
             "relative": os.path.relpath(stem, scenes),
             "dotted": "../" * 12 + str(stem).lstrip("/")}[form]  # fmt: skip
    path = study_file(tmp_path / "home", given)
    with pytest.raises(StudyError, match=r"\[model\] file: .* built-in scene \(a scene is "
                                         r"given by its name alone\)"):
        load_study(path)
    assert main(["theory", str(path)]) == 2
    assert main(["run", str(path), "-o", str(tmp_path / "out.nc")]) == 2
    err = capsys.readouterr().err
    assert "[model] file" in err and "Traceback" not in err
    assert not mark.exists(), "the file named as a scene ran"


def test_load_model_takes_a_scene_by_its_name_alone(tmp_path):
    stem, mark = _tripwire(tmp_path)
    with pytest.raises(stabdae.ModelError, match="load_model: .* given by its name alone"):
        stabdae.load_model(os.path.relpath(stem, stabdae._loading.scene_dir()))
    assert not mark.exists()
    assert stabdae.load_model("pendulum").name == "pendulum"


# ------------------------------------------------------------------ the parts folder
@pytest.fixture
def no_hang():
    """A read that blocks (a FIFO opened) fails the test instead of hanging it."""
    import signal

    def stop(*_):
        raise TimeoutError("blocked on a file of the parts folder")

    old = signal.signal(signal.SIGALRM, stop)
    signal.alarm(30)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


def test_a_manifest_names_only_chunks_inside_its_folder(tmp_path, no_hang):
    """A ``study.json`` with the right run key (anyone can compute it) listed
    ``../notes.txt`` and an absolute path with wrong checksums: resuming removed both.  A
    FIFO under a chunk's name hung the run.  Now names other than a chunk's are ignored
    with a message, a chunk that is not a regular file is neither opened nor removed, and
    its points are computed again."""
    from stabdae.study.store import Manifest, Store

    parts = tmp_path / "out.nc.parts"
    parts.mkdir()
    notes = tmp_path / "notes.txt"
    notes.write_text("a week of notes")
    far = tmp_path / "far"
    far.mkdir()
    absolute = far / "data.bin"
    absolute.write_text("not ours")
    os.mkfifo(parts / "chunk-1.npz")
    (parts / "chunk-2.npz").symlink_to(absolute)
    (parts / "chunk-7.npz").symlink_to(far / "unrecorded")  # a link no entry records
    (far / "unrecorded").write_text("not ours either")
    wrong = "0" * 64
    (parts / "study.json").write_text(json.dumps({
        "fingerprint": "key", "study": "study.toml",
        "chunks": {"../notes.txt": {"sha256": wrong, "points": [0]},
                   str(absolute): {"sha256": wrong, "points": [0]},
                   "chunk-1.npz": {"sha256": wrong, "points": [1]},
                   "chunk-2.npz": {"sha256": wrong, "points": [2]},
                   "chunk-03.npz": {"sha256": wrong, "points": [3]}}}))  # fmt: skip
    manifest = Manifest.read(parts)
    assert sorted(manifest.chunks) == ["chunk-1.npz", "chunk-2.npz"]
    said = []
    store = Store(manifest)
    store.resume(4, said.append)
    text = "\n".join(said)
    for name in ("'../notes.txt'", repr(str(absolute)), "'chunk-03.npz'"):
        assert f"the entry {name} is not the name of a chunk a run writes: ignored" in text
    assert f"grid points 1: {parts / 'chunk-1.npz'} is a FIFO" in text
    assert f"grid points 2: {parts / 'chunk-2.npz'} is a symbolic link" in text
    assert store.tables == {} and manifest.chunks == {}
    assert notes.read_text() == "a week of notes" and absolute.read_text() == "not ours"
    assert (far / "unrecorded").read_text() == "not ours either"
    assert os.path.lexists(parts / "chunk-1.npz") and (parts / "chunk-2.npz").is_symlink()
    assert (parts / "chunk-7.npz").is_symlink()


def test_a_run_says_when_its_parts_folder_stays_for_files_it_did_not_write(tmp_path):
    """A FIFO under a chunk's name is left alone, its point computed again; the run then
    removed its own files and said nothing of the folder that stayed behind.  Now it
    names what it left and why."""
    from stabdae.study.run import _fingerprint

    path = shared_study(tmp_path, members=16, t_end=0.2, omegas="5.0")
    parts = tmp_path / "out.nc.parts"
    parts.mkdir()
    os.mkfifo(parts / "chunk-0.npz")
    (parts / "study.json").write_text(json.dumps({
        "fingerprint": _fingerprint(load_study(path)), "study": str(path.resolve()),
        "chunks": {"chunk-0.npz": {"sha256": "0" * 64, "points": [0]}}}))  # fmt: skip
    said = []
    out = run_study(path, tmp_path / "out.nc", progress=False, log=said.append)
    text = "\n".join(map(str, said))
    assert out.exists() and (parts / "chunk-0.npz").exists()
    assert not (parts / "study.json").exists()
    assert f"{parts} is left in place: it holds chunk-0.npz, which no run wrote" in text


def test_clear_removes_regular_files_of_its_own_names_only(tmp_path):
    from stabdae.study.store import clear

    parts = tmp_path / "p.parts"
    parts.mkdir()
    (parts / "chunk-0.npz").write_bytes(b"ours")
    target = tmp_path / "target"
    target.write_text("theirs")
    (parts / "chunk-1.npz").symlink_to(target)
    os.mkfifo(parts / "chunk-2.npz")
    (parts / "keep.txt").write_text("theirs")
    clear(parts)
    assert sorted(p.name for p in parts.iterdir()) == ["chunk-1.npz", "chunk-2.npz",
                                                        "keep.txt"]  # fmt: skip
    assert target.read_text() == "theirs"


@pytest.mark.parametrize("kind", ["link", "file", "fifo"])
def test_a_parts_folder_that_is_not_a_folder_is_refused_before_computing(tmp_path, kind):
    """A parts folder that was a symbolic link had the dataset written, then the run
    exited 2 with ``Not a directory``; now the run is refused before any grid point, the
    link (file, FIFO) left as it is."""
    study = study_file(tmp_path, name="s.toml")
    parts = tmp_path / "out.nc.parts"
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    {"link": lambda: parts.symlink_to(elsewhere), "file": lambda: parts.write_text("x"),
     "fifo": lambda: os.mkfifo(parts)}[kind]()  # fmt: skip
    with pytest.raises(FileExistsError, match=r"out\.nc\.parts is (a symbolic link|a regular "
                                              r"file|a FIFO), not a folder of a run's parts"):
        run_study(study, tmp_path / "out.nc", progress=False, log=lambda *a: None)
    assert not (tmp_path / "out.nc").exists() and os.path.lexists(parts)
    assert list(elsewhere.iterdir()) == []


def test_a_lock_that_is_not_a_file_is_refused_not_read(tmp_path, no_hang):
    from stabdae.study.run import _lock

    parts = tmp_path / "p.parts"
    parts.mkdir()
    os.mkfifo(parts / "lock")
    with pytest.raises(FileExistsError, match=r"lock is a FIFO, not the lock a run writes"):
        _lock(parts)


# ------------------------------------------------------------------ distributed runs
def test_an_edit_of_the_study_file_during_a_dask_run_changes_nothing(tmp_path, monkeypatch):
    """Each worker re-read the study file per grid point: ``seed`` edited after the first
    point gave points of both seeds, exit 0, and the conflicting attribute dropped.  The
    parsed study is shipped once now; the run is the study as it was read."""
    pytest.importorskip("distributed")
    import xarray as xr

    from stabdae.study import store

    model = tmp_path / "home" / "pend.py"
    model.parent.mkdir()
    model.write_text((Path(__file__).resolve().parents[2] / "kernels" / "pendulum.py")
                     .read_text())  # fmt: skip
    path = shared_study(tmp_path / "home", members=16, t_end=0.2, omegas="5.0")
    path.write_text(path.read_text().replace('file = "pendulum"', 'file = "pend.py"'))
    clean = run_study(path, tmp_path / "clean.nc", progress=False, log=lambda *a: None)
    real_add, edited = store.Store.add, []

    def add_then_edit(self, index, table):
        real_add(self, index, table)
        if not edited:  # after the first point: the seed, and the model file itself
            path.write_text(path.read_text().replace("seed = 3", "seed = 99"))
            model.write_text(model.read_text().replace("9.81", "1.62"))
            edited.append(index)

    monkeypatch.setattr(store.Store, "add", add_then_edit)
    out = run_study(path, tmp_path / "dask.nc", workers=2, progress=False,
                    log=lambda *a: None)  # fmt: skip
    assert edited
    ds = xr.open_dataset(out).load()
    assert ds.attrs["seed"] == 3
    same_data(ds, xr.open_dataset(clean).load())


def test_an_edit_while_the_dask_cluster_starts_changes_nothing(tmp_path, monkeypatch):
    """The model file's bytes for the workers were read when the cluster was up, seconds
    after the run key: an edit of the model in between made every worker's key differ,
    and the run stopped with an error (nothing mixed, but the run lost).  The bytes are
    read once, with the study; the run is the study and model as they were read."""
    pytest.importorskip("distributed")
    import xarray as xr

    import stabdae.study.run as runner

    model = tmp_path / "home" / "pend.py"
    model.parent.mkdir()
    model.write_text((Path(__file__).resolve().parents[2] / "kernels" / "pendulum.py")
                     .read_text())  # fmt: skip
    path = shared_study(tmp_path / "home", members=16, t_end=0.2, omegas="5.0")
    path.write_text(path.read_text().replace('file = "pendulum"', 'file = "pend.py"'))
    clean = run_study(path, tmp_path / "clean.nc", progress=False, log=lambda *a: None)
    real = runner._run_dask

    def edit_then_start(*args, **kwargs):
        path.write_text(path.read_text().replace("seed = 3", "seed = 99"))
        model.write_text(model.read_text().replace("9.81", "1.62"))
        return real(*args, **kwargs)

    monkeypatch.setattr(runner, "_run_dask", edit_then_start)
    out = run_study(path, tmp_path / "dask.nc", workers=1, progress=False,
                    log=lambda *a: None)  # fmt: skip
    same_data(xr.open_dataset(out).load(), xr.open_dataset(clean).load())


def test_a_worker_result_under_another_run_key_is_refused(tmp_path, monkeypatch):
    """The run key is checked on every result a worker returns."""
    pytest.importorskip("distributed")
    import stabdae.study.run as runner

    path = shared_study(tmp_path, members=16, t_end=0.2, omegas="5.0")
    # this process's key differs from the one the worker computes (as when the worker's
    # library or numba differ)
    monkeypatch.setattr(runner, "_fingerprint", lambda study: "f" * 64)
    with pytest.raises(StudyError, match=r"a dask worker computed grid point \d+ under "
                                         r"another run key"):
        run_study(path, tmp_path / "x.nc", workers=1, progress=False, log=lambda *a: None)
    assert not (tmp_path / "x.nc").exists()


def test_the_run_key_is_the_same_for_a_scene_from_a_wheel_and_from_a_source_tree(tmp_path):
    """A worker with stabdae from a source tree (the scene loaded as a file's module) and
    a main process with it installed (``stabdae.scenes.pendulum``) computed different run
    keys for the same study, and every result was refused: the module name was in the key.
    The key holds the source by content, not where it was imported from; a changed line
    still changes it."""
    import dataclasses

    from stabdae._loading import load_as, scene_dir
    from stabdae.study.run import _fingerprint

    study = load_study(shared_study(tmp_path, members=16))
    file = scene_dir() / "pendulum.py"
    keys = {_fingerprint(dataclasses.replace(study, model=load_as(file, name)))
            for name in ("stabdae_model_from_source_tree", "stabdae_wheel_scenes_pendulum")}
    assert len(keys) == 1
    edited = tmp_path / "pendulum.py"
    edited.write_text(file.read_text().replace("\n", "\n\n", 1))  # every line moves by one
    moved = load_as(edited, "stabdae_model_edited_copy")
    assert _fingerprint(dataclasses.replace(study, model=moved)) not in keys


# ------------------------------------------------------------------ values out of range
def test_a_seed_the_dataset_cannot_store_is_refused_before_any_point(tmp_path):
    """A seed of 2**64 passed validation, then failed after every grid point was computed
    (``illegal data type for attribute b'seed'``), and every resume failed the same."""
    path = study_file(tmp_path)
    path.write_text(path.read_text().replace("seed = 1", f"seed = {2**64}"))
    with pytest.raises(StudyError, match=r"\[ensemble\] seed: must be at most 2\*\*64 - 1"):
        load_study(path)
    path.write_text(path.read_text().replace(f"seed = {2**64}", f"seed = {2**64 - 1}"))
    assert load_study(path).ensemble["seed"] == 2**64 - 1
    model = stabdae.load_model("pendulum")
    with pytest.raises(ValueError, match=r"sample_perturbations: seed must be at most"):
        stabdae.sample_perturbations(model, 4, seed=2**64)


@pytest.mark.parametrize("text, match", [
    (None, r"not a text file in UTF-8 \(byte \d+ is b'\\xff'\)"),
    ("[search]\nq = " + "[" * 500 + "1" + "]" * 500 + "\n", r"not valid TOML: nested too deeply"),
    ('[output]\npath = "a\\u0000b.nc"\n', r"\[output\] path: must be a file path without NUL"),
])
def test_study_files_that_cannot_be_read_name_the_file_and_key(tmp_path, text, match):
    """A non-UTF-8 study file's error named no file; a value 500 arrays deep ended in a
    RecursionError traceback; an output path with a NUL byte failed in the OS."""
    path = study_file(tmp_path)
    if text is None:
        path.write_bytes(path.read_bytes().replace(b"pendulum", b"pend\xffulum"))
    else:
        path.write_text(path.read_text() + text)
    with pytest.raises(StudyError, match=match):
        load_study(path)
    assert str(path.name) in str(pytest.raises(StudyError, load_study, path).value)


def test_command_line_values_out_of_range_name_their_option(tmp_path, capsys):
    """``run --threads -2`` failed only after the compile started; ``check --rtol -1`` ran;
    ``-o`` with a NUL byte named no option."""
    path = study_file(tmp_path)
    with pytest.raises(SystemExit) as stop:
        main(["run", str(path), "--threads", "-2"])
    assert stop.value.code == 2
    assert "argument --threads: expected a positive integer, got -2" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["check", "pendulum", "--rtol", "-1"])
    assert "argument --rtol: expected a positive finite number" in capsys.readouterr().err
    assert main(["run", str(path), "-o", "a\0b.nc"]) == 2
    assert "the output path (-o) contains a NUL character" in capsys.readouterr().err


def test_a_model_name_is_no_path_in_the_default_output():
    """``stabdae integrate`` wrote to ``results/<model name>_trajectory.nc`` with the name
    raw: ``../../escaped\\nline`` wrote outside results/."""
    from stabdae.study.cli import _safe_stem

    for name in ("../../escaped\nline", "/etc/passwd", "..", "a/b\\c", "pendulum"):
        out = Path("results") / f"{_safe_stem(name)}_trajectory.nc"
        assert out.parent == Path("results") and "/" not in _safe_stem(name)
        assert "\n" not in str(out) and not _safe_stem(name).startswith(".")
    assert _safe_stem("pendulum") == "pendulum"


def test_a_full_disk_during_a_chunk_write_says_so_and_leaves_no_orphan(tmp_path, monkeypatch):
    """A full disk gave a bare ``[Errno 28]`` and left ``.chunk-*.tmp`` behind."""
    import errno

    from stabdae.study.store import Manifest, Store

    parts = tmp_path / "p.parts"
    parts.mkdir()
    store = Store(Manifest(parts, "key", "study"))
    store.manifest.save()
    real = Path.write_bytes

    def full(self, data):
        if self.name.startswith(".chunk-"):
            real(self, data[:10])  # part of it, as a full disk leaves it
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, data)

    monkeypatch.setattr(Path, "write_bytes", full)
    from stabdae._ensemble_dataset import Table
    import numpy as np

    store.add(0, Table({"x": (("member",), np.zeros(3), {})}, {}, {}))
    with pytest.raises(OSError, match=r"could not write grid points 0 \(they are computed "
                                      r"again .*\) to .*chunk-0\.npz \(No space left"):
        store.flush()
    assert sorted(p.name for p in parts.iterdir()) == ["study.json"]
