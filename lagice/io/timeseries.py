"""Time series of named scalar diagnostics (functions of the model) in one
netCDF file with a ``time`` dimension.

Built-in diagnostics (:data:`BUILTIN`) cover the ice budget, damage and speed;
a scene adds its own as ``module:function`` hooks taking the model and returning
a float (units and long name given in the scene, or as function attributes
``units``/``long_name``). The file is rewritten atomically at every flush (a
checkpoint, the end of the run); a resumed run reloads the rows written up to
its checkpoint, so the series is the same as an uninterrupted run's.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .cf import CONVENTIONS, provenance, write_netcdf_atomic


@dataclass(frozen=True)
class ScalarDiagnostic:
    """A scalar function of the model with its units and long name."""

    function: object
    units: str = "1"
    long_name: str = ""


def _areas(model):
    return np.abs(model.mesh.areas())


def _speed(model):
    v = model.transport_velocity
    return np.hypot(v[:, 0], v[:, 1])


#: built-in diagnostics by name
BUILTIN = {
    "ice_volume": ScalarDiagnostic(lambda m: m.state.ice_volume_m3, "m3", "total ice volume"),
    "ice_area": ScalarDiagnostic(lambda m: float(np.sum(m.state.concentration * _areas(m))), "m2",
                                 "total ice area (concentration times element area)"),
    "volume_residual": ScalarDiagnostic(lambda m: m.volume_budget()["relative_residual"], "1",
                                        "relative residual of the ice volume budget"),
    "mean_damage": ScalarDiagnostic(lambda m: float(np.average(m.state.damage, weights=_areas(m))), "1",
                                    "area-mean damage"),
    "damaged_fraction": ScalarDiagnostic(
        lambda m: float(np.sum(_areas(m)[m.state.damage > 0.5]) / np.sum(_areas(m))), "1",
        "area fraction with damage > 0.5"),
    "mean_speed": ScalarDiagnostic(lambda m: float(np.mean(_speed(m))), "m s-1", "node-mean ice speed"),
    "max_speed": ScalarDiagnostic(lambda m: float(np.max(_speed(m))), "m s-1", "maximum ice speed"),
    "n_elements": ScalarDiagnostic(lambda m: float(m.mesh.n_elements), "1", "number of mesh elements"),
    "remesh_count": ScalarDiagnostic(lambda m: float(m.state.counters.get("remesh_count", 0)), "1",
                                     "remesh events so far"),
    "n_damaged": ScalarDiagnostic(lambda m: float(getattr(m.last_report.get("solver"), "n_damaged", 0)), "1",
                                  "elements that damaged in the last step"),
    "substeps": ScalarDiagnostic(lambda m: float(getattr(m.last_report.get("solver"), "iterations", 0)), "1",
                                 "sub-steps (explicit), iterations (mEVP) or fixed-point iterations (implicit)"),
}


def diagnostic(units: str = "1", long_name: str = ""):
    """Decorator giving a scene hook ``f(model) -> float`` its units and long name."""
    def deco(f):
        f.units = units
        f.long_name = long_name
        return f
    return deco


class TimeSeriesWriter:
    """Records ``diagnostics`` ({name: ScalarDiagnostic}) and writes them to ``path``."""

    def __init__(self, path, diagnostics: dict, start_date: str = "2000-01-01 00:00:00",
                 title: str = "lagice time series"):
        self.path = Path(path)
        self.diagnostics = dict(diagnostics)
        self.start_date = start_date
        self.title = title
        self.time = []
        self.rows = {k: [] for k in self.diagnostics}
        self.config = None

    def record(self, model) -> None:
        self.config = model.config
        self.time.append(model.clock.time_s)
        for k, d in self.diagnostics.items():
            self.rows[k].append(float(d.function(model)))

    def reload(self, up_to_time_s: float) -> None:
        """Start from the rows already in the file up to ``up_to_time_s`` (resume)."""
        if not self.path.exists():
            return
        import xarray as xr

        with xr.open_dataset(self.path, decode_times=False) as ds:
            keep = ds["time"].values <= up_to_time_s * (1 + 1e-12) + 1e-9
            self.time = [float(t) for t in ds["time"].values[keep]]
            for k in self.diagnostics:
                self.rows[k] = [float(v) for v in ds[k].values[keep]] if k in ds else [np.nan] * len(self.time)

    def flush(self) -> Path | None:
        if not self.time:
            return None
        import xarray as xr

        ds = xr.Dataset(coords={"time": ("time", np.array(self.time), {
            "units": f"seconds since {self.start_date}", "standard_name": "time", "calendar": "standard",
            "axis": "T"})})
        for k, d in self.diagnostics.items():
            ds[k] = ("time", np.array(self.rows[k]), {"units": d.units, "long_name": d.long_name or k})
        ds.attrs.update(provenance(self.title, self.config, {"Conventions": CONVENTIONS}))
        self.path.parent.mkdir(parents=True, exist_ok=True)
        return write_netcdf_atomic(ds, self.path)
