"""``Simulation``: the one time loop of lagice, and the activities scheduled on it.

    sim = Simulation(model, dt="10min", stop="28d")
    sim.output(every="1d", path="run/snapshots")             # UGRID/CF snapshots
    sim.checkpoint(every="2d", path="run/checkpoints", keep=3)
    sim.add_timeseries("run/timeseries.nc", ["ice_volume", "mean_damage"], every="1h")
    sim.add_callback(my_function, every="6h")
    sim.run()
    sim = Simulation.resume("run/checkpoints")               # or a checkpoint file

The loop is ``model.step(dt)`` followed by every activity whose schedule is due
(:mod:`lagice.activities`). Resuming rebuilds the model from the scene
configuration stored in the checkpoint (``builder`` = ``"module:function"``
returning a Simulation) and continues bit for bit as the uninterrupted run would
have.
"""
from __future__ import annotations

import importlib
import math
import sys
import time
from pathlib import Path

from . import __version__
from .activities import (
    Activity,
    Callback,
    Checkpointer,
    DrifterOutput,
    GridOutput,
    NaNChecker,
    Progress,
    SignalStop,
    SnapshotOutput,
    TimeSeriesOutput,
    VTUOutput,
)
from .errors import ConfigError, RestartError
from .io.checkpoint import FORMAT_VERSION, latest_valid_checkpoint, read_checkpoint, write_checkpoint
from .remesh.component import TRIGGER_CRITERIA
from .schedule import parse_duration


