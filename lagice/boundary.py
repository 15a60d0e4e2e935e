"""Boundary conditions on the node velocity: prescribed components on tagged
boundary segments (:class:`VelocityBC`) and the coast (no-slip), gathered into the
prescribed degrees of freedom of a mesh (:class:`DirichletSet`)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import ConfigError
from .mesh import Mesh


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
        """Values of component ``comp`` (0: u, 1: v) at time ``t`` [s] on the nodes ``xy``;
        a value that is not finite, or a callable that fails, is a ConfigError naming the
        scene key (``boundary.TAG.u``), the time, the node and the value."""
        val = self.u if comp == 0 else self.v
        key = f"boundary.{self.tag}.{'uv'[comp]}"
        if callable(val):
            try:
                with np.errstate(all="ignore"):
                    out = np.broadcast_to(np.asarray(val(t, xy[:, 0], xy[:, 1]), np.float64), (len(xy),))
            except ConfigError:
                raise
            except Exception as exc:  # noqa: BLE001 - a user's function: name the key and the time
                raise ConfigError(f"{key}: evaluating it at t = {t:g} s (day {t / 86400:.4f}) failed: "
                                  f"{type(exc).__name__}: {exc}") from exc
        else:
            out = np.full(len(xy), float(val))
        if not np.all(np.isfinite(out)):
            i = int(np.flatnonzero(~np.isfinite(out))[0])
            raise ConfigError(f"{key} = {out[i]} m s-1 at t = {t:g} s (day {t / 86400:.4f}) on the node at x = "
                              f"{xy[i, 0]:.6g} m, y = {xy[i, 1]:.6g} m; expected a finite velocity")
        return out


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
