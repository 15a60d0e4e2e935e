"""Statistics of the synthetic winter wind climatology against the targets (issue 12).

Generates ``--seeds`` records of ``--days`` days over the ``winter_basin`` extent
(1000 km box, 25 km records, as the scene builder does) with the default
:class:`forcing.climatology.ClimatologyParams`, prints every statistic of
:func:`forcing.climatology.wind_statistics` with its target band
(``forcing.climatology.TARGETS``; sources in ``docs/physics.md``), and does the
same for the 28-day ``cyclones`` forcing that ``winter_basin`` shipped before
(6 random cyclones + a uniform 2.2 m/s background) for comparison.

    python benchmarks/wind_climatology.py                 # 4 seeds x 120 days, ~10 s
    python benchmarks/wind_climatology.py --seeds 8 --days 240

Writes ``docs/figures/wind_climatology.png`` (speed PDF, temporal and spatial
correlation, basin-mean speed over 28 days, one wind map) and
``docs/figures/wind_climatology.json``.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from forcing.climatology import TARGETS, ClimatologyWind, generate_for_box, make_params, wind_statistics
from forcing.records import DAY_S, RegularGrid
from forcing.synthetic import cyclone_wind, random_cyclones

ROOT = Path(__file__).resolve().parents[1]


def old_cyclone_forcing(days=28.0, seed=2026, spacing_m=25e3, width_m=1000e3):
    """The forcing ``winter_basin`` used before issue 12: 6 cyclones drawn for the run
    length + background (2, −1) m/s, as a ClimatologyWind for the same statistics."""
    bbox = (-0.5 * width_m, 0.5 * width_m, -0.5 * width_m, 0.5 * width_m)
    grid = RegularGrid.from_bbox(*bbox, spacing_m, margin_m=max(4 * spacing_m, 0.2 * width_m))
    cyc = random_cyclones(bbox, days * DAY_S, 6, seed=seed)
    fld = cyclone_wind(grid, days * DAY_S, cyc, background_m_s=(2.0, -1.0))
    src = fld.source
    data = np.asarray(src.data)
    return ClimatologyWind(fld, np.asarray(src.times_s), grid, data[:, 0], data[:, 1], make_params(), [], bbox, seed)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--days", type=float, default=120.0)
    ap.add_argument("--fig-dir", type=Path, default=ROOT / "docs" / "figures")
    args = ap.parse_args(argv)
    runs = [generate_for_box(days=args.days, seed=s) for s in range(args.seeds)]
    stats = [wind_statistics(w) for w in runs]
    # the first version of the generator: gaussian background spectrum, same seeds
    gauss = [wind_statistics(generate_for_box(days=args.days, seed=s, background_spectrum="gaussian"))
             for s in range(args.seeds)]
    old = old_cyclone_forcing()
    old_stats = wind_statistics(old)
    for k in ("cyclone_passages_per_box_year", "cyclones_in_domain_per_30_days"):
        old_stats[k] = float("nan")  # its systems are not CycloneTracks: not counted here
    print(f"wind climatology: {args.seeds} seeds x {args.days:g} days, 1000 km box, 25 km records")
    print(f"{'statistic':34s} {'target':>14s}  {'per seed':40s} {'mean':>7s}  in band  | old 'cyclones' forcing"
          " | gaussian spectrum (mean)")
    rows = {}
    for k, (lo, hi, unit, src) in TARGETS.items():
        vals = [s[k] for s in stats]
        m = float(np.nanmean(vals))
        inside = sum(lo <= v <= hi for v in vals)
        ov = old_stats.get(k, float("nan"))
        gm = float(np.nanmean([g[k] for g in gauss]))
        rows[k] = {"target": [lo, hi], "unit": unit, "source": src, "per_seed": vals, "mean": m,
                   "seeds_in_band": inside, "old_cyclones_forcing": ov, "gaussian_spectrum_mean": gm}
        print(f"{k:34s} {f'{lo:g}–{hi:g}':>14s}  {' '.join(f'{v:7.2f}' for v in vals):40s} {m:7.2f}  "
              f"{inside}/{len(vals)}     | {ov:6.2f}                 | {gm:.2f}")
    extra = ("speed_p50_m_s", "speed_p95_m_s", "speed_max_m_s", "basin_mean_speed_min_m_s",
             "basin_mean_vector_speed_m_s", "cyclones_in_domain_per_30_days", "cyclone_depth_mean_hpa",
             "cyclone_lifetime_mean_days")
    for k in extra:
        vals = [s[k] for s in stats]
        rows[k] = {"per_seed": vals, "mean": float(np.nanmean(vals)), "old_cyclones_forcing": old_stats.get(k)}
        print(f"{k:34s} {'':>14s}  {' '.join(f'{v:7.2f}' for v in vals):40s} {np.nanmean(vals):7.2f}        "
              f"| {old_stats.get(k, float('nan')):.2f}")
    args.fig_dir.mkdir(parents=True, exist_ok=True)
    out = {"seeds": args.seeds, "days": args.days, "params": make_params().as_dict(), "statistics": rows}
    (args.fig_dir / "wind_climatology.json").write_text(json.dumps(out, indent=1, default=float))
    figure(runs, stats, old, old_stats, gauss, args.fig_dir / "wind_climatology.png")
    print(f"wrote {args.fig_dir / 'wind_climatology.png'} and wind_climatology.json")
    return out


def figure(runs, stats, old, old_stats, gauss, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 3, figsize=(15, 12.5))
    a = ax[0, 0]
    bins = np.linspace(0, 30, 61)
    for w in runs:
        X, Y = w.grid.mesh()
        x0, x1, y0, y1 = w.domain_bbox
        ins = (X >= x0) & (X <= x1) & (Y >= y0) & (Y <= y1)
        a.hist(np.hypot(w.u[:, ins], w.v[:, ins]).ravel(), bins=bins, density=True, histtype="step", color="C0", lw=0.8)
    X, Y = old.grid.mesh()
    x0, x1, y0, y1 = old.domain_bbox
    ins = (X >= x0) & (X <= x1) & (Y >= y0) & (Y <= y1)
    a.hist(np.hypot(old.u[:, ins], old.v[:, ins]).ravel(), bins=bins, density=True, histtype="step", color="C3",
           lw=1.2, label="old 'cyclones' (28 d)")
    lo, hi = TARGETS["mean_speed_m_s"][:2]
    a.axvspan(lo, hi, color="0.85", zorder=0, label="target mean speed")
    a.set_yscale("log")
    a.set_xlabel("10-m wind speed (m s⁻¹)")
    a.set_ylabel("PDF")
    a.set_title("speed distribution (blue: climatology, one line per seed)")
    a.legend(fontsize=8)
    a = ax[0, 1]
    for s in stats:
        a.plot(s["temporal_lags_days"], s["temporal_correlation"], color="C0", lw=0.8)
    a.plot(old_stats["temporal_lags_days"], old_stats["temporal_correlation"], color="C3")
    a.axhline(np.exp(-1), color="k", ls=":", lw=0.8)
    lo, hi = TARGETS["temporal_efolding_days"][:2]
    a.axvspan(lo, hi, color="0.85", zorder=0)
    a.set_xlabel("lag (days)")
    a.set_ylabel("autocorrelation of wind anomalies")
    a.set_title("temporal correlation (band: target e-folding)")
    a = ax[0, 2]
    for s in stats:
        a.plot(s["spatial_distance_km"], s["spatial_correlation"], color="C0", lw=0.8)
    a.plot(old_stats["spatial_distance_km"], old_stats["spatial_correlation"], color="C3")
    a.axhline(np.exp(-1), color="k", ls=":", lw=0.8)
    lo, hi = TARGETS["spatial_efolding_km"][:2]
    a.axvspan(lo, hi, color="0.85", zorder=0)
    a.set_xlabel("separation (km)")
    a.set_ylabel("correlation of wind anomalies")
    a.set_title("spatial correlation (band: target e-folding)")
    a = ax[1, 0]
    w = runs[0]
    X, Y = w.grid.mesh()
    x0, x1, y0, y1 = w.domain_bbox
    ins = (X >= x0) & (X <= x1) & (Y >= y0) & (Y <= y1)
    k28 = w.times_s <= 28 * DAY_S
    a.plot(w.times_s[k28] / DAY_S, np.hypot(w.u[k28][:, ins], w.v[k28][:, ins]).mean(axis=1), color="C0",
           label="climatology (seed 0)")
    k28o = old.times_s <= 28 * DAY_S
    a.plot(old.times_s[k28o] / DAY_S, np.hypot(old.u[k28o][:, ins], old.v[k28o][:, ins]).mean(axis=1), color="C3",
           label="old 'cyclones'")
    a.axhline(3.0, color="k", ls=":", lw=0.8)
    a.set_xlabel("day")
    a.set_ylabel("basin-mean speed (m s⁻¹)")
    a.set_title("basin-mean wind speed, first 28 days")
    a.legend(fontsize=8)
    bm = np.hypot(w.u[k28][:, ins], w.v[k28][:, ins]).mean(axis=1)
    i_storm = int(np.argmax(bm))
    for j, it in enumerate((i_storm, min(i_storm + 4, len(w.times_s) - 1))):
        a = ax[1, 1 + j]
        day = w.times_s[it] / DAY_S
        sp = np.hypot(w.u[it], w.v[it])
        pc = a.pcolormesh(w.grid.x_m / 1e3, w.grid.y_m / 1e3, sp, vmin=0, vmax=20, cmap="viridis", shading="auto")
        st = 3
        a.quiver(X[::st, ::st] / 1e3, Y[::st, ::st] / 1e3, w.u[it][::st, ::st], w.v[it][::st, ::st], scale=250,
                 width=0.003)
        a.plot([x0 / 1e3, x1 / 1e3, x1 / 1e3, x0 / 1e3, x0 / 1e3], [y0 / 1e3, y0 / 1e3, y1 / 1e3, y1 / 1e3, y0 / 1e3],
               "w--", lw=1)
        a.set_aspect("equal")
        a.set_title(f"seed 0, day {day:g} (dashed: basin)")
        fig.colorbar(pc, ax=a, label="speed (m s⁻¹)", shrink=0.8)
    a = ax[2, 0]
    for lab, ss, col in (("climatology (k⁻² background)", stats, "C0"), ("gaussian background (first version)",
                                                                       gauss, "C2")):
        for i, st in enumerate(ss):
            a.loglog(st["structure_distance_km"], st["structure_function_m2_s2"], color=col, lw=0.8,
                     label=lab if i == 0 else None)
    r = np.array([75.0, 300.0])
    d0 = stats[0]["structure_function_m2_s2"][int(np.argmin(np.abs(np.array(stats[0]["structure_distance_km"])
                                                                   - 75.0)))]
    a.loglog(r, d0 * (r / 75.0) ** 1.0, "k--", lw=1, label="D ∝ r (spectrum k⁻²)")
    a.loglog(r, 0.3 * d0 * (r / 75.0) ** 2.0, "k:", lw=1, label="D ∝ r² (smooth, k⁻³)")
    a.axvspan(75, 300, color="0.9", zorder=0)
    a.set_xlabel("separation r (km)")
    a.set_ylabel("structure function D(r) (m² s⁻²)")
    lo, hi = TARGETS["spectral_slope"][:2]
    a.set_title(f"wind structure function (fit 75–300 km; target slope {lo:g} to {hi:g})", fontsize=10)
    a.legend(fontsize=7)
    ax[2, 1].axis("off")
    ax[2, 2].axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


if __name__ == "__main__":
    main()
