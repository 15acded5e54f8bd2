"""``stabdae run``: resume after SIGKILL, dask equality, no overwrite without --force,
pictures."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from conftest import STUDY, assert_schema, same_data, study_file
from stabdae._schema import write_netcdf
from stabdae.study.cli import main
from stabdae.study.run import run_study

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src"


def recorded(parts: Path) -> int:
    """The grid points whose chunks the manifest of ``parts`` records (0 before it is)."""
    try:
        chunks = json.loads((parts / "study.json").read_text()).get("chunks", {})
    except (OSError, ValueError):
        return 0
    return sum(len(c["points"]) for c in chunks.values())


def test_run_writes_dataset_and_pictures_and_refuses_to_overwrite(tmp_path, capsys):
    path = study_file(tmp_path)
    assert main(["run", str(path), "--quiet"]) == 0
    out = tmp_path / "out" / "study.nc"
    printed = capsys.readouterr().out
    assert "summary" in printed and f"dataset written to {out}" in printed
    ds = xr.open_dataset(out)
    assert ds.fraction_bounded.dims == ("tau", "omega")
    assert ds.residual_norm.dims == ("tau", "omega", "trace", "time")
    assert_schema(ds)
    assert "stabdae run study.toml: 12 grid points of 64 members" in ds.attrs["history"]
    assert ds.attrs["study"] == "study.toml" and ds.attrs["swept"] == "run.tau, law.omega"
    assert ds.residual_norm.encoding.get("zlib") is True  # written compressed
    assert "x0" not in ds and "x_final" not in ds  # [ensemble] states: false by default
    # τ = 0.1, 0.2 are larger than save_dt: samples between their steps are NaN
    r = ds.residual_norm.sel(tau=0.2, omega=5.0).values
    assert np.isfinite(r[:, ::4]).all() and np.isnan(r[:, 1::4]).all()
    # the stability boundary: τω < 2 for the midpoint rule at ξ = 1
    pred = (ds.tau * ds.omega < 2.0).transpose("tau", "omega").values
    np.testing.assert_array_equal(ds.spectral_radius.values < 1, pred)
    for suffix in ("stability", "decay", "beta"):
        png = tmp_path / "out" / f"study_{suffix}.png"
        assert png.is_file() and png.stat().st_size > 10_000
    before = out.stat().st_mtime_ns
    assert main(["run", str(path), "--quiet"]) == 2
    assert "exists; pass --force" in capsys.readouterr().err
    assert out.stat().st_mtime_ns == before
    assert main(["run", str(path), "--quiet", "--force", "--no-plots"]) == 0
    same_data(xr.open_dataset(out).load(), ds.load())
    # stabdae plot on the dataset
    assert main(["plot", str(out), "-o", str(tmp_path / "again")]) == 0
    assert (tmp_path / "again_stability.png").is_file()


def test_resume_after_sigkill_gives_the_same_dataset(tmp_path):
    # slow enough per grid point (8192 members × 10⁴ steps) to be killed in the middle
    path = study_file(tmp_path, members=8192, t_end=5.0, omegas="5.0")
    (tmp_path / "ref").mkdir()
    reference = run_study(study_file(tmp_path / "ref", members=8192, t_end=5.0, omegas="5.0"),
                          progress=False, log=lambda *a: None)  # fmt: skip
    # a chunk per grid point, so that the kill lands between two
    env = dict(os.environ, PYTHONPATH=str(SRC), STABDAE_FLUSH_SECONDS="0")
    cmd = [sys.executable, "-m", "stabdae.study.cli", "run", str(path), "--quiet", "--no-plots"]
    parts = tmp_path / "out" / "study.nc.parts"

    # A process started from a background job inherits SIGINT ignored, and Python then
    # installs no handler for it: the Ctrl-C phase restores Python's own first.
    with_sigint = [sys.executable, "-c", "import signal, sys; signal.signal(signal.SIGINT, "
                   "signal.default_int_handler); from stabdae.study.cli import main; "
                   "sys.exit(main(sys.argv[1:]))", *cmd[3:]]  # fmt: skip

    def start_and_wait_for(points, command=cmd):
        proc = subprocess.Popen(command, env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)  # fmt: skip
        deadline = time.time() + 120
        while time.time() < deadline and recorded(parts) < points:
            time.sleep(0.01)
        return proc

    # Ctrl-C first: one line, exit 130, the points done kept and no lock left behind
    proc = start_and_wait_for(1, with_sigint)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and err.strip().count("\n") == 0, err
    assert "interrupted (the grid points done are kept: run the same command to resume)" in err
    assert recorded(parts) >= 1
    assert not (parts / "lock").exists()
    # then SIGKILL, in the middle of the resumed run; the points finished since the last
    # chunk are computed again, as is a chunk written but not yet recorded
    proc = start_and_wait_for(2)
    os.kill(proc.pid, signal.SIGKILL)
    proc.communicate()
    done = recorded(parts)
    assert 2 <= done < 6  # killed in the middle
    assert not (tmp_path / "out" / "study.nc").exists()
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    assert f"resuming: {done} of 6 grid points already done" in out.stdout
    assert not parts.exists()
    same_data(xr.open_dataset(tmp_path / "out" / "study.nc").load(),
              xr.open_dataset(reference).load())  # fmt: skip


def test_run_refuses_the_parts_of_another_study(tmp_path):
    """A parts folder left by a run of another study (or other ensemble settings) under
    the same output is refused, not mixed in; --force discards it and starts over."""
    from stabdae.study.run import _fingerprint
    from stabdae.study.spec import load_study

    mine = study_file(tmp_path, omegas="5.0", name="mine.toml")
    other = study_file(tmp_path, omegas="5.0, 30.0", name="other.toml")
    parts = tmp_path / "out" / "study.nc.parts"
    parts.mkdir(parents=True)
    (parts / "study.json").write_text(json.dumps(
        {"fingerprint": _fingerprint(load_study(other)), "study": str(other)}))
    (parts / "chunk-0.npz").write_bytes(b"not this study's")
    with pytest.raises(FileExistsError, match="holds a run of a different study"):
        run_study(mine, progress=False, log=lambda *a: None)
    assert (parts / "chunk-0.npz").exists()
    out = run_study(mine, force=True, progress=False, log=lambda *a: None)
    assert out.exists() and not parts.exists()


def test_default_run_starts_no_cluster(tmp_path):
    # (xarray's NetCDF writer imports dask.distributed, when installed, to look for a
    # client; stabdae itself imports it only for --workers/--scheduler)
    path = study_file(tmp_path, omegas="5.0")
    code = textwrap.dedent(f"""
        from stabdae.study.run import run_study
        run_study({str(path)!r}, progress=False, log=lambda *a: None)
        try:
            import distributed
            distributed.default_client()
            print("a dask client")
        except ImportError:
            print("no client")
        except ValueError:  # "No clients found"
            print("no client")
    """)
    env = dict(os.environ, PYTHONPATH=str(SRC))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True)  # fmt: skip
    assert out.stdout.strip() == "no client"


def test_dask_cluster_gives_the_same_dataset(tmp_path):
    pytest.importorskip("distributed")
    path = study_file(tmp_path, omegas="5.0, 30.0")
    local = run_study(path, tmp_path / "local.nc", progress=False, log=lambda *a: None)
    dist = run_study(path, tmp_path / "dask.nc", workers=2, progress=False, log=lambda *a: None)
    same_data(xr.open_dataset(dist).load(), xr.open_dataset(local).load())


def test_separate_scheduler_and_worker_processes_give_the_same_dataset(tmp_path):
    """--scheduler ADDRESS: a dask scheduler and a worker started as their own processes
    (on the loopback interface, in another folder), as on a cluster; the dataset equals the
    in-process run's."""
    pytest.importorskip("distributed")
    path = study_file(tmp_path, omegas="5.0, 30.0")
    local = run_study(path, tmp_path / "local.nc", progress=False, log=lambda *a: None)
    elsewhere = tmp_path / "worker_dir"
    elsewhere.mkdir()
    env = dict(os.environ, PYTHONPATH=str(SRC))
    scheduler_file = tmp_path / "scheduler.json"
    procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler",
                               "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                               "--scheduler-file", str(scheduler_file)],
                              cwd=elsewhere, env=env, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)]  # fmt: skip
    try:
        deadline = time.time() + 60
        while not scheduler_file.exists() and time.time() < deadline:
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker",
                                       address, "--nworkers", "1", "--nthreads", "1",
                                       "--no-dashboard", "--host", "127.0.0.1"],
                                      cwd=elsewhere, env=env, stdout=subprocess.DEVNULL,
                                      stderr=subprocess.DEVNULL))  # fmt: skip
        remote = run_study(path, tmp_path / "remote.nc", scheduler=address, progress=False,
                           log=lambda *a: None)  # fmt: skip
    finally:
        for proc in reversed(procs):
            proc.terminate()
        for proc in procs:
            proc.wait(timeout=60)
    same_data(xr.open_dataset(remote).load(), xr.open_dataset(local).load())


