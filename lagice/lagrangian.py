"""Lagrangian mesh motion and mass update (docs/design.md, "Lagrangian mass update").

Every outer step the nodes move with the ice, ``x ← x + u Δt`` with ``u`` the
model's transport velocity (:attr:`lagice.model.Model.transport_velocity`),
and every element keeps the ice it carries:

* ice volume ``V = h·a`` and ice area ``A·a`` are constant, so
  ``h ← h·a_old/a_new`` and ``A ← A·a_old/a_new`` (snow likewise);
* where ``A > 1`` after this, ``A`` is capped at 1 and the volume stays
  (ridging): the element's ice gets thicker. The ridged elements and the ice
  area removed by the cap are counted.

Which nodes move (boundary kinds of :mod:`lagice.mesh.core`):

* ``"coast"`` nodes never move (no-slip, fixed);
* ``"open"`` nodes never move either: an open boundary is a fixed gate in
  space through which ice leaves. The element owning an open edge is a
  control volume whose open face is fixed while the ice moves through it. Its
  ice (spread over the material area ``m = a_new + s``, ``s`` the signed area
  swept through its open edges in Δt, outward positive) loses the part that
  lies outside the gate: ``V ← V·a_new/m`` when ``s > 0``; this volume is
  booked as **outflow** (ice area likewise). Where ice moves inward
  (``s < 0``) open water enters: the volume stays and ``A``, ``h`` are
  diluted by the larger area. No ice ever enters through an open boundary.
* nodes of any other tag (segments with a prescribed velocity, e.g. a pushed
  or sliding wall) and interior nodes move with their velocity.

Inversion guard: a trial position is rejected for every element whose new
signed area would be ≤ ``min_area_ratio`` × its old area. The displacement
of the nodes of such elements is halved (repeatedly, at most
``max_halvings`` times, then set to zero, which always restores a valid
mesh since the old mesh is valid). Every limited node is counted
(``budget["limited_nodes"]``); the elements involved are also flagged for
the remesh trigger.

The budget dict (:func:`new_budget`) makes the volume balance checkable:
``V(t) − V(0) = Σ thermodynamic change − budget["outflow_volume_m3"]``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from .errors import ConfigError, SolverError
from .mesh import OPEN, Mesh
from .mesh.core import _signed_areas_kernel


def new_budget() -> dict:
    """A fresh ice budget (all counters zero). Units in the key names."""
    return {
        "steps": 0,
        "outflow_volume_m3": 0.0,        # ice volume that left through open boundaries
        "outflow_ice_area_m2": 0.0,      # ice area (A·a) that left through open boundaries
        "outflow_snow_volume_m3": 0.0,
        "ridged_elements": 0,            # element-steps in which A was capped at 1
        "ridged_ice_area_m2": 0.0,       # ice area removed by the cap (A − 1)·a
        "limited_nodes": 0,              # node-steps whose displacement was limited (inversion guard)
        "limited_steps": 0,              # steps in which the guard acted
    }


def fixed_node_mask(mesh: Mesh) -> np.ndarray:
    """(n,) bool: nodes that never move (on ``"coast"`` or ``"open"`` edges);
    :attr:`Mesh.fixed_node_mask`, cached on the mesh."""
    return mesh.fixed_node_mask


@njit(cache=True)
def _limit_displacement(nodes, disp, tri, area_old, min_ratio, max_halvings):
    """Scale down displacements of the nodes of elements that would (nearly)
    invert: halve them once per pass, zero them after ``max_halvings`` passes.
    Returns (new node positions, number of limited nodes, flagged elements mask)."""
    n = nodes.shape[0]
    m = tri.shape[0]
    scale = np.ones(n)
    reduce = np.zeros(n, dtype=np.bool_)
    trial = nodes + disp
    area = np.empty(m)
    flagged = np.zeros(m, dtype=np.bool_)
    # zeroing passes terminate: a bad element always has a node not yet zeroed
    for it in range(max_halvings + n + 1):
        _signed_areas_kernel(trial, tri, area)
        nbad = 0
        for e in range(m):
            if area[e] <= min_ratio * area_old[e]:
                nbad += 1
                flagged[e] = True
                for k in range(3):
                    reduce[tri[e, k]] = True
        if nbad == 0:
            break
        for v in range(n):
            if reduce[v]:
                reduce[v] = False
                scale[v] = 0.5 * scale[v] if it < max_halvings else 0.0
                trial[v, 0] = nodes[v, 0] + scale[v] * disp[v, 0]
                trial[v, 1] = nodes[v, 1] + scale[v] * disp[v, 1]
    nlim = 0
    for v in range(n):
        if scale[v] < 1.0:
            nlim += 1
    return trial, nlim, flagged


@njit(cache=True)
def _mass_update(area_old, area_new, swept_out, swept_signed, h, A, snow, has_snow):
    """Keep volume and ice area per element; remove outflow; cap A at 1.

    Returns (outflow volume, outflow ice area, outflow snow, n ridged, ridged ice area)."""
    out_v = 0.0
    out_a = 0.0
    out_s = 0.0
    n_ridged = 0
    ridged_area = 0.0
    for e in range(area_old.shape[0]):
        vol = h[e] * area_old[e]
        iarea = A[e] * area_old[e]
        svol = snow[e] * area_old[e] if has_snow else 0.0
        if swept_out[e] > 0.0:
            mat = area_new[e] + swept_signed[e]
            if mat < area_new[e]:
                mat = area_new[e]
            keep = area_new[e] / mat
            lost_v = vol * (1.0 - keep)
            lost_a = iarea * (1.0 - keep)
            lost_s = svol * (1.0 - keep)
            out_v += lost_v
            out_a += lost_a
            out_s += lost_s
            vol -= lost_v
            iarea -= lost_a
            svol -= lost_s
        h[e] = vol / area_new[e]
        a_new = iarea / area_new[e]
        if a_new > 1.0:
            n_ridged += 1
            ridged_area += (a_new - 1.0) * area_new[e]
            a_new = 1.0
        A[e] = a_new
        if has_snow:
            snow[e] = svol / area_new[e]
    return out_v, out_a, out_s, n_ridged, ridged_area


@dataclass
class MoveReport:
    """What one :func:`move_mesh` call did."""

    limited_nodes: int
    flagged_elements: np.ndarray   # indices of elements that triggered the inversion guard
    outflow_volume_m3: float
    ridged_elements: int
    min_area_ratio: float          # min over elements of a_new / a_old


def move_mesh(state, velocity: np.ndarray, dt_s: float, budget: dict | None = None, *, solver=None,
              min_area_ratio: float = 0.05, max_halvings: int = 8) -> MoveReport:
    """Move the nodes of ``state.mesh`` with ``velocity`` over ``dt_s`` [s] and
    update thickness, concentration and snow per element (module docstring).

    Args:
        state: :class:`~lagice.state.IceState`, modified in place (mesh nodes,
            thickness, concentration, snow).
        velocity: (n, 2) node velocity [m s-1] over the step (the transport velocity).
        dt_s: time step [s], > 0.
        budget: dict from :func:`new_budget`, updated in place (or None).
        solver: if given, ``solver.update_geometry()`` is called after the move.
        min_area_ratio: a move that makes ``a_new ≤ min_area_ratio·a_old`` is
            limited (inversion guard), in (0, 1).
        max_halvings: halvings of a limited node's displacement before it is zeroed.
    """
    if not dt_s > 0:
        raise ConfigError(f"dt_s = {dt_s!r} s must be > 0")
    if not 0.0 < min_area_ratio < 1.0:
        raise ConfigError(f"min_area_ratio = {min_area_ratio!r} must be in (0, 1)")
    mesh = state.mesh
    fixed = mesh.fixed_node_mask
    tri = mesh.triangles
    area_old = np.empty(mesh.n_elements)
    _signed_areas_kernel(mesh.nodes, tri, area_old)
    if np.any(area_old <= 0):
        raise SolverError(f"{int(np.sum(area_old <= 0))} inverted elements before the Lagrangian move")
    velocity = np.asarray(velocity, np.float64)
    if velocity.shape != (mesh.n_nodes, 2):
        raise ConfigError(f"velocity has shape {velocity.shape}; expected ({mesh.n_nodes}, 2)")
    disp = velocity * dt_s
    disp[fixed] = 0.0
    new_nodes, nlim, flagged = _limit_displacement(mesh.nodes, disp, tri, area_old,
                                                   float(min_area_ratio), int(max_halvings))
    area_new = np.empty(mesh.n_elements)
    _signed_areas_kernel(new_nodes, tri, area_new)
    swept_out = np.zeros(mesh.n_elements)
    swept_signed = np.zeros(mesh.n_elements)
    if mesh.has_tag(OPEN):
        sel = mesh.boundary_tags == mesh.tag_id(OPEN)
        if sel.any():
            edges = mesh.boundary_edges[sel]
            owner = mesh._topology_cache.get("open_edge_owner")
            if owner is None:  # sorts 3 m keys: about 4 ms at 28k elements, so once per mesh
                owner = mesh._topology_cache["open_edge_owner"] = _edge_owner(mesh, edges)
            d = mesh.nodes[edges[:, 1]] - mesh.nodes[edges[:, 0]]
            # outward normal (times length) of an edge with the domain on its left
            nx, ny = d[:, 1], -d[:, 0]
            u = 0.5 * (velocity[edges[:, 0]] + velocity[edges[:, 1]])
            s = (u[:, 0] * nx + u[:, 1] * ny) * dt_s
            np.add.at(swept_signed, owner, s)
            np.add.at(swept_out, owner, np.maximum(s, 0.0))
    has_snow = state.snow is not None
    snow = state.snow if has_snow else np.zeros(1)
    out_v, out_a, out_s, n_ridged, r_area = _mass_update(area_old, area_new, swept_out, swept_signed,
                                                         state.thickness, state.concentration,
                                                         snow, has_snow)
    mesh.nodes[:] = new_nodes
    if solver is not None:
        solver.update_geometry()
    if budget is not None:
        budget["steps"] += 1
        budget["outflow_volume_m3"] += out_v
        budget["outflow_ice_area_m2"] += out_a
        budget["outflow_snow_volume_m3"] += out_s
        budget["ridged_elements"] += int(n_ridged)
        budget["ridged_ice_area_m2"] += r_area
        budget["limited_nodes"] += int(nlim)
        budget["limited_steps"] += int(nlim > 0)
    return MoveReport(int(nlim), np.flatnonzero(flagged), float(out_v), int(n_ridged),
                      float(np.min(area_new / area_old)) if len(area_new) else 1.0)


def _edge_owner(mesh: Mesh, edges: np.ndarray) -> np.ndarray:
    """Element owning each (directed, domain on the left) boundary edge."""
    tri = mesh.triangles
    m = len(tri)
    n = np.int64(mesh.n_nodes)
    keys = np.concatenate([tri[:, 0] * n + tri[:, 1], tri[:, 1] * n + tri[:, 2], tri[:, 2] * n + tri[:, 0]])
    elem = np.concatenate([np.arange(m)] * 3)
    order = np.argsort(keys, kind="stable")
    q = edges[:, 0] * n + edges[:, 1]
    pos = np.searchsorted(keys[order], q)
    pos = np.minimum(pos, len(keys) - 1)
    if not np.all(keys[order][pos] == q):
        raise SolverError("a boundary edge does not belong to any element (mesh inconsistent)")
    return elem[order][pos]


class MeshMotion:
    """Component ``mesh_motion``: moves the nodes with the model's transport velocity
    (:func:`move_mesh`), refreshes the stepper's geometry and books the outflow
    through open boundaries in the model's volume ledger. Ridging and the
    inversion guard are counted in :attr:`budget` (carried in checkpoints)."""

    name = "mesh_motion"

    def __init__(self, min_area_ratio: float = 0.05, max_halvings: int = 8):
        if not 0.0 < min_area_ratio < 1.0:
            raise ConfigError(f"lagrangian.min_area_ratio = {min_area_ratio!r} must be in (0, 1)")
        if int(max_halvings) != max_halvings or max_halvings < 0:
            raise ConfigError(f"lagrangian.max_halvings = {max_halvings!r} must be an integer >= 0")
        self.min_area_ratio = float(min_area_ratio)
        self.max_halvings = int(max_halvings)
        self.budget = new_budget()
        self.last_flagged = None

    def advance(self, model, dt_s: float) -> MoveReport:
        out0 = self.budget["outflow_volume_m3"]
        rep = move_mesh(model.state, model.transport_velocity, dt_s, self.budget, solver=model.stepper,
                        min_area_ratio=self.min_area_ratio, max_halvings=self.max_halvings)
        model.ledger.book("outflow", -(self.budget["outflow_volume_m3"] - out0))
        self.last_flagged = rep.flagged_elements
        return rep

    def checkpoint_state(self):
        return {}, {"budget": dict(self.budget)}

    def restore(self, arrays, meta):
        self.budget.update(meta.get("budget", {}))

