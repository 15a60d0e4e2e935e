"""Command line.

    lagice run SCENE [--out DIR] [--set key=value ...]   run a bundled scene or a TOML file
    lagice resume CHECKPOINT                              continue a run (file or directory)
    lagice plot OUTPUT                                    plot a run directory or snapshot folder
    lagice info FILE                                      describe a netCDF output or checkpoint
    lagice diagnose OUTPUT [--window-steps K]             deformation statistics (JSON + PNG)
    lagice scenes                                         list bundled scenes
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from .errors import LagiceError


def _run(args) -> int:
    from .scenes import DEFAULT_SCENE, SCENES, parse_overrides, scene_module

    name = args.scene or DEFAULT_SCENE
    if name in SCENES:
        mod = scene_module(name)
        options = parse_overrides(args.set, mod.run)
        out = Path(args.out or Path("runs") / name)
        print(f"lagice: running scene {name!r} -> {out}/", flush=True)
        res = mod.run(out_dir=out, **options)
    else:
        from .scenes.config import load_scene
        from .scenes.toml_scene import build_simulation, finish

        cfg = load_scene(name, args.set)
        out = Path(args.out or Path("runs") / cfg["scene"]["name"])
        cfg["_out_dir"] = str(out)
        print(f"lagice: running scene {cfg['scene']['name']!r} ({cfg['scene']['source']}) -> {out}/", flush=True)
        sim = build_simulation(cfg, out)
        res = finish(sim)
    _report(res)
    return 0


def _report(res):
    print(f"lagice: done in {res['wall_s']:.1f} s wall")
    print(f"  output: {Path(res['netcdf']).resolve()}")
    if res.get("png"):
        print(f"  plot:   {Path(res['png']).resolve()}")


def _resume(args) -> int:
    from .scenes.toml_scene import finish
    from .simulation import Simulation

    ck = Path(args.checkpoint)
    ck_dir = ck if ck.is_dir() else ck.parent
    run_dir = ck_dir.parent if ck_dir.name == "checkpoints" else ck_dir
    sim = Simulation.resume(ck, out_dir=run_dir)
    st = sim.model.state
    print(f"lagice: resuming {sim.model.config.get('scene', {}).get('name', '?')!r} from "
          f"{sim.resumed_from} (step {st.step}, day {st.time_s / 86400:.3f}) -> {run_dir}/", flush=True)
    _report(finish(sim))
    return 0


def _snap_dir(p: Path) -> Path:
    if (p / "index.json").exists():
        return p
    if (p / "snapshots" / "index.json").exists():
        return p / "snapshots"
    raise LagiceError(f"{p} is not a run directory or snapshot folder (no index.json)")


def _plot(args) -> int:
    from .plotting import plot_run

    p = Path(args.output)
    if p.suffix == ".nc" and p.exists():
        import xarray as xr
        with xr.open_dataset(p) as ds:
            if "macro_stress" in ds:
                from .scenes.compression import plot_compression
                out = plot_compression(p, p.with_suffix(".png"))
                print(f"  plot: {out.resolve()}")
                return 0
        p = p.parent
    snaps = _snap_dir(p)
    summary = None
    for cand in (snaps.parent / "summary.json", snaps / "summary.json"):
        if cand.exists():
            summary = json.loads(cand.read_text())
    out = plot_run(snaps, Path(args.png or snaps.parent / "plot.png"), summary)
    print(f"  plot: {out.resolve()}")
    return 0


def _info(args) -> int:
    p = Path(args.file)
    if not p.exists():
        raise LagiceError(f"file {p} does not exist")
    if p.suffix == ".npz":
        from .io.checkpoint import read_checkpoint
        arrays, meta = read_checkpoint(p)
        print(f"checkpoint {p}: step {meta['step']}, t = {meta['time_s']:.1f} s, lagice {meta.get('lagice_version')}, "
              f"scene {meta.get('config', {}).get('scene', {}).get('name')}, fingerprint {meta.get('scene_fingerprint')}")
        for k, a in arrays.items():
            print(f"  {k}: {a.dtype} {a.shape}")
        return 0
    import xarray as xr
    with xr.open_dataset(p) as ds:
        print(ds)
    return 0


def _diagnose(args) -> int:
    import numpy as np
    import xarray as xr

    from .diagnostics import diagnose_arrays

    snaps = _snap_dir(Path(args.output))
    index = json.loads((snaps / "index.json").read_text())
    last = index[-1]
    same = [e for e in index if e["mesh_epoch"] == last["mesh_epoch"]]
    if len(same) < 2:
        raise LagiceError(f"{snaps}: need two snapshots on the same mesh to diagnose deformation "
                          f"(found {len(same)} in the last mesh epoch)")
    k = min(args.window_steps, len(same) - 1)
    e0, e1 = same[-1 - k], same[-1]
    d0 = xr.load_dataset(snaps / e0["file"], decode_times=False)
    d1 = xr.load_dataset(snaps / e1["file"], decode_times=False)
    xy0 = np.column_stack([d0["mesh_node_x"].values, d0["mesh_node_y"].values])
    xy1 = np.column_stack([d1["mesh_node_x"].values, d1["mesh_node_y"].values])
    tri = d1["mesh_face_nodes"].values.astype(np.int64)
    dt = e1["time_s"] - e0["time_s"]
    if np.allclose(xy0, xy1):  # fixed mesh: use the mean velocity over the window instead
        vel = 0.5 * (np.column_stack([d0["velocity_x"].values[0], d0["velocity_y"].values[0]])
                     + np.column_stack([d1["velocity_x"].values[0], d1["velocity_y"].values[0]]))
        xy1 = xy0 + vel * dt
    out = Path(args.out or snaps.parent / "diagnostics")
    res = diagnose_arrays(xy0, xy1, tri, dt, out)
    print(f"  diagnostics over a {dt / 86400:.2f}-day window -> {out.resolve()}/diagnostics.json")
    for key in ("beta_space", "pdf_tail_exponent_shear", "pdf_tail_exponent_divergence",
                "localisation_half_shear_area_fraction", "shear_divergence_r2"):
        if key in res:
            print(f"  {key}: {res[key]}")
    return 0


def _scenes(args) -> int:
    from .scenes import SCENES
    from .scenes.config import SCENE_DIR

    for name in sorted(SCENES):
        print(f"  {name}  (python scene)")
    for p in sorted(SCENE_DIR.glob("*.toml")):
        print(f"  {p.stem}  ({p})")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="lagice", description="Lagrangian Maxwell-EB sea-ice model")
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run a scene (bundled name or TOML file)")
    r.add_argument("scene", nargs="?", help="scene name or path.toml (default: uniaxial_compression)")
    r.add_argument("--out", help="output directory (default runs/SCENE)")
    r.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a scene key (TOML scenes: dotted, e.g. run.duration=2d)")
    r.set_defaults(func=_run)
    s = sub.add_parser("resume", help="resume from a checkpoint file or directory")
    s.add_argument("checkpoint")
    s.set_defaults(func=_resume)
    p = sub.add_parser("plot", help="plot a run directory, snapshot folder or compression output")
    p.add_argument("output")
    p.add_argument("--png")
    p.set_defaults(func=_plot)
    i = sub.add_parser("info", help="describe an output file or checkpoint")
    i.add_argument("file")
    i.set_defaults(func=_info)
    d = sub.add_parser("diagnose", help="deformation statistics of a run (JSON + PNG)")
    d.add_argument("output")
    d.add_argument("--window-steps", type=int, default=1, help="snapshots spanned by the window")
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
