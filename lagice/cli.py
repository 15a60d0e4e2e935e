"""Command line.

    lagice run SCENE [--out DIR] [--set key=value ...]   run a bundled scene or a TOML file
    lagice resume CHECKPOINT                              continue a run (file or directory)
    lagice plot RUN_DIR                                   redraw the run's own figure
    lagice info FILE                                      describe a netCDF output or checkpoint
    lagice diagnose OUTPUT [--window-steps K] [--coast-buffer-km B]
                                                          deformation statistics (JSON + PNG)
    lagice diagnose OUTPUT --window-days D [--start-day S] [--coast-buffer-km B]
                                                          statistics over back-to-back windows
    lagice scenes                                         list bundled scenes
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .errors import LagiceError


def _run(args) -> int:
    from .scenes import DEFAULT_SCENE
    from .scenes.builder import build_simulation, finish
    from .scenes.config import load_scene

    name = args.scene or DEFAULT_SCENE
    cfg = load_scene(name, args.set)
    out = Path(args.out or Path("runs") / cfg["scene"]["name"])
    print(f"lagice: running scene {cfg['scene']['name']!r} ({cfg['scene']['source']}) -> {out}/", flush=True)
    sim = build_simulation(cfg, out)
    _report(finish(sim))
    return 0


def _report(res):
    print(f"lagice: done in {res['wall_s']:.1f} s wall")
    print(f"  output: {Path(res['netcdf']).resolve()}")
    if res.get("png"):
        print(f"  plot:   {Path(res['png']).resolve()}")


def _resume(args) -> int:
    from .scenes.builder import finish
    from .simulation import Simulation

    ck = Path(args.checkpoint)
    ck_dir = ck if ck.is_dir() else ck.parent
    run_dir = ck_dir.parent if ck_dir.name == "checkpoints" else ck_dir
    sim = Simulation.resume(ck, out_dir=run_dir)
    clock = sim.model.clock
    print(f"lagice: resuming {sim.model.config.get('scene', {}).get('name', '?')!r} from "
          f"{sim.resumed_from} (step {clock.iteration}, day {clock.time_s / 86400:.3f}) -> {run_dir}/", flush=True)
    _report(finish(sim))
    return 0


def _plot(args) -> int:
    from .io.snapshots import snapshot_dir
    from .scenes.builder import plot_scene

    snaps = snapshot_dir(args.output)
    run_dir = snaps.parent if snaps.name == "snapshots" else snaps
    summary = None
    if (run_dir / "summary.json").exists():
        summary = json.loads((run_dir / "summary.json").read_text())
    cfg = _run_config(snaps)
    png = plot_scene(cfg, run_dir, summary)
    if args.png and png is not None:
        Path(png).replace(args.png)
        png = Path(args.png)
    print(f"  plot: {Path(png).resolve() if png else '(this scene has no plot)'}")
    return 0


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
    if p.suffix == ".npz":
        from .io.checkpoint import read_checkpoint
        arrays, meta = read_checkpoint(p)
        print(f"checkpoint {p}: step {meta['step']}, t = {meta['clock']['time_s']:.1f} s, "
              f"format {meta.get('format_version')}, lagice {meta.get('lagice_version')}, "
              f"scene {meta.get('config', {}).get('scene', {}).get('name')}, "
              f"fingerprint {meta.get('scene_fingerprint')}")
        for k, a in arrays.items():
            print(f"  {k}: {a.dtype} {a.shape}")
        return 0
    import xarray as xr
    with xr.open_dataset(p) as ds:
        print(ds)
    return 0


def _diagnose(args) -> int:
    """One window (the last ``--window-steps`` snapshots: JSON + PNG figures) or, with
    ``--window-days``, back-to-back windows over the run (``window_statistics.json``):
    both through :mod:`lagice.diagnostics.windows`."""
    from .diagnostics import diagnose_arrays, window_arrays, window_statistics
    from .io.snapshots import read_index, snapshot_dir

    snaps = snapshot_dir(args.output)
    if args.window_steps < 1:
        raise LagiceError(f"--window-steps = {args.window_steps}: expected an integer >= 1")
    if not args.coast_buffer_km >= 0:
        raise LagiceError(f"--coast-buffer-km = {args.coast_buffer_km}: expected a distance >= 0 km")
    index = read_index(snaps)
    if len(index) < 2:
        raise LagiceError(f"{snaps}: need two snapshots to diagnose deformation (found {len(index)})")
    out = Path(args.out or snaps.parent / "diagnostics")
    if args.window_days is not None:
        return _diagnose_windows(args, snaps, out, window_statistics)
    k = min(args.window_steps, len(index) - 1)
    xy0, xy1, tri, dt, w = window_arrays(snaps, index[-1 - k]["time_s"], index[-1]["time_s"],
                                         args.coast_buffer_km * 1e3)
    if w["remesh_events"]:
        print(f"  {w['remesh_events']} remesh event(s) in the window: nodes followed by node_id, "
              f"{w['n_elements_lost']} remeshed elements left out")
    if args.coast_buffer_km > 0:
        print(f"  {w['n_elements']} of {tri.shape[0]} elements are >= {args.coast_buffer_km:g} km from the boundary")
    res = diagnose_arrays(xy0, xy1, tri[w["interior"]], dt, out)
    print(f"  diagnostics over a {dt / 86400:.2f}-day window -> {out.resolve()}/diagnostics.json")
    for key in ("beta_space", "pdf_tail_exponent_shear", "pdf_tail_exponent_divergence",
                "localisation_half_shear_area_fraction", "shear_divergence_r2"):
        if key in res:
            print(f"  {key}: {res[key]}")
    return 0


def _diagnose_windows(args, snaps, out, window_statistics) -> int:
    res = window_statistics(snaps, args.window_days, args.coast_buffer_km, args.start_day, args.end_day)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "window_statistics.json"
    path.write_text(json.dumps(res, indent=1, default=_json_default))
    print(f"  {len(res['windows'])} back-to-back windows of {args.window_days:g} days from day {args.start_day:g}, "
          f"elements >= {args.coast_buffer_km:g} km from the boundary -> {path.resolve()}")
    for w in res["skipped"]:
        print(f"  days {w['start_day']:g}-{w['end_day']:g}: skipped: {w['reason']}")
    for w in res["windows"]:
        lost = f", {w['n_elements_lost']} remeshed left out" if w["n_elements_lost"] else ""
        print(f"  days {w['start_day']:g}-{w['end_day']:g}: {w['n_elements']} elements{lost}, "
              f"beta {_num(w['interior']['beta_space'])}")
    for key, med in res["median"].items():
        print(f"  {key}: median {_num(med)} [{_num(res['min'][key])}, {_num(res['max'][key])}]")
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
    ap = argparse.ArgumentParser(prog="lagice", description="Lagrangian Maxwell-EB sea-ice model")
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run a scene (bundled name or TOML file)")
    r.add_argument("scene", nargs="?", help="scene name or path.toml (default: uniaxial_compression)")
    r.add_argument("--out", help="output directory (default runs/SCENE)")
    r.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a scene key: table.key=value (e.g. run.duration=2d)")
    r.set_defaults(func=_run)
    s = sub.add_parser("resume", help="resume from a checkpoint file or directory")
    s.add_argument("checkpoint")
    s.set_defaults(func=_resume)
    p = sub.add_parser("plot", help="redraw the figure of a run directory (or its snapshot folder)")
    p.add_argument("output")
    p.add_argument("--png")
    p.set_defaults(func=_plot)
    i = sub.add_parser("info", help="describe an output file or checkpoint")
    i.add_argument("file")
    i.set_defaults(func=_info)
    d = sub.add_parser("diagnose", help="deformation statistics of a run (JSON + PNG)")
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
    d.add_argument("--out")
    d.set_defaults(func=_diagnose)
    sc = sub.add_parser("scenes", help="list bundled scenes")
    sc.set_defaults(func=_scenes)
    args = ap.parse_args(argv)
    try:
        return args.func(args)
    except LagiceError as exc:
        print(f"lagice: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
