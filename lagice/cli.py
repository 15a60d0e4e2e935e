"""Command line.

    lagice [--version] [--log-level LEVEL] COMMAND ...
    lagice run SCENE [--out DIR] [--overwrite | --resume] [--set key=value ...]
                                                          run a bundled scene or a TOML file
    lagice resume RUN_DIR|CHECKPOINT [--set key=value ...]
                                                          continue (or extend: --set run.duration=60d) a run
    lagice branch CHECKPOINT [--out DIR] [--set key=value ...]
                                                          a new run from a checkpoint, changed physics allowed
    lagice plot RUN_DIR                                   redraw the run's own figure
    lagice info FILE                                      describe a netCDF output or checkpoint
    lagice diagnose OUTPUT [--window-steps K] [--coast-buffer-km B]
                                                          deformation statistics (JSON + PNG)
    lagice diagnose OUTPUT --window-days D [--start-day S] [--coast-buffer-km B]
                                                          statistics over back-to-back windows
    lagice diagnose OUTPUT --wind-factor                  drifters' daily drift against the wind
    lagice scenes                                         list bundled scenes
    lagice ensemble SPEC [--out DIR] [--workers N] [--scheduler ADDRESS]
                                                          ensemble / parameter sweep on dask

A new run writes to ``runs/SCENE-YYYYmmdd-HHMMSS/`` (linked as ``runs/SCENE-latest``)
unless ``--out`` names a folder, which must be empty (``--overwrite`` replaces a
previous run in it, ``--resume`` continues it). The process that runs into a folder holds its
lock (``DIR/.lock``, :class:`lagice.rundir.RunLock`) until it exits: a second ``run``, ``resume``
or ``branch`` on the folder fails at once (exit 2). SIGTERM/SIGINT stop a run cleanly
with a checkpoint (exit 0). Errors in the input, the files or the file system print
one line and exit with status 2 (``--log-level debug`` shows the traceback).
"""
from __future__ import annotations

import argparse
import json
import logging
import math
import sys
from pathlib import Path

from .errors import LagiceError

log = logging.getLogger("lagice")


class _StdoutBelowWarning(logging.Handler):
    """INFO and DEBUG lines to stdout, warnings and errors to stderr, as ``lagice: ...``."""

    def emit(self, record):
        try:
            msg = self.format(record)
            if record.levelno >= logging.WARNING:
                print(f"lagice: {record.levelname.lower()}: {msg}", file=sys.stderr, flush=True)
            else:
                print(f"lagice: {msg}", file=sys.stdout, flush=True)
        except Exception:  # noqa: BLE001 - logging must never raise
            self.handleError(record)


def setup_logging(level: str = "info") -> None:
    """The ``lagice`` logger at ``level`` (debug, info, warning, error)."""
    lvl = getattr(logging, str(level).upper(), None)
    if not isinstance(lvl, int):
        raise LagiceError(f"--log-level {level!r}: expected debug, info, warning or error")
    for h in list(log.handlers):
        if isinstance(h, _StdoutBelowWarning):
            log.removeHandler(h)
    log.addHandler(_StdoutBelowWarning())
    log.setLevel(lvl)
    log.propagate = False


_COMPILE_NOTICE = []


def _announce_numba_compilation() -> None:
    """One line when numba starts compiling a kernel (a first run on this machine, or
    after an upgrade); kernels load from numba's cache afterwards (no such line)."""
    try:
        from numba.core import event
    except ImportError:  # pragma: no cover
        return

    class _Listener(event.Listener):
        def on_start(self, ev):
            if not _COMPILE_NOTICE:
                _COMPILE_NOTICE.append(1)
                log.info("numba is compiling the kernels this run needs (first run only: they are cached "
                         "for later runs; this can take a minute)")

        def on_end(self, ev):
            pass

    event.register("numba:compile", _Listener())


def _where(out: Path) -> str:
    return str(out) if out.is_absolute() else f"{out} ({out.resolve()})"


