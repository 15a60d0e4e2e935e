"""Mesh generation with the gmsh Python API from a shapely polygon.

``generate_mesh(polygon, size, segments=...)`` meshes a polygon (holes are
islands) with a target element size given as a number [m] or a callable
``size(x, y) -> m``, and tags the boundary edges.
"""
from __future__ import annotations

import signal
import threading
from contextlib import contextmanager

import numpy as np
import shapely
from shapely.geometry import LineString, Polygon, box
from shapely.validation import explain_validity

from ..errors import ConfigError, MeshError
from .core import COAST, Mesh, boundary_edges_of, signed_areas

_GMSH_LOCK = threading.RLock()


def _initialize(gmsh) -> None:
    """``gmsh.initialize``, keeping the SIGTERM handler: gmsh's initialisation resets
    the process's SIGTERM action to the default at the C level (Python still reports
    its handler, which then never runs), so a clean stop on SIGTERM (``Simulation``'s
    :class:`~lagice.activities.SignalStop`, ``lagice ensemble`` workers) would kill the
    process instead when gmsh first starts during a run (the first remesh of a resumed
    run). The Python handler is installed again (main thread only: elsewhere it cannot
    be, and whoever installs one must start gmsh first, e.g. with ``gmsh_session()``)."""
    handler = signal.getsignal(signal.SIGTERM)
    gmsh.initialize(interruptible=False)
    if handler is not None and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, handler)


@contextmanager
def gmsh_session(model_name: str = "lagice"):
    """Initialise gmsh once per process, clear the model, serialise access."""
    import gmsh

    with _GMSH_LOCK:
        if not gmsh.isInitialized():
            _initialize(gmsh)
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.Verbosity", 1)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.clear()
        gmsh.model.add(model_name)
        try:
            yield gmsh
        finally:
            gmsh.clear()


def validate_polygon(polygon, name: str = "polygon") -> Polygon:
    """Check a domain polygon; raise :class:`MeshError` naming the problem."""
    if not isinstance(polygon, Polygon):
        raise MeshError(f"{name} must be a shapely Polygon; got {type(polygon).__name__}")
    if polygon.is_empty:
        raise MeshError(f"{name} is empty")
    if not polygon.is_valid:
        raise MeshError(f"{name} is invalid: {explain_validity(polygon)} "
                        "(self-intersecting rings or islands outside the outer ring?)")
    if polygon.area <= 0:
        raise MeshError(f"{name} has zero area")
    return shapely.geometry.polygon.orient(polygon, sign=1.0)


def validate_size(size, polygon: Polygon):
    """Return a callable size(x, y) [m]; raise ConfigError for bad sizes."""
    if callable(size):
        x, y = polygon.representative_point().coords[0]
        try:
            s = float(np.asarray(size(np.array([x]), np.array([y]))).ravel()[0])
        except Exception as exc:  # noqa: BLE001 - report the user's function error
            raise ConfigError(f"element size function failed at ({x:.6g}, {y:.6g}) m: {exc}") from exc
        if not np.isfinite(s) or s <= 0:
            raise ConfigError(f"element size function returned {s!r} m at ({x:.6g}, {y:.6g}); "
                              "expected a positive finite length in metres")
        return size
    try:
        s = float(size)
    except (TypeError, ValueError):
        raise ConfigError(f"element size = {size!r} is neither a number [m] nor a function of (x, y)") from None
    if not np.isfinite(s) or s <= 0:
        raise ConfigError(f"element size = {size!r} m is out of range; expected a positive finite length")
    minx, miny, maxx, maxy = polygon.bounds
    if s > 10 * max(maxx - minx, maxy - miny):
        raise ConfigError(f"element size = {s:g} m is larger than 10x the domain extent")
    return s


def _rings(polygon: Polygon):
    yield np.asarray(polygon.exterior.coords)[:-1]
    for interior in polygon.interiors:
        yield np.asarray(interior.coords)[:-1]


#: gmsh 2-D algorithms that make triangles: 1 MeshAdapt, 2 Automatic, 5 Delaunay,
#: 6 Frontal-Delaunay, 7 BAMG (the others make quadrangles)
TRIANGLE_ALGORITHMS = {1: "MeshAdapt", 2: "Automatic", 5: "Delaunay", 6: "Frontal-Delaunay", 7: "BAMG"}


