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
    python benchmarks/beta_vs_damage.py F10-hthick-1125 --contrast 8 9 10     # active elements against the rest

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
#: share of the interior's area that ``activity_contrast`` calls active (the highest rates)
ACTIVE_SHARE = 0.05


def nearest_snapshot(run_dir, day: float):
    """(path, day) of the run's snapshot nearest ``day`` [days]; ConfigError when none lies
    within an hour of it."""
    idx = read_index(run_dir)
    times = np.array([e["time_s"] for e in idx])
    i = int(np.argmin(np.abs(times - day * DAY_S)))
    if abs(times[i] - day * DAY_S) > 3600.0:
        raise ConfigError(f"{run_dir}: no snapshot within an hour of day {day:g} (nearest: day "
                          f"{times[i] / DAY_S:g})")
    return snapshot_dir(run_dir) / idx[i]["file"], float(times[i] / DAY_S)


def start_damage(run_dir, day: float, buffer_m: float = BUFFER_M) -> dict:
    """The interior's damage in the snapshot nearest ``day`` [days]: ``mean_damage``
    (area-weighted over the elements whose centroid is >= ``buffer_m`` [m] from the mesh
    boundary), ``broken_area_share`` (their area with damage > :data:`BROKEN`),
    ``damaged_area_share`` (with damage > :data:`DAMAGED`), and the sums
    ``damage_area_m2`` (Σ d·A) and ``area_m2`` (Σ A) over those elements, and
    ``median_pressure_pa``: the median over them of the pressure −(σxx + σyy)/2 [Pa]
    (compression positive).
    Raises ConfigError when no snapshot lies within an hour of ``day``."""
    path, snap_day = nearest_snapshot(run_dir, day)
    with xr.open_dataset(path, decode_times=False) as ds:
        xy = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
        tri = ds["mesh_face_nodes"].values.astype(np.int64)
        damage = np.asarray(ds["damage"].values, np.float64).reshape(-1)
        pressure = -0.5 * (np.asarray(ds["stress_xx"].values, np.float64).reshape(-1)
                           + np.asarray(ds["stress_yy"].values, np.float64).reshape(-1))
    if damage.shape[0] != tri.shape[0]:
        raise ConfigError(f"{run_dir}: snapshot {path.name}: {damage.shape[0]} damage values for "
                          f"{tri.shape[0]} elements")
    inner = interior_triangles(xy, tri, buffer_m)
    area = np.abs(triangle_geometry(xy, tri)[0])[inner]
    d = damage[inner]
    return {"snapshot_day": snap_day, "mean_damage": float(np.sum(area * d) / area.sum()),
            "broken_area_share": float(area[d > BROKEN].sum() / area.sum()),
            "damaged_area_share": float(area[d > DAMAGED].sum() / area.sum()),
            "damage_area_m2": float(np.sum(area * d)), "area_m2": float(area.sum()),
            "median_pressure_pa": float(np.median(pressure[inner]))}


def load_ratio(stress: np.ndarray, cohesion: np.ndarray, friction: float) -> np.ndarray:
    """The stress against the nominal envelope of Dansereau et al. (2016): max(σ1/σT,
    (q σ1 − σ2)/σc) per element, σ1 ≥ σ2 the principal stresses (tension positive) of
    ``stress`` (m, 3) = (σxx, σyy, σxy) [Pa], (q, σc, σT) of the cohesion [Pa] and friction
    (:func:`lagice.rheology.maxwell_eb.envelope`). 1 on the envelope, k for k times such a
    stress (so 1/d_crit of the origin path outside), ≤ 0 under an isotropic compression."""
    from lagice.rheology.maxwell_eb import envelope

    q, sigma_c, sigma_t = envelope(np.asarray(cohesion, np.float64), friction)
    m = 0.5 * (stress[:, 0] + stress[:, 1])
    r = np.sqrt(0.25 * (stress[:, 0] - stress[:, 1]) ** 2 + stress[:, 2] ** 2)
    s1, s2 = m + r, m - r
    return np.maximum(s1 / sigma_t, (q * s1 - s2) / sigma_c)