def _run(args) -> int:
    from .rundir import RunLock, claim, make_run_dir, restart_unstarted, update_latest
    from .scenes import DEFAULT_SCENE
    from .scenes.builder import build_simulation, resume_simulation, validate_config
    from .scenes.config import load_scene

    name = args.scene or DEFAULT_SCENE
    cfg = load_scene(name, args.set)
    validate_config(cfg)  # every check that needs no mesh and no folder
    out = Path(args.out) if args.out else None
    if args.resume and out is None:
        raise LagiceError("--resume needs --out DIR (the run folder to continue)")
    default = out is None
    if default:  # a new runs/SCENE-YYYYmmdd-HHMMSS, made here (and removed again if the run cannot start)
        out = make_run_dir(cfg["scene"]["name"])
    # the run folder is this process's until it exits: a second process on it fails here, at once
    with RunLock(out, created=default):
        if args.resume and (out / "checkpoints").is_dir() and any((out / "checkpoints").glob("checkpoint_*.npz")):
            return _continue(resume_simulation(out, config=cfg), out, resumed=True)
        if args.resume:  # no checkpoint: start it (afresh, if it was stopped before one)
            restart_unstarted(out, cfg)
        elif not default:
            claim(out, overwrite=args.overwrite)
        sim = build_simulation(cfg, out)
        log.info(f"running scene {cfg['scene']['name']!r} ({cfg['scene']['source']}) -> {_where(sim.out_dir)}/")
        if default:
            link = update_latest(out, cfg["scene"]["name"])
            if link is not None:
                log.info(f"(also reachable as {link}/)")
        return _continue(sim, sim.out_dir)


def _continue(sim, run_dir: Path, resumed: bool = False) -> int:
    """Run ``sim`` to its end (or a stop) and report; a finished run is left untouched."""
    from .scenes.builder import finish

    clock = sim.model.clock
    if resumed or sim.resumed_from is not None:
        if sim.finished:
            log.info(f"the run in {run_dir}/ already finished at step {clock.iteration} (day "
                     f"{clock.time_s / 86400:.3f}); nothing to do. Extend it with: lagice resume {run_dir} "
                     f"--set run.duration=...")
            return 0
        log.info(f"resuming {sim.model.config.get('scene', {}).get('name', '?')!r} from {sim.resumed_from} "
                 f"(step {clock.iteration}, day {clock.time_s / 86400:.3f}) -> {run_dir}/")
    res = finish(sim)
    _report(res, sim)
    return 0


def _report(res, sim):
    s = res["summary"]
    out = Path(res["out_dir"])
    if s.get("stop_reason"):
        ck = s.get("checkpoint")
        print(f"lagice: stopped at step {s['steps']} (day {s['time_s'] / 86400:.3f}): {s['stop_reason']}; "
              f"checkpoint {ck if ck else '(none: this simulation has no checkpointer)'}")
        if ck:
            print(f"  resume with: lagice resume {out}")
        return
    print(f"lagice: done in {res['wall_s']:.1f} s wall (whole run)")
    print(f"  outputs: {out.resolve()}/")
    print(f"  output: {Path(res['netcdf']).resolve()}")
    if res.get("png"):
        print(f"  plot:   {Path(res['png']).resolve()}")


def _resume(args) -> int:
    from .errors import RestartError
    from .rundir import MARKER, RunLock
    from .scenes.builder import resume_simulation
    from .simulation import load_checkpoint, run_folder_of

    d = Path(args.checkpoint)
    if (d / MARKER).is_file() and not any((d / "checkpoints").glob("checkpoint_*.npz")):
        try:
            info = json.loads((d / MARKER).read_text())
        except (OSError, ValueError):
            info = {}
        scene = info.get("source") or info.get("scene") or "SCENE"
        raise RestartError(f"no checkpoint in {d}: its run stopped before its first checkpoint; start it again "
                           f"there with: lagice run {scene} --out {d} --resume")
    folder = _resume_folder(d)
    if folder is None:  # no such file or folder: load_checkpoint says what is wrong
        load_checkpoint(args.checkpoint)
        raise RestartError(f"{d}: not a checkpoint, checkpoint folder or run folder")
    with RunLock(folder):  # the run folder is this process's until it exits
        path = load_checkpoint(args.checkpoint)[0]
        run_dir = run_folder_of(path)
        if run_dir.resolve() != folder.resolve():  # pragma: no cover - _resume_folder follows load_checkpoint
            raise RestartError(f"{d}: its checkpoint {path} is not in the run folder {folder}")
        sim = resume_simulation(path, args.set)
        return _continue(sim, run_dir, resumed=True)


def _resume_folder(d: Path) -> Path | None:
    """The run folder ``lagice resume d`` writes (as :func:`lagice.simulation.load_checkpoint`
    finds the checkpoint: a file, a checkpoint folder or a run folder), without reading a
    checkpoint; None when ``d`` does not exist."""
    from .simulation import run_folder_of

    if d.is_file():
        return run_folder_of(d)
    if not d.is_dir():
        return None
    if (d / "checkpoints").is_dir() and not list(d.glob("checkpoint_*.npz")):
        return d  # a run folder
    return run_folder_of(d / "checkpoint")


