"""One ensemble member, run on a dask worker (or in-process), through the run
workflow of ``lagice run`` / ``lagice resume`` / ``lagice branch``
(:mod:`lagice.scenes.builder`, :mod:`lagice.rundir`): a new member claims its own
run folder and is built with ``build_simulation`` (``branch_simulation`` for a
member that starts from a checkpoint); an interrupted one continues with
``resume_simulation`` from its newest checkpoint (bit for bit, and extended when
only ``run.duration`` grew). The member id and overrides travel in the config
(``config["_ensemble"]``), so every output file of the member carries them
(:func:`lagice.io.cf.provenance`) and so do its checkpoints.

Member folder ``DIR/members/<id>/`` (a lagice run folder):

=======================  ==========================================================
``lagice_run.json``      the run-folder marker (:mod:`lagice.rundir`), with ``ensemble``
``member.json``          id, overrides, base, parent checkpoint (path, SHA-256),
                         config, status, host/worker, numba threads (updated at the end)
``snapshots/``           the run's snapshots (global attributes ``lagice_ensemble*``)
``checkpoints/``         the run's checkpoints (resume after an interruption)
``summary.json``         the run summary (``lagice run``'s)
``done.json``            marker of a finished member: its record (summary, diagnostics)
``failed.json``          the error of a failed member (type, message, traceback)
=======================  ==========================================================

A member stops cleanly (checkpoint, end-of-run outputs: ``Simulation.request_stop``
through a :class:`~lagice.activities.StopCondition`) when the ensemble folder holds
the file ``STOP`` (:data:`STOP_FILE`: written by ``lagice ensemble`` on SIGTERM/SIGINT,
or by hand, ``touch DIR/STOP``, on any cluster that shares the folder), or when its
worker process received SIGTERM/SIGINT (:class:`WorkerStopPlugin`: a batch system's
signal at the walltime, or Ctrl-C reaching the local workers): the worker's members
stop as ``lagice run`` does, and the worker starts no other member.
"""
from __future__ import annotations

import datetime as _dt
import json
import math
import os
import signal
import socket
import threading
import time
import traceback
from pathlib import Path

import numpy as np
from distributed.diagnostics.plugin import WorkerPlugin

from ..activities import StopCondition

DIAG_KEYS = ("beta_space", "beta_space_r2", "pdf_tail_exponent_shear", "pdf_tail_exponent_divergence",
             "localisation_half_shear_area_fraction", "shear_divergence_r2", "mean_total_s", "mean_shear_s",
             "mean_abs_divergence_s")
#: the ensemble's own files in a member folder (removed, with the run outputs, when a member starts afresh)
MEMBER_FILES = ("member.json", "done.json", "failed.json")
#: a file in the ensemble folder that asks every running member to stop cleanly
STOP_FILE = "STOP"


def _now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")


def write_json(path: Path, obj) -> None:
    """Atomic JSON write (temporary file + rename)."""
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    tmp.write_text(json.dumps(obj, indent=1, default=_json_default, allow_nan=True))
    os.replace(tmp, path)


def _json_default(o):
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, (np.floating,)):
        return float(o)
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)


# -- stopping ---------------------------------------------------------------------------------
#: why this worker process was asked to stop (set by :class:`WorkerStopPlugin`'s signal handler)
_WORKER_STOP = {"reason": None}


class WorkerStopPlugin(WorkerPlugin):
    """A dask worker plugin: the first SIGTERM or SIGINT the worker process receives
    stops its running members cleanly (checkpoint) and keeps it from starting others,
    instead of killing the process with the members in it; a second one acts as
    before (the worker stops at once). Registered by ``lagice ensemble`` on the
    clusters it starts (LocalCluster, SLURM/PBS jobs)."""

    name = "lagice-ensemble-stop"

    def setup(self, worker):
        if threading.current_thread() is not threading.main_thread():  # pragma: no cover - handlers need it
            return
        from ..mesh.generate import gmsh_session

        with gmsh_session():  # gmsh's first initialisation resets SIGTERM: do it before installing the handler
            pass
        for name in ("SIGTERM", "SIGINT"):
            num = getattr(signal, name)
            old = signal.getsignal(num)
            if getattr(old, "__name__", "") != "_worker_signal":
                _OLD_HANDLERS[num] = old
                signal.signal(num, _worker_signal)


_OLD_HANDLERS = {}