def split_by_rate(rate: np.ndarray, area: np.ndarray, top: float):
    """Boolean mask of the elements that carry the highest ``rate`` over a share ``top`` of the
    total ``area`` (the most active elements first; the element that crosses the share is in)."""
    order = np.argsort(-np.asarray(rate), kind="stable")
    cum = np.cumsum(np.asarray(area)[order])
    n = int(np.searchsorted(cum, top * cum[-1])) + 1
    mask = np.zeros(len(rate), dtype=bool)
    mask[order[:n]] = True
    return mask


def activity_contrast(run_dir, day: float, top: float = ACTIVE_SHARE, buffer_m: float = BUFFER_M) -> dict:
    """Damage and load of the interior's most active elements against the rest, in the snapshot
    nearest ``day``: the elements >= ``buffer_m`` from the boundary that carry the highest total
    deformation rate (of the snapshot's node velocity, the last sub-step's) over ``top`` of the
    interior's area, and the others. Medians of their damage and of their :func:`load_ratio`
    (the friction from the run's configuration), and the share of each group's area above a load
    ratio of 0.9. Raises ConfigError when no snapshot lies within an hour of ``day``."""
    from lagice.diagnostics.strain import velocity_gradients

    path, snap_day = nearest_snapshot(run_dir, day)
    with xr.open_dataset(path, decode_times=False) as ds:
        xy = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
        tri = ds["mesh_face_nodes"].values.astype(np.int64)
        vel = np.column_stack([ds["velocity_x"].values.reshape(-1), ds["velocity_y"].values.reshape(-1)])
        damage = np.asarray(ds["damage"].values, np.float64).reshape(-1)
        stress = np.column_stack([np.asarray(ds[f"stress_{k}"].values, np.float64).reshape(-1)
                                  for k in ("xx", "yy", "xy")])
        cohesion = np.asarray(ds["cohesion"].values, np.float64).reshape(-1)
        friction = float(json.loads(ds.attrs["lagice_config"])["rheology"]["friction"])
    inner = interior_triangles(xy, tri, buffer_m)
    area = np.abs(triangle_geometry(xy, tri)[0])[inner]
    rate = velocity_gradients(xy, tri, vel).total_s[inner]
    load = load_ratio(stress, cohesion, friction)[inner]
    d = damage[inner]
    act = split_by_rate(rate, area, top)
    out = {"snapshot_day": snap_day, "active_share": top,
           "median_rate_per_day": float(np.median(rate) * DAY_S)}
    for name, sel in (("active", act), ("rest", ~act)):
        out[name] = {"median_damage": float(np.median(d[sel])), "median_load_ratio": float(np.median(load[sel])),
                     "area_share_load_above_0.9": float(area[sel][load[sel] > 0.9].sum() / area[sel].sum())}
    return out


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
    ap.add_argument("--contrast", type=float, nargs="+", metavar="DAY",
                    help="print the damage and load of the most active 5 %% of the interior against the rest "
                         "at these days instead (nothing written)")
    args = ap.parse_args(argv)
    if args.contrast:
        for name in args.runs:
            for day in args.contrast:
                r = activity_contrast(RUNS / name, day)
                a, o = r["active"], r["rest"]
                print(f"{name:28s} day {day:5.1f} (median rate {r['median_rate_per_day']:.4f}/day): active 5 %: "
                      f"damage {a['median_damage']:.3f}, load {a['median_load_ratio']:.2f}, "
                      f"above 0.9 {a['area_share_load_above_0.9']:.2f} | rest: damage {o['median_damage']:.3f}, "
                      f"load {o['median_load_ratio']:.2f}, above 0.9 {o['area_share_load_above_0.9']:.2f}")
        return 0
    if args.at:
        for name in args.runs:
            for day in args.at:
                r = start_damage(RUNS / name, day)
                print(f"{name:34s} day {day:5.1f}: mean damage {r['mean_damage']:.3f}, area above "
                      f"{DAMAGED:g}: {r['damaged_area_share']:.2f}, above {BROKEN:g}: {r['broken_area_share']:.2f}, "
                      f"median pressure {r['median_pressure_pa'] / 1e3:.1f} kPa")
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
