"""Every error message of the model, law, scheme and integrate interfaces."""

from __future__ import annotations

import fractions

import numpy as np
import pytest
from numba import njit

import stabdae
from conftest import load_scene
from models.toy import unit_pendulum

# ---------------------------------------------------------------- a pendulum to break






@njit
def f_two_rows(t, q, p, out):
    out[0] = q[0] * q[0] + q[1] * q[1] - 1.0
    out[1] = q[0]


@njit
def f_q_three_columns(t, q, p, out):
    out[0, 0] = 2.0 * q[0]
    out[0, 1] = 2.0 * q[1]
    out[0, 2] = 0.0


@njit
def f_q_one_column(t, q, p, out):
    out[0, 0] = 2.0 * q[0]


@njit
def forces_nan(t, q, v, p, out):
    out[0] = 0.0
    out[1] = np.nan


@njit
def forces_bad_types(t, q, v, p, out):
    out[0] = "text"  # cannot compile
    out[1] = 0.0


@njit
def mass_identity(t, q, p, out):
    out[:, :] = 0.0
    out[0, 0] = 1.0
    out[1, 1] = 1.0


@njit
def energy_array(t, q, v, p):
    return np.zeros(2)


def forces_plain(t, q, v, p, out):
    out[0] = 0.0
    out[1] = 9.81




def build(**overrides):
    return unit_pendulum("broken", **overrides)


def test_valid_model_builds():
    assert build().r == 1


def test_output_with_too_many_rows():
    with pytest.raises(
        stabdae.ModelError,
        match=r"f\(t, q, p, out\) writes outside out: expected shape \(1,\) \(m from n=2, m=1, "
        r"k=0\), got \(2,\)",
    ):
        build(f=f_two_rows)


def test_output_with_too_many_columns():
    with pytest.raises(
        stabdae.ModelError, match=r"f_q\(t, q, p, out\) writes outside out: expected shape "
        r"\(1, 2\) .*got \(1, 3\)"
    ):  # fmt: skip
        build(f_q=f_q_three_columns)


def test_output_partly_unwritten():
    with pytest.raises(
        stabdae.ModelError,
        match=r"f_q\(t, q, p, out\) did not write every entry of out: expected shape \(1, 2\) "
        r".*got \(1, 1\); unwritten entries \[\(0, 1\)\]",
    ):
        build(f_q=f_q_one_column)


def test_counts_disagree_with_functions():
    """m = 2 declared, f writes one row: the shape got is named."""
    with pytest.raises(stabdae.ModelError, match=r"expected shape \(2,\) .*got \(1,\)"):
        build(m=2)


def test_non_finite_value():
    with pytest.raises(
        stabdae.ModelError,
        match=r"forces\(t, q, v, p, out\) returned non-finite values .*\[\(1,\)\]",
    ):
        build(forces=forces_nan)


def test_plain_python_function():
    with pytest.raises(
        stabdae.ModelError, match=r"forces must be an @njit function .*got a plain Python function"
    ):  # fmt: skip
        build(forces=forces_plain)


def test_compile_failure_is_named():
    with pytest.raises(stabdae.ModelError, match=r"forces\(t, q, v, p, out\) .*failed"):
        build(forces=forces_bad_types)


@njit
def forces_python_only(t, q, v, p, out):
    out[0] = 0.0
    out[1] = float(fractions.Fraction(1, 1))  # runs as Python; numba cannot type it


def test_loading_a_model_compiles_none_of_its_functions():
    """Construction runs the pieces as Python (the kernels compile their own copies):
    fresh dispatchers have no compiled signature after it, and one after evaluate."""
    base = build()
    fresh = {piece: njit(fn.py_func) for piece, fn in base.functions.items()}
    model = build(**fresh)
    assert all(fn.signatures == [] for fn in model.functions.values())
    assert model.evaluate("forces", 0.0, model.reference_state()).shape == (2,)
    assert len(model.functions["forces"].signatures) == 1
    assert model.functions["f_q"].signatures == []


def test_a_function_numba_cannot_compile_is_named_where_it_is_first_compiled():
    """It runs as Python, so the model loads; evaluate, check and integrate then name it
    (before, construction compiled every function and refused it there)."""
    model = build(forces=forces_python_only)
    x = model.reference_state()
    with pytest.raises(stabdae.ModelError, match=r"forces\(t, q, v, p, out\) failed to "
                                                 r"compile .*Fraction"):  # fmt: skip
        model.evaluate("forces", 0.0, x)
    with pytest.raises(stabdae.ModelError, match=r"forces\(t, q, v, p, out\) at check state "
                                                 r"0 failed to compile"):  # fmt: skip
        model.check()
    with pytest.raises(stabdae.ModelError, match=r"integrate: a function of model 'broken' "
                                                 r"raised TypingError"):  # fmt: skip
        stabdae.integrate(model, x, stabdae.baumgarte(10.0, 1.0), "rk4", 1e-3, 0.01, 0.01)


