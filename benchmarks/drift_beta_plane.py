"""Every published run in one plane: how freely the pack drifts against how its deformation
scales (docs/physics.md §4, "The drift against β over every run", fortieth session).

Issue 12 asks for a flagship whose medians lie inside six observed bands. Two of them pull
against each other in every change tried so far: β, the spatial scaling exponent of the
deformation rate (observed 0.17–0.20, Marsan et al. 2004), and the response of the drift to the
wind, the wind factor |A| of U = A G + C fitted to the geostrophic wind as Thorndike and Colony
(1982) fitted Arctic buoys (winter band 0.006–0.010). A pack bound tightly enough to drift like
observed ice deforms coherently (β low); a pack that localises like observed ice drifts almost
freely. This script puts every run that has both records on one figure.

It reads only the published records, so a fresh checkout draws the same figure:
``docs/figures/physics_experiments.json`` (each run's medians over its 3-day windows and its
overrides) and ``docs/figures/drift_response.json`` (its wind factor,
``benchmarks/drift_response.py``). Each run is put in one family by its overrides
(:func:`family_of`; the first rule that matches wins, in the order of :data:`FAMILIES`):

* EVP, the viscous-plastic control;
* Crouzeix–Raviart velocities: the statistics are those of the node motion, mostly the mesh's
  (thirty-ninth session, "What the best-β set-up's statistics measure");
* the nodal volumetric strain, whose spurious modes carry the deformation (thirtieth session);
* damage averaged over a length R, whose β follows R over the element size (a mesh parameter);
* the effective envelope with floes at least five times neXtSIM's strength (calibrated; forty-first
  session, "Strong floes in a weak network");
* the effective envelope (broken ice keeps no cohesion), with or without a damage cap or another α;
* the energy envelope (broken ice keeps C √(1 − d); forty-second session, "Broken ice that keeps part
  of its cohesion"), at any strength;
* broken ice that keeps or caps its pressure on the linear element (the mean stress kept, a bulk
  viscosity ratio, neXtSIM's compressive term, closed cracks);
* the nominal envelope on the linear element: the shipped set and every change of forcing,
  heterogeneity, healing, strength, drag, geometry or history.

Printed: per family, the number of runs, the medians and ranges of β and of the wind factor, how
many runs have β in its band, the wind factor in its band, both, and the most bands inside (of 6).
Written: ``docs/figures/drift_beta_plane.png`` (β against the wind factor; bands inside against
β) and ``docs/figures/drift_beta_plane.json`` (the per-family summary and every point).

    python benchmarks/drift_beta_plane.py
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from validate import TARGETS

from lagice.diagnostics.drift import THORNDIKE_COLONY_WINTER

ROOT = Path(__file__).resolve().parents[1]
RECORDS = ROOT / "docs" / "figures" / "physics_experiments.json"
FITS = ROOT / "docs" / "figures" / "drift_response.json"
#: observed bands, with their sources where they are declared (issue 12)
BETA_BAND = tuple(TARGETS["beta_space"][:2])
WIND_FACTOR_BAND = tuple(THORNDIKE_COLONY_WINTER["factor"])
N_BANDS = len(TARGETS)

#: C_lab [Pa, lagice's form] from which an effective-envelope run counts as "strong floes in a weak
#: network" (forty-first session): five times neXtSIM's 2 MPa converted (2.8 MPa)
STRONG_FLOES_LAB_PA = 5.0 * 2.8e6
#: (key, label, rule): a run belongs to the first family whose rule holds for its overrides
#: (a dict key -> value string)
FAMILIES = (
    ("evp", "EVP (viscous-plastic control)", lambda o: o.get("solver.name") == "evp"),
    ("crouzeix_raviart", "Crouzeix–Raviart velocities (node motion, mostly the mesh's)",
     lambda o: o.get("solver.velocity_element") == "crouzeix_raviart"),
    ("nodal", "nodal volumetric strain (its spurious modes carry the deformation)",
     lambda o: o.get("solver.volumetric_strain") == "nodal"),
    ("nonlocal", "damage averaged over R (a mesh parameter)",
     lambda o: float(o.get("rheology.damage_nonlocal_radius_m", "0")) > 0.0),
    ("strong_floes", "effective envelope, floes at least 5x neXtSIM's strength (calibrated)",
     lambda o: (o.get("rheology.failure_stress") == "effective"
                and float(o.get("rheology.strength_lab_pa", "0")) >= STRONG_FLOES_LAB_PA)),
    ("effective", "effective envelope (broken ice keeps no cohesion)",
     lambda o: o.get("rheology.failure_stress") == "effective"),
    ("energy", "energy envelope (broken ice keeps C sqrt(1 - d))",
     lambda o: o.get("rheology.failure_stress") == "energy"),
    ("pressure", "broken ice keeps or caps its pressure (linear element)",
     lambda o: (o.get("rheology.relax_mean_stress") == "false" or "rheology.bulk_shear_viscosity_ratio" in o
                or "rheology.max_pressure_pa" in o or o.get("rheology.crack_closure") == "true")),
    ("nominal", "nominal envelope, linear element (the shipped set and its variations)", lambda o: True),
)
COLOURS = {"evp": "tab:gray", "crouzeix_raviart": "tab:purple", "nodal": "tab:brown", "nonlocal": "tab:olive",
           "effective": "tab:red", "strong_floes": "tab:pink", "energy": "tab:cyan", "pressure": "tab:orange",
           "nominal": "tab:blue"}


def overrides_dict(overrides: list) -> dict:
    """``["a.b=1", ...]`` -> ``{"a.b": "1"}`` (values as written, quotes stripped)."""
    out = {}
    for o in overrides:
        key, _, value = o.partition("=")
        out[key.strip()] = value.strip().strip("\"'")
    return out


def family_of(overrides: list) -> str:
    """The family key of a run from its overrides (:data:`FAMILIES`, first match)."""
    o = overrides_dict(overrides)
    for key, _, rule in FAMILIES:
        if rule(o):
            return key
    raise AssertionError("the last family matches every run")


def plane_points(records: dict, fits: dict) -> list:
    """One point per run that has both a median β (``records``) and a wind-factor fit
    (``fits``): name, family, resolution [m], β, wind factor, bands inside (of 6)."""
    points = []
    for name, fit in fits.items():
        rec = records.get(name)
        if not isinstance(fit, dict) or "fit" not in fit or not rec or "median" not in rec:
            continue
        beta = rec["median"].get("beta_space")
        if beta is None or not np.isfinite(beta):
            continue
        inside = rec.get("inside") or {}
        points.append({"name": name, "family": family_of(rec.get("overrides", [])),
                       "resolution_m": float(rec["resolution_m"]), "beta": float(beta),
                       "wind_factor": float(fit["fit"]["factor"]),
                       "bands_inside": int(sum(bool(v) for v in inside.values()))})
    return points


def _in(x: float, band) -> bool:
    return band[0] <= x <= band[1]


def summary(points: list) -> dict:
    """Per family: runs, medians and ranges of β and of the wind factor, runs with β in its
    band, with the wind factor in its band, with both, and the most bands inside."""
    out = {}
    for key, label, _ in FAMILIES:
        pts = [p for p in points if p["family"] == key]
        if not pts:
            continue
        b = np.array([p["beta"] for p in pts])
        a = np.array([p["wind_factor"] for p in pts])
        both = [p["name"] for p in pts if _in(p["beta"], BETA_BAND) and _in(p["wind_factor"], WIND_FACTOR_BAND)]
        out[key] = {"label": label, "runs": len(pts),
                    "beta_median": float(np.median(b)), "beta_range": [float(b.min()), float(b.max())],
                    "wind_factor_median": float(np.median(a)), "wind_factor_range": [float(a.min()), float(a.max())],
                    "beta_in_band": int(sum(_in(x, BETA_BAND) for x in b)),
                    "wind_factor_in_band": int(sum(_in(x, WIND_FACTOR_BAND) for x in a)),
                    "both_in_band": len(both), "both_in_band_runs": both,
                    "most_bands_inside": int(max(p["bands_inside"] for p in pts))}
    return out


def table(summ: dict) -> str:
    rows = ["| family | runs | β median (range) | wind factor median (range) | β in band | wind factor in band "
            "| both | most bands inside |", "|---|---|---|---|---|---|---|---|"]
    for s in summ.values():
        rows.append(f"| {s['label']} | {s['runs']} | {s['beta_median']:.3f} ({s['beta_range'][0]:.3f}–"
                    f"{s['beta_range'][1]:.3f}) | {s['wind_factor_median']:.4f} ({s['wind_factor_range'][0]:.4f}–"
                    f"{s['wind_factor_range'][1]:.4f}) | {s['beta_in_band']} | {s['wind_factor_in_band']} | "
                    f"{s['both_in_band']} | {s['most_bands_inside']} |")
    return "\n".join(rows)


#: the figure's β axis ends here; runs above it are drawn on its top edge and counted in the title
BETA_AXIS_MAX = 0.42


def figure(points: list, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(13, 6.4), gridspec_kw={"width_ratios": [1.35, 1]})
    ax.add_patch(plt.Rectangle((WIND_FACTOR_BAND[0], BETA_BAND[0]), WIND_FACTOR_BAND[1] - WIND_FACTOR_BAND[0],
                               BETA_BAND[1] - BETA_BAND[0], color="tab:green", alpha=0.3, lw=0,
                               label="observed: β and the wind factor in their bands"))
    ax.axvspan(*WIND_FACTOR_BAND, color="tab:green", alpha=0.08, lw=0)
    ax.axhspan(*BETA_BAND, color="tab:green", alpha=0.08, lw=0)
    bx.axvspan(*BETA_BAND, color="tab:green", alpha=0.3, lw=0)
    above = [p for p in points if p["beta"] > BETA_AXIS_MAX]
    for key, label, _ in FAMILIES:
        pts = [p for p in points if p["family"] == key]
        if not pts:
            continue
        ax.scatter([], [], color=COLOURS[key], marker="s", s=30, label=f"{label}: {len(pts)}")
        for res, marker in ((10e3, "o"), (20e3, "^")):
            sel = [p for p in pts if abs(p["resolution_m"] - res) < 1.0]
            if not sel:
                continue
            kw = {"color": COLOURS[key], "marker": marker, "s": 22, "alpha": 0.75, "lw": 0}
            beta = np.minimum([p["beta"] for p in sel], BETA_AXIS_MAX)
            ax.scatter([p["wind_factor"] for p in sel], beta, **kw)
            jitter = np.linspace(-0.15, 0.15, len(sel)) if len(sel) > 1 else np.zeros(1)
            bx.scatter(beta, np.array([p["bands_inside"] for p in sel]) + jitter, **kw)
    ax.scatter([], [], color="k", marker="o", s=22, label="10 km")
    ax.scatter([], [], color="k", marker="^", s=22, label="20 km")
    ax.set_xscale("log")
    ax.set_ylim(0.0, BETA_AXIS_MAX * 1.02)
    bx.set_xlim(0.0, BETA_AXIS_MAX * 1.02)
    ax.set_xlabel("wind factor |A| (drift / geostrophic wind; below 1e-3 the pack is locked)")
    ax.set_ylabel("β (3-day windows, median over the month)")
    ax.set_title(f"{len(points)} runs: how freely the pack drifts against how it localises\n"
                 f"({len(above)} runs with β above {BETA_AXIS_MAX} drawn on the top edge)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    bx.set_xlabel("β")
    bx.set_ylabel(f"bands inside (of {N_BANDS})")
    bx.set_yticks(range(N_BANDS + 1))
    bx.set_title("bands inside against β (green: β's band)", fontsize=10)
    bx.grid(alpha=0.3)
    fig.legend(*ax.get_legend_handles_labels(), loc="lower center", ncol=3, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.14, 1, 1))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "drift_beta_plane.png")
    args = ap.parse_args(argv)
    points = plane_points(json.loads(RECORDS.read_text()), json.loads(FITS.read_text()))
    summ = summary(points)
    print(table(summ))
    print(f"drift_beta_plane: wrote {figure(points, args.out)}")
    js = args.out.with_suffix(".json")
    js.write_text(json.dumps({"beta_band": BETA_BAND, "wind_factor_band": WIND_FACTOR_BAND, "families": summ,
                              "points": points}, indent=1) + "\n")
    print(f"drift_beta_plane: wrote {js}")


if __name__ == "__main__":
    main()
