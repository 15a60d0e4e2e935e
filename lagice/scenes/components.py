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
clockwise), ``file``, ``expression``, ``function``. air_temperature ``kind``:
``synthetic`` (``synthetic_air_temperature`` keywords), ``constant`` (value_c),
``file``, ``expression`` (``value``).

Mesh motion, remeshing and drifters are components of their own
(:class:`lagice.lagrangian.MeshMotion`, :class:`lagice.remesh.Remesher`,
:class:`lagice.drifters.Drifters`); this module builds them from the scene.
"""
from __future__ import annotations

import inspect

import numpy as np

from ..errors import ConfigError
from .config import resolve_hook, time_space_callable

WIND_KINDS = ("uniform", "random", "cyclones", "file", "expression", "function")
OCEAN_KINDS = ("rest", "uniform", "gyre", "file", "expression", "function")
AIR_KINDS = ("synthetic", "constant", "file", "expression")
HEAL_LAWS = ("none", "constant", "thermodynamic", "fdd")


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
            "file": ([gridded.open_ocean_current, gridded.open_gridded], ("variables", "quantity"))}.get(kind)


def _check_kwargs(t: dict, key: str, kind: str) -> None:
    gen = _generators(key, kind)
    if gen is not None:
        _kwargs(t, key, *gen)


def validate(cfg: dict) -> None:
    """Checks before any mesh work (kinds, parameter names, dependencies)."""
    law = cfg["healing"]["law"]
    if law not in HEAL_LAWS:
        raise ConfigError(f"healing.law = {law!r}: expected one of {list(HEAL_LAWS)}")
    fc = cfg["forcing"]
    if law in ("thermodynamic", "fdd") and fc["air_temperature"] is None:
        raise ConfigError(f"healing.law = {law!r} needs [forcing.air_temperature]")
    if cfg["thermo"]["enabled"] and fc["air_temperature"] is None:
        raise ConfigError("thermo.enabled = true needs [forcing.air_temperature]")
    if cfg["remesh"]["enabled"] and not cfg["lagrangian"]["enabled"]:
        raise ConfigError("remesh.enabled = true needs lagrangian.enabled = true (a fixed mesh never distorts)")
    for key, kinds in (("wind", WIND_KINDS), ("ocean", OCEAN_KINDS)):
        t = fc[key]
        if t is None:
            continue
        kind = _kind(t, key, kinds)
        if kind == "function":
            _function_field(t, key)
        elif kind == "expression":
            _vector_expr(t, key)
        else:
            _check_kwargs(t, key, kind)
    if fc["air_temperature"] is not None:
        _kind(fc["air_temperature"], "air_temperature", AIR_KINDS)
    if fc["coriolis"] is not None:
        bad = set(fc["coriolis"]) - {"latitude_deg", "f_s"}
        if bad or len(fc["coriolis"]) != 1:
            raise ConfigError("[forcing.coriolis] takes exactly one of latitude_deg or f_s "
                              f"(got keys {sorted(fc['coriolis'])})")
    if fc["drag"] is not None:
        from ..params import DragParams
        try:
            DragParams(**fc["drag"])
        except TypeError as exc:
            raise ConfigError(f"[forcing.drag]: {exc}; known keys: {sorted(DragParams.__dataclass_fields__)}") from None
    if cfg["thermo"]["enabled"]:
        from thermo.zero_layer import ThermoParams
        try:
            ThermoParams(**cfg["thermo"]["params"])
        except TypeError as exc:
            raise ConfigError(f"[thermo.params]: {exc}; known keys: "
                              f"{sorted(ThermoParams.__dataclass_fields__)}") from None
    if cfg["remesh"]["enabled"]:
        from ..remesh import Remesher
        Remesher(1.0, cfg["remesh"]["min_angle_deg"], **cfg["remesh"]["params"])
    if cfg["lagrangian"]["enabled"]:
        from ..lagrangian import MeshMotion
        MeshMotion(cfg["lagrangian"]["min_area_ratio"], cfg["lagrangian"]["max_halvings"])


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


def build_wind(t: dict, grid, bbox, t_end, seed):
    from forcing import gridded
    from forcing import synthetic as syn

    kind = _kind(t, "wind", WIND_KINDS)
    if kind == "uniform":
        return syn.uniform_wind(grid, t_end, **_kwargs(t, "wind", [syn.uniform_wind], ("grid", "t_end_s")))
    if kind == "random":
        kw = _kwargs(t, "wind", [syn.random_wind], ("grid", "t_end_s"))
        kw.setdefault("seed", seed)
        return syn.random_wind(grid, t_end, **kw)
    if kind == "cyclones":
        kw = _kwargs(t, "wind", [syn.random_cyclones, syn.cyclone_wind], ("grid", "t_end_s", "bbox", "cyclones"))
        n = kw.pop("n", 4)
        cseed = kw.pop("seed", seed)
        wkw = {k: kw.pop(k) for k in list(kw) if k in inspect.signature(syn.cyclone_wind).parameters}
        cyclones = syn.random_cyclones(bbox, t_end, n, seed=cseed, **kw)
        return syn.cyclone_wind(grid, t_end, cyclones, **wkw)
    if kind == "file":
        kw = _kwargs(t, "wind", [gridded.open_wind, gridded.open_gridded], ("variables", "quantity"))
        return gridded.open_wind(**kw)
    if kind == "function":
        return _function_field(t, "wind")
    return _vector_expr(t, "wind")


def build_ocean(t: dict, grid):
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
    if kind == "file":
        return gridded.open_ocean_current(**_kwargs(t, "ocean", [gridded.open_ocean_current, gridded.open_gridded],
                                                     ("variables", "quantity")))
    if kind == "function":
        return _function_field(t, "ocean")
    return _vector_expr(t, "ocean")


def build_air_temperature(t: dict, grid, t_end, seed):
    from forcing import gridded
    from thermo.air_temperature import synthetic_air_temperature

    kind = _kind(t, "air_temperature", AIR_KINDS)
    if kind == "synthetic":
        kw = _kwargs(t, "air_temperature", [synthetic_air_temperature], ("grid", "t_end_s"))
        kw.setdefault("seed", seed)
        return synthetic_air_temperature(grid, t_end, **kw)
    if kind == "constant":
        if set(t) - {"kind", "value_c"}:
            raise ConfigError(f"unknown key in [forcing.air_temperature]: {sorted(set(t) - {'kind', 'value_c'})}")
        return float(t.get("value_c", -20.0))
    if kind == "file":
        return gridded.open_air_temperature(**_kwargs(t, "air_temperature",
                                                      [gridded.open_air_temperature, gridded.open_gridded],
                                                      ("variables", "quantity")))
    return time_space_callable(t.get("value", -20.0), "forcing.air_temperature.value")


def build(cfg: dict, mesh, state, rheology, duration_s: float) -> dict:
    """The model's forces and optional components from the scene (None when not asked for)."""
    parts = {"forces": [], "thermo": None, "healing": None, "mover": None, "remesher": None}
    fc = cfg["forcing"]
    seed = cfg["run"]["seed"]
    law = cfg["healing"]["law"]
    if law == "none" and hasattr(rheology.params, "healing_time_s"):
        rheology.params = rheology.params.replace(healing_time_s=None)
    need_grid = any(fc[k] is not None for k in ("wind", "ocean", "air_temperature"))
    grid = _grid(mesh, fc["grid_spacing_m"]) if need_grid else None
    x0, y0 = mesh.nodes.min(axis=0)
    x1, y1 = mesh.nodes.max(axis=0)
    t_end = duration_s
    wind = build_wind(fc["wind"], grid, (x0, x1, y0, y1), t_end, seed) if fc["wind"] is not None else None
    ocean = build_ocean(fc["ocean"], grid) if fc["ocean"] is not None else None
    air = (build_air_temperature(fc["air_temperature"], grid, t_end, seed)
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
        parts["forces"] = standard_forces(wind=wind, current=ocean, drag=DragParams(**(fc["drag"] or {})),
                                          coriolis_f=cor.get("f_s"), latitude_deg=cor.get("latitude_deg"))
    if cfg["thermo"]["enabled"]:
        from thermo.model_adapters import ThermoComponent
        from thermo.zero_layer import ThermoParams, ZeroLayerThermo

        parts["thermo"] = ThermoComponent(air, ZeroLayerThermo(ThermoParams(**cfg["thermo"]["params"])))
    if law in ("thermodynamic", "fdd"):
        from thermo.healing import FreezingDegreeDayHealing, ThermodynamicHealing
        from thermo.model_adapters import HealingComponent

        cls = ThermodynamicHealing if law == "thermodynamic" else FreezingDegreeDayHealing
        try:
            h = cls(**cfg["healing"]["params"])
        except TypeError as exc:
            raise ConfigError(f"[healing.params] for law {law!r}: {exc}") from None
        from ..schedule import parse_duration

        parts["healing"] = HealingComponent(h, air, dt_s=parse_duration(cfg["solver"]["dt"], "solver.dt"))
    if cfg["lagrangian"]["enabled"]:
        from ..lagrangian import MeshMotion

        lg = cfg["lagrangian"]
        parts["mover"] = MeshMotion(lg["min_area_ratio"], lg["max_halvings"])
    if cfg["remesh"]["enabled"]:
        parts["remesher"] = build_remesher(cfg)
    return parts


def build_remesher(cfg):
    from ..remesh import Remesher
    from .config import spatial_values

    res = cfg["domain"]["resolution_m"]
    size = res if not isinstance(res, str) else (
        lambda x, y: spatial_values(res, np.atleast_1d(x), np.atleast_1d(y), "domain.resolution_m"))
    return Remesher(size, cfg["remesh"]["min_angle_deg"], **cfg["remesh"]["params"])