def test_missing_and_superfluous_pieces():
    with pytest.raises(stabdae.ModelError, match=r"m=1 holonomic constraints need \['f_accel'\]"):
        build(f_accel=None)
    with pytest.raises(stabdae.ModelError, match=r"f is given but m=0"):
        build(m=0, k=1)
    with pytest.raises(stabdae.ModelError, match=r"k=1 nonholonomic constraints need \['h', 'h_q'"):
        build(k=1)
    with pytest.raises(stabdae.ModelError, match=r"forces\(t, q, v, p, out\) is required"):
        build(forces=None)
    with pytest.raises(stabdae.ModelError, match=r"at least one constraint"):
        build(m=0, f=None, f_q=None, f_accel=None)
    with pytest.raises(stabdae.ModelError, match=r"r = m \+ k = 3 constraints on n = 2"):
        build(m=3)
    with pytest.raises(stabdae.ModelError, match=r"m must be a non-negative integer, got 1.5"):
        build(m=1.5)


def test_reference_state_shape_and_consistency():
    with pytest.raises(
        stabdae.ModelError,
        match=r"reference_state must have shape \(2n,\) = \(4,\) for n=2, got \(3,\)",
    ):
        build(reference_state=np.zeros(3))
    with pytest.raises(stabdae.ModelError, match=r"not on the constraint manifold.*'f_0'"):
        build(reference_state=np.array([0.0, -1.1, 1.0, 0.0]))
    with pytest.raises(stabdae.ModelError, match=r"not on the constraint manifold.*'fdot_0'"):
        build(reference_state=np.array([0.0, -1.0, 0.0, 1.0]))


def test_bad_energy_and_params():
    with pytest.raises(stabdae.ModelError, match=r"energy\(t, q, v, p\) must return a float"):
        build(energy=energy_array)
    with pytest.raises(stabdae.ModelError, match=r"parameter 'g' must be finite"):
        build(params={"g": np.inf})
    with pytest.raises(stabdae.ModelError, match=r"coordinates must name the n=2 coordinates"):
        build(coordinates=["x"])
    model = build(params={"g": 9.81})
    with pytest.raises(stabdae.ModelError, match=r"unknown parameter 'l'; known .*\['g'\]"):
        model.param_vector({"l": 2.0})
    with pytest.raises(stabdae.ModelError, match=r"parameter vector must have shape \(1,\)"):
        model.param_vector(np.zeros(3))


# ---------------------------------------------------------------- laws


@njit
def law_wrong_shape(t, x, p, out):
    out[0, 0] = -1.0
    out[0, 1] = -1.0
    out[0, 2] = -1.0


def law_plain(t, x, p, out):
    out[:] = 0.0


def test_law_errors():
    model = build()
    with pytest.raises(
        stabdae.LawError, match=r"matrix: A must have shape \(r, m \+ r\) = \(1, 2\) .*got \(2, 3\)"
    ):  # fmt: skip
        stabdae.integrate(model, None, stabdae.matrix(np.zeros((2, 3))), "rk4", 0.1, 1.0)
    with pytest.raises(stabdae.LawError, match=r"first block row \[0, I_1, 0\]"):
        stabdae.matrix(np.array([[1.0, 0.0], [-1.0, -1.0]])).A(model)
    with pytest.raises(stabdae.LawError, match=r"baumgarte: model 'broken' has m=1 .*give omega"):
        stabdae.baumgarte(xi=1.0).A(model)
    with pytest.raises(stabdae.LawError, match=r"baumgarte: omega must be positive"):
        stabdae.baumgarte(omega=-1.0)
    with pytest.raises(stabdae.LawError, match=r"theorem5: the law is for nonholonomic"):
        stabdae.integrate(model, None, stabdae.theorem5(1.0), "rk4", 0.1, 1.0)
    sleigh = load_scene("chaplygin_sleigh")
    with pytest.raises(stabdae.LawError, match=r"theorem5: L must have shape \(k, k\) = \(1, 1\)"):
        stabdae.integrate(sleigh, None, stabdae.theorem5(1.0, np.eye(2)), "rk4", 0.1, 1.0)
    with pytest.raises(stabdae.LawError, match=r"theorem5: L must be symmetric positive definite"):
        stabdae.integrate(sleigh, None, stabdae.theorem5(1.0, [[-1.0]]), "rk4", 0.1, 1.0)
    with pytest.raises(stabdae.LawError, match=r"user law: .* must be an @njit function"):
        stabdae.user(law_plain)
    with pytest.raises(
        stabdae.LawError, match=r"law_wrong_shape\(t, x, p, out\) writes outside out: expected "
        r"shape \(1, 2\) .*got \(1, 3\)"
    ):  # fmt: skip
        stabdae.integrate(model, None, stabdae.user(law_wrong_shape), "rk4", 0.1, 1.0)


