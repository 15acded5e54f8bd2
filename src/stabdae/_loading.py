"""Loading model files: plain Python files that define ``model = stabdae.Model(...)``."""

from __future__ import annotations

import ast
import hashlib
import importlib.util
import keyword
import sys
import traceback
import types
from pathlib import Path

from ._laws import LawError
from ._model import Model, ModelError
from ._schemes import SchemeError

__all__ = ["file_error", "file_sha256", "load_model", "local_imports", "model_file", "module_name",
           "scene_names", "scene_dir"]


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


def model_file(source) -> Path:
    """The resolved path of a model file or of a built-in scene's file."""
    path = Path(source)
    if path.suffix != ".py":
        # a scene is a name, never a path: joined onto the scenes folder, a name with a
        # folder in it ("../x", "/usr/lib/python3/this") would import a file nobody named
        # as code
        if str(source) not in scene_names():
            raise ModelError(
                f"load_model: {str(source)!r} is neither a .py model file nor a built-in "
                f"scene (a scene is given by its name alone); scenes: {scene_names()}"
            )
        path = scene_dir() / f"{source}.py"
    if not path.is_file():
        raise ModelError(f"load_model: no such model file: {path}")
    return path.resolve()


def local_sources(path: Path) -> dict[Path, bytes]:
    """The bytes of :func:`local_imports`, by path, read once: what a run is keyed by and
    what its dask workers load must be the same bytes, whatever the files become."""
    out = {}
    for each in local_imports(path):
        try:
            out[each] = each.read_bytes()
        except OSError:
            continue
    return out


def local_imports(path: Path) -> list[Path]:
    """The model file and the modules of its own folder that it imports, recursively (what
    its numbers can depend on besides the library)."""
    seen: list[Path] = []
    todo = [Path(path).resolve()]
    while todo:
        current = todo.pop()
        if current in seen:
            continue
        seen.append(current)
        try:
            tree = ast.parse(current.read_text())
        except (OSError, SyntaxError, ValueError):
            continue
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            for name in names:
                base = current.parent / Path(*name.split("."))
                for candidate in (base.with_suffix(".py"), base / "__init__.py"):
                    if candidate.is_file():
                        todo.append(candidate.resolve())
    return seen


def module_name(path: Path) -> str:
    """The name a model file is loaded under: the one a plain ``import`` of it would give
    (``stabdae.scenes.<name>`` for an installed scene, else the file's stem) unless that
    name belongs to another module, else a name made from the path.

    Numba's on-disk cache (``@njit(cache=True)`` in the model file) keys its entries by
    file and function, and a cached function refers to its module by name: a file loaded
    here under one name and imported elsewhere under another would find entries it cannot
    load."""
    path = Path(path).resolve()
    if path.parent == Path(__file__).with_name("scenes").resolve():
        return f"stabdae.scenes.{path.stem}"
    stem = path.stem
    if stem.isidentifier() and not keyword.iskeyword(stem):
        existing = sys.modules.get(stem)
        if existing is not None:
            if _origin(getattr(existing, "__file__", None)) == path:
                return stem
        else:
            try:
                spec = importlib.util.find_spec(stem)
            except (ImportError, ValueError):
                spec = None
            if spec is None or _origin(spec.origin) == path:
                return stem
    digest = hashlib.sha1(str(path).encode()).hexdigest()[:10]
    return f"stabdae_model_{stem}_{digest}"


def _origin(file) -> Path | None:
    try:
        return Path(file).resolve() if file else None
    except (OSError, TypeError):
        return None


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
    path = model_file(source)
    return load_as(path, module_name(path), attribute)


def load_as(path: Path, name: str, attribute: str = "model") -> Model:
    """The model of the file ``path`` loaded as the module ``name`` (:func:`load_model`
    chooses the name; a dask worker gives the one the process that runs the study
    chose, so that the model's functions have the same fingerprints there)."""
    module = sys.modules.get(name)
    stamp = getattr(module, "__stabdae_sources__", None)
    if module is not None and stamp is not None and _sources_changed(stamp):
        # edited, or a helper it reads edited, since it was loaded (a notebook): load it
        # and every helper module it reads afresh
        for dep in stamp:
            if dep[0] != name:
                sys.modules.pop(dep[0], None)
        del sys.modules[name]
        module = None
    if module is None:
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        try:
            spec.loader.exec_module(module)
        except (ModelError, LawError, SchemeError):  # stabdae's own, already clear
            del sys.modules[name]
            raise
        except Exception as exc:  # the file's own error, in one line with its place
            del sys.modules[name]
            raise ModelError(f"load_model: {file_error(path, exc)}") from exc
        except BaseException:
            del sys.modules[name]
            raise
        module.__stabdae_sources__ = _sources(module)
    elif stamp is None:  # imported before stabdae saw it: watched from now on
        module.__stabdae_sources__ = _sources(module)
    model = getattr(module, attribute, None)
    if not isinstance(model, Model):
        raise ModelError(
            f"load_model: {path} must define a module-level stabdae.Model named "
            f"{attribute!r}; found {type(model).__name__}"
        )
    # where another process finds the same model (a helper compiling its sampler ahead)
    model._origin = (str(path), attribute)
    model._module = name  # the name it is loaded under (a dask worker loads it so too)
    return model


def _sources(module) -> tuple:
    """``(module name, file, SHA-256)`` of the model's module and of every module of the
    user's that it reads, directly or through the functions and modules it reads (helpers
    wherever they live; the library's modules and installed packages left out)."""
    out, todo, seen = [], [module], set()
    while todo:
        mod = todo.pop()
        if id(mod) in seen:
            continue
        seen.add(id(mod))
        file = _origin(getattr(mod, "__file__", None))
        if file is None or not file.is_file():
            continue
        out.append((mod.__name__, str(file), file_sha256(file)))
        for value in list(vars(mod).values()):
            dep = value if isinstance(value, types.ModuleType) else \
                sys.modules.get(getattr(getattr(value, "py_func", value), "__module__", None)
                                or "")  # fmt: skip
            if dep is not None and _user_module(dep):
                todo.append(dep)
    return tuple(out)


def _user_module(module) -> bool:
    name = getattr(module, "__name__", "") or ""
    if name.split(".")[0] in ("stabdae", "numba", "numpy", "scipy", "math", "builtins"):
        return False
    file = _origin(getattr(module, "__file__", None))
    if file is None:
        return False
    prefixes = {Path(p).resolve() for p in (sys.prefix, sys.base_prefix, sys.exec_prefix)}
    return not any(file.is_relative_to(p) for p in prefixes)


def _sources_changed(stamp) -> bool:
    for _, file, digest in stamp:
        try:
            if file_sha256(Path(file)) != digest:
                return True
        except OSError:
            return True
    return False


def file_sha256(path) -> str:
    """SHA-256 of a file's bytes, read in blocks."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def file_error(path: Path, exc: BaseException) -> str:
    """``path:line: Type: message`` for an exception raised while running a user's file:
    the line is the innermost of the traceback that lies in the file (a syntax error's
    own), so that a mistake anywhere in it is named in one line."""
    line = getattr(exc, "lineno", None) if isinstance(exc, SyntaxError) else None
    if line is None:
        target = Path(path).resolve()
        for frame in traceback.extract_tb(exc.__traceback__):
            try:
                if Path(frame.filename).resolve() == target:
                    line = frame.lineno
            except OSError:
                continue
    where = f"{path}:{line}" if line else str(path)
    return f"{where}: {type(exc).__name__}: {exc}"
