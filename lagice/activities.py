"""Scheduled activities of a :class:`~lagice.simulation.Simulation`.

Everything that happens during a run besides the model step is an activity with
a schedule (:mod:`lagice.schedule`): output writers, the checkpointer, progress
reports, the NaN/Inf checker, user callbacks and stop conditions. After every
outer step the simulation calls each activity whose schedule is due, in the order
they were added (the NaN checker first, so nothing non-finite is ever written).

An activity has ``name``, ``schedule`` and

* ``initialize(sim)`` — once before the loop (a fresh or a resumed run);
* ``__call__(sim)`` — when the schedule is due;
* ``finalize(sim)`` — once after the loop (``at_end`` activities run then too,
  when they did not just run);
* ``teardown(sim)`` — always, when :meth:`Simulation.run` returns or raises
  (release what ``initialize`` took: signal handlers, progress bars).

Before an activity with ``needs_host_state`` (the default) runs, the model brings
the state fields a device stepper keeps on its device up to date on the host
(:meth:`lagice.model.Model.needs_host_state`; free on the CPU).
"""
from __future__ import annotations

import logging
import math
import signal
import sys
import threading
import time
from pathlib import Path

import numpy as np

from .errors import SolverError
from .schedule import IterationInterval, WallTimeInterval, parse_schedule


class Activity:
    """Base class (see the module docstring)."""

    name = "activity"
    at_end = False      # also run once after the last step (if not just run)
    at_start = False    # also run before the first step of a fresh run
    needs_host_state = True  # reads velocity, stress or damage of the host state

    def __init__(self, schedule):
        self.schedule = parse_schedule(schedule, f"{self.name} every")
        self.last_iteration = None

    def initialize(self, sim) -> None:
        self.schedule.initialize(sim.model)
        if self.at_start and (sim.model.clock.iteration == 0 or getattr(sim, "branched_from", None)):
            self.run(sim)

    def run(self, sim) -> None:
        if self.needs_host_state:
            sim.model.needs_host_state()
        self(sim)
        self.last_iteration = sim.model.clock.iteration

    def __call__(self, sim) -> None:
        raise NotImplementedError

    def finalize(self, sim) -> None:
        if self.at_end and self.last_iteration != sim.model.clock.iteration:
            self.run(sim)

    def teardown(self, sim) -> None:
        pass


class SnapshotOutput(Activity):
    """UGRID/CF snapshot files (:class:`lagice.io.snapshots.SnapshotWriter`), written
    at the start of a fresh run, when due, and at the end."""

    name = "snapshots"
    at_start = True
    at_end = True

    def __init__(self, schedule, writer):
        super().__init__(schedule)
        self.writer = writer

    def __call__(self, sim):
        self.writer.write(sim.model)


class GridOutput(SnapshotOutput):
    """Regular-grid conservative averages (:class:`lagice.io.gridded.GridWriter`)."""

    name = "grid"


class VTUOutput(SnapshotOutput):
    """VTU files and a ``.pvd`` collection (:class:`lagice.io.vtu.VTUWriter`)."""

    name = "vtu"


class TimeSeriesOutput(Activity):
    """Named scalar diagnostics (:class:`lagice.io.timeseries.TimeSeriesWriter`):
    recorded when due (and at the start), written at every checkpoint and at the end."""

    name = "timeseries"
    at_start = True
    at_end = True

    def __init__(self, schedule, writer):
        super().__init__(schedule)
        self.writer = writer

    def initialize(self, sim):
        if sim.model.clock.iteration > 0:
            self.writer.reload(sim.model.clock.time_s)
        super().initialize(sim)

    def __call__(self, sim):
        self.writer.record(sim.model)

    def finalize(self, sim):
        super().finalize(sim)
        self.writer.flush()


class DrifterOutput(Activity):
    """The drifter trajectories as a CF trajectory file
    (:class:`lagice.io.drifters.DrifterWriter`), rewritten when due and at the end."""

    name = "drifter_output"
    at_end = True

    def __init__(self, schedule, writer):
        super().__init__(schedule)
        self.writer = writer

    def __call__(self, sim):
        if sim.model.drifters is not None:
            self.writer.write(sim.model)


class Checkpointer(Activity):
    """Checkpoints (:func:`lagice.io.checkpoint.write_checkpoint`), the last ``keep``
    kept: when the schedule is due (``None``: never), at the end of the run (so a
    finished run can be extended) and when the run is stopped. Flushes the time-series
    writers first so their files match the checkpoint. Removes the temporary files of
    killed writes when a run starts."""

    name = "checkpointer"
    at_end = True

    def __init__(self, schedule, directory, keep: int = 3):
        from .errors import ConfigError

        if isinstance(keep, bool) or int(keep) != keep or int(keep) < 1:
            raise ConfigError(f"checkpoint.keep = {keep!r} must be an integer >= 1")
        super().__init__(schedule)
        self.directory = Path(directory)
        self.keep = int(keep)
        self.last_path = None

    def initialize(self, sim):
        from .io.checkpoint import clean_stale_temporaries

        for p in clean_stale_temporaries(self.directory):
            logging.getLogger("lagice").info(f"removed a temporary file left by an interrupted write: {p}")
        super().initialize(sim)

    def __call__(self, sim):
        for act in sim.activities.values():
            if isinstance(act, TimeSeriesOutput):
                act.writer.flush()
        self.last_path = sim.write_checkpoint()