# ---------------------------------------------------------------- schemes and integrate


def test_scheme_errors():
    with pytest.raises(stabdae.SchemeError, match=r"unknown scheme 'rk5'"):
        stabdae.integrate(build(), None, stabdae.none(), "rk5", 0.1, 1.0)
    with pytest.raises(stabdae.SchemeError, match=r"got the function stabdae.midpoint; call it"):
        stabdae.integrate(build(), None, stabdae.none(), stabdae.midpoint, 0.1, 1.0)
    with pytest.raises(stabdae.SchemeError, match=r"declared order 2 but .* up to order 1"):
        stabdae.Scheme("bad", [[0, 0], [1, 0]], [1, 0], [0, 1], 2, {})
    with pytest.raises(stabdae.SchemeError, match=r"weights must sum to 1"):
        stabdae.Scheme("bad", [[0.0]], [0.5], [0.0], 1, {})
    with pytest.raises(stabdae.SchemeError, match=r"rows of A must sum to c"):
        stabdae.Scheme("bad", [[0, 0], [1, 0]], [0.5, 0.5], [0, 0.5], 1, {})
    with pytest.raises(stabdae.SchemeError, match=r"strictly lower triangular"):
        stabdae.Scheme("bad", [[1.0]], [1.0], [1.0], 1, {})


def test_integrate_errors():
    model = build()
    law = stabdae.baumgarte(10.0)
    with pytest.raises(
        ValueError, match=r"^integrate: t_end - t0 = 1 must be a whole multiple of tau = 0.3"
    ):
        stabdae.integrate(model, None, law, "rk4", 0.3, 1.0)
    with pytest.raises(
        ValueError, match=r"^integrate: save_dt = 0.15 must be a whole multiple of tau = 0.1"
    ):
        stabdae.integrate(model, None, law, "rk4", 0.1, 1.0, 0.15)
    with pytest.raises(ValueError, match=r"^integrate: tau must be positive and finite, got -0.1"):
        stabdae.integrate(model, None, law, "rk4", -0.1, 1.0)
    with pytest.raises(
        ValueError, match=r"^integrate: x0 must have shape \(2n,\) = \(4,\) .*got \(2,\)"
    ):
        stabdae.integrate(model, np.zeros(2), law, "rk4", 0.1, 1.0)
    with pytest.raises(ValueError, match=r"^integrate: x0 has non-finite entries"):
        stabdae.integrate(model, np.full(4, np.nan), law, "rk4", 0.1, 1.0)
    with pytest.raises(ValueError, match=r"^integrate: give a law"):
        stabdae.integrate(model, None, None, "rk4", 0.1, 1.0)
    with pytest.raises(ValueError, match=r"^integrate: t_end must be after t0"):
        stabdae.integrate(model, None, law, "rk4", 0.1, 0.0)


@njit
def mass_asymmetric(t, q, p, out):
    out[0, 0] = 1.0
    out[0, 1] = 0.25
    out[1, 0] = 0.0
    out[1, 1] = 1.0


def test_asymmetric_mass_matrix_is_refused():
    """The L D Lᵀ factorization reads the lower triangle only: an asymmetric mass matrix
    is refused at construction, naming the entries."""
    with pytest.raises(stabdae.ModelError, match=r"mass\(t, q, p, out\) is not symmetric at "
                                                 r"the reference state: out\[1, 0\] = 0\.0 but "
                                                 r"out\[0, 1\] = 0\.25"):  # fmt: skip
        unit_pendulum("asymmetric", mass=mass_asymmetric)


def test_two_stage_without_parameters_and_parameters_of_a_fixed_scheme():
    model = unit_pendulum()
    law = stabdae.baumgarte(10.0)
    with pytest.raises(stabdae.SchemeError, match=r"^integrate: scheme 'two_stage' needs its "
                                                  r"parameters a and sigma"):  # fmt: skip
        stabdae.integrate(model, None, law, "two_stage", 0.1, 1.0)
    with pytest.raises(stabdae.SchemeError, match=r"scheme 'rk4' has no parameters, got \['a'\]"):
        stabdae._schemes.as_scheme("rk4", a=0.5)


