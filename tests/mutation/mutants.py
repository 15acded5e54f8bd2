"""The single-point changes of the mutation check (see README.md): each one is a change a
user would notice, and the tests must catch every one."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Mutant:
    name: str
    file: str  # relative to the repository root
    old: str  # exact snippet, occurring once in the file
    new: str
    tests: tuple  # test files (or node ids) that cover the place
    what: str
    select: str | None = None  # pytest -k expression, to keep the run short


K = "src/stabdae/kernels/"
S = "src/stabdae/"

MUTANTS = [
    # ---- changes that passed the suite before the mutation check existed
    Mutant("theorem5-W-transpose", K + "rhs.py",
           "s = fma(hv[i, l], hv[j, l], s)", "s = fma(hv[i, l], hv[l, j], s)",
           ("tests/test_theory.py",), "Theorem 5 law: W = h_v h_vᵀ loses its transpose",
           "theorem5"),
    Mutant("heun-to-ralston", S + "_schemes.py",
           'return two_stage(1.0, 0.5, name="heun")',
           'return two_stage(2.0 / 3.0, 0.75, name="heun")',
           ("tests/test_convergence.py",), "Heun's tableau replaced by Ralston's", "heun"),
    Mutant("ldl-pivot-absolute", K + "linalg.py", "tol = rtol * dmax", "tol = rtol",
           ("tests/test_linalg.py",), "L D Lᵀ pivot threshold absolute instead of relative"),
    Mutant("radii-uniform", K + "sampler.py",
           "r = np.exp(rng.uniform(math.log(low), math.log(high), members))",
           "r = rng.uniform(low, high, members)",
           ("tests/test_ensemble.py",), "radii drawn uniform instead of log-uniform", "radii"),
    Mutant("tau-limit-failing-side", S + "theory.py", "    return good\n",
           "    return bad\n", ("tests/test_theory.py",),
           "τ-limit bisection returns the failing side of the bracket", "tau_limit"),
    Mutant("tau-limit-tau-max", S + "theory.py",
           "        if tau > tau_max:\n            return math.inf",
           "        if tau > tau_max:\n            return tau_max",
           ("tests/test_theory.py",), "τ-limit returns tau_max instead of inf", "tau_limit"),
    Mutant("theorem5-rate-l1", S + "theory.py", '"beta_proven": k0 * lam_min * l1 * l1 / lm',
           '"beta_proven": k0 * lam_min * l1 / lm', ("tests/test_theory.py",),
           "Theorem 5 rate constant l₁²/l_m → l₁/l_m", "theorem5"),
    Mutant("resume-ignores-fingerprint", S + "study/run.py", "        if old != stamp:",
           "        if False:", ("tests/test_run.py",), "resume ignores the study fingerprint",
           "refuses or resume"),
    Mutant("combine-drops-study", S + "study/run.py",
           '    ds.attrs["study"] = study.path.name\n', "",
           ("tests/test_run.py",), 'combine drops attrs["study"]', "writes_dataset"),
    Mutant("netcdf-uncompressed", S + "_schema.py",
           'encoding[name] = {"zlib": True, "complevel": compress, "shuffle": True}',
           "pass", ("tests/test_integrate.py", "tests/test_ensemble.py"),
           "NetCDF written without compression", "round_trip"),
    Mutant("no-history", S + "_schema.py",
           '    attrs["history"] = f"{attrs[\'created_at\']}: {action} (stabdae {__version__})"\n',
           "", ("tests/test_integrate.py",), "provenance without history", "schema"),
    Mutant("stability-radius-max", S + "_ensemble.py",
           "return float(alpha_norm[~bounded].min())",
           "return float(alpha_norm[~bounded].max())", ("tests/test_ensemble.py",),
           "stability_radius takes the max instead of the min", "stability_radius"),
    Mutant("bounded-without-decayed", S + "_ensemble.py",
           "bounded = ok & (max_res <= epsilon) & decayed",
           "bounded = ok & (max_res <= epsilon)", ("tests/test_ensemble.py",),
           'bounded without its "decayed" clause', "decayed"),
    Mutant("adaptive-rss", K + "adaptive.py", "return math.sqrt(s / N2)",
           "return math.sqrt(s)", ("tests/test_hard_cases.py",),
           "adaptive error norm not divided by N (RMS → root-sum-square)", "scipy"),
    Mutant("full-projection-one-sweep", K + "rhs.py", '"full": (8, 0.0)', '"full": (1, 0.0)',
           ("tests/test_stabilizations.py",), 'projection="full" does a single sweep',
           "projection"),
    Mutant("lead-fraction-zero", K + "decay.py", "LEAD_FRACTION = 0.3", "LEAD_FRACTION = 0.0",
           ("tests/test_ensemble.py",), "β fit's lead fraction set to 0", "beta or decay"),
    Mutant("member-step-no-stage-time", K + "ensemble.py",
           'f"    c{s} = rhs(t + tab_c[{s}] * tau, {arg},',
           'f"    c{s} = rhs(t, {arg},', ("tests/test_ensemble.py",),
           "generated ensemble step drops the stage time c·τ", "time_dependent"),
    # ---- changes the suite caught before; kept so that it goes on catching them
    Mutant("convective-sign", K + "rhs.py", "                rl[i] = -sm[i]",
           "                rl[i] = sm[i]", ("tests/test_residual_law.py",),
           "sign of (3.11)'s convective term"),
    Mutant("ldl-back-substitution", K + "linalg.py", "            s = fma(-l[p, i], b[p], s)",
           "            s = fma(-l[i, p], b[p], s)", ("tests/test_linalg.py",),
           "L D Lᵀ back-substitution reads L instead of Lᵀ"),
    Mutant("sampler-newton-sign", K + "sampler.py", "                x[l] += s\n",
           "                x[l] -= s\n", ("tests/test_ensemble.py",),
           "the sampler's Gauss–Newton step goes the wrong way", "radii or sampl"),
    Mutant("rollback-skips-restore", K + "ensemble.py",
           "                                X[l, j] = Xc[l, j]",
           "                                X[l, j] = X[l, j]", ("tests/test_ensemble.py",),
           "a failed block is not rolled back to its checkpoint", "rollback or stop"),
    # ---- more places a user would notice
    Mutant("status-precedence", K + "rhs.py",
           "return max(_MASS_NOT_SPD * bad_mass, _SINGULAR_S * bad_S)",
           "return min(_MASS_NOT_SPD * bad_mass, _SINGULAR_S * bad_S)",
           ("tests/test_integrate.py",), "a failed factorization reported as OK", "status"),
    Mutant("alpha-direction-unscaled", K + "sampler.py",
           "    u /= np.max(np.abs(u), axis=1, keepdims=True)\n", "",
           ("tests/test_ensemble.py",), "α⁰ directions not scaled to the unit max-norm",
           "radii"),
    Mutant("baumgarte-damping", S + "_laws.py",
           "A[:m, m : 2 * m] = -2.0 * self.xi * self.omega * np.eye(m)",
           "A[:m, m : 2 * m] = -self.xi * self.omega * np.eye(m)",
           ("tests/test_residual_law.py",), "Baumgarte's damping 2ξω → ξω", "oscillator"),
    Mutant("two-stage-matrix", S + "theory.py",
           "return E + tau * A + 0.5 * tau * tau * (A @ A + Ad)",
           "return E + tau * A + tau * tau * (A @ A + Ad)", ("tests/test_theory.py",),
           "(5.13)'s τ²/2 becomes τ²"),
    Mutant("weighted-norm-no-inverse", S + "theory.py",
           "return float(np.linalg.norm(P @ R @ np.linalg.inv(P), 2))",
           "return float(np.linalg.norm(P @ R, 2))", ("tests/test_theory.py",),
           "weighted norm ‖P R P⁻¹‖ loses P⁻¹"),
    Mutant("adaptive-last-sample", S + "_validate.py", "    out[-1] = t_end\n", "",
           ("tests/test_hard_cases.py",), "adaptive samples miss t_end", "adaptive"),
    Mutant("floor-whole-trace", K + "decay.py", "ntail = min(max(3, nvalid // 5), nvalid)",
           "ntail = nvalid", ("tests/test_ensemble.py",),
           "the floor is the median of the whole trace, not its last fifth",
           "beta or decay or floor"),
    Mutant("eigenvalue-clusters-off", S + "theory.py", "_CLUSTER_RTOL = 1e-6",
           "_CLUSTER_RTOL = 0.0", ("tests/test_theory.py",),
           "a defective eigenvalue's cluster not averaged (√ε errors at ξ = 1)",
           "spectral_tau_limit"),
    Mutant("spectral-limit-first-sign", S + "theory.py", "        if b[low] > 0:  # above 1",
           "        if b[low] < 0:  # above 1", ("tests/test_theory.py",),
           "τ limit: |R| growing right after τ = 0 taken as stable", "spectral_tau_limit"),
    Mutant("growth-after-reject", K + "adaptive.py", "                    fac = min(fac, 1.0)\n",
           "                    fac = fac\n", ("tests/test_hard_cases.py",),
           "the step grows right after a rejection", "scipy"),
]
