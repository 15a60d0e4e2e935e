"""Spun-up initial states: the end of a model run as the start of another (issue 12).

A spin-up run (e.g. ``examples/winter_basin_spinup.toml``: 14 days of the winter wind
climatology on pristine ice) leaves a heterogeneous, partly damaged pack.
:func:`save_spinup` keeps its element fields at the last snapshot (centroids,
damage, thickness, concentration; float32; and the correlated strength factor
``strength_factor`` with its ℓ and a when the run had one) in a small ``.npz``; the scene hooks
:func:`winter_basin_damage`, :func:`winter_basin_thickness`,
:func:`winter_basin_concentration` read ``data_stubs/winter_basin_spinup.npz`` and give
each new element the value of the nearest spin-up centroid, so they serve any
resolution (``[initial] damage = "lagice.spinup:winter_basin_damage"``). Scenes name
the file instead: ``[initial] state_file = "data_stubs/winter_basin_spinup.npz"`` with
``damage = "from_state"`` (and ``thickness_m``, ``concentration``), so that a run can
start from another spin-up (``--set initial.state_file=...``).

    python -m lagice.spinup RUN_DIR OUT.npz        # save the last snapshot of a run
"""
from __future__ import annotations

import json
import sys
from functools import lru_cache
from pathlib import Path

import numpy as np

from .errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]
WINTER_BASIN = ROOT / "data_stubs" / "winter_basin_spinup.npz"
FIELDS = ("damage", "thickness", "concentration")
#: fields a state file may hold: the correlated strength factor g (lagice.strength), with the
#: scalars ``strength_correlation_m`` and ``strength_correlated_amplitude`` of the run that made it
OPTIONAL_FIELDS = ("strength_factor",)
CORRELATION_KEYS = ("strength_correlation_m", "strength_correlated_amplitude")


def _correlation_of_run(run_dir: Path) -> dict:
    """ℓ and a of the correlated strength field of ``run_dir`` (from its newest checkpoint's
    configuration, with the law's defaults)."""
    from .io.checkpoint import read_checkpoint
    from .strength import StrengthLaw

    cks = sorted((run_dir / "checkpoints").glob("*.npz")) if (run_dir / "checkpoints").exists() else []
    if not cks:
        raise ConfigError(f"{run_dir}: its snapshots carry a correlated strength factor but the run has no "
                          "checkpoint to tell its strength_correlation_m and strength_correlated_amplitude")
    rh = read_checkpoint(cks[-1])[1]["config"]["rheology"]
    law = StrengthLaw(correlation_m=float(rh["strength_correlation_m"]),
                      correlated_amplitude=rh.get("strength_correlated_amplitude"))
    return {"strength_correlation_m": np.float64(law.correlation_m),
            "strength_correlated_amplitude": np.float64(law.amplitude)}


def save_spinup(run_dir, out_path) -> Path:
    """Element centroids and FIELDS (and OPTIONAL_FIELDS the run has) of the last snapshot
    of ``run_dir`` → ``out_path``."""
    import xarray as xr

    run_dir = Path(run_dir)
    idx = json.loads((run_dir / "snapshots" / "index.json").read_text())
    last = idx[-1]
    with xr.open_dataset(run_dir / "snapshots" / last["file"], decode_times=False) as ds:
        nodes = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
        tri = ds["mesh_face_nodes"].values.astype(np.int64)
        arrays = {k: ds[k].values[0].astype(np.float32) for k in FIELDS}
        arrays.update({k: ds[k].values[0].astype(np.float32) for k in OPTIONAL_FIELDS if k in ds})
    if "strength_factor" in arrays:
        arrays.update(_correlation_of_run(run_dir))
    c = nodes[tri].mean(axis=1)
    out = Path(out_path)
    np.savez_compressed(out, centroid_x_m=c[:, 0].astype(np.float32), centroid_y_m=c[:, 1].astype(np.float32),
                        time_s=np.float64(last["time_s"]), source=str(run_dir.name), **arrays)
    return out


#: valid range of each field of a state file (inclusive)
RANGES = {"damage": (0.0, 1.0), "thickness": (0.0, 100.0), "concentration": (0.0, 1.0),
          "strength_factor": (0.0, 2.0)}


def resolve_state_path(spec) -> Path:
    """A state file's path: absolute, else relative to the working directory when it
    exists there, else to the lagice checkout (as ``domain.file``)."""
    p = Path(spec)
    if not p.is_absolute() and not p.exists():
        p = ROOT / p
    return p


def load_state_file(spec, key: str = "initial.state_file"):
    """(centroid tree, {field: float64 values}) of a spin-up state, checked: the file
    exists and holds the centroids and FIELDS, finite and inside RANGES (a ConfigError
    names ``key``, the file, the field, the bad value and the range). OPTIONAL_FIELDS the
    file holds are checked alike and returned, with the CORRELATION_KEYS scalars."""
    p = resolve_state_path(spec)
    if not p.exists():
        raise ConfigError(f"{key} = {str(spec)!r}: spin-up state {p} does not exist; make it with "
                          "`python benchmarks/physics_experiments.py spinup`")
    return _load(str(p.resolve()), p.stat().st_mtime_ns, key)


