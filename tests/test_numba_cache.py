"""numba's disk cache keyed on the model's whole source (lagice/_numba_cache.py).

numba keys a cached kernel on its own file's time stamp and size only, so a kernel that inlines a
jitted function from another module is loaded stale after that module is edited. These tests
edit a copy of the package in a temporary directory and run real subprocesses, each with its own
numba cache directory.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from lagice import _numba_cache

ROOT = Path(__file__).resolve().parent.parent

PROBE_A = "from numba import njit\n\n\n@njit\ndef value():\n    return {v}\n"
PROBE_B = ("from numba import njit\n\nfrom ._probe_a import value\n\n\n"
           "@njit(cache=True)\ndef kernel():\n    return value() + 0\n")


def _run_probe(tmp: Path, cache: Path, mode: str | None) -> tuple[int, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "LAGICE_NUMBA_CACHE")}
    env["PYTHONPATH"] = str(tmp)
    env["NUMBA_CACHE_DIR"] = str(cache)
    if mode:
        env["LAGICE_NUMBA_CACHE"] = mode
    code = ("import lagice, os; from lagice._probe_b import kernel; "
            f"assert lagice.__file__.startswith({str(tmp)!r}), lagice.__file__; "
            "print(kernel(), os.environ['NUMBA_CACHE_DIR'])")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=300, cwd=tmp)
    assert out.returncode == 0, out.stderr[-3000:]
    value, path = out.stdout.split()
    return int(value), path


def _edit_probe_a(pkg: Path, v: int) -> None:
    f = pkg / "_probe_a.py"
    old = f.stat().st_mtime if f.exists() else time.time() - 10
    f.write_text(PROBE_A.format(v=v))
    os.utime(f, (old + 5, old + 5))  # a new time stamp, as an editor's save gives


def test_edit_to_an_inlined_function_is_not_loaded_stale(tmp_path):
    """Edit the function a cached kernel inlines (another module): the next process runs the new
    code. With numba's own placement (LAGICE_NUMBA_CACHE=numba) the same edit is loaded stale
    with numba 0.59-0.68; that control is printed, not asserted (numba may fix it one day)."""
    pkg = tmp_path / "lagice"
    shutil.copytree(ROOT / "lagice", pkg, ignore=shutil.ignore_patterns("__pycache__"))
    (pkg / "_probe_b.py").write_text(PROBE_B)
    cache = tmp_path / "cache"

    _edit_probe_a(pkg, 1)
    v1, dir1 = _run_probe(tmp_path, cache, None)
    assert v1 == 1
    assert Path(dir1).parent == cache and Path(dir1).name.startswith("lagice-")
    assert any(Path(dir1).rglob("*.nbi")), "the kernel was not cached in the digest directory"

    _edit_probe_a(pkg, 2)
    v2, dir2 = _run_probe(tmp_path, cache, None)
    assert v2 == 2, "a kernel built from the old source was loaded"
    assert dir2 != dir1 and Path(dir2).parent == cache

    # the control: numba's own cache placement, same two edits
    ctrl = tmp_path / "ctrl_cache"
    _edit_probe_a(pkg, 3)
    c1, _ = _run_probe(tmp_path, ctrl, "numba")
    _edit_probe_a(pkg, 4)
    c2, _ = _run_probe(tmp_path, ctrl, "numba")
    print(f"numba's own cache placement after the edit 3 -> 4: kernel returned {c2} "
          f"({'stale' if c2 == c1 else 'fresh'})")
    assert c1 == 3


def test_digest_follows_every_source_file_and_nothing_else(tmp_path):
    a = tmp_path / "pkg"
    (a / "sub").mkdir(parents=True)
    (a / "__init__.py").write_text("")
    (a / "sub" / "k.py").write_text("X = 1\n")
    d0 = _numba_cache.source_digest([a])
    assert d0 == _numba_cache.source_digest([a]) and len(d0) == 16
    (a / "notes.txt").write_text("not source")
    (a / "__pycache__").mkdir()
    (a / "__pycache__" / "junk.py").write_text("Y = 2\n")
    assert _numba_cache.source_digest([a]) == d0
    (a / "sub" / "k.py").write_text("X = 2\n")
    d1 = _numba_cache.source_digest([a])
    assert d1 != d0
    (a / "sub" / "k.py").rename(a / "k.py")  # same bytes, another place
    assert _numba_cache.source_digest([a]) not in (d0, d1)


def test_cache_base_and_pruning(tmp_path):
    assert _numba_cache.cache_base({"NUMBA_CACHE_DIR": str(tmp_path / "c")}) == tmp_path / "c"
    # a value set by lagice in a parent process: its parent is the base (no nesting)
    assert _numba_cache.cache_base({"NUMBA_CACHE_DIR": str(tmp_path / "c" / "lagice-0123")}) == tmp_path / "c"
    assert _numba_cache.cache_base({"XDG_CACHE_HOME": str(tmp_path)}) == tmp_path / "lagice" / "numba"

    now = time.time()
    dirs = []
    for i in range(8):
        d = tmp_path / f"lagice-{i:016d}"
        d.mkdir()
        age_days = 30 if i < 6 else 1
        os.utime(d, (now - age_days * 86400 - i, now - age_days * 86400 - i))
        dirs.append(d)
    (tmp_path / "other").mkdir()
    current = dirs[0]
    removed = _numba_cache.prune(tmp_path, current, now=now)
    kept = sorted(p.name for p in tmp_path.iterdir())
    # the current one, the two recent ones and the two newest old ones (KEEP = 4 of the others)
    assert current.exists() and dirs[6].exists() and dirs[7].exists() and (tmp_path / "other").exists()
    assert len(removed) == 7 - _numba_cache.KEEP
    assert len(kept) == 1 + 1 + _numba_cache.KEEP, kept


def test_configure_in_this_process_points_numba_at_the_digest():
    if os.environ.get("LAGICE_NUMBA_CACHE") == "numba":
        pytest.skip("LAGICE_NUMBA_CACHE=numba: numba's own cache placement was asked for")
    from numba.core import config

    import lagice  # noqa: F401 - configured at import
    d = Path(config.CACHE_DIR)
    assert d.name == "lagice-" + _numba_cache.source_digest(_numba_cache.package_dirs())
    assert {p.name for p in _numba_cache.package_dirs()} == {"lagice", "forcing", "thermo"}
