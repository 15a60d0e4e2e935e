"""Component ``remeshing``: after the mesh moved, check the trigger and remesh
distorted patches (:func:`lagice.remesh.remesh_if_needed`), with the target size
field of the scene's initial resolution, fixed in space."""
from __future__ import annotations

from ..errors import ConfigError
from .trigger import TriggerParams

#: options of :func:`lagice.remesh.remesh_if_needed` a scene may set in ``[remesh.params]``
REMESH_OPTIONS = ("rings", "max_retries", "max_patch_fraction", "algorithm", "remap_method", "damage_remap",
                  "density_control", "density_tolerance")


def remeshed_transport(old_mesh, transport, mesh, ev):
    """The step's transport velocity on the remeshed ``mesh`` and its strain rate: kept nodes
    keep theirs, new nodes take it interpolated in ``old_mesh`` (as the state's velocity,
    :func:`lagice.remesh.remesh_region`); ``ev.node_perm`` maps a renumbered mesh."""
    import numpy as np

    from ..fem import shape_gradients, strain_rate
    from .remap import interpolate_nodal

    transport = np.asarray(transport, np.float64)
    n = mesh.n_nodes
    stitched = np.arange(n) if ev.node_perm is None else np.asarray(ev.node_perm)
    kept = stitched < len(ev.kept_nodes)
    v = np.empty((n, 2))
    v[kept] = transport[ev.kept_nodes[stitched[kept]]]
    v[~kept] = interpolate_nodal(old_mesh.nodes, old_mesh.triangles, transport, mesh.nodes[~kept])
    b, c, _ = shape_gradients(mesh.nodes, mesh.triangles)
    return v, strain_rate(mesh.triangles, b, c, v)


#: the trigger's criteria (:func:`lagice.remesh.trigger.check_trigger`), each counted in
#: ``state.counters["remesh_trigger_<criterion>"]``: the remesh events in which it caught at
#: least one element (an event may count under several)
TRIGGER_CRITERIA = ("angle", "near_inversion", "edge_length")


class Remesher:
    """Remesh check after each move; events are appended to :attr:`log` and counted in
    ``state.counters`` (``remesh_count``, ``mesh_epoch``, and ``remesh_trigger_<criterion>`` for
    each of :data:`TRIGGER_CRITERIA`).

    Args:
        size_field: target element size [m] (number or vectorised ``f(x, y)``).
        min_angle_deg: trigger on any angle below this [deg].
        renumber: renumber nodes and elements for memory locality after each remesh
            (the scene's ``domain.renumber``).
        **params: :class:`~lagice.remesh.trigger.TriggerParams` fields and the
            options in :data:`REMESH_OPTIONS`; anything else is a ConfigError naming it.
    """

    name = "remeshing"

    def __init__(self, size_field, min_angle_deg=10.0, renumber: bool = False, **params):
        from . import RemeshLog

        known = set(TriggerParams.__dataclass_fields__) | set(REMESH_OPTIONS)
        for k in params:
            if k not in known:
                raise ConfigError(f"unknown key remesh.params.{k}; known keys: {sorted(known)}")
        self.size_field = size_field
        try:
            self.trigger = TriggerParams(min_angle_deg=min_angle_deg,
                                         **{k: v for k, v in params.items() if k in TriggerParams.__dataclass_fields__})
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"[remesh.params]: {exc}") from None
        self.options = {k: v for k, v in params.items() if k in REMESH_OPTIONS}
        #: density_control: the mesh's area per element / h² at the start of the run (measured at
        #: the first step, carried by checkpoints), the density remeshed patches are held to
        self.density_reference = None
        self.log = RemeshLog()
        #: events before the checkpoint this run resumed from (:meth:`restore`)
        self.n_events_before = 0
        self.renumber = bool(renumber)
        #: callables ``f(state, event)`` run after each successful remesh, after the remap (e.g.
        #: :meth:`lagice.strength.StrengthLaw.apply`: elements get the strength of their size)
        self.after_remesh = []

    def advance(self, model, dt_s: float):
        from . import remesh_if_needed

        st = model.state
        motion = model.component("mesh_motion")
        old_mesh, transport = st.mesh, model.transport_velocity  # the step's, on the mesh it moved
        extra = {}
        if self.options.get("density_control"):
            if self.density_reference is None:
                from .patch import area_per_size2
                # the density the run started with; measured before this step's remesh (the mesh
                # has moved by one step: the area is that of the ice it holds)
                self.density_reference = area_per_size2(st.mesh, self.size_field)
            extra["density_reference"] = self.density_reference
        ev = remesh_if_needed(st, self.size_field, solver=model.stepper, params=self.trigger, **extra,
                              flagged=motion.last_flagged if motion is not None else None, log=self.log,
                              time_s=model.clock.time_s + dt_s, step=model.clock.iteration + 1,
                              before_remap=model.needs_host_state, renumber=self.renumber, **self.options)
        if ev is not None and ev.kind != "failed":
            st.counters["remesh_count"] = st.counters.get("remesh_count", 0) + 1
            st.counters["mesh_epoch"] = st.counters.get("mesh_epoch", 0) + 1
            for k in TRIGGER_CRITERIA:  # events in which each criterion caught an element
                if ev.trigger_counts.get(k, 0) > 0:
                    st.counters[f"remesh_trigger_{k}"] = st.counters.get(f"remesh_trigger_{k}", 0) + 1
            for f in self.after_remesh:
                f(st, ev)
            model.set_remeshed_transport(*remeshed_transport(old_mesh, transport, st.mesh, ev))
        return ev

    @property
    def n_events(self) -> int:
        """Remesh events (failed ones included) over the whole run, parts before a resume included."""
        return self.n_events_before + len(self.log)

    def checkpoint_state(self):
        import numpy as np

        arrays = {} if self.density_reference is None else {
            "density_reference": np.array([self.density_reference], np.float64)}
        return arrays, {"n_events": self.n_events}

    def restore(self, arrays, meta):
        """Carry the event count of the run so far (:attr:`log` holds this session's events only)
        and the density_control reference (a checkpoint without it: measured at the next step)."""
        self.n_events_before = int(meta.get("n_events", 0))
        if "density_reference" in arrays:
            self.density_reference = float(arrays["density_reference"][0])
