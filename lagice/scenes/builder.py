"""Build and run a scene (see :mod:`lagice.scenes.config` for the schema).

``build_simulation(config, out_dir)`` is the checkpoint *builder*: a checkpoint
stores the validated config and ``"lagice.scenes.builder:build_simulation"``, so
``lagice resume CHECKPOINT`` rebuilds the same model and continues. Every scene
(bundled or a user's TOML file) and every benchmark goes through this builder and
:class:`~lagice.simulation.Simulation`: there is no other time loop.
"""
from __future__ import annotations

import json
import logging
import math
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import LineString, Polygon, shape

from ..errors import ConfigError, LagiceError, check_range
from ..mesh import generate_mesh, rectangle_domain, renumber_for_locality, rotate_mesh
from ..model import Model
from ..params import DragParams, MaxwellEBParams
from ..rheology import MaxwellEB, ViscousPlastic, ViscousPlasticParams, draw_cohesion
from ..schedule import parse_duration, parse_schedule
from ..simulation import Simulation
from ..solvers import SOLVER_RHEOLOGY, SOLVERS, VelocityBC
from ..spinup import check_footprint, field_from_spinup, load_state_file
from ..state import IceState
from . import components
from .components import time_step_s  # noqa: F401 - part of the builder API
from .config import (
    RHEOLOGY_KEYS,
    ROOT,
    SCHEMA,
    load_scene,
    override_config,
    physics_view,
    resolution_size_field,
    resolve_hook,
    spatial_values,
    time_space_callable,
)

BUILDER = "lagice.scenes.builder:build_simulation"


# -- domain ------------------------------------------------------------------------
def build_domain(d: dict):
    """(polygon, segments {tag: geometry}, exterior_tag, size) from [domain]."""
    kind = d["kind"]
    segs = {}
    if kind == "rectangle":
        for k in ("width_m", "height_m"):
            if d[k] is None:
                raise ConfigError(f"domain.{k} is required for a rectangle domain")
            check_range(f"domain.{k}", d[k], 0.0, None, low_open=True, unit="m")
        poly, sides = rectangle_domain(d["width_m"], d["height_m"], d["x0_m"], d["y0_m"])
    elif kind == "polygon":
        if not d["vertices"]:
            raise ConfigError("domain.vertices is required for a polygon domain ([[x, y], ...] in m)")
        try:
            poly = Polygon(d["vertices"], d["islands"])
        except (ValueError, TypeError) as exc:
            raise ConfigError(f"domain.vertices/islands: not a polygon: {exc}") from exc
        sides = {}
    elif kind == "file":
        poly, sides = _file_polygon(d), {}
    elif kind == "function":
        if not d["function"]:
            raise ConfigError("domain.function = 'module:function' is required for a function domain")
        res = resolve_hook(d["function"], "domain.function", d["params"])()
        poly, sides = (res if isinstance(res, tuple) else (res, {}))
        if not isinstance(poly, Polygon):
            raise ConfigError(f"domain.function = {d['function']!r} returned {type(poly).__name__}; "
                              f"expected a shapely Polygon (or (polygon, sides))")
    else:
        raise ConfigError(f"domain.kind = {kind!r}: expected 'rectangle', 'polygon', 'file' or 'function'")
    for tag, spec in d["segments"].items():
        if isinstance(spec, str):
            if spec not in sides:
                raise ConfigError(f"domain.segments.{tag} = {spec!r}: expected one of {sorted(sides)} "
                                  "or a list of [x, y] points")
            segs[tag] = sides[spec]
        elif isinstance(spec, list):
            try:
                segs[tag] = LineString(spec)
            except (ValueError, TypeError) as exc:
                raise ConfigError(f"domain.segments.{tag}: not a line: {exc}") from exc
        else:
            raise ConfigError(f"domain.segments.{tag} = {spec!r}: expected a side name or [[x, y], ...]")
    if d["resolution_m"] is None:
        raise ConfigError("domain.resolution_m is required (target element size in m, or an expression in x, y)")
    res = d["resolution_m"]
    if not isinstance(res, str):
        check_range("domain.resolution_m", res, 0.0, None, low_open=True, unit="m")
    return poly, segs, d["exterior_tag"], resolution_size_field(res)



def _geojson_crs(gj: dict) -> str | None:
    """The CRS a GeoJSON file declares: the (pre-RFC 7946) ``crs`` member, or a
    ``crs`` property of its first feature; None when it declares none."""
    c = gj.get("crs")
    if isinstance(c, dict):
        name = (c.get("properties") or {}).get("name")
        if name:
            return str(name)
    feats = gj.get("features") or []
    if feats and isinstance(feats[0], dict):
        val = (feats[0].get("properties") or {}).get("crs")
        if isinstance(val, str):
            return val
    return None


def _read_shapefile(p: Path, key: str):
    """The largest polygon of a shapefile (pyshp) and its CRS (the ``.prj`` WKT, or None)."""
    import shapefile
    from shapely.ops import unary_union

    try:
        with shapefile.Reader(str(p)) as r:
            geoms = [shape(s.__geo_interface__) for s in r.shapes() if s.shapeType in (5, 15, 25)]
    except Exception as exc:  # noqa: BLE001 - any reader failure is a bad file
        raise ConfigError(f"{key}: cannot read the shapefile: {exc}") from exc
    if not geoms:
        raise ConfigError(f"{key}: the shapefile holds no polygon")
    geom = unary_union(geoms) if len(geoms) > 1 else geoms[0]
    prj = p.with_suffix(".prj")
    return geom, (prj.read_text().strip() if prj.exists() else None)


def _file_polygon(d: dict):
    """The domain polygon of a GeoJSON file or a shapefile (``.shp``, read with pyshp),
    in the scene CRS (``domain.crs``); the largest polygon when there are several.

    The file's CRS is ``domain.file_crs``, else the one the file declares (a GeoJSON
    ``crs`` member, a shapefile's ``.prj``), else the scene CRS. A file in another
    CRS (e.g. lon/lat, ``EPSG:4326``) is projected; a file read in a metric CRS
    whose coordinates look like degrees is an error."""
    from ..crs import check_not_degrees, model_crs, parse_crs, project_geometry

    if not d["file"]:
        raise ConfigError("domain.file is required for a file domain (GeoJSON polygon or shapefile)")
    p = Path(d["file"])
    if not p.is_absolute() and not p.exists():
        p = ROOT / d["file"]
    if not p.exists():
        raise ConfigError(f"domain.file = {d['file']!r}: file not found")
    key = f"domain.file = {d['file']!r}"
    if p.suffix.lower() == ".shp":
        geom, file_crs = _read_shapefile(p, key)
    else:
        try:
            gj = json.loads(p.read_text())
            geom = shape(gj["features"][0]["geometry"] if "features" in gj else gj.get("geometry", gj))
        except Exception as exc:  # noqa: BLE001
            raise ConfigError(f"{key}: cannot read a GeoJSON polygon: {exc}") from exc
        file_crs = _geojson_crs(gj)
    if geom.geom_type == "MultiPolygon":
        geom = max(geom.geoms, key=lambda g: g.area)
    if geom.geom_type != "Polygon":
        raise ConfigError(f"{key}: the geometry is a {geom.geom_type}; expected a Polygon")
    target = model_crs(d["crs"], "domain.crs")
    declared = d["file_crs"] or file_crs
    if declared is None:
        check_not_degrees(geom.bounds, key, f"domain.crs = {d['crs']!r}")
        return geom
    src = parse_crs(declared, "domain.file_crs" if d["file_crs"] else f"{key} (its crs)")
    if src.is_projected:
        check_not_degrees(geom.bounds, key, f"its CRS {declared!r}")
    if src == target:
        return geom
    try:
        out = project_geometry(geom, src, target)
    except Exception as exc:  # noqa: BLE001
        raise ConfigError(f"{key}: cannot project from {declared!r} to domain.crs = {d['crs']!r}: {exc}") from exc
    if not out.is_valid or not np.all(np.isfinite(np.asarray(out.exterior.coords))):
        raise ConfigError(f"{key}: projected from {declared!r} to domain.crs = {d['crs']!r} it is not a valid "
                          f"polygon (does the domain.crs cover the region?)")
    return out