def _branch(args) -> int:
    from .rundir import RunLock, make_run_dir, update_latest
    from .scenes.builder import branch_config, branch_simulation
    from .simulation import load_checkpoint

    path, _, meta = load_checkpoint(args.checkpoint)
    cfg = branch_config(path, meta, args.set)  # every check that needs no mesh and no folder
    default = args.out is None
    out = make_run_dir(cfg["scene"]["name"]) if default else Path(args.out)
    with RunLock(out, created=default):  # the new run's folder is this process's until it exits
        sim = branch_simulation(path, out, config=cfg, overwrite=args.overwrite)
        p = sim.branched_from
        log.info(f"branching {sim.model.config['scene']['name']!r} from {p['checkpoint']} (step "
                 f"{sim.model.clock.iteration}, day {sim.model.clock.time_s / 86400:.3f}, sha256 "
                 f"{p['sha256'][:12]}...) -> {_where(sim.out_dir)}/")
        if default:
            update_latest(out, cfg["scene"]["name"])
        return _continue(sim, sim.out_dir)


def _plot(args) -> int:
    from .io.snapshots import snapshot_dir
    from .scenes.builder import plot_scene

    snaps = snapshot_dir(args.output)
    run_dir = snaps.parent if snaps.name == "snapshots" else snaps
    _note_if_running(run_dir, snaps, "figure", "the run draws its own figure again when it ends")
    summary = None
    if (run_dir / "summary.json").exists():
        summary = json.loads((run_dir / "summary.json").read_text())
    cfg = _run_config(snaps)
    # --png: drawn there, and the run's own figure stays (it used to be moved to --png)
    png = plot_scene(cfg, run_dir, summary, png_path=args.png or None)
    print(f"  plot: {Path(png).resolve() if png else '(this scene has no plot)'}")
    return 0


def _note_if_running(run_dir: Path, snaps: Path, what: str, after: str) -> None:
    """Say so when a process still runs into ``run_dir`` (its lock is held: a run or a resume
    still going): the commands that read a run folder work beside it, on the snapshots
    written so far (each snapshot and the index are written whole, by atomic renames), and
    what they write is written whole too (:func:`lagice.io.cf.save_figure_atomic`)."""
    from .io.snapshots import read_index
    from .rundir import running_holder

    holder = running_holder(run_dir)
    if holder is None:
        return
    last = read_index(snaps)[-1]
    log.info(f"the run in {run_dir}/ is still going ({holder}): this {what} covers its snapshots up to day "
             f"{last['time_s'] / 86400:.3f} (step {last['step']}); {after}")


def _run_config(snaps: Path) -> dict:
    """The scene configuration a run was made with (from its first snapshot)."""
    import xarray as xr

    from .io.snapshots import read_index

    idx = read_index(snaps)
    with xr.open_dataset(snaps / idx[0]["file"], decode_times=False) as ds:
        raw = ds.attrs.get("lagice_config")
    if raw is None:
        raise LagiceError(f"{snaps}: the snapshots carry no scene configuration (lagice_config attribute)")
    return json.loads(raw)


def _info(args) -> int:
    p = Path(args.file)
    if not p.exists():
        raise LagiceError(f"file {p} does not exist")
    if p.is_dir():
        raise LagiceError(f"{p} is a folder; give a netCDF output (.nc) or a checkpoint (.npz)")
    with open(p, "rb") as f:
        head = f.read(8)
    if p.suffix == ".npz" or head[:4] == b"PK\x03\x04":
        from .io.checkpoint import read_checkpoint
        arrays, meta = read_checkpoint(p)
        print(f"checkpoint {p}: step {meta['step']}, t = {meta['clock']['time_s']:.1f} s, "
              f"format {meta.get('format_version')}, lagice {meta.get('lagice_version')}, "
              f"scene {meta.get('config', {}).get('scene', {}).get('name')}, "
              f"fingerprint {meta.get('scene_fingerprint')}")
        parent = meta.get("config", {}).get("_parent")
        if parent:
            print(f"  branched from {parent['checkpoint']} (sha256 {parent['sha256']})")
        for k, a in arrays.items():
            print(f"  {k}: {a.dtype} {a.shape}")
        return 0
    if head[:3] != b"CDF" and head[:8] != b"\x89HDF\r\n\x1a\n":
        raise LagiceError(f"{p} is neither a netCDF file nor a lagice checkpoint (it starts with {head[:8]!r})")
    import xarray as xr
    try:
        ds = xr.open_dataset(p, decode_times=False)
    except Exception as exc:  # noqa: BLE001 - any reader failure is a bad file
        raise LagiceError(f"{p}: cannot read it as netCDF ({type(exc).__name__}: {exc})") from None
    with ds:
        print(ds)
    return 0


