"""The on-disk kernel cache: a second process reuses the compiled ensemble kernel, an edited
model file is recompiled, functions that differ only in what they close over get
different keys."""

from __future__ import annotations

import json
import os
import pickle
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from numba import njit

import stabdae
from stabdae._loading import scene_dir
from stabdae.engine.cache import function_fingerprint

SRC = Path(__file__).resolve().parents[2] / "src"

CHILD = textwrap.dedent(
    """
    import json, sys, time
    import numpy as np
    import stabdae
    from stabdae.engine.ensemble.block import ensemble_kernel_for
    from stabdae.engine.sampler import sampler_for
    from stabdae._laws import bind_law
    from stabdae.engine import linalg
    written, rewrite = [], linalg._scalarized_tree  # the written-out code parsed, rewritten
    linalg._scalarized_tree = lambda source: written.append(1) or rewrite(source)
    clock = time.perf_counter()
    model = stabdae.load_model(sys.argv[1])
    law = stabdae.baumgarte(10.0, 1.0)
    ds = stabdae.ensemble(model, law, "midpoint", tau=1e-3, t_end=0.2, members=8,
                          radius=(1e-5, 1e-4), seed=3)
    first = time.perf_counter() - clock
    bound = bind_law(law, model)
    kernels = [sampler_for(model), ensemble_kernel_for(model, bound, stabdae.midpoint(), 64)]
    print(json.dumps(dict(
        hits=sum(sum(k.stats.cache_hits.values()) for k in kernels),
        misses=sum(sum(k.stats.cache_misses.values()) for k in kernels),
        sampler=[sum(kernels[0].stats.cache_hits.values()),
                 sum(kernels[0].stats.cache_misses.values())],
        seconds=first,
        written=len(written),
        x_final=ds.x_final.values.tolist(),
    )))
    """
)


def _child(model_file: Path, cache: Path, ahead: str = "0") -> dict:
    env = dict(os.environ, STABDAE_CACHE_DIR=str(cache), PYTHONPATH=str(SRC),
               STABDAE_COMPILE_AHEAD=ahead)  # fmt: skip
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
    # the written-out linear algebra is generated only for a compilation: none here
    assert first["written"] > 0 and second["written"] == 0
    assert second["x_final"] == first["x_final"]  # the cached code computes the same numbers
    print(f"first process {first['seconds']:.2f} s, second {second['seconds']:.2f} s")

    # a changed model (here: a different default length) must not reuse the old kernels
    text = model_file.read_text()
    model_file.write_text(text + "\n# edited\n")
    third = _child(model_file, cache)
    assert third["hits"] == 0 and third["misses"] == 2
    assert third["x_final"] == first["x_final"]


def test_a_helper_process_compiles_the_sampler_while_the_kernel_compiles(tmp_path):
    """A new model's first ensemble, with two CPUs and the kernel cache: a helper process
    compiles the sampler into the cache while the ensemble compiles its kernel, and the
    ensemble loads the sampler from there (one hit, no miss; the kernel one miss).  The
    numbers are those of a process that compiled both itself, where the helper was
    switched off."""
    from stabdae.engine.ahead import _usable_cpus

    if _usable_cpus() < 2:
        pytest.skip("the helper runs only with two usable CPUs")
    model_file = tmp_path / "pendulum_ahead.py"
    model_file.write_text((scene_dir() / "pendulum.py").read_text())
    alone = _child(model_file, tmp_path / "alone")
    assert alone["sampler"] == [0, 1] and alone["misses"] == 2
    helped = _child(model_file, tmp_path / "helped", ahead="always")  # (the suite loads it)
    assert helped["sampler"] == [1, 0] and helped["hits"] == 1 and helped["misses"] == 1
    assert helped["x_final"] == alone["x_final"]
    print(f"first ensemble alone {alone['seconds']:.2f} s, helped {helped['seconds']:.2f} s")


