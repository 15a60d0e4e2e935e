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


def crs_variable(crs_epsg: int | None):
    """A scalar ``crs`` grid-mapping variable with CF attributes and WKT, or None."""
    if crs_epsg is None:
        return None
    import pyproj

    crs = pyproj.CRS.from_epsg(int(crs_epsg))
    attrs = crs.to_cf()
    attrs["crs_wkt"] = crs.to_wkt()
    if attrs.get("grid_mapping_name") == "polar_stereographic" and "latitude_of_projection_origin" not in attrs:
        # CF requires it; pyproj omits it for the variant-B (standard parallel) definition
        attrs["latitude_of_projection_origin"] = 90.0 if attrs.get("standard_parallel", 90.0) > 0 else -90.0
    return xr.DataArray(np.int32(0), attrs=attrs)


_COMMIT = None


def git_commit() -> str | None:
    """The commit of the lagice source tree, when it is a git checkout (else None)."""
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
        except (OSError, subprocess.SubprocessError):
            _COMMIT = ""
    return _COMMIT or None


def provenance(title: str, config: dict | None = None, extra: dict | None = None) -> dict:
    """Global attributes: Conventions, title, history, source (lagice version and
    commit), the scene configuration as JSON, plus ``extra``."""
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
    ds.to_netcdf(tmp, encoding=enc)
    os.replace(tmp, path)
    return path
