"""Scene files (TOML): strict schema, defaults, expressions and overrides.

A scene is a TOML file with the tables below; unknown tables/keys and values
of the wrong type are errors that name the key (``domain.resolution_m``).
Values that may vary in space/time accept a number, a numpy expression string
in ``x, y`` (initial fields) or ``t, x, y`` (forcing), e.g.
``"0.3 + 0.005*(sin(6e-5*x) + sin(3e-5*y))"``, or ``"module:function"``
naming a Python function with the same arguments.

``--set key=value`` (CLI) or ``overrides={"run.duration": "2d"}`` replaces
any key using its dotted path; the value is parsed as a TOML value.
"""
from __future__ import annotations

import copy
import importlib
import math
import re
import tomllib
from pathlib import Path

import numpy as np

from ..errors import ConfigError

NUM = (int, float)
EXPR = (int, float, str)
ANY = object

# table -> key -> (type or tuple of types, default). A nested dict is a sub-table;
# "*" as a key means free-form sub-tables (validated by the builder).
SCHEMA = {
    "scene": {"name": (str, None), "description": (str, ""), "extends": (str, None)},
    "domain": {
        "kind": (str, "rectangle"), "width_m": (NUM, None), "height_m": (NUM, None),
        "x0_m": (NUM, 0.0), "y0_m": (NUM, 0.0), "vertices": (list, None), "islands": (list, []),
        "file": (str, None), "function": (str, None), "params": (dict, {}),
        "resolution_m": (EXPR, None), "exterior_tag": (str, "coast"),
        "segments": (dict, {}), "rotate_deg": (NUM, 0.0), "renumber": (bool, True),
        "crs": (str, "EPSG:3413"), "file_crs": (str, None),
        # interior node jitter, a fraction of the local edge length (lagice.mesh.perturb; issue 12)
        "jitter": (NUM, 0.0),
        # gmsh 2-D algorithm of the initial mesh (lagice.mesh.generate; issue 12): 6 =
        # Frontal-Delaunay (one near-perfect lattice over the whole domain), 5 = Delaunay
        # (locally near-equilateral, no domain-wide lattice direction), 1 = MeshAdapt
        "mesh_algorithm": (int, 6),
    },
    "initial": {
        "thickness_m": (EXPR, 1.0), "concentration": (EXPR, 1.0), "damage": (EXPR, 0.0),
        "snow_m": (EXPR, None), "cohesion_pa": (EXPR, "random"), "stress_pa": (EXPR, 0.0),
        # a spun-up state (.npz of lagice.spinup.save_spinup): thickness_m, concentration,
        # damage = "from_state" take the value of its nearest element centroid (issue 12)
        "state_file": (str, None),
    },
    "rheology": {
        "law": (str, "maxwell_eb"),
        "poisson": (NUM, 0.3), "friction": (NUM, 0.7), "rho_ice": (NUM, 900.0),
        "shear_wave_speed": (NUM, 500.0), "young_modulus_pa": (NUM, None),
        "relaxation_time_s": (NUM, 1e7), "alpha": (NUM, 4.0), "cohesion_min_pa": (NUM, 25e3),
        "cohesion_max_pa": (NUM, 50e3), "healing_time_s": (NUM, 1e5), "concentration_c": (NUM, 20.0),
        "max_damage": (NUM, 1.0 - 1e-6), "stress_correction": (str, "origin"),
        "stress_correction_mean_fraction": (NUM, None),
        # neXtSIM's compressive term (lagice.params.MaxwellEBParams.max_pressure_pa; issue 12):
        # damaged ice below P_max = P* h^k exp(-c*(1-A)) in compression does not creep
        "max_pressure_pa": (NUM, None), "max_pressure_thickness_exponent": (NUM, 1.5),
        # false: the Maxwell relaxation acts on the deviatoric stress only (MaxwellEBParams.relax_mean_stress)
        "relax_mean_stress": (bool, True),
        # a dilatant Maxwell viscous flow, angle ψ in degrees (MaxwellEBParams.dilatancy_angle_deg; 0/None off)
        "dilatancy_angle_deg": (NUM, None),
        # nonlocal damage: the load ratio averaged over centroids within this radius [m]
        # (MaxwellEBParams.damage_nonlocal_radius_m; 0/None off)
        "damage_nonlocal_radius_m": (NUM, None),
        # the damage time td = ℓ/cs with this ℓ [m] for every element (MaxwellEBParams.damage_length_m;
        # 0/None: td = Δx/cs, the element's own size)
        "damage_length_m": (NUM, None),
        # a crack-band scaling of the viscous flow: λ times Δx/ℓ with this ℓ [m] on every element
        # (MaxwellEBParams.crack_band_length_m; 0/None: off)
        "crack_band_length_m": (NUM, None),
        # the stress the failure envelope judges: "nominal" (Dansereau et al. 2016) or "effective",
        # σ/(1 − d): cohesion C (1 − d), friction kept (MaxwellEBParams.failure_stress)
        "failure_stress": (str, "nominal"),
        # quasi-unilateral damage: the mean stress of compressed ice changes with the undamaged
        # modulus (MaxwellEBParams.crack_closure; needs relax_mean_stress = false)
        "crack_closure": (bool, False),
        # ζ/η of the Maxwell viscous flow: the mean stress relaxes more slowly than the deviator
        # (MaxwellEBParams.bulk_shear_viscosity_ratio; None: one λ for the whole stress)
        "bulk_shear_viscosity_ratio": (NUM, None),
        "p_star": (NUM, 27.5e3), "c_star": (NUM, 20.0), "ellipse": (NUM, 2.0), "delta_min": (NUM, 2e-9),
        "replacement_pressure": (bool, False),
        # strength law (lagice.strength; issue 12): "uniform" = cohesion_min/max_pa,
        # "scaled" = C_lab sqrt(L_lab/dx_e) (1 + disorder U_e) per element (maxwell_eb only)
        "strength_law": (str, "uniform"), "strength_lab_pa": (NUM, None), "strength_lab_scale_m": (NUM, None),
        "strength_disorder": (NUM, None),
        # spatially correlated strength factor g = 1 + a(2Φ(G) − 1), G correlated over ℓ (0: none)
        "strength_correlation_m": (NUM, None), "strength_correlated_amplitude": (NUM, None),
        # which elements get the law's C after a remesh: "new" (the default since 2026-11-28: kept
        # elements keep theirs) or "all" (every element recomputed from its current size, as from
        # 2026-11-24 to 2026-11-28; None, in the configurations of that code's checkpoints, means
        # "all"); StrengthLaw.after_remesh
        "strength_after_remesh": (str, "new"),
    },
    "solver": {
        "name": (str, "implicit"), "dt": (EXPR, None), "substeps": (int, None),
        "linear_solver": (str, None), "tol": (NUM, None), "max_iter": (int, None),
        "allow_unstable": (bool, False), "safety": (NUM, None), "parallel": ((bool, str), None),
        "substep_limit": (str, None),
        # explicit stepper: the volumetric strain rate of each element's stress update, its own
        # ("element", the default) or averaged at the nodes ("nodal": no volumetric locking where the
        # mean stress is kept; lagice.solvers.explicit._node_divergence)
        "volumetric_strain": (str, None),
        # explicit stepper: the velocity space, "linear" (the default, one value per node) or
        # "crouzeix_raviart" (one per edge midpoint; lagice.solvers.crouzeix_raviart)
        "velocity_element": (str, None),
        # with "crouzeix_raviart": Hansbo and Larson's (2003) interior-edge jump penalty κ (0: none;
        # lagice.solvers.crouzeix_raviart.JumpPenalty)
        "jump_penalty": (NUM, None),
        # implicit solver: Dansereau et al. (2016)'s fixed point between the solve and the damage
        # update (lagice.solvers.implicit, step 4); 1 pass (no fixed point) by default
        "damage_iterations": (int, None), "damage_tol": (NUM, None),
        "velocity": (str, None), "velocity_params": (dict, {}),
        "device": (str, "cpu"),
    },
    "boundary": {"*": {"u": (EXPR, None), "v": (EXPR, None)}},
    "forcing": {
        "grid_spacing_m": (NUM, 25e3),
        "wind": (dict, None), "ocean": (dict, None), "air_temperature": (dict, None),
        "coriolis": (dict, None), "drag": (dict, None),
    },
    # new_ice_undamaged: ice formed in open water is undamaged, so lateral growth dilutes the
    # element's damage, d <- d A_old/A_new (neXtSIM-DG's DamageHealing; thermo.model_adapters)
    "thermo": {"enabled": (bool, False), "params": (dict, {}), "new_ice_undamaged": (bool, False)},
    "healing": {"law": (str, "constant"), "params": (dict, {})},
    "lagrangian": {"enabled": (bool, False), "min_area_ratio": (NUM, 0.05), "max_halvings": (int, 8)},
    "remesh": {"enabled": (bool, False), "min_angle_deg": (NUM, 10.0), "params": (dict, {})},
    "run": {"duration": (EXPR, None), "seed": (int, 0), "progress": (bool, True),
            "start_date": (str, "2000-01-01 00:00:00"), "max_speed_m_s": (NUM, 10.0)},
    "output": {"every": (EXPR, "1d"), "vtu": (bool, False), "plot": ((bool, str), True),
               "grid_resolution_m": (NUM, None), "timeseries": (dict, None), "accumulate_strain": (bool, False)},
    "checkpoint": {"every": (EXPR, None), "every_wall": (EXPR, None), "keep": (int, 3)},
    "drifters": {"positions_m": (list, None), "count": (int, 0)},
}

