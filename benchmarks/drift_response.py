"""How freely the model's pack answers the wind (issue 12): the wind factor of finished runs.

For each run of ``benchmarks/physics_experiments.py`` (``benchmarks/out/physics/NAME``), the
drifters' daily velocities are fitted to the daily geostrophic wind along their tracks,
U = A G + C, as Thorndike and Colony (1982) did with Arctic buoys
(:mod:`lagice.diagnostics.drift`). The wind is the run's own forcing, rebuilt from the
configuration the run wrote into ``drifters.nc`` (the scene's initial mesh and ``scene_wind``,
the function that gave the run its wind), and the geostrophic wind is recovered exactly from the
climatology's 10-m wind (G = R(−θ) U10 / s with the run's ``surface_factor`` s and
``cross_isobar_angle_deg`` θ).

    python benchmarks/drift_response.py F10-hthick-1125 F10-hthick-1125-w2028 ...
    python benchmarks/drift_response.py --group "thick-and-thin, closed, eight months"   # a group, and its medians
    python benchmarks/drift_response.py --table          # the stored results as a markdown table

Results accumulate in ``benchmarks/out/physics/drift_response.json`` (copied to
``docs/figures/drift_response.json``), each with the run's median deformation rate from
``experiments.json`` beside it.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))


OUT = ROOT / "benchmarks" / "out" / "physics"
STORE = OUT / "drift_response.json"
PUBLISHED = ROOT / "docs" / "figures" / "drift_response.json"
from validate import update_record_store  # noqa: E402

from lagice.diagnostics.drift import THORNDIKE_COLONY_WINTER as OBSERVED  # noqa: E402

#: the store's entry for the observed band (always the module's, never a stored copy)
OBSERVED_KEY = "observed_thorndike_colony_1982_winter"


def analyse(name: str) -> dict:
    """:func:`lagice.diagnostics.drift.run_drift_response` of physics run ``name``, with its
    median rate and remesh count."""
    from lagice.diagnostics.drift import run_drift_response

    exp = json.loads((OUT / "experiments.json").read_text()).get(name, {})
    return {"name": name, **run_drift_response(OUT / name),
            "median_rate_per_day": exp.get("median", {}).get("mean_total_deformation_rate_per_day"),
            "remesh_events": exp.get("remesh_events"), "what": exp.get("what")}


def store(res: dict) -> None:
    """Add one run's fit to the store and the published copy (two analyses may finish together:
    :func:`validate.update_record_store`; without its lock they once dropped a record, forty-first
    session). The observed band is always the module's, first; the published copy leaves out the
    daily speed pairs (about 450 numbers per run)."""
    def update(data):
        data[res["name"]] = res
        return {OBSERVED_KEY: OBSERVED, **{k: v for k, v in sorted(data.items()) if k != OBSERVED_KEY}}

    def publish(full):
        slim = {k: ({a: b for a, b in v.items() if a != "daily_speeds_g_u_m_s"} if k != OBSERVED_KEY else v)
                for k, v in full.items()}
        PUBLISHED.write_text(json.dumps(slim, indent=1))

    update_record_store(STORE, PUBLISHED, update, publish)


def row(r: dict) -> str:
    f = r["fit"]
    rate = r.get("median_rate_per_day")
    lo, hi = OBSERVED["factor"]
    mark = " ✓" if lo <= f["factor"] <= hi else ""
    sp = r.get("factor_5_95_over_drifters")
    sp = f" ({sp[0]:.4f}–{sp[1]:.4f})" if sp else ""
    return (f"| {r['name']} | {f['factor']:.4f}{mark}{sp} | {f['angle_deg']:+.0f}° | {f['r2']:.2f} | "
            f"{100 * f['mean_ice_speed_m_s']:.1f} | {f['mean_wind_speed_m_s']:.1f} | "
            f"{'' if rate is None else f'{rate:.4f}'} | {f['n']} |")


def table(names=None) -> str:
    data = json.loads(STORE.read_text()) if STORE.exists() else {}
    head = ("| run | wind factor \\|A\\| (5–95 % over drifters) | turning | R² | mean ice speed (cm/s) "
            "| mean geostrophic wind (m/s) | ⟨ε̇tot⟩ d⁻¹ median | drifter-days |\n|---|---|---|---|---|---|---|---|\n"
            f"| observed (Thorndike and Colony 1982, winter) | about 0.008 (band {OBSERVED['factor'][0]}–"
            f"{OBSERVED['factor'][1]}) | about −5° | about 0.7 | | | 0.01–0.05 | |\n")
    keys = names or [k for k in sorted(data) if not k.startswith("observed")]
    return head + "\n".join(row(data[k]) for k in keys if k in data)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="*")
    ap.add_argument("--group", action="append", default=[], help="a spread group of physics_experiments.py")
    ap.add_argument("--table", action="store_true")
    ap.add_argument("--figure", type=Path, help="the wind factor against the deformation rate of every stored run")
    a = ap.parse_args(argv)
    names = list(a.runs)
    if a.group:
        import physics_experiments as pe

        for grp in a.group:
            if grp not in pe.ENSEMBLES:
                raise SystemExit(f"drift_response: no group {grp!r}; groups: {sorted(pe.ENSEMBLES)}")
            names += list(pe.ENSEMBLES[grp])
    for n in names:
        res = analyse(n)
        store(res)
        print(row(res), flush=True)
    for grp in a.group:
        print(group_medians(grp))
    if a.figure:
        print(f"wrote {figure(a.figure)}")
    if a.table or not (names or a.figure):
        print(table())


#: families of runs for the figure: (label, colour, test on the run name)
FAMILIES = (("shipped set, eight months, two basins", "k", lambda n: "-hthick-1125" in n and "-d" not in n
             and not n.endswith(("noheal", "str-50", "turn25", "eddies", "k7", "roundoff"))),
            ("strength calibrated to the wind factor (C_lab halved)", "tab:red",
             lambda n: "-str50" in n or n == "X10h-str-50"),
            ("±50 % sensitivity of the shipped set", "tab:orange", lambda n: n.startswith("X10h-")),
            ("compliance healing K = 50 and its sensitivity", "tab:blue",
             lambda n: "-K50" in n or n.startswith("X10k-")),
            ("EVP", "tab:green", lambda n: n.startswith("E10")),
            ("other diagnostics", "0.6", lambda n: True))


#: pooled runs of the figure's right panel: (label, colour, run names)
CURVES = (("shipped set, 16 month-basins", "k",
           [f"{p}-hthick-1125{w}" for p in ("F10", "F10s") for w in [""] + [f"-w{s}" for s in range(2027, 2034)]]),
          ("C_lab halved, 16 month-basins", "tab:red",
           ["X10h-str-50"] + [f"F10-hthick-str50-w{s}" for s in range(2027, 2034)]
           + [f"F10s-hthick-str50{w}" for w in [""] + [f"-w{s}" for s in range(2027, 2034)]]),
          ("compliance healing K = 50, 8 month-basins", "tab:blue",
           [f"{p}-hthick-K50{w}" for p in ("F10", "F10s") for w in ["", "-w2027", "-w2028", "-w2029"]]),
          ("EVP, validation month, 2 basins", "tab:green", ["E10h", "E10hs"]))


def free_drift_factor(g_m_s, thickness_m: float = 1.6) -> np.ndarray:
    """Free-drift ice speed [m s-1] under geostrophic winds ``g_m_s`` with the flagship's
    forcing (10-m wind 0.7 G, air drag 2.0e-3, water drag 5.5e-3, no turning, 80° N)."""
    from lagice.forces import free_drift_velocity
    from lagice.params import RHO_AIR, coriolis_from_latitude

    f = coriolis_from_latitude(80.0)
    out = []
    for g in np.atleast_1d(g_m_s):
        u10 = 0.7 * g
        out.append(abs(free_drift_velocity(complex(RHO_AIR * 2.0e-3 * u10 * u10, 0.0), f, 917.0 * thickness_m)))
    return np.array(out)


def figure(path: Path) -> Path:
    """Left: the wind factor |A| against the median deformation rate of every stored run,
    with the observed ranges. Right: the daily ice speed against the daily geostrophic wind
    speed (medians in 2 m s⁻¹ bins) of pooled runs, with Thorndike and Colony's 0.008 G and
    free drift."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = {k: v for k, v in json.loads(STORE.read_text()).items() if not k.startswith("observed")}
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(13, 5.5))
    ax.add_patch(plt.Rectangle((OBSERVED["factor"][0], 0.01), OBSERVED["factor"][1] - OBSERVED["factor"][0], 0.04,
                               color="tab:green", alpha=0.12, label="observed: wind factor (winter) and ⟨ε̇tot⟩"))
    done = set()
    for label, colour, test in FAMILIES:
        ns = [n for n in data if n not in done and test(n) and data[n].get("median_rate_per_day")]
        done.update(ns)
        if ns:
            ax.scatter([data[n]["fit"]["factor"] for n in ns],
                       [max(data[n]["median_rate_per_day"], 1e-5) for n in ns], c=colour, s=22, label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wind factor |A| (daily ice velocity / geostrophic wind)")
    ax.set_ylabel("⟨ε̇tot⟩, median over 3-day windows (day$^{-1}$)")
    ax.set_title(f"{len(done)} runs: how freely the pack answers the wind, and how much it deforms", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(True, which="both", alpha=0.3)
    edges = np.arange(0.0, 26.0, 2.0)
    mid = 0.5 * (edges[1:] + edges[:-1])
    for label, colour, names in CURVES:
        pairs = [np.asarray(data[n]["daily_speeds_g_u_m_s"]) for n in names
                 if "daily_speeds_g_u_m_s" in data.get(n, {})]
        if not pairs:
            continue
        pr = np.concatenate(pairs)
        k = np.digitize(pr[:, 0], edges) - 1
        med = [np.median(pr[k == i, 1]) if np.sum(k == i) >= 10 else np.nan for i in range(len(mid))]
        bx.plot(mid, 100 * np.array(med), "o-", c=colour, ms=4, label=f"{label} ({len(pairs)} runs)")
    bx.plot(mid, 100 * 0.008 * mid, "--", c="tab:green", label="Thorndike and Colony (1982), winter: 0.008 G")
    bx.plot(mid, 100 * free_drift_factor(mid), ":", c="0.4", label="free drift, the model's drag (1.6 m)")
    bx.set_xlabel("daily geostrophic wind speed along the track (m s$^{-1}$)")
    bx.set_ylabel("daily ice speed (cm s$^{-1}$), median per 2 m s$^{-1}$ bin")
    bx.set_title("Daily drift against the wind (bins with at least 10 drifter-days)", fontsize=9)
    bx.legend(fontsize=7, loc="upper left")
    bx.grid(True, alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def group_medians(group: str) -> str:
    """The medians over a group's runs of |A|, the turning, R² and the deformation rate."""
    import physics_experiments as pe

    data = json.loads(STORE.read_text())
    rs = [data[n] for n in pe.ENSEMBLES[group] if n in data]
    med = {k: float(np.median([r["fit"][k] for r in rs])) for k in ("factor", "angle_deg", "r2")}
    rates = [r["median_rate_per_day"] for r in rs if r.get("median_rate_per_day") is not None]
    lo, hi = OBSERVED["factor"]
    inside = "inside" if lo <= med["factor"] <= hi else "outside"
    return (f"{group} ({len(rs)} runs): median wind factor {med['factor']:.4f} ({inside} {lo}-{hi}), turning "
            f"{med['angle_deg']:+.0f}°, R² {med['r2']:.2f}; median of the runs' rates "
            f"{np.median(rates) if rates else float('nan'):.4f} d⁻¹")


if __name__ == "__main__":
    main()
