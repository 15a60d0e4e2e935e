"""What every benchmark script shares: a run is a bundled scene (``examples/*.toml``)
with ``--set``-style overrides, built by the scene builder
(:func:`lagice.scenes.config.load_scene` + :func:`lagice.scenes.builder.build_simulation`)
and advanced by :class:`lagice.simulation.Simulation` — the production path of
``lagice run``. Anything recorded during a run is a callback activity
(:class:`Recorder`), and kernel timings are read from the stepper
(``kernel_timings``) and the model (``model.timings``) after the run.

    sim = scene_simulation("wind_square", {"domain.resolution_m": 25e3, "run.duration": "1d"})
    rec = Recorder(sim, mean_damage=lambda m: float(m.state.damage.mean()))
    wall = timed_run(sim)
"""
from __future__ import annotations

import atexit
import math
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from lagice.scenes.builder import build_mesh, build_simulation
from lagice.scenes.config import load_scene

#: overrides every benchmark run gets: no progress lines, no figure
QUIET = {"run.progress": False, "output.plot": False}
#: the activities that write files (left out of a timed run unless asked for)
OUTPUT_ACTIVITIES = ("snapshots", "grid", "vtu", "timeseries", "checkpointer")


def scene_config(scene: str, overrides: dict | None = None) -> dict:
    """The validated configuration of bundled ``scene`` with ``overrides``
    (``{"table.key": value}``, as ``lagice run --set``; ``None`` removes an optional table)."""
    return load_scene(scene, {**QUIET, **(overrides or {})})


def scene_simulation(scene: str, overrides: dict | None = None, out_dir=None, outputs: bool = False):
    """A :class:`~lagice.simulation.Simulation` of bundled ``scene`` with ``overrides``,
    built by :func:`~lagice.scenes.builder.build_simulation`.

    ``outputs=False`` (the default) takes the file-writing activities (snapshots,
    time series, checkpoints) out of the run, so that a timed run measures the model
    and the activities every run has (the NaN/speed checker); ``out_dir`` then
    defaults to a temporary folder that is removed at exit."""
    overrides = dict(overrides or {})
    if not outputs:
        # the file-writing activities are taken out below, so their schedules must not stop
        # the build: a benchmark's own solver.dt (a multiple of a stability limit) is rarely a
        # whole divisor of the scene's "6h" (the builder refuses such intervals, rightly, for
        # runs that write). Every outer step, for activities that will not run.
        for key in ("output.every", "checkpoint.every"):
            overrides.setdefault(key, "1 steps")
        overrides.setdefault("output.timeseries", None)
    cfg = scene_config(scene, overrides)
    if out_dir is None:
        out_dir = Path(tempfile.mkdtemp(prefix=f"lagice_bench_{scene}_"))
        _TEMP_DIRS.append(out_dir)
    sim = build_simulation(cfg, out_dir)
    if not outputs:
        for name in OUTPUT_ACTIVITIES:
            sim.activities.pop(name, None)
    return sim


def scene_dx_min(scene: str, overrides: dict | None = None) -> float:
    """Smallest element size sqrt(2 min area) [m] of the scene's mesh (the length in the
    explicit stepper's stability limit), from the mesh alone (no model is built)."""
    mesh, _ = build_mesh(scene_config(scene, overrides))
    return float(math.sqrt(2.0 * mesh.areas().min()))


def reuse_gmsh_meshes() -> dict:
    """Mesh each domain once per process (large benchmark meshes: gmsh takes about 70 s
    for 2M elements, and a benchmark builds the same scene several times).

    Wraps :func:`lagice.mesh.generate_mesh` as the scene builder calls it: the first call
    with a given polygon, size and options runs gmsh; later calls get a copy of that
    mesh (:meth:`lagice.mesh.Mesh.copy`, so a run that moves its nodes leaves the cached
    one alone), which is what gmsh would return again (it is deterministic). Everything
    after gmsh (jitter, renumbering, rotation, the model) is built afresh. Returns the
    statistics dict ``{"gmsh_calls": .., "reused": ..}`` that the wrapper updates."""
    import hashlib
    import pickle

    import lagice.scenes.builder as builder

    real = getattr(builder.generate_mesh, "__wrapped__", builder.generate_mesh)
    cache, stats = {}, {"gmsh_calls": 0, "reused": 0}

    def generate_mesh(polygon, size, **kw):
        try:
            key = hashlib.sha1(pickle.dumps((polygon.wkb, size, sorted(kw.items())))).hexdigest()
        except Exception:  # an unpicklable size field: no caching
            key = None
        if key is None or key not in cache:
            stats["gmsh_calls"] += 1
            mesh = real(polygon, size, **kw)
            if key is None:
                return mesh
            cache[key] = mesh
        else:
            stats["reused"] += 1
        return cache[key].copy()

    generate_mesh.__wrapped__ = real
    builder.generate_mesh = generate_mesh
    return stats


def whole_steps(duration_s: float, dt_s: float) -> int:
    """Outer steps of ``dt_s`` covering ``duration_s`` (the last one may overshoot)."""
    return max(1, int(math.ceil(duration_s / dt_s - 1e-9)))


def timed_run(sim, n_steps: int | None = None) -> float:
    """Wall time [s] of ``sim.run(n_steps)`` (the time loop, its activities included)."""
    t0 = time.perf_counter()
    sim.run(n_steps=n_steps)
    return time.perf_counter() - t0


def reset_timings(model) -> None:
    """Zero the model's component timings and the stepper's kernel timings (after a warm-up)."""
    for k in model.timings:
        model.timings[k] = 0.0
    kt = getattr(model.stepper, "kernel_timings", None)
    if kt is not None:
        for k in kt:
            kt[k] = 0.0
    io = getattr(model.stepper, "_io", None)  # the GPU stepper's copy and launch counts
    if io is not None:
        for k in io.counts:
            io.counts[k] = 0


class Recorder:
    """A callback activity that records named scalar functions of the model after
    every outer step (``every``), into lists: ``rec["name"]``, ``rec.time_s``.
    ``solver_info=True`` also keeps each step's :class:`~lagice.solvers.base.StepInfo`
    (``rec.infos``: iterations, linear iterations, timings of the implicit stepper).
    ``needs_host_state=False``: the functions read no velocity, stress or damage (on a GPU
    stepper the recorder then downloads nothing; see :class:`lagice.activities.Callback`)."""

    def __init__(self, sim, every="1 steps", solver_info: bool = False, name: str = "recorder",
                 needs_host_state: bool = True, **functions):
        self.functions = functions
        self.values = {k: [] for k in functions}
        self.time_s = []
        self.infos = [] if solver_info else None
        sim.add_callback(self, every=every, name=name, needs_host_state=needs_host_state)

    def __call__(self, sim):
        m = sim.model
        self.time_s.append(m.clock.time_s)
        for k, f in self.functions.items():
            self.values[k].append(f(m))
        if self.infos is not None:
            self.infos.append(m.last_report["solver"])

    def __getitem__(self, key) -> np.ndarray:
        return np.asarray(self.values[key])

    def clear(self) -> None:
        self.time_s.clear()
        for v in self.values.values():
            v.clear()
        if self.infos is not None:
            self.infos.clear()


def area_weighted(model, values) -> float:
    area = model.mesh.areas()
    return float(np.average(values, weights=area))


_TEMP_DIRS: list[Path] = []


def _cleanup():
    for d in _TEMP_DIRS:
        shutil.rmtree(d, ignore_errors=True)


atexit.register(_cleanup)