class Progress(Activity):
    """Progress of the run: simulated day, percentage, rate, ETA, remesh count and the
    volume budget. On a terminal a ``tqdm`` bar updated every step (rate and ETA from
    this session's steps); otherwise (a log file, a batch queue) a line every
    ``every`` of wall time with the rate in simulated days per wall hour, also over
    this session's steps only, so both are right after a resume. Silent when the
    ``lagice`` logger's level is set above INFO (``--log-level warning``)."""

    name = "progress"
    at_end = True
    needs_host_state = False  # clock, counters and the volume budget only

    def __init__(self, schedule="wall 10s", stream=None, bar: bool | None = None):
        super().__init__(schedule)
        self.stream = stream
        self.bar = bar
        self._line_schedule = self.schedule
        self._t0 = None
        self._sim0 = None
        self._bar = None

    def _quiet(self) -> bool:
        level = logging.getLogger("lagice").level  # set by `--log-level` (the API default NOTSET prints)
        return level != logging.NOTSET and level > logging.INFO

    def initialize(self, sim):
        stream = self.stream or sys.stdout
        use_bar = self.bar if self.bar is not None else bool(getattr(stream, "isatty", lambda: False)())
        self._bar = None
        if use_bar and not self._quiet():
            import shutil

            from tqdm import tqdm

            self.schedule = IterationInterval(1)
            size = shutil.get_terminal_size((100, 24))  # a pty may report 0 x 0: tqdm would then draw nothing
            self._bar = tqdm(total=sim.n_steps, initial=sim.model.clock.iteration, unit="step", file=stream,
                             ncols=size.columns if size.columns > 0 else 100,
                             nrows=size.lines if size.lines > 0 else 24, mininterval=0.5, smoothing=0.1,
                             desc=str(sim.model.config.get("scene", {}).get("name", "lagice")))
        else:
            self.schedule = self._line_schedule
        super().initialize(sim)
        self._t0 = time.perf_counter()
        self._sim0 = sim.model.clock.time_s

    def __call__(self, sim):
        m = sim.model
        if self._quiet():
            return
        if self._bar is not None:
            self._bar.update(m.clock.iteration - self._bar.n)
            self._bar.set_postfix_str(f"day {m.clock.time_s / 86400.0:.2f}, remeshes "
                                      f"{m.state.counters.get('remesh_count', 0)}", refresh=False)
            return
        wall = time.perf_counter() - self._t0
        done = m.clock.time_s - self._sim0
        rate = done / 86400.0 / wall * 3600.0 if wall > 0 else float("nan")
        frac = m.clock.time_s / sim.stop_time if sim.stop_time else float("nan")
        left = sim.stop_time - m.clock.time_s if sim.stop_time else float("nan")
        eta = left / done * wall if done > 0 else float("nan")
        eta_s = _fmt_wall(eta) if math.isfinite(eta) else "?"
        b = m.volume_budget()
        print(f"  day {m.clock.time_s / 86400.0:7.3f}  {100 * frac:5.1f} %  step {m.clock.iteration}/{sim.n_steps}  "
              f"{rate:8.1f} sim-days/wall-hour  ETA {eta_s}  remeshes {m.state.counters.get('remesh_count', 0)}  "
              f"volume {b['current_m3']:.4e} m3 (thermo {b['thermodynamic_m3']:+.2e}, outflow "
              f"{b['outflow_m3']:.2e}, drift {b['relative_residual']:+.1e})",
              file=self.stream or sys.stdout, flush=True)

    def teardown(self, sim):
        if self._bar is not None:
            self._bar.close()
            self._bar = None


def _fmt_wall(s: float) -> str:
    s = max(0.0, s)
    if s < 90:
        return f"{s:.0f} s"
    if s < 5400:
        return f"{s / 60:.1f} min"
    return f"{s / 3600:.1f} h"


