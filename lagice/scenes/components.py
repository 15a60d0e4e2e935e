"""Optional model components built from a scene config: external forces,
thermodynamics, healing, Lagrangian mesh motion, remeshing. A component
the scene does not ask for is not built (None / empty) and costs nothing.

``[forcing.wind]``, ``[forcing.ocean]`` and ``[forcing.air_temperature]``
take ``kind`` plus the keyword arguments of the generator it names:

========================  =====================================================
wind ``kind``             generator (``forcing.synthetic``/``forcing.gridded``)
========================  =====================================================
``uniform``               ``uniform_wind(grid, t_end, **kw)``
``random``                ``random_wind(grid, t_end, seed=run.seed, **kw)``
``cyclones``              ``random_cyclones(bbox, t_end, n, seed, ...)`` +
                          ``cyclone_wind(grid, t_end, cyclones, background_m_s)``
``file``                  ``open_wind(path, **kw)`` (ERA5-like netCDF)
``expression``            ``u``, ``v``: expressions in t, x, y or module:function
``function``              ``function = "module:function"`` ``f(t, x, y, **params)
                          -> (u, v)`` with ``params`` a table (a scene hook)
========================  =====================================================

ocean ``kind``: ``rest``, ``uniform`` (u_m_s, v_m_s), ``gyre`` (max_speed_m_s,
clockwise), ``eddies`` (eddy_speed_m_s, radius_m, spacing_radii, seed), ``file``,
``expression``, ``function``. air_temperature ``kind``:
``synthetic`` (``synthetic_air_temperature`` keywords), ``constant`` (value_c),
``file``, ``expression`` (``value``).

Every keyword is checked before any mesh work: its name against the generator's
signature, its type and range against :mod:`.checks` (explicit specs, else the
generator's annotations and defaults), then the generator itself runs once on a
tiny grid so its own range checks fire early. ``file`` kinds take the scene's
CRS (``[domain] crs``) and model time 0 is ``run.start_date``: records are
aligned by their CF dates (``crs`` and ``reference_time`` are not keys of a
scene). Files are opened and checked (variables, units, dates covering the
whole run, NaN over the domain) before meshing (:func:`check_forcing_files`).

``random``/``cyclones`` winds and ``synthetic`` air temperature draw their
records over ``[0, run.duration]``, so the run length is part of their physics
and such a run cannot be extended on resume; ``horizon = "120d"`` draws them over
a fixed span instead (the run can then be extended up to it).

Mesh motion, remeshing and drifters are components of their own
(:class:`lagice.lagrangian.MeshMotion`, :class:`lagice.remesh.Remesher`,
:class:`lagice.drifters.Drifters`); this module builds them from the scene.
"""
from __future__ import annotations

import inspect

import numpy as np

from ..errors import ConfigError, ForcingError, check_range
from ..schedule import parse_duration
from . import checks
from .config import resolve_hook, time_space_callable

WIND_KINDS = ("uniform", "random", "cyclones", "climatology", "file", "expression", "function")
OCEAN_KINDS = ("rest", "uniform", "gyre", "eddies", "file", "expression", "function")
AIR_KINDS = ("synthetic", "constant", "file", "expression")
HEAL_LAWS = ("none", "constant", "thermodynamic", "fdd", "nextsim")


def time_step_s(cfg: dict) -> float:
    """The outer step [s]: ``solver.dt`` as a duration, or ``"td"`` for the damage time
    scale of the nominal element size, Δt = Δx/cs (Dansereau et al. 2016)."""
    dt = cfg["solver"]["dt"]
    if dt is None:
        raise ConfigError("solver.dt is required (e.g. '10min', seconds, or 'td' for Δx/cs)")
    if dt == "td":
        res = cfg["domain"]["resolution_m"]
        if not isinstance(res, (int, float)):
            raise ConfigError("solver.dt = 'td' needs a numeric domain.resolution_m (Δt = Δx/cs)")
        check_range("domain.resolution_m", res, 0.0, None, low_open=True, unit="m")
        check_range("rheology.shear_wave_speed", cfg["rheology"]["shear_wave_speed"], 0.0, None, low_open=True,
                    unit="m s-1")
        return float(res) / float(cfg["rheology"]["shear_wave_speed"])
    return parse_duration(dt, "solver.dt")


def _kind(table: dict, key: str, kinds) -> str:
    kind = table.get("kind")
    if kind not in kinds:
        raise ConfigError(f"forcing.{key}.kind = {kind!r}: expected one of {list(kinds)}")
    return kind