@pytest.mark.parametrize("name", ["k/m", "g ", "2g", ""])
def test_parameter_names_must_be_identifiers(name):
    """Parameter names become NetCDF attribute names (model_param_<name>): a name NetCDF
    refuses is refused when the model is built, not after a computation."""
    with pytest.raises(stabdae.ModelError, match=r"parameter names must be identifiers"):
        unit_pendulum("named", params={name: 1.0})


def test_a_missing_f_t_is_named():
    """Time-dependent constraints without f_t: the inconsistent reference state is
    reported with the likely cause."""
    from conftest import scene_module

    mod = scene_module("pendulum_varying_length")
    with pytest.raises(stabdae.ModelError, match=r"f changes with t but the model gives no "
                                                 r"f_t\(t, q, p, out\)"):  # fmt: skip
        stabdae.Model("no_f_t", n=2, m=1, params={"g": 9.81, "l0": 1.0, "eps": 0.1,
                                                   "Omega": 3.0},
                      reference_state=mod.reference_state, forces=mod.forces, f=mod.f,
                      f_q=mod.f_q, f_accel=mod.f_accel)  # fmt: skip


@njit
def _forces_raising_after(t, q, v, p, out):
    out[0] = 0.0
    out[1] = 9.81
    if t > p[0]:
        raise ValueError("boom")


def test_a_raising_model_function_is_named_with_its_time_and_state():
    """numba hands an exception out of compiled code with its message alone: integrate and
    ensemble replay to the step that raised and name the function, the time and the state
    (checked against the trajectory stored up to there), or say the raise came from a
    stage of that step when no function raises at the state itself."""
    model = unit_pendulum("raising", forces=_forces_raising_after,
                          params={"t_raise": 0.2475})  # fmt: skip
    law = stabdae.baumgarte(10.0)
    ref = stabdae.integrate(model, None, law, "midpoint", 0.01, 0.25, save_dt=0.01)
    q = np.array2string(ref.x.values[-1, :2], precision=6)
    with pytest.raises(stabdae.ModelError) as info:
        stabdae.integrate(model, None, law, "midpoint", 0.01, 1.0)
    assert str(info.value) == (f"integrate: raising's forces(t, q, v, p, out) raised "
                               f"ValueError: boom at t = 0.25, q = {q}, v = "
                               f"{np.array2string(ref.x.values[-1, 2:], precision=6)}")
    with pytest.raises(stabdae.ModelError, match=r"ensemble: raising's forces\(t, q, v, p, "
                                                 r"out\) raised ValueError: boom at t = 0.25, "
                                                 r".* \(the reference trajectory\)"):
        stabdae.ensemble(model, law, "midpoint", 0.01, 1.0, members=4)
    # the midpoint stage at t + τ/2 = 0.255 raises, the state at t = 0.25 does not: the
    # step is run again stage by stage, and the message names the function at the stage
    late = {"t_raise": 0.2525}
    ref = stabdae.integrate(model, None, law, "midpoint", 0.01, 0.25, save_dt=0.01, params=late)
    x = ref.x.values[-1]
    _, half = _midpoint_stage(model, law, x, 0.25, 0.01, late)
    stage = (f"raised ValueError: boom at t = 0.255, q = {np.array2string(half[:2], precision=6)}"
             f", v = {np.array2string(half[2:], precision=6)}: stage 2 of the step from "
             f"t = 0.25, q = {np.array2string(x[:2], precision=6)}")
    with pytest.raises(stabdae.ModelError) as info:
        stabdae.integrate(model, None, law, "midpoint", 0.01, 1.0, params=late)
    assert str(info.value).startswith("integrate: raising's forces(t, q, v, p, out) " + stage)
    with pytest.raises(stabdae.ModelError) as info:
        stabdae.ensemble(model, law, "midpoint", 0.01, 1.0, members=4, params=late)
    assert str(info.value).startswith("ensemble: raising's forces(t, q, v, p, out) " + stage)
    assert str(info.value).endswith("(the reference trajectory)")


def _midpoint_stage(model, law, x, t, tau, params):
    """The midpoint rule's second stage state ``x + τ/2 ẋ(t, x)``, from the plain NumPy
    right-hand side written from the paper's equations (``tests/reference/rhs.py``)."""
    from reference.rhs import stabilized_rhs

    p = model.param_vector(params)
    k0 = stabilized_rhs(model, law, t, x, p)
    return k0, x + 0.5 * tau * k0


