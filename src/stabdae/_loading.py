"""Loading model files: plain Python files that define ``model = stabdae.Model(...)``."""

from __future__ import annotations

import hashlib
import importlib.util
import sys
from pathlib import Path

from ._model import Model, ModelError

__all__ = ["load_model", "scene_names", "scene_dir"]


def scene_dir() -> Path:
    """Folder of the built-in scenes: ``stabdae/scenes`` in an installed wheel, else the
    source tree's ``kernels/``."""
    installed = Path(__file__).with_name("scenes")
    if installed.is_dir():
        return installed
    return Path(__file__).resolve().parents[2] / "kernels"


def scene_names() -> list[str]:
    """Names of the built-in scenes (model files shipped with stabdae)."""
    return sorted(p.stem for p in scene_dir().glob("*.py") if not p.stem.startswith("_"))


def load_model(source, attribute: str = "model") -> Model:
    """Load a model from a file path or the name of a built-in scene.

    Parameters
    ----------
    source : str or path
        ``"kernels/pendulum.py"``, any model file, or a scene name such as ``"pendulum"``.
    attribute : str
        Name of the module-level :class:`Model` in the file.

    Examples
    --------
    >>> model = load_model("pendulum")
    >>> model.n, model.m
    (2, 1)
    """
    path = Path(source)
    if path.suffix != ".py":
        candidate = scene_dir() / f"{source}.py"
        if not candidate.is_file():
            raise ModelError(
                f"load_model: {source!r} is neither a .py model file nor a built-in scene; "
                f"scenes: {scene_names()}"
            )
        path = candidate
    if not path.is_file():
        raise ModelError(f"load_model: no such model file: {path}")
    path = path.resolve()
    digest = hashlib.sha1(str(path).encode()).hexdigest()[:10]
    name = f"stabdae_model_{path.stem}_{digest}"
    if name in sys.modules:
        module = sys.modules[name]
    else:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        try:
            spec.loader.exec_module(module)
        except BaseException:
            del sys.modules[name]
            raise
    model = getattr(module, attribute, None)
    if not isinstance(model, Model):
        raise ModelError(
            f"load_model: {path} must define a module-level stabdae.Model named "
            f"{attribute!r}; found {type(model).__name__}"
        )
    return model
