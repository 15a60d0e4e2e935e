"""``Ensemble``: run the members of a spec on dask.distributed, resume, summarise."""
from __future__ import annotations

import contextlib
import datetime as _dt
import json
import math
import os
import shutil
import signal
import socket
import sys
import threading
import time
import uuid
from pathlib import Path

from ..errors import ConfigError, LagiceError
from ..rundir import clear_folder
from .member import STOP_FILE, member_state, run_member, write_json
from .spec import EnsembleSpec, load_spec


class Ensemble:
    """An ensemble of lagice runs.

    ::

        ens = lagice.Ensemble.from_file("examples/ensembles/shear_box_grid.toml", out_dir="runs/sweep")
        summary = ens.run()                 # embedded LocalCluster sized to the machine
        summary = ens.run(client=client)    # an existing dask.distributed Client
        grids = lagice.ensemble.open_grids("runs/sweep")

    ``spec``: an :class:`~lagice.ensemble.spec.EnsembleSpec`, a TOML path, TOML
    text or a dict (validated at once: a bad spec raises
    :class:`~lagice.errors.ConfigError` before anything runs).
    """

    def __init__(self, spec, out_dir=None, overrides=None):
        self.spec: EnsembleSpec = spec if isinstance(spec, EnsembleSpec) else load_spec(spec, overrides)
        self.out_dir = Path(out_dir) if out_dir is not None else Path("runs") / self.spec.name
        self.last_run = {}
        self.stopped = None  # why the last run stopped early (a signal, DIR/STOP), else None
        self._lock_failed = {}  # records of the last run's members that could not lock their run folder

    @classmethod
    def from_file(cls, path, out_dir=None, overrides=None) -> Ensemble:
        return cls(load_spec(Path(path), overrides), out_dir)

    @property
    def members(self):
        return self.spec.members

    # -- bookkeeping ---------------------------------------------------------------------
    def _task(self, m) -> dict:
        s = self.spec
        return {"id": m.id, "out": str(self.out_dir.resolve()), "config": m.config, "config_hash": m.config_hash,
                "overrides": m.overrides, "common": s.common, "ensemble": s.name, "base": s.base,
                "branch_from": str(s.branch_from.resolve()) if s.branch_from else None,
                "branch_sha256": s.branch_sha256, "analysis": s.analysis}

    def _info(self) -> dict:
        s = self.spec
        from .. import __version__
        return {"name": s.name, "source": s.source, "base": s.base, "common": s.common,
                "branch_from": str(s.branch_from.resolve()) if s.branch_from else None,
                "branch_sha256": s.branch_sha256, "analysis": s.analysis, "lagice_version": __version__,
                "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")}

    def clear_folder(self) -> None:
        """Remove an earlier ensemble in the output folder (``lagice ensemble --overwrite``):
        only a folder that holds an ensemble (``ensemble.json``) or nothing."""
        if not self.out_dir.exists() or not any(self.out_dir.iterdir()):
            return
        if not (self.out_dir / "ensemble.json").exists():
            raise ConfigError(f"--out {self.out_dir}: the folder is not empty and holds no ensemble (no "
                              "ensemble.json); refusing to delete it with --overwrite")
        with _FolderLock(self.out_dir / "ensemble.lock"):
            clear_folder(self.out_dir, keep=("ensemble.lock",))

    def check_folder(self) -> dict:
        """Compare the spec with an earlier run in the output folder (``ensemble.json``):
        a member whose physics changed (anything a resumed run may not change, as for
        ``lagice resume``: all but ``run.duration``, ``output.*``, ``checkpoint.*``...;
        or another parent checkpoint) is an error: its outputs would mix two runs. A
        longer ``run.duration`` extends the members from their last checkpoints.
        Returns the earlier ``ensemble.json`` content ({} if none)."""
        from ..scenes.config import changed_keys, physics_view

        p = self.out_dir / "ensemble.json"
        if not p.exists():
            if self.out_dir.exists() and any(self.out_dir.iterdir()):
                raise ConfigError(f"--out {self.out_dir}: the folder is not empty and holds no ensemble "
                                  "(no ensemble.json); choose a new or empty folder")
            return {}
        old = json.loads(p.read_text())
        for m in self.members:
            prev = old.get("members", {}).get(m.id)
            if prev is None or prev["config_hash"] == m.config_hash:
                continue
            was = prev.get("config", {})
            moved = changed_keys(physics_view(was), physics_view(m.config))
            if (was.get("_parent") or {}).get("sha256") != (m.config.get("_parent") or {}).get("sha256"):
                moved.append("ensemble.branch_from (another parent checkpoint)")
            if moved:
                diff = [f"{k}: {_lookup(was, k)!r} -> {_lookup(m.config, k)!r}" if "." in k and " " not in k else k
                        for k in moved]
                raise ConfigError(f"{self.out_dir}: member {m.id!r} was started with other physics "
                                  f"({'; '.join(diff[:5])}); re-running resumes the same ensemble, and may only "
                                  "change run.duration (extend), output.* and checkpoint.*: use a new --out, or "
                                  f"delete {self.out_dir / 'members' / m.id}")
        return old

    def _write_ensemble_json(self, old: dict) -> None:
        members = dict(old.get("members", {}))
        order = [m.id for m in self.members] + [k for k in members if k not in {m.id for m in self.members}]
        for m in self.members:
            members[m.id] = {"overrides": m.overrides, "config_hash": m.config_hash, "config": m.config}
        info = {**self._info(), "members": {k: members[k] for k in order}, "order": order}
        self.out_dir.mkdir(parents=True, exist_ok=True)
        write_json(self.out_dir / "ensemble.json", info)
        if self.spec.source not in ("<dict>", "<toml>"):
            shutil.copyfile(self.spec.source, self.out_dir / "ensemble_spec.toml")

    def plan(self, retry_failed: bool = True) -> dict:
        """{member id: "done" | "resume" | "new" | "retry" | "skip_failed"}."""
        out = {}
        for m in self.members:
            st = member_state(self.out_dir / "members" / m.id, m.config_hash)
            if st == "failed":
                st = "retry" if retry_failed else "skip_failed"
            out[m.id] = st
        return out

    # -- running ---------------------------------------------------------------------------
    def run(self, client=None, *, workers: int | None = None, scheduler: str | None = None,
            serial: bool = False, retry_failed: bool = True, plot: bool = True, handle_signals: bool = True):
        """Run the members that are not finished; return the summary (xarray Dataset).

        ``client``: a ``distributed.Client`` to use; otherwise a cluster is made from
        the spec's ``[cluster]`` table (default: a LocalCluster sized to the machine),
        ``scheduler`` (an address) or, with ``serial=True``, members run one by one
        in this process. Finished members (``done.json``) are skipped, interrupted
        ones resume from their newest checkpoint, failed ones are run again unless
        ``retry_failed=False``. Writes ``ensemble_summary.nc`` and ``ensemble_spread.png``.

        Stopping: the file ``DIR/STOP`` asks every running member to stop after its
        current step with a checkpoint (the run workflow's clean stop); members not
        started yet are not started. ``handle_signals`` (in the main thread): the first
        SIGTERM or SIGINT writes that file (then the summary is written and ``run``
        returns; ``self.stopped`` names the signal); a second one interrupts at once
        (KeyboardInterrupt: the local workers are killed, members resume from their
        last periodic checkpoint). Re-running resumes the stopped members.
        """
        old = self.check_folder()
        self.out_dir.mkdir(parents=True, exist_ok=True)
        with _FolderLock(self.out_dir / "ensemble.lock"):
            (self.out_dir / STOP_FILE).unlink(missing_ok=True)  # an earlier stop request is over
            with _StopOnSignal(self, enabled=handle_signals):
                return self._run_locked(old, client, workers, scheduler, serial, retry_failed, plot)

    def _run_locked(self, old, client, workers, scheduler, serial, retry_failed, plot):
        self.stopped = None
        self._lock_failed = {}
        self._write_ensemble_json(old)
        plan = self.plan(retry_failed)
        listed = [m for m in self.members if plan[m.id] in ("new", "resume", "retry")]
        todo = largest_first(listed)
        counts = {k: sum(v == k for v in plan.values()) for k in ("done", "resume", "new", "retry", "skip_failed")}
        _say(f"ensemble {self.spec.name!r}: {len(self.members)} members -> {self.out_dir}/ "
             f"({counts['done']} done, {counts['resume']} to resume, {counts['new']} to start, "
             f"{counts['retry']} failed to retry" + (f", {counts['skip_failed']} failed kept" if counts["skip_failed"]
                                                      else "") + ")")
        if todo != listed:  # say so: the members do not start in the spec's order
            ids = [m.id for m in todo]
            _say(f"ensemble {self.spec.name!r}: members start largest first (estimated elements x steps x sub-steps): "
                 + ", ".join(ids[:12]) + (f", ... ({len(ids) - 12} more)" if len(ids) > 12 else ""))
        t0 = time.perf_counter()
        self.last_run = {"plan": plan, "setup_s": 0.0, "cluster": None}
        try:
            if todo:
                if serial:
                    self._run_serial(todo)
                else:
                    self._run_dask(todo, client, workers, scheduler)
        finally:
            self.last_run["wall_s"] = time.perf_counter() - t0
            if (self.out_dir / STOP_FILE).exists():
                self.stopped = self.stopped or f"{self.out_dir / STOP_FILE} found"
            summary = self.summarise(plot=plot and not self.stopped)
        failed = [str(m) for m, s in zip(summary["member"].values, summary["status"].values) if s != "done"]
        _say(f"ensemble {self.spec.name!r}: {len(self.members) - len(failed)} of {len(self.members)} members done "
             f"in {self.last_run['wall_s']:.1f} s wall; summary {self.out_dir / 'ensemble_summary.nc'}")
        for m in failed:
            i = list(summary["member"].values).index(m)
            _say(f"  {m}: {summary['status'].values[i]}: {summary['error'].values[i]}")
        if self.stopped:
            (self.out_dir / STOP_FILE).unlink(missing_ok=True)
            _say(f"ensemble {self.spec.name!r}: stopped ({self.stopped}); the members in flight wrote a checkpoint. "
                 f"Run the same command again to resume (finished members are skipped)")
        return summary

    def _run_serial(self, todo):
        prog = _Progress(len(todo), slots=1)
        for m in todo:
            if self.stopped or (self.out_dir / STOP_FILE).exists():
                break
            prog.started(m.id)
            rec = run_member(self._task(m))  # in the main thread: the member's own SIGTERM/SIGINT clean stop
            self._note_lock_failed(rec)
            prog.finished(rec)
            if rec["status"] == "stopped":
                self.stopped = self.stopped or str(rec.get("error"))

    def _run_dask(self, todo, client, workers, scheduler):
        from distributed import Client, as_completed

        from .cluster import make_cluster, scale, uses_member_resource

        own_client = own_cluster = None
        interrupted = False
        t_setup = time.perf_counter()
        if client is None:
            cfg = dict(self.spec.cluster)
            if scheduler:
                cfg = {"kind": "address", "address": scheduler}
            cluster, desc = make_cluster(cfg, len(todo), workers)
            own_cluster = cluster
            try:
                own_client = client = Client(cluster if cluster is not None else cfg["address"])
            except (OSError, TimeoutError) as exc:
                if cluster is not None:
                    cluster.close()
                raise LagiceError(f"cannot connect to the dask scheduler {cfg.get('address', '')}: {exc}") from exc
            if cluster is not None:
                scale(cluster, cfg, workers)
            _say(f"ensemble: {desc}; ready in {time.perf_counter() - t_setup:.1f} s; "
                 f"dashboard {client.dashboard_link}")
            self.last_run["cluster"] = desc
        try:
            if own_cluster is not None:  # our LocalCluster / jobqueue workers all declare the member resource
                resource, slots = True, max(1, len(getattr(own_cluster, "workers", {})) or 1)
            else:  # an existing cluster: use the resource only if every worker declares it
                try:
                    client.wait_for_workers(1, timeout=120)
                except TimeoutError:
                    raise LagiceError(f"no dask worker joined the scheduler {client.scheduler.address} "
                                      "in 120 s") from None
                resource, slots = uses_member_resource(client)
            if own_cluster is not None:  # a signal reaching our workers stops their members cleanly
                from .member import WorkerStopPlugin
                client.register_plugin(WorkerStopPlugin())
            self.last_run["setup_s"] = time.perf_counter() - t_setup
            token = uuid.uuid4().hex[:8]
            futures = {}
            for rank, m in enumerate(todo):  # largest first: dask runs the higher priority first
                kw = {"resources": {"member": 1}} if resource else {}
                f = client.submit(run_member, self._task(m), key=f"lagice-member-{m.id}-{token}", pure=False,
                                  priority=len(todo) - rank, **kw)
                futures[f] = m.id
            prog = _Progress(len(todo), slots=max(1, slots), client=client)
            interrupted = True  # until the loop ends normally: Ctrl-C / SIGTERM stop the workers promptly
            for f in as_completed(futures):
                mid = futures[f]
                if f.status != "finished":  # the worker died, or the task was cancelled
                    try:
                        exc = f.exception()
                    except BaseException as e:  # noqa: BLE001 - CancelledError
                        exc = e
                    rec = {"member": mid, "status": "failed", "error": f"{type(exc).__name__}: {exc}",
                           "overrides": self.spec.member(mid).overrides, "wall_s": math.nan}
                    mdir = self.out_dir / "members" / mid
                    mdir.mkdir(parents=True, exist_ok=True)
                    write_json(mdir / "failed.json", rec)
                else:
                    rec = f.result()
                    self._note_lock_failed(rec)
                prog.finished(rec)
            interrupted = False
        finally:
            if interrupted and own_cluster is not None:
                _kill_local_workers(own_cluster)
            if own_client is not None:
                own_client.close()
            if own_cluster is not None:
                own_cluster.close()

    def _note_lock_failed(self, rec: dict) -> None:
        """A member that could not lock its run folder (another process holds the lock) wrote
        nothing there: its record of this run goes into the summary from here."""
        if rec.get("lock_failed"):
            self._lock_failed[rec["member"]] = rec

    # -- summary ----------------------------------------------------------------------------
    def records(self) -> list[dict]:
        """Every member's record from its folder, in member order: done, failed, stopped
        (a clean stop with a checkpoint) or not_run."""
        from .member import member_diagnostics
        out = []
        keys = list(dict.fromkeys(k for m in self.members for k in m.overrides))
        for m in self.members:
            mdir = self.out_dir / "members" / m.id
            rec = None
            for name in ("done.json", "failed.json"):
                if (mdir / name).exists():
                    rec = json.loads((mdir / name).read_text())
                    break
            if rec is not None and rec["status"] == "done" and rec.get("config_hash") != m.config_hash:
                rec = {"member": m.id, "status": "not_run", "overrides": m.overrides,
                       "error": "finished with an earlier run.duration/output settings; run the ensemble again "
                                "to extend it"}
            if rec is None and (mdir / "member.json").exists():
                info = json.loads((mdir / "member.json").read_text())
                if info.get("status") == "stopped":
                    rec = {k: info.get(k) for k in ("member", "status", "error", "overrides", "resumed_from",
                                                    "wall_s", "cpu_s", "numba_threads")}
            if m.id in self._lock_failed:  # this run could not lock its folder (another process writes it)
                rec = {k: v for k, v in self._lock_failed[m.id].items() if k != "lock_failed"}
            if rec is None:
                rec = {"member": m.id, "status": "not_run", "overrides": m.overrides,
                       "error": "not finished (interrupted or not started)"}
            rec["values"] = {k: _lookup(m.config, k) for k in keys}
            if rec["status"] == "done" and rec.get("analysis") != self.spec.analysis:
                rec["diagnostics"] = member_diagnostics(mdir, self.spec.analysis)  # analysis settings changed
                rec["analysis"] = self.spec.analysis
                write_json(mdir / "done.json", rec)
            out.append(rec)
        return out

    def summarise(self, plot: bool = True):
        """Write ``ensemble_summary.nc`` (and the spread PNG) from the member folders."""
        from .summary import plot_spread, summary_dataset, write_summary

        ds = summary_dataset(self.records(), self._info())
        write_summary(ds, self.out_dir / "ensemble_summary.nc")
        if plot:
            try:
                png = plot_spread(self.out_dir, ds)
                if png is not None:
                    _say(f"ensemble: spread plot {png}")
            except Exception as exc:  # noqa: BLE001 - a plot failure must not hide the summary
                _say(f"ensemble: warning: no spread plot ({type(exc).__name__}: {exc})")
        return ds