def _kwargs(table: dict, key: str, funcs, exclude=()) -> dict:
    """Keyword arguments of ``table`` (minus kind) checked against ``funcs``' signatures."""
    kw = {k: v for k, v in table.items() if k != "kind"}
    allowed = set()
    for f in funcs:
        allowed |= {n for n, p in inspect.signature(f).parameters.items()
                    if p.kind in (p.KEYWORD_ONLY, p.POSITIONAL_OR_KEYWORD)}
    allowed -= set(exclude)
    for k in kw:
        if k not in allowed:
            raise ConfigError(f"unknown key forcing.{key}.{k}; known keys: {sorted(allowed)}")
    return kw


def _generators(key: str, kind: str):
    """The generator functions whose keywords a ``[forcing.KEY]`` table of ``kind`` takes,
    and the parameters the builder fills itself."""
    from forcing import gridded
    from forcing import synthetic as syn

    if key == "wind":
        return {"uniform": ([syn.uniform_wind], ("grid", "t_end_s")),
                "random": ([syn.random_wind], ("grid", "t_end_s")),
                "cyclones": ([syn.random_cyclones, syn.cyclone_wind], ("grid", "t_end_s", "bbox", "cyclones")),
                "file": ([gridded.open_wind, gridded.open_gridded], ("variables", "quantity"))}.get(kind)
    return {"uniform": ([syn.uniform_current], ("grid",)), "gyre": ([syn.gyre_current], ("grid",)),
            "eddies": ([syn.eddy_current], ("grid",)),
            "file": ([gridded.open_ocean_current, gridded.open_gridded], ("variables", "quantity"))}.get(kind)


def _check_kwargs(t: dict, key: str, kind: str) -> None:
    gen = _generators(key, kind)
    if gen is not None:
        _kwargs({k: v for k, v in t.items() if k != "horizon"}, key, *gen)
        checks.check_keywords(f"forcing.{key}", {k: v for k, v in t.items() if k not in ("kind", "horizon")},
                              gen[0])


#: keys the builder fills for ``file`` kinds (one CRS and one date per scene)
_FILLED = {"crs": "the scene's CRS is [domain] crs", "reference_time": "model time 0 is run.start_date"}


def _generator_table(t: dict, key: str, kind: str) -> dict:
    """The keywords of a generator table: ``horizon`` (length-dependent kinds only)
    and the builder-filled keys of file kinds are refused here with a clear message."""
    for k, why in _FILLED.items():
        if kind == "file" and k in t:
            raise ConfigError(f"forcing.{key}.{k} is not a scene key: {why}")
    if "horizon" in t and (key, kind) not in _LENGTH_KINDS:
        raise ConfigError(f"forcing.{key}.horizon applies to random forcing drawn over the run "
                          f"({', '.join(f'{a}.kind = {b!r}' for a, b in _LENGTH_KINDS)}), not to kind {kind!r}")
    return {k: v for k, v in t.items() if k not in ("kind", "horizon")}


_LENGTH_KINDS = (("wind", "random"), ("wind", "cyclones"), ("air_temperature", "synthetic"))


def draw_span_s(t: dict, key: str, duration_s: float) -> float:
    """The span [s] random forcing is drawn over: ``horizon`` if set, else the run."""
    if t.get("horizon") is None:
        return duration_s
    h = parse_duration(t["horizon"], f"forcing.{key}.horizon")
    if h < duration_s - 1e-9:
        raise ConfigError(f"forcing.{key}.horizon = {t['horizon']!r} ({h:g} s) is shorter than run.duration "
                          f"({duration_s:g} s); the forcing would run out: set horizon >= run.duration")
    return h


def start_day_of_year(start_date) -> float:
    """Day of year of ``run.start_date`` (1.0 = 1 January 00:00), fractional."""
    import datetime as _dt

    d = parse_start_date(start_date)
    jan1 = _dt.datetime(d.year, 1, 1, tzinfo=d.tzinfo)
    return 1.0 + (d - jan1).total_seconds() / 86400.0


def parse_start_date(value, key: str = "run.start_date"):
    """``run.start_date`` as a datetime (ISO 8601, e.g. ``"2026-01-15 00:00:00"``)."""
    import datetime as _dt

    if not isinstance(value, str):
        raise ConfigError(f"{key} = {value!r}: expected a date string like '2026-01-15 00:00:00'")
    try:
        d = _dt.datetime.fromisoformat(value.strip())
    except ValueError:
        raise ConfigError(f"{key} = {value!r}: not a date; expected ISO 8601 like '2026-01-15 00:00:00'") from None
    if d.tzinfo is not None and d.utcoffset() != _dt.timedelta(0):
        raise ConfigError(f"{key} = {value!r}: give the date in UTC (no time-zone offset)")
    return d.replace(tzinfo=None)


