"""The coordinate reference system (CRS) of a scene: one per scene.

``[domain] crs`` (any string pyproj understands: ``"EPSG:3413"``, a PROJ string,
WKT) is the projected plane the model works in. The same CRS

* places the domain: a coastline file in another CRS (``[domain] file_crs``, or the
  file's own ``crs`` member) is projected into it; coordinates that look like
  degrees in a metric CRS are an error (:func:`check_not_degrees`);
* reads gridded forcing files (lon/lat grids are mapped with it, east/north
  vectors rotated into its x/y frame);
* labels every output (the CF grid-mapping variable ``crs``: :func:`cf_grid_mapping`);
* gives the Coriolis parameter per node when ``[forcing.coriolis] latitude_deg =
  "crs"`` (:func:`latitudes`).

The model plane must be projected with metre axes: the mesh, the solvers and
every length in a scene are in metres.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from .errors import ConfigError

DEFAULT_CRS = "EPSG:3413"  # NSIDC sea-ice polar stereographic north


@lru_cache(maxsize=32)
def _parse(value: str):
    import pyproj

    return pyproj.CRS.from_user_input(value)


def parse_crs(value, key: str = "domain.crs"):
    """A :class:`pyproj.CRS` from a string, an EPSG number or a CRS; ConfigError naming ``key``."""
    import pyproj

    if isinstance(value, pyproj.CRS):
        return value
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise ConfigError(f"{key} = {value!r}: expected a CRS string pyproj understands (e.g. 'EPSG:3413')")
    try:
        return _parse(f"EPSG:{value}" if isinstance(value, int) else value)
    except pyproj.exceptions.CRSError as exc:
        raise ConfigError(f"{key} = {value!r}: not a coordinate reference system pyproj understands ({exc})") from None


def model_crs(value, key: str = "domain.crs"):
    """The model plane's CRS: projected, with metre axes (ConfigError otherwise)."""
    crs = parse_crs(value, key)
    if not crs.is_projected:
        raise ConfigError(f"{key} = {value!r} is a geographic CRS (degrees); the model plane must be a projected "
                          f"CRS in metres (e.g. 'EPSG:3413' for the Arctic, 'EPSG:3031' for the Antarctic)")
    units = {(ax.unit_name or "").lower() for ax in crs.axis_info[:2]}
    if not units <= {"metre", "meter", "m"}:
        raise ConfigError(f"{key} = {value!r} has axis units {sorted(units)}; the model plane must be in metres")
    return crs


@lru_cache(maxsize=32)
def _to_lonlat(crs_wkt: str):
    import pyproj

    return pyproj.Transformer.from_crs(pyproj.CRS.from_wkt(crs_wkt), "EPSG:4326", always_xy=True)


def lonlat(crs, x, y):
    """Longitude and latitude [deg] of projected points ``x, y`` [m] of ``crs``."""
    crs = parse_crs(crs)
    lon, lat = _to_lonlat(crs.to_wkt()).transform(np.asarray(x, np.float64), np.asarray(y, np.float64))
    return np.asarray(lon, np.float64), np.asarray(lat, np.float64)


def latitudes(crs, x, y) -> np.ndarray:
    """Latitude [deg] of projected points ``x, y`` [m] of ``crs``."""
    return lonlat(crs, x, y)[1]


def looks_like_degrees(bounds) -> bool:
    """True when a bounding box (xmin, ymin, xmax, ymax) fits in ±180 × ±90: in a
    metric CRS that is a domain a few hundred metres wide at most, far more likely a
    lon/lat file read as metres."""
    x0, y0, x1, y1 = bounds
    return -180.0 <= x0 <= x1 <= 360.0 and -90.0 <= y0 <= y1 <= 90.0


def check_not_degrees(bounds, key: str, crs_text: str) -> None:
    """ConfigError when coordinates read in a metric CRS look like degrees."""
    if looks_like_degrees(bounds):
        x0, y0, x1, y1 = bounds
        raise ConfigError(
            f"{key}: coordinates span x {x0:g}..{x1:g}, y {y0:g}..{y1:g}, which look like longitude/latitude "
            f"degrees, but they are read in {crs_text} (metres): the domain would be {x1 - x0:.3g} m x "
            f"{y1 - y0:.3g} m. If the file is in lon/lat, set domain.file_crs = 'EPSG:4326' (it is then "
            f"projected into domain.crs)")


def project_geometry(geom, src, dst):
    """A shapely geometry from CRS ``src`` to CRS ``dst`` (pyproj, always x=lon/east first)."""
    import pyproj
    import shapely

    tr = pyproj.Transformer.from_crs(parse_crs(src), parse_crs(dst), always_xy=True)
    return shapely.transform(geom, lambda xy: np.column_stack(tr.transform(xy[:, 0], xy[:, 1])))


def cf_grid_mapping(crs) -> dict:
    """CF grid-mapping attributes of ``crs`` (pyproj ``to_cf``) plus ``crs_wkt``, with
    the attributes CF requires that pyproj leaves out."""
    crs = parse_crs(crs)
    attrs = crs.to_cf()
    attrs["crs_wkt"] = crs.to_wkt()
    if attrs.get("grid_mapping_name") == "polar_stereographic" and "latitude_of_projection_origin" not in attrs:
        # CF requires it; pyproj omits it for the variant-B (standard parallel) definition
        attrs["latitude_of_projection_origin"] = 90.0 if attrs.get("standard_parallel", 90.0) > 0 else -90.0
    return attrs