#: keys that were removed, with what replaces them (an error says so)
REMOVED = {
    "forcing.crs": "the scene has one CRS: set [domain] crs (it is used for the domain, the forcing files, "
                   "the outputs and Coriolis)",
    "output.crs_epsg": "outputs are labelled with the scene's one CRS: set [domain] crs (e.g. 'EPSG:3413')",
}

#: rheology keys of each law (``[rheology] law``); keys of the other law are not used
RHEOLOGY_KEYS = {
    "maxwell_eb": ("poisson", "friction", "rho_ice", "shear_wave_speed", "young_modulus_pa", "relaxation_time_s",
                   "alpha", "cohesion_min_pa", "cohesion_max_pa", "healing_time_s", "concentration_c",
                   "max_damage", "stress_correction", "stress_correction_mean_fraction", "max_pressure_pa",
                   "max_pressure_thickness_exponent", "relax_mean_stress",
                   "dilatancy_angle_deg", "damage_nonlocal_radius_m", "failure_stress", "crack_closure",
                   "bulk_shear_viscosity_ratio", "damage_length_m", "crack_band_length_m"),
    "viscous_plastic": ("p_star", "c_star", "ellipse", "delta_min", "replacement_pressure", "rho_ice"),
}

#: config keys that do not change the trajectory of a run (left out of the checkpoint
#: fingerprint, so a run can be extended, re-scheduled or re-described on resume)
NON_PHYSICS = {"scene": ("name", "description", "extends", "source"), "run": ("duration", "progress", "max_speed_m_s"),
               "output": None, "checkpoint": None,
               # where the explicit stepper runs (CPU serial/parallel kernels, GPU): same physics, results
               # equal to round-off (docs/gpu.md), so a checkpoint resumes on another device
               "solver": ("device", "parallel")}

