"""Checkpoints: the whole model state in one ``.npz`` file, written atomically.

Format (``FORMAT_VERSION``): a numpy ``.npz`` (no pickles) holding named
arrays and one ``__meta__`` array with a UTF-8 JSON header: format version,
lagice version, scene fingerprint, simulated time, step, counters, random
generator state, and the SHA-256 of every array (name, dtype, shape, bytes).

Writing goes to ``NAME.tmp-PID`` in the same directory, is flushed and
fsync'ed, then renamed over ``NAME`` (``os.replace`` is atomic on POSIX), so a
run killed mid-write leaves the previous checkpoints intact; a failed write
(disk full, read-only folder) removes its temporary file and raises
:class:`~lagice.errors.OutputError`; stale ``.tmp-PID`` files of a killed
writer are ignored when reading and removed when the next run starts
(:func:`clean_stale_temporaries`). The last ``keep`` checkpoints are kept.
Any unreadable, truncated, corrupted (checksum) or incompatible (version,
scene) file raises :class:`~lagice.errors.RestartError`.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import re
import zipfile
from pathlib import Path

import numpy as np

from ..errors import RestartError

FORMAT_VERSION = 3
_NAME = re.compile(r"^checkpoint_(\d{10})\.npz$")


def _digest(arrays: dict) -> str:
    h = hashlib.sha256()
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(name.encode())
        h.update(str(a.dtype).encode())
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def checkpoint_name(step: int) -> str:
    return f"checkpoint_{step:010d}.npz"


def write_checkpoint(directory, step: int, arrays: dict, meta: dict, keep: int = 3) -> Path:
    """Write ``arrays`` + ``meta`` atomically as ``directory/checkpoint_STEP.npz``;
    keep the newest ``keep`` checkpoints."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    arrays = {k: np.asarray(v) for k, v in arrays.items()}
    for k, a in arrays.items():
        if a.dtype == object:
            raise RestartError(f"checkpoint array {k!r} has dtype object; only plain arrays are stored")
    header = dict(meta)
    header["format_version"] = FORMAT_VERSION
    header["sha256"] = _digest(arrays)
    header["step"] = int(step)
    buf = io.BytesIO()
    np.savez(buf, __meta__=np.frombuffer(json.dumps(header).encode(), dtype=np.uint8), **arrays)
    final = directory / checkpoint_name(step)
    tmp = directory / f"{final.name}.tmp-{os.getpid()}"
    from .cf import atomic_write_errors

    with atomic_write_errors(final, tmp):
        with open(tmp, "wb") as f:
            f.write(buf.getbuffer())
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, final)
    try:
        dfd = os.open(directory, os.O_RDONLY)
        os.fsync(dfd)
        os.close(dfd)
    except OSError:
        pass
    for old in list_checkpoints(directory)[:-keep] if keep > 0 else []:
        old.unlink(missing_ok=True)
    return final


_TMP = re.compile(r"^checkpoint_\d{10}\.npz\.tmp-(\d+)$")


def _pid_alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True  # exists, owned by someone else
    return True


def clean_stale_temporaries(directory) -> list[Path]:
    """Remove the ``checkpoint_*.npz.tmp-PID`` files a killed writer left in
    ``directory`` (those of a process that no longer runs); returns them."""
    directory = Path(directory)
    if not directory.is_dir():
        return []
    removed = []
    for p in directory.iterdir():
        m = _TMP.match(p.name)
        if m and not _pid_alive(int(m.group(1))):
            p.unlink(missing_ok=True)
            removed.append(p)
    return removed


def file_sha256(path) -> str:
    """SHA-256 of a file's bytes (the parent checkpoint of a branched run)."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def list_checkpoints(directory) -> list[Path]:
    """Checkpoint files in ``directory``, oldest first (temporary files excluded)."""
    directory = Path(directory)
    if not directory.is_dir():
        return []
    files = [p for p in directory.iterdir() if _NAME.match(p.name)]
    return sorted(files, key=lambda p: int(_NAME.match(p.name).group(1)))


def read_checkpoint(path, expect_fingerprint: str | None = None) -> tuple[dict, dict]:
    """Read and verify a checkpoint; returns (arrays, meta). Raises RestartError."""
    path = Path(path)
    if not path.is_file():
        raise RestartError(f"checkpoint {path} does not exist")
    try:
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (zipfile.BadZipFile, ValueError, OSError, EOFError, KeyError) as exc:
        raise RestartError(f"checkpoint {path} is unreadable (truncated or corrupted): {exc}") from exc
    if "__meta__" not in arrays:
        raise RestartError(f"checkpoint {path} has no header; not a lagice checkpoint")
    try:
        meta = json.loads(arrays.pop("__meta__").tobytes().decode())
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise RestartError(f"checkpoint {path} has a corrupted header: {exc}") from exc
    ver = meta.get("format_version")
    if ver != FORMAT_VERSION:
        raise RestartError(f"checkpoint {path} has format version {ver!r}; this lagice reads "
                           f"version {FORMAT_VERSION}")
    if _digest(arrays) != meta.get("sha256"):
        raise RestartError(f"checkpoint {path} is corrupted: checksum mismatch")
    if expect_fingerprint is not None and meta.get("scene_fingerprint") != expect_fingerprint:
        raise RestartError(f"checkpoint {path} belongs to another scene or configuration "
                           f"(fingerprint {meta.get('scene_fingerprint')!r}, expected {expect_fingerprint!r})")
    return arrays, meta


def latest_valid_checkpoint(directory, expect_fingerprint: str | None = None):
    """Newest checkpoint in ``directory`` that reads and verifies; older ones are
    tried when the newest is damaged. Returns (path, arrays, meta, skipped)."""
    skipped = []
    for p in reversed(list_checkpoints(directory)):
        try:
            arrays, meta = read_checkpoint(p, expect_fingerprint)
            return p, arrays, meta, skipped
        except RestartError as exc:
            skipped.append(str(exc))
    detail = ("; ".join(skipped)) if skipped else "no checkpoint files"
    raise RestartError(f"no usable checkpoint in {directory}: {detail}")