#: what one implicit step costs per element, in explicit element-sub-steps, for the start
#: order of :func:`estimated_cost`. Measured on the 2-vCPU VM, one thread (2026-11-28): an
#: implicit step took 1.0 µs per element in ``uniaxial_compression`` and 17.6 µs in
#: ``winter_basin`` at 20 km, against about 22 ns per element-sub-step for the serial
#: explicit kernels (45 M/s, docs/benchmarks.md): 45 and 800 sub-steps; 200 lies between them
#: (their geometric mean is 190). A calibration for the order only.
IMPLICIT_STEP_SUBSTEPS = 200.0


def estimated_cost(cfg: dict) -> float:
    """A member's relative cost, for the order in which members start (:func:`largest_first`):
    elements × outer steps × sub-steps per step. Elements from the domain's area over the area
    of an equilateral triangle of edge ``domain.resolution_m``; outer steps ``run.duration`` /
    ``solver.dt``; sub-steps ``solver.substeps`` when fixed, for the explicit Maxwell-EB stepper
    otherwise ``solver.dt`` over the stability limit at that resolution and the undamaged
    modulus (:func:`lagice.stability.explicit_substep_limit`, times ``solver.safety``), 300 for
    mEVP (its default), and :data:`IMPLICIT_STEP_SUBSTEPS` for an implicit step (its Newton
    iterations are not known before it runs: a measured average, not the member's). Only an
    estimate, for the order: nothing is meshed, and a member whose estimate fails (its domain
    cannot be built here) gets +inf, so it starts first rather than last."""
    from ..scenes.builder import domain_polygon
    from ..scenes.components import time_step_s
    from ..schedule import parse_duration

    try:
        res = float(cfg["domain"]["resolution_m"])
        elements = domain_polygon(cfg).area / (math.sqrt(3.0) / 4.0 * res * res)
        dt = time_step_s(cfg)
        steps = parse_duration(cfg["run"]["duration"], "run.duration") / dt
        sv = cfg["solver"]
        per_step = IMPLICIT_STEP_SUBSTEPS if sv["name"] == "implicit" else 1.0
        if sv.get("substeps"):
            per_step = float(sv["substeps"])
        elif sv["name"] == "evp":
            per_step = 300.0
        elif sv["name"] == "explicit":
            from ..scenes.builder import build_rheology
            from ..stability import explicit_substep_limit

            p = build_rheology(cfg).params
            per_step = math.ceil(dt / ((sv.get("safety") or 0.7) * explicit_substep_limit(res, p.E0, p)))
        return elements * steps * per_step
    except Exception:  # noqa: BLE001 - an estimate only: the member's own checks report real problems
        return math.inf


