"""Pieces shared by the time steppers: boundary conditions, step reports."""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConfigError
from ..mesh import Mesh


@dataclass(frozen=True)
class VelocityBC:
    """Prescribed velocity on the nodes of a tagged boundary segment, per component.

    ``u``/``v`` [m s-1]: a number, a callable ``f(t_s, x_m, y_m)`` returning
    values at the given node positions, or None (component free).
    """

    tag: str
    u: object = None
    v: object = None

    def value(self, comp, t, xy):
        val = self.u if comp == 0 else self.v
        if callable(val):
            return np.broadcast_to(np.asarray(val(t, xy[:, 0], xy[:, 1]), np.float64), (len(xy),))
        return np.full(len(xy), float(val))


class DirichletSet:
    """Prescribed dofs of a mesh from a list of :class:`VelocityBC` plus the
    coast (no-slip) nodes. Coast wins where a node is on both."""

    def __init__(self, mesh: Mesh, bcs):
        bcs = list(bcs or [])
        for bc in bcs:
            if not isinstance(bc, VelocityBC):
                raise ConfigError(f"boundary conditions must be VelocityBC objects; got {bc!r}")
            mesh.tag_id(bc.tag)  # raises ConfigError naming the unknown tag
            if bc.u is None and bc.v is None:
                raise ConfigError(f"boundary condition on {bc.tag!r} prescribes neither u nor v")
        self.bcs = bcs
        ndof = 2 * mesh.n_nodes
        owner = np.full(ndof, -1, np.int64)  # index into bcs, or -2 for coast
        for k, bc in enumerate(bcs):
            nodes = mesh.nodes_with_tag(bc.tag)
            if bc.u is not None:
                owner[2 * nodes] = k
            if bc.v is not None:
                owner[2 * nodes + 1] = k
        coast = mesh.coast_nodes()
        owner[2 * coast] = -2
        owner[2 * coast + 1] = -2
        self.owner = owner
        self.dofs = np.flatnonzero(owner != -1)
        self.mask = owner != -1
        self.coast_nodes = coast
        self.mesh = mesh

    def values(self, t: float) -> np.ndarray:
        """Prescribed values at the prescribed dofs, time t [s] (coast: 0)."""
        out = np.zeros(len(self.dofs))
        own = self.owner[self.dofs]
        for k, bc in enumerate(self.bcs):
            for comp in (0, 1):
                sel = (own == k) & (self.dofs % 2 == comp)
                if sel.any():
                    out[sel] = bc.value(comp, t, self.mesh.nodes[self.dofs[sel] // 2])
        return out


@dataclass
class StepInfo:
    """What one time step did: iterations, residual, timings [s], damage events."""

    iterations: int = 0
    residual: float = 0.0
    linear_iterations: int = 0
    n_damaged: int = 0
    n_capped: int = 0
    timings: dict = field(default_factory=lambda: {"assembly": 0.0, "solve": 0.0, "damage": 0.0})


class Timer:
    def __init__(self, timings: dict, key: str):
        self.t, self.k = timings, key

    def __enter__(self):
        self.t0 = time.perf_counter()

    def __exit__(self, *exc):
        self.t[self.k] = self.t.get(self.k, 0.0) + time.perf_counter() - self.t0


class LumpedMassSolver:
    """What the sub-stepped, lumped-mass solvers (explicit Maxwell-EB, EVP) share:
    prescribed-dof masks, geometry caches and the serial/parallel kernel choice.

    Subclasses set ``bcs``, ``parallel`` and call :meth:`reset_topology`; they
    add their own derived geometry in :meth:`_geometry_extras`.
    """

    def reset_topology(self, mesh) -> None:
        """Rebuild everything that depends on connectivity (after a remesh)."""
        self.mesh = mesh
        self.mean_velocity = None
        self.dirichlet = DirichletSet(mesh, self.bcs)
        fixed = np.zeros((mesh.n_nodes, 2), np.int8)
        fixed.reshape(-1)[self.dirichlet.dofs] = 1
        self.fixed = fixed
        self.update_geometry()

    def update_geometry(self) -> None:
        """Recompute shape gradients and areas after nodes moved (Lagrangian step)."""
        from ..errors import SolverError
        from ..fem import SHAPE_GRADIENTS

        m = self.mesh
        sg = SHAPE_GRADIENTS[1] if self._parallel_for(m) else SHAPE_GRADIENTS[0]
        self.b, self.c, self.area = sg(m.nodes, m.triangles)
        if np.any(self.area <= 0):
            raise SolverError(f"{int(np.sum(self.area <= 0))} inverted elements in the mesh")
        self._geometry_extras()

    def _geometry_extras(self) -> None:
        """Hook for solver-specific geometry (called by :meth:`update_geometry`)."""

    def _prescribed_velocity(self, t_s: float) -> np.ndarray:
        """(n, 2) prescribed velocities at time t [s] (0 where free; see ``self.fixed``)."""
        out = np.zeros((self.mesh.n_nodes, 2))
        if len(self.dirichlet.dofs):
            out.reshape(-1)[self.dirichlet.dofs] = self.dirichlet.values(t_s)
        return out

    def _lumped(self, h: np.ndarray, rho: float, par: bool):
        """Lumped nodal mass [kg] and nodal area [m²] for thickness h [m]."""
        from ..fem import LUMPED_MASS

        lm = LUMPED_MASS[1] if par else LUMPED_MASS[0]
        ptr, elems, _local = self.mesh.node_elements
        return lm(ptr, elems, self.area, rho * h), lm(ptr, elems, self.area, np.ones_like(h))

    def _node_setup(self, state, terms, rho: float, dt_sub: float, thickness_weights: bool):
        """What every sub-step of a lumped-mass solver needs per node, from the state
        and the external terms ``terms`` (:func:`lagice.forces.explicit_terms`).

        Returns ``(h, mass, wb, wc, m_dt, fext, cda, par)``: thickness h [m], lumped
        mass [kg], adjacency weights area·∂φ/∂x, area·∂φ/∂y (times h if
        ``thickness_weights``: depth-averaged stress) [m or m²], m/Δt_sub [kg s-1],
        wind force a·τa [N], drag coefficient a·ρw·Cw [kg m-1] and the parallel flag.
        """
        from .explicit import adjacency_weights, adjacency_weights_serial

        mesh = self.mesh
        ptr, elems, local = mesh.node_elements
        par = self._parallel_for(mesh)
        h = np.ascontiguousarray(state.thickness, np.float64)
        mass, node_area = self._lumped(h, rho, par)
        wb, wc = (adjacency_weights if par else adjacency_weights_serial)(
            mesh.triangles, self.b, self.c, self.area, h if thickness_weights else np.ones_like(h),
            ptr, elems, local)
        return (h, mass, wb, wc, mass / dt_sub, terms.tau * node_area[:, None],
                terms.drag_coef * node_area, par)

    def _parallel_for(self, mesh) -> bool:
        from .._numba import PARALLEL_MIN_SIZE

        return self.parallel if self.parallel is not None else mesh.n_elements >= PARALLEL_MIN_SIZE
