"""Shared fixtures: the scene registry and seeded perturbed initial states."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

import stabdae

ROOT = Path(__file__).resolve().parents[1]
KERNELS = ROOT / "kernels"

#: every scene of kernels/, the registry tests parametrize over
SCENES = [
    "pendulum",
    "double_pendulum",
    "pendulum_varying_length",
    "hoop_bead",
    "chaplygin_sleigh",
    "knife_edge",
]
#: scenes whose energy function is a first integral of the exact motion
CONSERVATIVE = ["pendulum", "double_pendulum", "hoop_bead", "chaplygin_sleigh", "knife_edge"]


def load_scene(name: str) -> stabdae.Model:
    return stabdae.load_model(KERNELS / f"{name}.py")


def scene_module(name: str):
    """The scene's module (for its closed-form helpers)."""
    load_scene(name)
    key = next(k for k in sys.modules if k.startswith(f"stabdae_model_{name}_"))
    return sys.modules[key]


def perturbed_state(model: stabdae.Model, size: float, seed: int = 0) -> np.ndarray:
    """The reference state displaced by ``size`` (relative) in a seeded random direction."""
    rng = np.random.default_rng(seed)
    x = model.reference_state()
    return x + size * np.maximum(1.0, np.abs(x)) * rng.standard_normal(x.shape)


@pytest.fixture(params=SCENES)
def scene(request) -> stabdae.Model:
    return load_scene(request.param)


def load_file(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
