"""The field registry: one declaration per field of the model state.

Each :class:`FieldSpec` says where a field lives (node or element), its units,
CF names, valid range, how remeshing transfers it, and whether checkpoints and
snapshots carry it. The registry drives state validation
(:func:`validate_state`), the fields remeshing remaps
(:func:`remapped_element_fields`), the attributes of snapshot variables, the
arrays of a checkpoint (:func:`checkpoint_arrays`) and the NaN/Inf check of a
running simulation (:func:`first_non_finite`).

Diagnostics that are functions of the model rather than state (the transport
velocity, deformation rates) are declared in :data:`DIAGNOSTICS` with the same
metadata, so every writer labels them the same way.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import ConfigError

NODE = "node"
ELEMENT = "element"


@dataclass(frozen=True)
class FieldSpec:
    """One state field.

    Attributes:
        name: attribute of :class:`~lagice.state.IceState`.
        location: ``"node"`` or ``"element"``.
        units: UDUNITS string.
        long_name: CF long_name.
        standard_name: CF standard name, or None.
        components: names of the trailing dimension (``("xx", "yy", "xy")``), or ().
        valid_min, valid_max: closed range of valid values (None: unbounded).
        remap: how remeshing transfers it: ``"area_mean"`` (element: area-weighted
            mean over the supermesh, so ∫ f da is kept: extensive totals h·a, A·a
            are conserved), ``"interpolate"`` (node: P1 interpolation at new
            nodes), ``"ids"`` (node identifiers: kept nodes keep theirs, new nodes
            get new ones), or ``"none"``.
        checkpoint: carried in checkpoints.
        snapshot: written to snapshots.
        optional: may be None (absent) in a state.
        dtype: numpy dtype name of the stored array.
    """

    name: str
    location: str
    units: str
    long_name: str
    standard_name: str | None = None
    components: tuple = ()
    valid_min: float | None = None
    valid_max: float | None = None
    remap: str = "area_mean"
    checkpoint: bool = True
    snapshot: bool = True
    optional: bool = False
    dtype: str = "float64"

    def shape(self, n_nodes: int, n_elements: int) -> tuple:
        n = n_nodes if self.location == NODE else n_elements
        return (n, len(self.components)) if self.components else (n,)


#: the state fields, in the order they are written
FIELDS: dict[str, FieldSpec] = {f.name: f for f in (
    FieldSpec("velocity", NODE, "m s-1", "ice velocity at the end of the step (dynamic state)",
              components=("x", "y"), remap="interpolate", snapshot=False),
    FieldSpec("node_id", NODE, "1", "persistent node identifier (kept through remeshing)",
              remap="ids", optional=True, dtype="int64"),
    FieldSpec("thickness", ELEMENT, "m", "ice volume per unit area (effective thickness)",
              "sea_ice_thickness", valid_min=0.0),
    FieldSpec("concentration", ELEMENT, "1", "ice concentration", "sea_ice_area_fraction",
              valid_min=0.0, valid_max=1.0),
    FieldSpec("damage", ELEMENT, "1", "damage (0 undamaged, 1 fully damaged)", valid_min=0.0, valid_max=1.0),
    FieldSpec("stress", ELEMENT, "Pa", "depth-averaged internal stress, tension positive",
              components=("xx", "yy", "xy")),
    FieldSpec("cohesion", ELEMENT, "Pa", "cohesion of the Mohr-Coulomb envelope", valid_min=0.0),
    FieldSpec("snow", ELEMENT, "m", "snow volume per unit area", "surface_snow_thickness", valid_min=0.0,
              optional=True),
    FieldSpec("strength_factor", ELEMENT, "1",
              "spatially correlated strength factor (multiplies the cohesion; carried by the ice)",
              valid_min=0.0, optional=True),
    FieldSpec("strain_accumulated", ELEMENT, "1",
              "time integral of the strain rate the rheology used, since counters['strain_accumulated_since_s'] "
              "(output.accumulate_strain)", components=("xx", "yy", "xy"), optional=True),
)}


@dataclass(frozen=True)
class DiagnosticSpec:
    """A field computed from the model for output (not part of the state)."""

    name: str
    location: str
    units: str
    long_name: str
    standard_name: str | None = None


#: diagnostics every snapshot carries (computed by :func:`diagnostic_fields`)
DIAGNOSTICS: dict[str, DiagnosticSpec] = {d.name: d for d in (
    DiagnosticSpec("velocity_x", NODE, "m s-1",
                   "ice velocity x component over the last step (transport velocity: moved the nodes)",
                   "sea_ice_x_velocity"),
    DiagnosticSpec("velocity_y", NODE, "m s-1",
                   "ice velocity y component over the last step (transport velocity: moved the nodes)",
                   "sea_ice_y_velocity"),
    DiagnosticSpec("divergence_rate", ELEMENT, "s-1", "divergence of the transport velocity",
                   "divergence_of_sea_ice_velocity"),
    DiagnosticSpec("shear_rate", ELEMENT, "s-1", "maximum shear rate of the transport velocity"),
    DiagnosticSpec("total_deformation_rate", ELEMENT, "s-1", "total deformation rate sqrt(div^2+shear^2)"),
)}


def element_specs(*, remapped: bool = False):
    return [f for f in FIELDS.values() if f.location == ELEMENT and (not remapped or f.remap != "none")]


def node_specs():
    return [f for f in FIELDS.values() if f.location == NODE]


def remapped_element_fields(state) -> dict:
    """The element fields of ``state`` that remeshing transfers (name -> array)."""
    out = {}
    for f in element_specs(remapped=True):
        v = getattr(state, f.name, None)
        if v is not None:
            out[f.name] = v
    return out


def validate_state(state) -> None:
    """Raise :class:`ConfigError` naming the field, its shape or its value range and
    the expected one, for any state field that is missing, misshapen, non-finite
    or out of range."""
    n, m = state.mesh.n_nodes, state.mesh.n_elements
    for f in FIELDS.values():
        a = getattr(state, f.name, None)
        if a is None:
            if f.optional:
                continue
            raise ConfigError(f"state field {f.name!r} is missing")
        shape = f.shape(n, m)
        if np.shape(a) != shape:
            per = "node" if f.location == NODE else "element"
            raise ConfigError(f"{f.name} has shape {np.shape(a)}; expected {shape} (one value per {per})")
        if a.dtype.kind == "f" and not np.all(np.isfinite(a)):
            raise ConfigError(f"{f.name} contains NaN or inf")
        lo, hi = f.valid_min, f.valid_max
        if a.size and ((lo is not None and a.min() < lo) or (hi is not None and a.max() > hi)):
            raise ConfigError(f"{f.name} ranges over [{a.min():.6g}, {a.max():.6g}] {f.units}; expected values "
                              f"in [{lo if lo is not None else '-inf'}, {hi if hi is not None else 'inf'}]")
    if state.damage.size and state.damage.max() >= 1.0:
        raise ConfigError("damage must be < 1 (1 = fully damaged has zero stiffness)")


def checkpoint_arrays(state) -> dict:
    """State arrays a checkpoint carries (absent optional fields are left out)."""
    out = {}
    for f in FIELDS.values():
        a = getattr(state, f.name, None)
        if f.checkpoint and a is not None:
            out[f.name] = a
    return out


def first_non_finite(state, skip=()):
    """``(field, index, value)`` of the first NaN/Inf in the floating-point state
    fields (but those named in ``skip``), or None when all are finite."""
    for f in FIELDS.values():
        if f.name in skip:
            continue
        a = getattr(state, f.name, None)
        if a is None or a.dtype.kind != "f":
            continue
        if np.isfinite(np.sum(a)):
            continue  # a NaN or an inf makes the sum NaN or inf: all finite (one pass, no mask)
        bad = ~np.isfinite(a)
        if bad.any():
            idx = np.argwhere(bad)[0]
            return f, int(idx[0]), float(a[tuple(idx)])
    return None


def cf_attrs(spec, grid_mapping: str | None = None) -> dict:
    """CF/UGRID attributes of a field or diagnostic variable on the ``mesh`` topology."""
    attrs = {"units": spec.units, "long_name": spec.long_name, "mesh": "mesh",
             "location": "node" if spec.location == NODE else "face"}
    if spec.standard_name:
        attrs["standard_name"] = spec.standard_name
    if grid_mapping:
        attrs["grid_mapping"] = grid_mapping
    return attrs