def _tiny_grid():
    from forcing.records import RegularGrid

    return RegularGrid([0.0, 1.0], [0.0, 1.0])


def _dry_run(cfg: dict, key: str, kind: str, duration_s: float) -> None:
    """Run a synthetic generator once on a tiny grid so its own checks fire before meshing."""
    t = cfg["forcing"][key]
    seed = cfg["run"]["seed"]
    span = draw_span_s(t, key, duration_s)
    if key == "wind":
        build_wind(t, _tiny_grid(), (0.0, 1.0, 0.0, 1.0), span, seed)
    elif key == "ocean":
        build_ocean(t, _tiny_grid())
    else:
        build_air_temperature(t, _tiny_grid(), span, seed, start_date=cfg["run"]["start_date"])


def validate(cfg: dict, duration_s: float) -> None:
    """Checks before any mesh work: kinds, parameter names, types and ranges,
    dependencies between tables, and the synthetic generators run once on a tiny grid."""
    law = cfg["healing"]["law"]
    if law not in HEAL_LAWS:
        raise ConfigError(f"healing.law = {law!r}: expected one of {list(HEAL_LAWS)}")
    fc = cfg["forcing"]
    if law in ("thermodynamic", "fdd", "nextsim") and fc["air_temperature"] is None:
        raise ConfigError(f"healing.law = {law!r} needs [forcing.air_temperature]")
    if cfg["thermo"]["enabled"] and fc["air_temperature"] is None:
        raise ConfigError("thermo.enabled = true needs [forcing.air_temperature]")
    if cfg["remesh"]["enabled"] and not cfg["lagrangian"]["enabled"]:
        raise ConfigError("remesh.enabled = true needs lagrangian.enabled = true (a fixed mesh never distorts)")
    checks.check_value("forcing.grid_spacing_m", fc["grid_spacing_m"],
                       checks.Spec(checks.NUMBER, 0.0, None, low_open=True, unit="m"))
    for key, kinds in (("wind", WIND_KINDS), ("ocean", OCEAN_KINDS), ("air_temperature", AIR_KINDS)):
        t = fc[key]
        if t is None:
            continue
        kind = _kind(t, key, kinds)
        _generator_table(t, key, kind)
        if kind == "rest" and set(t) != {"kind"}:
            raise ConfigError(f"unknown key forcing.{key}.{sorted(set(t) - {'kind'})[0]}; kind 'rest' takes no keys")
        if kind == "function":
            _function_field(t, key)
        elif kind == "expression":
            if key == "air_temperature":
                _scalar_expr(t, key)
            else:
                _vector_expr(t, key)
        elif key == "air_temperature" and kind == "constant":
            _constant_air(t)
        elif key == "air_temperature":
            _check_air_kwargs(t, kind, cfg["run"]["start_date"])
        elif kind == "climatology":
            ckw = _climatology_kwargs(_generator_table(t, key, kind))
            _check_climatology_resolution(ckw, fc["grid_spacing_m"])
            _check_climatology_latitude(ckw, fc["coriolis"])
        else:
            _check_kwargs(t, key, kind)
        if key == "ocean" and kind == "eddies":
            from forcing.synthetic import check_eddy_resolution, eddy_current

            default = inspect.signature(eddy_current).parameters["radius_m"].default
            radius = float(_generator_table(t, key, kind).get("radius_m", default))
            if fc["grid_spacing_m"] is not None:
                check_eddy_resolution(radius, float(fc["grid_spacing_m"]), "forcing.ocean.radius_m")
        if kind in ("uniform", "random", "cyclones", "gyre", "eddies", "synthetic"):
            _dry_run(cfg, key, kind, duration_s)
    if fc["coriolis"] is not None:
        _check_coriolis(fc["coriolis"])
    if fc["drag"] is not None:
        from ..params import DragParams

        checks.check_dataclass_params("forcing.drag", DragParams, fc["drag"])
        _check_turning_hemisphere(fc)
    if cfg["thermo"]["enabled"]:
        from thermo.zero_layer import ThermoParams

        checks.check_dataclass_params("thermo.params", ThermoParams, cfg["thermo"]["params"])
    _check_healing(cfg)
    if cfg["remesh"]["enabled"]:
        _check_remesh(cfg["remesh"])
    if cfg["lagrangian"]["enabled"]:
        from ..lagrangian import MeshMotion
        MeshMotion(cfg["lagrangian"]["min_area_ratio"], cfg["lagrangian"]["max_halvings"])


