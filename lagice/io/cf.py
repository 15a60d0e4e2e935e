"""CF conventions shared by the writers: the grid-mapping variable of a projected
CRS and the global attributes (provenance) of every file lagice writes."""
from __future__ import annotations

import json
import os
import subprocess
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import xarray as xr

CONVENTIONS_UGRID = "CF-1.8 UGRID-1.0"
CONVENTIONS = "CF-1.8"


def crs_variable(crs):
    """A scalar ``crs`` grid-mapping variable with CF attributes and WKT for ``crs``
    (any pyproj input: ``"EPSG:3413"``, an EPSG number, a PROJ string), or None."""
    if crs is None:
        return None
    from ..crs import cf_grid_mapping

    return xr.DataArray(np.int32(0), attrs=cf_grid_mapping(crs))


_COMMIT = None
_MODIFIED: list = []


def git_modified_files() -> list:
    """The tracked files of the lagice source tree that differ from its commit (what makes
    :func:`git_commit` end in ``-dirty``), as paths relative to the tree; [] if none or unknown."""
    git_commit()
    return list(_MODIFIED)


def git_commit() -> str | None:
    """The commit of the lagice source tree, when it is a git checkout (else None); ``-dirty``
    appended when tracked files differ from it (:func:`git_modified_files` names them)."""
    global _COMMIT
    if _COMMIT is None:
        root = Path(__file__).resolve().parents[2]
        try:
            out = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True,
                                 timeout=5)
            _COMMIT = out.stdout.strip() if out.returncode == 0 else ""
            if _COMMIT:
                dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                                       capture_output=True, text=True, timeout=5)
                if dirty.returncode == 0 and dirty.stdout.strip():
                    _COMMIT += "-dirty"
                    _MODIFIED[:] = [line[3:] for line in dirty.stdout.splitlines() if len(line) > 3]
        except (OSError, subprocess.SubprocessError):
            _COMMIT = ""
    return _COMMIT or None


def provenance(title: str, config: dict | None = None, extra: dict | None = None) -> dict:
    """Global attributes: Conventions, title, history, source (lagice version and
    commit), the scene configuration as JSON, the parent checkpoint of a branched run
    (``lagice_parent_checkpoint``, ``lagice_parent_checkpoint_sha256``, from
    ``config["_parent"]``), the ensemble member of an ensemble run (``lagice_ensemble``,
    ``lagice_ensemble_member``, ``lagice_ensemble_member_overrides`` as JSON, from
    ``config["_ensemble"]``, :mod:`lagice.ensemble`), plus ``extra``."""
    from .. import __version__

    now = datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
    attrs = {"title": title, "institution": "lagice", "source": f"lagice {__version__}",
             "history": f"{now}: written by lagice {__version__}", "lagice_version": __version__}
    commit = git_commit()
    if commit:
        attrs["lagice_git_commit"] = commit
        attrs["source"] += f" (git {commit})"
    if config:
        attrs["lagice_config"] = json.dumps({k: v for k, v in config.items() if not str(k).startswith("_")},
                                            sort_keys=True, default=str)
        parent = config.get("_parent")
        if parent:
            attrs["lagice_parent_checkpoint"] = str(parent["checkpoint"])
            attrs["lagice_parent_checkpoint_sha256"] = str(parent["sha256"])
            attrs["history"] += (f"\n{now}: branched from checkpoint {parent['checkpoint']} (step {parent['step']}, "
                                 f"sha256 {parent['sha256']})")
        member = config.get("_ensemble")
        if member:
            attrs["lagice_ensemble"] = str(member["ensemble"])
            attrs["lagice_ensemble_member"] = str(member["member"])
            attrs["lagice_ensemble_member_overrides"] = json.dumps(member.get("overrides", {}), sort_keys=True,
                                                                   default=str)
            attrs["history"] += f"\n{now}: member {member['member']!r} of the ensemble {member['ensemble']!r}"
    attrs.update(extra or {})
    return attrs


def time_coordinate(time_s: float, start_date: str) -> tuple:
    return ("time", np.array([float(time_s)]), {"units": f"seconds since {start_date}", "standard_name": "time",
                                                "calendar": "standard", "axis": "T"})


def write_netcdf_atomic(ds: xr.Dataset, path: Path) -> Path:
    """Write ``ds`` to ``path`` through a temporary file and an atomic rename; no
    ``_FillValue`` on variables without missing values."""
    path = Path(path)
    tmp = path.with_suffix(path.suffix + ".tmp")
    enc = {v: {"_FillValue": None} for v in ds.variables
           if ds[v].dtype.kind in "fiu" and "_FillValue" not in ds[v].encoding and not ds[v].isnull().any()}
    with atomic_write_errors(path, tmp):
        ds.to_netcdf(tmp, encoding=enc)
        os.replace(tmp, path)
    return path


def write_text_atomic(path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` through a temporary file and an atomic rename: a
    reader (or a second writer: ``lagice diagnose`` beside a run) sees the old file or the
    new one, never a part."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    with atomic_write_errors(path, tmp):
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    return path


def save_figure_atomic(fig, path, **savefig_kw) -> Path:
    """``fig.savefig(path)`` through a temporary file (named ``.NAME.tmp.SUFFIX``, so that
    matplotlib keeps the format of ``path``) and an atomic rename: a run that redraws its
    figure at its end and ``lagice plot`` beside it never leave a half-written PNG."""
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    with atomic_write_errors(path, tmp):
        fig.savefig(tmp, **savefig_kw)
        os.replace(tmp, path)
    return path


class atomic_write_errors:
    """Context manager for a write through ``tmp``: on failure the temporary file is
    removed and the error becomes an :class:`~lagice.errors.OutputError` naming
    ``path`` and the reason (disk full, read-only folder, ...)."""

    def __init__(self, path, tmp=None):
        self.path = Path(path)
        self.tmp = Path(tmp) if tmp is not None else None

    def __enter__(self):
        return self

    def __exit__(self, typ, exc, tb):
        if exc is None:
            return False
        if self.tmp is not None:
            try:
                self.tmp.unlink(missing_ok=True)
            except OSError:
                pass
        from ..errors import LagiceError, OutputError

        if isinstance(exc, LagiceError) or not isinstance(exc, Exception):
            return False
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else f"{type(exc).__name__}: {exc}"
        try:
            st = os.statvfs(self.path.parent)
            free = f"; {st.f_bavail * st.f_frsize / 1e9:.3g} GB free there"
        except OSError:
            free = ""
        raise OutputError(f"cannot write {self.path}: {reason} (disk full, quota or read-only folder?{free})"
                          ) from exc