def domain_polygon(cfg: dict):
    """The domain polygon in the scene CRS, as the mesh will cover it (rotated as asked)."""
    d = cfg["domain"]
    poly = build_domain(d)[0]
    if d["rotate_deg"]:
        poly = shapely.affinity.rotate(poly, d["rotate_deg"], origin=poly.centroid)
    return poly


def _domain_points(poly, n: int = 30) -> np.ndarray:
    """Points spanning a polygon (its vertices and an n x n grid over its bounding box)."""
    x0, y0, x1, y1 = poly.bounds
    gx, gy = np.meshgrid(np.linspace(x0, x1, n), np.linspace(y0, y1, n))
    v = np.asarray(poly.exterior.coords)
    return np.vstack([v, np.column_stack([gx.ravel(), gy.ravel()])])


def smallest_extent_m(poly) -> float:
    """The domain's smallest extent [m]: the shorter side of its minimum rotated rectangle
    (a rectangle's width or height, whichever is smaller)."""
    r = np.asarray(poly.minimum_rotated_rectangle.exterior.coords)
    sides = np.hypot(*np.diff(r[:3], axis=0).T)
    return float(sides.min())


def check_resolution(res, poly) -> None:
    """A numeric ``domain.resolution_m`` (the target element size) must not exceed the
    domain's smallest extent (:func:`smallest_extent_m`): a mesh needs at least one element
    across the domain. ConfigError naming the key, the value and the extent in km."""
    if isinstance(res, str):
        return
    ext = smallest_extent_m(poly)
    if res > ext:
        raise ConfigError(f"domain.resolution_m = {res:g} m is larger than the domain: its smallest extent is "
                          f"{ext / 1e3:.1f} km; expected an element size of at most {ext:g} m (at least one "
                          f"element across the domain)")


def _footprint_points(poly, state_file) -> np.ndarray:
    """Points covering a polygon, to check a spin-up state's footprint before meshing: its
    boundary every state centroid spacing, and a 60 x 60 grid over its bounding box (inside)."""
    from ..spinup import FOOTPRINT_SPACINGS, footprint_tolerance_m

    step = footprint_tolerance_m(state_file) / FOOTPRINT_SPACINGS
    rings = (poly.exterior, *poly.interiors)
    bnd = [np.asarray((r.segmentize(step) if math.isfinite(step) and step > 0 else r).coords) for r in rings]
    g = _domain_points(poly, 60)
    inside = g[shapely.contains_xy(poly, g[:, 0], g[:, 1])]
    return np.vstack([*bnd, inside])


def build_mesh(cfg: dict, with_order: bool = False):
    """The scene's mesh (gmsh), renumbered and rotated as asked; also returns the polygon.

    ``domain.renumber`` (default true) renumbers nodes and elements along a Morton
    curve (:func:`lagice.mesh.renumber_for_locality`: the kernels' gathers hit nearby
    memory). ``with_order=True`` also returns the element permutation (new element k
    is gmsh's element ``order[k]``; the identity without renumbering), so that per-element
    random draws can be made in gmsh's order and stay the same with or without it."""
    d = cfg["domain"]
    poly, segs, ext_tag, size = build_domain(d)
    mesh = generate_mesh(poly, size, segments=segs, exterior_tag=ext_tag, algorithm=d["mesh_algorithm"])
    order = np.arange(mesh.n_elements)
    if d["jitter"]:  # mesh-imprint option (issue 12): break the lattice of gmsh's frontal meshes
        from ..mesh.perturb import jitter_mesh

        mesh = jitter_mesh(mesh, d["jitter"], cfg["run"]["seed"] + 104729)
    if d["renumber"]:
        mesh, _, order = renumber_for_locality(mesh)
    if d["rotate_deg"]:
        c = poly.centroid
        mesh = rotate_mesh(mesh, d["rotate_deg"], (c.x, c.y))
        poly = shapely.affinity.rotate(poly, d["rotate_deg"], origin=c)
    for tag in cfg["boundary"]:
        mesh.tag_id(tag)  # unknown boundary tag -> ConfigError naming it
    return (mesh, poly, order) if with_order else (mesh, poly)


# -- checks before any mesh work ---------------------------------------------------


def strength_law(cfg: dict):
    """The scene's strength law (:class:`lagice.strength.StrengthLaw`), or None for the
    uniform draw in [cohesion_min_pa, cohesion_max_pa] (and for rheologies without
    cohesion); keys checked (ConfigError naming key, value and range) before any mesh work."""
    from .. import strength

    law = strength.from_config(cfg["rheology"], cfg["run"]["seed"])
    # like cohesion_min/max_pa, the strength law is a Maxwell-EB key: the viscous-plastic
    # rheology (EVP comparison runs of the same scene) has no cohesion and does not use it
    return law if cfg["rheology"]["law"] == "maxwell_eb" else None


#: messages of :func:`check_other_law_keys` and :func:`check_unused_keys` already logged in this
#: process (the checks run more than once per run: the CLI, then the builder)
_LOGGED_UNUSED: set = set()


def check_other_law_keys(rp: dict) -> None:
    """Keys of ``[rheology]`` that only the other law uses, set away from their schema defaults:
    under ``maxwell_eb`` a viscous-plastic key (``p_star`` ...) is refused, since nothing would
    read it; under ``viscous_plastic`` the Maxwell-EB keys (and the strength law's) are logged
    once as not used, since the EVP comparison runs a Maxwell-EB scene file with ``law`` switched."""
    from .. import strength

    law = rp["law"]
    if law not in RHEOLOGY_KEYS:
        return
    own = set(RHEOLOGY_KEYS[law]) | ({"law"} | set(strength.RHEOLOGY_KEYS) if law == "maxwell_eb" else {"law"})
    other = [k for k in SCHEMA["rheology"] if k not in own and rp.get(k) != SCHEMA["rheology"][k][1]]
    if not other:
        return
    shown = ", ".join(f"rheology.{k} = {rp[k]!r}" for k in other)
    if law == "maxwell_eb":
        raise ConfigError(f"{shown}: rheology.law = 'maxwell_eb' does not use "
                          f"{'it' if len(other) == 1 else 'them'} (keys of the viscous-plastic law); remove "
                          f"{'it' if len(other) == 1 else 'them'}, or set rheology.law = 'viscous_plastic'")
    msg = f"rheology.law = {law!r} ignores these Maxwell-EB keys of the scene: {shown}"
    if msg not in _LOGGED_UNUSED:
        _LOGGED_UNUSED.add(msg)
        import logging

        logging.getLogger("lagice").warning(msg)


#: keys each ``domain.kind`` reads and no other kind does (``domain.file_crs``: refused
#: outside ``kind = "file"``, :func:`validate_config`)
DOMAIN_KIND_KEYS = {"rectangle": ("width_m", "height_m", "x0_m", "y0_m"), "polygon": ("vertices", "islands"),
                    "file": ("file",), "function": ("function", "params")}
#: forcing kinds whose generators sample the forcing grid (``forcing.grid_spacing_m``)
GRID_KINDS = {"wind": ("uniform", "random", "cyclones", "climatology"), "ocean": ("uniform", "gyre", "eddies"),
              "air_temperature": ("synthetic",)}
#: ``[forcing.drag]`` keys of the wind stress (read only with a ``[forcing.wind]``)
AIR_DRAG_KEYS = ("rho_air", "air_drag")
#: healing laws that read the air temperature (as thermodynamics does)
AIR_HEALING_LAWS = ("thermodynamic", "fdd", "nextsim")


def _shown(v) -> str:
    """A value as the scene file writes it (true/false, strings quoted)."""
    return str(v).lower() if isinstance(v, bool) else repr(v)