def _diagnose(args) -> int:
    """One window (the last ``--window-steps`` snapshots: JSON + PNG figures) or, with
    ``--window-days``, back-to-back windows over the run (``window_statistics.json``):
    both through :mod:`lagice.diagnostics.windows`."""
    from .diagnostics import diagnose_arrays, window_arrays, window_statistics
    from .io.snapshots import read_index, snapshot_dir

    if args.wind_factor:
        return _diagnose_drift(args)
    snaps = snapshot_dir(args.output)
    if args.window_steps < 1:
        raise LagiceError(f"--window-steps = {args.window_steps}: expected an integer >= 1")
    if not args.coast_buffer_km >= 0:
        raise LagiceError(f"--coast-buffer-km = {args.coast_buffer_km}: expected a distance >= 0 km")
    if args.rgps_error_m is not None and args.window_days is None:
        raise LagiceError(f"--rgps-error-m = {args.rgps_error_m:g} needs --window-days (the RGPS view is computed "
                          f"per window)")
    if args.rgps_error_m is not None and not (math.isfinite(args.rgps_error_m) and args.rgps_error_m >= 0):
        raise LagiceError(f"--rgps-error-m = {args.rgps_error_m}: expected a tracking error >= 0 m (RGPS: 100)")
    index = read_index(snaps)
    if len(index) < 2:
        raise LagiceError(f"{snaps}: need two snapshots to diagnose deformation (found {len(index)})")
    _note_if_running(snaps.parent if snaps.name == "snapshots" else snaps, snaps, "diagnosis",
                     "run it again after the run ends for the whole run")
    out = Path(args.out or snaps.parent / "diagnostics")
    if args.window_days is not None:
        return _diagnose_windows(args, snaps, out, window_statistics)
    k = min(args.window_steps, len(index) - 1)
    if k < args.window_steps:
        log.warning(f"--window-steps {args.window_steps}: the run has {len(index)} snapshots; the window was "
                    f"shortened to {k} snapshot interval(s)")
    xy0, xy1, tri, dt, w = window_arrays(snaps, index[-1 - k]["time_s"], index[-1]["time_s"],
                                         args.coast_buffer_km * 1e3)
    if w["remesh_events"]:
        print(f"  {w['remesh_events']} remesh event(s) in the window: nodes followed by node_id, "
              f"{w['n_elements_lost']} remeshed elements left out")
    if w["n_elements_folded"]:
        print(f"  {w['n_elements_folded']} element(s) inverted in the mid-window geometry left out "
              f"({w['n_interior_folded']} inside the buffer)")
    if args.coast_buffer_km > 0:
        print(f"  {w['n_elements']} of {tri.shape[0]} elements are >= {args.coast_buffer_km:g} km from the boundary")
    res = diagnose_arrays(xy0, xy1, tri[w["interior"]], dt, out)
    print(f"  diagnostics over a {dt / 86400:.2f}-day window -> {out.resolve()}/diagnostics.json")
    for key in ("beta_space", "pdf_tail_exponent_shear", "pdf_tail_exponent_divergence",
                "localisation_half_shear_area_fraction", "shear_divergence_r2"):
        if key in res:
            print(f"  {key}: {res[key]}")
    from .diagnostics.statistics import tail_fit_quality  # goodness of fit, power law vs lognormal
    from .diagnostics.strain import lagrangian_velocity_gradients

    rates = lagrangian_velocity_gradients(xy0, xy1, tri, dt, res.get("geometry", "mid"))
    for name, vals in (("shear", rates.shear_s), ("|divergence|", abs(rates.divergence_s))):
        for msg in tail_fit_quality(vals).warnings(f"PDF tail of {name}"):
            log.warning(msg)
    return 0


