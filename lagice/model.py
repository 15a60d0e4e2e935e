"""``Model``: mesh + state + rheology + solver + (optional) forcing, thermodynamics,
healing, mesh motion and remeshing. A component that is not given is not
built and costs nothing in a step (STYLE.md: Oceananigans-like shape)."""
from __future__ import annotations

import hashlib
import json
import time

import numpy as np

from .errors import ConfigError
from .mesh import Mesh
from .rheology import MaxwellEB
from .solvers import SOLVERS
from .state import IceState

STATE_FIELDS = ("thickness", "concentration", "damage", "stress", "cohesion")
COMPONENTS = ("thermo", "mover", "remesher", "drifters")


class Model:
    """A runnable sea-ice model.

    Args:
        state: :class:`~lagice.state.IceState` (its ``mesh`` is the model mesh).
        rheology: :class:`~lagice.rheology.MaxwellEB` (default parameters if None).
        solver: solver name (``"implicit"``, ``"explicit"``, ...) or a built solver.
        solver_options: keyword options for the solver constructor.
        bcs: list of :class:`~lagice.solvers.VelocityBC`.
        forces: external forces (wind, ocean drag, Coriolis) passed to the solver.
        thermo: object with ``step(state, t_s, dt_s) -> dict`` or None (off).
        healing: callable ``(state, t_s) -> heal rate (m,) [s-1]`` or None
            (the rheology's constant rate, or none if its healing time is None).
        mover: object with ``advance(state, dt_s) -> dict`` moving nodes with the
            ice (Lagrangian step) or None (fixed mesh, small-deformation runs).
        remesher: object with ``__call__(state, solver) -> event | None`` or None.
        config: the scene configuration (a JSON-able dict) that rebuilds this model;
            stored in checkpoints, and its hash is the scene fingerprint.
        rng: numpy Generator carried in checkpoints.
    """

    def __init__(self, state: IceState, rheology: MaxwellEB | None = None, solver="implicit",
                 solver_options: dict | None = None, bcs=(), forces=(), thermo=None, healing=None,
                 mover=None, remesher=None, drifters=None, config: dict | None = None, rng=None):
        self.state = state
        self.rheology = rheology or MaxwellEB()
        self.forces = list(forces)
        self.thermo = thermo
        self.healing = healing
        self.mover = mover
        self.remesher = remesher
        self.drifters = drifters
        self.config = config or {}
        self.rng = rng if rng is not None else np.random.default_rng(0)
        opts = dict(solver_options or {})
        if isinstance(solver, str):
            if solver not in SOLVERS:
                raise ConfigError(f"solver = {solver!r} is unknown; expected one of {sorted(SOLVERS)}")
            heal = None
            if healing is not None:
                heal = lambda st: healing(st, st.time_s)  # noqa: E731
            self.solver = SOLVERS[solver](self.rheology, state.mesh, bcs=bcs, forces=self.forces,
                                          heal_rate=heal, **opts)
        else:
            self.solver = solver
        self.timings = {"dynamics": 0.0, "mesh_motion": 0.0, "thermodynamics": 0.0, "remeshing": 0.0}
        self.remesh_events = []

    @property
    def mesh(self) -> Mesh:
        return self.state.mesh

    def step(self, dt_s: float) -> dict:
        """Advance one outer step; returns a report of what happened."""
        st = self.state
        t0 = time.perf_counter()
        info = self.solver.step(st, dt_s)
        t1 = time.perf_counter()
        self.timings["dynamics"] += t1 - t0
        report = {"solver": info}
        if self.mover is not None:
            report["motion"] = self.mover.advance(st, dt_s)
            self.solver.update_geometry()
            t2 = time.perf_counter()
            self.timings["mesh_motion"] += t2 - t1
            t1 = t2
        if self.thermo is not None:
            report["thermo"] = self.thermo.step(st, st.time_s, dt_s)
            t2 = time.perf_counter()
            self.timings["thermodynamics"] += t2 - t1
            t1 = t2
        if self.remesher is not None:
            ev = self.remesher(st, self.solver)
            if ev is not None and getattr(ev, "kind", "") != "failed":
                self.remesh_events.append(ev)
                st.counters["remesh_count"] = st.counters.get("remesh_count", 0) + 1
                st.counters["mesh_epoch"] = st.counters.get("mesh_epoch", 0) + 1
            report["remesh"] = ev
            self.timings["remeshing"] += time.perf_counter() - t1
        if self.drifters is not None:
            self.drifters.advance(st, dt_s)
        return report

    def volume_budget(self) -> dict:
        """Ice volume budget [m³]: V(t) − V(0) = thermodynamic change − outflow + residual.

        The residual is what mesh motion and remapping did to the volume
        (round-off when they conserve it)."""
        st = self.state
        v0 = st.counters.get("volume0_m3", st.ice_volume_m3)
        thermo = 0.0
        if self.thermo is not None and getattr(self.thermo, "budget", None) is not None:
            thermo = float(self.thermo.budget.thermo_m3)
        outflow = 0.0
        if self.mover is not None and hasattr(self.mover, "budget"):
            outflow = float(self.mover.budget.get("outflow_volume_m3", 0.0))
        v = st.ice_volume_m3
        res = v - v0 - thermo + outflow
        return {"initial_m3": v0, "current_m3": v, "thermodynamic_m3": thermo, "outflow_m3": outflow,
                "residual_m3": res, "relative_residual": res / v0 if v0 else 0.0}

    # -- checkpoint support ------------------------------------------------------
    def fingerprint(self) -> str:
        """Hash of the scene configuration: a checkpoint resumes only the same scene."""
        cfg = {k: v for k, v in self.config.items() if not k.startswith("_")}  # e.g. _out_dir
        blob = json.dumps(cfg, sort_keys=True, default=str).encode()
        return hashlib.sha256(blob).hexdigest()[:16]

    def state_arrays(self) -> dict:
        st = self.state
        m = st.mesh
        arrays = {
            "mesh_nodes": m.nodes, "mesh_triangles": m.triangles,
            "mesh_boundary_edges": m.boundary_edges, "mesh_boundary_tags": m.boundary_tags,
            "velocity": st.velocity,
        }
        for name in STATE_FIELDS:
            arrays[name] = getattr(st, name)
        if st.snow is not None:
            arrays["snow"] = st.snow
        if st.node_id is not None:
            arrays["node_id"] = st.node_id
        for name, arr in self.extra_arrays().items():
            arrays[f"extra_{name}"] = arr
        return arrays

    def extra_arrays(self) -> dict:
        """Arrays of components that carry state (e.g. a thermodynamic budget)."""
        out = {}
        for comp_name in COMPONENTS:
            comp = getattr(self, comp_name)
            if comp is not None and hasattr(comp, "checkpoint_arrays"):
                for k, v in comp.checkpoint_arrays().items():
                    out[f"{comp_name}_{k}"] = v
        return out

    def state_meta(self) -> dict:
        st = self.state
        comp = {}
        for comp_name in COMPONENTS:
            c = getattr(self, comp_name)
            if c is not None and hasattr(c, "checkpoint_meta"):
                comp[comp_name] = c.checkpoint_meta()
        return {"time_s": st.time_s, "step": st.step, "counters": st.counters,
                "tag_names": list(st.mesh.tag_names), "rng_state": _rng_state_json(self.rng),
                "rheology_capped": self.rheology.n_capped_total, "components": comp,
                "timings": self.timings}

    def load_state(self, arrays: dict, meta: dict) -> None:
        """Replace the state with checkpointed arrays (exact, bit for bit)."""
        mesh = Mesh(arrays["mesh_nodes"].copy(), arrays["mesh_triangles"].copy(),
                    arrays["mesh_boundary_edges"].copy(), arrays["mesh_boundary_tags"].copy(),
                    tuple(meta["tag_names"]))
        st = IceState(mesh=mesh, velocity=arrays["velocity"].copy(),
                      **{name: arrays[name].copy() for name in STATE_FIELDS},
                      snow=arrays["snow"].copy() if "snow" in arrays else None,
                      node_id=arrays["node_id"].copy() if "node_id" in arrays else None,
                      time_s=float(meta["time_s"]), step=int(meta["step"]),
                      counters=dict(meta["counters"]))
        self.state = st
        self.rng.bit_generator.state = _rng_state_from_json(meta["rng_state"])
        self.rheology.n_capped_total = int(meta.get("rheology_capped", 0))
        self.timings = dict(meta.get("timings", self.timings))
        self.solver.reset_topology(mesh)
        comp_meta = meta.get("components", {})
        for comp_name in COMPONENTS:
            c = getattr(self, comp_name)
            if c is not None and hasattr(c, "load_checkpoint"):
                pre = f"extra_{comp_name}_"
                c.load_checkpoint({k[len(pre):]: v for k, v in arrays.items() if k.startswith(pre)},
                                  comp_meta.get(comp_name, {}))


def _rng_state_json(rng) -> dict:
    s = rng.bit_generator.state
    return json.loads(json.dumps(s, default=int))


def _rng_state_from_json(s: dict) -> dict:
    return s
