"""The README's main study run until decided, against 4096 members at every grid point.

``studies/pendulum_tau_omega.toml`` (the planar pendulum under Baumgarte's law, midpoint
rule, 10 × 10 (τ, ω); ``[ensemble] members = { max = 1024, batch = 64 }``, the default
confidence 0.95 and q = 0.05), beside the same study with 4096 members at every
grid point.  Where the 4096-member run's exact 95 % interval of the unstable fraction
(Clopper–Pearson; its low end from the unstable members, its high end from those not
stable) lies on one side of q, the sequential decision must be the same.  Also: the same
study with batches of 32 (the members both ran, bit for bit the same), and the members
used in all against 256 × 100.  Writes the decision picture to ``--figure``.

Usage::

    python studies/certify_main.py [--out studies/results] [--figure docs/figures]
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import xarray as xr

from stabdae._codes import Verdict
from stabdae._sequential import bounds
from stabdae.plots import decision_map
from stabdae.study.run import run_study
from stabdae.study.spec import load_study

HERE = Path(__file__).resolve().parent
STUDY = HERE / "pendulum_tau_omega.toml"
WORDS = {int(v): v.message for v in Verdict}


def sequential_file(folder: Path, batch: int) -> Path:
    text = STUDY.read_text()
    text = re.sub(r"(?m)^members = .*$", f"members = {{ max = 1024, batch = {batch} }}", text)
    path = folder / f"sequential_{batch}.toml"
    path.write_text(text)
    return path


def run(path, out: Path, members=None) -> tuple[xr.Dataset, float]:
    clock = time.perf_counter()
    study = load_study(path, members=members)
    ds = xr.open_dataset(run_study(study, out, force=True, progress=False,
                                   log=lambda *a, **k: None)).load()  # fmt: skip
    return ds, time.perf_counter() - clock


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=HERE / "results")
    ap.add_argument("--figure", type=Path, default=HERE.parent / "docs" / "figures")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        seq, wall_seq = run(sequential_file(tmp, 64), tmp / "seq.nc")
        seq32, _ = run(sequential_file(tmp, 32), tmp / "seq32.nc")
        full, wall_full = run(STUDY, tmp / "full.nc", members=4096)
    q = float(seq.attrs["sequential_q"])
    verdict = full.verdict.values  # (tau, omega, member)
    n = verdict.shape[-1]
    unstable = (verdict == int(Verdict.UNSTABLE)).sum(-1)
    not_stable = (verdict != int(Verdict.STABLE)).sum(-1)
    agree, differ, excluded, rows = 0, [], 0, []
    for idx in np.ndindex(unstable.shape):
        low = bounds(unstable[idx], n, 0.025)[0]
        high = bounds(not_stable[idx], n, 0.025)[1]
        ref = 0 if high <= q else 1 if low > q else None
        d = int(seq.decision.values[idx])
        point = {"tau": float(seq.tau[idx[0]]), "omega": float(seq.omega[idx[1]])}
        if ref is None:
            rows.append({**point, "reference": "q inside its interval", "decision": WORDS[d]})
            continue
        excluded += 1
        if d == ref:
            agree += 1
        else:
            differ.append({**point, "reference": WORDS[ref], "decision": WORDS[d],
                           "reference_interval": [low, high],
                           "reason": int(seq.decision_reason.values[idx])})  # fmt: skip
    # the members both ran at each grid point: the same, bit for bit
    same_members = all(
        np.array_equal(seq[name].values[idx][:k], seq32[name].values[idx][:k], equal_nan=True)
        for idx in np.ndindex(unstable.shape)
        for k in [min(int(seq.members_used.values[idx]), int(seq32.members_used.values[idx]))]
        for name in seq.data_vars if seq[name].dims[2:] == ("member",)
    )  # fmt: skip
    report = {
        "members_used": int(seq.members_used.sum()),
        "members_used_batch_32": int(seq32.members_used.sum()),
        "members_fixed": 256 * seq.decision.size,
        "decisions": {WORDS[v]: int((seq.decision.values == v).sum()) for v in WORDS},
        "reasons_undecided": [
            {"tau": float(seq.tau[i]), "omega": float(seq.omega[j]),
             "reason": int(seq.decision_reason.values[i, j]),
             "members_used": int(seq.members_used.values[i, j]),
             "interval": [float(seq.decision_low.values[i, j]),
                          float(seq.decision_high.values[i, j])]}
            for i, j in zip(*np.nonzero(seq.decision.values == int(Verdict.UNDECIDED)))
        ],  # fmt: skip
        "reference_members": n,
        "reference_decided": excluded,
        "agree": agree,
        "differ": differ,
        "reference_undecided": rows,
        "same_decisions_batch_32": bool((seq.decision.values == seq32.decision.values).all()),
        "same_members_batch_32": bool(same_members),
        "wall_sequential_s": wall_seq,
        "wall_4096_s": wall_full,
    }
    print(json.dumps(report, indent=1))
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "certify_main.json").write_text(json.dumps(report, indent=1))
    args.figure.mkdir(parents=True, exist_ok=True)
    decision_map(seq, args.figure / "pendulum_tau_omega_decision.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