def _worker_signal(signum, frame):
    name = signal.Signals(signum).name
    if _WORKER_STOP["reason"] is None:
        _WORKER_STOP["reason"] = f"{name} received by the worker (pid {os.getpid()})"
        return
    old = _OLD_HANDLERS.pop(signum, signal.SIG_DFL)  # a second signal: as before the plugin
    signal.signal(signum, old if old is not None else signal.SIG_DFL)
    os.kill(os.getpid(), signum)


def stop_reason(out_dir: Path) -> str | None:
    """Why members should stop now (the worker was signalled, ``DIR/STOP`` exists), or None."""
    if _WORKER_STOP["reason"] is not None:
        return _WORKER_STOP["reason"]
    if (Path(out_dir) / STOP_FILE).exists():
        return f"the ensemble was asked to stop ({Path(out_dir) / STOP_FILE})"
    return None


class EnsembleStop(StopCondition):
    """Checked after every step of a member: stops it (``sim.request_stop``: checkpoint,
    end-of-run outputs, ``stop_reason``) when :func:`stop_reason` gives a reason."""

    name = "ensemble_stop"

    def __init__(self, out_dir):
        super().__init__(lambda sim: False, "the ensemble was asked to stop")
        self.out_dir = Path(out_dir)

    def __call__(self, sim):
        why = stop_reason(self.out_dir)
        if why:
            sim.request_stop(why)


def member_tag(ensemble: str, member_id: str, overrides: dict) -> dict:
    """``config["_ensemble"]``: what every output file of the member records."""
    return {"ensemble": ensemble, "member": member_id, "overrides": dict(overrides)}


# -- diagnostics ------------------------------------------------------------------------
def member_diagnostics(run_dir, analysis: dict) -> dict:
    """Deformation statistics (``lagice.diagnostics.summarise``) of the run's last
    window(s): medians over ``analysis["windows"]`` back-to-back windows of
    ``analysis["window_s"]`` (default: the span of the last two snapshots) ending
    at the last snapshot. Each window goes through
    :func:`lagice.diagnostics.windows.window_arrays`, the path of ``lagice diagnose`` and
    ``benchmarks/validate.py``: the elements a remesh replaced during the window and those
    whose mid-window geometry is inverted are left out (and counted), and the coast buffer
    is measured on the window's first mesh, so a member's statistics are those
    ``lagice diagnose --window-days`` gives for the same windows. Keys: :data:`DIAG_KEYS`
    (NaN when not computable) and ``diag_status`` ("ok" or why not), ``diag_window_s``,
    ``diag_n_windows``, ``diag_n_elements`` (the fewest elements in a window),
    ``diag_n_folded`` (inverted mid-window elements left out, summed over the windows)."""
    from ..diagnostics import summarise
    from ..diagnostics.windows import WindowError, window_arrays
    from ..errors import ConfigError
    from ..io.snapshots import read_index

    out = {k: math.nan for k in DIAG_KEYS}
    out.update({"diag_status": "ok", "diag_window_s": math.nan, "diag_n_windows": 0, "diag_n_elements": 0,
                "diag_n_folded": 0})
    try:
        idx = read_index(run_dir)
    except Exception as exc:  # noqa: BLE001 - reported, not raised
        out["diag_status"] = f"no snapshots: {exc}"
        return out
    times = np.array([e["time_s"] for e in idx])
    if times.size < 2:
        out["diag_status"] = f"insufficient_snapshots: {times.size} snapshot(s), need 2"
        return out
    window = analysis.get("window_s") or float(times[-1] - times[-2])
    n = int(analysis.get("windows", 1))
    ends = times[-1] - window * np.arange(n)[::-1]
    starts = ends - window
    tol = 1e-6 * window + 1e-6
    for t in np.concatenate([starts, ends]):
        if np.min(np.abs(times - t)) > tol:
            if t < times[0] - tol:
                out["diag_status"] = (f"insufficient_snapshots: {n} window(s) of {window:g} s ending at "
                                      f"{times[-1]:g} s start before the first snapshot ({times[0]:g} s)")
            else:
                out["diag_status"] = (f"window_not_on_snapshots: no snapshot at {t:g} s for {n} window(s) of "
                                      f"{window:g} s ending at {times[-1]:g} s (set analysis.window to a "
                                      "multiple of output.every)")
            return out
    out["diag_window_s"] = window
    buffer_m = 1e3 * float(analysis.get("coast_buffer_km", 0.0))
    per = {k: [] for k in DIAG_KEYS}
    n_el, n_folded = [], 0
    try:
        for t0, t1 in zip(starts, ends):
            try:
                xy0, xy1, tri, dt, info = window_arrays(run_dir, t0, t1, buffer_m)
            except (ConfigError, WindowError) as exc:  # too few elements (inside the buffer, or followable)
                out["diag_status"] = f"too_few_elements: {exc}"
                return out
            n_folded += info["n_interior_folded"]
            tri = tri[info["interior"]]
            s = summarise(xy0, xy1, tri, dt)
            s.pop("_arrays", None)
            for k in DIAG_KEYS:
                v = s.get(k)
                per[k].append(math.nan if v is None else float(v))
            n_el.append(int(tri.shape[0]))
    except Exception as exc:  # noqa: BLE001 - a diagnostics failure is reported per member
        out["diag_status"] = f"diagnostics_error: {type(exc).__name__}: {exc}"
        return out
    for k in DIAG_KEYS:
        vals = np.array(per[k])
        out[k] = float(np.median(vals)) if np.all(np.isfinite(vals)) else math.nan
    missing = [k for k in DIAG_KEYS if not np.isfinite(out[k])]
    if missing:
        out["diag_status"] = f"partial: not computable: {', '.join(missing)}"
    out["diag_n_windows"] = n
    out["diag_n_elements"] = int(min(n_el))
    out["diag_n_folded"] = int(n_folded)
    return out


