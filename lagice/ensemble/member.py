"""One ensemble member, run on a dask worker (or in-process): start, resume or branch,
write provenance, compute its diagnostics, and leave a marker.

Member folder ``DIR/members/<id>/``:

=======================  ==========================================================
``member.json``          id, overrides, base, parent checkpoint (path, SHA-256),
                         config, status, host/worker, numba threads (updated at the end)
``snapshots/``           the run's snapshots (global attributes ``ensemble_*``)
``checkpoints/``         the run's checkpoints (resume after an interruption)
``summary.json``         the run summary (``lagice run``'s)
``done.json``            marker of a finished member: its record (summary, diagnostics)
``failed.json``          the error of a failed member (type, message, traceback)
=======================  ==========================================================
"""
from __future__ import annotations

import datetime as _dt
import json
import math
import os
import shutil
import socket
import time
import traceback
from pathlib import Path

import numpy as np

DIAG_KEYS = ("beta_space", "beta_space_r2", "pdf_tail_exponent_shear", "pdf_tail_exponent_divergence",
             "localisation_half_shear_area_fraction", "shear_divergence_r2", "mean_total_s", "mean_shear_s",
             "mean_abs_divergence_s")
OWN_OUTPUTS = ("snapshots", "checkpoints", "summary.json", "done.json", "failed.json")


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


# -- provenance in output files ---------------------------------------------------------
class ProvenanceWriter:
    """Wraps a run's :class:`~lagice.io.snapshots.SnapshotWriter`: every snapshot (and
    regular-grid file) gets the member's provenance as global attributes."""

    def __init__(self, writer, attrs: dict):
        self._writer = writer
        self.attrs = {k: v for k, v in attrs.items() if v is not None}

    def write(self, state, strain_rate=None, extra=None):
        path = self._writer.write(state, strain_rate, {**self.attrs, **(extra or {})})
        if getattr(self._writer, "grid_resolution_m", None):
            grid = Path(path).with_name(f"grid_{state.step:08d}.nc")
            if grid.exists():
                import netCDF4
                with netCDF4.Dataset(grid, "a") as nc:
                    nc.setncatts(self.attrs)
        return path

    def __getattr__(self, name):
        return getattr(self._writer, name)


def provenance_attrs(ensemble: str, member_id: str, overrides: dict, parent=None, parent_sha=None) -> dict:
    return {"ensemble_name": ensemble, "ensemble_member": member_id,
            "ensemble_member_overrides": json.dumps(overrides, sort_keys=True, default=str),
            "parent_checkpoint": str(parent) if parent else None, "parent_checkpoint_sha256": parent_sha}


# -- branching -------------------------------------------------------------------------
def branch_simulation(checkpoint, overrides: dict | None = None, out_dir=None, progress: bool = False,
                      config: dict | None = None):
    """A new :class:`~lagice.simulation.Simulation` that starts from ``checkpoint``'s
    state with ``overrides`` applied to its configuration, writing to ``out_dir``.

    The checkpoint's config (or ``config``, already built with
    :func:`lagice.ensemble.spec.member_config`) is rebuilt into a model, then the
    checkpoint's mesh, fields, clock, counters and random-generator state are
    loaded; the parent's fingerprint is not required to match (that is the
    point of a branch). ``domain.*``, ``initial.*`` and ``solver.dt`` cannot
    change; ``run.duration`` is the end time counted from the start of the
    parent run. The parent path and SHA-256 are stored in ``config["_parent"]``
    (so the branch's own checkpoints carry them) and on ``sim.parent``. The
    branch's first snapshot (the parent state) is written at once.
    """
    from ..io.checkpoint import read_checkpoint
    from ..scenes.toml_scene import build_simulation
    from .spec import file_sha256, member_config

    checkpoint = Path(checkpoint)
    arrays, meta = read_checkpoint(checkpoint)
    cfg = config if config is not None else member_config(None, dict(overrides or {}), meta)
    parent = {"checkpoint": str(checkpoint.resolve()), "sha256": file_sha256(checkpoint),
              "step": int(meta["step"]), "time_s": float(meta["time_s"])}
    cfg = dict(cfg)
    cfg["_parent"] = parent
    out = Path(out_dir) if out_dir is not None else Path("runs") / f"{cfg['scene']['name']}_branch"
    cfg["_out_dir"] = str(out)
    sim = build_simulation(cfg, out, progress=progress)
    sim.model.load_state(arrays, meta)
    sim.volume0 = sim.model.state.counters.get("volume0_m3")
    sim.parent = parent
    return sim