def _interrupted(study, after: int, monkeypatch):
    """Run ``study`` and stop it with an error after ``after`` grid points (as a kill
    would), leaving their parts behind."""
    import stabdae.study.run as runner

    real, calls = runner.run_point, []

    def stop_after(*args, **kwargs):
        if len(calls) == after:
            raise KeyboardInterrupt
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(runner, "run_point", stop_after)
    with pytest.raises(KeyboardInterrupt):
        run_study(study, progress=False, log=lambda *a: None)
    monkeypatch.setattr(runner, "run_point", real)


def test_resume_after_a_model_edit_recomputes_and_equals_a_clean_run(tmp_path, monkeypatch):
    """Parts computed with the model file as it was are not mixed with points of the
    edited model: the run key covers the model file (and what it imports from its
    folder), so the resumed run starts over and equals a clean run of the edited model."""
    models = tmp_path / "models"
    models.mkdir()
    source = (ROOT / "kernels" / "pendulum.py").read_text()
    (models / "pend.py").write_text(source)
    text = STUDY.format(members=16, t_end=0.2, omegas="5.0").replace(
        'file = "pendulum"', 'file = "models/pend.py"')
    study = tmp_path / "study.toml"
    study.write_text(text)
    _interrupted(study, 2, monkeypatch)
    assert recorded(tmp_path / "out" / "study.nc.parts") == 2
    (models / "pend.py").write_text(source.replace('"g": 9.81', '"g": 1.62'))
    env = dict(os.environ, PYTHONPATH=str(SRC))
    cmd = [sys.executable, "-m", "stabdae.study.cli", "run", str(study), "--quiet", "--no-plots"]
    resumed = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
    assert "changed since" in resumed.stdout and "starting over" in resumed.stdout
    clean = tmp_path / "clean"
    clean.mkdir()
    (clean / "models").mkdir()
    (clean / "models" / "pend.py").write_text((models / "pend.py").read_text())
    (clean / "study.toml").write_text(text)
    subprocess.run([*cmd[:4], str(clean / "study.toml"), "--quiet", "--no-plots"], env=env,
                   capture_output=True, text=True, check=True)  # fmt: skip
    got = xr.open_dataset(tmp_path / "out" / "study.nc").load()
    assert got.attrs["model_param_g"] == 1.62
    same_data(got, xr.open_dataset(clean / "out" / "study.nc").load())