def unused_keys(cfg: dict) -> list[tuple[str, object, str]]:
    """``(key, value, why)`` of every key set away from its schema default that the run
    does not read because its component is off or another kind is chosen: remeshing off,
    mesh motion off, a healing law other than "constant" (``rheology.healing_time_s``), a
    cohesion from the strength law or from ``initial.cohesion_pa`` (``cohesion_min/max_pa``),
    no compressive term (its exponent), ``solver.parallel`` on the GPU, keys of another
    ``domain.kind``, a forcing grid no forcing kind samples, drag without the forces it
    belongs to, an air temperature nothing reads, ``[remesh.params]``, ``[thermo.params]`` and
    ``thermo.new_ice_undamaged`` with their component off, ``[healing.params]`` under a healing law
    that takes none ("constant", "none"). Keys that are refused instead (the strength-law keys
    under "uniform", keys of the other rheology law...) are checked where they are refused;
    Maxwell-EB keys under the viscous-plastic law by :func:`check_other_law_keys`."""
    out = []

    def away(table: str, key: str) -> bool:
        return cfg[table][key] != SCHEMA[table][key][1]

    def add(table: str, keys, why: str) -> None:
        out.extend((f"{table}.{k}", cfg[table][k], why) for k in keys if away(table, k))

    if not cfg["remesh"]["enabled"]:
        add("remesh", ("min_angle_deg",), "remeshing is off: remesh.enabled = false")
        if cfg["remesh"]["params"]:  # a scene's [remesh.params] with remeshing switched off by --set
            out.append(("remesh.params", cfg["remesh"]["params"], "remeshing is off: remesh.enabled = false"))
    if not cfg["thermo"]["enabled"]:
        if cfg["thermo"]["params"]:
            out.append(("thermo.params", cfg["thermo"]["params"], "thermodynamics is off: thermo.enabled = false"))
        add("thermo", ("new_ice_undamaged",), "thermodynamics is off (thermo.enabled = false): no new ice forms")
    if cfg["healing"]["law"] in ("constant", "none") and cfg["healing"]["params"]:
        law = cfg["healing"]["law"]
        out.append(("healing.params", cfg["healing"]["params"],
                    f"healing.law = {law!r} takes no parameters" + (" (it uses rheology.healing_time_s)"
                                                                      if law == "constant" else "")))
    if not cfg["lagrangian"]["enabled"]:
        add("lagrangian", ("min_area_ratio", "max_halvings"), "the mesh does not move: lagrangian.enabled = false")
    rp = cfg["rheology"]
    if rp["law"] == "maxwell_eb":  # under viscous_plastic: check_other_law_keys names them
        heal = cfg["healing"]["law"]
        if heal != "constant":
            add("rheology", ("healing_time_s",),
                "healing.law = 'none': no healing" if heal == "none" else
                f"healing.law = {heal!r} sets the healing rate; healing_time_s is the constant law's")
        coh = cfg["initial"]["cohesion_pa"]
        if rp["strength_law"] != "uniform":
            add("rheology", ("cohesion_min_pa", "cohesion_max_pa"),
                f"rheology.strength_law = {rp['strength_law']!r} gives the cohesion")
        elif coh != "random":
            add("rheology", ("cohesion_min_pa", "cohesion_max_pa"), f"initial.cohesion_pa = {coh!r} gives the cohesion")
        if not rp["max_pressure_pa"]:
            add("rheology", ("max_pressure_thickness_exponent",),
                "no compressive term: rheology.max_pressure_pa is not set")
    sv = cfg["solver"]
    if sv["device"] == "cuda" and sv["parallel"] not in (None, "auto"):
        out.append(("solver.parallel", sv["parallel"], "solver.device = 'cuda': the CPU kernels' threading does not "
                    "apply on the GPU"))
    d = cfg["domain"]
    if d["kind"] in DOMAIN_KIND_KEYS:
        for kind, keys in DOMAIN_KIND_KEYS.items():
            if kind != d["kind"]:
                add("domain", keys, f"domain.kind = {d['kind']!r}; it is a key of kind {kind!r}")
    fc = cfg["forcing"]
    if not any(isinstance(fc[k], dict) and fc[k].get("kind") in kinds for k, kinds in GRID_KINDS.items()):
        add("forcing", ("grid_spacing_m",), "no [forcing.*] table has a kind drawn on the forcing grid; expression, "
            "function, file, constant and rest are not")
    dflt = DragParams()  # [forcing.drag] keys at DragParams' defaults change nothing either way
    drag = {k: v for k, v in (fc["drag"] or {}).items() if v != getattr(dflt, k, None)}
    if drag and fc["wind"] is None and fc["ocean"] is None and fc["coriolis"] is None:
        out.extend((f"forcing.drag.{k}", v, "no external forces: no [forcing.wind], [forcing.ocean] or "
                    "[forcing.coriolis]") for k, v in drag.items())
    else:
        if fc["wind"] is None:
            out.extend((f"forcing.drag.{k}", drag[k], "no wind stress: no [forcing.wind]") for k in AIR_DRAG_KEYS
                       if k in drag)
        if "coriolis_f" in drag and fc["coriolis"] is not None:
            out.append(("forcing.drag.coriolis_f", drag["coriolis_f"],
                        "[forcing.coriolis] sets the Coriolis parameter"))
    if (fc["air_temperature"] is not None and not cfg["thermo"]["enabled"]
            and cfg["healing"]["law"] not in AIR_HEALING_LAWS):
        out.append(("forcing.air_temperature", fc["air_temperature"],
                    f"nothing reads it: thermo.enabled = false, and healing.law = {cfg['healing']['law']!r} is not "
                    f"one of the laws that do, {', '.join(map(repr, AIR_HEALING_LAWS))}"))
    return out


def check_unused_keys(cfg: dict) -> None:
    """One warning (logged once per distinct message) naming every key of :func:`unused_keys`:
    such keys are not refused, because scene files carry them legitimately when a ``--set``
    (or an ``extends``) switches their component off or picks another kind (the EVP comparison,
    tests that switch remeshing off), and because a resumed run's stored configuration may hold
    them; but nothing that is set is dropped in silence."""
    keys = unused_keys(cfg)
    if not keys:
        return
    msg = ("this run ignores these keys of the scene: "
           + "; ".join(f"{k} = {_shown(v)} ({why})" for k, v, why in keys))
    if msg not in _LOGGED_UNUSED:
        _LOGGED_UNUSED.add(msg)
        import logging

        logging.getLogger("lagice").warning(msg)


def build_rheology(cfg: dict):
    rp = cfg["rheology"]
    law = rp["law"]
    check_other_law_keys(rp)
    if law == "maxwell_eb":
        return MaxwellEB(MaxwellEBParams(**{k: rp[k] for k in RHEOLOGY_KEYS[law]}))
    if law == "viscous_plastic":
        return ViscousPlastic(ViscousPlasticParams(**{k: rp[k] for k in RHEOLOGY_KEYS[law]}))
    raise ConfigError(f"rheology.law = {law!r}: expected one of {sorted(RHEOLOGY_KEYS)}")


