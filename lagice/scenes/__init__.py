"""Bundled scenes, addressable by name from the CLI (``lagice run NAME``).

Each scene is a module with ``run(out_dir, **options) -> dict`` whose keyword
options can be overridden with ``--set key=value``.
"""
from __future__ import annotations

import ast
import inspect

from ..errors import ConfigError

SCENES = {
    "uniaxial_compression": "lagice.scenes.compression",
    "shear_channel": "lagice.scenes.shear_channel",
    "wind_square": "lagice.scenes.wind_square",
}
DEFAULT_SCENE = "uniaxial_compression"


def scene_module(name: str):
    import importlib

    if name not in SCENES:
        raise ConfigError(f"unknown scene {name!r}; available scenes: {sorted(SCENES)}")
    return importlib.import_module(SCENES[name])


def parse_overrides(pairs, run_func) -> dict:
    """Parse ``key=value`` strings; values are Python literals (numbers, booleans,
    strings). Unknown keys raise ConfigError naming the key and the known keys."""
    sig = inspect.signature(run_func)
    build = getattr(inspect.getmodule(run_func), "build", None)
    known = {k for k in sig.parameters if k not in ("out_dir", "build_kw")}
    if build is not None:
        known |= {k for k in inspect.signature(build).parameters if k != "solver_options"}
    out = {}
    for pair in pairs or []:
        if "=" not in pair:
            raise ConfigError(f"--set {pair!r}: expected key=value")
        key, raw = pair.split("=", 1)
        key = key.strip()
        if key not in known:
            raise ConfigError(f"--set {key}: unknown key; known keys: {sorted(known)}")
        try:
            val = ast.literal_eval(raw)
        except (ValueError, SyntaxError):
            val = raw
        default = sig.parameters[key].default if key in sig.parameters else None
        if build is not None and key in inspect.signature(build).parameters:
            default = inspect.signature(build).parameters[key].default
        if isinstance(default, bool) and not isinstance(val, bool):
            raise ConfigError(f"--set {key}={raw}: expected true/false (True or False)")
        if isinstance(default, (int, float)) and not isinstance(default, bool):
            if isinstance(val, bool) or not isinstance(val, (int, float)):
                raise ConfigError(f"--set {key}={raw}: expected a number")
            if isinstance(default, int) and not isinstance(val, int):
                raise ConfigError(f"--set {key}={raw}: expected an integer")
        out[key] = val
    return out