#: keys added to the schema after checkpoints existed, each with the value(s) that do what
#: the code did before the key existed. A checkpoint written before a key existed has no
#: such key in its configuration, and its fingerprint was hashed without it: it resumes
#: when the key's value here is one of these (:func:`legacy_keys_check`, used by
#: :meth:`lagice.simulation.Simulation.resume`), and is refused, naming the key, otherwise.
#: A key whose default does not reproduce the earlier code (``domain.renumber``: meshes were
#: not renumbered before it) is not listed, so such checkpoints are refused.
LEGACY_VALUES = {
    "domain.jitter": (0.0, 0),                       # 2026-11-23: no node jitter
    "domain.mesh_algorithm": (6,),                   # 2026-11-23: gmsh Frontal-Delaunay
    "rheology.strength_law": ("uniform",),           # 2026-11-23: cohesion_min/max_pa
    "rheology.strength_lab_pa": (None,),
    "rheology.strength_lab_scale_m": (None,),
    "rheology.strength_disorder": (None,),
    "rheology.strength_correlation_m": (None, 0.0, 0),  # 2026-11-26: no correlated strength field
    "rheology.strength_after_remesh": (None, "all"),   # before 2026-11-28: every element recomputed at a remesh
    "rheology.strength_correlated_amplitude": (None,),
    "rheology.stress_correction": ("origin",),       # 2026-11-24: scaling towards the origin
    "rheology.stress_correction_mean_fraction": (None,),
    "rheology.max_pressure_pa": (None, 0, 0.0),      # 2026-11-26: no compressive term
    "rheology.max_pressure_thickness_exponent": (1.5,),
    "rheology.relax_mean_stress": (True,),            # 2026-11-27: the whole stress relaxes
    "rheology.dilatancy_angle_deg": (None, 0, 0.0),   # 2026-11-27: the viscous flow does not dilate
    "rheology.damage_nonlocal_radius_m": (None, 0, 0.0),  # 2026-11-28: local damage
    "rheology.damage_length_m": (None, 0, 0.0),      # 2026-11-30: td = Δx/cs, the element's own size
    "rheology.crack_band_length_m": (None, 0, 0.0),  # 2026-11-30: λ not scaled with the element's size
    "rheology.failure_stress": ("nominal",),         # 2026-11-28: the envelope judges the nominal stress
    "rheology.crack_closure": (False,),              # 2026-11-28: damage lowers the modulus for every strain
    "rheology.bulk_shear_viscosity_ratio": (None,),  # 2026-11-28: one relaxation time for the whole stress
    "thermo.new_ice_undamaged": (False,),            # 2026-11-27: new ice takes the element's damage
    "initial.state_file": (None, ""),                # 2026-11-24: no spin-up state
    "solver.substep_limit": (None, "mesh"),          # 2026-11-25: the whole-mesh limit
    "solver.volumetric_strain": (None, "element"),   # 2026-11-28: each element's own volumetric strain
    "solver.velocity_element": (None, "linear"),     # 2026-11-28: velocities at the nodes
    "solver.jump_penalty": (None, 0, 0.0),           # 2026-11-28: no jump penalty
}