#: keys of ``[healing.params]`` (law "nextsim") that, when the scene does not set them, follow the
#: model's own values: the thermodynamics' Tf, ki, ks and the rheology's c*
SHARED_HEALING_KEYS = {"freezing_point_c": "thermo", "conductivity_ice_w_m_k": "thermo",
                       "conductivity_snow_w_m_k": "thermo", "concentration_c": "rheology"}


def nextsim_healing_params(cfg: dict) -> dict:
    """``[healing.params]`` of the nextsim law, with the keys it does not set taken from the
    model it heals (:data:`SHARED_HEALING_KEYS`): the freezing point and conductivities of
    ``[thermo.params]`` (when thermodynamics is on and sets them) and the rheology's
    ``concentration_c``, so that the healing's ΔT across the ice and its e^(−c*(1−A)) are the
    model's. A key set in ``[healing.params]`` wins. Under the defaults nothing changes."""
    params = dict(cfg["healing"]["params"])
    for key, table in SHARED_HEALING_KEYS.items():
        if key in params:
            continue
        if table == "thermo" and cfg["thermo"]["enabled"] and key in cfg["thermo"]["params"]:
            params[key] = cfg["thermo"]["params"][key]
        elif table == "rheology" and cfg["rheology"].get(key) is not None:
            params[key] = cfg["rheology"][key]
    return params


def _check_turning_hemisphere(fc: dict) -> None:
    """A warning when ``forcing.drag.turning_angle_deg`` turns the ocean drag counter-clockwise
    while the Coriolis parameter is negative (Southern Hemisphere), where the Ekman turning is
    clockwise: neXtSIM's 25° is a Northern-Hemisphere value (the convention of
    :class:`lagice.forces.OceanDrag` is counter-clockwise positive everywhere)."""
    theta = (fc["drag"] or {}).get("turning_angle_deg", 0.0) or 0.0
    cor = fc["coriolis"] or {}
    f = cor.get("f_s")
    lat = cor.get("latitude_deg")
    if f is None and isinstance(lat, (int, float)):
        f = float(lat)  # the sign of f is the sign of the latitude
    if f is None and not cor:
        f = (fc["drag"] or {}).get("coriolis_f")
    if isinstance(f, (int, float)) and f < 0.0 and theta > 0.0:
        import logging

        logging.getLogger("lagice").warning(
            f"forcing.drag.turning_angle_deg = {theta:g} turns the ocean drag counter-clockwise, but the Coriolis "
            f"parameter is negative (Southern Hemisphere), where the Ekman turning is clockwise: use "
            f"turning_angle_deg = {-theta:g} (neXtSIM's 25 degrees is a Northern-Hemisphere value)")


def _check_coriolis(c: dict) -> None:
    bad = set(c) - {"latitude_deg", "f_s"}
    if bad or len(c) != 1:
        raise ConfigError("[forcing.coriolis] takes exactly one of latitude_deg or f_s "
                          f"(got keys {sorted(c)})")
    if "f_s" in c:
        checks.check_value("forcing.coriolis.f_s", c["f_s"], checks.Spec(checks.NUMBER, -2e-4, 2e-4, unit="s-1"))
    elif c["latitude_deg"] != "crs":
        if isinstance(c["latitude_deg"], str):
            raise ConfigError(f"forcing.coriolis.latitude_deg = {c['latitude_deg']!r}: expected a latitude in "
                              f"[-90, 90] deg, or 'crs' (each node's latitude from domain.crs)")
        checks.check_value("forcing.coriolis.latitude_deg", c["latitude_deg"],
                           checks.Spec(checks.NUMBER, -90.0, 90.0, unit="deg"))


def _check_healing(cfg: dict) -> None:
    law, params = cfg["healing"]["law"], cfg["healing"]["params"]
    if law == "nextsim":  # neXtSIM's temperature- and concentration-dependent healing (issue 12)
        from ..strength import check_nextsim_healing_params

        check_nextsim_healing_params(params)
        return
    if law not in ("thermodynamic", "fdd"):
        return  # "constant" and "none" read no [healing.params]: named by builder.unused_keys
    from thermo.healing import FreezingDegreeDayHealing, ThermodynamicHealing

    cls = ThermodynamicHealing if law == "thermodynamic" else FreezingDegreeDayHealing
    known = [n for n in inspect.signature(cls).parameters]
    for k in params:
        if k not in known:
            raise ConfigError(f"unknown key healing.params.{k} for healing.law = {law!r}; known keys: {sorted(known)}")
    checks.check_keywords("healing.params", params, [cls])
    checks.call_checked("healing.params", cls, **params)