def test_the_helper_starts_only_where_it_can_gain_and_a_failed_one_is_waited_out(
        tmp_path, monkeypatch):  # fmt: skip
    """No helper for a model not loaded from a file, with the cache or the helper switched
    off, or a sampler already compiled; a helper that cannot load its model ends, and
    ``join`` says it did not finish cleanly (the ensemble then compiles the sampler)."""
    from stabdae._laws import bind_law
    from stabdae.engine import ahead
    from stabdae.engine.ensemble.block import ensemble_kernel_for
    from stabdae.engine.sampler import sampler_for

    monkeypatch.setattr(ahead, "_usable_cpus", lambda: 2)
    monkeypatch.setattr(ahead, "busy_cpus", lambda: 0.2)  # this process alone on the machine
    monkeypatch.setenv("STABDAE_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv(ahead.ENV, "1")
    model_file = tmp_path / "pendulum_guard.py"
    model_file.write_text((scene_dir() / "pendulum.py").read_text())
    model = stabdae.load_model(model_file)
    assert model._origin == (str(model_file), "model")
    sampler = sampler_for(model)
    kernel = ensemble_kernel_for(model, bind_law(stabdae.baumgarte(10.0), model),
                                 stabdae.midpoint(), 64)  # fmt: skip
    assert ahead.enabled() and not ahead.on_disk(sampler) and not ahead.on_disk(kernel)
    for env, value in ((ahead.ENV, "0"), ("STABDAE_CACHE_DIR", "off")):
        with monkeypatch.context() as m:
            m.setenv(env, value)
            assert ahead.sampler_ahead(model, sampler, kernel) is None, env
    monkeypatch.setattr(ahead, "_usable_cpus", lambda: 1)
    assert ahead.sampler_ahead(model, sampler, kernel) is None
    monkeypatch.setattr(ahead, "_usable_cpus", lambda: 2)
    with monkeypatch.context() as m:  # another process keeps the second CPU busy
        m.setattr(ahead, "busy_cpus", lambda: 1.0)
        assert ahead.sampler_ahead(model, sampler, kernel) is None
        m.setenv(ahead.ENV, "always")
        started = ahead.sampler_ahead(model, sampler, kernel)
        assert started is not None
        started.stop()
    anonymous = model.replace()  # built in this process: no file to load it from
    assert ahead.sampler_ahead(anonymous, sampler_for(anonymous), kernel) is None
    model._origin = (str(model_file), "no_such_model")
    helper = ahead.sampler_ahead(model, sampler, kernel)
    assert helper is not None and helper.join(60) is False


@pytest.mark.parametrize(("cpus", "busy", "idle"), [
    (2, 0.0, True), (2, 0.5, True), (2, 0.6, False), (2, 1.0, False), (2, 6.5, False),
    (1, 0.0, False), (4, 2.5, True), (4, 2.6, False), (16, 14.5, True),
])  # fmt: skip
def test_the_helper_needs_a_cpu_idle_beside_this_process(cpus, busy, idle):
    """A CPU is idle beside this process when other work leaves more than one and a half
    of the usable CPUs (one for this process's compiling): on a machine other work keeps
    busy the helper would compete with this process, which the first ensemble waits for."""
    from stabdae.engine.ahead import idle_cpu

    assert idle_cpu(cpus, busy) is idle


def test_a_busy_process_beside_is_seen_as_a_busy_cpu():
    """What the rule reads: a process spinning beside this one keeps about one CPU busy
    (this process sleeps while the counters are read, so its own share is not counted)."""
    import subprocess
    import sys
    import time

    from stabdae.engine.ahead import busy_cpus

    spin = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        time.sleep(0.3)
        assert busy_cpus() >= 0.6
    finally:
        spin.kill()
        spin.wait()


def test_waiting_for_a_helper_counts_as_compiling():
    import time

    from stabdae.engine.jit import compile_seconds, compiling_elsewhere

    before = compile_seconds()
    with compiling_elsewhere():
        time.sleep(0.2)
    assert compile_seconds() - before >= 0.2


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
    from stabdae.engine.cache import cache_dir, keyed_cache

    monkeypatch.setenv("STABDAE_CACHE_DIR", value)
    assert cache_dir() is None
    d = njit(lambda x: x)
    before = d._cache
    assert keyed_cache(d, "some-key") is d and d._cache is before


INTEGRATE = textwrap.dedent(
    """
    import json, sys
    import stabdae
    from test_cache import given_states
    out = {}
    for name in sys.argv[1:]:
        model = stabdae.load_model(name)
        ds = stabdae.ensemble(model, stabdae.baumgarte(200.0, 0.5), "euler", 1e-3, 0.2,
                              x0=given_states(model))
        out[name] = [ds.x_final.values.tolist(), ds.energy_drift.values.tolist()]
    print(json.dumps(out))
    """
)


def given_states(model):
    """Eight states off the constraints by up to 7e-4: given states, so that only the
    ensemble kernel compiles (no sampler, no reference trajectory)."""
    return model.reference_state() + 1e-4 * np.arange(8.0)[:, None]


def test_a_kernel_loaded_from_the_cache_does_not_capture_a_fresh_compile(tmp_path):
    """Process 1 compiles and caches the pendulum's kernels.  Process 2 loads them, then
    compiles the double pendulum's (the same closures under the same names but for the
    key, see ``_cache.tag``).  The pendulum must give process 1's numbers, the double
    pendulum those of the same ensemble run in this process."""

    def run(*names, cache=str(tmp_path)):
        env = dict(os.environ, STABDAE_CACHE_DIR=cache,
                   PYTHONPATH=os.pathsep.join([str(SRC), str(Path(__file__).parent)]))
        out = subprocess.run([sys.executable, "-c", INTEGRATE, *names], env=env, check=True,
                             capture_output=True, text=True, timeout=300)  # fmt: skip
        return json.loads(out.stdout.strip().splitlines()[-1])

    first = run("pendulum")
    both = run("pendulum", "double_pendulum")
    assert both["pendulum"] == first["pendulum"]
    model = stabdae.load_model("double_pendulum")
    reference = stabdae.ensemble(model, stabdae.baumgarte(200.0, 0.5), "euler", 1e-3, 0.2,
                                 x0=given_states(model))  # fmt: skip
    assert both["double_pendulum"] == [reference.x_final.values.tolist(),
                                       reference.energy_drift.values.tolist()]


# ---------------------------------------------------------------- what the key covers
MODEL_WITH_GLOBAL = '''
import os
import numpy as np
from numba import njit
import stabdae
import consts_mod
from helper_mod import radial_accel

G = float(os.environ.get("STABDAE_TEST_G", "9.81"))  # read when the file is loaded


@njit
def forces(t, q, v, p, out):
    out[0] = 0.0
    out[1] = G * consts_mod.SCALE


@njit
def f(t, q, p, out):
    out[0] = q[0] * q[0] + q[1] * q[1] - 1.0


@njit
def f_q(t, q, p, out):
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]


@njit
def f_accel(t, q, v, p, out):
    out[0] = radial_accel(v)


model = stabdae.Model("global_pendulum", n=2, m=1, forces=forces, f=f, f_q=f_q,
                      f_accel=f_accel, reference_state=np.array([0.0, -1.0, 1.0, 0.0]))
'''
HELPER = '''
from numba import njit


@njit
def radial_accel(v):
    return 2.0 * (v[0] * v[0] + v[1] * v[1])
'''
RUN_MODEL = textwrap.dedent(
    """
    import importlib.util, json, sys, warnings
    import stabdae
    path, how = sys.argv[1], sys.argv[2]
    sys.path.insert(0, str(__import__("pathlib").Path(path).parent))
    if how == "unregistered":  # as plugin loaders and notebooks run a file
        spec = importlib.util.spec_from_file_location("<dynamic>", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        model = module.model
    else:
        model = stabdae.load_model(path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = stabdae.integrate(model, None, stabdae.baumgarte(10.0), "rk4", 1e-3, 0.3)
    print(json.dumps({"x": ds.x.values[-1].tolist(),
                      "warnings": [str(w.message) for w in caught]}))
    """
)


def _run_model(path, cache, how="load", **env_extra):
    env = dict(os.environ, STABDAE_CACHE_DIR=str(cache), PYTHONPATH=str(SRC), **env_extra)
    out = subprocess.run([sys.executable, "-c", RUN_MODEL, str(path), how], env=env,
                         capture_output=True, text=True, timeout=300)  # fmt: skip
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


@pytest.fixture
def model_folder(tmp_path):
    folder = tmp_path / "model"
    folder.mkdir()
    (folder / "global_pendulum.py").write_text(MODEL_WITH_GLOBAL)
    (folder / "helper_mod.py").write_text(HELPER)
    (folder / "consts_mod.py").write_text("SCALE = 1.0\n")
    return folder / "global_pendulum.py"


def test_a_global_read_at_run_time_and_an_edited_helper_are_in_the_key(model_folder, tmp_path):
    """numba freezes a global's value into the compiled code: a second process with
    another value must not reuse the first one's kernel.  And a helper module the model
    imports from its folder is keyed by its content: editing it recompiles."""
    cache = tmp_path / "cache"
    earth = _run_model(model_folder, cache)
    moon = _run_model(model_folder, cache, STABDAE_TEST_G="1.62")
    assert moon["x"] != earth["x"]  # a kernel of its own, not the earth's
    helper = model_folder.parent / "helper_mod.py"
    helper.write_text(HELPER.replace("2.0 * (", "2.0 * 1.5 * ("))  # a different f_accel
    edited = _run_model(model_folder, cache)
    assert edited["x"] == _run_model(model_folder, "off")["x"] != earth["x"]
    # a module attribute the model reads (consts_mod.SCALE): its value is in the key
    (model_folder.parent / "consts_mod.py").write_text("SCALE = 1.25\n")
    assert _run_model(model_folder, cache)["x"] != edited["x"]


def test_the_values_of_module_attributes_a_function_reads_are_in_its_key():
    """``consts.G`` inside a model function is frozen into the compiled code like a
    global: the function's key holds the attribute's value, and a nested module's too."""
    import types

    consts = types.ModuleType("stabdae_test_consts")
    consts.inner = types.ModuleType("stabdae_test_consts.inner")
    consts.G, consts.inner.K, consts.unused = 9.81, 2.0, 1.0

    def forces(t, q, v, p, out):
        out[0] = consts.G * consts.inner.K

    first = function_fingerprint(forces)
    consts.unused = 5.0  # not read: the key stays
    assert function_fingerprint(forces) == first
    consts.G = 1.62
    moon = function_fingerprint(forces)
    consts.inner.K = 3.0
    assert len({first, moon, function_fingerprint(forces)}) == 3
    consts.inner.K = object()  # a value without a fingerprint: no key, not a wrong one
    assert function_fingerprint(forces) is None


def test_an_unregistered_module_runs_twice_in_a_fresh_cache(model_folder, tmp_path):
    """A model module executed without being registered in sys.modules: the second
    process must not crash on a kernel from the cache (it compiles again if it cannot
    load it), and a properly loaded run afterwards still works."""
    cache = tmp_path / "cache"
    first = _run_model(model_folder, cache, "unregistered")
    second = _run_model(model_folder, cache, "unregistered")
    proper = _run_model(model_folder, cache)
    assert first["x"] == second["x"] == proper["x"]


def test_a_truncated_cache_and_an_unusable_cache_folder_still_compile_and_run(model_folder,
                                                                              tmp_path):
    """Every cache file cut in half: the next run compiles again, warns, and gives the same
    numbers.  A cache folder that cannot be created (a file in its place): the run compiles
    in memory and says so."""
    cache = tmp_path / "cache"
    first = _run_model(model_folder, cache)
    files = [p for p in (cache / "kernels").iterdir() if p.is_file()]
    assert files
    for p in files:
        data = p.read_bytes()
        p.write_bytes(data[: len(data) // 2])
    again = _run_model(model_folder, cache)
    assert again["x"] == first["x"]
    assert any("could not be loaded" in w for w in again["warnings"]), again["warnings"]
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("a file where the cache folder would be")
    blocked = _run_model(model_folder, blocker / "cache")
    assert blocked["x"] == first["x"]
    assert any("cache" in w for w in blocked["warnings"]), blocked["warnings"]


def test_without_numbas_private_caching_api_kernels_compile_in_memory(monkeypatch):
    from stabdae.engine import cache as kc

    monkeypatch.setattr(kc, "CACHING_API", False)
    monkeypatch.setattr(kc, "_WARNED", set())
    d = njit(lambda x: 2.0 * x)
    before = d._cache
    with pytest.warns(RuntimeWarning, match="kernel cache unavailable"):
        assert kc.keyed_cache(d, "some-key") is d
    assert d._cache is before and d(1.5) == 3.0


IMPORT_PLAIN = textwrap.dedent(
    """
    import sys
    sys.path.insert(0, sys.argv[1])
    import pendulum_cached
    model = pendulum_cached.model
    for piece in model.functions:  # compiled when first called: the entries are used here
        model.evaluate(piece, model.t0, model.reference_state())
    print(model.name, pendulum_cached.__name__)
    """
)
LOAD = textwrap.dedent(
    """
    import sys
    import stabdae
    model = stabdae.load_model(sys.argv[1])
    for piece in model.functions:
        model.evaluate(piece, model.t0, model.reference_state())
    print(model.name, [k for k, m in sys.modules.items()
                       if not k.startswith("__") and getattr(m, "model", None) is model])
    """
)


def test_a_cached_model_file_loads_and_imports_under_one_name(tmp_path):
    """A model file whose functions are ``@njit(cache=True)``: numba's entries (made when
    a piece is first evaluated) name the module they were compiled in.  load_model gives
    the file the name a plain import does, so a process that imports it and one that loads
    it share the entries both ways; an entry made under another name (here: loaded with
    importlib under a made-up one) is passed over, not an error."""
    model_file = tmp_path / "pendulum_cached.py"
    model_file.write_text((scene_dir() / "pendulum.py").read_text())
    assert "@njit(cache=True)" in model_file.read_text()
    env = dict(os.environ, PYTHONPATH=str(SRC), STABDAE_CACHE_DIR=str(tmp_path / "cache"))

    def run(code, arg):
        out = subprocess.run([sys.executable, "-c", code, str(arg)], env=env, text=True,
                             capture_output=True, timeout=300)  # fmt: skip
        assert out.returncode == 0, out.stderr
        return out.stdout.strip().splitlines()[-1]

    other_name = textwrap.dedent(
        """
        import importlib.util, sys
        spec = importlib.util.spec_from_file_location("elsewhere_named", sys.argv[1])
        module = importlib.util.module_from_spec(spec)
        sys.modules["elsewhere_named"] = module
        spec.loader.exec_module(module)
        for piece in module.model.functions:
            module.model.evaluate(piece, 0.0, module.model.reference_state())
        print(module.model.name)
        """
    )
    assert run(other_name, model_file) == "pendulum"  # entries made under "elsewhere_named"
    assert any((tmp_path / "__pycache__").glob("*.nbi"))
    assert run(LOAD, model_file) == "pendulum ['pendulum_cached']"
    assert run(IMPORT_PLAIN, tmp_path) == "pendulum pendulum_cached"
    assert run(LOAD, model_file) == "pendulum ['pendulum_cached']"


def test_load_model_sees_an_edited_file_and_an_edited_helper(model_folder, monkeypatch):
    """In one process (a notebook): editing the model file, or a helper module it reads,
    and calling load_model again gives the edited model, not the one loaded before; an
    unedited file gives the same model object."""
    monkeypatch.syspath_prepend(str(model_folder.parent))
    first = stabdae.load_model(model_folder)
    assert stabdae.load_model(model_folder) is first
    model_folder.write_text(MODEL_WITH_GLOBAL.replace('"global_pendulum"', '"edited"'))
    edited = stabdae.load_model(model_folder)
    assert edited.name == "edited"
    consts = model_folder.parent / "consts_mod.py"
    consts.write_text("SCALE = 2.0\n")
    again = stabdae.load_model(model_folder)
    assert again is not edited
    forces = again.functions["forces"]
    assert forces.py_func.__globals__["consts_mod"].SCALE == 2.0


def test_bounds_checked_kernels_are_keyed_apart(monkeypatch):
    """NUMBA_BOUNDSCHECK=1 asks for kernels that check every index: a kernel compiled
    without the checks must not come back from the cache."""
    import numba

    from stabdae.engine.cache import fingerprint

    monkeypatch.setattr(numba.config, "BOUNDSCHECK", 0)
    plain = fingerprint("pendulum", 2, 1, 0)
    monkeypatch.setattr(numba.config, "BOUNDSCHECK", 1)
    assert fingerprint("pendulum", 2, 1, 0) != plain


def test_a_damaged_numba_cache_entry_is_cleared_with_a_warning_that_names_it(tmp_path):
    """A model file's @njit(cache=True) functions with their numba cache entries
    overwritten: the model loads and evaluates, each damaged entry is named in one warning
    (not blamed on the model), and the next process finds a sound cache again."""
    model_file = tmp_path / "pendulum_damaged.py"
    model_file.write_text((scene_dir() / "pendulum.py").read_text())
    load = ("import stabdae, sys; m = stabdae.load_model(sys.argv[1])\n"
            "for piece in m.functions: m.evaluate(piece, m.t0, m.reference_state())\n"
            "print(m.n)")
    env = dict(os.environ, PYTHONPATH=str(SRC))

    def run():
        out = subprocess.run([sys.executable, "-W", "always", "-c", load, str(model_file)],
                             env=env, capture_output=True, text=True, timeout=300)  # fmt: skip
        assert out.returncode == 0, out.stderr[-3000:]
        assert out.stdout.strip() == "2"
        return out.stderr

    run()
    entries = sorted((tmp_path / "__pycache__").glob("pendulum_damaged.*.nbc"))
    assert len(entries) >= 4
    for entry in entries:
        entry.write_bytes(b"not a pickle")
    said = run()
    assert "numba's on-disk cache entry of forces in" in said and "was damaged" in said
    assert "Model" not in said
    assert "damaged" not in run()


TWO_LAWS = textwrap.dedent(
    """
    import json, sys, warnings
    import stabdae
    sys.path.insert(0, str(__import__("pathlib").Path(sys.argv[1]).parent))
    model = stabdae.load_model(sys.argv[1])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = {name: stabdae.integrate(model, None, law, "rk4", 1e-3, 0.3).x.values[-1].tolist()
               for name, law in (("baumgarte", stabdae.baumgarte(10.0)),
                                 ("acpr", stabdae.acpr(10.0)))}
    print(json.dumps({"x": out, "warnings": [str(w.message) for w in caught]}))
    """
)


def test_a_cache_entry_knows_which_kernel_it_is(model_folder, tmp_path):
    """Two kernels' compiled code swapped between their cache files (the integrate loops
    under two kinds of law), then one byte of an entry changed: each entry carries
    the key of the kernel it belongs to and a checksum, so the next process compiles those
    again, with one warning that names the cache, and gives the first process's numbers
    (before: the stabilized run returned the unstabilized one's numbers)."""
    cache = tmp_path / "cache"
    env = dict(os.environ, STABDAE_CACHE_DIR=str(cache), PYTHONPATH=str(SRC))

    def run():
        out = subprocess.run([sys.executable, "-c", TWO_LAWS, str(model_folder)], env=env,
                             capture_output=True, text=True, timeout=300)  # fmt: skip
        assert out.returncode == 0, out.stderr[-3000:]
        return json.loads(out.stdout.strip().splitlines()[-1])

    first = run()
    assert first["x"]["baumgarte"] != first["x"]["acpr"]
    loops = sorted((cache / "kernels").glob("*integrate_kernel*.nbc"))
    assert len(loops) == 2, loops
    a, b = (p.read_bytes() for p in loops)
    loops[0].write_bytes(b)
    loops[1].write_bytes(a)
    again = run()
    assert again["x"] == first["x"]
    assert any("cache" in w and "does not match" in w for w in again["warnings"]), again
    data = bytearray(loops[0].read_bytes())  # rewritten by the run before
    data[len(data) // 2] ^= 0x01
    loops[0].write_bytes(bytes(data))
    third = run()
    assert third["x"] == first["x"]
    assert any("does not match" in w for w in third["warnings"]), third
    assert run()["warnings"] == []  # sound again


def test_compile_seconds_counts_the_compiling_of_a_new_function_and_nothing_else():
    """The clock of numba's compiler lock moves by the time a new function takes to
    compile, and not while compiled code runs."""
    import time

    import numba

    from stabdae.engine.jit import compile_seconds

    offset = time.time_ns()  # a constant of its own: never in any cache

    @numba.njit
    def fresh(x):
        s = 0.0
        for i in range(x):
            s += (i * offset) % 7
        return s

    before, clock = compile_seconds(), time.perf_counter()
    fresh(10)
    elapsed, counted = time.perf_counter() - clock, compile_seconds() - before
    assert 0.8 * elapsed <= counted <= elapsed
    before, clock = compile_seconds(), time.perf_counter()
    fresh(3_000_000)
    assert compile_seconds() - before < 0.01 * max(time.perf_counter() - clock, 0.01)


@pytest.mark.skipif(not stabdae.engine.jit.JIT, reason="numba's wrappers: needs the JIT")
def test_an_internal_function_has_no_wrappers_and_python_calls_reach_its_twin():
    """A kernel's piece compiled without numba's CPython and C wrappers: compiled callers
    call it; a call from Python (which would jump into a wrapper that is not there) goes
    to a twin compiled with them, made once; the piece's own compilation has neither."""
    from stabdae.engine.jit import from_python, internal

    @internal(error_model="numpy")
    def piece(x, out):
        out[0] = 2.0 * x
        return out[0] + 1.0

    @njit
    def caller(x):
        out = np.zeros(1)
        return piece(x, out)

    assert caller(3.0) == 7.0
    (sig,) = piece.signatures
    library = piece.overloads[sig].library
    assert "cpython" not in library.get_llvm_str() and "cfunc" not in library.get_llvm_str()
    out = np.zeros(1)
    assert piece(4.0, out) == 9.0 and out[0] == 8.0  # from Python: the twin
    twin = from_python(piece)
    assert twin is from_python(piece) and twin is not piece
    assert "cpython" in twin.overloads[twin.signatures[0]].library.get_llvm_str()
    assert from_python(caller) is caller  # anything else: itself


@pytest.mark.skipif(not stabdae.engine.jit.JIT, reason="numba's code libraries: needs the JIT")
def test_an_internal_function_is_compiled_for_its_callers_only(capfd):
    """An uncached piece gets no machine code of its own: its callers link its LLVM IR and
    compile it with theirs, so the engine holds no symbol of it, and the callers compute
    what the piece computes.  A piece whose code reads its environment (``print`` does)
    gets its machine code, and its environment, as before, and runs.  A piece cached on
    disk keeps numba's compilation (the cache stores machine code)."""
    from stabdae.engine.jit import _LINK_ONLY, internal

    if not _LINK_ONLY:
        pytest.skip("this numba has no hook to compile to LLVM IR only")

    @internal(error_model="numpy")
    def quiet(x, out):
        out[0] = 3.0 * x
        return out[0] - 1.0

    @internal()
    def loud(x):
        print("loud", x)
        return x + 0.5

    @njit
    def caller(x):
        out = np.zeros(1)
        return quiet(x, out) + loud(x) + out[0]

    assert caller(2.0) == 5.0 + 2.5 + 6.0
    assert "loud 2.0" in capfd.readouterr().out

    def address(piece):
        (sig,) = piece.signatures
        cres = piece.overloads[sig]
        return cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name)

    assert address(quiet) == 0
    assert address(loud) != 0
    out = np.zeros(1)
    assert quiet(2.0, out) == 5.0 and out[0] == 6.0  # from Python: the twin, as before

    @internal(cache=True)
    def cached(x):
        return x

    assert type(cached._compiler) is not type(quiet._compiler)


class _Mark:
    """Unpickled, it creates a file: what a crafted cache index could do."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return (os.system, (f"touch {self.path}",))


POWERS = (
    "import json, warnings\n"
    "import numpy as np\n"
    "from stabdae import theory\n"
    "with warnings.catch_warnings(record=True) as caught:\n"
    "    warnings.simplefilter('always')\n"
    "    out = theory.power_norms(np.array([[0.5, 1.0], [0.0, 0.25]]))\n"
    "print(json.dumps({'x': list(out), 'warnings': [str(w.message) for w in caught]}))\n"
)


def test_the_librarys_numba_cache_is_data_damaged_or_crafted(tmp_path):
    """The library's own ``@njit(cache=True)`` functions in numba's cache folder: entries
    overwritten gave ``_pickle.UnpicklingError`` on every later run (``theory``'s walk over
    the powers of R); an index is no longer a pickle, so a crafted one runs nothing.  Each
    damaged file is named in one warning, compiled again, and the next run is silent with
    the same numbers."""
    cache = tmp_path / "numba"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(SRC),
               STABDAE_CACHE_DIR="off")  # fmt: skip

    def run():
        out = subprocess.run([sys.executable, "-c", POWERS], env=env, capture_output=True,
                             text=True, timeout=300)  # fmt: skip
        assert out.returncode == 0, out.stderr[-3000:]
        return json.loads(out.stdout.strip().splitlines()[-1])

    first = run()
    walk = sorted(cache.rglob("theory._power_walk*.nbc")) + \
        sorted(cache.rglob("theory._power_walk*.nbi"))  # fmt: skip
    assert len(walk) == 2, sorted(cache.rglob("theory.*"))
    for path in walk:  # a pickle that would leave a mark if unpickled
        path.write_bytes(b"not a pickle")
    data, index = walk
    again = run()
    assert again["x"] == first["x"]
    assert run()["warnings"] == []
    mark = tmp_path / "ran"
    index.write_bytes(pickle.dumps(_Mark(mark)))  # numba's own index format: a pickle
    assert run()["x"] == first["x"] and not mark.exists()
    text = index.read_bytes()
    assert text.startswith(b"stabdae kernel cache index 1\n"), text[:80]
    index.write_bytes(text[: len(text) // 2])  # ours, cut short: named, then replaced
    said = run()
    assert said["x"] == first["x"]
    assert any(f"the cache index {index} is damaged" in w for w in said["warnings"]), said
    data.write_bytes(b"stabdae kernel cache entry 2\n" + b"x" * 100)
    said = run()
    assert said["x"] == first["x"]
    assert any(f"the cache entry {data} does not match" in w for w in said["warnings"]), said
    assert run()["warnings"] == []