def test_the_run_key_covers_helpers_outside_the_model_folder(tmp_path, monkeypatch):
    """A model function that calls a helper from a module outside the model's folder (on
    sys.path), or reads a value from one: editing the helper changes the run key, so
    parts of the old helper are never mixed in."""
    from stabdae.study.run import _fingerprint
    from stabdae.study.spec import load_study

    lib = tmp_path / "shared_lib"
    lib.mkdir()
    (lib / "pend_helpers_x.py").write_text("from numba import njit\nSCALE = 1.0\n\n\n"
                                           "@njit\ndef gravity(g):\n    return g\n")
    monkeypatch.syspath_prepend(str(lib))
    models = tmp_path / "models"
    models.mkdir()
    source = (ROOT / "kernels" / "pendulum.py").read_text()
    assert "out[1] = p[0]" in source  # the pendulum's gravity, replaced below
    source = "import pend_helpers_x\n" + source.replace(
        "out[1] = p[0]", "out[1] = pend_helpers_x.gravity(p[0]) * pend_helpers_x.SCALE")
    (models / "pend_x.py").write_text(source)
    study = tmp_path / "study.toml"
    study.write_text(STUDY.format(members=16, t_end=0.2, omegas="5.0").replace(
        'file = "pendulum"', 'file = "models/pend_x.py"'))
    keys = [_fingerprint(load_study(study))]
    helper = lib / "pend_helpers_x.py"
    helper.write_text(helper.read_text().replace("return g", "return 0.5 * g"))
    keys.append(_fingerprint(load_study(study)))
    helper.write_text(helper.read_text().replace("SCALE = 1.0", "SCALE = 2.0"))
    keys.append(_fingerprint(load_study(study)))
    assert len(set(keys)) == 3


