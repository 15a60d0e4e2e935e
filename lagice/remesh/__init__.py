"""Remeshing: trigger, local gmsh patches, conservative remapping (docs/design.md §5).

The entry point is :func:`remesh_if_needed`, called once per outer step after
the Lagrangian move (:func:`lagice.lagrangian.move_mesh`)::

    event = remesh_if_needed(state, size_field, solver=solver, log=log)

It checks the trigger (:mod:`.trigger`), remeshes a patch around the bad
elements (:mod:`.patch`; larger patches, then a global remesh, when gmsh
fails or patches grow too large), remaps the element fields of the
:class:`~lagice.state.IceState` that the field registry marks for remapping
(:mod:`lagice.fields`) conservatively (:mod:`.remap`), interpolates the
velocity at new nodes, replaces ``state.mesh`` and calls
``solver.reset_topology(new_mesh)``. It returns a :class:`RemeshEvent`
(diagnostics) or None when nothing needed remeshing. In a model, the
:class:`Remesher` component (:mod:`.component`) calls it once per step.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConfigError, MeshError
from ..fields import remapped_element_fields
from ..mesh import Mesh, angles_deg, renumber_for_locality, signed_areas
from .patch import Stitch, grow_patch, make_manifold, mesh_patch, patch_boundary, stitch, target_element_count
from .remap import interpolate_nodal, intersect_triangles, locate_points, remap_field, remap_weights
from .trigger import TriggerParams, TriggerResult, check_trigger, evaluate_size

__all__ = [
    "RemeshEvent", "RemeshLog", "TriggerParams", "TriggerResult", "check_trigger", "evaluate_size",
    "remesh_if_needed", "remesh_region", "apply_remesh", "remesh_global", "intersect_triangles", "remap_field",
    "remap_weights", "interpolate_nodal", "locate_points", "grow_patch", "element_fields", "totals",
    "Remesher",
]


@dataclass
class RemeshEvent:
    """Diagnostics of one remesh event (times in s, areas m², volumes m³)."""

    time_s: float
    step: int
    kind: str                      # "local", "global" or "failed"
    attempts: list = field(default_factory=list)   # what was tried, with failure reasons
    trigger_counts: dict = field(default_factory=dict)
    n_bad: int = 0
    n_patch_old: int = 0           # elements replaced
    n_patch_new: int = 0           # elements created
    n_nodes_removed: int = 0
    n_nodes_added: int = 0
    n_elements_before: int = 0
    n_elements_after: int = 0
    t_trigger_s: float = 0.0
    t_gmsh_s: float = 0.0
    t_remap_s: float = 0.0
    t_total_s: float = 0.0
    totals_before: dict = field(default_factory=dict)
    totals_after: dict = field(default_factory=dict)
    rel_change: dict = field(default_factory=dict)
    extrema_before: dict = field(default_factory=dict)   # over the patch: name -> (min, max)
    extrema_after: dict = field(default_factory=dict)
    min_angle_before: float = 0.0   # in the patch [deg]
    min_angle_after: float = 0.0
    kept_elements: np.ndarray | None = field(default=None, repr=False)  # old index of new element k < len
    kept_nodes: np.ndarray | None = field(default=None, repr=False)     # old index of new node k < len
    node_perm: np.ndarray | None = field(default=None, repr=False)      # renumbering after the stitch
    element_perm: np.ndarray | None = field(default=None, repr=False)
    n_patch_target: float = float("nan")  # elements the target size gives the patch (density_control)
    size_scale: float = 1.0        # factor on the target size inside the patch (density_control)
    n_patch_at_target_size: int = 0  # elements gmsh made at the target size itself (= n_patch_new without)

    @property
    def elements_touched(self) -> int:
        return self.n_patch_old + self.n_patch_new

    def as_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class RemeshLog:
    """Accumulates :class:`RemeshEvent` s."""

    events: list = field(default_factory=list)

    def append(self, ev: RemeshEvent) -> None:
        self.events.append(ev)

    def __len__(self):
        return len(self.events)

    def summary(self) -> dict:
        ev = self.events
        if not ev:
            return {"n_events": 0}
        rel = [max(abs(v) for v in e.rel_change.values()) if e.rel_change else 0.0 for e in ev]
        return {
            "n_events": len(ev),
            "n_local": sum(e.kind == "local" for e in ev),
            "n_global": sum(e.kind == "global" for e in ev),
            "n_failed": sum(e.kind == "failed" for e in ev),
            "elements_touched": int(sum(e.elements_touched for e in ev)),
            "t_gmsh_s": float(sum(e.t_gmsh_s for e in ev)),
            "t_remap_s": float(sum(e.t_remap_s for e in ev)),
            "t_total_s": float(sum(e.t_total_s for e in ev)),
            "max_rel_change": float(max(rel)),
        }


def element_fields(state) -> dict:
    """The element fields of ``state`` that are remapped (name -> array), from the
    field registry (:func:`lagice.fields.remapped_element_fields`): all are
    area-weighted means over the supermesh, so the extensive totals h·a, A·a,
    hs·a are conserved."""
    return remapped_element_fields(state)


def totals(mesh: Mesh, state) -> dict:
    """Ice volume [m³], ice area [m²] and snow volume [m³] of the whole mesh."""
    from ..mesh.core import _signed_areas_kernel

    a = np.empty(mesh.n_elements)
    _signed_areas_kernel(mesh.nodes, mesh.triangles, a)
    t = {"ice_volume_m3": float(np.sum(state.thickness * a)),
         "ice_area_m2": float(np.sum(state.concentration * a))}
    if state.snow is not None:
        t["snow_volume_m3"] = float(np.sum(state.snow * a))
    return t


def _extrema(fields: dict, sel) -> dict:
    out = {}
    for k, v in fields.items():
        w = v[sel]
        if w.size:
            out[k] = (float(w.min()), float(w.max()))
    return out


#: density_control: at most this many extra gmsh calls per patch, and this factor on the size
DENSITY_ITERATIONS = 5
MAX_SIZE_SCALE = 2.0


def remesh_region(state, mask: np.ndarray, size_field, *, algorithm: int = 6,
                  remap_method: str = "auto", damage_remap: str = "area",
                  density_control: bool = False, density_tolerance: float = 0.01,
                  density_reference: float | None = None):
    """Remesh the elements in ``mask`` (made manifold first) and remap ``state``.

    Returns ``(new_mesh, new_fields, new_velocity, stitch, timings)``; ``state``
    is not modified. Raises :class:`MeshError` on any gmsh/stitch/remap failure.

    ``damage_remap``: ``"area"`` (default) remaps d as an area-weighted mean
    (conserves ∫d da); ``"compliance"`` remaps the compliance 1/(1 − d)
    (keeps the series stiffness across thin damage bands, Åström & Benn 2019 eq. 1,
    at the price of raising ∫d da; see docs/remeshing.md).

    ``density_control``: when gmsh puts more than (1 + ``density_tolerance``) times the
    elements the reference density gives the patch's area (:func:`.patch.target_element_count`;
    ``density_reference``: area per element / h², default gmsh's own inside a large region),
    the patch is meshed again with the size inside it scaled up by √(made / target) (at most
    ``DENSITY_ITERATIONS`` times, to at most ``MAX_SIZE_SCALE``, never finer than the target
    size), and the mesh whose count is nearest the target is kept (docs/remeshing.md,
    "Element count drift").
    The timings then hold ``n_target``, ``size_scale`` and ``n_at_target_size`` (gmsh's count
    at the target size itself).
    """
    if damage_remap not in ("area", "compliance"):
        raise ConfigError(f"damage_remap = {damage_remap!r}; expected 'area' or 'compliance'")
    mesh = state.mesh
    mask = make_manifold(mesh, np.asarray(mask, bool))
    t0 = time.perf_counter()
    bnd = patch_boundary(mesh, mask)
    new_xy, new_tri = mesh_patch(mesh, bnd, size_field, algorithm=algorithm)
    extra = {}
    if density_control:
        pe = np.flatnonzero(mask)
        n_target = target_element_count(mesh, pe, size_field, algorithm, density_reference)
        scale, best = 1.0, 1.0
        trial, tri_first = len(new_tri), new_tri
        if trial > (1.0 + density_tolerance) * n_target:
            # coarser until at or below the target (coming from above: the count is not biased
            # upwards), then the try nearest the target; never finer than the target size
            for _ in range(DENSITY_ITERATIONS):
                new_scale = min(scale * float(np.sqrt(trial / n_target)), MAX_SIZE_SCALE)
                if new_scale <= scale:  # at the bound
                    break
                scale = new_scale
                xy2, tri2 = mesh_patch(mesh, bnd, size_field, algorithm=algorithm, size_scale=scale)
                trial = len(tri2)
                if abs(trial - n_target) < abs(len(new_tri) - n_target):
                    new_xy, new_tri, best = xy2, tri2, scale
                if trial <= n_target:
                    break
        extra = {"n_target": n_target, "size_scale": best, "n_at_target_size": len(tri_first)}
    t_gmsh = time.perf_counter() - t0
    t0 = time.perf_counter()
    st: Stitch = stitch(mesh, mask, new_xy, new_tri)
    nm = st.mesh
    k0 = len(st.kept_elements)
    a_new = signed_areas(nm.nodes, nm.triangles[k0:])
    a_old = signed_areas(mesh.nodes, mesh.triangles[st.patch_elements])
    if np.any(a_new <= 0):
        raise MeshError(f"gmsh patch has {int(np.sum(a_new <= 0))} inverted triangles")
    rel = abs(a_new.sum() - a_old.sum()) / a_old.sum()
    if rel > 1e-9:
        raise MeshError(f"new patch area differs from the old one by {rel:.3g} (relative)")
    i_old, j_new, w = intersect_triangles(mesh.nodes, mesh.triangles[st.patch_elements],
                                          nm.nodes, nm.triangles[k0:], method=remap_method)
    S = remap_weights(i_old, j_new, w, len(a_new), new_areas=a_new)
    fields = {}
    for name, v in element_fields(state).items():
        if name == "damage" and damage_remap == "compliance":
            c = remap_field(1.0 / (1.0 - v[st.patch_elements]), i_old, j_new, w, S)
            vp = 1.0 - 1.0 / c
        else:
            vp = remap_field(v[st.patch_elements], i_old, j_new, w, S)
        fields[name] = np.concatenate([v[st.kept_elements], vp])
    # velocity: kept nodes keep theirs; new nodes interpolated in the old patch
    nk = len(st.kept_nodes)
    vel_new = interpolate_nodal(mesh.nodes, mesh.triangles[st.patch_elements], state.velocity,
                                nm.nodes[nk:])
    velocity = np.concatenate([state.velocity[st.kept_nodes], vel_new])
    t_remap = time.perf_counter() - t0
    return nm, fields, velocity, st, {"gmsh": t_gmsh, "remap": t_remap, **extra}


def apply_remesh(state, nm, fields, velocity, solver=None, kept_nodes=None, renumber: bool = False):
    """Install the result of :func:`remesh_region` in ``state`` (mesh, element
    fields, velocity, ``counters["remesh_events"]``) and reset the solver topology.

    ``kept_nodes`` (old indices of the first new nodes, :class:`Stitch`) carries
    the persistent ``state.node_id`` over; the appended nodes get fresh ids.
    Without it the ids are dropped (``None``: continuity unknown).
    ``renumber``: renumber the new mesh's nodes and elements along a Morton curve
    (:func:`lagice.mesh.renumber_for_locality`; the stitched mesh appends the patch
    at the end, far in memory from its neighbours), the fields and ids with it.
    Returns ``(node_perm, element_perm)`` of that renumbering (None without it)."""
    if kept_nodes is not None:
        old = state.node_id if state.node_id is not None else np.arange(state.mesh.n_nodes, dtype=np.int64)
        nxt = int(state.counters.get("next_node_id", int(old.max()) + 1 if old.size else 0))
        n_new = nm.n_nodes - len(kept_nodes)
        state.node_id = np.concatenate([old[kept_nodes], nxt + np.arange(n_new, dtype=np.int64)])
        state.counters["next_node_id"] = nxt + n_new
    else:
        state.node_id = None
    perms = None
    if renumber:
        nm, pn, pe = renumber_for_locality(nm)
        fields = {k: v[pe] for k, v in fields.items()}
        velocity = velocity[pn]
        if state.node_id is not None:
            state.node_id = state.node_id[pn]
        perms = (pn, pe)
    state.mesh = nm
    for k, v in fields.items():
        setattr(state, k, v)
    state.velocity = velocity
    state.counters["remesh_events"] = int(state.counters.get("remesh_events", 0)) + 1
    if solver is not None:
        solver.reset_topology(nm)
    return perms


def remesh_if_needed(state, size_field, *, solver=None, params: TriggerParams | None = None,
                     rings: int = 2, max_retries: int = 2, max_patch_fraction: float = 0.5,
                     flagged=None, log: RemeshLog | None = None, algorithm: int = 6,
                     remap_method: str = "auto", damage_remap: str = "area",
                     force_global: bool = False, time_s: float = 0.0, step: int = 0,
                     before_remap=None, renumber: bool = False, density_control: bool = False,
                     density_tolerance: float = 0.01, density_reference: float | None = None
                     ) -> RemeshEvent | None:
    """Check the trigger and, if needed, remesh and remap ``state`` in place.

    Args:
        state: :class:`~lagice.state.IceState`; its mesh and element/node fields are replaced.
        size_field: target element size [m] (number or vectorised ``f(x, y)``), fixed in space.
        solver: object with ``reset_topology(mesh)`` (e.g. ImplicitSolver) or None.
        params: trigger thresholds (:class:`TriggerParams`).
        rings: rings of neighbours added around the bad elements.
        max_retries: larger patches (one more ring each) tried after a failure
            before the global remesh.
        max_patch_fraction: a patch larger than this fraction of the mesh is
            replaced by a global remesh.
        flagged: elements flagged by the Lagrangian inversion guard (indices or mask).
        log: :class:`RemeshLog` to append the event to.
        algorithm: gmsh 2-D algorithm (6 Frontal-Delaunay, 5 Delaunay).
        remap_method: ``"auto"``, ``"clip"`` or ``"celltree"`` (:func:`intersect_triangles`).
        damage_remap: ``"area"`` or ``"compliance"`` (:func:`remesh_region`).
        force_global: remesh everything (regardless of the trigger).
        time_s, step: model time [s] and iteration, recorded in the event.
        before_remap: called (no arguments) when the trigger fired, before any field
            is read (:meth:`lagice.model.Model.needs_host_state`: a device stepper's
            fields come to the host only when a remesh happens).
        density_control, density_tolerance, density_reference: hold the element density of
            remeshed patches (:func:`remesh_region`; off by default).
        renumber: renumber the new mesh for memory locality (:func:`apply_remesh`);
            ``kept_elements``/``kept_nodes`` of the event refer to the stitched order
            before it, ``element_perm``/``node_perm`` map it (new k is stitched ``perm[k]``).

    Returns:
        :class:`RemeshEvent`, or None when the trigger found nothing.
        A failed global remesh keeps the old mesh (event kind ``"failed"``).
    """
    if int(rings) < 0:
        raise ConfigError(f"rings = {rings!r} must be >= 0")
    if not 0.0 < max_patch_fraction <= 1.0:
        raise ConfigError(f"max_patch_fraction = {max_patch_fraction!r} must be in (0, 1]")
    t_start = time.perf_counter()
    mesh = state.mesh
    trig = check_trigger(mesh, size_field, params, flagged)
    t_trig = time.perf_counter() - t_start
    if not trig.any and not force_global:
        return None
    if before_remap is not None:
        before_remap()
    m = mesh.n_elements
    ev = RemeshEvent(time_s=float(time_s), step=int(step), kind="failed",
                     trigger_counts=dict(trig.counts), n_bad=int(trig.bad.sum()),
                     n_elements_before=m, t_trigger_s=t_trig)
    fields_before = element_fields(state)
    ev.totals_before = totals(mesh, state)
    result = None
    def candidates():
        if not force_global:
            mask = trig.seeds if trig.seeds is not None else trig.bad
            for r in range(int(rings) + int(max_retries) + 1):
                if r > 0:
                    mask = grow_patch(mesh, mask, 1)
                if r >= int(rings):
                    yield "local", r, mask
        yield "global", -1, np.ones(m, bool)

    for kind, r, mask in candidates():
        if kind == "local" and mask.sum() > max_patch_fraction * m:
            ev.attempts.append(f"local rings={r}: patch of {int(mask.sum())} elements > "
                               f"{max_patch_fraction:g} of the mesh")
            continue
        try:
            result = remesh_region(state, mask, size_field, algorithm=algorithm, remap_method=remap_method,
                                   damage_remap=damage_remap, density_control=density_control,
                                   density_tolerance=density_tolerance, density_reference=density_reference)
        except MeshError as exc:
            ev.attempts.append(f"{kind} rings={r}: {exc}")
            continue
        ev.attempts.append(f"{kind} rings={r}: ok")
        ev.kind = kind
        break
    if result is None:
        ev.t_total_s = time.perf_counter() - t_start
        ev.n_elements_after = m
        if log is not None:
            log.append(ev)
        return ev
    nm, fields, velocity, st, tm = result
    pe = st.patch_elements
    ev.extrema_before = _extrema(fields_before, pe)
    ang_old = angles_deg(mesh.nodes, mesh.triangles[pe])
    ev.min_angle_before = float(np.nanmin(ang_old)) if ang_old.size else 0.0
    k0 = len(st.kept_elements)
    ev.extrema_after = _extrema(fields, slice(k0, None))
    perms = apply_remesh(state, nm, fields, velocity, solver, kept_nodes=st.kept_nodes, renumber=renumber)
    if perms is not None:
        ev.node_perm, ev.element_perm = perms
    ev.min_angle_after = float(np.nanmin(angles_deg(nm.nodes, nm.triangles[k0:])))
    ev.totals_after = totals(state.mesh, state)
    ev.rel_change = {k: (ev.totals_after[k] - v) / v if v != 0 else ev.totals_after[k] - v
                     for k, v in ev.totals_before.items()}
    ev.n_patch_old = len(pe)
    ev.kept_elements = st.kept_elements
    ev.kept_nodes = st.kept_nodes
    ev.n_patch_new = st.n_new_elements
    ev.n_nodes_removed = mesh.n_nodes - len(st.kept_nodes)
    ev.n_nodes_added = st.n_new_nodes
    ev.n_elements_after = nm.n_elements
    ev.t_gmsh_s = tm["gmsh"]
    ev.t_remap_s = tm["remap"]
    ev.n_patch_target = tm.get("n_target", float("nan"))
    ev.size_scale = tm.get("size_scale", 1.0)
    ev.n_patch_at_target_size = tm.get("n_at_target_size", st.n_new_elements)
    ev.t_total_s = time.perf_counter() - t_start
    if log is not None:
        log.append(ev)
    return ev


def remesh_global(state, size_field, **kw) -> RemeshEvent:
    """Remesh the whole domain (boundary nodes kept) and remap ``state``."""
    return remesh_if_needed(state, size_field, force_global=True, **kw)


from .component import Remesher  # noqa: E402  (uses remesh_if_needed above)