def _check_remesh(rm: dict) -> None:
    from ..remesh import Remesher, remesh_if_needed
    from ..remesh.component import REMESH_OPTIONS
    from ..remesh.trigger import TriggerParams

    params = rm["params"]
    trig = {k: v for k, v in params.items() if k in TriggerParams.__dataclass_fields__}
    opts = {k: v for k, v in params.items() if k in REMESH_OPTIONS}
    checks.check_keywords("remesh.params", opts, [remesh_if_needed])
    for k, v in trig.items():
        checks.check_value(f"remesh.params.{k}", v, checks.Spec(checks.NUMBER))
    Remesher(1.0, rm["min_angle_deg"], **params)  # unknown keys and trigger ranges


def _check_climatology_latitude(kw: dict, coriolis) -> None:
    """A warning when the wind climatology's ``latitude_deg`` (its geostrophic wind's f) differs
    from a numeric ``[forcing.coriolis] latitude_deg`` (the ice's f): the wind would be built for
    another latitude than the ice drifts at."""
    from forcing.climatology import ClimatologyParams

    lat_w = float(kw.get("latitude_deg", ClimatologyParams.latitude_deg))
    lat_i = (coriolis or {}).get("latitude_deg")
    if isinstance(lat_i, (int, float)) and not isinstance(lat_i, bool) and abs(lat_i - lat_w) > 1e-9:
        import logging

        logging.getLogger("lagice").warning(
            f"forcing.wind.latitude_deg = {lat_w:g} (the climatology's geostrophic wind) differs from "
            f"forcing.coriolis.latitude_deg = {lat_i:g} (the ice's Coriolis parameter): set both to the scene's "
            f"latitude")


def _climatology_kwargs(t: dict) -> dict:
    """Keywords of a ``[forcing.wind]`` table of kind ``"climatology"``
    (:func:`forcing.climatology.climatology_wind`): ``seed``, ``interval_s`` and the
    :class:`~forcing.climatology.ClimatologyParams` fields, checked before any mesh work
    (unknown keys and out-of-range values raise ConfigError naming key, value and range)."""
    from forcing.climatology import ClimatologyParams, make_params

    from ..errors import check_range

    kw = {k: v for k, v in t.items() if k != "kind"}
    known = {"seed", "interval_s"} | set(ClimatologyParams.__dataclass_fields__)
    for k in kw:
        if k not in known:
            raise ConfigError(f"unknown key forcing.wind.{k} for kind 'climatology'; known keys: {sorted(known)}")
    if "seed" in kw and (isinstance(kw["seed"], bool) or not isinstance(kw["seed"], int)):
        raise ConfigError(f"forcing.wind.seed = {kw['seed']!r}: expected an integer")
    if "interval_s" in kw:
        check_range("forcing.wind.interval_s", kw["interval_s"], 0.0, 86400.0, low_open=True, unit="s")
    try:
        make_params(**{k: v for k, v in kw.items() if k not in ("seed", "interval_s")})
    except (ConfigError, TypeError) as exc:
        raise ConfigError(f"forcing.wind (kind 'climatology'): {exc}") from None
    return kw


#: fewest record-grid points per wavelength of the shortest climatology wind wave: on
#: coarser records bilinear interpolation puts kinks in the wind stress along the grid
#: rows and columns (docs/physics.md §4)
CLIMATOLOGY_POINTS_PER_WAVE = 8


def _check_climatology_resolution(kw: dict, grid_spacing_m: float) -> None:
    """The forcing grid must resolve the shortest wave of the climatology's background
    (exponential spectrum): ``forcing.grid_spacing_m`` ≤ ``shortest_wavelength_m`` / 8."""
    from forcing.climatology import make_params

    p = make_params(**{k: v for k, v in kw.items() if k not in ("seed", "interval_s", "kind")})
    if p.background_spectrum != "exponential" or p.background_wind_std_m_s == 0.0:
        return
    limit = p.shortest_wavelength_m / CLIMATOLOGY_POINTS_PER_WAVE
    if grid_spacing_m > limit:
        raise ConfigError(
            f"forcing.grid_spacing_m = {grid_spacing_m:g} m is too coarse for the wind climatology: its shortest "
            f"wave (forcing.wind.shortest_wavelength_m = {p.shortest_wavelength_m:g} m) needs records at most "
            f"{limit:g} m apart ({CLIMATOLOGY_POINTS_PER_WAVE} points per wave); lower grid_spacing_m or raise "
            f"shortest_wavelength_m")


def _constant_air(t: dict) -> None:
    if set(t) - {"kind", "value_c"}:
        raise ConfigError(f"unknown key forcing.air_temperature.{sorted(set(t) - {'kind', 'value_c'})[0]}; "
                          f"known keys: ['value_c']")
    if "value_c" in t:
        checks.check_value("forcing.air_temperature.value_c", t["value_c"], checks.SPECS["value_c"])


