"""Model state as structure of arrays (docs/design.md, "State").

The fields and their units, ranges and remap rules are declared once in
:mod:`lagice.fields`; simulated time lives in the model's clock
(:class:`lagice.clock.Clock`), not in the state."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .mesh import Mesh


@dataclass
class IceState:
    """Node and element fields of the ice on a :class:`~lagice.mesh.Mesh`.

    Node fields: ``velocity`` (n, 2) [m s-1]; node positions are ``mesh.nodes`` [m].
    Element fields: ``thickness`` h = ice volume per unit area [m],
    ``concentration`` A [-], ``damage`` d [-] (0 undamaged), ``stress``
    (m, 3) = (σxx, σyy, σxy) [Pa, tension positive], ``cohesion`` C [Pa],
    ``snow`` hs snow volume per unit area [m]. ``strength_factor`` g [-]: the
    spatially correlated part of the strength (:mod:`lagice.strength`), carried by
    the ice and remapped like the other element fields; ``None`` without one.
    ``strain_accumulated`` (m, 3) [-]: the time integral of the strain rate the
    rheology used (ε̇xx, ε̇yy, ε̇xy; ``output.accumulate_strain``, :meth:`lagice.model.Model.step`),
    remapped like the other element fields; ``None`` when not asked for.
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
    strength_factor: np.ndarray | None = None
    strain_accumulated: np.ndarray | None = None
    counters: dict = field(default_factory=dict)

    @classmethod
    def uniform(cls, mesh: Mesh, *, thickness_m=1.0, concentration=1.0, cohesion_pa=None,
                damage=0.0) -> IceState:
        n, m = mesh.n_nodes, mesh.n_elements

        def field_of(name, v):
            a = np.broadcast_to(np.asarray(v, np.float64), (m,)).copy()
            return a

        st = cls(mesh=mesh, velocity=np.zeros((n, 2)),
                 thickness=field_of("thickness_m", thickness_m),
                 concentration=field_of("concentration", concentration),
                 damage=field_of("damage", damage), stress=np.zeros((m, 3)),
                 cohesion=field_of("cohesion_pa", 0.0 if cohesion_pa is None else cohesion_pa),
                 node_id=np.arange(n, dtype=np.int64))
        st.validate()
        return st

    def validate(self) -> None:
        """Raise ConfigError on missing, misshapen, non-finite or out-of-range fields
        (the field registry, :mod:`lagice.fields`, gives names, units and ranges)."""
        from .fields import validate_state

        validate_state(self)

    @property
    def ice_volume_m3(self) -> float:
        return float(np.sum(self.thickness * np.abs(self.mesh.areas())))