def check_mesh_algorithm(algorithm, key: str = "algorithm") -> int:
    """The gmsh 2-D algorithm, checked (ConfigError naming the key, the value and the choices)."""
    if isinstance(algorithm, bool) or not isinstance(algorithm, int) or algorithm not in TRIANGLE_ALGORITHMS:
        choices = ", ".join(f"{k} ({v})" for k, v in TRIANGLE_ALGORITHMS.items())
        raise ConfigError(f"{key} = {algorithm!r}: expected a gmsh triangle algorithm, one of {choices}")
    return algorithm


def set_size_options(gmsh, algorithm: int, size_max_m: float) -> None:
    """gmsh's 2-D algorithm and every size option (they persist across models, so all are set
    each time): no minimum, ``size_max_m`` as the maximum (a constant size, or 1e22 under a size
    callback), and no size from the points, the boundary's pieces or the curvature: the size
    is the target alone (docs/remeshing.md §7.1)."""
    opt = gmsh.option
    opt.setNumber("Mesh.Algorithm", algorithm)
    opt.setNumber("Mesh.MeshSizeMin", 0.0)
    opt.setNumber("Mesh.MeshSizeMax", size_max_m)
    opt.setNumber("Mesh.MeshSizeFromPoints", 0)
    opt.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    opt.setNumber("Mesh.MeshSizeFromCurvature", 0)