def _scalar_expr(t: dict, key: str):
    for k in t:
        if k not in ("kind", "value"):
            raise ConfigError(f"unknown key forcing.{key}.{k}; known keys: ['value']")
    return time_space_callable(t.get("value", -20.0), f"forcing.{key}.value")


def _check_air_kwargs(t: dict, kind: str, start_date) -> None:
    from forcing import gridded
    from thermo.air_temperature import synthetic_air_temperature

    if kind == "synthetic":
        funcs, filled = [synthetic_air_temperature], ("grid", "t_end_s")
    else:
        funcs, filled = [gridded.open_air_temperature, gridded.open_gridded], ("variables", "quantity")
    kw = _kwargs({k: v for k, v in t.items() if k != "horizon"}, "air_temperature", funcs, filled)
    checks.check_keywords("forcing.air_temperature", kw, funcs)
    if kind == "synthetic" and "start_day_of_year" in kw:
        want = start_day_of_year(start_date)
        if abs(float(kw["start_day_of_year"]) - want) > 1e-6:
            raise ConfigError(f"forcing.air_temperature.start_day_of_year = {kw['start_day_of_year']!r} disagrees "
                              f"with run.start_date = {start_date!r} (day {want:g} of the year); leave it out "
                              f"(it follows run.start_date) or change run.start_date")


def _grid(mesh, spacing):
    from forcing.records import RegularGrid

    x0, y0 = mesh.nodes.min(axis=0)
    x1, y1 = mesh.nodes.max(axis=0)
    return RegularGrid.from_bbox(x0, x1, y0, y1, spacing, margin_m=max(4 * spacing, 0.2 * max(x1 - x0, y1 - y0)))


def _vector_expr(t, key):
    fu = time_space_callable(t.get("u", 0.0), f"forcing.{key}.u")
    fv = time_space_callable(t.get("v", 0.0), f"forcing.{key}.v")
    for k in t:
        if k not in ("kind", "u", "v"):
            raise ConfigError(f"unknown key forcing.{key}.{k}; known keys: ['u', 'v']")
    return lambda tt, x, y: (fu(tt, x, y), fv(tt, x, y))


def _function_field(t, key):
    """A ``kind = "function"`` field: ``function`` names ``f(t, x, y, **params)``."""
    for k in t:
        if k not in ("kind", "function", "params"):
            raise ConfigError(f"unknown key forcing.{key}.{k}; known keys: ['function', 'params']")
    if "function" not in t:
        raise ConfigError(f"forcing.{key}.kind = 'function' needs forcing.{key}.function = 'module:function'")
    return resolve_hook(t["function"], f"forcing.{key}.function", t.get("params"))


def _file_kw(t: dict, key: str, funcs, crs, start_date) -> dict:
    kw = _kwargs(_generator_table(t, key, "file"), key, funcs, ("variables", "quantity"))
    path = kw.get("path")
    if isinstance(path, str):
        from pathlib import Path

        from .config import ROOT

        p = Path(path)
        if not p.is_absolute() and not p.exists() and (ROOT / p).exists():
            kw["path"] = str(ROOT / p)
    kw["crs"] = crs
    kw["reference_time"] = None if start_date is None else parse_start_date(start_date).isoformat()
    return kw


def build_wind(t: dict, grid, bbox, t_end, seed, crs="EPSG:3413", start_date=None):
    from forcing import gridded
    from forcing import synthetic as syn

    kind = _kind(t, "wind", WIND_KINDS)
    tt = _generator_table(t, "wind", kind)
    if kind == "uniform":
        return syn.uniform_wind(grid, t_end, **_kwargs(tt, "wind", [syn.uniform_wind], ("grid", "t_end_s")))
    if kind == "random":
        kw = _kwargs(tt, "wind", [syn.random_wind], ("grid", "t_end_s"))
        kw.setdefault("seed", seed)
        return syn.random_wind(grid, t_end, **kw)
    if kind == "cyclones":
        kw = _kwargs(tt, "wind", [syn.random_cyclones, syn.cyclone_wind], ("grid", "t_end_s", "bbox", "cyclones"))
        n = kw.pop("n", 4)
        cseed = kw.pop("seed", seed)
        wkw = {k: kw.pop(k) for k in list(kw) if k in inspect.signature(syn.cyclone_wind).parameters}
        cyclones = syn.random_cyclones(bbox, t_end, n, seed=cseed, **kw)
        return syn.cyclone_wind(grid, t_end, cyclones, **wkw)
    if kind == "climatology":  # winter wind climatology (issue 12, docs/physics.md §1)
        from forcing.climatology import climatology_wind

        kw = _climatology_kwargs(tt)
        kw.setdefault("seed", seed)
        return climatology_wind(grid, t_end, domain_bbox=bbox, **kw)
    if kind == "file":
        return gridded.open_wind(**_file_kw(t, "wind", [gridded.open_wind, gridded.open_gridded], crs, start_date))
    if kind == "function":
        return _function_field(t, "wind")
    return _vector_expr(t, "wind")