@lru_cache(maxsize=4)
def _load(path: str, mtime_ns: int, key: str):
    from scipy.spatial import cKDTree

    try:
        z = np.load(path)
        names = set(z.files)
    except Exception as exc:  # noqa: BLE001
        raise ConfigError(f"{key}: cannot read {path} as an .npz spin-up state: {exc}") from exc
    need = {"centroid_x_m", "centroid_y_m", *FIELDS}
    if need - names:
        raise ConfigError(f"{key}: {path} lacks {sorted(need - names)} (a spin-up state holds {sorted(need)})")
    xy = np.column_stack([z["centroid_x_m"], z["centroid_y_m"]]).astype(np.float64)
    if len(xy) == 0 or not np.isfinite(xy).all():
        raise ConfigError(f"{key}: {path}: centroids are empty or not finite")
    fields = {}
    for k in FIELDS + tuple(f for f in OPTIONAL_FIELDS if f in names):
        v = z[k].astype(np.float64)
        lo, hi = RANGES[k]
        if v.shape != (len(xy),):
            raise ConfigError(f"{key}: {path}: field {k!r} has shape {v.shape}, expected ({len(xy)},)")
        bad = ~np.isfinite(v) | (v < lo) | (v > hi)
        if bad.any():
            raise ConfigError(f"{key}: {path}: field {k!r} has {int(bad.sum())} values outside [{lo:g}, {hi:g}] "
                              f"(first: {v[bad][0]!r})")
        fields[k] = v
    if "strength_factor" in fields:
        if set(CORRELATION_KEYS) - names:
            raise ConfigError(f"{key}: {path} holds strength_factor but lacks {sorted(set(CORRELATION_KEYS) - names)}")
        for k in CORRELATION_KEYS:
            fields[k] = float(z[k])
    return cKDTree(xy), fields


#: a point lies in a state's footprint when a state centroid is within this many times the
#: state's centroid spacing of it (:func:`check_footprint`)
FOOTPRINT_SPACINGS = 5.0


@lru_cache(maxsize=4)
def _spacing(path: str, mtime_ns: int, key: str) -> float:
    tree = _load(path, mtime_ns, key)[0]
    if tree.n < 2:
        return float("inf")
    d, _ = tree.query(tree.data, k=2)
    return float(np.median(d[:, 1]))


def footprint_tolerance_m(spec, key: str = "initial.state_file") -> float:
    """The distance [m] from a state centroid within which a point is covered by the state:
    :data:`FOOTPRINT_SPACINGS` (5) times the state's centroid spacing ``s``, the median
    distance from a state centroid to its nearest neighbour. On a mesh of equilateral
    elements of side h, s = h / sqrt(3), so the tolerance is about 2.9 h: a domain point
    (even a corner of the coast) is a fraction of an element from the nearest centroid of a
    state made on the same domain, and a mesh beyond the state is refused."""
    load_state_file(spec, key)
    p = resolve_state_path(spec)
    return FOOTPRINT_SPACINGS * _spacing(str(p.resolve()), p.stat().st_mtime_ns, key)


def check_footprint(spec, x, y, key: str = "initial.state_file", what: str = "the mesh") -> None:
    """ConfigError unless every point (x, y) [m] lies within :func:`footprint_tolerance_m`
    of a centroid of the spin-up state ``spec``: the nearest-centroid lookup of
    :func:`field_from_spinup` would otherwise fill a domain the state does not cover. The
    message names ``key``, the file, the farthest point, its distance in km and the tolerance."""
    tree, _ = load_state_file(spec, key)
    xy = np.column_stack([np.asarray(x, np.float64).ravel(), np.asarray(y, np.float64).ravel()])
    if not len(xy):
        return
    d, _ = tree.query(xy)
    tol = footprint_tolerance_m(spec, key)
    i = int(np.argmax(d))
    if d[i] > tol:
        lo, hi = tree.data.min(axis=0) / 1e3, tree.data.max(axis=0) / 1e3
        raise ConfigError(
            f"{key} = {str(spec)!r}: {what} lies outside the spin-up state's footprint: the point x = "
            f"{xy[i, 0] / 1e3:.1f} km, y = {xy[i, 1] / 1e3:.1f} km is {d[i] / 1e3:.1f} km from the nearest state "
            f"centroid (tolerance {tol / 1e3:.1f} km: {FOOTPRINT_SPACINGS:g} times the state's centroid spacing); "
            f"the state covers x in [{lo[0]:.0f}, {hi[0]:.0f}] km, y in [{lo[1]:.0f}, {hi[1]:.0f}] km. Use a state "
            f"made on this domain (and domain.crs)")


def field_from_spinup(path, name, x, y) -> np.ndarray:
    """Value of spin-up field ``name`` at the nearest spin-up centroid of each (x, y)."""
    tree, fields = load_state_file(path)
    _, i = tree.query(np.column_stack([np.asarray(x, np.float64), np.asarray(y, np.float64)]))
    v = fields[name][i]
    if name == "damage":  # float32 storage may round 0.9999999 up to 1 (the rheology's cap)
        v = np.minimum(v, 1.0 - 1e-6)
    return v


def winter_basin_damage(x, y):
    """Damage of the winter_basin spin-up (scene hook)."""
    return field_from_spinup(WINTER_BASIN, "damage", x, y)


def winter_basin_thickness(x, y):
    """Effective thickness [m] of the winter_basin spin-up (scene hook)."""
    return field_from_spinup(WINTER_BASIN, "thickness", x, y)


def winter_basin_concentration(x, y):
    """Concentration of the winter_basin spin-up (scene hook)."""
    return field_from_spinup(WINTER_BASIN, "concentration", x, y)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        raise SystemExit("usage: python -m lagice.spinup RUN_DIR OUT.npz")
    print(f"wrote {save_spinup(sys.argv[1], sys.argv[2])}")
