"""The command line: stabdae check and stabdae integrate."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import xarray as xr

import stabdae
from conftest import KERNELS, ROOT
from stabdae.study.cli import main


def test_check_passes_on_a_scene(capsys):
    assert main(["check", str(KERNELS / "double_pendulum.py")]) == 0
    out = capsys.readouterr().out
    assert "all pieces agree" in out and "f_accel" in out


def test_check_fails_on_a_wrong_model(tmp_path, capsys):
    text = (KERNELS / "pendulum.py").read_text()
    wrong = text.replace("out[0] = 2.0 * (v[0] * v[0] + v[1] * v[1])",
                         "out[0] = 3.0 * (v[0] * v[0] + v[1] * v[1])")  # fmt: skip
    assert wrong != text
    path = tmp_path / "wrong_pendulum.py"
    path.write_text(wrong)
    assert main(["check", str(path)]) == 1
    assert "pieces that disagree: f_accel" in capsys.readouterr().out


def test_integrate_writes_a_dataset(tmp_path, capsys):
    out = tmp_path / "traj.nc"
    code = main(["integrate", "pendulum", "--t-end", "1", "--save-dt", "0.1", "-o", str(out)])
    assert code == 0
    text = capsys.readouterr().out
    assert "expm" in text and f"dataset written to {out}" in text
    with xr.open_dataset(out) as ds:
        assert ds.sizes["time"] == 11 and ds.attrs["scheme"] == "midpoint"
        assert float(ds.residual_norm[-1]) < float(ds.residual_norm[0])


def test_bad_input_exits_with_a_message(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "stabdae.study.cli", "integrate", "pendulum", "--tau", "0.3",
         "-o", str(tmp_path / "x.nc")],
        capture_output=True, text=True, cwd=ROOT,
    )  # fmt: skip
    assert proc.returncode == 2
    assert "must be a whole multiple of tau = 0.3" in proc.stderr


def _installed(*args, cwd=None, env=None):
    """The installed command line (stabdae on PATH next to this Python)."""
    exe = Path(sys.executable).with_name("stabdae")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "stabdae.study.cli"]
    return subprocess.run([*cmd, *args], capture_output=True, text=True, cwd=cwd, timeout=600,
                          env=env)  # fmt: skip


def test_version_and_one_line_errors(tmp_path):
    """--version; a missing dataset, a model file with a syntax error and bad worker counts
    give one line on stderr and exit 2, no traceback."""
    import stabdae

    out = _installed("--version")
    assert out.returncode == 0 and out.stdout.strip() == f"stabdae {stabdae.__version__}"
    out = _installed("plot", str(tmp_path / "nope.nc"))
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert out.stderr.startswith("stabdae plot: error:") and "nope.nc" in out.stderr
    bad = tmp_path / "bad_model.py"
    bad.write_text("import stabdae\nmodel = (\n")
    out = _installed("check", str(bad))
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert f"{bad}:2: SyntaxError" in out.stderr or f"{bad}:3: SyntaxError" in out.stderr
    for workers in ("-1", "0", "two"):
        out = _installed("run", "study.toml", "--workers", workers)
        assert out.returncode == 2 and "--workers: expected a positive integer" in out.stderr


def test_unreachable_scheduler_and_unwritable_output_give_one_line(tmp_path, monkeypatch,
                                                                   capsys):  # fmt: skip
    """An unreachable dask scheduler and an output folder that cannot be written: one line
    naming the address or the folder, exit 2, before anything is computed."""
    import os

    from conftest import study_file

    study = study_file(tmp_path, members=8, t_end=0.2, omegas="5.0")
    env = dict(os.environ, DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT="1s")
    out = _installed("run", str(study), "--scheduler", "tcp://127.0.0.1:9", "--quiet",
                     "--no-plots", env=env)  # fmt: skip
    assert out.returncode == 2 and "Traceback" not in out.stderr, out.stderr
    assert out.stderr.startswith("stabdae run: error: could not reach the dask scheduler at "
                                 "tcp://127.0.0.1:9")  # fmt: skip
    assert out.stderr.strip().count("\n") == 0
    # a read-only folder (simulated: as root, permissions do not deny writes)
    mkdir = Path.mkdir

    def read_only(self, *args, **kwargs):
        if self.name.endswith(".parts"):
            raise PermissionError(13, "Permission denied", str(self))
        return mkdir(self, *args, **kwargs)

    monkeypatch.setattr(Path, "mkdir", read_only)
    assert main(["run", str(study), "--quiet", "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert err == (f"stabdae run: error: cannot write in {tmp_path / 'out'} (Permission "
                   "denied); give an output folder you can write with -o\n")  # fmt: skip
    assert not (tmp_path / "out" / "study.nc").exists()


def test_run_output_folder_orphans_and_foreign_files(tmp_path):
    """-o with a folder writes <study>.nc inside it; a temporary file left by a killed write
    is removed; a file that is not a stabdae dataset is not replaced, even with --force."""
    from conftest import study_file

    study = study_file(tmp_path, members=8, t_end=0.2, omegas="5.0")
    folder = tmp_path / "outdir"
    folder.mkdir()
    orphan = folder / ".study.nc.abc123.tmp"
    orphan.write_bytes(b"half a dataset")
    out = _installed("run", str(study), "-o", str(folder), "--force", "--quiet", "--no-plots")
    assert out.returncode == 0, out.stderr
    assert (folder / "study.nc").is_file() and not orphan.exists()
    with xr.open_dataset(folder / "study.nc") as ds:
        assert "stabdae_version" in ds.attrs
    new = tmp_path / "newdir"
    out = _installed("run", str(study), "-o", f"{new}/", "--quiet", "--no-plots")
    assert out.returncode == 0 and (new / "study.nc").is_file(), out.stderr
    precious = tmp_path / "notes.nc"
    precious.write_text("my notes")
    out = _installed("run", str(study), "-o", str(precious), "--force", "--quiet",
                     "--no-plots")  # fmt: skip
    assert out.returncode == 2 and "is not a stabdae dataset" in out.stderr
    assert precious.read_text() == "my notes"


def test_integrate_with_rk3_and_with_a_tableau(tmp_path, capsys):
    tableau = '{"A": [[0, 0], [1, 0]], "b": [0.5, 0.5], "c": [0, 1], "order": 2}'
    out = tmp_path / "tab.nc"
    assert main(["integrate", "pendulum", "--tableau", tableau, "--t-end", "0.2",
                 "-o", str(out)]) == 0  # fmt: skip
    heun = tmp_path / "heun.nc"
    assert main(["integrate", "pendulum", "--scheme", "heun", "--t-end", "0.2",
                 "-o", str(heun)]) == 0  # fmt: skip
    with stabdae.open_dataset(out) as a, stabdae.open_dataset(heun) as b:
        assert a.attrs["scheme"] == "custom"
        np.testing.assert_array_equal(a.x.values, b.x.values)  # the same tableau as Heun's
    assert main(["integrate", "pendulum", "--scheme", "rk3", "--t-end", "0.2",
                 "-o", str(tmp_path / "rk3.nc")]) == 0  # fmt: skip
    assert main(["integrate", "pendulum", "--tableau", "[1, 2]"]) == 2
    assert "a tableau needs A, b, c and order" in capsys.readouterr().err


def test_progress_says_compiling_until_the_kernels_are_ready(tmp_path, capsys):
    """The progress bar reads "compiling" until the first members are done (no estimate
    of hours from a rate of zero), then how long the kernels took."""
    from conftest import study_file

    study = study_file(tmp_path, members=8, t_end=0.2, omegas="5.0")
    assert main(["run", str(study), "--no-plots"]) == 0
    err = capsys.readouterr().err
    assert "stabdae run (compiling)" in err and "kernels ready in" in err
    assert err.index("stabdae run (compiling)") < err.index("kernels ready in")
    compiling = err[: err.index("kernels ready in")]
    assert " 0/48 " in compiling and "?" in compiling  # no rate, no time left guessed


def test_progress_counts_the_members_that_ran(tmp_path, capsys):
    """Grid points run until decided: the bar counts the members that ran (not each
    point's max), and ends at its total, the sum of the points' members_used."""
    import re

    from conftest import study_file

    study = study_file(tmp_path, members="{ max = 256, batch = 16 }", t_end=0.2,
                       omegas="5.0")  # fmt: skip
    assert main(["run", str(study), "--no-plots"]) == 0
    err = capsys.readouterr().err
    counts = re.findall(r"\| (\d+)/(\d+) \[", err.replace("\r", "\n"))
    ds = xr.open_dataset(tmp_path / "out" / "study.nc")
    used = int(ds.members_used.sum())
    ds.close()
    assert used < 6 * 256  # decided before max: the old bar counted 6 × 256
    assert counts and counts[-1] == (str(used), str(used)), counts[-3:]
    assert all(int(n) <= used for n, _ in counts)


def test_plot_refuses_an_older_dataset_in_one_line(tmp_path, capsys):
    """A dataset written by an earlier version, without a variable this version's pictures
    read: one line that names both versions and what is missing, exit 2, no traceback;
    the same dataset with the variable plots."""
    import pytest

    import stabdae
    from conftest import pendulum_scene
    from stabdae._schema import write_netcdf

    ds = stabdae.ensemble(pendulum_scene(), stabdae.baumgarte(10.0), "midpoint", 0.01, 0.5,
                          members=16, seed=1)  # fmt: skip
    old = ds.drop_vars("residual_norm")
    old.attrs["stabdae_version"] = "0.0.1"
    write_netcdf(old, tmp_path / "old.nc")
    assert main(["plot", str(tmp_path / "old.nc")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert f"written by stabdae 0.0.1; stabdae {stabdae.__version__} plots what" in err
    assert "'residual_norm'" in err
    pytest.importorskip("matplotlib")
    write_netcdf(ds, tmp_path / "new.nc")
    assert main(["plot", str(tmp_path / "new.nc")]) == 0


def test_plot_of_a_file_that_is_not_netcdf_says_so_in_one_line(tmp_path, capsys):
    """A study file given to ``stabdae plot`` by mistake: one line that names the file and
    says it is not a NetCDF dataset (before: xarray's three lines about IO backends)."""
    study = tmp_path / "study.toml"
    study.write_text("[model]\nfile = 'pendulum'\n")
    assert main(["plot", str(study)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert f"{study} is not a NetCDF dataset" in err