def _diagnose_drift(args) -> int:
    """``--wind-factor``: the drifters' daily velocities fitted to the wind along their tracks
    (Thorndike and Colony 1982; docs/diagnostics.md §13) -> ``drift_response.json``."""
    from .diagnostics.drift import run_drift_response
    from .io.cf import write_text_atomic
    from .io.snapshots import snapshot_dir

    run = Path(args.output)
    try:
        snaps = snapshot_dir(run)
    except LagiceError:
        snaps = None  # run_drift_response names what is missing
    if snaps is not None:
        _note_if_running(run, snaps, "fit", "run it again after the run ends for the whole run")
    res = run_drift_response(run)
    out = Path(args.out or run / "diagnostics")
    out.mkdir(parents=True, exist_ok=True)
    path = out / "drift_response.json"
    write_text_atomic(path, json.dumps(res, indent=1))
    f = res["fit"]
    sp = res["factor_5_95_over_drifters"]
    side = "left" if f["angle_deg"] > 0 else "right"
    print(f"  {f['n']} drifter-days ({res['drifters']} drifters, {res['lost']} lost) against the "
          f"{res['wind']} wind -> {path.resolve()}")
    print(f"  wind factor |A| = {f['factor']:.4f}" + (f" (5-95 % over the drifters {sp[0]:.4f}-{sp[1]:.4f})" if sp
                                                     else "")
          + f", the ice {abs(f['angle_deg']):.0f} deg to the {side} of the wind, R2 = {f['r2']:.2f}, mean ice speed "
          f"{100 * f['mean_ice_speed_m_s']:.1f} cm/s")
    if res["wind"] == "geostrophic":
        print("  observed (Thorndike and Colony 1982, Arctic winter): |A| about 0.008, about 5 deg to the right, "
              "R2 about 0.7")
    return 0


def _diagnose_windows(args, snaps, out, window_statistics) -> int:
    from .io.cf import write_text_atomic

    res = window_statistics(snaps, args.window_days, args.coast_buffer_km, args.start_day, args.end_day,
                            rgps_tracking_error_m=args.rgps_error_m)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "window_statistics.json"
    write_text_atomic(path, json.dumps(res, indent=1, default=_json_default))
    print(f"  {len(res['windows'])} back-to-back windows of {args.window_days:g} days from day {args.start_day:g}, "
          f"elements >= {args.coast_buffer_km:g} km from the boundary -> {path.resolve()}")
    for w in res["skipped"]:
        print(f"  days {w['start_day']:g}-{w['end_day']:g}: skipped: {w['reason']}")
    for w in res["windows"]:
        lost = f", {w['n_elements_lost']} remeshed left out" if w["n_elements_lost"] else ""
        if w["n_elements_folded"]:
            lost += (f", {w['n_elements_folded']} inverted in the mid-window geometry left out "
                     f"({w['n_interior_folded']} inside the buffer)")
        i = w["interior"]
        print(f"  days {w['start_day']:g}-{w['end_day']:g}: {w['n_elements']} elements{lost}, "
              f"beta {_num(i['beta_space'])} (over {i['beta_space_grids']} box grids "
              f"{_num(i['beta_space_grid_mean'])} ± {_num(i['beta_space_grid_sd'])})")
    for key, med in res["median"].items():
        print(f"  {key}: median {_num(med)} [{_num(res['min'][key])}, {_num(res['max'][key])}]")
    if args.rgps_error_m is not None:
        print(f"  as RGPS would see it (10 km cells, {args.rgps_error_m:g} m tracking error; without error):")
        for key, med in res["median_rgps"].items():
            print(f"  {key}: median {_num(med)} ({_num(res['median_rgps_cells'][key])})")
    return 0


def _num(x) -> str:
    return "n/a" if x is None else f"{x:.4g}"


def _json_default(x):
    import numpy as np

    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        return x.item()
    raise TypeError(f"not JSON-serialisable: {type(x).__name__}")


def _scenes(args) -> int:
    from .scenes import DEFAULT_SCENE
    from .scenes.config import list_scenes

    for name, (path, desc) in list_scenes().items():
        mark = " (default)" if name == DEFAULT_SCENE else ""
        print(f"  {name}{mark}: {desc}\n      {path}")
    return 0


