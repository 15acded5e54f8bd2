"""The on-disk kernel cache: a second process reuses the compiled ensemble kernel, an edited
model file is recompiled, functions that differ only in what they close over get
different keys."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from numba import njit

from stabdae._loading import scene_dir
from stabdae.kernels.cache import function_fingerprint

SRC = Path(__file__).resolve().parents[1] / "src"

CHILD = textwrap.dedent(
    """
    import json, sys, time
    import numpy as np
    import stabdae
    from stabdae.kernels.ensemble import ensemble_kernel_for
    from stabdae.kernels.sampler import sampler_for
    from stabdae._laws import bind_law
    clock = time.perf_counter()
    model = stabdae.load_model(sys.argv[1])
    law = stabdae.baumgarte(10.0, 1.0)
    ds = stabdae.ensemble(model, law, "midpoint", tau=1e-3, t_end=0.2, members=8,
                          radius=(1e-5, 1e-4), seed=3)
    first = time.perf_counter() - clock
    kernels = [sampler_for(model),
               ensemble_kernel_for(model, bind_law(law, model), stabdae.midpoint(), 64)]
    print(json.dumps(dict(
        hits=sum(sum(k.stats.cache_hits.values()) for k in kernels),
        misses=sum(sum(k.stats.cache_misses.values()) for k in kernels),
        seconds=first,
        x_final=ds.x_final.values.tolist(),
    )))
    """
)


def _child(model_file: Path, cache: Path) -> dict:
    env = dict(os.environ, STABDAE_CACHE_DIR=str(cache), PYTHONPATH=str(SRC))
    out = subprocess.run([sys.executable, "-c", CHILD, str(model_file)], env=env, check=True,
                         capture_output=True, text=True, timeout=300)  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_second_process_loads_the_kernels_and_an_edit_recompiles(tmp_path):
    model_file = tmp_path / "pendulum_copy.py"
    model_file.write_text((scene_dir() / "pendulum.py").read_text())
    cache = tmp_path / "cache"

    first = _child(model_file, cache)
    assert first["hits"] == 0 and first["misses"] == 2
    assert any((cache / "kernels").glob("*.nbi"))

    second = _child(model_file, cache)
    assert second["hits"] == 2 and second["misses"] == 0
    assert second["x_final"] == first["x_final"]  # the cached code computes the same numbers
    print(f"first process {first['seconds']:.2f} s, second {second['seconds']:.2f} s")

    # a changed model (here: a different default length) must not reuse the old kernels
    text = model_file.read_text()
    model_file.write_text(text + "\n# edited\n")
    third = _child(model_file, cache)
    assert third["hits"] == 0 and third["misses"] == 2
    assert third["x_final"] == first["x_final"]


def _scaled(c):
    @njit
    def f(x):
        return c * x

    return f


def test_closures_are_told_apart_by_what_they_capture():
    a, b, a2 = _scaled(1.0), _scaled(2.0), _scaled(1.0)
    assert function_fingerprint(a) != function_fingerprint(b)
    assert function_fingerprint(a) == function_fingerprint(a2)
    assert function_fingerprint(_scaled(np.ones(2))) != function_fingerprint(_scaled(np.zeros(2)))
    assert function_fingerprint(_scaled(object())) is None  # not fingerprintable: no cache


@pytest.mark.parametrize("value", ["off", "0"])
def test_cache_can_be_switched_off(monkeypatch, value):
    from stabdae.kernels.cache import cache_dir, keyed_cache

    monkeypatch.setenv("STABDAE_CACHE_DIR", value)
    assert cache_dir() is None
    d = njit(lambda x: x)
    before = d._cache
    assert keyed_cache(d, "some-key") is d and d._cache is before


INTEGRATE = textwrap.dedent(
    """
    import json, sys
    import stabdae
    out = {}
    for name in sys.argv[1:]:
        model = stabdae.load_model(name)
        ds = stabdae.ensemble(model, stabdae.baumgarte(200.0, 0.5), "euler", 1e-3, 0.2,
                              members=8, radius=(1e-6, 1e-4), seed=1)
        out[name] = [ds.x_final.values.tolist(), ds.energy_drift.values.tolist()]
    print(json.dumps(out))
    """
)


def test_a_kernel_loaded_from_the_cache_does_not_capture_a_fresh_compile(tmp_path):
    """Process 1 compiles and caches the pendulum's kernels.  Process 2 loads them, then
    compiles the double pendulum's (the same closures under the same names but for the
    key, see ``_cache.tag``).  Both must give the numbers of runs without any cache."""

    def run(*names, cache=str(tmp_path)):
        env = dict(os.environ, STABDAE_CACHE_DIR=cache, PYTHONPATH=str(SRC))
        out = subprocess.run([sys.executable, "-c", INTEGRATE, *names], env=env, check=True,
                             capture_output=True, text=True, timeout=300)  # fmt: skip
        return json.loads(out.stdout.strip().splitlines()[-1])

    first = run("pendulum")
    both = run("pendulum", "double_pendulum")
    reference = run("double_pendulum", cache="off")
    assert both["pendulum"] == first["pendulum"]
    assert both["double_pendulum"] == reference["double_pendulum"]