def build_ocean(t: dict, grid, crs="EPSG:3413", start_date=None):
    from forcing import gridded
    from forcing import synthetic as syn

    kind = _kind(t, "ocean", OCEAN_KINDS)
    if kind == "rest":
        return None
    if kind == "uniform":
        kw = _kwargs(t, "ocean", [syn.uniform_current], ("grid",))
        return syn.uniform_current(grid, **kw)
    if kind == "gyre":
        return syn.gyre_current(grid, **_kwargs(t, "ocean", [syn.gyre_current], ("grid",)))
    if kind == "eddies":
        return syn.eddy_current(grid, **_kwargs(t, "ocean", [syn.eddy_current], ("grid",)))
    if kind == "file":
        return gridded.open_ocean_current(**_file_kw(t, "ocean", [gridded.open_ocean_current, gridded.open_gridded],
                                                     crs, start_date))
    if kind == "function":
        return _function_field(t, "ocean")
    return _vector_expr(t, "ocean")


def build_air_temperature(t: dict, grid, t_end, seed, crs="EPSG:3413", start_date=None):
    from forcing import gridded
    from thermo.air_temperature import synthetic_air_temperature

    kind = _kind(t, "air_temperature", AIR_KINDS)
    if kind == "synthetic":
        kw = _kwargs(_generator_table(t, "air_temperature", kind), "air_temperature", [synthetic_air_temperature],
                     ("grid", "t_end_s"))
        kw.setdefault("seed", seed)
        if start_date is not None:
            kw.setdefault("start_day_of_year", start_day_of_year(start_date))
        return synthetic_air_temperature(grid, t_end, **kw)
    if kind == "constant":
        _constant_air(t)
        return float(t.get("value_c", -20.0))
    if kind == "file":
        return gridded.open_air_temperature(**_file_kw(t, "air_temperature",
                                                       [gridded.open_air_temperature, gridded.open_gridded],
                                                       crs, start_date))
    return _scalar_expr(t, "air_temperature")


def check_forcing_files(cfg: dict, points_xy, duration_s: float) -> None:
    """Open every ``file`` forcing and check it before meshing: variables, units,
    plausible values, the file's CF dates covering the whole run
    (``run.start_date`` .. + ``run.duration``; ``time_extrapolation = "hold"`` opts
    in to holding the first/last record) and no NaN over the domain
    (``points_xy``: points spanning the domain polygon, in the scene CRS)."""

    fc = cfg["forcing"]
    crs, start = cfg["domain"]["crs"], cfg["run"]["start_date"]
    builders = {"wind": lambda t: build_wind(t, None, None, duration_s, 0, crs, start),
                "ocean": lambda t: build_ocean(t, None, crs, start),
                "air_temperature": lambda t: build_air_temperature(t, None, duration_s, 0, crs, start)}
    t0 = np.datetime64(parse_start_date(start), "ns")
    t1 = t0 + np.timedelta64(int(round(duration_s * 1e9)), "ns")
    for key, build_field in builders.items():
        t = fc[key]
        if t is None or t.get("kind") != "file":
            continue
        field = build_field(t)
        src = field.source
        times = src.record_times
        if field.time_extrapolation == "error" and times.size > 1 and (t0 < times[0] or t1 > times[-1]):
            raise ForcingError(
                f"forcing.{key}.path = {t.get('path')!r}: the file's records cover {str(times[0])[:16]} .. "
                f"{str(times[-1])[:16]} but the run covers {str(t0)[:16]} .. {str(t1)[:16]} (run.start_date + "
                f"run.duration); set run.start_date inside the file's dates (records are aligned by date), "
                f"shorten the run, or set forcing.{key}.time_extrapolation = 'hold' to opt in to holding the "
                f"first/last record")
        field.prepare(0.0, duration_s, points_xy[:, 0], points_xy[:, 1])
        src.close()