# -- diagnostics ------------------------------------------------------------------------
def member_diagnostics(run_dir, analysis: dict) -> dict:
    """Deformation statistics (``lagice.diagnostics.summarise``) of the run's last
    window(s): medians over ``analysis["windows"]`` back-to-back windows of
    ``analysis["window_s"]`` (default: the span of the last two snapshots) ending
    at the last snapshot. Keys: :data:`DIAG_KEYS` (NaN when not computable) and
    ``diag_status`` ("ok" or why not), ``diag_window_s``, ``diag_n_windows``,
    ``diag_n_elements``."""
    from ..diagnostics import summarise
    from ..diagnostics.faults import interior_triangles
    from ..io.snapshots import load_window, read_index

    out = {k: math.nan for k in DIAG_KEYS}
    out.update({"diag_status": "ok", "diag_window_s": math.nan, "diag_n_windows": 0, "diag_n_elements": 0})
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
    n_el = []
    try:
        for t0, t1 in zip(starts, ends):
            w = load_window(run_dir, t0, t1)
            xy0, xy1, tri = w["xy0"], w["xy1"], w["triangles"]
            if w["fixed_mesh"]:  # a fixed (Eulerian) mesh: displacement from the mean velocity
                xy1 = xy0 + 0.5 * (w["velocity0"] + w["velocity1"]) * w["dt_s"]
            if buffer_m > 0:
                keep = interior_triangles(*w["start_mesh"], buffer_m)[w["kept_elements"]]
                tri = tri[keep]
            if tri.shape[0] < 10:
                out["diag_status"] = (f"too_few_elements: {tri.shape[0]} element(s) in the window "
                                      f"(coast buffer {buffer_m / 1e3:g} km)")
                return out
            s = summarise(xy0, xy1, tri, w["dt_s"])
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
    return out


# -- running one member -------------------------------------------------------------------
def member_state(member_dir: Path) -> str:
    """"done", "failed" (run again from its newest checkpoint, if any), "resume" (a
    checkpoint of an interrupted attempt), or "new"."""
    if (member_dir / "done.json").exists():
        return "done"
    if (member_dir / "failed.json").exists():
        return "failed"
    from ..io.checkpoint import list_checkpoints
    if list_checkpoints(member_dir / "checkpoints"):
        return "resume"
    return "new"


def run_member(task: dict) -> dict:
    """Run one member to its end (a dask task; never raises for a member's own error).

    The member runs with dask's synchronous scheduler: on a worker, xarray would
    otherwise take a scheduler-wide ``distributed.Lock`` for every netCDF file it
    writes (a round trip to the scheduler per snapshot, and a failed write when
    the scheduler goes away); a member's files are its own.

    ``task``: ``id``, ``out`` (ensemble folder), ``config`` (validated scene config),
    ``overrides`` (the member's own), ``common``, ``ensemble`` (name), ``base``,
    ``branch_from`` and ``branch_sha256`` (or None), ``analysis``.
    Returns the member record (also written as ``done.json`` or ``failed.json``)."""
    import dask

    with dask.config.set(scheduler="synchronous"):
        return _run_member(task)