def absent_keys(view: dict, stored: dict | None) -> list[str]:
    """Dotted keys of the physics ``view`` (tables of key → value) that the stored
    configuration ``stored`` (a checkpoint's) does not have: keys added since the
    code that wrote it."""
    if not isinstance(stored, dict):
        return []
    out = []
    for table, val in view.items():
        if table.startswith("_"):
            continue
        if table not in stored:
            out.append(table)
        elif isinstance(val, dict) and isinstance(stored[table], dict):
            out += [f"{table}.{k}" for k in val if k not in stored[table]]
    return out


#: keys whose default changed after they existed (or were added with a new default): a
#: checkpoint's stored configuration that lacks one is read with this value, which makes the
#: code do what the code that wrote it did (:func:`with_legacy_values`, used by every resume and
#: branch), instead of the schema's new default. ``rheology.strength_after_remesh``: None
#: means "all" (:func:`lagice.strength.from_config`), the behaviour before 2026-11-28.
LEGACY_FILL = {"rheology.strength_after_remesh": None}


def with_legacy_values(stored: dict) -> dict:
    """A copy of a checkpoint's stored configuration with each key of :data:`LEGACY_FILL` that
    it lacks set to its legacy value (tables it lacks are left alone: a component that was off
    or did not exist). The copy is one level deep: ``stored`` is not changed."""
    out = {k: (dict(v) if isinstance(v, dict) else v) for k, v in stored.items()}
    for key, value in LEGACY_FILL.items():
        table, _, name = key.partition(".")
        if isinstance(out.get(table), dict) and name not in out[table]:
            out[table][name] = value
    return out


