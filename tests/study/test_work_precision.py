"""studies/work_precision.py at reduced size: one scene, three settings per ladder, every
stabdae configuration and every peer (IDA when scikit-sundae is installed)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import xarray as xr

from conftest import ROOT, load_file

wp = load_file(ROOT / "studies" / "work_precision.py", "stabdae_study_work_precision")


def test_cost_at_interpolates_log_log():
    # errors 1e-4 at cost 1, 1e-8 at cost 100: 1e-6 is half way in log, cost 10
    cost, how = wp.cost_at([1e-4, 1e-8], [1.0, 100.0])
    assert how == "interpolated" and math.isclose(cost, 10.0, rel_tol=1e-12)
    assert math.isnan(wp.cost_at([1e-3, 1e-4], [1.0, 2.0])[0])
    assert wp.cost_at([1e-7, 1e-9], [3.0, 5.0]) == (3.0, "first run already below")


def test_work_precision_study_runs(tmp_path):
    summary = wp.main(["--scenes", "slider_crank", "--quick", "--out", str(tmp_path)])
    with xr.open_dataset(tmp_path / "work_precision.nc") as ds:
        ds = ds.load()
    for name in ("wall_s", "rhs_evaluations", "error", "digits", "residual"):
        assert ds[name].attrs["long_name"], name
    methods = set(zip(ds.method.values.tolist(), ds.stabilization.values.tolist()))
    ours = ("rk4", "dopri5", "dop853", "dopri5-adaptive", "dop853-adaptive")
    for stab in wp.STABILIZATIONS:
        for method in ours:
            assert (method, stab) in methods
    for peer in ("scipy-DOP853", "scipy-Radau"):
        assert (peer, "none") in methods and (peer, "projection") in methods
    try:
        import sksundae  # noqa: F401

        assert ("sundials-IDA", "none") in methods
    except ImportError:
        pass
    # every ladder gets more accurate as it gets more expensive …
    for method, stab in methods:
        mask = ((ds.method == method) & (ds.stabilization == stab)).values
        err = ds.error.values[mask]
        assert np.all(np.isfinite(err)), (method, stab)
        assert err[-1] < err[0], (method, stab, err)
    # … projections hold the residual at roundoff, the unstabilized runs drift
    proj = ds.where((ds.stabilization == "projection") & (ds.method == "rk4"), drop=True)
    none = ds.where((ds.stabilization == "none") & (ds.method == "rk4"), drop=True)
    assert proj.residual.max() < 1e-12 < none.residual.min()
    s = summary["slider_crank"]
    method, stab = s["best_stabdae"].split("/")
    assert method in ours and stab in wp.STABILIZATIONS  # a stabdae configuration
    for peer, v in s["peers"].items():  # the peer's time over the best stabdae time
        assert v["ratio_to_best_stabdae"] == pytest.approx(
            v["wall_s"] / s["best_stabdae_wall_s"], rel=1e-12), peer
    saved = json.loads((tmp_path / "work_precision.json").read_text())
    assert saved["at_target"]["slider_crank"]["best_stabdae"] == s["best_stabdae"]
    assert (tmp_path / "work_precision_time.png").stat().st_size > 10_000
    assert (tmp_path / "work_precision_evals.png").stat().st_size > 10_000


def test_ensemble_summary_picks_the_cheapest_run_and_reads_the_ladder_between_runs():
    """The ensemble benchmark's summary: the cheapest measured run at or below each error
    level per tool, their ratio, and each tool's cost read log–log along its ladder to the
    level itself (exact for a power law)."""
    bench = load_file(ROOT / "studies" / "bench_work_precision_ensemble.py",
                      "stabdae_study_bench_wpe")  # fmt: skip

    def ladder(tool, config, steps, c_err, c_cost, order):
        # error c_err · N^-order and cost c_cost · N: a power law, exact under log–log
        return [dict(tool=tool, config=config, setting=1.0 / n, error=c_err * n ** -order,
                     core_s_per_member=c_cost * n) for n in steps]  # fmt: skip

    rows = (ladder("stabdae", "dop853 fixed", (100, 200, 400), 5e3, 1e-8, 8)
            + ladder("stabdae", "rk4 fixed", (100, 200, 400), 1.0, 2e-8, 4)
            + ladder("heyoka", "batch, 1 thread", (50, 500), 1e2, 1e-7, 6))  # fmt: skip
    out = bench.summarize(rows, agreement=1e-16)
    level = bench.LEVELS[1]  # 1e-9
    e = out[f"{level:g}"]
    # measured: DOP853 is below 1e-9 from its first run (N = 100: 5e-13, cost 1e-6); RK4
    # from N = 200 (6.25e-10), at a cost of 4e-6
    assert e["stabdae"]["config"] == "dop853 fixed" and e["stabdae"]["setting"] == 1 / 100
    assert math.isclose(e["stabdae"]["core_s_per_member"], 1e-6)
    # heyoka reaches 1e-9 (1e2 · N⁻⁶ ≤ 1e-9 ⇔ N ≥ 10^(11/6) ≈ 68.1) at its N = 500 run
    assert e["heyoka"]["setting"] == 1 / 500
    assert math.isclose(e["stabdae_over_heyoka"], 1e-6 / 5e-5)
    # interpolated: heyoka's power law read at the level, N = 10^(11/6) exactly
    n_star = 10 ** (11 / 6)
    assert math.isclose(e["heyoka interpolated"]["core_s_per_member"], 1e-7 * n_star,
                        rel_tol=1e-12)  # fmt: skip
    # stabdae's first run is already below: its interpolated cost is that run's
    assert math.isclose(e["stabdae interpolated"]["core_s_per_member"], 1e-6)
    assert math.isclose(e["stabdae_over_heyoka_interpolated"], 1e-6 / (1e-7 * n_star),
                        rel_tol=1e-12)  # fmt: skip
    assert e["stabdae interpolated"]["config"] == "dop853 fixed"
    # RK4 read between its runs (N = 10^(9/4): 3.6e-6) is still dearer than DOP853's run;
    # at 1e-12 only DOP853 (N = 100) and heyoka (N = 500: 6.4e-15) reach the level
    e = out[f"{bench.LEVELS[2]:g}"]
    assert e["stabdae interpolated"]["config"] == "dop853 fixed"
    assert math.isclose(e["heyoka interpolated"]["core_s_per_member"], 1e-7 * 10 ** (14 / 6),
                        rel_tol=1e-12)  # fmt: skip