def _run_member(task: dict) -> dict:
    t_start, c_start = time.perf_counter(), time.process_time()
    mdir = Path(task["out"]) / "members" / task["id"]
    mdir.mkdir(parents=True, exist_ok=True)
    rec = {"member": task["id"], "status": "running", "error": None, "started": _now(),
           "host": socket.gethostname(), "pid": os.getpid(), "worker": _worker_address(),
           "numba_threads": _numba_threads(), "resumed_from": None, "overrides": task["overrides"]}
    info = {"member": task["id"], "ensemble": task["ensemble"], "overrides": task["overrides"],
            "common_overrides": task["common"], "base": task["base"],
            "parent_checkpoint": task.get("branch_from"), "parent_checkpoint_sha256": task.get("branch_sha256"),
            "config_hash": task["config_hash"], "config": task["config"], **rec}
    from .. import __version__
    info["lagice_version"] = __version__
    try:
        if (mdir / "done.json").exists():  # finished by an earlier run: nothing to do
            return json.loads((mdir / "done.json").read_text())
        (mdir / "failed.json").unlink(missing_ok=True)
        sim, resumed = _start_or_resume(task, mdir)
        rec["resumed_from"] = info["resumed_from"] = str(resumed) if resumed else None
        write_json(mdir / "member.json", info)
        from ..scenes.toml_scene import finish
        res = finish(sim)
        st = sim.model.state
        bad = [name for name in ("thickness", "concentration", "damage", "stress", "velocity")
               if not np.all(np.isfinite(getattr(st, name)))]
        if bad:
            from ..errors import SolverError
            raise SolverError(f"non-finite values at the end of the run (t = {st.time_s:g} s) in: {', '.join(bad)}")
        summary = res["summary"]
        rec["summary"] = {k: summary[k] for k in ("time_s", "steps", "wall_s", "remesh_count", "ice_volume_m3",
                                                  "volume_budget", "timings") if k in summary}
        rec["diagnostics"] = member_diagnostics(mdir, task["analysis"])
        rec["analysis"] = {k: v for k, v in task["analysis"].items()}
        rec["status"] = "done"
    except Exception as exc:  # noqa: BLE001 - a member's error is its result, not the ensemble's
        rec["status"] = "failed"
        rec["error"] = f"{type(exc).__name__}: {exc}"
        rec["traceback"] = traceback.format_exc()
    rec["finished"] = _now()
    rec["wall_s"] = time.perf_counter() - t_start
    rec["cpu_s"] = time.process_time() - c_start  # < wall_s when the member waited for a core
    info.update({k: rec[k] for k in ("status", "error", "finished", "wall_s", "cpu_s")})
    write_json(mdir / "member.json", info)
    write_json(mdir / ("done.json" if rec["status"] == "done" else "failed.json"), rec)
    return rec


def _start_or_resume(task: dict, mdir: Path):
    """(simulation, checkpoint it resumed from or None)."""
    from ..errors import RestartError
    from ..io.checkpoint import list_checkpoints
    from ..simulation import Simulation

    attrs = provenance_attrs(task["ensemble"], task["id"], task["overrides"], task.get("branch_from"),
                             task.get("branch_sha256"))
    resumed = None
    sim = None
    if list_checkpoints(mdir / "checkpoints"):
        try:
            sim = Simulation.resume(mdir / "checkpoints", out_dir=mdir, progress=False)
            resumed = sim.resumed_from
        except RestartError as exc:
            print(f"lagice ensemble: member {task['id']}: cannot resume ({exc}); starting it again", flush=True)
            sim = None
    if sim is None:
        for name in OWN_OUTPUTS:  # a fresh start: nothing of an earlier attempt may mix in
            p = mdir / name
            if p.is_dir():
                shutil.rmtree(p)
            else:
                p.unlink(missing_ok=True)
        cfg = json.loads(json.dumps(task["config"]))  # a private copy
        if task.get("branch_from"):
            sim = branch_simulation(task["branch_from"], out_dir=mdir, config=cfg)
            sim.writer = ProvenanceWriter(sim.writer, attrs)
            sim.writer.write(sim.model.state)  # the branch's first snapshot: the parent state
            return sim, None
        from ..scenes.toml_scene import build_simulation
        cfg["_out_dir"] = str(mdir)
        sim = build_simulation(cfg, mdir, progress=False)
    sim.writer = ProvenanceWriter(sim.writer, attrs)
    return sim, resumed


def _worker_address() -> str:
    try:
        from distributed import get_worker
        return get_worker().address
    except (ImportError, ValueError):
        return "in-process"


def _numba_threads() -> int:
    import numba
    return int(numba.config.NUMBA_NUM_THREADS)