class Simulation:
    """Runs a :class:`~lagice.model.Model` with a fixed outer step ``dt`` until ``stop``.

    Args:
        model: the model.
        dt: outer step (duration string or seconds).
        stop: simulated time to stop at (duration string or seconds since the start).
        progress: print a progress line every ``progress_every_s`` of wall time.
        builder: ``"module:function"`` that rebuilds this simulation from
            ``model.config`` (stored in checkpoints for :meth:`resume`).
        nan_check: stop with a clear error at the first NaN/Inf in the state, or at an
            ice speed above ``max_speed_m_s`` [m s-1] (:class:`~lagice.activities.NaNChecker`).
        handle_signals: stop cleanly on SIGTERM/SIGINT (:class:`~lagice.activities.SignalStop`):
            checkpoint (if there is a checkpointer), end-of-run outputs, ``stop_reason``.
    """

    def __init__(self, model, dt, stop, progress: bool = True, builder: str | None = None,
                 progress_every_s: float = 10.0, nan_check: bool = True, max_speed_m_s: float = 10.0,
                 handle_signals: bool = True):
        self.model = model
        self.dt = parse_duration(dt, "dt")
        self.stop_time = parse_duration(stop, "stop")
        if self.dt > self.stop_time:
            raise ConfigError(f"dt = {self.dt:g} s is longer than the run ({self.stop_time:g} s)")
        self.n_steps = int(round(self.stop_time / self.dt))
        if not math.isclose(self.n_steps * self.dt, self.stop_time, rel_tol=1e-9):
            raise ConfigError(f"stop = {self.stop_time:g} s is not a whole number of steps of dt = {self.dt:g} s")
        self.builder = builder
        self.activities: dict[str, Activity] = {}
        if nan_check:
            self.add(NaNChecker(max_speed_m_s=max_speed_m_s))
        if handle_signals:
            self.add(SignalStop())
        if progress:
            self.add(Progress(f"wall {progress_every_s}s"))
        self.wall_total = 0.0
        self._t_run = None
        self.stop_reason = None
        self._stop_requested = None
        self.resumed_from = None
        self.branched_from = None
        self.out_dir = None

    @property
    def stop(self) -> float:
        return self.stop_time

    # -- activities ----------------------------------------------------------------
    def add(self, activity: Activity, name: str | None = None) -> Simulation:
        """Add an activity (replacing one of the same name)."""
        name = name or activity.name
        if name in self.activities:
            del self.activities[name]
        self.activities[name] = activity
        if "progress" in self.activities and name != "progress":  # progress reports after the others
            self.activities["progress"] = self.activities.pop("progress")
        return self

    def output(self, every, path, crs="EPSG:3413", vtu: bool = False,
               start_date: str = "2000-01-01 00:00:00", grid_resolution_m: float | None = None,
               title: str = "lagice snapshot", drifters_path=None):
        """Snapshots every ``every`` into ``path`` (plus VTU files, regular-grid
        averages and the drifter trajectory file ``drifters_path`` when asked, on the
        same schedule). ``crs``: the model plane's CRS (any pyproj input; None: no
        grid mapping), written as the CF grid mapping of every file."""
        from .io.snapshots import SnapshotWriter

        path = Path(path)
        self.add(SnapshotOutput(every, SnapshotWriter(path, crs, start_date, title)))
        if vtu:
            from .io.vtu import VTUWriter

            self.add(VTUOutput(every, VTUWriter(path)))
        if grid_resolution_m:
            from .io.gridded import GridWriter

            self.add(GridOutput(every, GridWriter(path, grid_resolution_m, crs, start_date)))
        if drifters_path is not None:
            from .io.drifters import DrifterWriter

            self.add(DrifterOutput(every, DrifterWriter(drifters_path, crs, start_date)))
        return self

    def add_timeseries(self, path, diagnostics, every, start_date: str = "2000-01-01 00:00:00"):
        """Record scalar diagnostics (built-in names from :data:`lagice.io.timeseries.BUILTIN`
        or ``{name: ScalarDiagnostic}``) every ``every`` into the netCDF file ``path``."""
        from .io.timeseries import BUILTIN, ScalarDiagnostic, TimeSeriesWriter

        diags = {}
        for k in diagnostics:
            d = diagnostics[k] if isinstance(diagnostics, dict) else None
            if d is None:
                if k not in BUILTIN:
                    raise ConfigError(f"unknown time-series diagnostic {k!r}; built-in: {sorted(BUILTIN)}")
                d = BUILTIN[k]
            if not isinstance(d, ScalarDiagnostic):
                raise ConfigError(f"time-series diagnostic {k!r} must be a ScalarDiagnostic")
            diags[k] = d
        return self.add(TimeSeriesOutput(every, TimeSeriesWriter(path, diags, start_date)))

    def checkpoint(self, every, path, keep: int = 3):
        """Checkpoints every ``every`` (simulated time, ``"N steps"`` or ``"wall 55min"``)."""
        return self.add(Checkpointer(every, path, keep))

    def add_callback(self, fn, every, name: str | None = None, needs_host_state: bool = True):
        """Call ``fn(sim)`` every ``every`` (``needs_host_state``: :class:`~lagice.activities.Callback`)."""
        return self.add(Callback(fn, every, name or f"callback_{len(self.activities)}", needs_host_state))

    @property
    def checkpointer(self) -> Checkpointer | None:
        return self.activities.get("checkpointer")

    @property
    def ckpt_dir(self):
        c = self.checkpointer
        return None if c is None else c.directory

    def request_stop(self, reason: str) -> None:
        """Stop after the current step (a checkpoint is written first, if any)."""
        self._stop_requested = reason

    # -- running ---------------------------------------------------------------------
    def run(self, n_steps: int | None = None) -> dict:
        """Run to the stop time (or ``n_steps`` more steps); returns a summary."""
        model = self.model
        target = self.n_steps if n_steps is None else min(self.n_steps, model.clock.iteration + int(n_steps))
        self._stop_requested = None
        self.stop_reason = None
        self._t_run = time.perf_counter()
        acts = list(self.activities.values())
        try:
            for act in acts:
                act.initialize(self)
            while model.clock.iteration < target:
                model.step(self.dt)
                for act in acts:
                    if act.schedule(model):
                        act.run(self)
                if model.last_report.get("non_finite"):
                    NaNChecker(1)(self)  # a run without a NaN checker still stops, with the same message
                if self._stop_requested:
                    break
            if self._stop_requested:
                self.stop_reason = self._stop_requested
                if self.checkpointer is not None and self.checkpointer.last_iteration != model.clock.iteration:
                    self.checkpointer.run(self)
            for act in acts:
                if act.at_end and (model.clock.iteration == self.n_steps or self._stop_requested):
                    act.finalize(self)
                elif isinstance(act, TimeSeriesOutput):
                    act.writer.flush()
            model.needs_host_state()  # the caller reads model.state next
        finally:
            for act in acts:
                act.teardown(self)
            self.wall_total = self.wall_s
            self._t_run = None
        return self.summary()

    @property
    def wall_s(self) -> float:
        """Wall time [s] spent in :meth:`run` over the whole run, resumed parts included."""
        return self.wall_total + (time.perf_counter() - self._t_run if self._t_run is not None else 0.0)

    @property
    def finished(self) -> bool:
        return self.model.clock.iteration >= self.n_steps

    def summary(self) -> dict:
        """Simulated time and steps, wall time (all sessions of the run, resumed parts
        included, like the component ``timings``), remesh count and the events each trigger
        criterion fired in (``remesh_triggers``), the mesh's element and node
        counts now (remeshing changes them: docs/remeshing.md §7.1), ice volume budget,
        why the run stopped early (None: it reached its end) and the last checkpoint."""
        m = self.model
        st = m.state
        ck = self.checkpointer
        return {"time_s": m.clock.time_s, "steps": m.clock.iteration, "stop_time_s": self.stop_time,
                "finished": self.finished, "wall_s": self.wall_s,
                "timings": dict(m.timings), "remesh_count": st.counters.get("remesh_count", 0),
                "remesh_triggers": {k: st.counters.get(f"remesh_trigger_{k}", 0) for k in TRIGGER_CRITERIA},
                "n_elements": int(st.mesh.n_elements), "n_nodes": int(st.mesh.n_nodes),
                "ice_volume_m3": st.ice_volume_m3, "volume_budget": m.volume_budget(),
                "stop_reason": self.stop_reason,
                "checkpoint": str(ck.last_path) if ck is not None and ck.last_path is not None else None,
                "branched_from": self.branched_from}

    # -- checkpoint / resume ---------------------------------------------------------
    def _meta(self) -> dict:
        meta = self.model.state_meta()
        meta.update({
            "lagice_version": __version__, "scene_fingerprint": self.model.fingerprint(),
            "config": self.model.config, "builder": self.builder,
            "simulation": {"dt_s": self.dt, "stop_s": self.stop_time, "wall_s": self.wall_s},
        })
        return meta

    def write_checkpoint(self) -> Path:
        c = self.checkpointer
        if c is None:
            raise ConfigError("this simulation has no checkpointer (sim.checkpoint(every, path))")
        return write_checkpoint(c.directory, self.model.clock.iteration, self.model.state_arrays(), self._meta(),
                                keep=c.keep)

    @classmethod
    def resume(cls, checkpoint, model=None, builder=None, config: dict | None = None, **builder_kw) -> Simulation:
        """Resume from a checkpoint file or a checkpoint directory (newest usable one).

        The model is rebuilt with the checkpoint's ``builder`` and ``config``
        (or pass ``model=`` / ``builder=``; ``config=`` replaces the stored
        configuration, e.g. with a longer ``run.duration`` or other output
        schedules); its fingerprint (the physics) must match the checkpoint's.
        Outputs go to the run folder of the checkpoint (the parent of its
        ``checkpoints`` folder) unless ``out_dir=`` is given.
        Checkpoints are read by their format version (:data:`lagice.io.checkpoint.FORMAT_VERSION`).
        """
        path, arrays, meta = load_checkpoint(checkpoint)
        if model is None:
            spec = builder or meta.get("builder")
            if not spec:
                raise RestartError(f"checkpoint {path} names no builder; pass model= to resume it")
            if "out_dir" not in builder_kw:  # the run folder the checkpoint lives in
                builder_kw["out_dir"] = run_folder_of(path)
            from .scenes.config import with_legacy_values

            stored = with_legacy_values(meta["config"]) if isinstance(meta.get("config"), dict) else meta["config"]
            sim = _call_builder(spec, stored if config is None else config, **builder_kw)
        else:
            sim = cls(model, dt=meta["simulation"]["dt_s"], stop=meta["simulation"]["stop_s"])
        sim._check_fingerprint(path, meta)
        sim.model.load_state(arrays, meta)
        if sim.model.clock.time_s > sim.stop_time * (1 + 1e-12):
            raise RestartError(f"checkpoint {path} is at t = {sim.model.clock.time_s:g} s, after the end of the run "
                               f"({sim.stop_time:g} s): give a run.duration of at least "
                               f"{sim.model.clock.time_s:g} s")
        if abs(meta.get("simulation", {}).get("dt_s", sim.dt) - sim.dt) > 1e-12 * sim.dt:
            raise RestartError(f"checkpoint {path} was written with dt = {meta['simulation']['dt_s']:g} s; this "
                               f"simulation has dt = {sim.dt:g} s (the step count would not match)")
        sim.wall_total = float(meta.get("simulation", {}).get("wall_s", 0.0))
        sim.resumed_from = path
        return sim

    def _check_fingerprint(self, path, meta: dict) -> None:
        """The checkpoint's fingerprint must be the model's: the same physics. A checkpoint
        written by a version without some of today's keys (its stored configuration lacks
        them) matches the model's fingerprint hashed without them, provided each has the
        value that does what that version did (:data:`lagice.scenes.config.LEGACY_VALUES`);
        otherwise it is refused, naming the keys."""
        from .scenes.config import absent_keys, legacy_keys_check

        expect = meta.get("scene_fingerprint")
        model = self.model
        if model.fingerprint() == expect:
            return
        view = model.fingerprint_config if model.fingerprint_config is not None else model.config
        absent = absent_keys(view, meta.get("config"))
        if absent and model.fingerprint(without=absent) == expect:
            bad = legacy_keys_check(view, absent)
            if bad:
                raise RestartError(
                    f"checkpoint {path} was written by lagice {meta.get('lagice_version', '?')}, whose configuration "
                    f"had no {', '.join(absent)}; with {', '.join(bad)} this run would not continue the same "
                    f"physics: resume without setting them, or branch a new run (lagice branch {path} --set ...)")
            import logging

            logging.getLogger("lagice").info(
                f"checkpoint {path} was written by lagice {meta.get('lagice_version', '?')} without the keys "
                f"{', '.join(absent)}; their values here do what that version did (the same physics)")
            return
        hint = (f"; its configuration has no {', '.join(absent)} (keys added since the version that wrote it)"
                if absent else "")
        raise RestartError(f"checkpoint {path} belongs to another scene or configuration "
                           f"(fingerprint {expect}, model {model.fingerprint()}){hint}")