def validate_config(cfg: dict) -> None:
    """Every check that needs no mesh, so bad input fails before any work: keys,
    types and ranges of every table (forcing generator keywords, remesh/thermo/
    healing parameters, drifters, output and checkpoint settings), the scene CRS
    and start date, the domain geometry (polygon, coastline file projected into
    the scene CRS), drifter positions inside it, and gridded forcing files
    (variables, units, dates covering the run, NaN over the domain)."""
    from ..crs import model_crs
    from ..solvers.cuda_explicit import check_solver_device

    check_solver_device(cfg["solver"])  # [solver] device: "cuda" needs the explicit stepper and a GPU
    if cfg["run"]["duration"] is None:
        raise ConfigError("run.duration is required (e.g. '28d')")
    duration = parse_duration(cfg["run"]["duration"], "run.duration")
    model_crs(cfg["domain"]["crs"], "domain.crs")
    if cfg["domain"]["file_crs"] is not None and cfg["domain"]["kind"] != "file":
        raise ConfigError(f"domain.file_crs applies to domain.kind = 'file' only (kind is {cfg['domain']['kind']!r})")
    components.parse_start_date(cfg["run"]["start_date"])
    dt = time_step_s(cfg)
    n = duration / dt
    if abs(n - round(n)) > 1e-9 * max(1.0, n) or round(n) < 1:
        raise ConfigError(f"run.duration = {cfg['run']['duration']!r} is not a whole number (>= 1) of steps of "
                          f"solver.dt = {dt:g} s")
    check_range("run.max_speed_m_s", cfg["run"]["max_speed_m_s"], 0.0, None, low_open=True, unit="m s-1")
    check_whole_steps("output.every", cfg["output"]["every"], dt)
    check_whole_steps("checkpoint.every", cfg["checkpoint"]["every"], dt)
    if isinstance(cfg["output"]["timeseries"], dict) and "every" in cfg["output"]["timeseries"]:
        check_whole_steps("output.timeseries.every", cfg["output"]["timeseries"]["every"], dt)
    rheo = build_rheology(cfg)
    law = strength_law(cfg)
    check_state_file_strength(cfg, law)
    if law is not None and law.correlated and cfg["initial"]["cohesion_pa"] != "random":
        raise ConfigError(f"rheology.strength_correlation_m = {law.correlation_m:g} m needs the cohesion from the "
                          f"strength law, but initial.cohesion_pa = {cfg['initial']['cohesion_pa']!r}; "
                          "leave initial.cohesion_pa at 'random'")
    from ..mesh.generate import check_mesh_algorithm
    from ..mesh.perturb import check_jitter

    check_jitter(cfg["domain"]["jitter"], "domain.jitter")
    check_mesh_algorithm(cfg["domain"]["mesh_algorithm"], "domain.mesh_algorithm")
    sv = cfg["solver"]
    want = SOLVER_RHEOLOGY.get(sv["name"], "?")
    if sv["name"] in SOLVERS and want is not None and rheo.name != want:
        raise ConfigError(f"solver.name = {sv['name']!r} solves the {want} rheology, but rheology.law = "
                          f"{cfg['rheology']['law']!r}; set rheology.law = {want!r}")
    if rheo.name == "maxwell_eb" and sv["name"] in SOLVERS:
        rheo.require_stepper("explicit_cuda" if sv["name"] == "explicit" and sv["device"] != "cpu" else sv["name"])
    if sv["name"] == "evp" and cfg["healing"]["law"] not in ("none",):
        raise ConfigError(f"healing.law = {cfg['healing']['law']!r}: the viscous-plastic rheology (solver 'evp') "
                          f"has no damage to heal; set healing.law = 'none'")
    if sv["name"] == "prescribed" and cfg["healing"]["law"] != "none":
        raise ConfigError("solver 'prescribed' updates no damage: set healing.law = 'none'")
    if cfg["thermo"]["new_ice_undamaged"] and rheo.name != "maxwell_eb":
        raise ConfigError(f"thermo.new_ice_undamaged = true: rheology.law = {cfg['rheology']['law']!r} has no "
                          f"damage for new ice to dilute; leave it false")
    solver_options(cfg)
    parse_schedule(cfg["output"]["every"], "output.every")
    checkpoint_schedule(cfg)
    if isinstance(cfg["checkpoint"]["keep"], bool) or cfg["checkpoint"]["keep"] < 1:
        raise ConfigError(f"checkpoint.keep = {cfg['checkpoint']['keep']!r}: expected an integer >= 1")
    timeseries_diagnostics(cfg)
    if isinstance(cfg["output"]["plot"], str):
        resolve_hook(cfg["output"]["plot"], "output.plot")
    if cfg["output"]["grid_resolution_m"] is not None:
        check_range("output.grid_resolution_m", cfg["output"]["grid_resolution_m"], 0.0, None, low_open=True,
                    unit="m")
    dr = cfg["drifters"]
    if dr["count"] < 0:
        raise ConfigError(f"drifters.count = {dr['count']}: expected an integer >= 0")
    if dr["positions_m"] is not None:
        pos = dr["positions_m"]
        if not all(isinstance(p, list) and len(p) == 2 and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                                 and np.isfinite(v) for v in p) for p in pos):
            raise ConfigError(f"drifters.positions_m = {pos!r}: expected a list of [x, y] pairs of numbers in m")
        if dr["count"] and dr["count"] != len(pos):
            raise ConfigError(f"drifters.count = {dr['count']} and drifters.positions_m ({len(pos)} positions) "
                              f"disagree; give one of them")
    d = cfg["domain"]
    known_tags = set(d["segments"]) | {d["exterior_tag"], "coast"}
    for tag, bc in cfg["boundary"].items():
        if tag not in known_tags:
            raise ConfigError(f"[boundary.{tag}]: unknown boundary tag {tag!r}; this domain has tags "
                              f"{sorted(known_tags)} (name segments in [domain.segments])")
        for comp in ("u", "v"):
            if bc[comp] is not None:
                time_space_callable(bc[comp], f"boundary.{tag}.{comp}")
    probe = np.array([0.5 * (d.get("width_m") or 1.0)]), np.array([0.5 * (d.get("height_m") or 1.0)])
    state_fields = check_initial_state_file(cfg["initial"])
    for key, val in cfg["initial"].items():
        if val is None or (key == "cohesion_pa" and val == "random") or key == "state_file" or key in state_fields:
            continue
        if isinstance(val, (int, float)) and not isinstance(val, bool):  # a constant: its range now
            check_initial_range(key, val)
        if key == "stress_pa" and isinstance(val, str) and ":" in val:
            resolve_hook(val, "initial.stress_pa")
            continue
        spatial_values(val, *probe, f"initial.{key}")
    components.validate(cfg, duration)
    poly = domain_polygon(cfg)  # no mesh yet: the polygon only
    if not poly.is_valid or poly.area <= 0:
        raise ConfigError(f"domain: the polygon is not valid ({shapely.validation.explain_validity(poly)})")
    check_resolution(d["resolution_m"], poly)
    if state_fields:  # the spin-up state must cover the domain (its boundary and inside)
        check_footprint(cfg["initial"]["state_file"], *_footprint_points(poly, cfg["initial"]["state_file"]).T,
                        "initial.state_file", "the domain")
    if dr["positions_m"]:
        for k, p in enumerate(dr["positions_m"]):
            if not poly.contains(shapely.Point(p)):
                raise ConfigError(f"drifters.positions_m[{k}] = {p!r} lies outside the domain (bounds "
                                  f"{tuple(round(b) for b in poly.bounds)} m in domain.crs)")
    components.check_forcing_files(cfg, _domain_points(poly), duration)
    check_unused_keys(cfg)  # keys of components that are off, or of another kind: one warning


def check_whole_steps(key: str, value, dt: float) -> None:
    """An interval of simulated time (``output.every = "6h"``, not ``"N steps"`` or wall
    time) must be a whole number (>= 1) of time steps, as ``run.duration`` is: otherwise
    the activity falls due at irregular steps. ConfigError naming the key, the interval
    and solver.dt, with the nearest whole multiples."""
    from ..schedule import TimeInterval

    if value is None:
        return
    sched = parse_schedule(value, key)
    if not isinstance(sched, TimeInterval):
        return
    n = sched.interval / dt
    if abs(n - round(n)) > 1e-9 * max(1.0, n) or round(n) < 1:
        lo, hi = max(1, math.floor(n)), max(1, math.ceil(n))
        near = f"{lo * dt:g} s" + (f" or {hi * dt:g} s" if hi != lo else "")
        raise ConfigError(f"{key} = {value!r} ({sched.interval:g} s) is not a whole number (>= 1) of steps of "
                          f"solver.dt = {dt:g} s; it would fall due at irregular steps (use e.g. {near}, "
                          f"or '{lo} steps')")


def checkpoint_schedule(cfg: dict):
    """The checkpoint schedule: ``checkpoint.every`` (simulated time, steps or
    ``"wall 55min"``) and/or ``checkpoint.every_wall`` (wall-clock time, e.g.
    ``"55min"``, for batch queues); None when neither is set (a checkpoint is
    still written at the end of the run and when it is stopped)."""
    from ..schedule import AnyOf, WallTimeInterval

    ck = cfg["checkpoint"]
    every = parse_schedule(ck["every"], "checkpoint.every") if ck["every"] is not None else None
    wall = None
    if ck["every_wall"] is not None:
        w = ck["every_wall"]
        if isinstance(w, str) and w.strip().startswith("wall"):
            w = w.strip()[4:].strip()
        wall = WallTimeInterval(w, "checkpoint.every_wall")
    if every is None or wall is None:
        return every or wall
    return AnyOf(every, wall)


