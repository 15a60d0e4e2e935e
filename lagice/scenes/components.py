"""Optional model components built from a scene config: external forces,
thermodynamics, healing, Lagrangian mesh motion, remeshing. A component
the scene does not ask for is not built (None) and costs nothing."""
from __future__ import annotations

from ..errors import ConfigError


def validate(cfg: dict) -> None:
    """Cheap checks before any mesh work (kinds and parameter names)."""
    law = cfg["healing"]["law"]
    if law not in ("none", "constant", "thermodynamic", "fdd"):
        raise ConfigError(f"healing.law = {law!r}: expected 'none', 'constant', 'thermodynamic' or 'fdd'")
    if law in ("thermodynamic", "fdd") and cfg["forcing"]["air_temperature"] is None:
        raise ConfigError(f"healing.law = {law!r} needs [forcing.air_temperature]")
    if cfg["thermo"]["enabled"] and cfg["forcing"]["air_temperature"] is None:
        raise ConfigError("thermo.enabled = true needs [forcing.air_temperature]")
    if cfg["remesh"]["enabled"] and not cfg["lagrangian"]["enabled"]:
        raise ConfigError("remesh.enabled = true needs lagrangian.enabled = true (a fixed mesh never distorts)")


def build(cfg: dict, mesh, state, rheology, duration_s: float) -> dict:
    parts = {"forces": [], "thermo": None, "healing": None, "mover": None, "remesher": None}
    if cfg["healing"]["law"] == "none":
        rheology.params = rheology.params.replace(healing_time_s=None)
    return parts
