"""numba's disk cache, keyed on the whole model's source.

numba keys a cached kernel on the modification time and size of the file that defines it,
nothing else. A kernel that calls a jitted function from another module compiles that function
into itself (``lagice.fem.element_strain_rate`` inside the explicit sub-step kernels, for
instance), and a kernel freezes the module globals it reads. So an edit to ``fem.py`` leaves the
explicit kernels' cache entries looking valid, and the next run loads kernels built from the old
``fem.py``: stale code with no warning (seen in the thirty-third session, where it gave wrong
results until the cache files were deleted by hand).

:func:`configure` (called by ``lagice/__init__.py`` before any kernel module is imported) puts
every cached kernel of ``lagice``, ``forcing`` and ``thermo`` under a directory named after a
digest of all three packages' ``.py`` files::

    $NUMBA_CACHE_DIR/lagice-<digest>/        if the user set NUMBA_CACHE_DIR
    $XDG_CACHE_HOME/lagice/numba/lagice-<digest>/   otherwise (~/.cache/... by default)

so any change to any source file, or a different installed version, reads and writes a fresh
directory, and no kernel is ever loaded from a cache built from other sources. The digest costs
a few ms at import (1.2 MB of source). Directories of other digests that have not been used for
``PRUNE_AFTER_DAYS`` days are removed, the newest ``KEEP`` always kept.

``LAGICE_NUMBA_CACHE=numba`` leaves numba's own cache placement alone (in-tree ``__pycache__``,
keyed per file as described above), e.g. to share caches with other numba code.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

#: the packages whose kernels are cached, as siblings of ``lagice`` (a checkout or site-packages)
PACKAGES = ("lagice", "forcing", "thermo")
#: unused digest directories older than this are removed ...
PRUNE_AFTER_DAYS = 14.0
#: ... except the newest few
KEEP = 4
PREFIX = "lagice-"


def package_dirs() -> list[Path]:
    """The source directories of ``PACKAGES`` next to this file's package (those that exist)."""
    root = Path(__file__).resolve().parent.parent
    return [root / p for p in PACKAGES if (root / p / "__init__.py").is_file()]


def source_digest(dirs) -> str:
    """A 16-hex-digit SHA-256 digest of every ``.py`` file under ``dirs`` (path relative to its
    package's parent, then its bytes, in sorted order), with numba's and Python's versions."""
    h = hashlib.sha256()
    try:
        import importlib.metadata as md
        numba_version = md.version("numba")
    except Exception:  # pragma: no cover - numba not installed as a distribution
        numba_version = "?"
    h.update(f"python {sys.version_info[:3]} numba {numba_version}\n".encode())
    for d in dirs:
        d = Path(d)
        for f in sorted(d.rglob("*.py")):
            if "__pycache__" in f.parts:
                continue
            h.update(str(f.relative_to(d.parent)).encode() + b"\0")
            h.update(f.read_bytes())
            h.update(b"\0")
    return h.hexdigest()[:16]


def cache_base(environ=None) -> Path:
    """Where the digest directories live: ``$NUMBA_CACHE_DIR`` if the user set it (a value this
    module set in a parent process, ending in ``lagice-<digest>``, counts as its parent), else
    ``$XDG_CACHE_HOME/lagice/numba`` (``~/.cache/lagice/numba``)."""
    env = os.environ if environ is None else environ
    user = env.get("NUMBA_CACHE_DIR", "")
    if user:
        p = Path(user)
        return p.parent if p.name.startswith(PREFIX) else p
    xdg = env.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(xdg) / "lagice" / "numba"


def _writable(path: Path) -> bool:
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=path):
            pass
        return True
    except OSError:
        return False


def prune(base: Path, current: Path, now: float | None = None) -> list[Path]:
    """Remove ``lagice-*`` directories under ``base`` other than ``current`` that were last used
    more than ``PRUNE_AFTER_DAYS`` ago, keeping the ``KEEP`` newest; the removed paths."""
    now = time.time() if now is None else now
    try:
        others = [p for p in base.iterdir() if p.is_dir() and p.name.startswith(PREFIX) and p != current]
    except OSError:
        return []
    others.sort(key=lambda p: p.stat().st_mtime, reverse=True)
    removed = []
    for p in others[KEEP:]:
        if now - p.stat().st_mtime > PRUNE_AFTER_DAYS * 86400.0:
            shutil.rmtree(p, ignore_errors=True)
            removed.append(p)
    return removed


def configure() -> str | None:
    """Point numba's disk cache at ``lagice-<digest>`` (see the module doc); the directory, or
    None when ``LAGICE_NUMBA_CACHE=numba`` asks for numba's own placement. Must run before any
    ``cache=True`` kernel is decorated: numba picks a kernel's cache directory then."""
    if os.environ.get("LAGICE_NUMBA_CACHE", "") == "numba":
        return None
    base = cache_base()
    path = base / (PREFIX + source_digest(package_dirs()))
    if not _writable(path):  # e.g. a read-only home: a per-user temporary directory
        base = Path(tempfile.gettempdir()) / f"lagice-numba-{os.getuid() if hasattr(os, 'getuid') else 'user'}"
        path = base / path.name
        _writable(path)
    try:
        os.utime(path)  # "last used", for prune()
    except OSError:
        pass
    prune(base, path)
    os.environ["NUMBA_CACHE_DIR"] = str(path)  # read by numba at its import, and by child processes
    if "numba" in sys.modules:  # numba already imported: its config was read before this
        from numba.core import config
        config.CACHE_DIR = str(path)
    return str(path)