def timeseries_diagnostics(cfg: dict) -> dict | None:
    """``{name: ScalarDiagnostic}`` of ``[output.timeseries]`` (None when not asked for)."""
    ts = cfg["output"]["timeseries"]
    if ts is None:
        return None
    from ..io.timeseries import BUILTIN, ScalarDiagnostic

    for k in ts:
        if k not in ("every", "diagnostics"):
            raise ConfigError(f"unknown key output.timeseries.{k}; known keys: ['diagnostics', 'every']")
    if "every" not in ts:
        raise ConfigError("output.timeseries.every is required (e.g. '1h' or '1 steps')")
    parse_schedule(ts["every"], "output.timeseries.every")
    names = ts.get("diagnostics", [])
    if not isinstance(names, list) or not names:
        raise ConfigError(f"output.timeseries.diagnostics = {names!r}: expected a non-empty list of built-in "
                          f"names {sorted(BUILTIN)} or 'module:function' hooks")
    out = {}
    for n in names:
        if not isinstance(n, str):
            raise ConfigError(f"output.timeseries.diagnostics: {n!r} is not a name")
        if n in BUILTIN:
            out[n] = BUILTIN[n]
        elif ":" not in n:  # not a hook: a misspelt built-in name
            import difflib

            near = difflib.get_close_matches(n, list(BUILTIN), n=1)
            hint = f" (did you mean {near[0]!r}?)" if near else ""
            raise ConfigError(f"output.timeseries.diagnostics: unknown diagnostic {n!r}{hint}; known: "
                              f"{sorted(BUILTIN)}, or a 'module:function' hook")
        else:
            f = resolve_hook(n, "output.timeseries.diagnostics")
            out[n.partition(":")[2]] = ScalarDiagnostic(f, getattr(f, "units", "1"), getattr(f, "long_name", ""))
    return out


def solver_options(cfg: dict) -> dict:
    """The [solver] options the named stepper's constructor accepts; a set option it
    does not accept is an error naming it."""
    import inspect

    sv = cfg["solver"]
    if sv["name"] not in SOLVERS:
        raise ConfigError(f"solver.name = {sv['name']!r}: expected one of {sorted(SOLVERS)}")
    accepted = set(inspect.signature(SOLVERS[sv["name"]].__init__).parameters)
    opts = {}
    for k in ("linear_solver", "tol", "max_iter", "substeps", "allow_unstable", "safety", "parallel",
              "substep_limit", "volumetric_strain", "velocity_element", "jump_penalty", "damage_iterations",
              "damage_tol"):
        if sv[k] is None or (k == "allow_unstable" and sv[k] is False):
            continue
        if k == "parallel" and isinstance(sv[k], str):
            if sv[k] != "auto":
                raise ConfigError(f"solver.parallel = {sv[k]!r}: expected true, false or \"auto\" (measured "
                                  f"at the first step)")
            continue  # "auto" is the steppers' default (None)
        if k not in accepted:
            raise ConfigError(f"solver.{k} does not apply to solver {sv['name']!r}")
        if k == "substep_limit":
            from ..solvers.explicit import check_substep_limit

            check_substep_limit(sv[k])
            if sv["device"] != "cpu":
                from ..solvers.cuda_explicit import check_cuda_substep_limit

                check_cuda_substep_limit(sv[k], bool(cfg["rheology"]["crack_closure"]))
        if k == "velocity_element":
            from ..solvers.explicit import check_velocity_element

            check_velocity_element(sv[k])
            if sv[k] != "linear":
                if cfg["rheology"]["damage_nonlocal_radius_m"]:
                    raise ConfigError(f"solver.velocity_element = {sv[k]!r} is not implemented with "
                                      f"rheology.damage_nonlocal_radius_m; use \"linear\"")
                if sv["volumetric_strain"] not in (None, "element"):
                    raise ConfigError(f"solver.volumetric_strain = {sv['volumetric_strain']!r} averages linear "
                                      f"velocities at the nodes; with solver.velocity_element = {sv[k]!r} use "
                                      f"\"element\"")
        if k == "jump_penalty" and not sv[k] >= 0.0:
            raise ConfigError(f"solver.jump_penalty = {sv[k]!r}: expected a number >= 0 (Hansbo and Larson's penalty "
                              f"factor κ; 0: none)")
        if k == "jump_penalty" and sv[k] and sv["velocity_element"] != "crouzeix_raviart":
            raise ConfigError(f"solver.jump_penalty = {sv[k]!r} penalises the jumps of Crouzeix-Raviart velocities; "
                              f"set solver.velocity_element = \"crouzeix_raviart\" or leave it unset")
        if k == "volumetric_strain":
            from ..solvers.explicit import check_volumetric_strain

            check_volumetric_strain(sv[k])
            if cfg["rheology"]["damage_nonlocal_radius_m"] and sv[k] != "element":
                raise ConfigError(f"solver.volumetric_strain = {sv[k]!r} is not implemented with "
                                  f"rheology.damage_nonlocal_radius_m; use \"element\"")
        opts[k] = sv[k]
    if sv["velocity"] is not None or sv["velocity_params"]:
        if "velocity" not in accepted:
            raise ConfigError(f"solver.velocity applies to solver 'prescribed' only, not {sv['name']!r}")
        if sv["velocity"] is None:
            raise ConfigError("solver.velocity_params needs solver.velocity = 'module:function'")
        opts["velocity"] = resolve_hook(sv["velocity"], "solver.velocity", sv["velocity_params"])
    elif sv["name"] == "prescribed":
        raise ConfigError("solver 'prescribed' needs solver.velocity = 'module:function' (f(t, x, y) -> (u, v))")
    return opts


# -- the model -----------------------------------------------------------------------
#: initial fields a spun-up state file provides (``[initial] KEY = "from_state"``)
FROM_STATE = {"thickness_m": "thickness", "concentration": "concentration", "damage": "damage"}


def check_initial_state_file(ini: dict) -> list[str]:
    """The ``[initial]`` keys set to ``"from_state"``, after checking that they and
    ``initial.state_file`` go together and that the file holds valid fields (before any
    meshing)."""
    keys = [k for k in FROM_STATE if ini.get(k) == "from_state"]
    other = [k for k, v in ini.items() if v == "from_state" and k not in FROM_STATE]
    if other:
        raise ConfigError(f"initial.{other[0]} = 'from_state': only {sorted(FROM_STATE)} can come from "
                          f"initial.state_file")
    if keys and not ini.get("state_file"):
        raise ConfigError(f"initial.{keys[0]} = 'from_state' needs initial.state_file (a spin-up state .npz, "
                          f"`python benchmarks/physics_experiments.py spinup`)")
    if ini.get("state_file") and not keys:
        raise ConfigError(f"initial.state_file = {ini['state_file']!r} is set but no initial field uses it: set "
                          f"some of {sorted(FROM_STATE)} to 'from_state', or remove initial.state_file")
    if keys:
        load_state_file(ini["state_file"], "initial.state_file")
    return keys


def state_file_strength(cfg: dict) -> dict | None:
    """The spin-up state file's correlated strength factor ({"strength_factor": g,
    "strength_correlation_m": ℓ, "strength_correlated_amplitude": a}), or None when the
    scene reads no state file or the file has none."""
    ini = cfg["initial"]
    if not ini.get("state_file") or not any(ini.get(k) == "from_state" for k in FROM_STATE):
        return None
    fields = load_state_file(ini["state_file"], "initial.state_file")[1]
    return fields if "strength_factor" in fields else None


def check_state_file_strength(cfg: dict, law) -> None:
    """A state file made with a correlated strength factor is read only by a run with the
    same ℓ and a (its factor is then carried on; without them it would be ignored)."""
    sf = state_file_strength(cfg)
    if sf is None:
        return
    f = cfg["initial"]["state_file"]
    ell, a = sf["strength_correlation_m"], sf["strength_correlated_amplitude"]
    if law is None or not law.correlated:
        raise ConfigError(f"initial.state_file = {f!r} carries a correlated strength factor (ℓ = {ell:g} m, "
                          f"a = {a:g}) but rheology.strength_correlation_m is not set: set "
                          f"rheology.strength_correlation_m = {ell:g} and strength_correlated_amplitude = {a:g}, "
                          "or start from a state file without one")
    if not (math.isclose(law.correlation_m, ell, rel_tol=1e-9) and math.isclose(law.amplitude, a, rel_tol=1e-9)):
        raise ConfigError(f"rheology.strength_correlation_m = {law.correlation_m:g} m and "
                          f"strength_correlated_amplitude = {law.amplitude:g}, but initial.state_file = {f!r} "
                          f"carries a factor made with {ell:g} m and {a:g}; use the state file's values")


