"""Do the shear bands stay where they were the day before? (docs/physics.md §4, "Bands that
wander", thirty-ninth session.)

The published deformation statistics are taken over 3-day Lagrangian windows, as RGPS's are
(Marsan et al. 2004; Girard et al. 2011). A band that keeps slipping in the same elements for three
days adds up there, and the window's rates keep the one-day field's contrast; a band that moves
from day to day spreads the window's shear over all the elements it crossed, so their 3-day rates
are alike and the PDF tail gets lighter. This script measures how much of each day's shear falls
where the previous day's fell.

For every pair of consecutive days (k → k+1, k+1 → k+2) of a run's daily snapshots it follows the
elements of day k's mesh whose three nodes still exist at days k+1 and k+2 (by ``node_id``, with
:func:`lagice.io.snapshots.load_window`), keeps those whose centroid lies at least 100 km from
the boundary (the published windows' buffer), and computes each day's Lagrangian shear rate
(:func:`lagice.diagnostics.strain.lagrangian_velocity_gradients`, mid-day geometry). Then:

* ``overlap``: the area of the elements that hold half of day k+1's shear (Σ ε̇II·A, as the
  half-shear area) that also hold half of day k's, over the area of day k+1's set;
* ``chance``: the same overlap if day k+1's set had fallen anywhere, day k's set's share of the
  area;
* ``spearman``: the rank correlation of the two days' element rates.

It prints one row per run (medians over the day pairs from ``--start-day``) and, with ``--json``,
writes the per-pair values. ``--against-windows`` then sets the persistence beside the published
statistics of the same runs (``docs/figures/physics_experiments.json``): over the runs (medians),
and over their 3-day windows (each window's persistence the mean overlap of its two day pairs),
pooled and within runs (ranks taken inside each run). ``--from-json`` reads the per-pair values
written before instead of the snapshots.

    python benchmarks/band_persistence.py F10-hthick-m10 F10-hthick-P-vcrj1-m10
    python benchmarks/band_persistence.py --from-json docs/figures/band_persistence.json --against-windows
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from scipy.stats import rankdata, spearmanr

from lagice.diagnostics.faults import interior_triangles
from lagice.diagnostics.strain import lagrangian_velocity_gradients, shear_rate, triangle_geometry
from lagice.errors import ConfigError
from lagice.io.snapshots import load_window, read_index

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "benchmarks" / "out" / "physics"
RECORDS = ROOT / "docs" / "figures" / "physics_experiments.json"
#: the published statistics set beside the persistence
STATS = ("beta_space", "pdf_tail_exponent_shear", "pdf_tail_exponent_divergence",
         "localisation_half_shear_area_fraction", "shear_divergence_r2", "mean_total_s")
PAIR_KEYS = ("day", "n_elements", "overlap", "chance", "spearman")
DAY_S = 86400.0
#: the coast buffer of the published window statistics [m]
BUFFER_M = 100e3
#: the share of each day's shear whose elements form its band set (as the half-shear area)
SHARE = 0.5


def band_set(rate: np.ndarray, area: np.ndarray, share: float = SHARE) -> np.ndarray:
    """Mask of the fastest elements that hold ``share`` of Σ rate·area (the element that crosses
    the share included)."""
    order = np.argsort(-rate, kind="stable")
    cum = np.cumsum((rate * area)[order])
    n = int(np.searchsorted(cum, share * cum[-1])) + 1
    mask = np.zeros(rate.size, bool)
    mask[order[:n]] = True
    return mask


def day_pair(run_dir: Path, day: float) -> dict:
    """The persistence measures of days ``day`` → ``day`` + 1 → ``day`` + 2."""
    one, two = (load_window(run_dir, day * DAY_S, (day + k) * DAY_S) for k in (1, 2))
    for w, k in ((one, 1), (two, 2)):
        if abs(w["end_s"] - (day + k) * DAY_S) > 3600.0 or abs(w["start_s"] - day * DAY_S) > 3600.0:
            raise ConfigError(f"{run_dir}: no snapshots within an hour of days {day:g} and {day + k:g}")
    (xy0, tri), xy1, xy2 = one["start_mesh"], one["start_nodes_at_end"], two["start_nodes_at_end"]
    inside = interior_triangles(xy0, tri, BUFFER_M)
    followed = np.all(np.isfinite(xy1[tri]).all(axis=2) & np.isfinite(xy2[tri]).all(axis=2), axis=1)
    sub = tri[inside & followed]
    # an element that folds in a day's mid geometry has no Lagrangian rate (windows.window_arrays)
    ok = (triangle_geometry(0.5 * (xy0 + np.nan_to_num(xy1)), sub)[0] > 0) & \
         (triangle_geometry(0.5 * (np.nan_to_num(xy1) + np.nan_to_num(xy2)), sub)[0] > 0)
    sub = sub[ok]
    if sub.shape[0] < 100:
        raise ConfigError(f"{run_dir}: days {day:g}-{day + 2:g}: only {sub.shape[0]} interior elements can be "
                          "followed through both days")
    used = np.unique(sub)
    renum = np.full(xy0.shape[0], -1, np.int64)
    renum[used] = np.arange(used.size)
    t = renum[sub]
    g1 = lagrangian_velocity_gradients(xy0[used], xy1[used], t, DAY_S)
    g2 = lagrangian_velocity_gradients(xy1[used], xy2[used], t, DAY_S)
    s1, s2 = shear_rate(g1.gradient_s), shear_rate(g2.gradient_s)
    a = triangle_geometry(xy1[used], t)[0]
    b1, b2 = band_set(s1, a), band_set(s2, a)
    return {"day": float(day), "n_elements": int(t.shape[0]),
            "overlap": float(a[b1 & b2].sum() / a[b2].sum()), "chance": float(a[b1].sum() / a.sum()),
            "spearman": float(spearmanr(s1, s2).statistic),
            "mean_shear_per_day": [float(np.sum(s1 * a) / a.sum() * DAY_S), float(np.sum(s2 * a) / a.sum() * DAY_S)]}


def _print_run(name: str, rows: dict) -> None:
    med = {k: float(np.median(rows[k])) for k in ("overlap", "chance", "spearman")}
    ratio = float(np.median(np.asarray(rows["overlap"]) / np.asarray(rows["chance"])))
    print(f"| {name} | {len(rows['day'])} | {med['overlap']:.2f} | {med['chance']:.2f} | {ratio:.2f} | "
          f"{med['spearman']:.2f} |", flush=True)


def against_windows(runs: dict, records_path: Path = RECORDS) -> dict:
    """Spearman's rank correlation of the persistence (overlap) with each published statistic:
    ``runs`` over the runs' medians, ``windows_pooled`` over all their 3-day windows, and
    ``windows_within_runs`` (Pearson's correlation of the ranks taken inside each run, centred)."""
    rec = json.loads(records_path.read_text())
    med_x, med_y, win_x, win_y, rx, ry = [], {s: [] for s in STATS}, [], {s: [] for s in STATS}, [], \
        {s: [] for s in STATS}
    for name, rows in runs.items():
        if name not in rec:
            raise SystemExit(f"{name}: no published record in {records_path.name}")
        med_x.append(float(np.median(rows["overlap"])))
        for s_ in STATS:  # the records' medians carry the rate per day, their windows per second
            med_y[s_].append(rec[name]["median"]["mean_total_deformation_rate_per_day" if s_ == "mean_total_s" else s_])
        by_day = dict(zip((round(d) for d in rows["day"]), rows["overlap"]))
        xs, ys = [], {s_: [] for s_ in STATS}
        for w in rec[name]["per_window"]:
            d = round(w["start_day"])
            if d in by_day and d + 1 in by_day and all(np.isfinite(w[s_]) for s_ in STATS):
                xs.append(0.5 * (by_day[d] + by_day[d + 1]))
                for s_ in STATS:
                    ys[s_].append(w[s_])
        if len(xs) < 4:
            continue
        win_x += xs
        rx += list(rankdata(xs) / len(xs) - 0.5)
        for s_ in STATS:
            win_y[s_] += ys[s_]
            ry[s_] += list(rankdata(ys[s_]) / len(xs) - 0.5)
    out = {"n_runs": len(med_x), "n_windows": len(win_x), "runs": {}, "windows_pooled": {}, "windows_within_runs": {}}
    for s_ in STATS:
        out["runs"][s_] = float(spearmanr(med_x, med_y[s_]).statistic)
        out["windows_pooled"][s_] = float(spearmanr(win_x, win_y[s_]).statistic)
        out["windows_within_runs"][s_] = float(np.corrcoef(rx, ry[s_])[0, 1])
    print(f"\nthe overlap against the published statistics ({out['n_runs']} runs, {out['n_windows']} 3-day windows)")
    print("| statistic | over the runs' medians | over the windows, pooled | over the windows, within runs |")
    print("|---|---|---|---|")
    for s_ in STATS:
        print(f"| {s_} | {out['runs'][s_]:+.2f} | {out['windows_pooled'][s_]:+.2f} | "
              f"{out['windows_within_runs'][s_]:+.2f} |")
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="*", help="run names in benchmarks/out/physics (daily snapshots)")
    ap.add_argument("--from-json", type=Path, help="read the per-pair values from this file (written by --json)")
    ap.add_argument("--against-windows", action="store_true",
                    help="also the correlations with the published statistics of the same runs")
    ap.add_argument("--start-day", type=float, default=1.0, help="first day k of the pairs (default 1)")
    ap.add_argument("--json", type=Path, help="write the per-pair values here")
    args = ap.parse_args(argv)
    if bool(args.runs) == bool(args.from_json):
        ap.error("give either run names or --from-json")
    print("| run | day pairs | overlap of the half-shear sets | chance | overlap / chance | Spearman |")
    print("|---|---|---|---|---|---|")
    if args.from_json:
        doc = json.loads(args.from_json.read_text())
        out = doc["runs"]
        for name, rows in out.items():
            _print_run(name, rows)
    else:
        out = {}
        for name in args.runs:
            run_dir = RUNS / name
            if not (run_dir / "snapshots").is_dir():
                raise SystemExit(f"{run_dir}: no snapshots (make the run with physics_experiments.py run {name})")
            last = read_index(run_dir)[-1]["time_s"] / DAY_S
            pairs = [day_pair(run_dir, d) for d in np.arange(args.start_day, last - 2 + 1e-9, 1.0)]
            out[name] = {k: [round(p[k], 4) if isinstance(p[k], float) else p[k] for p in pairs] for k in PAIR_KEYS}
            _print_run(name, out[name])
        doc = {"command": "python benchmarks/band_persistence.py " + " ".join(argv if argv is not None
                                                                           else sys.argv[1:]),
               "share": SHARE, "buffer_m": BUFFER_M, "runs": out}
    if args.against_windows:
        doc["against_windows"] = against_windows(out)
    if args.json:
        args.json.write_text(json.dumps(doc) + "\n")
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