def legacy_keys_check(view: dict, keys) -> list[str]:
    """The keys among ``keys`` (dotted, absent from a checkpoint's configuration) whose
    value in ``view`` is not a value of :data:`LEGACY_VALUES` that reproduces the code
    from before the key existed: a resume with them would not continue the same physics."""
    bad = []
    for key in keys:
        table, _, name = key.partition(".")
        val = view.get(table, {}).get(name) if name else view.get(table)
        if key not in LEGACY_VALUES or not any(val == v and type(val) is type(v) for v in LEGACY_VALUES[key]):
            bad.append(f"{key} = {val!r}")
    return bad


ROOT = Path(__file__).resolve().parents[2]  # relative data paths of scenes are tried here too
SCENE_DIR = ROOT / "examples"
_MODFUNC = re.compile(r"^[A-Za-z_][\w.]*:[A-Za-z_]\w*$")


def _type_name(t):
    if isinstance(t, tuple):
        return " or ".join(_type_name(x) for x in t)
    return {int: "integer", float: "number", str: "string", bool: "boolean", list: "array",
            dict: "table"}.get(t, getattr(t, "__name__", str(t)))


def _check_type(key, value, typ):
    if value is None:
        return
    types = typ if isinstance(typ, tuple) else (typ,)
    if isinstance(value, bool) and bool not in types:
        raise ConfigError(f"{key} = {value!r}: expected {_type_name(typ)}, got a boolean")
    if float in types and isinstance(value, int) and not isinstance(value, bool):
        return
    if not isinstance(value, types):
        raise ConfigError(f"{key} = {value!r}: expected {_type_name(typ)}, got {type(value).__name__}")


def validate(raw: dict, source: str = "<scene>") -> dict:
    """Check keys and types against SCHEMA and fill defaults. Returns a new dict."""
    if not isinstance(raw, dict):
        raise ConfigError(f"{source}: a scene must be a TOML table")
    out = {}
    for table in raw:
        if table not in SCHEMA:
            raise ConfigError(f"{source}: unknown table [{table}]; known tables: {sorted(SCHEMA)}")
    for table, spec in SCHEMA.items():
        given = raw.get(table, {})
        if not isinstance(given, dict):
            raise ConfigError(f"{source}: [{table}] must be a table")
        if "*" in spec:
            sub = {}
            for name, vals in given.items():
                if not isinstance(vals, dict):
                    raise ConfigError(f"{source}: {table}.{name} must be a table")
                sub[name] = _validate_table(f"{table}.{name}", vals, spec["*"], source)
            out[table] = sub
        else:
            out[table] = _validate_table(table, given, spec, source)
    return out


def _validate_table(prefix, given, spec, source):
    res = {}
    for key, val in given.items():
        if key not in spec:
            if f"{prefix}.{key}" in REMOVED:
                raise ConfigError(f"{source}: {prefix}.{key} is no longer a setting: {REMOVED[prefix + '.' + key]}")
            raise ConfigError(f"{source}: unknown key {prefix}.{key}; known keys of [{prefix}]: {sorted(spec)}")
        _check_type(f"{source}: {prefix}.{key}", val, spec[key][0])
        res[key] = val
    for key, (_typ, default) in spec.items():
        res.setdefault(key, copy.deepcopy(default))
    return res


def parse_value(raw: str):
    """A ``--set`` value: a TOML value (number, boolean, string, array), else a bare string."""
    try:
        return tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        return raw


def apply_overrides(raw: dict, overrides) -> dict:
    """Apply ``{"table.key": value}`` or ``["table.key=value", ...]`` to a raw scene."""
    raw = copy.deepcopy(raw)
    items = overrides.items() if isinstance(overrides, dict) else split_overrides(overrides)
    for dotted, val in items:
        parts = dotted.split(".")
        if len(parts) < 2:
            raise ConfigError(f"--set {dotted}: expected table.key=value (e.g. run.duration=2d)")
        table = parts[0]
        if table not in SCHEMA:
            raise ConfigError(f"--set {dotted}: unknown table [{table}]; known tables: {sorted(SCHEMA)}")
        node = raw.setdefault(table, {})
        for p in parts[1:-1]:
            node = node.setdefault(p, {})
            if not isinstance(node, dict):
                raise ConfigError(f"--set {dotted}: {p} is not a table")
        node[parts[-1]] = val
    return raw


