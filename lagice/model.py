"""``Model``: the state, the clock, a rheology, the time stepper that solves it, and
optional components (drifters, mesh motion, thermodynamics, remeshing, healing).

The model owns the clock and the step (docs/design.md, "Architecture"):

    info = stepper.step(state, t, Δt)       # velocity, stress, damage over [t, t+Δt]
    for component in (drifters, mesh_motion, thermodynamics, remeshing):
        component.advance(model, Δt)         # with model.transport_velocity
    clock.tick(Δt)

A component that is not given is not built and costs nothing in a step.
"""
from __future__ import annotations

import hashlib
import json
import time

import numpy as np

from .budget import VolumeLedger
from .clock import Clock
from .components import ORDER
from .errors import ConfigError, SolverError
from .fields import FIELDS, checkpoint_arrays
from .mesh import Mesh
from .rheology import RHEOLOGIES, MaxwellEB
from .solvers import SOLVER_RHEOLOGY, SOLVERS, TimeStepper
from .state import IceState

#: the keys of :attr:`Model.timings` [s], per component
TIMING_KEYS = ("dynamics", "drifters", "mesh_motion", "thermodynamics", "remeshing")


class Model:
    """A runnable sea-ice model.

    Args:
        state: :class:`~lagice.state.IceState` (its ``mesh`` is the model mesh).
        rheology: :class:`~lagice.rheology.MaxwellEB` (default) or
            :class:`~lagice.rheology.ViscousPlastic`.
        solver: time-stepper name (``"implicit"``, ``"explicit"``, ``"evp"``,
            ``"prescribed"``) or a built stepper (:class:`~lagice.solvers.TimeStepper`).
        solver_options: keyword options for the stepper constructor.
        bcs: list of :class:`~lagice.boundary.VelocityBC`.
        forces: external forces (wind, ocean drag, Coriolis) passed to the stepper.
        thermo: ``thermodynamics`` component (:class:`thermo.model_adapters.ThermoComponent`) or None.
        healing: ``healing`` component (``rate(state, t_s) -> (m,) [s-1]``) or None
            (the rheology's constant rate, or none if its healing time is None).
        mover: ``mesh_motion`` component (:class:`lagice.lagrangian.MeshMotion`) or
            None (fixed mesh, small-deformation runs).
        remesher: ``remeshing`` component (:class:`lagice.remesh.Remesher`) or None.
        drifters: ``drifters`` component (:class:`lagice.drifters.Drifters`) or None.
        config: the scene configuration (a JSON-able dict) that rebuilds this model;
            stored in checkpoints.
        fingerprint_config: the part of ``config`` that determines the trajectory
            (default: all of it); its hash is the checkpoint fingerprint.
        rng: numpy Generator carried in checkpoints.
    """

    def __init__(self, state: IceState, rheology=None, solver="implicit", solver_options: dict | None = None,
                 bcs=(), forces=(), thermo=None, healing=None, mover=None, remesher=None, drifters=None,
                 config: dict | None = None, fingerprint_config: dict | None = None, rng=None):
        self.state = state
        self.clock = Clock()
        self.rheology = rheology if rheology is not None else MaxwellEB()
        self.forces = list(forces)
        self.healing = healing
        self.config = config or {}
        self.fingerprint_config = fingerprint_config
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.ledger = VolumeLedger()
        self.ledger.start(state.ice_volume_m3)
        opts = dict(solver_options or {})
        if isinstance(solver, str):
            if solver not in SOLVERS:
                raise ConfigError(f"solver = {solver!r} is unknown; expected one of {sorted(SOLVERS)}")
            want = SOLVER_RHEOLOGY[solver]
            if want is not None and not isinstance(self.rheology, RHEOLOGIES[want]):
                raise ConfigError(f"solver {solver!r} solves the {want} rheology; the model's rheology is "
                                  f"{getattr(self.rheology, 'name', type(self.rheology).__name__)} "
                                  f"(set rheology.law = {want!r} or choose another solver)")
            heal = healing.rate if healing is not None else None
            self.stepper = SOLVERS[solver](self.rheology, state.mesh, bcs=bcs, forces=self.forces,
                                           heal_rate=heal, **opts)
        else:
            if not isinstance(solver, TimeStepper):
                raise ConfigError(f"solver {solver!r} does not follow the TimeStepper protocol "
                                  f"(step, reset_topology, update_geometry, transport_velocity, last_strain_rate)")
            self.stepper = solver
        given = {"drifters": drifters, "mesh_motion": mover, "thermodynamics": thermo, "remeshing": remesher}
        self.components = [given[name] for name in ORDER if given[name] is not None]
        self.timings = dict.fromkeys(TIMING_KEYS, 0.0)
        self.last_report = {}
        #: (transport velocity, strain rate) of the step that ended with a remesh, on the new
        #: mesh (:meth:`set_remeshed_transport`): the stepper dropped its own with the old mesh
        self._remeshed_transport = None
        #: add Δt × the stepper's strain rate to ``state.strain_accumulated`` every step
        #: (``output.accumulate_strain``; :meth:`step`)
        self.accumulate_strain = False

    # -- the pieces ----------------------------------------------------------------
    @property
    def mesh(self) -> Mesh:
        return self.state.mesh

    @property
    def solver(self):
        """The time stepper (old name, kept for scripts)."""
        return self.stepper

    def component(self, name: str):
        """The component called ``name``, or None when the model has none."""
        if name == "healing":
            return self.healing
        for c in self.components:
            if c.name == name:
                return c
        return None

    @property
    def drifters(self):
        return self.component("drifters")

    @property
    def transport_velocity(self) -> np.ndarray:
        """(n, 2) [m s-1] the velocity that moves the nodes, the drifters and every
        Lagrangian displacement over the last step: the stepper's time-mean velocity
        over the step (docs/design.md, "Which velocity moves the mesh"). Before the
        first step, the state's velocity."""
        v = self.stepper.transport_velocity
        if v is None and self._remeshed_transport is not None and len(self._remeshed_transport[0]) == \
                self.mesh.n_nodes:
            return self._remeshed_transport[0]
        return self.state.velocity if v is None else v

    def set_remeshed_transport(self, velocity, strain_rate) -> None:
        """The last step's transport velocity (n, 2) [m s-1] and its strain rate (m, 3)
        [s-1] carried onto the mesh a remesh at the end of that step made (the remeshing
        component: kept nodes keep theirs, new nodes interpolated, as the state's velocity
        is). Only what is read after the step sees it (outputs, the NaN check): the stepper
        dropped its own with the old mesh, and the next step replaces both."""
        self._remeshed_transport = (velocity, strain_rate)

    def needs_host_state(self, fields=None) -> IceState:
        """The state, with the fields a device stepper keeps on its device between
        steps (velocity, stress, damage: ``CudaExplicitSolver(sync="explicit")``,
        docs/gpu.md) brought up to date on the host. Call before reading or editing
        them between steps (scheduled activities, checkpoints and remeshing do);
        free for CPU steppers, whose host state is always current."""
        to_host = getattr(self.stepper, "to_host", None)
        if to_host is not None:
            if fields is None:
                to_host(self.state)
            else:
                to_host(self.state, tuple(fields))
        return self.state

    def device_checked_fields(self, max_speed_m_s: float) -> tuple:
        """State fields a device stepper found finite, with ice speeds below
        ``max_speed_m_s`` [m s-1], at the end of the last step (so the NaN checker
        need not download them); () for CPU steppers. When the device found a
        problem, the fields are downloaded (:meth:`needs_host_state`) and () returned."""
        check = getattr(self.stepper, "device_check", None)
        if check is None:
            return ()
        fields, ok = check(max_speed_m_s)
        if ok:
            return tuple(fields)
        self.needs_host_state()
        return ()

    @property
    def strain_rate(self) -> np.ndarray | None:
        """(m, 3) [s-1] strain rate of the transport velocity over the last step."""
        eps = self.stepper.last_strain_rate
        if eps is None and self._remeshed_transport is not None:
            eps = self._remeshed_transport[1]
        if eps is not None and len(eps) != self.mesh.n_elements:
            return None
        return eps

    # -- one step --------------------------------------------------------------------
    def step(self, dt_s: float) -> dict:
        """Advance one outer step of ``dt_s`` [s]; returns a report of what happened."""
        st = self.state
        t0 = time.perf_counter()
        info = self.stepper.step(st, self.clock.time_s, dt_s)
        t1 = time.perf_counter()
        self.timings["dynamics"] += t1 - t0
        report = {"solver": info}
        self._accumulate_strain(dt_s)
        if not np.all(np.isfinite(self.transport_velocity)):
            # the dynamics blew up: components must not consume a non-finite velocity
            # (mesh motion, gmsh); the simulation's NaN checker names the field and place
            report["non_finite"] = True
            self.clock.tick(dt_s)
            self.last_report = report
            return report
        for comp in self.components:
            report[comp.name] = comp.advance(self, dt_s)
            t2 = time.perf_counter()
            self.timings[comp.name] = self.timings.get(comp.name, 0.0) + t2 - t1
            t1 = t2
        self.clock.tick(dt_s)
        self.last_report = report
        return report

    def _accumulate_strain(self, dt_s: float) -> None:
        """``state.strain_accumulated`` += Δt × the strain rate the stepper's rheology used over
        the step (m, 3) [-], on the mesh before it moves (``output.accumulate_strain``). With
        linear velocities it is the strain rate of the velocity that moves the nodes; with
        Crouzeix–Raviart velocities it is the elements' own, which the nodes follow only in the
        mean (docs/solvers.md, "What the mesh follows"), so a window's statistics can be taken
        from both (``benchmarks/window_split.py``). Remeshing remaps it as an area-weighted mean
        (∫ strain da is kept). The accumulation starts at the first step that asks for it
        (``counters["strain_accumulated_since_s"]``, also after a resume from a checkpoint
        without the field); a run that stops asking drops the field."""
        st = self.state
        if not self.accumulate_strain:
            if st.strain_accumulated is not None:
                st.strain_accumulated = None
                st.counters.pop("strain_accumulated_since_s", None)
            return
        eps = self.stepper.last_strain_rate
        if eps is None or len(eps) != self.mesh.n_elements:
            raise SolverError(f"output.accumulate_strain: the {type(self.stepper).__name__} stepper reported no strain "
                              f"rate for this mesh at step {self.clock.iteration}")
        if st.strain_accumulated is None:
            st.strain_accumulated = np.zeros((self.mesh.n_elements, 3))
            st.counters["strain_accumulated_since_s"] = float(self.clock.time_s)
        st.strain_accumulated += dt_s * np.asarray(eps, np.float64)

    def volume_budget(self) -> dict:
        """Ice volume budget [m³]: V(t) − V(0) = thermodynamic change − outflow + residual.

        The residual is what mesh motion and remapping did to the volume
        (round-off when they conserve it)."""
        return self.ledger.budget(self.state.ice_volume_m3)

    # -- checkpoint support ------------------------------------------------------
    def fingerprint(self, without=()) -> str:
        """Hash of the configuration that determines the trajectory: a checkpoint
        resumes only a model with the same physics. ``without``: dotted keys
        (``"solver.substep_limit"``) left out of the hash, as the code of a version
        that did not have them hashed it (:meth:`lagice.simulation.Simulation.resume`)."""
        cfg = self.fingerprint_config if self.fingerprint_config is not None else self.config
        cfg = {k: v for k, v in cfg.items() if not k.startswith("_")}
        for key in without:
            table, _, name = key.partition(".")
            if name and isinstance(cfg.get(table), dict):
                cfg[table] = {k: v for k, v in cfg[table].items() if k != name}
            else:
                cfg.pop(table, None)
        blob = json.dumps(cfg, sort_keys=True, default=str).encode()
        return hashlib.sha256(blob).hexdigest()[:16]

    def state_arrays(self) -> dict:
        """Every array a checkpoint needs: the mesh, the registry's checkpointed
        state fields and the components' arrays (``component.<name>.<array>``)."""
        st = self.needs_host_state()
        m = st.mesh
        arrays = {"mesh_nodes": m.nodes, "mesh_triangles": m.triangles,
                  "mesh_boundary_edges": m.boundary_edges, "mesh_boundary_tags": m.boundary_tags}
        arrays.update(checkpoint_arrays(st))
        for comp in self.components:
            for k, v in comp.checkpoint_state()[0].items():
                arrays[f"component.{comp.name}.{k}"] = v
        # a stepper's own dynamic state beyond the state's fields (the explicit stepper's
        # Crouzeix–Raviart edge velocities), so that a resume is bit for bit
        for k, v in getattr(self.stepper, "checkpoint_arrays", dict)().items():
            arrays[f"stepper.{k}"] = v
        return arrays

    def state_meta(self) -> dict:
        st = self.state
        return {"clock": self.clock.as_dict(), "counters": st.counters,
                "tag_names": list(st.mesh.tag_names), "rng_state": _rng_state_json(self.rng),
                "rheology_capped": self.rheology.n_capped_total, "ledger": self.ledger.as_dict(),
                "components": {c.name: c.checkpoint_state()[1] for c in self.components},
                "timings": self.timings}

    def load_state(self, arrays: dict, meta: dict, fresh_components: bool = False) -> list[str]:
        """Replace the state with checkpointed arrays (exact, bit for bit).

        A component of this model that the checkpoint does not hold is an error, or,
        with ``fresh_components`` (a branch that switches a component on), keeps its
        freshly built state; returns the names of such components."""
        mesh = Mesh(arrays["mesh_nodes"].copy(), arrays["mesh_triangles"].copy(),
                    arrays["mesh_boundary_edges"].copy(), arrays["mesh_boundary_tags"].copy(),
                    tuple(meta["tag_names"]))
        kw = {name: (arrays[name].copy() if name in arrays else None)
              for name, spec in FIELDS.items() if spec.checkpoint}
        self.state = IceState(mesh=mesh, counters=dict(meta["counters"]), **kw)
        clock = meta["clock"]
        self.clock = Clock(float(clock["time_s"]), int(clock["iteration"]))
        self.rng.bit_generator.state = meta["rng_state"]
        self.rheology.n_capped_total = int(meta.get("rheology_capped", 0))
        self.ledger = VolumeLedger.from_dict(meta["ledger"])
        self.timings = {**dict.fromkeys(TIMING_KEYS, 0.0), **meta.get("timings", {})}
        self.stepper.reset_topology(mesh)
        held = {k[len("stepper."):]: v for k, v in arrays.items() if k.startswith("stepper.")}
        if held or hasattr(self.stepper, "restore_arrays"):
            restore = getattr(self.stepper, "restore_arrays", None)
            if restore is None:
                raise ConfigError(f"the checkpoint holds stepper arrays {sorted(held)} that the "
                                  f"{type(self.stepper).__name__} stepper does not read")
            restore(held)
        comp_meta = meta.get("components", {})
        fresh = []
        for c in self.components:
            pre = f"component.{c.name}."
            held = {k[len(pre):]: v for k, v in arrays.items() if k.startswith(pre)}
            if c.name not in comp_meta and not held:
                if not fresh_components:
                    from .errors import RestartError

                    raise RestartError(f"the checkpoint holds no state of component {c.name!r}, which this model has")
                fresh.append(c.name)
                continue
            c.restore(held, comp_meta.get(c.name, {}))
        return fresh


def _rng_state_json(rng) -> dict:
    s = rng.bit_generator.state
    return json.loads(json.dumps(s, default=int))