#: valid range of each ``[initial]`` field, as the state checks it (:func:`lagice.fields.validate_state`):
#: (low, high, high_open, unit)
INITIAL_RANGES = {"thickness_m": (0.0, None, False, "m"), "concentration": (0.0, 1.0, False, ""),
                  "damage": (0.0, 1.0, True, ""), "cohesion_pa": (0.0, None, False, "Pa"),
                  "snow_m": (0.0, None, False, "m"), "stress_pa": (None, None, False, "Pa")}


def check_initial_range(key: str, value) -> None:
    """ConfigError naming ``initial.KEY``, the value and the expected range, unless the
    constant ``value`` lies in :data:`INITIAL_RANGES` (and is finite)."""
    if key not in INITIAL_RANGES:
        return
    lo, hi, hi_open, unit = INITIAL_RANGES[key]
    check_range(f"initial.{key}", value, lo, hi, high_open=hi_open, unit=unit)
    if not math.isfinite(float(value)):
        raise ConfigError(f"initial.{key} = {value!r}: expected a finite number{' in ' + unit if unit else ''}")


def check_initial_values(key: str, spec, values) -> None:
    """The values of ``initial.KEY`` (= ``spec``, an expression or a hook) over the mesh's
    elements in :data:`INITIAL_RANGES`; ConfigError naming the key, the range found and the one expected."""
    if key not in INITIAL_RANGES or not np.size(values):
        return
    lo, hi, hi_open, unit = INITIAL_RANGES[key]
    v = np.asarray(values, np.float64)
    bad = ~np.isfinite(v)
    if lo is not None:
        bad |= v < lo
    if hi is not None:
        bad |= (v >= hi) if hi_open else (v > hi)
    if bad.any():
        rng = (f"[{lo:g}, " if lo is not None else "(-inf, ") + (
            "inf)" if hi is None else f"{hi:g})" if hi_open else f"{hi:g}]")
        u = f" {unit}" if unit else ""
        raise ConfigError(f"initial.{key} = {spec!r} gives values in [{np.nanmin(v):.6g}, {np.nanmax(v):.6g}]{u} "
                          f"over the mesh ({int(bad.sum())} of {v.size} elements outside); expected values in "
                          f"{rng}{u}")


def initial_state(cfg: dict, mesh, rheo, rng, order=None) -> IceState:
    """The scene's initial state on ``mesh``; ``order`` (see :func:`build_mesh`): random
    cohesion is drawn in the mesh generator's element order, then permuted, so the
    realisation does not depend on ``domain.renumber``."""
    c = mesh.centroids()
    x, y = c[:, 0], c[:, 1]
    ini = cfg["initial"]
    coh = ini["cohesion_pa"]
    law = strength_law(cfg)
    if coh == "random":
        if not isinstance(rheo, MaxwellEB):
            cohesion = np.zeros(mesh.n_elements)
        elif law is not None:  # C from each element's size and its disorder factor (issue 12)
            cohesion = law.cohesion(mesh.nodes, mesh.triangles, np.arange(mesh.n_nodes, dtype=np.int64))
        else:
            cohesion = draw_cohesion(mesh.n_elements, rheo.params, rng)
            if order is not None:
                cohesion = cohesion[order]
    else:
        cohesion = spatial_values(coh, x, y, "initial.cohesion_pa")
        check_initial_values("cohesion_pa", coh, cohesion)

    def field(key):
        if ini[key] == "from_state":
            return field_from_spinup(ini["state_file"], FROM_STATE[key], x, y)
        v = spatial_values(ini[key], x, y, f"initial.{key}")
        check_initial_values(key, ini[key], v)
        return v

    if any(ini[k] == "from_state" for k in FROM_STATE):
        check_footprint(ini["state_file"], x, y, "initial.state_file", "the mesh")
    state = IceState.uniform(mesh, thickness_m=field("thickness_m"), concentration=field("concentration"),
                             damage=field("damage"), cohesion_pa=cohesion)
    if coh == "random" and law is not None and law.correlated:  # a law only for Maxwell-EB (strength_law)
        # the correlated strength factor: the spin-up's, carried on with its ice (nearest
        # spin-up centroid, like its other fields), else laid on the ice at its start positions
        if state_file_strength(cfg) is not None:
            state.strength_factor = field_from_spinup(ini["state_file"], "strength_factor", x, y)
        else:
            state.strength_factor = law.correlated_factor(x, y)
        state.cohesion = state.cohesion * state.strength_factor
    if ini["snow_m"] is not None:
        state.snow = spatial_values(ini["snow_m"], x, y, "initial.snow_m")
        check_initial_values("snow_m", ini["snow_m"], state.snow)
    sp = ini["stress_pa"]
    if isinstance(sp, str) and ":" in sp:
        stress = np.asarray(resolve_hook(sp, "initial.stress_pa")(x, y), np.float64)
        if stress.shape != (mesh.n_elements, 3):
            raise ConfigError(f"initial.stress_pa = {sp!r} returned shape {stress.shape}; expected "
                              f"({mesh.n_elements}, 3) (σxx, σyy, σxy per element, Pa)")
        state.stress = np.ascontiguousarray(stress)
    else:  # isotropic
        s = spatial_values(sp, x, y, "initial.stress_pa")
        state.stress = np.ascontiguousarray(np.column_stack([s, s, np.zeros_like(s)]))
    state.validate()
    return state


def build_model(cfg: dict, validated: bool = False) -> Model:
    """The model of a scene (``validated``: :func:`validate_config` already ran)."""
    if not validated:
        validate_config(cfg)
    mesh, poly, order = build_mesh(cfg, with_order=True)
    rng = np.random.default_rng(cfg["run"]["seed"])
    rheo = build_rheology(cfg)
    state = initial_state(cfg, mesh, rheo, rng, order)
    bcs = []
    for tag, bc in cfg["boundary"].items():
        kw = {comp: (time_space_callable(bc[comp], f"boundary.{tag}.{comp}") if isinstance(bc[comp], str)
                     else bc[comp]) for comp in ("u", "v")}
        bcs.append(VelocityBC(tag, **kw))
    duration = parse_duration(cfg["run"]["duration"], "run.duration")
    parts = components.build(cfg, mesh, state, rheo, duration)
    law = strength_law(cfg)
    if law is not None and parts["remesher"] is not None:
        parts["remesher"].after_remesh.append(law.apply)  # new elements get the strength of their size
    opts = solver_options(cfg)
    solver = cfg["solver"]["name"]
    if cfg["solver"]["device"] == "cuda":  # the explicit stepper on the GPU (validate_config checked both)
        from ..solvers.cuda_explicit import CudaExplicitSolver

        heal = parts["healing"].rate if parts["healing"] is not None else None
        # sync="explicit": the state stays on the device; the Model brings it to the host when an
        # activity, a checkpoint or a remesh reads it (Model.needs_host_state, docs/gpu.md)
        solver = CudaExplicitSolver(rheo, mesh, bcs=bcs, forces=parts["forces"], heal_rate=heal, sync="explicit",
                                    **opts)
    model = Model(state, rheology=rheo, solver=solver, solver_options=opts, bcs=bcs,
                  forces=parts["forces"], thermo=parts["thermo"], healing=parts["healing"],
                  mover=parts["mover"], remesher=parts["remesher"], drifters=build_drifters(cfg, poly),
                  config=cfg, fingerprint_config=physics_view(cfg), rng=rng)
    model.accumulate_strain = bool(cfg["output"]["accumulate_strain"])
    if model.accumulate_strain:  # zeros from the start, so the first snapshot holds the field
        model.state.strain_accumulated = np.zeros((model.mesh.n_elements, 3))
        model.state.counters["strain_accumulated_since_s"] = float(model.clock.time_s)
    return model


