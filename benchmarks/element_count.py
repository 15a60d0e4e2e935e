"""The element count under remeshing, with and without ``[remesh.params] density_control``
(docs/remeshing.md, "Element count drift").

1. ``channel``: the ocean-driven channel (``shear_channel_implicit``, ImplicitSolver, 1-h steps) for
   ``--days`` at ``--size`` through the scene builder and ``Simulation``, once without and once with
   the control. Printed: elements at the start and end, the density ratio (elements over the count
   the target size gives the mesh's area, Σ A / (k h²), k measured for the gmsh algorithm:
   :func:`lagice.remesh.patch.target_element_count`), remesh events, the sums over the events of
   the elements replaced, made at the target size and kept, and the remeshing wall time.
2. ``runs NAME ...``: the same counts for finished runs of ``benchmarks/physics_experiments.py``
   (first and last snapshot; the remesh target is the scene's resolution).

    python benchmarks/element_count.py channel --size 8e3 --days 10
    python benchmarks/element_count.py runs F10-hthick-ship-w2032 F10-hthick-dens-w2032
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import xarray as xr

from lagice.remesh.patch import target_element_count

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "benchmarks" / "out" / "physics"


def density_ratio(mesh, size_field, algorithm: int) -> float:
    """Elements over the count the target size gives the mesh's area."""
    return mesh.n_elements / target_element_count(mesh, np.arange(mesh.n_elements), size_field, algorithm)


def channel(size_m: float, days: float, density_control: bool) -> dict:
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from bench_remesh import channel_overrides
    from scene_runs import scene_simulation, timed_run

    sim = scene_simulation("shear_channel_implicit", {**channel_overrides(size_m), "run.duration": f"{days:g}d",
                                                      "remesh.params.density_control": density_control})
    model = sim.model
    rem = model.component("remeshing")
    alg = int(rem.options.get("algorithm", 6))
    n0, r0 = model.mesh.n_elements, density_ratio(model.mesh, rem.size_field, alg)
    v0 = model.state.ice_volume_m3
    wall = timed_run(sim)
    ev = [e for e in rem.log.events if e.kind != "failed"]
    return {"size_m": size_m, "days": days, "density_control": density_control, "elements_start": n0,
            "elements_end": model.mesh.n_elements, "density_ratio_start": r0,
            "density_ratio_end": density_ratio(model.mesh, rem.size_field, alg), "events": len(ev),
            "replaced": int(sum(e.n_patch_old for e in ev)),
            "made_at_target_size": int(sum(e.n_patch_at_target_size for e in ev)),
            "kept": int(sum(e.n_patch_new for e in ev)),
            "size_scale_median": float(np.median([e.size_scale for e in ev])) if ev else 1.0,
            "size_scale_max": float(max((e.size_scale for e in ev), default=1.0)),
            "remesh_s": model.timings["remeshing"], "wall_s": wall,
            "volume_relative_change": model.state.ice_volume_m3 / v0 - 1.0}


def run_counts(name: str) -> dict:
    d = RUNS / name
    snaps = sorted((d / "snapshots").glob("snapshot_*.nc"))
    if not snaps:
        raise SystemExit(f"{d}: no snapshots (make the run with physics_experiments.py run {name})")
    out = {"name": name}
    for key, path in (("first", snaps[0]), ("last", snaps[-1])):
        with xr.open_dataset(path) as ds:
            cfg = json.loads(ds.attrs["lagice_config"])
            nodes = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
            tri = ds["mesh_face_nodes"].values.astype(np.int64)
        mesh = SimpleNamespace(nodes=nodes, triangles=tri, n_elements=len(tri))
        size = float(cfg["domain"]["resolution_m"])
        alg = int(cfg.get("remesh", {}).get("params", {}).get("algorithm", 6))
        out[f"elements_{key}"] = mesh.n_elements
        out[f"density_ratio_{key}"] = density_ratio(mesh, size, alg)
    out["growth"] = out["elements_last"] / out["elements_first"] - 1.0
    # where the growth is: the elements never remeshed between the first and the last snapshot
    # (followed by node id) and the rest, the part remeshed at least once
    from lagice.diagnostics.windows import window_arrays
    from lagice.mesh import signed_areas

    xy0, xy1, tri, _, info = window_arrays(d, 0.0, 1e12)  # the first and the last snapshot
    start_xy, start_tri = info["start_mesh"][:2]
    area_all = np.abs(signed_areas(start_xy, start_tri)).sum()
    ok = np.all(np.isfinite(xy1[tri]).reshape(len(tri), -1), axis=1)
    a0, a1 = np.abs(signed_areas(xy0, tri[ok])).sum(), np.abs(signed_areas(xy1, tri[ok])).sum()
    out.update(never_remeshed=int(ok.sum()), never_remeshed_area_change=float(a1 / a0 - 1.0),
               remeshed_elements_first=int(len(start_tri) - ok.sum()),
               remeshed_elements_last=int(out["elements_last"] - ok.sum()),
               remeshed_area_change=float((area_all - a1) / (area_all - a0) - 1.0))
    summary = json.loads((d / "summary.json").read_text())
    out["remesh_count"] = summary.get("remesh_count")
    out["density_control"] = bool(cfg.get("remesh", {}).get("params", {}).get("density_control", False))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("channel")
    c.add_argument("--size", type=float, default=8e3, help="element size [m] (default 8 km)")
    c.add_argument("--days", type=float, default=10.0)
    r = sub.add_parser("runs")
    r.add_argument("names", nargs="+")
    args = ap.parse_args(argv)
    if args.cmd == "channel":
        print(f"shear_channel_implicit, {args.size / 1e3:g} km, {args.days:g} days")
        for on in (False, True):
            x = channel(args.size, args.days, on)
            print(f"  density_control {str(on):5s}: elements {x['elements_start']} -> {x['elements_end']} "
                  f"({100 * (x['elements_end'] / x['elements_start'] - 1):+.1f} %), density ratio "
                  f"{x['density_ratio_start']:.3f} -> {x['density_ratio_end']:.3f}; {x['events']} events: "
                  f"{x['replaced']} elements replaced by {x['kept']} (gmsh at the target size: "
                  f"{x['made_at_target_size']}); size factor median {x['size_scale_median']:.2f}, max "
                  f"{x['size_scale_max']:.2f}; remeshing {x['remesh_s']:.1f} s of {x['wall_s']:.1f} s; "
                  f"volume change {x['volume_relative_change']:+.1e}", flush=True)
    else:
        for name in args.names:
            x = run_counts(name)
            print(f"{name:28s} density_control {str(x['density_control']):5s}: elements {x['elements_first']} -> "
                  f"{x['elements_last']} ({100 * x['growth']:+.1f} %), density ratio {x['density_ratio_first']:.3f} "
                  f"-> {x['density_ratio_last']:.3f}, {x['remesh_count']} remeshes")
            print(f"    never remeshed: {x['never_remeshed']} elements, their area "
                  f"{100 * x['never_remeshed_area_change']:+.1f} %; remeshed at least once: elements "
                  f"{x['remeshed_elements_first']} -> {x['remeshed_elements_last']} "
                  f"({100 * (x['remeshed_elements_last'] / x['remeshed_elements_first'] - 1):+.1f} %), area "
                  f"{100 * x['remeshed_area_change']:+.1f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