def split_overrides(overrides) -> list:
    """``["table.key=value", ...]`` → ``[(key, value), ...]``. A key given twice with
    different values is refused (the first value would be silently ignored)."""
    items = [_split(s) for s in overrides or []]
    seen = {}
    for k, v in items:
        if k in seen and seen[k] != v:
            raise ConfigError(f"--set {k} is given twice ({k}={seen[k]!r}, then {k}={v!r}); give it once")
        seen[k] = v
    return items


def _split(s):
    if "=" not in s:
        raise ConfigError(f"--set {s!r}: expected key=value")
    k, v = s.split("=", 1)
    return k.strip(), parse_value(v.strip())


def scene_path(name_or_path) -> Path:
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists():
        if not p.exists():
            raise ConfigError(f"scene file {p} does not exist")
        return p
    cand = SCENE_DIR / f"{name_or_path}.toml"
    if cand.exists():
        return cand
    known = sorted(q.stem for q in SCENE_DIR.glob("*.toml")) if SCENE_DIR.exists() else []
    raise ConfigError(f"unknown scene {name_or_path!r}; bundled scenes: {known}")


def _merge(base: dict, child: dict) -> dict:
    """``child`` over ``base``: tables merge key by key, other values replace."""
    out = copy.deepcopy(base)
    for k, v in child.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else copy.deepcopy(v)
    return out


def read_raw_scene(path: Path, _chain=()) -> dict:
    """The raw TOML of a scene, with ``[scene] extends = "base.toml"`` resolved:
    the base scene (path relative to this file) is read first and this file's
    tables are merged over it, key by key. The base's ``name`` is not inherited."""
    path = Path(path)
    if path.resolve() in _chain:
        raise ConfigError(f"{path}: scene.extends makes a cycle: {' -> '.join(str(p) for p in (*_chain, path))}")
    try:
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from exc
    base_name = raw.get("scene", {}).get("extends") if isinstance(raw.get("scene"), dict) else None
    if base_name is None:
        return raw
    if not isinstance(base_name, str):
        raise ConfigError(f"{path}: scene.extends = {base_name!r}: expected a scene file name")
    base_path = path.parent / base_name
    if not base_path.exists():
        raise ConfigError(f"{path}: scene.extends = {base_name!r}: file {base_path} does not exist")
    base = read_raw_scene(base_path, (*_chain, path.resolve()))
    base.setdefault("scene", {}).pop("name", None)
    merged = _merge(base, raw)
    merged["scene"].pop("extends", None)
    return merged


def physics_view(cfg: dict) -> dict:
    """The part of a scene configuration that determines the trajectory: everything
    but :data:`NON_PHYSICS` (run length, output and checkpoint schedules, names).
    Forcing generators whose records depend on the run length (``random`` and
    ``cyclones`` winds, ``synthetic`` air temperature draw their schedule over the
    whole run, :func:`length_dependent_forcing`) keep ``run.duration`` in the view,
    unless their ``horizon`` is set."""
    out = {}
    for table, val in cfg.items():
        if table.startswith("_"):
            continue
        drop = NON_PHYSICS.get(table, ())
        if drop is None:
            continue
        out[table] = {k: v for k, v in val.items() if k not in drop} if isinstance(val, dict) else val
    if length_dependent_forcing(cfg):
        out["run"]["duration"] = cfg["run"]["duration"]
    return out


#: forcing generators that draw their records over the whole run: ``(table, kind)``
LENGTH_DEPENDENT = (("wind", "random"), ("wind", "cyclones"), ("air_temperature", "synthetic"))