def load_checkpoint(checkpoint):
    """``(path, arrays, meta)`` of a checkpoint file, or of the newest usable one in a
    checkpoint or run folder (damaged newer ones are reported and skipped)."""
    path = Path(checkpoint)
    if path.is_dir() and (path / "checkpoints").is_dir() and not list(path.glob("checkpoint_*.npz")):
        path = path / "checkpoints"  # a run folder
    if path.is_dir():
        path, arrays, meta, skipped = latest_valid_checkpoint(path)
        for s in skipped:
            print(f"lagice: skipped damaged checkpoint: {s}", file=sys.stderr)
    else:
        arrays, meta = read_checkpoint(path)
    return path, arrays, meta


def run_folder_of(checkpoint_path) -> Path:
    """The run folder a checkpoint file belongs to (the parent of its ``checkpoints`` folder)."""
    ck_dir = Path(checkpoint_path).parent
    return ck_dir.parent if ck_dir.name == "checkpoints" else ck_dir


def _call_builder(spec: str, config: dict, **kw):
    mod_name, _, fn_name = spec.partition(":")
    try:
        fn = getattr(importlib.import_module(mod_name), fn_name)
    except (ImportError, AttributeError) as exc:
        raise RestartError(f"cannot import checkpoint builder {spec!r}: {exc}") from exc
    return fn(config, **kw)


__all__ = ["Simulation", "FORMAT_VERSION", "load_checkpoint", "run_folder_of"]
