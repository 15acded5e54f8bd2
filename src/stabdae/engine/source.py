"""Source code that the library generates and compiles, made visible.

The ensemble kernel's member step, the adaptive ensemble's attempted step, the workspace
builders and the written-out linear algebra are Python source written for one model's
sizes (and one scheme's pattern of coefficients), then compiled.  Each piece is
registered with :mod:`linecache` under a readable name (``<stabdae generated member_step
1a2b3c4d5e6f>``), so that tracebacks show its lines and :func:`inspect.getsource` returns
it.  With ``STABDAE_DUMP_SOURCE=FOLDER`` in the
environment every piece is also written to ``FOLDER/<label>-<digest>.py`` as it is
generated, for reading or stepping through with ``NUMBA_DISABLE_JIT=1``.
"""

from __future__ import annotations

import hashlib
import linecache
import os
from pathlib import Path

__all__ = ["exec_source", "generated_filename"]


def generated_filename(label: str, source: str) -> str:
    """The name under which ``source`` is compiled and registered with linecache."""
    digest = hashlib.sha256(source.encode()).hexdigest()[:12]
    return f"<stabdae generated {label} {digest}>"


def exec_source(source: str, label: str, namespace: dict) -> dict:
    """Compile and run ``source`` in ``namespace`` (the names it uses), registered with
    linecache under :func:`generated_filename`; returns ``namespace``."""
    filename = generated_filename(label, source)
    # (size, mtime None: linecache.checkcache keeps the entry, it has no file to go stale)
    linecache.cache[filename] = (len(source), None, source.splitlines(keepends=True), filename)
    folder = os.environ.get("STABDAE_DUMP_SOURCE")
    if folder:
        path = Path(folder).expanduser()
        path.mkdir(parents=True, exist_ok=True)
        digest = filename.rsplit(" ", 1)[1].rstrip(">")
        (path / f"{label}-{digest}.py").write_text(source)  # same lines as in tracebacks
    exec(compile(source, filename, "exec"), namespace)
    return namespace