def generate_mesh(polygon: Polygon, size, *, segments: dict | None = None,
                  exterior_tag: str = COAST, island_tag: str = COAST,
                  algorithm: int = 6) -> Mesh:
    """Mesh ``polygon`` with triangles of target size ``size``.

    Args:
        polygon: shapely Polygon (metres); holes are islands.
        size: target element size [m], a number or ``size(x, y)`` (vectorised or scalar).
        segments: ``{name: geometry}``; boundary edges lying on ``geometry``
            (within 1e-7 of the domain extent) get tag ``name``. Names ``"coast"``
            and ``"open"`` have their special meaning (see :mod:`lagice.mesh.core`).
        exterior_tag: tag of outer-boundary edges not on any segment.
        island_tag: tag of island-boundary edges not on any segment.
        algorithm: gmsh 2-D algorithm (:data:`TRIANGLE_ALGORITHMS`). 6 = Frontal-Delaunay
            gives near-equilateral triangles on one lattice over the whole domain (most
            edges within three 15° bins 60° apart); 5 = Delaunay gives near-equilateral
            triangles with no domain-wide lattice direction (docs/physics.md §3).

    Raises:
        MeshError: invalid polygon or gmsh failure; ConfigError: invalid size.
    """
    check_mesh_algorithm(algorithm)
    polygon = validate_polygon(polygon)
    size_v = validate_size(size, polygon)
    segments = dict(segments or {})
    for name, geom in segments.items():
        if not isinstance(name, str) or not name:
            raise ConfigError(f"segment names must be non-empty strings; got {name!r}")
        if not hasattr(geom, "geom_type"):
            raise ConfigError(f"segment {name!r} must be a shapely geometry; got {type(geom).__name__}")
        if polygon.boundary.distance(geom) > 1e-9 * max(1.0, polygon.length):
            raise ConfigError(f"segment {name!r} does not touch the domain boundary")
        tol = 1e-7 * max(1.0, np.sqrt(polygon.area))  # the tolerance of tag_boundary_edges
        coords = np.asarray(shapely.get_coordinates(geom))
        probe = np.concatenate([coords, 0.5 * (coords[1:] + coords[:-1])]) if len(coords) > 1 else coords
        off = shapely.distance(shapely.points(probe), polygon.boundary)
        if off.max() > tol:
            k = int(np.argmax(off))
            raise ConfigError(f"segment {name!r} leaves the domain boundary: point {probe[k].tolist()} is "
                              f"{off[k]:.3g} m from it (tolerance {tol:.3g} m); give the boundary's own "
                              f"vertices, with the same coordinates")

    with gmsh_session() as gmsh:
        geo = gmsh.model.geo
        loops = []
        for ring in _rings(polygon):
            pts = [geo.addPoint(float(x), float(y), 0.0) for x, y in ring]   # sizes: set_size_options
            lines = [geo.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
            loops.append(geo.addCurveLoop(lines))
        geo.addPlaneSurface(loops)
        geo.synchronize()
        # the size comes from ``size`` alone, never from the boundary's pieces: gmsh would
        # otherwise spread the pieces it cuts a coast into (shorter than the size where the
        # coast's vertices are closer) over the whole domain (docs/remeshing.md §7.1)
        set_size_options(gmsh, algorithm, 1e22 if callable(size_v) else float(size_v))
        if callable(size_v):
            def cb(dim, tag, x, y, z, lc):
                return float(np.asarray(size_v(np.array([x]), np.array([y]))).ravel()[0])

            gmsh.model.mesh.setSizeCallback(cb)
        try:
            gmsh.model.mesh.generate(2)
        except Exception as exc:  # noqa: BLE001
            raise MeshError(f"gmsh failed to mesh the polygon: {exc}") from exc
        finally:
            if callable(size_v):
                gmsh.model.mesh.removeSizeCallback()
        tags, coords, _ = gmsh.model.mesh.getNodes()
        etypes, _, enodes = gmsh.model.mesh.getElements(2)
    if 2 not in list(etypes):
        raise MeshError("gmsh produced no triangles (domain too small for the element size?)")
    tri_tags = np.asarray(enodes[list(etypes).index(2)], dtype=np.int64).reshape(-1, 3)
    return mesh_from_arrays(np.asarray(coords).reshape(-1, 3)[:, :2], np.asarray(tags, np.int64),
                            tri_tags, polygon, segments, exterior_tag, island_tag)


def mesh_from_arrays(coords, node_tags, tri_tags, polygon, segments, exterior_tag=COAST,
                     island_tag=COAST) -> Mesh:
    """Build a :class:`Mesh` from gmsh arrays: compact node numbering, CCW, tags."""
    used = np.unique(tri_tags)
    lookup = np.full(int(max(node_tags.max(), used.max())) + 1, -1, dtype=np.int64)
    lookup[node_tags] = np.arange(len(node_tags))
    old_index = lookup[used]
    nodes = coords[old_index]
    renum = np.full(len(lookup), -1, dtype=np.int64)
    renum[used] = np.arange(len(used))
    tri = renum[tri_tags]
    neg = signed_areas(nodes, tri) < 0
    tri[neg] = tri[neg][:, [0, 2, 1]]
    edges = boundary_edges_of(tri)
    tags, names = tag_boundary_edges(nodes, edges, polygon, segments, exterior_tag, island_tag)
    return Mesh(nodes, tri, edges, tags, names)


def tag_boundary_edges(nodes, edges, polygon, segments, exterior_tag=COAST, island_tag=COAST):
    """Tag each boundary edge: the first segment containing both its end points
    and midpoint, else the island or exterior tag."""
    names = []
    for n in [*segments.keys(), exterior_tag, island_tag]:
        if n not in names:
            names.append(n)
    tol = 1e-7 * max(1.0, np.sqrt(polygon.area))
    mids = shapely.points(0.5 * (nodes[edges[:, 0]] + nodes[edges[:, 1]]))
    p0 = shapely.points(nodes[edges[:, 0]])
    p1 = shapely.points(nodes[edges[:, 1]])
    tags = np.full(len(edges), names.index(exterior_tag), dtype=np.int32)
    assigned = np.zeros(len(edges), dtype=bool)
    for name, geom in segments.items():
        on = ((shapely.distance(mids, geom) < tol) & (shapely.distance(p0, geom) < tol)
              & (shapely.distance(p1, geom) < tol) & ~assigned)
        if not on.any():
            d = float(shapely.distance(mids, geom).min()) if len(edges) else float("nan")
            raise ConfigError(f"segment {name!r} tags no boundary edge: no edge lies on it within {tol:.3g} m "
                              f"(nearest edge midpoint {d:.3g} m away); a segment must follow the domain "
                              f"boundary through its vertices, with the same coordinates")
        tags[on] = names.index(name)
        assigned |= on
    if len(polygon.interiors):
        holes = shapely.MultiLineString([LineString(r.coords) for r in polygon.interiors])
        on = (shapely.distance(mids, holes) < tol) & ~assigned
        tags[on] = names.index(island_tag)
    return tags, tuple(names)


def rectangle_domain(width_m: float, height_m: float, x0: float = 0.0, y0: float = 0.0):
    """A rectangle polygon and its four sides as named segments
    ``bottom, right, top, left``."""
    if not (width_m > 0 and height_m > 0):
        raise ConfigError(f"rectangle size ({width_m!r} m x {height_m!r} m) must be positive")
    x1, y1 = x0 + width_m, y0 + height_m
    poly = box(x0, y0, x1, y1)
    segs = {
        "bottom": LineString([(x0, y0), (x1, y0)]),
        "right": LineString([(x1, y0), (x1, y1)]),
        "top": LineString([(x1, y1), (x0, y1)]),
        "left": LineString([(x0, y1), (x0, y0)]),
    }
    return poly, segs