# -- running one member -------------------------------------------------------------------
def member_state(member_dir: Path, config_hash: str | None = None) -> str:
    """"done" (finished with this configuration), "failed" (run again: resumed from its
    newest checkpoint, if any), "resume" (a checkpoint of an interrupted attempt, or a
    finished member whose run grew longer: ``run.duration`` only), or "new"."""
    done = member_dir / "done.json"
    if done.exists():
        if config_hash is None or json.loads(done.read_text()).get("config_hash") == config_hash:
            return "done"
        return "resume" if _has_checkpoints(member_dir) else "new"
    if (member_dir / "failed.json").exists():
        return "failed"
    return "resume" if _has_checkpoints(member_dir) else "new"


def _has_checkpoints(member_dir: Path) -> bool:
    from ..io.checkpoint import list_checkpoints

    return bool(list_checkpoints(member_dir / "checkpoints"))


def run_member(task: dict) -> dict:
    """Run one member to its end (a dask task; never raises for a member's own error).

    The member runs with dask's synchronous scheduler: on a worker, xarray would
    otherwise take a scheduler-wide ``distributed.Lock`` for every netCDF file it
    writes (a round trip to the scheduler per snapshot, and a failed write when
    the scheduler goes away); a member's files are its own.

    ``task``: ``id``, ``out`` (ensemble folder), ``config`` (validated scene config),
    ``config_hash``, ``overrides`` (the member's own), ``common``, ``ensemble`` (name),
    ``base``, ``branch_from`` and ``branch_sha256`` (or None), ``analysis``.
    Returns the member record: status "done" (also written as ``done.json``),
    "failed" (``failed.json``) or "stopped" (a clean stop on request: resumable)."""
    import dask

    with dask.config.set(scheduler="synchronous"):
        return _run_member(task)


def _run_member(task: dict) -> dict:
    t_start, c_start = time.perf_counter(), time.process_time()
    out = Path(task["out"])
    mdir = out / "members" / task["id"]
    rec = {"member": task["id"], "status": "running", "error": None, "started": _now(),
           "host": socket.gethostname(), "pid": os.getpid(), "worker": _worker_address(),
           "numba_threads": _numba_threads(), "resumed_from": None, "overrides": task["overrides"],
           "config_hash": task["config_hash"]}
    why = stop_reason(out)
    if why:  # the ensemble or this worker is stopping: do not start
        return {**rec, "status": "stopped", "error": f"not started: {why}"}
    state = member_state(mdir, task["config_hash"])
    if state == "done":  # finished by an earlier run: nothing to do
        return json.loads((mdir / "done.json").read_text())
    from ..errors import LagiceError
    from ..rundir import RunLock

    lock = RunLock(mdir)  # the member's run folder is this worker's until the member ends (lagice.rundir)
    try:
        lock.acquire()
    except LagiceError as exc:  # e.g. a `lagice resume` of the member folder runs: leave its files alone
        return {**rec, "status": "failed", "error": f"{type(exc).__name__}: {exc}", "finished": _now(),
                "wall_s": time.perf_counter() - t_start, "cpu_s": time.process_time() - c_start,
                "lock_failed": True}  # nothing written into the folder: the ensemble's summary takes it
    try:
        return _run_member_locked(task, rec, out, mdir, state, t_start, c_start)
    finally:
        lock.release()


