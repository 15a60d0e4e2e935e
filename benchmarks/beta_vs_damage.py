"""β of each 3-day window against how broken the pack was when the window began
(docs/physics.md §4, "Is the weather too wide for the basin?", the intact start).

For every window of the published records (``docs/figures/physics_experiments.json``,
``per_window``: β, the rate), the snapshot at the window's start gives the interior's damage:
its area-weighted mean and the share of its area above 0.9, over the elements whose centroid
is at least 100 km from the boundary (the buffer of the window statistics). The script prints
one row per window and Spearman's rank correlation of β with each (and with the window's rate,
the other thing β moves with), and writes ``docs/figures/beta_vs_damage.json``.

    python benchmarks/beta_vs_damage.py F10-hthick-1125 F10s-hthick-1125 F10-hthick-1125-intact F10s-hthick-1125-intact
    python benchmarks/beta_vs_damage.py F10-hthick-1125-intact --at 7 10      # the damage at given days

Runs are read from ``benchmarks/out/physics`` (made by ``physics_experiments.py run``); a run
whose snapshots are missing stops the script with its name, so no window is left out silently.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import xarray as xr
from scipy.stats import spearmanr

from lagice.diagnostics.faults import interior_triangles
from lagice.diagnostics.strain import triangle_geometry
from lagice.errors import ConfigError
from lagice.io.snapshots import read_index, snapshot_dir

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "benchmarks" / "out" / "physics"
RECORDS = ROOT / "docs" / "figures" / "physics_experiments.json"
OUT = ROOT / "docs" / "figures" / "beta_vs_damage.json"
DAY_S = 86400.0
#: the coast buffer of the published window statistics [m]
BUFFER_M = 100e3
#: damage above which an element counts as broken in ``broken_area_share``
BROKEN = 0.9
#: damage above which an element counts in ``damaged_area_share`` (the over-failure's measure)
DAMAGED = 0.5


def start_damage(run_dir, day: float, buffer_m: float = BUFFER_M) -> dict:
    """The interior's damage in the snapshot nearest ``day`` [days]: ``mean_damage``
    (area-weighted over the elements whose centroid is >= ``buffer_m`` [m] from the mesh
    boundary), ``broken_area_share`` (their area with damage > :data:`BROKEN`),
    ``damaged_area_share`` (with damage > :data:`DAMAGED`), and the sums
    ``damage_area_m2`` (Σ d·A) and ``area_m2`` (Σ A) over those elements.
    Raises ConfigError when no snapshot lies within an hour of ``day``."""
    idx = read_index(run_dir)
    times = np.array([e["time_s"] for e in idx])
    i = int(np.argmin(np.abs(times - day * DAY_S)))
    if abs(times[i] - day * DAY_S) > 3600.0:
        raise ConfigError(f"{run_dir}: no snapshot within an hour of day {day:g} (nearest: day "
                          f"{times[i] / DAY_S:g})")
    with xr.open_dataset(snapshot_dir(run_dir) / idx[i]["file"], decode_times=False) as ds:
        xy = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
        tri = ds["mesh_face_nodes"].values.astype(np.int64)
        damage = np.asarray(ds["damage"].values, np.float64).reshape(-1)
    if damage.shape[0] != tri.shape[0]:
        raise ConfigError(f"{run_dir}: snapshot {idx[i]['file']}: {damage.shape[0]} damage values for "
                          f"{tri.shape[0]} elements")
    inner = interior_triangles(xy, tri, buffer_m)
    area = np.abs(triangle_geometry(xy, tri)[0])[inner]
    d = damage[inner]
    return {"snapshot_day": float(times[i] / DAY_S), "mean_damage": float(np.sum(area * d) / area.sum()),
            "broken_area_share": float(area[d > BROKEN].sum() / area.sum()),
            "damaged_area_share": float(area[d > DAMAGED].sum() / area.sum()),
            "damage_area_m2": float(np.sum(area * d)), "area_m2": float(area.sum())}


def rows_for(name: str, records: dict, runs: Path = RUNS) -> list:
    """One row per published window of run ``name``: start day, β, rate [day-1] and the
    damage at the window's start (:func:`start_damage`)."""
    if name not in records:
        raise ConfigError(f"{name}: no published record in {RECORDS.name}")
    run = runs / name
    if not (run / "snapshots").exists():
        raise ConfigError(f"{name}: no snapshots in {run} (run it with physics_experiments.py run {name})")
    return [{"run": name, "start_day": w["start_day"], "beta_space": w["beta_space"],
             "rate_per_day": w["mean_total_s"] * DAY_S, **start_damage(run, w["start_day"])}
            for w in records[name]["per_window"]]


def correlations(rows: list) -> dict:
    """Spearman's ρ (and its p-value) of β against the mean damage, the broken share and the
    rate, over the windows whose β is defined."""
    ok = [r for r in rows if r["beta_space"] is not None and np.isfinite(r["beta_space"])]
    beta = [r["beta_space"] for r in ok]
    out = {"n_windows": len(ok)}
    for k in ("mean_damage", "broken_area_share", "rate_per_day"):
        rho, p = spearmanr(beta, [r[k] for r in ok])
        out[k] = {"spearman": float(rho), "p_value": float(p)}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", help="run names in benchmarks/out/physics with published records")
    ap.add_argument("--out", type=Path, default=OUT, help=f"the JSON written (default {OUT.relative_to(ROOT)})")
    ap.add_argument("--at", type=float, nargs="+", metavar="DAY",
                    help="print the interior's damage of each run at these days instead (nothing written)")
    args = ap.parse_args(argv)
    if args.at:
        for name in args.runs:
            for day in args.at:
                r = start_damage(RUNS / name, day)
                print(f"{name:34s} day {day:5.1f}: mean damage {r['mean_damage']:.3f}, area above "
                      f"{DAMAGED:g}: {r['damaged_area_share']:.2f}, above {BROKEN:g}: {r['broken_area_share']:.2f}")
        return 0
    records = json.loads(RECORDS.read_text())
    rows = [r for n in args.runs for r in rows_for(n, records)]
    print(f"{'run':30s} {'day':>4s} {'mean d':>7s} {'>0.9':>5s} {'beta':>7s} {'rate/day':>9s}")
    for r in rows:
        print(f"{r['run']:30s} {r['start_day']:4.0f} {r['mean_damage']:7.3f} {r['broken_area_share']:5.2f} "
              f"{r['beta_space']:7.3f} {r['rate_per_day']:9.4f}")
    cor = correlations(rows)
    for k in ("mean_damage", "broken_area_share", "rate_per_day"):
        print(f"Spearman beta vs {k} over {cor['n_windows']} windows: {cor[k]['spearman']:+.2f} "
              f"(p = {cor[k]['p_value']:.2g})")
    args.out.write_text(json.dumps({"runs": args.runs, "buffer_m": BUFFER_M, "broken_damage": BROKEN,
                                    "windows": rows, "correlation": cor}, indent=1) + "\n")
    print(f"beta_vs_damage: wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