class NaNChecker(Activity):
    """Stops the run with :class:`~lagice.errors.SolverError` naming the field, the
    step, the element or node (index and position) of the first NaN/Inf in the state
    (fields from the registry, :mod:`lagice.fields`), or of an ice speed above
    ``max_speed_m_s`` (default 10 m/s: sea ice in free drift under a 30 m/s wind moves
    at about 1 m/s; an unstable time step makes the speed grow without bound, and the
    quadratic ocean drag can keep it finite). Runs every step by default. Fields a
    device stepper checked on its device are not downloaded
    (:meth:`lagice.model.Model.device_checked_fields`)."""

    name = "nan_checker"
    needs_host_state = False  # downloads only what the device could not clear

    def __init__(self, schedule=None, max_speed_m_s: float = 10.0):
        from .errors import check_range

        super().__init__(schedule if schedule is not None else IterationInterval(1))
        self.max_speed_m_s = check_range("max_speed_m_s", max_speed_m_s, 0.0, None, low_open=True, unit="m s-1")

    def __call__(self, sim):
        from .fields import FIELDS, NODE, first_non_finite

        m = sim.model
        checked = m.device_checked_fields(self.max_speed_m_s)
        bad = first_non_finite(m.state, skip=checked)
        if bad is not None:
            spec, idx, val = bad
            what = f"non-finite {spec.name} ({val})"
        else:
            if "velocity" in checked:
                return
            v = m.state.velocity  # the dynamic velocity: an unstable sub-step oscillation
            speed = np.hypot(v[:, 0], v[:, 1])  # averages out of the transport velocity
            idx = int(np.argmax(speed)) if speed.size else 0
            if not speed.size or speed[idx] <= self.max_speed_m_s:
                return
            spec = FIELDS["velocity"]
            what = f"ice speed {speed[idx]:.4g} m/s above the bound {self.max_speed_m_s:g} m/s (non-physical)"
        mesh = m.mesh
        where = (mesh.nodes[idx] if spec.location == NODE else mesh.nodes[mesh.triangles[idx]].mean(axis=0))
        raise SolverError(
            f"{what} at step {m.clock.iteration} (t = {m.clock.time_s:g} s) in {spec.location} {idx} at "
            f"x = {where[0]:.0f} m, y = {where[1]:.0f} m; the run was stopped (the last checkpoint is "
            f"untouched). An unstable time step or sub-step is the usual cause.")


class Callback(Activity):
    """A user function ``fn(sim)`` called when due. ``needs_host_state=False`` declares
    that ``fn`` reads no velocity, stress or damage of the state (the clock, the mesh,
    the last step's report): on a GPU stepper nothing is then downloaded for it."""

    name = "callback"

    def __init__(self, fn, schedule, name: str | None = None, needs_host_state: bool = True):
        super().__init__(schedule)
        self.fn = fn
        self.needs_host_state = bool(needs_host_state)
        if name:
            self.name = name

    def __call__(self, sim):
        self.fn(sim)


class StopCondition(Activity):
    """Stops the run (after the current step) when ``condition(sim)`` is true; the
    reason is kept in ``sim.stop_reason``. Checked every step by default."""

    name = "stop_condition"

    def __init__(self, condition, reason: str = "stop condition met", schedule=None):
        super().__init__(schedule if schedule is not None else IterationInterval(1))
        self.condition = condition
        self.reason = reason

    def __call__(self, sim):
        if self.condition(sim):
            sim.request_stop(self.reason)


class SignalStop(StopCondition):
    """Stops the run cleanly on SIGTERM or SIGINT (batch-queue pre-emption, Ctrl-C):
    the signal only sets a flag; after the current step the simulation writes a
    checkpoint and its end-of-run outputs, and returns with ``stop_reason`` naming the
    signal. A second signal of the same kind acts as usual (Ctrl-C twice interrupts
    at once). Handlers are installed only in the main thread, for the run's duration."""

    name = "signal_stop"
    SIGNALS = ("SIGTERM", "SIGINT")
    # reads a flag only: with a device stepper, checking it every step must not download
    # velocity, stress and damage (and upload them again before the next step)
    needs_host_state = False

    def __init__(self):
        super().__init__(lambda sim: self.received is not None, "signal received")
        self.received = None
        self._old = {}

    def _handler(self, signum, frame):
        self.received = signal.Signals(signum).name
        self.reason = f"{self.received} received"
        old = self._old.pop(signum, None)  # the next one acts as usual
        if old is not None:
            signal.signal(signum, old)

    def initialize(self, sim):
        super().initialize(sim)
        self.received = None
        if threading.current_thread() is not threading.main_thread():
            return
        for name in self.SIGNALS:
            num = getattr(signal, name)
            self._old[num] = signal.signal(num, self._handler)

    def teardown(self, sim):
        for num, old in self._old.items():
            signal.signal(num, old)
        self._old = {}


class WallTimeLimit(StopCondition):
    """Stops the run (after a checkpoint, if the simulation has a checkpointer) once
    ``limit`` of wall time has passed — for batch queues."""

    name = "wall_time_limit"
    needs_host_state = False  # reads the wall clock only

    def __init__(self, limit):
        sched = WallTimeInterval(limit, "run.wall_time_limit")
        super().__init__(lambda sim: True, f"wall-time limit of {sched.interval:g} s reached", sched)