OUT_OF_BOUNDS_MODEL = '''
import numpy as np
from numba import njit
from stabdae import Model


@njit
def forces(t, q, v, p, out):
    out[0] = 0.0
    out[1] = -9.81
    if q[0] > 0.5:  # a defect away from the reference state, which Model() cannot see
        out[1000000000000] = 1.0


@njit
def f(t, q, p, out):
    out[0] = 0.5 * (q[0] ** 2 + q[1] ** 2 - 1.0)


@njit
def f_q(t, q, p, out):
    out[0, 0] = q[0]
    out[0, 1] = q[1]


@njit
def f_accel(t, q, v, p, out):
    out[0] = v[0] ** 2 + v[1] ** 2


model = Model(name="out_of_bounds", n=2, m=1, forces=forces, f=f, f_q=f_q, f_accel=f_accel,
              reference_state=np.array([0.0, -1.0, 2.0, 0.0]))
'''
CRASHING_RUN = '''
import sys
import stabdae
model = stabdae.load_model(sys.argv[1])
law = stabdae.baumgarte(10.0, 1.0)
try:
    if sys.argv[2] == "ensemble":
        stabdae.ensemble(model, law, "rk4", 1e-3, 1.0, members=16, seed=1, threads=2)
    else:
        stabdae.integrate(model, None, law, "rk4", 1e-3, 1.0)
except stabdae.ModelError as exc:
    print("ModelError:", exc)
'''


def test_a_crash_in_a_compiled_kernel_says_what_to_do(tmp_path):
    """A model function that writes far outside its out array at states away from the
    reference state: the unchecked trajectory still dies (memory may be corrupt), but
    says why and what to run instead (before: "Segmentation fault" and nothing else); the
    run it advises stops with an error that names the function, the time and the state,
    in an ensemble too."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    model_file = tmp_path / "out_of_bounds.py"
    model_file.write_text(OUT_OF_BOUNDS_MODEL)
    src = str(Path(stabdae.__file__).resolve().parents[1])

    def run(kind, **env):
        environ = dict(os.environ, PYTHONPATH=src, STABDAE_CACHE_DIR=str(tmp_path / "c"), **env)
        return subprocess.run([sys.executable, "-c", CRASHING_RUN, str(model_file), kind],
                              env=environ, capture_output=True, text=True, timeout=600)  # fmt: skip

    crashed = run("integrate")
    assert crashed.returncode != 0, crashed.stdout
    assert "stabdae: integrate crashed inside a compiled kernel" in crashed.stderr, crashed.stderr
    assert "NUMBA_BOUNDSCHECK=1" in crashed.stderr
    # in the ensemble's member loop the same write lands in (or is dropped from) a stack
    # buffer: no crash, maybe no sign at all; the checked run finds it there too
    checked = run("ensemble", NUMBA_BOUNDSCHECK="1")
    assert checked.returncode == 0, checked.stderr[-3000:]
    assert "IndexError" in checked.stdout and "t = " in checked.stdout, checked.stdout
    assert "q = [" in checked.stdout


def test_heap_corruption_found_after_the_kernel_still_says_what_to_do(tmp_path):
    """A model that writes just past its ``out`` array on the heap: glibc found the
    corruption at a later free, after the kernel had returned, and the process died of
    ``malloc(): unaligned tcache chunk detected`` (an abort, exit 134) or a fault with
    nothing else said.  The message now comes however it dies."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    model_file = tmp_path / "heap_writer.py"
    model_file.write_text(OUT_OF_BOUNDS_MODEL.replace(
        "out[1000000000000] = 1.0", "for j in range(2, 40):\n            out[j] = 1e300"))
    src = str(Path(stabdae.__file__).resolve().parents[1])
    environ = dict(os.environ, PYTHONPATH=src, STABDAE_CACHE_DIR=str(tmp_path / "c"))
    crashed = subprocess.run([sys.executable, "-c", CRASHING_RUN, str(model_file), "integrate"],
                             env=environ, capture_output=True, text=True, timeout=600)  # fmt: skip
    assert crashed.returncode != 0, crashed.stdout
    assert "stabdae: " in crashed.stderr and "integrate" in crashed.stderr, crashed.stderr
    assert "wrote outside its arrays" in crashed.stderr and "NUMBA_BOUNDSCHECK=1" in \
        crashed.stderr, crashed.stderr  # fmt: skip