def build_drifters(cfg, poly):
    """Drifters at the given positions, or ``count`` seeded random points at
    least 50 km inside the domain (None when none are asked for)."""
    from ..drifters import Drifters

    dr = cfg["drifters"]
    if dr["positions_m"]:
        return Drifters(dr["positions_m"])
    if dr["count"] <= 0:
        return None
    inner = poly.buffer(-50e3)
    if inner.is_empty:
        inner = poly
    rng = np.random.default_rng(cfg["run"]["seed"] + 7919)
    minx, miny, maxx, maxy = inner.bounds
    pts = []
    while len(pts) < dr["count"]:
        p = rng.uniform((minx, miny), (maxx, maxy))
        if inner.contains(shapely.Point(p)):
            pts.append(p)
    return Drifters(pts)


# -- the simulation ------------------------------------------------------------------
def build_simulation(cfg: dict, out_dir=None, progress: bool | None = None, overrides=None) -> Simulation:
    """Model + Simulation with the output, time-series, drifter and checkpoint
    activities of the config, writing into ``out_dir`` (default a new folder
    ``runs/SCENE-YYYYmmdd-HHMMSS``, linked as ``runs/SCENE-latest``).

    Order: every check that needs no mesh (:func:`validate_config`), then the output
    folder is created and proved writable (:func:`lagice.rundir.prepare`: a
    read-only folder fails here, before any mesh work), then the mesh and the model.
    A checkpointer is always added: it writes when ``checkpoint.every`` /
    ``checkpoint.every_wall`` are due, at the end of the run (so it can be
    extended) and when the run is stopped (SIGTERM/SIGINT). ``overrides``
    (``{"table.key": value}``) change the config first, e.g. when a checkpoint
    resumes on another device: ``Simulation.resume(path, overrides={"solver.device":
    "cuda"})`` (keys outside :data:`~lagice.scenes.config.NON_PHYSICS` change the
    fingerprint, and the resume is refused)."""
    from .. import rundir

    # validated again (with the overrides): a configuration stored in a checkpoint by an
    # earlier version gets today's defaults for the keys it lacks (Simulation.resume then
    # checks that they do what that version did)
    cfg = override_config(cfg, overrides or {})
    validate_config(cfg)
    out = rundir.new_run_dir(cfg["scene"]["name"]) if out_dir is None else Path(out_dir)
    existed, fresh = out.exists(), rundir.is_empty(out)
    rundir.prepare(out, cfg)
    try:
        sim = _simulation(cfg, out, progress)
    except LagiceError:
        if fresh:  # a new run failed its checks on the mesh: leave no folder that blocks the corrected rerun
            rundir.discard(out, remove_folder=not existed)
        raise
    if out_dir is None:
        rundir.update_latest(out, cfg["scene"]["name"])
    return sim


def _log_mesh_size(model, cfg: dict) -> None:
    """One log line: the mesh's edge lengths against ``domain.resolution_m`` (what was asked
    and what gmsh gave)."""
    from ..mesh import size_line, size_report

    res = cfg["domain"]["resolution_m"]
    target = f"domain.resolution_m = {res}" if isinstance(res, str) else f"domain.resolution_m = {res / 1e3:g} km"
    report = size_report(model.mesh.nodes, model.mesh.triangles, resolution_size_field(res))
    logging.getLogger("lagice").info(size_line(report, target))


def _simulation(cfg: dict, out: Path, progress) -> Simulation:
    """The model (mesh, initial state: the checks that need the mesh) and its
    :class:`Simulation` writing into the prepared folder ``out``."""
    model = build_model(cfg, validated=True)
    _log_mesh_size(model, cfg)
    prog = cfg["run"]["progress"] if progress is None else progress
    sim = Simulation(model, dt=time_step_s(cfg), stop=cfg["run"]["duration"], progress=prog, builder=BUILDER,
                     max_speed_m_s=cfg["run"]["max_speed_m_s"])
    sim.out_dir = out
    oc = cfg["output"]
    sim.output(oc["every"], out / "snapshots", crs=cfg["domain"]["crs"], vtu=oc["vtu"],
               start_date=cfg["run"]["start_date"], grid_resolution_m=oc["grid_resolution_m"],
               title=f"lagice {cfg['scene']['name']}: {cfg['scene']['description']}".rstrip(": "),
               drifters_path=out / "drifters.nc" if model.drifters is not None else None)
    diags = timeseries_diagnostics(cfg)
    if diags:
        sim.add_timeseries(out / "timeseries.nc", diags, oc["timeseries"]["every"], cfg["run"]["start_date"])
    sim.checkpoint(checkpoint_schedule(cfg), out / "checkpoints", keep=cfg["checkpoint"]["keep"])
    return sim


def run_scene(name_or_path, out_dir=None, overrides=None, progress=None, overwrite: bool = False) -> dict:
    """Run a scene into a new folder (or ``out_dir``: empty, or replaced with ``overwrite``),
    holding the folder's lock (:class:`lagice.rundir.RunLock`) for the whole run."""
    from .. import rundir

    cfg = load_scene(name_or_path, overrides)
    validate_config(cfg)
    default = out_dir is None
    out = rundir.make_run_dir(cfg["scene"]["name"]) if default else Path(out_dir)
    with rundir.RunLock(out, created=default):
        if not default:
            rundir.claim(out, overwrite)
        sim = build_simulation(cfg, out, progress)
        if default:
            rundir.update_latest(out, cfg["scene"]["name"])
        return finish(sim)


# -- extend and branch ---------------------------------------------------------------
#: keys a branch cannot change: the state (mesh, fields, clock) comes from the checkpoint
BRANCH_FIXED = ("domain", "initial", "solver.dt", "run.start_date")


def override_config_of(meta: dict) -> dict:
    """The configuration of a checkpoint (``meta``), with the defaults of keys added since, but
    the legacy value of a key whose default changed since (:data:`~.config.LEGACY_FILL`)."""
    from .config import override_config, with_legacy_values

    return override_config(with_legacy_values(meta["config"]), {})


def resume_simulation(checkpoint, overrides=None, progress: bool | None = None, config: dict | None = None
                      ) -> Simulation:
    """Continue the run of ``checkpoint`` (a file, or the newest usable one in a
    checkpoint or run folder) in its run folder, with ``overrides`` that leave the
    physics unchanged: ``run.duration`` (extend), ``output.*``, ``checkpoint.*``,
    ``run.progress``... Anything else is refused, naming the keys (use
    :func:`branch_simulation`). The result is bit-identical to a straight run."""
    from ..errors import RestartError
    from ..simulation import load_checkpoint
    from .config import changed_keys, length_dependent_forcing, override_config

    path, arrays, meta = load_checkpoint(checkpoint)
    old = override_config_of(meta)
    if config is not None:  # a full scene config (lagice run SCENE --out DIR --resume)
        cfg = {**config, **{k: v for k, v in old.items() if k.startswith("_")}}
    else:
        cfg = override_config(old, overrides) if overrides else old
    if cfg is not old:
        moved = changed_keys(physics_view(old), physics_view(cfg))
        if moved == ["run.duration"] and length_dependent_forcing(cfg):
            tables = ", ".join(length_dependent_forcing(cfg))
            raise RestartError(
                f"cannot extend this run: {tables} draws its random records over the whole run, so changing "
                f"run.duration would change the forcing already used. Start such runs with a fixed "
                f"{length_dependent_forcing(cfg)[0]}.horizon (e.g. '120d'; they can then be extended up to it), or "
                f"branch a new run from this checkpoint (lagice branch {path} --set run.duration=...: its forcing "
                f"is drawn anew)")
        if moved:
            raise RestartError(
                f"the settings change the physics of the run ({', '.join(moved)}); a resumed run continues the same "
                f"physics (only run.duration, output.* and checkpoint.* may change). To change it, branch a new run "
                f"from the checkpoint: lagice branch {path} --set ...")
    from ..simulation import Simulation, run_folder_of

    sim = Simulation.resume(path, config=cfg, out_dir=run_folder_of(path), progress=progress)
    return sim


