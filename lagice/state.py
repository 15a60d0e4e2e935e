"""Model state as structure of arrays (DESIGN.md §2)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import ConfigError
from .mesh import Mesh


@dataclass
class IceState:
    """Node and element fields of the ice on a :class:`~lagice.mesh.Mesh`.

    Node fields: ``velocity`` (n, 2) [m s-1]; node positions are ``mesh.nodes`` [m].
    Element fields: ``thickness`` h = ice volume per unit area [m],
    ``concentration`` A [-], ``damage`` d [-] (0 undamaged), ``stress``
    (m, 3) = (σxx, σyy, σxy) [Pa, tension positive], ``cohesion`` C [Pa],
    ``snow`` hs snow volume per unit area [m].
    ``node_id`` (n,) int64: persistent node identifiers. Remeshing keeps the
    identifiers of the nodes it keeps and gives new nodes new ones
    (``counters["next_node_id"]``), so Lagrangian diagnostics can follow the
    nodes across remesh events (:func:`lagice.io.snapshots.load_window`).
    ``None`` when continuity is unknown.
    """

    mesh: Mesh
    velocity: np.ndarray
    thickness: np.ndarray
    concentration: np.ndarray
    damage: np.ndarray
    stress: np.ndarray
    cohesion: np.ndarray
    snow: np.ndarray | None = None
    node_id: np.ndarray | None = None
    time_s: float = 0.0
    step: int = 0
    counters: dict = field(default_factory=dict)

    @classmethod
    def uniform(cls, mesh: Mesh, *, thickness_m=1.0, concentration=1.0, cohesion_pa=None,
                damage=0.0, time_s=0.0) -> "IceState":
        n, m = mesh.n_nodes, mesh.n_elements

        def field_of(name, v):
            a = np.broadcast_to(np.asarray(v, np.float64), (m,)).copy()
            return a

        st = cls(mesh=mesh, velocity=np.zeros((n, 2)),
                 thickness=field_of("thickness_m", thickness_m),
                 concentration=field_of("concentration", concentration),
                 damage=field_of("damage", damage), stress=np.zeros((m, 3)),
                 cohesion=field_of("cohesion_pa", 0.0 if cohesion_pa is None else cohesion_pa),
                 node_id=np.arange(n, dtype=np.int64), time_s=float(time_s))
        st.validate()
        return st

    def validate(self) -> None:
        """Raise ConfigError on out-of-range initial fields (name, value, range)."""
        m = self.mesh.n_elements
        for name in ("thickness", "concentration", "damage", "cohesion"):
            a = getattr(self, name)
            if a.shape != (m,):
                raise ConfigError(f"{name} has shape {a.shape}; expected ({m},) (one value per element)")
            if not np.all(np.isfinite(a)):
                raise ConfigError(f"{name} contains NaN or inf")
        checks = (("thickness", 0.0, None), ("concentration", 0.0, 1.0), ("damage", 0.0, 1.0),
                  ("cohesion", 0.0, None))
        for name, lo, hi in checks:
            a = getattr(self, name)
            if lo is not None and a.min() < lo or hi is not None and a.max() > hi:
                raise ConfigError(f"{name} ranges over [{a.min():.6g}, {a.max():.6g}]; expected values "
                                  f"in [{lo}, {'inf' if hi is None else hi}]")
        if self.damage.max() >= 1.0:
            raise ConfigError("damage must be < 1 (1 = fully damaged has zero stiffness)")

    @property
    def ice_volume_m3(self) -> float:
        return float(np.sum(self.thickness * np.abs(self.mesh.areas())))
