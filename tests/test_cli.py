"""The command line: stabdae check and stabdae integrate."""

from __future__ import annotations

import subprocess
import sys

import xarray as xr

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