def branch_config(checkpoint, meta: dict, overrides=None, sha256: str | None = None) -> dict:
    """The validated configuration of a branch from ``checkpoint`` (whose metadata is
    ``meta``) with ``overrides``: every check of :func:`branch_simulation` that needs
    no mesh (keys of :data:`BRANCH_FIXED` unchanged, a run end after the checkpoint
    time, :func:`validate_config`), and ``_parent`` = the checkpoint's path, SHA-256
    (``sha256`` when already known), step, time, scene and fingerprint. Raises
    :class:`~lagice.errors.RestartError` or :class:`~lagice.errors.ConfigError`.
    Used to check every member of an ensemble before any starts."""
    from ..errors import RestartError
    from ..io.checkpoint import file_sha256
    from .config import changed_keys, override_config

    old = override_config_of(meta)
    cfg = override_config(old, overrides)
    for key in changed_keys({k: v for k, v in old.items() if not k.startswith("_")},
                            {k: v for k, v in cfg.items() if not k.startswith("_")}):
        if any(key == f or key.startswith(f + ".") for f in BRANCH_FIXED):
            raise RestartError(f"--set {key}: a branch starts from the checkpoint's state (mesh, fields, clock), so "
                               f"{', '.join(BRANCH_FIXED)} cannot change")
    if meta["clock"]["time_s"] >= parse_duration(cfg["run"]["duration"], "run.duration") * (1 - 1e-12):
        raise RestartError(f"the checkpoint is at t = {meta['clock']['time_s']:g} s; the branch's run.duration "
                           f"= {cfg['run']['duration']!r} leaves nothing to run: set a longer run.duration")
    path = Path(checkpoint).resolve()
    cfg["_parent"] = {"checkpoint": str(path), "sha256": sha256 or file_sha256(path), "step": int(meta["step"]),
                      "time_s": float(meta["clock"]["time_s"]), "scene": old["scene"]["name"],
                      "fingerprint": meta.get("scene_fingerprint")}
    validate_config(cfg)
    return cfg


def branch_simulation(checkpoint, out_dir=None, overrides=None, progress: bool | None = None,
                      overwrite: bool = False, config: dict | None = None) -> Simulation:
    """A new run in ``out_dir`` (a new folder by default) that starts from the state of
    ``checkpoint`` with ``overrides`` (forcing, rheology, remeshing... may change; the
    fingerprint then differs: branching is explicit). Keys of :data:`BRANCH_FIXED` cannot
    change. Its outputs record the parent checkpoint (path and SHA-256: global
    attributes ``lagice_parent_checkpoint*``, ``lagice_run.json``, checkpoints).
    ``config``: the branch's configuration made earlier by :func:`branch_config` (instead
    of ``overrides``); the checkpoint file must still have the SHA-256 recorded in it."""
    from .. import rundir
    from ..errors import RestartError
    from ..io.checkpoint import file_sha256
    from ..simulation import load_checkpoint

    path, arrays, meta = load_checkpoint(checkpoint)
    path = path.resolve()
    if config is None:
        cfg = branch_config(path, meta, overrides)
    else:
        cfg = config
        parent = cfg.get("_parent") or {}
        if parent.get("checkpoint") != str(path) or parent.get("sha256") != file_sha256(path):
            raise RestartError(f"checkpoint {path} is not the parent this branch configuration was made for "
                               f"({parent.get('checkpoint')}, sha256 {parent.get('sha256')}): the file changed?")
    if out_dir is not None:
        rundir.claim(out_dir, overwrite)
    sim = build_simulation(cfg, out_dir, progress)
    fresh = sim.model.load_state(arrays, meta, fresh_components=True)
    import logging

    if fresh:
        logging.getLogger("lagice").info(f"branch: component(s) {', '.join(fresh)} start fresh (not in the parent)")
    changed = branch_strength(sim.model.state, override_config_of(meta), cfg)
    if changed:
        logging.getLogger("lagice").info(f"branch: the strength law changed ({changed}); the cohesion of every "
                                         "element is set from the branch's law at the branch point")
    if abs(meta["simulation"]["dt_s"] - sim.dt) > 1e-12 * sim.dt:  # pragma: no cover - solver.dt is fixed above
        raise RestartError("the branch's time step differs from the checkpoint's")
    sim.branched_from = {"checkpoint": str(path), "sha256": cfg["_parent"]["sha256"]}
    return sim


def branch_strength(state, parent_cfg: dict, cfg: dict) -> str:
    """Apply the branch's strength law to ``state`` (loaded from the parent's checkpoint)
    when it differs from the parent's: its keys or the run seed (the disorder's) changed.
    Otherwise the cohesion would keep the parent's values until the first remesh and then
    jump to the new law's. A correlated factor is laid on the ice at the branch point when
    the branch asks for one the parent did not have (or another ℓ or a), and dropped when
    the branch has none. Returns what changed ("" when nothing did)."""
    old, new = strength_law(parent_cfg), strength_law(cfg)
    if old == new or new is None:
        if new is None and state.strength_factor is not None:
            state.strength_factor = None  # the branch's law has no correlated factor to carry
            return "no correlated strength factor"
        return ""
    what = ", ".join(f"{k}: {getattr(old, k, None)!r} -> {getattr(new, k)!r}"
                     for k in ("lab_cohesion_pa", "lab_scale_m", "disorder", "seed", "correlation_m",
                               "correlated_amplitude") if getattr(old, k, None) != getattr(new, k))
    if new.correlated:
        same_field = (old is not None and old.correlated and old.seed == new.seed
                      and old.correlation_m == new.correlation_m and old.amplitude == new.amplitude)
        if not same_field or state.strength_factor is None:
            c = state.mesh.centroids()
            state.strength_factor = new.correlated_factor(c[:, 0], c[:, 1])
    else:
        state.strength_factor = None
    new.apply(state)
    return what


def finish(sim: Simulation, plot: bool = True) -> dict:
    """Run a (new or resumed) simulation to its end (or until it is stopped), then
    write ``summary.json`` and, when it finished, the plot. A run stopped by an error
    (a :class:`~lagice.errors.LagiceError`: a solver failure, a boundary value that is not
    finite...) also writes ``summary.json`` (``stop_reason`` "error: ...", the last
    checkpoint) before the error goes on to the caller."""
    out = Path(sim.out_dir if sim.out_dir is not None else ".")
    try:
        summary = sim.run()
    except LagiceError as exc:
        try:
            failed = sim.summary()
            failed.update(stop_reason=f"error: {exc}", error=str(exc), scene=sim.model.config["scene"]["name"])
            _write_summary(out, failed)
        except Exception as inner:  # noqa: BLE001 - the run's own error is the one to report
            import logging

            logging.getLogger("lagice").warning(f"could not write {out / 'summary.json'} after the error: {inner}")
        raise
    out.mkdir(parents=True, exist_ok=True)
    cfg = sim.model.config
    summary["scene"] = cfg["scene"]["name"]
    res = {"summary": summary, "netcdf": out / "snapshots" / "index.json", "wall_s": summary["wall_s"],
           "png": None, "out_dir": out}
    _write_summary(out, summary)
    if plot and sim.stop_reason is None:
        res["png"] = plot_scene(cfg, out, summary)
    return res


def _write_summary(out: Path, summary: dict) -> None:
    from ..io.cf import atomic_write_errors

    out.mkdir(parents=True, exist_ok=True)
    with atomic_write_errors(out / "summary.json", out / "summary.json.tmp"):
        (out / "summary.json.tmp").write_text(json.dumps(summary, indent=1, default=str))
        (out / "summary.json.tmp").replace(out / "summary.json")


def plot_scene(cfg: dict, out: Path, summary: dict | None = None, drifters=None, png_path=None):
    """The scene's own figure: ``output.plot`` true (the standard run plot), false
    (none) or a ``module:function`` hook ``f(run_dir, png_path, summary)``. Drifter
    trajectories come from the run's drifter file (``drifters.nc``) unless given. The
    figure goes to ``png_path`` (``lagice plot --png``), by default ``out/SCENE.png``."""
    spec = cfg["output"]["plot"]
    if spec is False:
        return None
    png = Path(png_path) if png_path is not None else Path(out) / f"{cfg['scene']['name']}.png"
    if isinstance(spec, str):
        return resolve_hook(spec, "output.plot")(Path(out), png, summary)
    from ..plotting import plot_run

    traj = drifters.trajectories() if drifters is not None else None
    if traj is None and (Path(out) / "drifters.nc").exists():
        from ..io.drifters import read_trajectories

        traj = read_trajectories(Path(out) / "drifters.nc")
    return plot_run(Path(out) / "snapshots", png, summary, trajectories=traj)