def length_dependent_forcing(cfg: dict) -> list[str]:
    """The ``[forcing.*]`` tables whose records depend on ``run.duration``: random
    generators drawing their schedule over ``[0, run.duration]`` (cyclone birth
    times, wind and temperature sequences), unless ``horizon`` fixes the span they
    are drawn over (then the run can be extended up to the horizon)."""
    fc = cfg.get("forcing", {})
    out = []
    for table, kind in LENGTH_DEPENDENT:
        t = fc.get(table) or {}
        if t.get("kind") == kind and t.get("horizon") is None:
            out.append(f"forcing.{table}")
    return out


def override_config(cfg: dict, overrides) -> dict:
    """A validated config (e.g. from a checkpoint) with ``overrides`` (``{"table.key":
    value}`` or ``["table.key=value", ...]``) applied and validated again, e.g. a
    longer ``run.duration`` to extend a run, or ``{"solver.device": "cuda"}`` when
    resuming on another device; private keys (``_parent``) and the scene's name and
    source are kept."""
    raw = {k: copy.deepcopy(v) for k, v in cfg.items() if not k.startswith("_")}
    scene = dict(raw.get("scene", {}))
    source = scene.pop("source", "<checkpoint>")
    raw["scene"] = scene
    raw = apply_overrides(raw, overrides or {})
    out = validate(raw, "--set")
    out["scene"]["source"] = source
    for k, v in cfg.items():
        if k.startswith("_"):
            out[k] = copy.deepcopy(v)
    return out


def changed_keys(a: dict, b: dict, prefix: str = "") -> list[str]:
    """Dotted keys whose values differ between two (nested) configs."""
    out = []
    for k in sorted(set(a) | set(b), key=str):
        va, vb = a.get(k), b.get(k)
        if isinstance(va, dict) and isinstance(vb, dict):
            out += changed_keys(va, vb, f"{prefix}{k}.")
        elif va != vb:
            out.append(f"{prefix}{k}")
    return out


def load_scene(name_or_path, overrides=None) -> dict:
    """Read, override and validate a scene; returns the full config dict."""
    path = scene_path(name_or_path)
    raw = read_raw_scene(path)
    raw = apply_overrides(raw, overrides or {})
    cfg = validate(raw, str(path))
    cfg["scene"]["name"] = cfg["scene"]["name"] or path.stem
    cfg["scene"]["source"] = str(path)
    return cfg


# -- expressions ---------------------------------------------------------------
_NP_NAMES = {name: getattr(np, name) for name in (
    "sin", "cos", "tan", "exp", "log", "log10", "sqrt", "abs", "tanh", "arctan2", "hypot", "where",
    "minimum", "maximum", "clip", "pi", "sign", "floor", "ceil", "ones_like", "zeros_like")}


def list_scenes() -> dict:
    """Bundled scenes: ``{name: (path, description)}`` from ``examples/*.toml``."""
    out = {}
    for p in sorted(SCENE_DIR.glob("*.toml")) if SCENE_DIR.exists() else []:
        try:
            raw = read_raw_scene(p)
        except ConfigError:
            continue
        sc = raw.get("scene", {}) if isinstance(raw.get("scene"), dict) else {}
        out[sc.get("name") or p.stem] = (p, sc.get("description", ""))
    return out


def resolve_hook(spec: str, key: str, params: dict | None = None):
    """The function named by ``"module:function"`` with ``params`` bound as keyword
    arguments (a ConfigError names ``key`` when it cannot be imported)."""
    import functools

    if not isinstance(spec, str) or not _MODFUNC.match(spec):
        raise ConfigError(f"{key} = {spec!r}: expected 'module:function'")
    f = resolve_callable(spec, key)
    if params:
        if not isinstance(params, dict):
            raise ConfigError(f"{key} params = {params!r}: expected a table of keyword arguments")
        import inspect

        try:
            sig = inspect.signature(f)
        except (TypeError, ValueError):
            sig = None
        if sig is not None and not any(p.kind == p.VAR_KEYWORD for p in sig.parameters.values()):
            for k in params:
                if k not in sig.parameters:
                    raise ConfigError(f"{key}: {spec} takes no parameter {k!r}; known: "
                                      f"{sorted(n for n in sig.parameters if n not in ('t', 'x', 'y'))}")
        f = functools.partial(f, **params)
    return f