def largest_first(members: list) -> list:
    """``members`` sorted by :func:`estimated_cost`, largest first (spec order among equal
    costs): with fewer workers than members, the longest members do not start last and
    leave the other workers idle while they finish (the makespan of a sweep over resolution
    or duration)."""
    cost = {m.id: estimated_cost(m.config) for m in members}
    return sorted(members, key=lambda m: -cost[m.id])


class _StopOnSignal:
    """While an ensemble runs (main thread only): the first SIGTERM or SIGINT writes
    ``DIR/STOP`` (members stop cleanly with a checkpoint, none starts) and sets
    ``ensemble.stopped``; a second one raises KeyboardInterrupt (stop at once)."""

    SIGNALS = ("SIGTERM", "SIGINT")

    def __init__(self, ensemble, enabled: bool = True):
        self.ens = ensemble
        self.enabled = enabled and threading.current_thread() is threading.main_thread()
        self._old = {}
        self.received = 0

    def _handler(self, signum, frame):
        name = signal.Signals(signum).name
        self.received += 1
        if self.received > 1:
            raise KeyboardInterrupt(f"second signal ({name})")
        self.ens.stopped = f"{name} received"
        with contextlib.suppress(OSError):
            (self.ens.out_dir / STOP_FILE).write_text(f"{name} received {_dt.datetime.now().isoformat()}\n")
        print(f"lagice ensemble: {name} received: the running members stop after their current step with a "
              "checkpoint, no other member starts (a second signal stops at once)", flush=True)

    def __enter__(self):
        self.ens.stopped = None
        if self.enabled:
            for name in self.SIGNALS:
                num = getattr(signal, name)
                self._old[num] = signal.signal(num, self._handler)
        return self

    def __exit__(self, *exc):
        for num, old in self._old.items():
            signal.signal(num, old)
        self._old = {}
        return False