def main(argv=None) -> int:
    from . import __version__

    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--log-level", default=argparse.SUPPRESS, metavar="LEVEL",
                        help="debug, info (default), warning or error; debug also prints tracebacks")
    ap = argparse.ArgumentParser(prog="lagice", description="Lagrangian Maxwell-EB sea-ice model", parents=[common])
    ap.add_argument("--version", action="version", version=f"lagice {__version__}")
    sub = ap.add_subparsers(dest="cmd", required=True)
    sets = {"action": "append", "metavar": "KEY=VALUE",
            "help": "override a scene key: table.key=value (e.g. run.duration=2d)"}
    r = sub.add_parser("run", help="run a scene (bundled name or TOML file)", parents=[common])
    r.add_argument("scene", nargs="?", help="scene name or path.toml (default: uniaxial_compression)")
    r.add_argument("--out", help="output folder, empty or new (default: a new runs/SCENE-YYYYmmdd-HHMMSS, "
                                 "linked as runs/SCENE-latest)")
    how = r.add_mutually_exclusive_group()
    how.add_argument("--overwrite", action="store_true", help="replace the previous run in --out (deleted first)")
    how.add_argument("--resume", action="store_true",
                     help="continue the run in --out from its newest checkpoint (start it if there is none)")
    r.add_argument("--set", **sets)
    r.set_defaults(func=_run)
    s = sub.add_parser("resume", parents=[common],
                       help="continue a run from its folder, checkpoint folder or a checkpoint file; "
                            "--set run.duration=... extends it, output.*/checkpoint.* may change")
    s.add_argument("checkpoint")
    s.add_argument("--set", **sets)
    s.set_defaults(func=_resume)
    b = sub.add_parser("branch", parents=[common],
                       help="start a new run from a checkpoint with changed settings (forcing, parameters)")
    b.add_argument("checkpoint")
    b.add_argument("--out", help="output folder of the new run (default: a new runs/SCENE-YYYYmmdd-HHMMSS)")
    b.add_argument("--overwrite", action="store_true", help="replace the previous run in --out")
    b.add_argument("--set", **sets)
    b.set_defaults(func=_branch)
    p = sub.add_parser("plot", help="redraw the figure of a run directory (or its snapshot folder)", parents=[common])
    p.add_argument("output")
    p.add_argument("--png")
    p.set_defaults(func=_plot)
    i = sub.add_parser("info", help="describe an output file or checkpoint", parents=[common])
    i.add_argument("file")
    i.set_defaults(func=_info)
    d = sub.add_parser("diagnose", help="deformation statistics of a run (JSON + PNG)", parents=[common])
    d.add_argument("output")
    d.add_argument("--window-steps", type=int, default=1, help="snapshots spanned by the window")
    d.add_argument("--coast-buffer-km", type=float, default=0.0,
                   help="analyse only elements this far from the mesh boundary (Girard et al. 2011: 150 km)")
    d.add_argument("--window-days", type=float, default=None,
                   help="statistics over back-to-back windows of this many days (median, [min, max]; "
                        "window_statistics.json) instead of one window")
    d.add_argument("--start-day", type=float, default=1.0, help="with --window-days: first window start (spin-up)")
    d.add_argument("--end-day", type=float, default=None, help="with --window-days: last window end (default: "
                                                               "the last snapshot)")
    d.add_argument("--rgps-error-m", type=float, default=None,
                   help="with --window-days: also the statistics as RGPS would see them: 10 km cells of tracked "
                        "points with this tracking error in m (RGPS: 100, Lindsay and Stern 2003)")
    d.add_argument("--wind-factor", action="store_true",
                   help="instead: the drifters' daily drift against the run's wind (U = A G + C, Thorndike and "
                        "Colony 1982; drift_response.json)")
    d.add_argument("--out")
    d.set_defaults(func=_diagnose)
    sc = sub.add_parser("scenes", help="list bundled scenes", parents=[common])
    sc.set_defaults(func=_scenes)
    from .ensemble.command import add_subcommand as _add_ensemble  # ensembles (lagice/ensemble, issue 14)
    _add_ensemble(sub, parents=[common])
    args = ap.parse_args(argv)
    level = getattr(args, "log_level", "info")
    try:
        setup_logging(level)
        if args.cmd in ("run", "resume", "branch"):
            _announce_numba_compilation()
        return args.func(args)
    except (LagiceError, OSError) as exc:
        if isinstance(exc, OSError) and not isinstance(exc, LagiceError):
            where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
            msg = f"{where}{exc.strerror or exc}"
        else:
            msg = str(exc)
        if log.isEnabledFor(logging.DEBUG):
            import traceback

            traceback.print_exc()
        print(f"lagice: error: {msg}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("lagice: interrupted (a second Ctrl-C: no checkpoint was written)", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