def resolve_callable(spec: str, key: str):
    mod, _, fn = spec.partition(":")
    try:
        f = getattr(importlib.import_module(mod), fn)
    except (ImportError, AttributeError) as exc:
        raise ConfigError(f"{key} = {spec!r}: cannot import {fn!r} from {mod!r} ({exc})") from exc
    if not callable(f):
        raise ConfigError(f"{key} = {spec!r} is not callable")
    return f


def spatial_values(value, x, y, key: str) -> np.ndarray:
    """Evaluate an initial field (number, expression in x, y, or module:function)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return np.full(len(x), float(value))
    if isinstance(value, str):
        if _MODFUNC.match(value):
            out = resolve_callable(value, key)(x, y)
        else:
            try:
                out = eval(compile(value, key, "eval"), {"__builtins__": {}}, {**_NP_NAMES, "x": x, "y": y})
            except Exception as exc:  # noqa: BLE001
                raise ConfigError(f"{key} = {value!r}: cannot evaluate the expression in x, y: {exc}") from exc
        out = np.broadcast_to(np.asarray(out, np.float64), (len(x),)).copy()
        if not np.all(np.isfinite(out)):
            raise ConfigError(f"{key} = {value!r} gives NaN or inf in the domain")
        return out
    raise ConfigError(f"{key} = {value!r}: expected a number, an expression in x, y or module:function")


def time_space_callable(value, key: str):
    """A callable f(t, x, y) from a number, expression in t, x, y, or module:function."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        v = float(value)
        if not math.isfinite(v):
            raise ConfigError(f"{key} = {value!r}: expected a finite number (or an expression in t, x, y)")
        return lambda t, x, y: np.full(np.shape(x), v)
    if isinstance(value, str):
        if _MODFUNC.match(value):
            return resolve_callable(value, key)
        try:
            code = compile(value, key, "eval")
        except SyntaxError as exc:
            raise ConfigError(f"{key} = {value!r}: not a valid expression: {exc}") from exc

        def raw(t, x, y, _code=code):
            with np.errstate(all="ignore"):
                return np.broadcast_to(np.asarray(eval(_code, {"__builtins__": {}},
                                                       {**_NP_NAMES, "t": t, "x": x, "y": y}), np.float64),
                                       np.shape(x))

        def f(t, x, y):
            """``raw``; a failure or a value that is not finite is a ConfigError naming the key and the time."""
            try:
                out = raw(t, x, y)
            except Exception as exc:  # noqa: BLE001 - a user's expression: name it and the time
                raise ConfigError(f"{key} = {value!r}: cannot evaluate the expression at t = {float(np.max(t)):g} s: "
                                  f"{type(exc).__name__}: {exc}") from exc
            if not np.all(np.isfinite(out)):
                bad = out[~np.isfinite(out)].flat[0]
                raise ConfigError(f"{key} = {value!r} gives {bad} at t = {float(np.max(t)):g} s; expected finite "
                                  f"values")
            return out
        try:
            raw(0.0, np.zeros(2), np.zeros(2))  # it evaluates (its values are checked where it is used)
        except Exception as exc:  # noqa: BLE001
            raise ConfigError(f"{key} = {value!r}: cannot evaluate the expression in t, x, y: {exc}") from exc
        return f
    raise ConfigError(f"{key} = {value!r}: expected a number, an expression in t, x, y or module:function")


def resolution_size_field(res):
    """The target element size [m] of ``domain.resolution_m``: the number itself, or for an
    expression in x, y a vectorised ``f(x, y)`` (mesh generation, remeshing, the run's mesh line)."""
    if isinstance(res, str):
        return lambda x, y: spatial_values(res, np.atleast_1d(x), np.atleast_1d(y), "domain.resolution_m")
    return res
