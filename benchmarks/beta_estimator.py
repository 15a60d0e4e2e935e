"""β with and without the widths that hold only a few boxes (docs/physics.md, "How β was estimated").

β is the slope of ⟨ε̇tot⟩(L) from the coarse-graining (:func:`lagice.diagnostics.spatial_scaling`).
In the 1000 km basin, less 100 km along the coast, the widest box width (about 300 km) holds one
box, and the next (about 150 km) a few. Until 2026-11-24 every width with a box entered the fit, so
one box (a mean over one sample of a heavy-tailed rate) carried the fit's lever arm. This script
re-analyses finished runs of ``benchmarks/physics_experiments.py`` window by window (the 3-day
windows from day 1 and the 100 km coast buffer of the validation) and prints, per run, the medians
over the windows of:

* β with every width (``min_boxes = 1``, the estimator used before);
* β with the widths holding at least 4 boxes, and at least 10 (the default now);
* β with at least 10 boxes over the widths of 10 km and more only, so that runs on meshes of
  20, 10 and 5 km are compared over the same physical widths;
* ⟨ε̇tot⟩ at each box width pooled over the windows (printed after the table);
* the widest width used with 10 boxes, and the ratio of the element-scale ⟨ε̇tot⟩ to the
  ⟨ε̇tot⟩ at that width (observed: about 2 between 10 and 300 km, from β ≈ 0.2).

``--pooled`` also prints, per run, β of one curve over every box of every window (default grid, and
every box of the nine grids), as observed β is computed (Marsan et al. 2004; Girard et al. 2011;
:func:`lagice.diagnostics.windows.pooled_window_scaling`), beside the window median, and the same
pooled over all the runs named (one mesh; e.g. the eight months of a basin) (rule PC).

``--origins N`` also fits each window's β as the validation does with the box grid laid from N
seeded random offsets of its corner (uniform in [0, 92 km) in x and y, the widest width fitted in the
basin) besides the validation's own corner, and prints per run the spread of the window medians over
those grids: how much β moves with where the boxes fall, an uncertainty of the estimator itself
(docs/physics.md §4, rule OR).

    python benchmarks/beta_estimator.py F10 F10x2 ...   # runs in benchmarks/out/physics
    python benchmarks/beta_estimator.py                  # the default list below
    python benchmarks/beta_estimator.py RUN ... --figure docs/figures/NAME.png  # and the pooled curves

Results go to ``docs/figures/beta_estimator.json``.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from lagice.diagnostics.scaling import MIN_FIT_BOXES, fit_power_law, spatial_scaling
from lagice.diagnostics.strain import lagrangian_velocity_gradients
from lagice.diagnostics.windows import window_arrays, window_starts_days, window_summary

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "benchmarks" / "out" / "physics"
DAY_S = 86400.0
#: the narrowest box width [m] of the fit over the same widths on every mesh (a 20 km mesh's finest is ~12 km)
COMMON_MIN_SCALE_M = 10e3
DEFAULT_RUNS = ("F10", "F10s", "F10-w2027", "F10-heal-K50-w2027", "B20", "B20x2", "F10x2", "F10x2-w2027",
                "E10", "E10s")


def run_estimates(run_dir: Path, window_days: float = 3.0, start_day: float = 1.0,
                  coast_buffer_m: float = 100e3) -> dict:
    """Per-window β for several minimum box counts, and their medians over the windows (``_interiors``:
    each window's interior statistics, for :func:`pooled_table`; not JSON)."""
    rows, interiors = [], []
    for s0 in window_starts_days(run_dir, window_days, start_day):
        s = window_summary(run_dir, s0 * DAY_S, window_days * DAY_S, coast_buffer_m)["interior"]
        interiors.append(s)
        sc = s["scaling_space"]
        scale = np.asarray(sc["scale_m"], float)
        mean = np.asarray(sc["mean_total_s"], float)
        nbox = np.asarray(sc["n_boxes"])
        row = {"start_day": float(s0), "element_rate_per_day": float(mean[0] * DAY_S)}
        for n_min in (1, 4, MIN_FIT_BOXES):
            k = nbox >= n_min
            row[f"beta_min_boxes_{n_min}"] = fit_power_law(scale[k], mean[k]).exponent
        k = nbox >= MIN_FIT_BOXES
        # the same physical widths on every mesh: the finest box of a 20 km mesh is about 12 km wide,
        # so the finer meshes' octaves below 10 km are left out (docs/physics.md §4, "A damage time of
        # fixed length")
        kk = k & (scale >= COMMON_MIN_SCALE_M)
        row["beta_widths_from_10km"] = (fit_power_law(scale[kk], mean[kk]).exponent if kk.sum() >= 2
                                        else float("nan"))
        row["widest_scale_km_min_boxes_10"] = float(scale[k].max() / 1e3)
        row["fit_widths_km"] = [float(x / 1e3) for x in scale[k]]
        row["rate_per_day_by_width"] = [float(x * DAY_S) for x in mean[k]]
        row["element_to_widest_rate_ratio"] = float(mean[0] / mean[k][-1])
        row["scales_km"] = [float(x / 1e3) for x in scale]
        row["n_boxes"] = [int(n) for n in nbox]
        rows.append(row)
    keys = [k for k in rows[0] if k not in ("start_day", "scales_km", "n_boxes", "fit_widths_km",
                                            "rate_per_day_by_width")]
    return {"windows": rows, "median": {k: float(np.median([r[k] for r in rows])) for k in keys},
            "curve": pooled_curve(rows), "_interiors": interiors}


#: the range [m] of the --origins offsets of the box grid's corner: the widest width fitted in the basin
ORIGIN_RANGE_M = 92e3


def origin_spread(run_dir: Path, n_origins: int, seed: int = 0, window_days: float = 3.0, start_day: float = 1.0,
                  coast_buffer_m: float = 100e3) -> dict:
    """Window-median β (the validation's estimator: widths with at least :data:`MIN_FIT_BOXES` boxes,
    the element scale included) with the box grid laid from the validation's corner (the mesh's
    mid-window bounds) and from ``n_origins`` seeded offsets of it, uniform in [0,
    :data:`ORIGIN_RANGE_M`) in x and y. Returns the offsets [m], the medians per grid (the validation's
    first) and their span."""
    rng = np.random.default_rng(seed)
    offsets = np.vstack([[0.0, 0.0], rng.uniform(0.0, ORIGIN_RANGE_M, size=(n_origins, 2))])
    per_window = []
    for s0 in window_starts_days(run_dir, window_days, start_day):
        xy0, xy1, tri, dt, info = window_arrays(run_dir, s0 * DAY_S, (s0 + window_days) * DAY_S, coast_buffer_m)
        rates = lagrangian_velocity_gradients(xy0, xy1, tri[info["interior"]], dt)
        corner = rates.bounds_m[:2]
        per_window.append([spatial_scaling(rates, origin_xy_m=corner - off).fit.exponent for off in offsets])
    medians = np.median(np.asarray(per_window), axis=0)
    return {"offsets_m": offsets.tolist(), "median_beta": medians.tolist(),
            "span": float(medians.max() - medians.min())}


def mean_gradient(rates) -> np.ndarray:
    """The area-weighted mean velocity gradient [s⁻¹] of a set of elements: by Green's theorem the
    gradient of the whole set as one cell (its boundary's velocities)."""
    a = rates.area_m2
    return (rates.gradient_s * a[:, None, None]).sum(axis=0) / a.sum()


def less_uniform(rates):
    """The element rates less the area-weighted mean gradient of the whole set (the part in which the
    set deforms as one body): a diagnostic of what the uniform part does to β (rule UM), not how RGPS
    is processed."""
    from lagice.diagnostics.strain import ElementStrainRates

    return ElementStrainRates(rates.gradient_s - mean_gradient(rates), rates.area_m2, rates.centroid_xy_m,
                              rates.bounds_m)


def uniform_mode(run_dir: Path, window_days: float = 3.0, start_day: float = 1.0,
                 coast_buffer_m: float = 100e3) -> dict:
    """Per validation window: β over nine box grids (:func:`lagice.diagnostics.grid_averaged_beta`) of
    the interior's element rates as they are and less their uniform part (:func:`less_uniform`), the
    element-mean rate [day⁻¹], the ratio of the interior's net rate (one box over the whole interior)
    to it, and the net divergence over the mean |divergence|; and the window medians of the two β."""
    from lagice.diagnostics.scaling import grid_averaged_beta
    from lagice.diagnostics.strain import total_deformation_rate

    rows = []
    for s0 in window_starts_days(run_dir, window_days, start_day):
        xy0, xy1, tri, dt, info = window_arrays(run_dir, s0 * DAY_S, (s0 + window_days) * DAY_S, coast_buffer_m)
        rates = lagrangian_velocity_gradients(xy0, xy1, tri[info["interior"]], dt)
        a = rates.area_m2
        mean_rate = float(np.average(rates.total_s, weights=a))
        net = mean_gradient(rates)
        div = rates.divergence_s
        rows.append({"start_day": float(s0), "beta_grid_mean": grid_averaged_beta(rates).mean,
                     "beta_grid_mean_less_uniform": grid_averaged_beta(less_uniform(rates)).mean,
                     "rate_per_day": mean_rate * DAY_S,
                     "net_to_mean_rate": float(total_deformation_rate(net[None])[0] / mean_rate),
                     "net_to_mean_abs_divergence": float(np.average(div, weights=a) / np.average(np.abs(div),
                                                                                                  weights=a))})
    return {"windows": rows, "median": {k: float(np.median([r[k] for r in rows]))
                                        for k in ("beta_grid_mean", "beta_grid_mean_less_uniform")}}


def pooled_table(interiors: dict, out: dict) -> None:
    """Rule PC: per run (``interiors``: run name → its windows' interior statistics, from
    :func:`run_estimates`) the window median of β (default grid) and β of one curve over every box of
    every window (default grid; every grid), then the same over every window of all the runs."""
    from lagice.diagnostics.windows import pooled_window_scaling
    from lagice.errors import ConfigError

    print("\nβ as the window median and as one curve over every box of every window (rule PC):")
    print("| run | window median, default grid | pooled, default grid | pooled, nine grids |")
    print("|---|---|---|---|")
    names, every = list(interiors), []
    for name in names:
        windows = [{"interior": i} for i in interiors[name]]
        every += windows
        pc = pooled_window_scaling(windows)
        median = float(np.median([i["beta_space"] for i in interiors[name]]))
        out[name]["pooled"] = {"window_median": median, "beta_space": pc["beta_space"],
                               "beta_space_grids": pc["beta_space_grids"]}
        print(f"| {name} | {median:.4f} | {pc['beta_space']:.4f} | {pc['beta_space_grids']:.4f} |", flush=True)
    if len(names) > 1:
        try:
            pc = pooled_window_scaling(every)
        except ConfigError as e:   # runs on different meshes: their box widths differ, nothing to pool
            print(f"(the runs are not pooled together: {e})")
            return
        out["_pooled_over_runs"] = {"runs": list(names), "beta_space": pc["beta_space"],
                                    "beta_space_grids": pc["beta_space_grids"], "n_windows": pc["n_windows"]}
        print(f"| all {len(names)} runs, {pc['n_windows']} windows | | {pc['beta_space']:.3f} | "
              f"{pc['beta_space_grids']:.3f} |")


def pooled_curve(rows: list) -> dict:
    """⟨ε̇tot⟩(L) pooled over the windows: per box width (counted from the widest with at least
    10 boxes, so that every window has it), the mean width [km] and the geometric mean over the
    windows of ⟨ε̇tot⟩ [day⁻¹]. The ratio of two widths' values is the window-mean of the ratio on
    a log scale, so the slope between them is the windows' mean local β."""
    widths, rates = pool_curves([r["fit_widths_km"] for r in rows], [r["rate_per_day_by_width"] for r in rows])
    return {"width_km": [float(x) for x in widths], "rate_per_day": [float(x) for x in rates]}


def pool_curves(widths: list, rates: list) -> tuple[np.ndarray, np.ndarray]:
    """Curves ⟨ε̇tot⟩(L) of several windows (each a list of widths, narrowest first, and its rates)
    pooled: the widths counted from the widest that every window has, their mean, and the geometric
    mean of the rates per width."""
    n = min(len(r) for r in rates)
    w = np.array([x[-n:] for x in widths], dtype=np.float64)
    r = np.array([x[-n:] for x in rates], dtype=np.float64)
    return w.mean(axis=0), np.exp(np.log(r).mean(axis=0))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="*", default=list(DEFAULT_RUNS), help="run names in benchmarks/out/physics")
    ap.add_argument("--json", type=Path, default=ROOT / "docs" / "figures" / "beta_estimator.json")
    ap.add_argument("--figure", type=Path, default=None,
                    help="also draw the pooled ⟨ε̇tot⟩(L), each run divided by its value at the widest width, "
                         "to this PNG")
    ap.add_argument("--absolute", action="store_true",
                    help="with --figure: draw ⟨ε̇tot⟩(L) itself [day⁻¹], not divided by its widest value, to "
                         "compare the rates of runs at each width")
    ap.add_argument("--origins", type=int, default=0, metavar="N",
                    help="also the window-median β with the box grid laid from N seeded random offsets of its "
                         "corner, and its spread (rule OR)")
    ap.add_argument("--pooled", action="store_true",
                    help="also β of one curve over every box of every window, per run and over all runs (rule PC)")
    ap.add_argument("--uniform-mode", action="store_true",
                    help="also β over nine grids of each window less the interior's uniform part (rule UM)")
    args = ap.parse_args(argv)
    if args.origins < 0:
        raise SystemExit(f"beta_estimator: --origins {args.origins}: expected a number of offsets >= 0")
    missing = [r for r in args.runs if not (RUNS / r / "snapshots").is_dir()]
    if missing:
        raise SystemExit(f"beta_estimator: no finished run for {', '.join(missing)} in {RUNS} "
                         "(make them with benchmarks/physics_experiments.py run NAME)")
    out = json.loads(args.json.read_text()) if args.json.exists() else {}
    print("| run | β, every width | β, ≥ 4 boxes | β, ≥ 10 boxes | β, ≥ 10 boxes, widths ≥ 10 km "
          "| widest width with ≥ 10 boxes (km) | ⟨ε̇tot⟩ element / widest |")
    print("|---|---|---|---|---|---|---|")
    interiors = {}
    for name in args.runs:
        r = run_estimates(RUNS / name)
        interiors[name] = r.pop("_interiors")
        out[name] = r
        m = r["median"]
        print(f"| {name} | {m['beta_min_boxes_1']:.3f} | {m['beta_min_boxes_4']:.3f} | "
              f"{m[f'beta_min_boxes_{MIN_FIT_BOXES}']:.3f} | {m['beta_widths_from_10km']:.3f} | "
              f"{m['widest_scale_km_min_boxes_10']:.0f} | "
              f"{m['element_to_widest_rate_ratio']:.2f} |", flush=True)
        args.json.write_text(json.dumps(out, indent=1, allow_nan=True) + "\n")
    print("\n⟨ε̇tot⟩ [day⁻¹] by box width, pooled over the windows (geometric mean; widths with ≥ 10 boxes):")
    for name in args.runs:
        c = out[name]["curve"]
        print(f"  {name}: " + ", ".join(f"{w:.0f} km {r:.4f}" for w, r in zip(c["width_km"], c["rate_per_day"])))
    if args.origins:
        print(f"\nβ (window median, ≥ {MIN_FIT_BOXES} boxes) with the box grid laid from the validation's corner "
              f"and from {args.origins} offsets of it:")
        print("| run | validation's corner | offsets: min – max | span |")
        print("|---|---|---|---|")
        for name in args.runs:
            o = origin_spread(RUNS / name, args.origins)
            out[name]["origin_spread"] = o
            b = o["median_beta"]
            print(f"| {name} | {b[0]:.3f} | {min(b[1:]):.3f} – {max(b[1:]):.3f} | {o['span']:.3f} |", flush=True)
        args.json.write_text(json.dumps(out, indent=1, allow_nan=True) + "\n")
    if args.pooled:
        pooled_table(interiors, out)
        args.json.write_text(json.dumps(out, indent=1, allow_nan=True) + "\n")
    if args.uniform_mode:
        print("\nβ over nine box grids (window median), as it is and less the interior's uniform part (rule UM):")
        print("| run | β | β less the uniform part | windows: β / less uniform / net-to-mean rate |")
        print("|---|---|---|---|")
        for name in args.runs:
            u = uniform_mode(RUNS / name)
            out[name]["uniform_mode"] = u
            w = "; ".join(f"{r['beta_grid_mean']:.3f}/{r['beta_grid_mean_less_uniform']:.3f}/"
                          f"{r['net_to_mean_rate']:.2f}" for r in u["windows"])
            print(f"| {name} | {u['median']['beta_grid_mean']:.3f} | "
                  f"{u['median']['beta_grid_mean_less_uniform']:.3f} | {w} |", flush=True)
        args.json.write_text(json.dumps(out, indent=1, allow_nan=True) + "\n")
    print(f"beta_estimator: wrote {args.json}", file=sys.stderr)
    if args.figure is not None:
        figure_curves({name: out[name]["curve"] for name in args.runs}, args.figure, absolute=args.absolute)
        print(f"beta_estimator: wrote {args.figure}", file=sys.stderr)


