"""``Simulation``: time stepping, output/checkpoint schedules, callbacks, resume.

    sim = Simulation(model, dt="10min", stop="28d")
    sim.output(every="1d", path="run/out")
    sim.checkpoint(every="2d", path="run/checkpoints", keep=3)
    sim.run()
    sim = Simulation.resume("run/checkpoints")        # or a checkpoint file

Resuming rebuilds the model from the scene configuration stored in the
checkpoint (``builder`` = ``"module:function"`` returning a Simulation) and
continues bit for bit as the uninterrupted run would have.
"""
from __future__ import annotations

import importlib
import math
import sys
import time
from pathlib import Path


from . import __version__
from .errors import ConfigError, RestartError
from .io.checkpoint import latest_valid_checkpoint, read_checkpoint, write_checkpoint
from .io.snapshots import SnapshotWriter
from .schedule import TimeInterval, parse_duration


class Simulation:
    def __init__(self, model, dt, stop, progress: bool = True, builder: str | None = None,
                 progress_every_s: float = 10.0):
        self.model = model
        self.dt = parse_duration(dt, "dt")
        self.stop = parse_duration(stop, "stop")
        if self.dt > self.stop:
            raise ConfigError(f"dt = {self.dt:g} s is longer than the run ({self.stop:g} s)")
        self.n_steps = int(round(self.stop / self.dt))
        if not math.isclose(self.n_steps * self.dt, self.stop, rel_tol=1e-9):
            raise ConfigError(f"stop = {self.stop:g} s is not a whole number of steps of dt = {self.dt:g} s")
        self.progress = progress
        self.progress_every_s = progress_every_s
        self.builder = builder
        self.writer = None
        self.output_schedule = None
        self.ckpt_dir = None
        self.ckpt_schedule = None
        self.ckpt_keep = 3
        self.callbacks = []
        self.wall = {"output": 0.0, "checkpoint": 0.0}
        self.wall_total = 0.0
        self.volume0 = None

    # -- attachments ---------------------------------------------------------------
    def output(self, every, path, crs_epsg: int | None = 3413, vtu: bool = False,
               start_date: str = "2000-01-01 00:00:00", grid_resolution_m: float | None = None):
        self.output_schedule = TimeInterval(every, "output every")
        self.writer = SnapshotWriter(path, crs_epsg=crs_epsg, vtu=vtu, start_date=start_date,
                                     grid_resolution_m=grid_resolution_m)
        return self

    def checkpoint(self, every, path, keep: int = 3):
        if int(keep) < 1:
            raise ConfigError(f"checkpoint keep = {keep!r} must be >= 1")
        self.ckpt_schedule = TimeInterval(every, "checkpoint every")
        self.ckpt_dir = Path(path)
        self.ckpt_keep = int(keep)
        return self

    def add_callback(self, fn, every):
        self.callbacks.append((TimeInterval(every, "callback every"), fn))
        return self

    # -- running ---------------------------------------------------------------------
    def run(self, n_steps: int | None = None) -> dict:
        """Run to the stop time (or ``n_steps`` more steps); returns a summary."""
        model = self.model
        st = model.state
        if self.volume0 is None:
            self.volume0 = st.counters.setdefault("volume0_m3", st.ice_volume_m3)
        target = self.n_steps if n_steps is None else min(self.n_steps, st.step + int(n_steps))
        if st.step == 0 and self.writer is not None:
            self._write_output()
        t_wall0 = time.perf_counter()
        last = t_wall0
        while st.step < target:
            t_prev = st.time_s
            model.step(self.dt)
            st = model.state
            t_now = st.time_s
            if self.writer is not None and (self.output_schedule.due(t_prev, t_now) or st.step == self.n_steps):
                self._write_output()
            for sched, fn in self.callbacks:
                if sched.due(t_prev, t_now):
                    fn(self)
            if self.ckpt_dir is not None and self.ckpt_schedule.due(t_prev, t_now):
                self.write_checkpoint()
            now = time.perf_counter()
            if self.progress and (now - last > self.progress_every_s or st.step == target):
                last = now
                self._print_progress(now - t_wall0)
        self.wall_total += time.perf_counter() - t_wall0
        return self.summary()

    def _write_output(self):
        t0 = time.perf_counter()
        eps = getattr(self.model.solver, "last_strain_rate", None)
        if eps is not None and len(eps) != self.model.mesh.n_elements:
            eps = None
        self.writer.write(self.model.state, eps)
        self.wall["output"] += time.perf_counter() - t0

    def _print_progress(self, wall_s):
        st = self.model.state
        days = st.time_s / 86400.0
        rate = (st.step * self.dt / 86400.0) / max(wall_s, 1e-9) * 3600.0 if wall_s > 0 else float("nan")
        b = self.model.volume_budget()
        print(f"  day {days:7.3f}  step {st.step}/{self.n_steps}  {rate:8.1f} sim-days/wall-hour  "
              f"remeshes {st.counters.get('remesh_count', 0)}  volume {b['current_m3']:.4e} m3 "
              f"(thermo {b['thermodynamic_m3']:+.2e}, outflow {b['outflow_m3']:.2e}, "
              f"drift {b['relative_residual']:+.1e})", flush=True)

    def summary(self) -> dict:
        st = self.model.state
        return {"time_s": st.time_s, "steps": st.step, "wall_s": self.wall_total,
                "timings": {**self.model.timings, **self.wall},
                "remesh_count": st.counters.get("remesh_count", 0),
                "ice_volume_m3": st.ice_volume_m3, "volume_budget": self.model.volume_budget()}

    # -- checkpoint / resume ---------------------------------------------------------
    def _meta(self) -> dict:
        meta = self.model.state_meta()
        meta.update({
            "lagice_version": __version__, "scene_fingerprint": self.model.fingerprint(),
            "config": self.model.config, "builder": self.builder,
            "simulation": {"dt_s": self.dt, "stop_s": self.stop},
        })
        return meta

    def write_checkpoint(self) -> Path:
        t0 = time.perf_counter()
        p = write_checkpoint(self.ckpt_dir, self.model.state.step, self.model.state_arrays(), self._meta(),
                             keep=self.ckpt_keep)
        self.wall["checkpoint"] += time.perf_counter() - t0
        return p

    @classmethod
    def resume(cls, checkpoint, model=None, builder=None, **builder_kw) -> "Simulation":
        """Resume from a checkpoint file or a checkpoint directory (newest usable one).

        The model is rebuilt with the checkpoint's ``builder`` and ``config``
        (or pass ``model=`` / ``builder=``); the scene fingerprint must match.
        """
        path = Path(checkpoint)
        if path.is_dir():
            path, arrays, meta, skipped = latest_valid_checkpoint(path)
            for s in skipped:
                print(f"lagice: skipped damaged checkpoint: {s}", file=sys.stderr)
        else:
            arrays, meta = read_checkpoint(path)
        ver = meta.get("lagice_version")
        if ver != __version__:
            raise RestartError(f"checkpoint {path} was written by lagice {ver}; this is lagice "
                               f"{__version__} (incompatible)")
        if model is None:
            spec = builder or meta.get("builder")
            if not spec:
                raise RestartError(f"checkpoint {path} names no builder; pass model= to resume it")
            sim = _call_builder(spec, meta["config"], **builder_kw)
        else:
            sim = cls(model, dt=meta["simulation"]["dt_s"], stop=meta["simulation"]["stop_s"])
        if sim.model.fingerprint() != meta.get("scene_fingerprint"):
            raise RestartError(f"checkpoint {path} belongs to another scene or configuration "
                               f"(fingerprint {meta.get('scene_fingerprint')}, model {sim.model.fingerprint()})")
        sim.model.load_state(arrays, meta)
        sim.volume0 = sim.model.state.counters.get("volume0_m3")
        sim.resumed_from = path
        return sim


def _call_builder(spec: str, config: dict, **kw):
    mod_name, _, fn_name = spec.partition(":")
    try:
        fn = getattr(importlib.import_module(mod_name), fn_name)
    except (ImportError, AttributeError) as exc:
        raise RestartError(f"cannot import checkpoint builder {spec!r}: {exc}") from exc
    return fn(config, **kw)