def _run_member_locked(task: dict, rec: dict, out: Path, mdir: Path, state: str, t_start: float,
                       c_start: float) -> dict:
    for name in ("done.json", "failed.json"):  # the record of an earlier attempt (or a shorter run)
        (mdir / name).unlink(missing_ok=True)
    from .. import __version__

    info = {"member": task["id"], "ensemble": task["ensemble"], "overrides": task["overrides"],
            "common_overrides": task["common"], "base": task["base"],
            "parent_checkpoint": task.get("branch_from"), "parent_checkpoint_sha256": task.get("branch_sha256"),
            "config": task["config"], "lagice_version": __version__, **rec}
    sim = None
    try:
        sim, resumed = _start_or_resume(task, mdir, state)
        rec["resumed_from"] = info["resumed_from"] = str(resumed) if resumed else None
        write_json(mdir / "member.json", info)
        from ..scenes.builder import finish

        sim.add(EnsembleStop(out))
        res = finish(sim)
        summary = res["summary"]
        rec["summary"] = {k: summary[k] for k in ("time_s", "steps", "wall_s", "remesh_count", "ice_volume_m3",
                                                  "volume_budget", "timings", "stop_reason", "checkpoint")
                          if k in summary}
        if summary.get("stop_reason"):
            rec["status"] = "stopped"
            rec["error"] = (f"stopped at step {summary['steps']} (day {summary['time_s'] / 86400:.3f}): "
                            f"{summary['stop_reason']}; checkpoint {summary.get('checkpoint')}")
        else:
            rec["diagnostics"] = member_diagnostics(mdir, task["analysis"])
            rec["analysis"] = dict(task["analysis"])
            rec["status"] = "done"
    except Exception as exc:  # noqa: BLE001 - a member's error is its result, not the ensemble's
        rec["status"] = "failed"
        rec["error"] = f"{type(exc).__name__}: {exc}"
        rec["traceback"] = traceback.format_exc()
    rec["finished"] = _now()
    rec["wall_s"] = time.perf_counter() - t_start
    rec["cpu_s"] = time.process_time() - c_start  # < wall_s when the member waited for a core
    info.update({k: rec[k] for k in ("status", "error", "finished", "wall_s", "cpu_s")})
    mdir.mkdir(parents=True, exist_ok=True)
    write_json(mdir / "member.json", info)
    if rec["status"] in ("done", "failed"):
        write_json(mdir / ("done.json" if rec["status"] == "done" else "failed.json"), rec)
    return rec


def _start_or_resume(task: dict, mdir: Path, state: str):
    """(simulation, checkpoint it resumed from or None), through the run workflow:
    ``resume_simulation`` (newest usable checkpoint of the member folder; refused
    when the physics changed), else a fresh start in the member folder, claimed as
    ``lagice run --out`` does (an earlier attempt's outputs are replaced):
    ``branch_simulation`` from the ensemble's checkpoint or ``build_simulation``."""
    from .. import rundir
    from ..errors import RestartError
    from ..scenes.builder import branch_simulation, build_simulation, resume_simulation

    cfg = json.loads(json.dumps(task["config"]))  # a private copy
    cfg["_ensemble"] = member_tag(task["ensemble"], task["id"], task["overrides"])
    if state in ("resume", "failed") and _has_checkpoints(mdir):
        try:
            sim = resume_simulation(mdir, config=cfg, progress=False)
            return sim, sim.resumed_from
        except RestartError as exc:
            print(f"lagice ensemble: member {task['id']}: cannot resume ({exc}); starting it again", flush=True)
    for name in MEMBER_FILES:  # a fresh start: nothing of an earlier attempt may mix in
        (mdir / name).unlink(missing_ok=True)
    rundir.claim(mdir, overwrite=True)  # refuses a folder that is not a lagice run folder
    if task.get("branch_from"):
        return branch_simulation(task["branch_from"], mdir, config=cfg, progress=False), None
    return build_simulation(cfg, mdir, progress=False), None


def _worker_address() -> str:
    try:
        from distributed import get_worker
        return get_worker().address
    except (ImportError, ValueError):
        return "in-process"


def _numba_threads() -> int:
    import numba
    return int(numba.config.NUMBA_NUM_THREADS)