def scene_wind(cfg: dict, mesh, duration_s: float, grid=None):
    """The wind field ``f(t, x, y) -> (u, v)`` [m s-1] of a scene on its initial ``mesh`` for a
    run of ``duration_s`` (None without wind): the field :func:`build` gives the model, also
    used to rebuild a finished run's wind (:func:`lagice.diagnostics.drift.run_drift_response`)."""
    fc = cfg["forcing"]
    if fc["wind"] is None:
        return None
    if grid is None:
        grid = _grid(mesh, fc["grid_spacing_m"])
    x0, y0 = mesh.nodes.min(axis=0)
    x1, y1 = mesh.nodes.max(axis=0)
    return build_wind(fc["wind"], grid, (x0, x1, y0, y1), draw_span_s(fc["wind"], "wind", duration_s),
                      cfg["run"]["seed"], cfg["domain"]["crs"], cfg["run"]["start_date"])


def build(cfg: dict, mesh, state, rheology, duration_s: float) -> dict:
    """The model's forces and optional components from the scene (None when not asked for)."""
    parts = {"forces": [], "thermo": None, "healing": None, "mover": None, "remesher": None}
    fc = cfg["forcing"]
    seed = cfg["run"]["seed"]
    crs, start = cfg["domain"]["crs"], cfg["run"]["start_date"]
    law = cfg["healing"]["law"]
    if law == "none" and hasattr(rheology.params, "healing_time_s"):
        rheology.params = rheology.params.replace(healing_time_s=None)
    need_grid = any(fc[k] is not None for k in ("wind", "ocean", "air_temperature"))
    grid = _grid(mesh, fc["grid_spacing_m"]) if need_grid else None
    t_end = duration_s
    wind = scene_wind(cfg, mesh, duration_s, grid)
    ocean = build_ocean(fc["ocean"], grid, crs, start) if fc["ocean"] is not None else None
    air = (build_air_temperature(fc["air_temperature"], grid,
                                 draw_span_s(fc["air_temperature"], "air_temperature", duration_s), seed, crs, start)
           if fc["air_temperature"] is not None else None)
    # validate coverage of every field over the run before any stepping
    from forcing.base import Forcing

    c = mesh.centroids()
    Forcing(wind=wind, ocean=ocean, air_temperature=air).prepare(0.0, t_end, mesh.nodes[:, 0], mesh.nodes[:, 1],
                                                                  c[:, 0], c[:, 1])
    if wind is not None or ocean is not None or fc["coriolis"] is not None:
        from ..forces import standard_forces
        from ..params import DragParams

        cor = fc["coriolis"] or {}
        lat = cor.get("latitude_deg")
        drag = DragParams(**(fc["drag"] or {}))
        if fc["coriolis"] is not None:  # [forcing.coriolis] sets f; drag.coriolis_f is named as unused
            import dataclasses

            drag = dataclasses.replace(drag, coriolis_f=0.0)
        parts["forces"] = standard_forces(wind=wind, current=ocean, drag=drag,
                                          coriolis_f=cor.get("f_s"), latitude_deg=None if lat == "crs" else lat)
        if lat == "crs":
            from ..forces import Coriolis

            parts["forces"].append(Coriolis(crs=crs))
    if cfg["thermo"]["enabled"]:
        from thermo.model_adapters import ThermoComponent
        from thermo.zero_layer import ThermoParams, ZeroLayerThermo

        parts["thermo"] = ThermoComponent(air, ZeroLayerThermo(ThermoParams(**cfg["thermo"]["params"])),
                                          new_ice_undamaged=cfg["thermo"]["new_ice_undamaged"])
    if law in ("thermodynamic", "fdd"):
        from thermo.healing import FreezingDegreeDayHealing, ThermodynamicHealing
        from thermo.model_adapters import HealingComponent

        cls = ThermodynamicHealing if law == "thermodynamic" else FreezingDegreeDayHealing
        try:
            h = cls(**cfg["healing"]["params"])
        except TypeError as exc:
            raise ConfigError(f"[healing.params] for law {law!r}: {exc}") from None
        parts["healing"] = HealingComponent(h, air, dt_s=time_step_s(cfg))
    if law == "nextsim":
        from ..strength import NextsimHealing, NextsimHealingComponent

        parts["healing"] = NextsimHealingComponent(NextsimHealing(air, **nextsim_healing_params(cfg)))
    if cfg["lagrangian"]["enabled"]:
        from ..lagrangian import MeshMotion

        lg = cfg["lagrangian"]
        parts["mover"] = MeshMotion(lg["min_area_ratio"], lg["max_halvings"])
    if cfg["remesh"]["enabled"]:
        parts["remesher"] = build_remesher(cfg)
    return parts


def build_remesher(cfg):
    from ..remesh import Remesher
    from .config import resolution_size_field

    size = resolution_size_field(cfg["domain"]["resolution_m"])
    return Remesher(size, cfg["remesh"]["min_angle_deg"], renumber=cfg["domain"]["renumber"],
                    **cfg["remesh"]["params"])