def figure_curves(curves: dict, path: Path, absolute: bool = False) -> None:
    """⟨ε̇tot⟩(L) / ⟨ε̇tot⟩(widest) against L on log-log axes, one line per run, with the slopes of
    β = 0.10 and 0.20 drawn from the widest width for reference. ``absolute``: ⟨ε̇tot⟩(L) itself
    [day⁻¹], the β slopes drawn through the first run's widest value."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for name, c in curves.items():
        w = np.asarray(c["width_km"])
        r = np.asarray(c["rate_per_day"])
        ax.plot(w, r if absolute else r / r[-1], "o-", label=name)
    w_all = np.concatenate([np.asarray(c["width_km"]) for c in curves.values()])
    lw = np.geomspace(w_all.min(), w_all.max(), 20)
    ref = float(np.asarray(next(iter(curves.values()))["rate_per_day"])[-1]) if absolute else 1.0
    for beta, ls in ((0.1, ":"), (0.2, "--")):
        ax.plot(lw, ref * (lw / lw[-1]) ** -beta, "k" + ls, lw=0.8, label=f"β = {beta:g}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("box width L (km)")
    ax.set_ylabel("⟨ε̇tot⟩(L) (day⁻¹), pooled over the windows" if absolute
                  else "⟨ε̇tot⟩(L) / ⟨ε̇tot⟩(widest), pooled over the windows")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
