"""Command line: ``lagice run SCENE [--out DIR] [--set key=value ...]``, ``lagice info FILE``."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .errors import LagiceError


def _run(args) -> int:
    from .scenes import DEFAULT_SCENE, parse_overrides, scene_module

    name = args.scene or DEFAULT_SCENE
    mod = scene_module(name)
    options = parse_overrides(args.set, mod.run)
    out = Path(args.out or Path("runs") / name)
    print(f"lagice: running scene {name!r} -> {out}/", flush=True)
    res = mod.run(out_dir=out, **options)
    print(f"lagice: done in {res['wall_s']:.1f} s wall")
    print(f"  output: {Path(res['netcdf']).resolve()}")
    if res.get("png"):
        print(f"  plot:   {Path(res['png']).resolve()}")
    return 0


def _info(args) -> int:
    import xarray as xr

    p = Path(args.file)
    if not p.exists():
        raise LagiceError(f"file {p} does not exist")
    with xr.open_dataset(p) as ds:
        print(ds)
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="lagice", description="Lagrangian Maxwell-EB sea-ice model")
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run a scene")
    r.add_argument("scene", nargs="?", help="scene name (default: uniaxial_compression)")
    r.add_argument("--out", help="output directory (default runs/SCENE)")
    r.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene option")
    r.set_defaults(func=_run)
    i = sub.add_parser("info", help="describe an output file")
    i.add_argument("file")
    i.set_defaults(func=_info)
    args = ap.parse_args(argv)
    try:
        return args.func(args)
    except LagiceError as exc:
        print(f"lagice: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