def test_bad_parts_are_computed_again_and_force_keeps_good_ones(tmp_path, monkeypatch):
    """Each chunk of the store is checked before it is used: a chunk replaced by another's
    bytes, a truncated one, a missing one and one rewritten with other numbers (their
    checksums differ from those recorded when they were written), and one whose recorded
    checksum was edited to match but holds other grid points, are computed again, and
    say so; a chunk the manifest does not record (a kill between the two writes) is
    removed.  --force replaces the finished output but resumes from the chunks of this
    run.  Every way ends with the dataset of a clean run."""
    monkeypatch.setenv("STABDAE_FLUSH_SECONDS", "0")  # a chunk per grid point
    study = study_file(tmp_path, members=16, t_end=0.2, omegas="5.0")
    (tmp_path / "ref").mkdir()
    clean = run_study(study_file(tmp_path / "ref", members=16, t_end=0.2, omegas="5.0"),
                      progress=False, log=lambda *a: None)  # fmt: skip
    parts = tmp_path / "out" / "study.nc.parts"
    _interrupted(study, 6 - 1, monkeypatch)
    manifest = json.loads((parts / "study.json").read_text())
    assert [manifest["chunks"][f"chunk-{i}.npz"]["points"] for i in range(5)] == \
        [[0], [1], [2], [3], [4]]
    (parts / "chunk-0.npz").write_bytes((parts / "chunk-1.npz").read_bytes())
    data = (parts / "chunk-2.npz").read_bytes()
    (parts / "chunk-2.npz").write_bytes(data[: len(data) // 2])  # truncated
    (parts / "chunk-3.npz").unlink()
    with np.load(parts / "chunk-4.npz") as npz:  # opens, right key, other numbers
        arrays = dict(npz)
    arrays["d/fraction_bounded"] = arrays["d/fraction_bounded"] * 0 + 0.5
    np.savez(parts / "chunk-4.npz", **arrays)
    # chunk 1's bytes under the name of chunk 5, with a checksum that matches
    (parts / "chunk-5.npz").write_bytes((parts / "chunk-1.npz").read_bytes())
    manifest["chunks"]["chunk-5.npz"] = {**manifest["chunks"]["chunk-1.npz"], "points": [5]}
    (parts / "study.json").write_text(json.dumps(manifest))
    (parts / "chunk-6.npz").write_bytes(b"written, never recorded")
    said = []
    out = run_study(study, progress=False, log=said.append)
    said = "\n".join(map(str, said))
    assert "grid points 0: chunk-0.npz does not match its recorded checksum" in said
    assert "grid points 2: chunk-2.npz does not match its recorded checksum" in said
    assert "grid points 3: chunk-3.npz is missing: computing them again" in said
    assert "grid points 4: chunk-4.npz does not match its recorded checksum" in said
    assert "grid points 5: chunk-5.npz holds other grid points than recorded" in said
    assert "resuming: 1 of 6 grid points already done" in said
    same_data(xr.open_dataset(out).load(), xr.open_dataset(clean).load())
    # --force replaces the output; the chunks this run wrote are resumed, not discarded
    out.unlink()
    _interrupted(study, 2, monkeypatch)
    out.write_bytes(clean.read_bytes())
    said = []
    out = run_study(study, force=True, progress=False, log=said.append)
    assert "resuming: 2 of 6 grid points already done" in said
    same_data(xr.open_dataset(out).load(), xr.open_dataset(clean).load())


def _stored_and_read_back(tmp_path, tables):
    """A store that wrote ``tables`` as one chunk, and a second one that read it back."""
    from stabdae.study.store import Manifest, Store

    parts = tmp_path / "parts"
    parts.mkdir()
    store = Store(Manifest(parts, "key", "study"))
    for i, table in tables.items():
        store.add(i, table)
    store.flush()
    again = Store(Manifest.read(parts))
    again.resume(len(tables), log=lambda *a: pytest.fail(str(a)))
    return again


def test_the_store_gives_back_every_table_as_it_was(tmp_path):
    """A chunk read back gives each grid point's table exactly: the values, their types,
    the dimensions, every attribute (numpy scalars and arrays of their own type, a
    variable's attribute that differs between points, a global one that one point lacks)
    and the coordinates."""
    from stabdae.study.spec import load_study

    study = load_study(study_file(tmp_path, members=16, t_end=0.2, omegas="5.0, 30.0"))
    from stabdae.study.run import run_point

    tables = {i: run_point(study, values) for i, (_, values) in enumerate(study.points())}
    tables[3].data["stability_radius"][2]["comment"] = "this point's own"
    tables[2].attrs["only_here"] = np.float32(0.25)
    del tables[1].attrs["model"]
    again = _stored_and_read_back(tmp_path, tables)
    assert sorted(again.tables) == sorted(tables)
    for i, table in tables.items():
        got = again.tables[i]
        xr.testing.assert_identical(got.to_dataset(), table.to_dataset())
        for name, (_, values, _) in table.data.items():
            assert got.data[name][1].dtype == np.asarray(values).dtype, name
        assert got.attrs.keys() == table.attrs.keys()
    assert type(again.tables[2].attrs["only_here"]) is np.float32


def test_the_store_gives_back_tables_of_different_member_counts(tmp_path):
    """Grid points decided after different numbers of members share a chunk: each
    variable's tables of different shapes come back each with its own shape and values."""
    from stabdae.study.run import run_point
    from stabdae.study.spec import load_study

    tables = {}
    for i, members in enumerate((16, 48, 32)):
        (tmp_path / str(i)).mkdir()
        study = load_study(study_file(tmp_path / str(i), members=members, t_end=0.2,
                                      omegas="5.0"))  # fmt: skip
        tables[i] = run_point(study, next(iter(study.points()))[1])
    assert len({t.data["alpha0"][1].shape for t in tables.values()}) == 3
    again = _stored_and_read_back(tmp_path, tables)
    for i, table in tables.items():
        xr.testing.assert_identical(again.tables[i].to_dataset(), table.to_dataset())


def test_a_dataset_that_cannot_be_written_leaves_every_point_to_resume(tmp_path, monkeypatch):
    """The last grid points are kept in memory until the dataset is written; when that
    write fails they go to the store, and the run again computes none of them."""
    import stabdae.study.run as runner

    study = study_file(tmp_path, members=16, t_end=0.2, omegas="5.0")

    def full_disk(ds, path, **kwargs):
        raise OSError(f"could not write {path}: no space left")

    monkeypatch.setattr(runner, "write_netcdf", full_disk)
    with pytest.raises(OSError, match="no space left"):
        run_study(study, progress=False, log=lambda *a: None)
    assert recorded(tmp_path / "out" / "study.nc.parts") == 6
    monkeypatch.setattr(runner, "write_netcdf", write_netcdf)
    monkeypatch.setattr(runner, "run_point", lambda *a, **k: pytest.fail("computed again"))
    said = []
    run_study(study, progress=False, log=said.append)
    assert "resuming: 6 of 6 grid points already done" in said


def test_the_run_accounts_for_its_time(tmp_path):
    """The run's last line splits its wall time into sampling and integration, compiling
    (or loading compiled code), and the rest, and they add up to it."""
    import re

    said = []
    run_study(study_file(tmp_path, members=16, t_end=0.2, omegas="5.0"), progress=False,
              log=said.append)  # fmt: skip
    line = str(said[-1])
    m = re.search(r"in ([\d.]+) s: sampling and integration ([\d.]+) s, compiling or loading "
                  r"compiled code ([\d.]+) s, the rest (-?[\d.]+) s\)", line)  # fmt: skip
    assert m, line
    wall, work, compiled, rest = map(float, m.groups())
    assert min(work, compiled, rest) >= 0.0
    assert work + compiled + rest == pytest.approx(wall, abs=0.025)


def test_force_never_removes_what_stabdae_did_not_write(tmp_path):
    """A folder at OUTPUT.parts that no stabdae run wrote (no manifest) is refused, with
    and without --force, and left as it was; the parts of another study are discarded by
    --force file by file (its points and manifest), leaving anything else in the folder."""
    study = study_file(tmp_path, members=8, t_end=0.2, omegas="5.0")
    parts = tmp_path / "out" / "study.nc.parts"
    parts.mkdir(parents=True)
    (parts / "thesis.tex").write_text("years of work")
    (parts / "point-0.nc").write_bytes(b"a file that only looks like a part")
    for force in (False, True):
        with pytest.raises(FileExistsError, match=r"was not written by a stabdae run"):
            run_study(study, force=force, progress=False, log=lambda *a: None)
        assert sorted(p.name for p in parts.iterdir()) == ["point-0.nc", "thesis.tex"]
    (parts / "point-0.nc").unlink()
    other = study_file(tmp_path, members=8, t_end=0.2, omegas="5.0, 30.0", name="other.toml")
    from stabdae.study.run import _fingerprint
    from stabdae.study.spec import load_study

    (parts / "study.json").write_text(json.dumps(
        {"fingerprint": _fingerprint(load_study(other)), "study": str(other)}))
    (parts / "point-0.nc").write_bytes(b"the other study's")
    out = run_study(study, force=True, progress=False, log=lambda *a: None)
    assert out.is_file()
    assert sorted(p.name for p in parts.iterdir()) == ["thesis.tex"]


def test_the_same_study_resumes_from_another_folder(tmp_path, monkeypatch):
    """The run key decides what a part holds, not the path the study was named by: an
    interrupted run resumes when started again from another working folder."""
    study = study_file(tmp_path, members=8, t_end=0.2, omegas="5.0")
    monkeypatch.chdir(tmp_path)
    _interrupted(Path("study.toml"), 2, monkeypatch)
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")
    said = []
    out = run_study(study, progress=False, log=said.append)
    assert "resuming: 2 of 6 grid points already done" in said and out.is_file()


def test_a_second_run_on_the_same_output_is_refused_while_the_first_lives(tmp_path):
    """Two runs writing one output would remove each other's parts: the parts folder is
    locked by the process that runs it, and a lock left by a dead process is taken over."""
    study = study_file(tmp_path, members=8, t_end=0.2, omegas="5.0")
    parts = tmp_path / "out" / "study.nc.parts"
    parts.mkdir(parents=True)
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        (parts / "lock").write_text(f"{sleeper.pid} somehost\n")
        with pytest.raises(FileExistsError, match=rf"being written by another stabdae run "
                                                  rf"\(process {sleeper.pid}\)"):  # fmt: skip
            run_study(study, progress=False, log=lambda *a: None)
    finally:
        sleeper.kill()
        sleeper.wait()
    out = run_study(study, progress=False, log=lambda *a: None)  # the holder is gone
    assert out.is_file() and not parts.exists()


def test_resume_with_another_member_count_starts_over_and_equals_a_clean_run(tmp_path,
                                                                           monkeypatch):
    """``--members`` changes the numbers without changing the study file: parts of 16
    members are not mixed into a run of 24 (the run key covers the ensemble settings as
    run); the resumed run starts over and equals a clean run of 24 members."""
    study = study_file(tmp_path, members=16, t_end=0.2, omegas="5.0")
    _interrupted(study, 2, monkeypatch)
    said = []
    out = run_study(study, members=24, progress=False, log=said.append)
    assert any("starting over" in line for line in said), said
    clean = tmp_path / "clean"
    clean.mkdir()
    (clean / "study.toml").write_text(study.read_text())
    ref = run_study(clean / "study.toml", members=24, progress=False, log=lambda *a: None)
    got = xr.open_dataset(out).load()
    assert got.sizes["member"] == 24
    same_data(got, xr.open_dataset(ref).load())


#: one change to each section of the study file that decides the numbers
_STUDY_EDITS = {
    "model parameter": ('file = "models/pend.py"',
                        'file = "models/pend.py"\nparams = {g = 1.62}'),
    "law": ("omega = 10.0", "omega = 11.0"),
    "scheme": ('name = "rk2"', 'name = "euler"'),
    "run": ("save_dt = 0.05", "save_dt = 0.1"),
    "ensemble": ("seed = 3", "seed = 4"),
    "grid": ("tau = [5e-4, 1e-3", "tau = [6e-4, 1e-3"),
}


def test_every_setting_that_decides_the_numbers_is_in_the_run_key(tmp_path, monkeypatch):
    """The run key changes with each thing that decides a grid point's numbers, one at a
    time: each section of the study file, the member count given on the command line, a
    module the model imports from its folder, the library's source and its version; and
    it does not change when nothing does (the same study loaded again)."""
    import stabdae.study.run as runner
    from stabdae.study.spec import load_study

    models = tmp_path / "models"
    models.mkdir()
    (models / "pend_local.py").write_text("G_SCALE = 1.0\n")
    source = (ROOT / "kernels" / "pendulum.py").read_text()
    (models / "pend.py").write_text("import pend_local  # noqa: F401\n" + source)
    text = STUDY.format(members=16, t_end=0.2, omegas="5.0").replace(
        'file = "pendulum"', 'file = "models/pend.py"')
    study = tmp_path / "study.toml"
    study.write_text(text)
    monkeypatch.syspath_prepend(str(models))

    def key(**kw):
        return runner._fingerprint(load_study(study, **kw))

    base = key()
    assert key() == base
    changed = {}
    for what, (old, new) in _STUDY_EDITS.items():
        assert old in text, what
        study.write_text(text.replace(old, new, 1))
        changed[what] = key()
    study.write_text(text)
    changed["--members"] = key(members=32)
    (models / "pend_local.py").write_text("G_SCALE = 2.0\n")
    changed["local module"] = key()
    (models / "pend_local.py").write_text("G_SCALE = 1.0\n")
    assert key() == base
    with monkeypatch.context() as m:
        m.setattr(runner, "library_fingerprint", lambda: "another library")
        changed["library source"] = key()
    with monkeypatch.context() as m:
        m.setattr(runner, "__version__", "0.0.0+other")
        changed["library version"] = key()
    same = [what for what, k in changed.items() if k == base]
    assert not same, f"the run key ignores: {same}"
    assert len(set(changed.values())) == len(changed)


def test_progress_counts_every_member_of_every_point(capsys):
    """The bar counts the members this run runs: before any point, the points left × the
    most members a point may run (a resumed run leaves out the points done); each point's
    members advance it, and a point done after fewer shrinks the total to what the points
    done need on average; the last point reads ``3/3``; disabled, or with no point to
    run, nothing is written."""
    from stabdae.study.run import _Progress

    bar = _Progress(3, 1, 10, True)  # 3 points, 1 done before, at most 10 members each
    assert (bar._bar.total, bar._bar.n) == (20, 0)
    bar.members(4, 10)
    assert bar._bar.n == 4
    bar.point_done(6)  # decided after 6 members: the other point is expected to need 6
    assert (bar._bar.total, bar._bar.n) == (12, 6)
    bar.members(10, 10)
    assert bar._bar.n == 16
    bar.point_done()  # the members reported: 10
    assert bar._bar.n == bar._bar.total == 16
    bar.close()
    assert "grid point 3/3" in capsys.readouterr().err
    for quiet in (_Progress(3, 0, 10, False), _Progress(0, 0, 10, True)):
        quiet.members(5, 10)
        quiet.note("boundary: tau = 0.1 stable")
        quiet.point_done()
        quiet.close()
        assert quiet._bar is None
    assert capsys.readouterr().err == ""


def test_progress_rate_and_time_left_start_after_compiling(capsys):
    """The first chunk of members waits for the kernels to compile (seconds to minutes):
    the bar's clock restarts when it is done, so that the rate and the time left are
    those of the integration (right after compiling the bar showed hours left)."""
    from stabdae.study.run import _Progress

    bar = _Progress(2, 0, 100, True)
    time.sleep(0.6)  # "compiling"
    bar.members(10, 100)
    assert bar._bar.n == 10 and bar._bar.format_dict["elapsed"] < 0.3
    time.sleep(0.1)
    bar.members(30, 100)
    fmt = bar._bar.format_dict
    assert fmt["n"] == 30 and fmt["initial"] == 10
    rate = (fmt["n"] - fmt["initial"]) / fmt["elapsed"]
    assert rate > 60  # 20 members in about 0.1 s, not in the 0.7 s since the start
    bar.members(100, 100)
    bar.point_done()
    bar.close()
    assert "kernels ready" in capsys.readouterr().err


def test_ctrl_c_during_a_write_takes_effect_once_the_file_is_written(tmp_path, monkeypatch):
    """SIGINT arriving while a dataset (a study's part, its final file) is being written:
    the file is finished, then KeyboardInterrupt is raised.  Interrupted inside the write,
    xarray's file lock was left held and the interrupted write's clean-up waited on it
    forever (a study that did not stop on Ctrl-C); here the old code lost the file."""
    ds = xr.Dataset({"a": ("x", np.arange(5.0))})
    real = xr.Dataset.to_netcdf

    def interrupted(self, *args, **kwargs):
        out = real(self, *args, **kwargs)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.2)  # Python runs a signal's handler at the next bytecode boundary
        return out

    monkeypatch.setattr(xr.Dataset, "to_netcdf", interrupted)
    # Python's own handler, as in a terminal (a test run started as a background job
    # inherits SIGINT ignored)
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            write_netcdf(ds, tmp_path / "a.nc")
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, before)
    with xr.open_dataset(tmp_path / "a.nc") as back:
        xr.testing.assert_identical(back.load(), ds)