class _FolderLock:
    """``DIR/ensemble.lock`` while an ensemble runs in DIR: an exclusive ``flock`` on the
    file, which holds the holder's host, pid and start time as JSON. A second ``lagice
    ensemble`` on the same folder is refused at once, naming that process, instead of mixing
    runs. The kernel drops the lock when its process ends, so a file left by a killed run
    (or one naming a pid that this host has since given to another process) never blocks
    the next one. The file is removed on release, while the lock is still held; a process
    that locked the file just before it was removed sees that it holds a lock on a file no
    longer in the folder and tries again."""

    def __init__(self, path: Path):
        self.path = path
        self.held = False
        self._fd = None

    def __enter__(self):
        try:
            import fcntl
        except ImportError:  # pragma: no cover - not a POSIX system
            raise LagiceError(f"{self.path}: this system has no flock (fcntl); lagice does not run an ensemble "
                              "unlocked") from None
        me = {"host": socket.gethostname(), "pid": os.getpid(),
              "started": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")}
        for _ in range(10):
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                try:
                    other = json.loads(os.read(fd, 4096).decode() or "{}")
                except (OSError, ValueError):
                    other = {}
                os.close(fd)
                raise LagiceError(f"{self.path.parent}: another lagice ensemble is running in this folder "
                                  f"(pid {other.get('pid')} on {other.get('host')}, since {other.get('started')}); "
                                  "wait for it to end, or stop it (SIGTERM to that process, or touch "
                                  f"{self.path.parent / STOP_FILE})") from None
            except OSError as exc:
                os.close(fd)
                raise LagiceError(f"{self.path}: cannot take the ensemble lock: {exc.strerror}") from None
            try:
                same = os.fstat(fd).st_ino == os.stat(self.path).st_ino
            except FileNotFoundError:
                same = False
            if not same:  # removed by the holder that released it just now: lock the new file
                os.close(fd)
                continue
            os.ftruncate(fd, 0)
            os.write(fd, json.dumps(me).encode())
            self._fd = fd
            self.held = True
            return self
        raise LagiceError(f"{self.path}: cannot take the ensemble lock (the file kept being replaced)")

    def __exit__(self, *exc):
        if self.held:
            self.path.unlink(missing_ok=True)
            os.close(self._fd)  # drops the flock
            self._fd = None
            self.held = False
        return False


def _kill_local_workers(cluster) -> None:
    """Stop the worker processes of our LocalCluster at once (Ctrl-C, SIGTERM): a
    graceful close would wait for the members in flight. Their checkpoints,
    snapshots and markers are written atomically, so a re-run resumes them."""
    for w in list(getattr(cluster, "workers", {}).values()):
        pid = getattr(w, "pid", None)
        if isinstance(pid, int) and pid > 0:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.kill(pid, signal.SIGKILL)


class _Progress:
    """Progress across members: done / running / failed / waiting and an ETA."""

    def __init__(self, n: int, slots: int, client=None):
        self.n, self.slots, self.client = n, slots, client
        self.done = self.failed = self.stopped = 0
        self.t0 = time.perf_counter()

    def started(self, mid):
        _say(f"  [{self.done + self.failed + self.stopped + 1}/{self.n}] {mid}: started")

    def finished(self, rec):
        if rec.get("status") == "done":
            self.done += 1
            what = f"done in {rec.get('wall_s', math.nan):.1f} s"
            if rec.get("resumed_from"):
                what += f" (resumed from {Path(rec['resumed_from']).name})"
        elif rec.get("status") == "stopped":
            self.stopped += 1
            what = str(rec.get("error"))
        else:
            self.failed += 1
            what = f"FAILED after {rec.get('wall_s', math.nan):.1f} s: {rec.get('error')}"
        k = self.done + self.failed + self.stopped
        left = self.n - k
        if self.client is not None:
            from .cluster import uses_member_resource
            with contextlib.suppress(Exception):  # progress only: keep the last count
                self.slots = max(1, uses_member_resource(self.client)[1])
        running = min(self.slots, left)
        el = time.perf_counter() - self.t0
        eta = el / k * left if k and not self.stopped else math.nan
        stopped = f", stopped {self.stopped}" if self.stopped else ""
        _say(f"  [{k}/{self.n}] {rec['member']}: {what} | done {self.done}, failed {self.failed}{stopped}, "
             f"running {running}, waiting {left - running} | elapsed {_hms(el)}, ETA {_hms(eta)}")


def _hms(s: float) -> str:
    if not math.isfinite(s):
        return "--:--:--"
    s = round(s)
    return f"{s // 3600:d}:{s // 60 % 60:02d}:{s % 60:02d}"


def _say(msg: str) -> None:
    print(f"lagice {msg}" if not msg.startswith(" ") else msg, flush=True, file=sys.stdout)


def _lookup(cfg: dict, dotted: str):
    node = cfg
    for p in dotted.split("."):
        if not isinstance(node, dict):
            return None
        node = node.get(p)
    return node
