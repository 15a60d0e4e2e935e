"""Build and run a TOML scene (see :mod:`lagice.scenes.config` for the schema).

``build_simulation(config)`` is the checkpoint *builder*: a checkpoint stores
the validated config and ``"lagice.scenes.toml_scene:build_simulation"``, so
``lagice resume CHECKPOINT`` rebuilds the same model and continues.
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import LineString, Polygon, shape

from ..errors import ConfigError, check_range
from ..mesh import generate_mesh, rectangle_domain
from ..model import Model
from ..params import MaxwellEBParams
from ..rheology import MaxwellEB, draw_cohesion
from ..schedule import parse_duration
from ..simulation import Simulation
from ..solvers import VelocityBC
from ..state import IceState
from . import components
from .config import load_scene, spatial_values, time_space_callable

BUILDER = "lagice.scenes.toml_scene:build_simulation"


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
        if not d["file"]:
            raise ConfigError("domain.file is required for a file domain (GeoJSON polygon in metres)")
        p = Path(d["file"])
        if not p.is_absolute() and not p.exists():
            p = Path(__file__).resolve().parents[2] / d["file"]
        if not p.exists():
            raise ConfigError(f"domain.file = {d['file']!r}: file not found")
        try:
            gj = json.loads(p.read_text())
            geom = shape(gj["features"][0]["geometry"] if "features" in gj else gj.get("geometry", gj))
        except Exception as exc:  # noqa: BLE001
            raise ConfigError(f"domain.file = {d['file']!r}: cannot read a GeoJSON polygon: {exc}") from exc
        if geom.geom_type == "MultiPolygon":
            geom = max(geom.geoms, key=lambda g: g.area)
        poly, sides = geom, {}
    else:
        raise ConfigError(f"domain.kind = {kind!r}: expected 'rectangle', 'polygon' or 'file'")
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
    if isinstance(res, str):
        size = lambda x, y: spatial_values(res, np.atleast_1d(x), np.atleast_1d(y), "domain.resolution_m")  # noqa: E731
    else:
        size = res
    return poly, segs, d["exterior_tag"], size


def validate_components(cfg: dict) -> None:
    """Cheap checks of everything before any mesh work."""
    MaxwellEBParams(**{k: v for k, v in cfg["rheology"].items() if v is not None or k == "young_modulus_pa"})
    if cfg["run"]["duration"] is None:
        raise ConfigError("run.duration is required (e.g. '28d')")
    parse_duration(cfg["run"]["duration"], "run.duration")
    if cfg["solver"]["dt"] is None:
        raise ConfigError("solver.dt is required (e.g. '10min' or seconds)")
    parse_duration(cfg["solver"]["dt"], "solver.dt")
    parse_duration(cfg["output"]["every"], "output.every")
    if cfg["checkpoint"]["every"] is not None:
        parse_duration(cfg["checkpoint"]["every"], "checkpoint.every")
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
    for key, val in cfg["initial"].items():
        if val is not None and not (key == "cohesion_pa" and val == "random"):
            spatial_values(val, *probe, f"initial.{key}")
    solver_options(cfg["solver"])
    components.validate(cfg)


def build_model(cfg: dict) -> Model:
    validate_components(cfg)
    poly, segs, ext_tag, size = build_domain(cfg["domain"])
    mesh = generate_mesh(poly, size, segments=segs, exterior_tag=ext_tag)
    for tag in cfg["boundary"]:
        mesh.tag_id(tag)  # unknown boundary tag -> ConfigError naming it
    rng = np.random.default_rng(cfg["run"]["seed"])
    rp = {k: v for k, v in cfg["rheology"].items()}
    rheo = MaxwellEB(MaxwellEBParams(**rp))
    c = mesh.centroids()
    x, y = c[:, 0], c[:, 1]
    ini = cfg["initial"]
    coh = ini["cohesion_pa"]
    cohesion = (draw_cohesion(mesh.n_elements, rheo.params, rng) if coh == "random"
                else spatial_values(coh, x, y, "initial.cohesion_pa"))
    state = IceState.uniform(
        mesh, thickness_m=spatial_values(ini["thickness_m"], x, y, "initial.thickness_m"),
        concentration=spatial_values(ini["concentration"], x, y, "initial.concentration"),
        damage=spatial_values(ini["damage"], x, y, "initial.damage"), cohesion_pa=cohesion)
    if ini["snow_m"] is not None:
        state.snow = spatial_values(ini["snow_m"], x, y, "initial.snow_m")
    bcs = []
    for tag, bc in cfg["boundary"].items():
        kw = {comp: (time_space_callable(bc[comp], f"boundary.{tag}.{comp}") if isinstance(bc[comp], str)
                     else bc[comp]) for comp in ("u", "v")}
        bcs.append(VelocityBC(tag, **kw))
    duration = parse_duration(cfg["run"]["duration"], "run.duration")
    parts = components.build(cfg, mesh, state, rheo, duration)
    sv = cfg["solver"]
    opts = solver_options(sv)
    return Model(state, rheology=rheo, solver=sv["name"], solver_options=opts, bcs=bcs,
                 forces=parts["forces"], thermo=parts["thermo"], healing=parts["healing"],
                 mover=parts["mover"], remesher=parts["remesher"], drifters=build_drifters(cfg, poly),
                 config=cfg, rng=rng)


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


def solver_options(sv: dict) -> dict:
    """The [solver] options the named solver's constructor accepts; a set option
    it does not accept is an error naming it."""
    import inspect

    from ..solvers import SOLVERS

    if sv["name"] not in SOLVERS:
        raise ConfigError(f"solver.name = {sv['name']!r}: expected one of {sorted(SOLVERS)}")
    accepted = set(inspect.signature(SOLVERS[sv["name"]].__init__).parameters)
    opts = {}
    for k in ("linear_solver", "tol", "max_iter", "substeps", "allow_unstable"):
        if sv[k] is None or (k == "allow_unstable" and sv[k] is False):
            continue
        if k not in accepted:
            raise ConfigError(f"solver.{k} does not apply to solver {sv['name']!r}")
        opts[k] = sv[k]
    return opts


def build_simulation(cfg: dict, out_dir=None, progress: bool | None = None) -> Simulation:
    """Model + Simulation with output and checkpoint schedules from the config."""
    model = build_model(cfg)
    prog = cfg["run"]["progress"] if progress is None else progress
    sim = Simulation(model, dt=cfg["solver"]["dt"], stop=cfg["run"]["duration"], progress=prog, builder=BUILDER)
    out = Path(out_dir or cfg.get("_out_dir") or Path("runs") / cfg["scene"]["name"])
    cfg["_out_dir"] = str(out)
    sim.out_dir = out
    sim.output(cfg["output"]["every"], out / "snapshots", crs_epsg=cfg["output"]["crs_epsg"],
               vtu=cfg["output"]["vtu"], start_date=cfg["run"]["start_date"],
               grid_resolution_m=cfg["output"]["grid_resolution_m"])
    if cfg["checkpoint"]["every"] is not None:
        sim.checkpoint(cfg["checkpoint"]["every"], out / "checkpoints", keep=cfg["checkpoint"]["keep"])
    return sim


def run_scene(name_or_path, out_dir=None, overrides=None, progress=None) -> dict:
    cfg = load_scene(name_or_path, overrides)
    if out_dir is not None:
        cfg["_out_dir"] = str(out_dir)
    sim = build_simulation(cfg, out_dir, progress)
    return finish(sim)


def finish(sim: Simulation) -> dict:
    """Run a (new or resumed) simulation to its end, then write summary and plots."""
    t0 = time.perf_counter()
    summary = sim.run()
    out = sim.out_dir if hasattr(sim, "out_dir") else Path(sim.model.config.get("_out_dir", "."))
    out.mkdir(parents=True, exist_ok=True)
    summary["wall_s"] = time.perf_counter() - t0
    summary["scene"] = sim.model.config["scene"]["name"]
    res = {"summary": summary, "netcdf": out / "snapshots" / "index.json", "wall_s": summary["wall_s"],
           "png": None, "out_dir": out}
    if sim.model.config["output"]["plot"]:
        from ..plotting import plot_run
        dr = sim.model.drifters
        res["png"] = plot_run(out / "snapshots", out / f"{summary['scene']}.png", summary,
                              trajectories=dr.trajectories() if dr is not None else None)
    (out / "summary.json").write_text(json.dumps(summary, indent=1, default=str))
    return res
